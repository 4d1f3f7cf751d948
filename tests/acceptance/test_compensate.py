#!/usr/bin/env python3
"""Acceptance of `dhcal compensate` (issue 16): a calibration deployed as joint commands
makes the TRUE arm land on its targets.

Two arms of our own, each a host_sim scenario written here (the true arm: nominal geometry
plus errors and hidden effects, never shown to dhcal):
  paper3  the paper's 3-DOF arm; joint 1's belt stage is 0.25 % off (joint_scale:1) and
          joint 2's gearbox is compliant under the links' weight (joint_compliance:2).
  arm6    a 6-DOF arm reaching 1.3 m, a tool 120 mm off the flange (and 1-2 mm off its
          drawing), a compliant shoulder (joint 2) under 20 kg of links.
Per arm:
  1. `dhcal-sim dataset` measures the true arm at random poses (x,y,z + 0.05 mm noise);
     `dhcal refine` calibrates the nominal model from them (--out C.json);
  2. 30 targets: the true arm's tool point (`dhcal-sim dataset --exact`, no noise) at random
     angles inside the ranges;
  3. today's commands: the nominal model's inverse kinematics of each target, started from
     the random angles moved by a few degrees (what a nominal controller commands);
  4. `dhcal compensate --model C.json --targets T.csv --nominal N.json` from today's commands;
  5. the true arm at today's commands and at the compensated ones (`--exact` again): the
     distance of its tool point from the target, before and after.
Passes when the true RMS error falls at least 10x and ends at or below the measurement noise
floor sqrt(3) x 0.05 mm (the RMS length of the noise vector), and when the nominal target
xn,yn,zn makes the nominal model's own IK give the compensated angles. arm6 again with pose
targets (the orientation today's commands give on the nominal model, from our own FK): all
reached, the true point at the floor, qwn..qzn the nominal orientation at the angles. Both
calibrations are from positions only: the orientation is met on the model as fitted.
Then bad input: NaN in a target and a missing column exit 2 naming file and line and leave
no output; a target out of reach exits 1 with every row written.

Usage: test_compensate.py --dhcal PATH --dhcal-sim PATH [--work DIR] [--wrapper CMD]
The last line is "N passed, M failed".
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
import tempfile

sys.dont_write_bytecode = True
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from checks import Checks  # noqa: E402

NOISE_MM = 0.05
FLOOR_MM = math.sqrt(3.0) * NOISE_MM
N_TARGETS = 30

DRIVE = {
    "motor": {"r_ohm": 1.5, "l_h": 0.002, "ke_v_s_per_rad": 0.1, "kt_nm_per_a": 0.1,
              "jm_kgm2": 0.0001, "bm_nms_per_rad": 0.0001, "coulomb_nm": 0.02, "brake_nm": 1.0},
    "amplifier": {"gain_v_per_v": 3.6, "supply_v": 36, "current_limit_a": 6},
    "gear": {"ratio": 100},
    # 5000 lines x4 x 100: 3 urad per count, so that the counts do not hide the effects
    "encoder": {"lines": 5000},
}

ARMS = {
    "paper3": {
        "model": {
            "name": "paper3-compensate",
            "joints": [
                {"alpha_deg": 90, "a_mm": 0, "d_mm": 433, "min_deg": -170, "max_deg": 170},
                {"alpha_deg": 0, "a_mm": 400, "d_mm": 0, "min_deg": -10, "max_deg": 170},
                {"alpha_deg": 0, "a_mm": 345, "d_mm": 0, "min_deg": -150, "max_deg": 150}],
            "tool_mm": [0, 0, 0], "gravity": [0, 0, -1]},
        "scenario": {
            "seed": 161,
            "truth": {"joints": [
                {"theta_offset_deg": 0.25, "d_mm": 0.6, "a_mm": 0.4, "alpha_deg": 0.15},
                {"theta_offset_deg": -0.2, "a_mm": -0.5, "alpha_deg": -0.1, "beta_deg": 0.05},
                {"theta_offset_deg": 0.15, "d_mm": -0.4, "a_mm": 0.3, "alpha_deg": 0.12}]},
            "joints": [
                {"link": {"mass_kg": 5.0, "com_mm": [0, -216, 0]},
                 "gear": {"ratio": 100.25}, "controller": {"gear_ratio": 100}},
                {"link": {"mass_kg": 3.8, "com_mm": [-160, 0, 0]},
                 "gear": {"stiffness_nm_per_rad": 12000}},
                {"link": {"mass_kg": 1.5, "com_mm": [-172.5, 0, 0]}}],
            "payload": {"mass_kg": 0.5}},
        "train_poses": 80,
        "margin_deg": [10, 10, 15],
    },
    "arm6": {
        "model": {
            "name": "arm6-compensate",
            "joints": [
                {"alpha_deg": 90, "a_mm": 150, "d_mm": 400, "min_deg": -170, "max_deg": 170},
                {"alpha_deg": 0, "a_mm": 600, "d_mm": 0, "min_deg": -20, "max_deg": 160},
                {"alpha_deg": 90, "a_mm": 100, "d_mm": 0, "min_deg": -150, "max_deg": 150},
                {"alpha_deg": -90, "a_mm": 0, "d_mm": 550, "min_deg": -170, "max_deg": 170},
                {"alpha_deg": 90, "a_mm": 0, "d_mm": 0, "min_deg": -120, "max_deg": 120},
                {"alpha_deg": 0, "a_mm": 0, "d_mm": 100, "min_deg": -170, "max_deg": 170}],
            "tool_mm": [30, 0, 120], "gravity": [0, 0, -1]},
        "scenario": {
            "seed": 162,
            "truth": {"random_sd": {"theta_offset_deg": 0.15, "d_mm": 0.5, "a_mm": 0.5,
                                    "alpha_deg": 0.1, "beta_deg": 0.05},
                      "tool_mm": [1.5, -1.0, 2.0]},
            "joints": [
                {"link": {"mass_kg": 15.0, "com_mm": [0, -200, 0]}},
                {"link": {"mass_kg": 10.0, "com_mm": [-300, 0, 0]},
                 "gear": {"stiffness_nm_per_rad": 40000}},
                {"link": {"mass_kg": 5.0, "com_mm": [-50, 0, 0]}},
                {"link": {"mass_kg": 3.0, "com_mm": [0, 200, 0]}},
                {"link": {"mass_kg": 1.0, "com_mm": [0, 0, 0]}},
                {"link": {"mass_kg": 0.5, "com_mm": [0, 0, -30]}}],
            "payload": {"mass_kg": 1.0}},
        "train_poses": 150,
        "margin_deg": [10, 10, 15, 10, 15, 10],
    },
}


def run(wrapper, args, expect=(0,)):
    cmd = shlex.split(wrapper) + [str(a) for a in args]
    res = subprocess.run(cmd, capture_output=True, text=True, timeout=600)
    if res.returncode not in expect:
        raise RuntimeError("%s: exit %d\n%s%s" % (" ".join(cmd), res.returncode, res.stdout,
                                                   res.stderr))
    return res


def read_rows(path):
    with open(path) as f:
        return list(csv.DictReader(line for line in f if not line.startswith("#")))


def write_plan(path, qs):
    n = len(qs[0])
    with open(path, "w") as f:
        f.write(",".join("q%d" % (j + 1) for j in range(n)) + ","
                + ",".join("dir%d" % (j + 1) for j in range(n)) + "\n")
        for q in qs:
            f.write(",".join("%.9f" % v for v in q) + "," + ",".join("1" for _ in q) + "\n")


def write_targets(path, points, qs):
    n = len(qs[0])
    with open(path, "w") as f:
        f.write("x,y,z," + ",".join("q%d" % (j + 1) for j in range(n)) + "\n")
        for p, q in zip(points, qs):
            f.write(",".join("%.6f" % v for v in p) + "," + ",".join("%.9f" % v for v in q)
                    + "\n")


def angles(rows, n):
    return [[float(r["q%d" % (j + 1)]) for j in range(n)] for r in rows]


class Arm:
    """One arm's files and programs."""

    def __init__(self, name, spec, work, dhcal, sim, wrapper):
        self.name, self.spec, self.dir = name, spec, os.path.join(work, name)
        self.dhcal, self.sim, self.wrapper = dhcal, sim, wrapper
        os.makedirs(self.dir, exist_ok=True)
        self.model = self.path("nominal.json")
        self.n = len(spec["model"]["joints"])
        with open(self.model, "w") as f:
            json.dump(spec["model"], f, indent=1)
        sc = dict(spec["scenario"])
        sc.update({"name": name, "model": "nominal.json", "joint_defaults": DRIVE,
                   "noise": {"xyz_mm": NOISE_MM}})
        self.scenario = self.path("scenario.json")
        with open(self.scenario, "w") as f:
            json.dump(sc, f, indent=1)

    def path(self, name):
        return os.path.join(self.dir, name)

    def true_points(self, qs, name):
        """The TRUE arm's tool point at commanded angles qs (deg): ideal servo, no noise."""
        write_plan(self.path(name + "-plan.csv"), qs)
        run(self.wrapper, [self.sim, "dataset", "--scenario", self.scenario, "--plan",
                           self.path(name + "-plan.csv"), "--exact", "--out",
                           self.path(name + "-true.csv")])
        return [[float(r[k]) for k in "xyz"] for r in read_rows(self.path(name + "-true.csv"))]

    def compensate(self, model, targets, out, extra=(), expect=(0,)):
        return run(self.wrapper, [self.dhcal, "compensate", "--model", model, "--targets",
                                  targets, "--out", out, "--json"] + list(extra), expect)


