#!/usr/bin/env python3
"""Acceptance of the user's loop on generated data (issue #12), the data made by
hidden_effects.py's independent model of the paper's 3-DOF arm (pure Python):

  small    8 poses, two of them gross as real ones come: placeholder angles near 300 deg
           (joint 1 ranges +-170) and a point 1.3 m from the shoulder of an arm that reaches
           0.75 m; the arm's errors in its joint offsets (machined to drawing). `dhcal refine`: both flagged with their reasons, a reduced geometry chosen
           by cross-validation, no parameter far from its physical value, no claim of
           fitting the noise (no reference).
  outside  an effect outside every catalogue: joint 2 off by a bump exp(-(q - 60 deg)^2 /
           (2 (15 deg)^2)) x 0.3 deg (a damaged gear tooth region), 10 poses measured three
           times each: refine ends with the verdict systematic_error (the repeats are the
           reference); the same rows without repeats (one of each): unknown.
  diagnose --cv  each candidate's cv_rms_mm as `fit --cv` with it added gives it.
  sweep    the bump, rows measured in the order of joint 2 (time a function of the pose): no
           drift candidate is scored or added.
  clean    geometry errors only, repeats: fits_noise.

Usage: test_user_loop.py --dhcal PATH [--work DIR] [--wrapper CMD]
The last line is "N passed, M failed".
"""
import argparse
import json
import math
import os
import shlex
import subprocess
import sys
import tempfile

sys.dont_write_bytecode = True
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import hidden_effects as he  # noqa: E402
from checks import Checks  # noqa: E402


def write_csv(path, rows):
    with open(path, "w") as f:
        f.write("q1,q2,q3,x,y,z\n")
        for q, p in rows:
            f.write(",".join("%.6f" % v for v in q) + "," + ",".join("%.6f" % v for v in p) + "\n")


def measure(arm, poses, rng, bump=False, joint_error=None):
    rows = []
    for q_deg in poses:
        q = [math.radians(v) for v in q_deg]
        if joint_error:
            q_eff = joint_error(q)
        elif bump:
            q_eff = list(q)
            q_eff[1] += math.radians(0.3) * math.exp(-((q_deg[1] - 60.0) ** 2) / (2 * 15.0 ** 2))
        else:
            q_eff = q
        p = he.tool_point(arm, q_eff)
        rows.append((q_deg, [v + rng.gauss(0.0, he.NOISE_MM) for v in p]))
    return rows


