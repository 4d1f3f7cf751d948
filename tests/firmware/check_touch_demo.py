#!/usr/bin/env python3
"""Acceptance of the controller's calibration by touching (issue 28): dhcal-touch-demo on a
scenario with a touch probe, three planes and three gauge blocks (host_sim/scenarios/
touch_planes.json). The controller touches, calibrates, stores, and positions fresh targets;
the plant's truth judges it.

Passes when:
  - the true positioning error after the best rigid motion (what touches can see) falls at
    least 5x from the nominal model to the calibrated one;
  - the calibration is stored (better than nothing stored), every plane's touches and every
    gauge's pairs became samples (one per plane touch, one per pair);
  - the blind directions are named: the arm's turn about its base axis and its height
    (theta1, d1), and nothing else (the gauges give the scale);
  - a scenario without a probe is refused with exit 2, naming the file;
  - with --dhcal: the desk's `dhcal fit` on the touches the controller wrote (--out,
    touch-samples.csv) fits them about as well as the controller did (within 2x and 2 um),
    blind in theta1 and d1 only, its prior weighed against the noise leaving planes out finds.
Usage: check_touch_demo.py --demo PATH --scenario S.json [--dhcal PATH] [--max-seconds S]
"""
import argparse
import json
import os
import subprocess
import sys
import tempfile
import time


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--demo", required=True)
    ap.add_argument("--scenario", required=True)
    ap.add_argument("--max-seconds", type=float, default=120.0)
    ap.add_argument("--dhcal", default=None)
    args = ap.parse_args()
    failed = 0

    def check(ok, what):
        nonlocal failed
        print(("PASS: " if ok else "FAIL: ") + what)
        failed += 0 if ok else 1

    scratch = tempfile.TemporaryDirectory(prefix="dhcal-touch-demo-")
    t0 = time.time()
    run = subprocess.run([args.demo, "--scenario", args.scenario, "--json", "--out", scratch.name],
                         stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, check=False)
    seconds = time.time() - t0
    sys.stdout.write(run.stderr)
    if run.returncode != 0:
        print(f"FAIL: dhcal-touch-demo exited {run.returncode}")
        return 1
    r = json.loads(run.stdout)
    before, after = r["before_rms_mm"], r["after_rms_mm"]
    check(after <= before / 5.0, f"the true error after the best rigid motion falls at least "
                                 f"5x: {before:.4f} -> {after:.4f} mm ({before / after:.1f}x)")
    check(r["stored"], "the calibration is stored")
    expected_samples = r["touch_offs"] - r["samples"]  # one extra touch-off per pair
    check(r["planes"] == 3 and r["gauges"] == 3 and expected_samples > 0,
          f"3 planes and 3 gauges touched: {r['touch_offs']} touch-offs, {r['samples']} samples")
    check(sorted(r["blind"]) == ["d1", "theta1"],
          f"blind: the arm's turn about its base axis and its height only: {r['blind']}")
    check(seconds <= args.max_seconds, f"runs within {args.max_seconds:.0f} s ({seconds:.1f} s)")

    if args.dhcal is not None:
        with open(args.scenario) as f:
            model = os.path.join(os.path.dirname(os.path.abspath(args.scenario)),
                                 json.load(f)["model"])
        desk = subprocess.run([args.dhcal, "fit", "--model", model, "--data",
                               os.path.join(scratch.name, "touch-samples.csv"), "--json"],
                              stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                              check=False)
        if desk.returncode != 0:
            check(False, f"dhcal fit on the controller's touches: exit {desk.returncode}: "
                         f"{desk.stderr.strip()[:200]}")
        else:
            d = json.loads(desk.stdout)
            blind = sorted(u["param"] for u in d["unidentifiable"] if u["blind"])
            check(d["rms_mm"] <= 2.0 * r["fit_rms_mm"] + 0.002 and blind == ["d1", "theta1"] and
                  d["prior"].get("cv_rms_mm", 0.0) > 0.0,
                  f"the desk fits the controller's touches to {d['rms_mm']:.4f} mm (the "
                  f"controller {r['fit_rms_mm']:.4f}), blind {blind}, prior {d['prior']}")
    scratch.cleanup()

    with tempfile.TemporaryDirectory(prefix="dhcal-touch-") as tmp:
        plain = os.path.join(tmp, "no-probe.json")
        with open(args.scenario) as f:
            sc = json.load(f)
        sc.pop("probe")
        sc["model"] = os.path.join(os.path.dirname(os.path.abspath(args.scenario)), sc["model"])
        with open(plain, "w") as f:
            json.dump(sc, f)
        bad = subprocess.run([args.demo, "--scenario", plain], stdout=subprocess.PIPE,
                             stderr=subprocess.PIPE, text=True, check=False)
        check(bad.returncode == 2 and plain in bad.stderr and "no probe" in bad.stderr,
              f"a scenario without a probe is refused naming the file: exit {bad.returncode}: "
              f"{bad.stderr.strip()[:160]}")
    print(f"{'FAILED' if failed else 'passed'}")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