def nominal_pose(model, q_deg):
    """Standard DH forward kinematics of a nominal model file (no offsets, no beta, base at
    the world origin): the tool point and the last link's rotation, written here from
    docs/formats.md, not from the library."""
    rot = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]
    pos = [0.0, 0.0, 0.0]
    for jt, q in zip(model["joints"], q_deg):
        th, al = math.radians(q + jt.get("theta_offset_deg", 0.0)), math.radians(jt["alpha_deg"])
        ct, st, ca, sa = math.cos(th), math.sin(th), math.cos(al), math.sin(al)
        a = [[ct, -st * ca, st * sa], [st, ct * ca, -ct * sa], [0.0, sa, ca]]
        p = [jt["a_mm"] * ct, jt["a_mm"] * st, jt["d_mm"]]
        pos = [pos[r] + sum(rot[r][k] * p[k] for k in range(3)) for r in range(3)]
        rot = [[sum(rot[r][k] * a[k][c] for k in range(3)) for c in range(3)] for r in range(3)]
    tool = model["tool_mm"]
    return ([pos[r] + sum(rot[r][k] * tool[k] for k in range(3)) for r in range(3)], rot)


def quaternion(rot):
    """Unit quaternion (w, x, y, z), w >= 0, of a rotation matrix (trace or largest axis)."""
    t = rot[0][0] + rot[1][1] + rot[2][2]
    if t > 0.0:
        w = math.sqrt(1.0 + t) / 2.0
        q = [w, (rot[2][1] - rot[1][2]) / (4 * w), (rot[0][2] - rot[2][0]) / (4 * w),
             (rot[1][0] - rot[0][1]) / (4 * w)]
    else:
        i = max(range(3), key=lambda k: rot[k][k])
        j, k = (i + 1) % 3, (i + 2) % 3
        v = math.sqrt(1.0 + rot[i][i] - rot[j][j] - rot[k][k]) / 2.0
        q = [0.0] * 4
        q[1 + i], q[0] = v, (rot[k][j] - rot[j][k]) / (4 * v)
        q[1 + j], q[1 + k] = (rot[j][i] + rot[i][j]) / (4 * v), (rot[k][i] + rot[i][k]) / (4 * v)
    return q if q[0] >= 0.0 else [-v for v in q]


