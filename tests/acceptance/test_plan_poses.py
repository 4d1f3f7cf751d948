#!/usr/bin/env python3
"""Pose plans (dhcal plan), end to end: do planned poses calibrate better?

For each arm and DRAWS random draws (the arm's errors, the hidden effect's size, the
candidates, the noise, the held-out poses all change with the draw):
  * planned: `dhcal plan --poses N` chooses among 20 N random candidates; the TRUE arm (this
    file's own kinematics, never shown to dhcal) is measured there with noise;
  * random: N random poses, and 2 N random poses, measured the same way;
  * each calibrated with `dhcal fit --effects E` (E: the hidden effect and what the arm's
    errors need, named to the plan and to the fit) and judged on 60 held-out random poses
    (heldout_rms_mm), whose rows are the true tool points: the calibration's positioning
    error, without the tracker's noise.
Asserted: averaged over the draws, the planned N poses calibrate better than N random ones,
the plan's predicted variance is at least 1.3x below the random plan's, and in every draw
within 10 % above the floor `dhcal plan` puts under every plan of N poses (variance_floor).
Reported: how they compare with 2 N random poses (the goal of "half the measurements"), and
whether any selection of N poses could reach that: the mean floor against the mean variance
2 N random poses predict (variance_random of a plan of 2 N).
Arms: the paper's 3-DOF arm with joint_compliance:2 (hidden_effects.py's generator, tool
positions), N = 15; the paper's 6-DOF arm (Table 1 as built, Table 2 nominal) with a tool
80 mm off the flange and joint_scale:3, N = 25.

  test_plan_poses.py --dhcal PATH --work DIR [--wrapper CMD]
"""
import argparse
import csv
import json
import math
import os
import random
import shlex
import subprocess
import sys

import hidden_effects as he

DRAWS = 16
HELDOUT = 60


def run(cmd):
    p = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    if p.returncode != 0:
        sys.stderr.write(p.stdout + p.stderr)
        raise SystemExit("FAIL: %s exited %d" % (" ".join(cmd), p.returncode))
    return p.stdout


def write_csv(path, rows, n_joints):
    with open(path, "w", newline="") as f:
        w = csv.writer(f, lineterminator="\n")
        w.writerow(["q%d" % (j + 1) for j in range(n_joints)] + ["x", "y", "z"])
        for q_deg, p in rows:
            w.writerow(["%.9f" % v for v in q_deg] + ["%.6f" % v for v in p])


def read_plan(path, n_joints):
    with open(path) as f:
        lines = [l for l in f if not l.lstrip().startswith("#") and l.strip()]
    header = lines[0].strip().split(",")
    assert header == ["q%d" % (j + 1) for j in range(n_joints)], header
    return [[float(v) for v in l.split(",")] for l in lines[1:]]


# ---------------------------------------------------------------- the 6-DOF arm
# Paper Table 1 (as built) and Table 2 (nominal): alpha deg, a mm, d mm.
TABLE1 = [(91.2, 101.0, 201.0), (1.0, 104.0, 2.0), (1.8, 102.0, 100.1),
          (-92.1, -1.0, 12.0), (-0.8, 14.0, 110.0), (91.1, 3.0, 2.1)]
TABLE2 = [(90.0, 100.0, 200.0), (0.0, 100.0, 0.0), (0.0, 100.0, 100.0),
          (-90.0, 0.0, 10.0), (0.0, 10.0, 100.0), (90.0, 0.0, 0.0)]
RANGE6 = 170.0
TOOL6 = (0.0, 0.0, 80.0)


def fk6(table, theta_deg, tool, q_rad):
    t = he.identity()
    for i, (alpha, a, d) in enumerate(table):
        t = he.mat_mul(t, he.rot_z(q_rad[i] + math.radians(theta_deg[i])))
        t = he.mat_mul(t, he.trans(a, 0.0, d))
        t = he.mat_mul(t, he.rot_x(math.radians(alpha)))
    return he.apply(t, tool)


class Arm6(object):
    effect = "tool_offset,joint_scale:3"

    def __init__(self, draw):
        rng = random.Random("dhcal-plan-6dof|%d" % draw)
        self.theta = [2.0 + rng.gauss(0.0, 0.2) for _ in range(6)]  # the paper's 2 deg
        self.tool = [TOOL6[k] + rng.gauss(0.0, 0.5) for k in range(3)]
        self.s = 0.002 * rng.uniform(0.7, 1.3) * (1 if rng.random() < 0.5 else -1)
        self.noise = 0.02
        self.n_joints = 6

    def model(self):
        return {"name": "paper-6dof-plan",
                "joints": [{"alpha_deg": al, "a_mm": a, "d_mm": d, "theta_offset_deg": 0.0,
                            "min_deg": -RANGE6, "max_deg": RANGE6} for al, a, d in TABLE2],
                "tool_mm": list(TOOL6),
                "base": {"xyz_mm": [0, 0, 0], "rpy_deg": [0, 0, 0]},
                "gravity": [0, 0, -1]}

    def random_q(self, rng):
        return [rng.uniform(-RANGE6, RANGE6) for _ in range(6)]

    def measure(self, q_deg, rng):
        """The true tool point, with the tracker's noise when rng is given."""
        q = [math.radians(v) for v in q_deg]
        q[2] += self.s * q[2]
        p = fk6(TABLE1, self.theta, self.tool, q)
        return [v + (rng.gauss(0.0, self.noise) if rng else 0.0) for v in p]


