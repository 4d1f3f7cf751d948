#!/usr/bin/env python3
"""check_desk.py --demo BIN --dhcal BIN --scenarios DIR: the controller's samples at the
analyst's desk. dhcal-demo runs the firmware against a host_sim arm and writes its samples;
`dhcal diagnose` reads them with the noise model the controller measured (--noise, from the
demo's JSON) and must reach the controller's verdict: nothing on the clean arm, the hidden
effect on the compliant one."""
import argparse
import json
import os
import subprocess
import sys
import tempfile


def run(cmd):
    r = subprocess.run(cmd, capture_output=True, text=True, timeout=600, check=False)
    if r.returncode != 0:
        sys.stderr.write(r.stderr)
        raise SystemExit(f"FAIL: {' '.join(cmd)} exited {r.returncode}")
    return r.stdout


def top_significant(diag):
    c = diag.get("candidates", [])
    if not c or not c[0]["significant"]:
        return None
    j = c[0]["joint"]
    return c[0]["effect"] + (f":{j}" if j is not None else "")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--demo", required=True)
    ap.add_argument("--dhcal", required=True)
    ap.add_argument("--scenarios", required=True)
    a = ap.parse_args()
    model = os.path.join(a.scenarios, "paper-3dof-model.json")
    failures = []
    for scenario, expected in (("clean", None), ("joint_compliance_2", "joint_compliance:2")):
        with tempfile.TemporaryDirectory(prefix="dhcal-desk-") as out:
            demo = json.loads(run([a.demo, "--scenario",
                                   os.path.join(a.scenarios, scenario + ".json"), "--json",
                                   "--out", out]))
            nm = demo["noise_model"]
            noise = f"{nm['joint_deg']:.6g},{nm['meas_mm']:.6g}"
            samples = os.path.join(out, "samples.csv")
            weighted = json.loads(run([a.dhcal, "diagnose", "--model", model, "--data", samples,
                                       "--noise", noise, "--json"]))
            plain = json.loads(run([a.dhcal, "diagnose", "--model", model, "--data", samples,
                                    "--json"]))
        got = top_significant(weighted)
        print(f"{scenario}: controller says {demo['effect']}; desk with --noise {noise} says "
              f"{got or 'none'} (whitened sd {weighted['noise_model']['whitened_sd']:.3f}); "
              f"desk unweighted says {top_significant(plain) or 'none'}")
        if got != expected:
            failures.append(f"{scenario}: dhcal diagnose --noise named {got}, expected {expected}")
        if (demo["effect"] if demo["effect"] != "none" else None) != expected:
            failures.append(f"{scenario}: the controller named {demo['effect']}")
    if failures:
        print("FAIL:", "; ".join(failures))
        return 1
    print("PASS")
    return 0


if __name__ == "__main__":
    sys.exit(main())