def distance(a, b):
    return math.sqrt(sum((x - y) ** 2 for x, y in zip(a, b)))


def rms(values):
    return math.sqrt(sum(v * v for v in values) / len(values))


def check_arm(arm, checks, rng):
    n = arm.n
    # 1. calibration on noisy measurements of the true arm
    run(arm.wrapper, [arm.sim, "dataset", "--scenario", arm.scenario, "--poses",
                      arm.spec["train_poses"], "--seed", 1, "--out", arm.path("train.csv")])
    cal = arm.path("calibrated.json")
    res = run(arm.wrapper, [arm.dhcal, "refine", "--model", arm.model, "--data",
                            arm.path("train.csv"), "--out", cal, "--json"])
    ref = json.loads(res.stdout)
    print("%s: refine chose %s, rms %.4f mm, cv %.4f mm" % (
        arm.name, ",".join(ref["effects"]) or "(base model)", ref["rms_mm"], ref["cv_rms_mm"]))
    # 2. targets the true arm reaches: its tool point at random angles inside the ranges
    joints = arm.spec["model"]["joints"]
    drawn = N_TARGETS + 10
    q_true = [[rng.uniform(jt["min_deg"] + m, jt["max_deg"] - m)
               for jt, m in zip(joints, arm.spec["margin_deg"])] for _ in range(drawn)]
    targets = arm.true_points(q_true, "targets")
    # 3. today's commands: the nominal model's IK, from the true angles a few degrees off.
    # A target at the edge of the nominal workspace (the arm stretched) or beyond a range
    # there, the nominal controller cannot command at all: those are not compared.
    start = [[q + rng.uniform(-3.0, 3.0) for q in qs] for qs in q_true]
    write_targets(arm.path("nominal-ik-in.csv"), targets, start)
    arm.compensate(arm.model, arm.path("nominal-ik-in.csv"), arm.path("nominal-ik.csv"),
                   expect=(0, 1))
    ik_rows = read_rows(arm.path("nominal-ik.csv"))
    keep = [k for k, r in enumerate(ik_rows) if float(r["error_mm"]) <= 1e-6][:N_TARGETS]
    checks.check("%s: the nominal IK commands %d targets" % (arm.name, N_TARGETS),
                 len(keep) == N_TARGETS, "%d of %d drawn reached" % (
                     sum(float(r["error_mm"]) <= 1e-6 for r in ik_rows), drawn))
    targets = [targets[k] for k in keep]
    q_today = [angles(ik_rows, n)[k] for k in keep]
    # 4. compensation from today's commands
    write_targets(arm.path("T.csv"), targets, q_today)
    res = arm.compensate(cal, arm.path("T.csv"), arm.path("J.csv"),
                         ["--nominal", arm.model])
    summary = json.loads(res.stdout)
    out_rows = read_rows(arm.path("J.csv"))
    q_comp = angles(out_rows, n)
    checks.check("%s: every target reached on the calibrated model" % arm.name,
                 summary["reached"] == N_TARGETS and summary["max_error_mm"] <= 1e-6,
                 "%d of %d, max error_mm %.2g" % (summary["reached"], N_TARGETS,
                                                   summary["max_error_mm"]))
    # 5. the true arm at both sets of commands
    before = [distance(p, t) for p, t in zip(arm.true_points(q_today, "before"), targets)]
    after = [distance(p, t) for p, t in zip(arm.true_points(q_comp, "after"), targets)]
    print("%s: true positioning error over %d targets, mm: nominal IK rms %.4f max %.4f; "
          "compensated rms %.4f max %.4f; noise floor %.4f (sqrt(3) x %.2f); factor %.1f" % (
              arm.name, N_TARGETS, rms(before), max(before), rms(after), max(after), FLOOR_MM,
              NOISE_MM, rms(before) / rms(after)))
    checks.check("%s: true error falls at least 10x" % arm.name, rms(after) * 10.0 <= rms(before),
                 "%.4f -> %.4f mm" % (rms(before), rms(after)))
    checks.check("%s: true error at or below the noise floor" % arm.name, rms(after) <= FLOOR_MM,
                 "rms %.4f <= %.4f mm" % (rms(after), FLOOR_MM))
    # the nominal target: the nominal controller's own IK of xn,yn,zn gives the compensated q
    nominal_points = [[float(r[k]) for k in ("xn", "yn", "zn")] for r in out_rows]
    write_targets(arm.path("nominal-check-in.csv"), nominal_points, q_today)
    arm.compensate(arm.model, arm.path("nominal-check-in.csv"), arm.path("nominal-check.csv"))
    q_back = angles(read_rows(arm.path("nominal-check.csv")), n)
    if n == 3:  # a point fixes 3 joints: the same angles to the file's 1 nm rounding
        worst = max(abs(a - b) for qa, qb in zip(q_back, q_comp) for a, b in zip(qa, qb))
        checks.check("%s: the nominal IK of xn,yn,zn is the compensated command" % arm.name,
                     worst <= 1e-5, "max difference %.2g deg" % worst)
    else:  # redundant for a point: the same tool point on the true arm
        back = [distance(p, t) for p, t in zip(arm.true_points(q_back, "via-nominal"), targets)]
        checks.check("%s: commanding xn,yn,zn through the nominal IK reaches the targets" %
                     arm.name, rms(back) <= FLOOR_MM, "true rms %.4f mm" % rms(back))