class Arm3(object):
    effect = "joint_compliance:2"

    def __init__(self, draw):
        self.sc = he.Scenario(self.effect, 100 + draw)
        self.n_joints = 3

    def model(self):
        m = he.model_json("paper-3dof-plan")
        del m["measurer"]  # a tracker measures the tool: position rows
        return m

    def random_q(self, rng):
        return [rng.uniform(lo, hi) for lo, hi in he.RANGES_DEG]

    def measure(self, q_deg, rng):
        q = [math.radians(v) for v in q_deg]
        q_eff = he.effective_angles(self.effect, self.sc.effect, self.sc.arm, q, [1, 1, 1])
        p = he.tool_point(self.sc.arm, q_eff)
        return [v + (rng.gauss(0.0, he.NOISE_MM) if rng else 0.0) for v in p]


def heldout_rms(dhcal, work, arm, name, rows, held):
    data = os.path.join(work, name + ".csv")
    write_csv(data, rows, arm.n_joints)
    out = run(dhcal + ["fit", "--model", os.path.join(work, "model.json"), "--data", data,
                       "--effects", arm.effect, "--heldout", held, "--json"])
    return json.loads(out)["heldout_rms_mm"]


def compare(dhcal, work_root, arm_class, n):
    rms = {"planned": [], "random": [], "random2": []}
    predicted = {"planned": [], "floor": [], "random2": []}
    ok = True
    for draw in range(DRAWS):
        arm = arm_class(draw)
        work = os.path.join(work_root, "%s-%d" % (arm_class.__name__, draw))
        os.makedirs(work, exist_ok=True)
        with open(os.path.join(work, "model.json"), "w") as f:
            json.dump(arm.model(), f)
        rng = random.Random("dhcal-plan|%s|%d" % (arm_class.__name__, draw))
        held = os.path.join(work, "heldout.csv")
        held_q = [arm.random_q(rng) for _ in range(HELDOUT)]
        # the held-out rows are the true tool points: their RMS is the calibration's own
        # positioning error, not the tracker's noise
        write_csv(held, [(q, arm.measure(q, None)) for q in held_q], arm.n_joints)
        plan = os.path.join(work, "plan.csv")
        report = json.loads(run(dhcal + ["plan", "--model", os.path.join(work, "model.json"),
                                         "--poses", str(n), "--effects", arm.effect,
                                         "--candidates", str(20 * n),
                                         "--seed", str(draw + 1), "--out", plan, "--json"]))
        # what 2 N random poses predict (the first 2 N of the same kind of candidates)
        report2 = json.loads(run(dhcal + ["plan", "--model", os.path.join(work, "model.json"),
                                          "--poses", str(2 * n), "--effects", arm.effect,
                                          "--candidates", str(20 * n), "--seed", str(draw + 1),
                                          "--out", os.path.join(work, "plan2.csv"),
                                          "--json"]))
        predicted["planned"].append(report["variance"])
        predicted["floor"].append(report["variance_floor"])
        predicted["random2"].append(report2["variance_random"])
        sets = {"planned": read_plan(plan, arm.n_joints),
                "random": [arm.random_q(rng) for _ in range(n)],
                "random2": [arm.random_q(rng) for _ in range(2 * n)]}
        assert len(sets["planned"]) == n, len(sets["planned"])
        got = {}
        for name in ("planned", "random", "random2"):
            got[name] = heldout_rms(dhcal, work, arm, name,
                                    [(q, arm.measure(q, rng)) for q in sets[name]], held)
            rms[name].append(got[name])
        print("%s draw %d: held-out RMS %d planned %.4f mm, %d random %.4f mm, %d random "
              "%.4f mm; predicted variance planned %.3f, random %.3f"
              % (arm_class.__name__, draw, n, got["planned"], n, got["random"], 2 * n,
                 got["random2"], report["variance"], report["variance_random"]))
        if not report["variance_floor"] <= report["variance"] <= 1.1 * report["variance_floor"]:
            print("FAIL: the plan's variance %.4f is not within 10 %% above the floor %.4f"
                  % (report["variance"], report["variance_floor"]))
            ok = False
    mean = {k: sum(v) / DRAWS for k, v in rms.items()}
    pmean = {k: sum(v) / DRAWS for k, v in predicted.items()}
    ok = ok and mean["planned"] < mean["random"]
    if not report["variance_random"] > 1.3 * report["variance"]:
        print("FAIL: the plan predicts %.3f, the random plan %.3f: not 1.3x less"
              % (report["variance"], report["variance_random"]))
        ok = False
    print("%s: mean held-out RMS over %d draws: %d planned poses %.4f mm, %d random %.4f mm "
          "(%s), %d random %.4f mm (planned/2N-random %.2f)"
          % (arm_class.__name__, DRAWS, n, mean["planned"], n, mean["random"],
             "ok" if ok else "FAIL: the plan is no better", 2 * n, mean["random2"],
             mean["planned"] / mean["random2"]))
    print("%s: predicted variance, mean over the draws: %d planned poses %.3f; no plan of %d "
          "poses below %.3f; %d random poses %.3f: %s"
          % (arm_class.__name__, n, pmean["planned"], n, pmean["floor"], 2 * n,
             pmean["random2"],
             "%d poses could match %d random ones" % (n, 2 * n)
             if pmean["floor"] <= pmean["random2"] else
             "no selection of %d poses can match %d random ones on this arm" % (n, 2 * n)))
    return ok


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--dhcal", required=True)
    ap.add_argument("--work", required=True)
    ap.add_argument("--wrapper", default="")
    a = ap.parse_args()
    dhcal = shlex.split(a.wrapper) + [a.dhcal]
    os.makedirs(a.work, exist_ok=True)
    ok = compare(dhcal, a.work, Arm3, 15)
    ok = compare(dhcal, a.work, Arm6, 25) and ok
    print("OK" if ok else "FAILED")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