def run(cmd, wrapper):
    full = shlex.split(wrapper) + cmd if wrapper else cmd
    r = subprocess.run(full, capture_output=True, text=True, timeout=900)
    try:
        out = json.loads(r.stdout)
    except json.JSONDecodeError:
        out = None
    return r, out


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--dhcal", required=True)
    ap.add_argument("--work")
    ap.add_argument("--wrapper", default="")
    a = ap.parse_args()
    work = a.work or tempfile.mkdtemp(prefix="dhcal-user-loop-")
    os.makedirs(work, exist_ok=True)
    model = os.path.join(work, "model.json")
    with open(model, "w") as f:
        json.dump(he.model_json(), f)
    c = Checks()

    # ---- small, with two gross rows
    rng = he._rng("user-loop-small", 1, "all")
    # an arm whose errors are its encoders' zero offsets (0.3 deg), machined to drawing:
    # on six good rows a full fit's nine further parameters only add variance, which
    # cross-validation sees
    arm = he.nominal_arm()
    for i in range(he.N_JOINTS):
        arm["theta_deg"][i] += rng.gauss(0.0, 0.3)
    poses = [q for q, _ in he.sample_poses(rng, 8, arm)]
    rows = measure(arm, poses, rng)
    rows[2] = ([299.87, 300.12, 299.95], rows[2][1])           # placeholder angles
    rows[5] = (rows[5][0], [900.0, 850.0, 1100.0])              # 1.3 m from the shoulder
    small = os.path.join(work, "small.csv")
    write_csv(small, rows)
    r, out = run([a.dhcal, "refine", "--model", model, "--data", small, "--json"], a.wrapper)
    c.check("small: refine exits 0", r.returncode == 0, "exit %d %s" % (r.returncode, r.stderr.strip()))
    if out:
        reasons = {o["row"]: o["reason"] for o in out["outliers"]}
        c.check("small: the placeholder row is flagged joint_range", reasons.get(3) == "joint_range",
                str(reasons))
        c.check("small: the far row is flagged beyond_reach", reasons.get(6) == "beyond_reach",
                str(reasons))
        c.check("small: no good row flagged", len(reasons) == 2, str(reasons))
        c.check("small: a reduced geometry chosen", out["geometry"] in ("offsets", "lengths"),
                "%s (%s)" % (out["geometry"], out.get("geometry_why", "")))
        worst_len = max([abs(p["value"] - n) for p in out["parameters"]
                         for k, n in (("a1", 0.0), ("a2", 400.0), ("a3", 345.0), ("d1", 433.0))
                         if p["name"] == k] + [0.0])
        c.check("small: no absurd length (within 5 mm of nominal)", worst_len < 5.0,
                "%.3f mm" % worst_len)
        c.check("small: no claim of fitting the noise", out["adequacy"]["verdict"] == "unknown",
                str(out["adequacy"]))

    # ---- an effect outside every catalogue, with and without repeats
    rng = he._rng("user-loop-outside", 1, "all")
    arm = he.true_arm(rng)
    base_poses = [q for q, _ in he.sample_poses(rng, 40, arm)]
    rep_rows = measure(arm, [q for q in base_poses for _ in range(3)], rng, bump=True)
    one_rows = measure(arm, base_poses, rng, bump=True)
    rep_path = os.path.join(work, "outside-repeats.csv")
    one_path = os.path.join(work, "outside-once.csv")
    write_csv(rep_path, rep_rows)
    write_csv(one_path, one_rows)
    r, out = run([a.dhcal, "refine", "--model", model, "--data", rep_path, "--json"], a.wrapper)
    c.check("outside, repeats: refine exits 0", r.returncode == 0, r.stderr.strip())
    if out:
        ad = out["adequacy"]
        c.check("outside, repeats: systematic_error", ad["verdict"] == "systematic_error", str(ad))
        c.check("outside, repeats: the noise measured from the repeats",
                ad["noise_source"] == "repeats" and abs(ad["noise_mm"] - he.NOISE_MM) < 0.02,
                str(ad))
    r, out = run([a.dhcal, "refine", "--model", model, "--data", one_path, "--json"], a.wrapper)
    c.check("outside, once: refine exits 0", r.returncode == 0, r.stderr.strip())
    if out:
        c.check("outside, once: unknown (no noise reference)",
                out["adequacy"]["verdict"] == "unknown", str(out["adequacy"]))

    # ---- diagnose --cv: each candidate's CV RMS as a fit with it added cross-validates
    # (a catalogue error, 2-per-rev of joint 1, on clean rows: no outlier for either path)
    rng = he._rng("user-loop-cv", 1, "all")
    arm = he.true_arm(rng)
    twice = os.path.join(work, "twice-per-rev.csv")
    write_csv(twice, measure(arm, [q for q, _ in he.sample_poses(rng, 60, arm)], rng,
                             joint_error=lambda q: [q[0] + math.radians(0.05) * math.sin(2 * q[0]),
                                                    q[1], q[2]]))
    r, out = run([a.dhcal, "diagnose", "--model", model, "--data", twice, "--cv", "--json"],
                 a.wrapper)
    c.check("diagnose --cv: exits 0", r.returncode == 0, r.stderr.strip())
    tried = [k for k in (out or {}).get("candidates", []) if "cv_rms_mm" in k]
    c.check("diagnose --cv: candidates carry cv_rms_mm", len(tried) > 0,
            str([k["effect"] for k in tried]))
    for k in tried[:2]:
        label = k["effect"] + (":%d" % k["joint"] if k["joint"] is not None else "")
        r2, fit = run([a.dhcal, "fit", "--model", model, "--data", twice, "--effects", label,
                       "--cv", "--json"], a.wrapper)
        ok = fit is not None and abs(fit["cv_rms_mm"] - k["cv_rms_mm"]) <= 0.02 * fit["cv_rms_mm"]
        c.check("diagnose --cv: %s's CV RMS matches fit --cv with it (2 %%)" % label, ok,
                "%s vs %s" % (k["cv_rms_mm"], fit and fit["cv_rms_mm"]))

    # ---- a sweep: rows measured in the order of joint 2, the bump error of joint 2 growing
    # with it; time (the row number) is then a function of the pose, and a drift fitted to it
    # would be the bump in disguise
    rng = he._rng("user-loop-sweep", 1, "all")
    arm = he.true_arm(rng)
    poses = sorted((q for q, _ in he.sample_poses(rng, 120, arm)), key=lambda q: q[1])
    sweep = os.path.join(work, "sweep.csv")
    write_csv(sweep, measure(arm, poses, rng, bump=True))
    r, out = run([a.dhcal, "diagnose", "--model", model, "--data", sweep, "--json"], a.wrapper)
    c.check("sweep: diagnose exits 0", r.returncode == 0, r.stderr.strip())
    if out:
        c.check("sweep: time is in step with the pose", out["time_pose_r2"] > 0.5,
                "%.3f" % out["time_pose_r2"])
        c.check("sweep: no drift candidate scored",
                not any(k["effect"].startswith("drift") for k in out["candidates"]),
                str([k["effect"] for k in out["candidates"][:3]]))
    r, out = run([a.dhcal, "refine", "--model", model, "--data", sweep, "--json"], a.wrapper)
    c.check("sweep: refine exits 0", r.returncode == 0, r.stderr.strip())
    if out:
        c.check("sweep: refine adds no drift", not any(e.startswith("drift") for e in out["effects"]),
                str(out["effects"]))

    # ---- clean, with repeats: fits the noise
    rng = he._rng("user-loop-clean", 1, "all")
    arm = he.true_arm(rng)
    base_poses = [q for q, _ in he.sample_poses(rng, 40, arm)]
    clean = os.path.join(work, "clean-repeats.csv")
    write_csv(clean, measure(arm, [q for q in base_poses for _ in range(3)], rng))
    r, out = run([a.dhcal, "refine", "--model", model, "--data", clean, "--json"], a.wrapper)
    c.check("clean, repeats: refine exits 0", r.returncode == 0, r.stderr.strip())
    if out:
        c.check("clean, repeats: fits_noise", out["adequacy"]["verdict"] == "fits_noise",
                str(out["adequacy"]))
        c.check("clean: no effect added", out["effects"] == [], str(out["effects"]))

    print("%d passed, %d failed" % (c.passed, c.failed))
    return 0 if c.failed == 0 else 1


if __name__ == "__main__":
    sys.exit(main())