def check_pose_targets(arm, checks):
    """6 joints: targets with an orientation, the one today's commands give on the nominal
    model (what a controller keeps when it only corrects the position). The calibrated
    model meets both; the true arm's point is judged. The data were positions only, so the
    calibration leaves the last link's turn about the tool point at nominal: the orientation
    is met on the model as fitted, which the simulator cannot measure."""
    rows = read_rows(arm.path("T.csv"))
    q_today = angles(rows, arm.n)
    targets = [[float(r[k]) for k in "xyz"] for r in rows]
    with open(arm.path("T-pose.csv"), "w") as f:
        f.write("x,y,z,qw,qx,qy,qz," + ",".join("q%d" % (j + 1) for j in range(arm.n)) + "\n")
        for p, q in zip(targets, q_today):
            quat = quaternion(nominal_pose(arm.spec["model"], q)[1])
            f.write(",".join("%.6f" % v for v in p) + "," + ",".join("%.12f" % v for v in quat)
                    + "," + ",".join("%.9f" % v for v in q) + "\n")
    res = arm.compensate(arm.path("calibrated.json"), arm.path("T-pose.csv"),
                         arm.path("J-pose.csv"), ["--nominal", arm.model])
    summary = json.loads(res.stdout)
    out = read_rows(arm.path("J-pose.csv"))
    q_comp = angles(out, arm.n)
    after = [distance(p, t) for p, t in zip(arm.true_points(q_comp, "after-pose"), targets)]
    print("%s, pose targets: reached %d of %d, true rms %.4f mm max %.4f mm" % (
        arm.name, summary["reached"], len(rows), rms(after), max(after)))
    checks.check("%s: pose targets reached on the calibrated model, true error at the floor" %
                 arm.name, summary["reached"] == len(rows) and summary["orientation"] == "targets"
                 and rms(after) <= FLOOR_MM, "rms %.4f mm" % rms(after))
    # qwn..qzn: the nominal model's orientation at the written angles (our own FK)
    worst = 0.0
    for r, q in zip(out, q_comp):
        pos, rot = nominal_pose(arm.spec["model"], q)
        want = quaternion(rot)
        got = [float(r[k]) for k in ("qwn", "qxn", "qyn", "qzn")]
        worst = max(worst, distance(pos, [float(r[k]) for k in ("xn", "yn", "zn")]) / 1000.0,
                    min(distance(want, got), distance(want, [-v for v in got])))
    checks.check("%s: xn..qzn are the nominal model's pose at the written angles" % arm.name,
                 worst <= 1e-8, "worst %.2g (quaternion units; mm / 1000)" % worst)


def check_bad_input(arm, checks):
    out = arm.path("bad-out.csv")
    if os.path.exists(out):
        os.remove(out)
    cases = [("nan", "x,y,z,q1,q2,q3\n500,0,600,0,40,-30\n500,nan,600,0,40,-30\n", ":3:"),
             ("missing column", "x,y,q1,q2,q3\n500,0,0,40,-30\n", ":1:")]
    for name, text, where in cases:
        path = arm.path("bad-%s.csv" % name.replace(" ", "-"))
        with open(path, "w") as f:
            f.write(text)
        res = arm.compensate(arm.model, path, out, expect=(0, 1, 2))
        checks.check("bad input (%s): exit 2, file and line named, nothing written" % name,
                     res.returncode == 2 and os.path.basename(path) + where in res.stderr
                     and not os.path.exists(out), res.stderr.strip().splitlines()[0])
    path = arm.path("unreachable.csv")
    with open(path, "w") as f:
        f.write("x,y,z,q1,q2,q3\n500,100,600,10,40,-30\n3000,0,400,5,45,-10\n"
                "400,-200,300,-20,20,-60\n")
    res = arm.compensate(arm.model, path, out, expect=(0, 1, 2))
    rows = read_rows(out) if os.path.exists(out) else []
    summary = json.loads(res.stdout) if res.stdout.strip() else {}
    ok = (res.returncode == 1 and len(rows) == 3 and summary.get("out_of_reach") == 1
          and [float(rows[1]["q%d" % j]) for j in (1, 2, 3)] == [5.0, 45.0, -10.0]
          and float(rows[1]["error_mm"]) > 1000.0
          and float(rows[0]["error_mm"]) <= 1e-6 and float(rows[2]["error_mm"]) <= 1e-6)
    checks.check("a target out of reach: exit 1, every row written, its input angles kept",
                 ok, "exit %d, %d rows, %s" % (res.returncode, len(rows),
                                                res.stderr.strip().splitlines()[0]
                                                if res.stderr.strip() else ""))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--dhcal", required=True)
    ap.add_argument("--dhcal-sim", required=True)
    ap.add_argument("--work")
    ap.add_argument("--wrapper", default="")
    ap.add_argument("--arms", default="paper3,arm6")
    a = ap.parse_args()
    work = a.work or tempfile.mkdtemp(prefix="dhcal-compensate-")
    os.makedirs(work, exist_ok=True)
    checks = Checks()
    rng = random.Random(16)
    arms = {}
    for name in a.arms.split(","):
        arms[name] = Arm(name, ARMS[name], work, a.dhcal, a.dhcal_sim, a.wrapper)
        check_arm(arms[name], checks, rng)
        if arms[name].n >= 6:
            check_pose_targets(arms[name], checks)
    check_bad_input(Arm("paper3-bad", ARMS["paper3"], work, a.dhcal, a.dhcal_sim, a.wrapper),
                    checks)
    print("%d passed, %d failed" % (checks.passed, checks.failed))
    return 1 if checks.failed else 0


if __name__ == "__main__":
    sys.exit(main())
