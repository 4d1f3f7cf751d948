#!/usr/bin/env python3
"""Acceptance of calibration without a tracker (issue 28): touches of three planes of unknown
pose, and a gauge between pairs of poses, calibrate an arm whose drawing is off.

Two arms of our own (the paper's 3-DOF arm, and a 6-DOF arm with a tool 80 mm off the flange),
each with hidden errors drawn here in its link lengths, offsets and twists (a few tenths of a
millimetre and a few hundredths of a degree, the tolerances a drawing states) and never shown to
dhcal. With this test's own kinematics (standard DH, no lib code) the true arm:
  - touches a table, a wall and a slanted plate (60 touches each; joint 2 turned until the
    tool point meets the plane, 0.02 mm of noise along the normal);
  - measures a 300 mm gauge between 12 pairs of poses (joint 3 of the second pose turned until
    the two tool points are the gauge's length apart, 0.01 mm of noise).
`dhcal fit --json --out C.json` calibrates the drawing from those rows alone. The true error:
over 300 random poses inside the joint ranges, the RMS distance between the truth's tool point
and the model's after the best rigid motion of the model's points onto the truth's (touches and
lengths cannot see where the arm stands: that is the blind part, held at the drawing).
Passes when, per arm:
  - the true error falls at least 5x from the drawing to the calibration, and ends within 1.5x
    of the accuracy the report predicted (`predicted_accuracy_mm`);
  - the report names the blind directions (`unidentifiable[].blind`): the arm's height d1 and
    its turn theta1 about the base axis, and no other length with the gauge;
  - the prior is weighed against the noise leaving each plane out finds (docs/effects.md), and
    on planes that wave by 0.3 mm (structure no arm fits) against no less than that;
  - with the planes alone (no gauge) the common scale is blind too, and left to the prior (the
    drawing's tolerances spread it over every length): the arm ends no worse than the drawing
    and within 1.5x of the predicted accuracy, which counts the scale's tolerance.
Usage: test_touch_calibration.py --dhcal PATH [--work DIR] [--wrapper CMD]
The last line is "N passed, M failed".
"""
import argparse
import json
import math
import os
import random
import shlex
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))

PAPER3 = {
    "name": "paper-3dof touches",
    "joints": [
        {"alpha_deg": 90.0, "a_mm": 0.0, "d_mm": 433.0, "theta_offset_deg": 0.0,
         "min_deg": -170.0, "max_deg": 170.0},
        {"alpha_deg": 0.0, "a_mm": 400.0, "d_mm": 0.0, "theta_offset_deg": 0.0,
         "min_deg": -170.0, "max_deg": 170.0},
        {"alpha_deg": 0.0, "a_mm": 345.0, "d_mm": 0.0, "theta_offset_deg": 0.0,
         "min_deg": -170.0, "max_deg": 170.0},
    ],
    "tool_mm": [0.0, 0.0, 0.0],
}

ARM6 = {
    "name": "arm6 touches",
    "joints": [
        {"alpha_deg": 90.0, "a_mm": 150.0, "d_mm": 450.0, "theta_offset_deg": 0.0,
         "min_deg": -170.0, "max_deg": 170.0},
        {"alpha_deg": 0.0, "a_mm": 600.0, "d_mm": 0.0, "theta_offset_deg": 0.0,
         "min_deg": -150.0, "max_deg": 150.0},
        {"alpha_deg": 90.0, "a_mm": 120.0, "d_mm": 0.0, "theta_offset_deg": 0.0,
         "min_deg": -150.0, "max_deg": 150.0},
        {"alpha_deg": -90.0, "a_mm": 0.0, "d_mm": 550.0, "theta_offset_deg": 0.0,
         "min_deg": -170.0, "max_deg": 170.0},
        {"alpha_deg": 90.0, "a_mm": 0.0, "d_mm": 0.0, "theta_offset_deg": 0.0,
         "min_deg": -120.0, "max_deg": 120.0},
        {"alpha_deg": 0.0, "a_mm": 0.0, "d_mm": 100.0, "theta_offset_deg": 0.0,
         "min_deg": -170.0, "max_deg": 170.0},
    ],
    "tool_mm": [30.0, 0.0, 80.0],
}

TOUCHES_PER_PLANE = 60
PLANE_NOISE_MM = 0.02
GAUGE_MM = 300.0
GAUGE_PLACEMENTS = 12
GAUGE_NOISE_MM = 0.01
CHECK_POSES = 300


# ---------------------------------------------------------------- kinematics (standard DH)

def tool_point(model, q_deg):
    """The tool point: A_i = Rz(q + theta) Tz(d) Tx(a) Rx(alpha) Ry(beta) (docs/formats.md 1),
    then the tool offset."""
    r = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]
    p = [0.0, 0.0, 0.0]
    for joint, q in zip(model["joints"], q_deg):
        th = math.radians(q + joint["theta_offset_deg"])
        al = math.radians(joint["alpha_deg"])
        ct, st, ca, sa = math.cos(th), math.sin(th), math.cos(al), math.sin(al)
        a = [[ct, -st * ca, st * sa], [st, ct * ca, -ct * sa], [0.0, sa, ca]]
        be = math.radians(joint.get("beta_deg", 0.0))
        cb, sb = math.cos(be), math.sin(be)
        a = [[row[0] * cb - row[2] * sb, row[1], row[0] * sb + row[2] * cb] for row in a]
        t = [joint["a_mm"] * ct, joint["a_mm"] * st, joint["d_mm"]]
        p = [p[i] + sum(r[i][k] * t[k] for k in range(3)) for i in range(3)]
        r = [[sum(r[i][k] * a[k][j] for k in range(3)) for j in range(3)] for i in range(3)]
    tool = model["tool_mm"]
    return [p[i] + sum(r[i][k] * tool[k] for k in range(3)) for i in range(3)]


def random_q(model, rng, margin_deg=10.0):
    return [rng.uniform(j["min_deg"] + margin_deg, j["max_deg"] - margin_deg)
            for j in model["joints"]]


def in_range(model, q_deg):
    return all(j["min_deg"] < q < j["max_deg"] for j, q in zip(model["joints"], q_deg))


def solve_joint(model, q_deg, joint, f):
    """Turns joint `joint` until f(tool point) = 0 (secant steps); None when it does not."""
    q = list(q_deg)
    for _ in range(40):
        v = f(tool_point(model, q))
        if abs(v) < 1e-10:
            return q if in_range(model, q) else None
        q[joint] += 1e-5
        slope = (f(tool_point(model, q)) - v) / 1e-5
        q[joint] -= 1e-5
        if abs(slope) < 1e-3:
            return None
        q[joint] -= v / slope
    return None


def true_arm(nominal, rng):
    """The arm as built: each link length, offset and twist off the drawing (a length d only
    where the joint's axis is not parallel to the next one's: there the drawing's d is no
    parameter of the fit)."""
    truth = json.loads(json.dumps(nominal))
    for joint in truth["joints"]:
        joint["a_mm"] += rng.gauss(0.0, 0.3)
        if abs(joint["alpha_deg"]) > 1.0:
            joint["d_mm"] += rng.gauss(0.0, 0.3)
        joint["theta_offset_deg"] += rng.gauss(0.0, 0.03)
        joint["alpha_deg"] += rng.gauss(0.0, 0.03)
    truth["tool_mm"] = [v + rng.gauss(0.0, 0.3) for v in truth["tool_mm"]]
    return truth


# ---------------------------------------------------------------- the measurements

def plane_touches(truth, rng, wave_mm=0.0):
    """Rows (q, plane id) of the true arm touching three planes through points it reaches;
    with wave_mm, each surface waves that much about its plane (a period of 150 mm along one
    of its tangents): structure no arm model can fit."""
    mid = tool_point(truth, [0.5 * (j["min_deg"] + j["max_deg"]) + 20.0
                             for j in truth["joints"]])
    s = 1.0 / math.sqrt(0.09 + 0.25 + 0.64)
    normals = [[0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.3 * s, 0.5 * s, 0.8 * s]]
    rows = []
    for pid, n in enumerate(normals, start=1):
        h = sum(n[k] * mid[k] for k in range(3))
        t = [n[1], -n[0], 0.0] if abs(n[2]) < 0.9 else [1.0, 0.0, 0.0]
        tn = math.sqrt(sum(v * v for v in t))
        t = [v / tn for v in t]
        made = 0
        while made < TOUCHES_PER_PLANE:
            off = rng.gauss(0.0, PLANE_NOISE_MM)
            q = solve_joint(truth, random_q(truth, rng), 1,
                            lambda p: sum(n[k] * p[k] for k in range(3)) - h - off - wave_mm *
                            math.sin(2.0 * math.pi * sum(t[k] * p[k] for k in range(3)) / 150.0))
            if q is not None:
                rows.append((q, pid))
                made += 1
    return rows


def gauge_pairs(truth, rng):
    """Rows (q, pair id, distance) of a 300 mm gauge between pairs of the true arm's poses."""
    rows = []
    pid = 0
    while pid < GAUGE_PLACEMENTS:
        qa = random_q(truth, rng)
        pa = tool_point(truth, qa)
        length = GAUGE_MM + rng.gauss(0.0, GAUGE_NOISE_MM)
        qb = solve_joint(truth, random_q(truth, rng), 2,
                         lambda p: math.dist(p, pa) - length)
        if qb is None:
            continue
        pid += 1
        rows.append((qa, pid, GAUGE_MM))
        rows.append((qb, pid, None))
    return rows


def write_rows(path, n_joints, touches, lengths):
    with open(path, "w") as out:
        cols = [f"q{j + 1}" for j in range(n_joints)] + ["plane"]
        if lengths:
            cols += ["pair", "distance_mm"]
        out.write(",".join(cols) + "\n")
        for q, pid in touches:
            out.write(",".join(f"{v:.9f}" for v in q) + f",{pid}" + (",," if lengths else "")
                      + "\n")
        for q, pair, dist in lengths:
            out.write(",".join(f"{v:.9f}" for v in q) + f",,{pair},"
                      + (f"{dist:.6f}" if dist is not None else "") + "\n")


# ---------------------------------------------------------------- the true error

def best_rotation(a, b):
    """Horn's quaternion for the rotation taking the centred points a onto b (the largest
    eigenvector of his 4x4 matrix, by power iteration on it shifted to be positive)."""
    s = [[sum(x[i] * y[j] for x, y in zip(a, b)) for j in range(3)] for i in range(3)]
    n = [[s[0][0] + s[1][1] + s[2][2], s[1][2] - s[2][1], s[2][0] - s[0][2], s[0][1] - s[1][0]],
         [0.0, s[0][0] - s[1][1] - s[2][2], s[0][1] + s[1][0], s[2][0] + s[0][2]],
         [0.0, 0.0, -s[0][0] + s[1][1] - s[2][2], s[1][2] + s[2][1]],
         [0.0, 0.0, 0.0, -s[0][0] - s[1][1] + s[2][2]]]
    for i in range(4):
        for j in range(i):
            n[i][j] = n[j][i]
    shift = sum(abs(v) for row in n for v in row)
    for i in range(4):
        n[i][i] += shift
    v = [1.0, 0.1, 0.1, 0.1]
    for _ in range(2000):
        w = [sum(n[i][j] * v[j] for j in range(4)) for i in range(4)]
        norm = math.sqrt(sum(x * x for x in w))
        v = [x / norm for x in w]
    w, x, y, z = v
    return [[w * w + x * x - y * y - z * z, 2 * (x * y - w * z), 2 * (x * z + w * y)],
            [2 * (x * y + w * z), w * w - x * x + y * y - z * z, 2 * (y * z - w * x)],
            [2 * (x * z - w * y), 2 * (y * z + w * x), w * w - x * x - y * y + z * z]]


def registered_error_mm(truth, model, rng):
    """RMS distance of the model's tool points from the truth's over random poses in the
    ranges, after the best rigid motion of the former onto the latter."""
    qs = [random_q(truth, rng, 0.0) for _ in range(CHECK_POSES)]
    pt = [tool_point(truth, q) for q in qs]
    pm = [tool_point(model, q) for q in qs]
    ct = [sum(p[k] for p in pt) / len(pt) for k in range(3)]
    cm = [sum(p[k] for p in pm) / len(pm) for k in range(3)]
    a = [[p[k] - cm[k] for k in range(3)] for p in pm]
    b = [[p[k] - ct[k] for k in range(3)] for p in pt]
    r = best_rotation(a, b)
    total = 0.0
    for x, y in zip(a, b):
        rx = [sum(r[i][k] * x[k] for k in range(3)) for i in range(3)]
        total += sum((rx[i] - y[i]) ** 2 for i in range(3))
    return math.sqrt(total / len(a))


def calibrated(path):
    """A model file dhcal wrote, as this test's kinematics reads it."""
    with open(path) as f:
        m = json.load(f)
    for j in m["joints"]:
        j.setdefault("theta_offset_deg", 0.0)
    m.setdefault("tool_mm", [0.0, 0.0, 0.0])
    base = m.get("base", {})
    if any(abs(v) > 0.0 for v in base.get("xyz_mm", [0.0] * 3) + base.get("rpy_deg", [0.0] * 3)):
        raise SystemExit(f"{path}: a base pose this test does not read")
    return m


# ---------------------------------------------------------------- the cases

class Check:
    def __init__(self):
        self.passed = 0
        self.failed = 0

    def __call__(self, ok, what):
        print(("PASS: " if ok else "FAIL: ") + what)
        if ok:
            self.passed += 1
        else:
            self.failed += 1


def run_fit(args, model_path, data_path, out_path):
    cmd = shlex.split(args.wrapper) + [args.dhcal, "fit", "--model", model_path, "--data",
                                       data_path, "--json", "--out", out_path]
    p = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                       check=False)
    if p.returncode != 0:
        raise SystemExit(f"{' '.join(cmd)}: exit {p.returncode}: {p.stderr.strip()}")
    return json.loads(p.stdout)


def is_length(name):
    return name[0] in "ad" and name[1:].isdigit()


def blind_lengths(report):
    """The lengths the report calls blind and holds at the drawing."""
    return sorted(u["param"] for u in report["unidentifiable"]
                  if u.get("blind") and is_length(u["param"]))


def blind_fitted_lengths(report):
    """The lengths the report calls blind and fits with the prior alone holding them."""
    return sorted(p["name"] for p in report["parameters"]
                  if p.get("blind") and is_length(p["name"]))


def one_arm(args, check, label, nominal, seed):
    rng = random.Random(seed)
    truth = true_arm(nominal, rng)
    n = len(nominal["joints"])
    work = os.path.join(args.work, label)
    os.makedirs(work, exist_ok=True)
    model_path = os.path.join(work, "nominal.json")
    with open(model_path, "w") as f:
        json.dump(nominal, f, indent=1)
    touches = plane_touches(truth, rng)
    lengths = gauge_pairs(truth, rng)
    both = os.path.join(work, "touches-and-gauge.csv")
    planes = os.path.join(work, "touches.csv")
    write_rows(both, n, touches, lengths)
    write_rows(planes, n, touches, [])

    report = run_fit(args, model_path, both, os.path.join(work, "calibrated.json"))
    # the noise scale leaving planes out chose: at least their scatter, and within the grid's
    # step (sqrt 10) of the touches' 0.02 mm noise, far below the drawing's scatter
    prior = report["prior"]
    check(prior.get("cv_rms_mm", 0.0) > 0.0 and
          prior["cv_rms_mm"] <= prior["scale_mm"] <= 5.0 * PLANE_NOISE_MM,
          f"{label}: the prior weighed against the noise leaving planes out finds ({prior})")
    model = calibrated(os.path.join(work, "calibrated.json"))
    before = registered_error_mm(truth, nominal, random.Random(seed + 1))
    after = registered_error_mm(truth, model, random.Random(seed + 1))
    predicted = report["predicted_accuracy_mm"]
    print(f"{label}: true error over the ranges {before:.4f} mm with the drawing -> "
          f"{after:.4f} mm calibrated ({before / after:.1f}x); predicted {predicted:.4f} mm; "
          f"RMS of the rows {report['rms_mm']:.4f} mm")
    check(after <= before / 5.0, f"{label}: the true error falls at least 5x "
                                 f"({before:.4f} -> {after:.4f} mm)")
    check(after <= 1.5 * predicted, f"{label}: it ends within 1.5x of the predicted accuracy "
                                    f"({after:.4f} <= 1.5 x {predicted:.4f} mm)")
    blind = {u["param"] for u in report["unidentifiable"] if u.get("blind")}
    check({"d1", "theta1"} <= blind and blind_lengths(report) == ["d1"],
          f"{label}: blind with the gauge: {sorted(blind)} (d1 and theta1, no other length)")

    alone = run_fit(args, model_path, planes, os.path.join(work, "planes-only.json"))
    held = blind_lengths(alone)
    scale = blind_fitted_lengths(alone)
    check(held == ["d1"] and len(scale) == 1,
          f"{label}: planes alone leave a common scale blind, held near the drawing by the "
          f"prior: blind lengths held {held}, left to the prior {scale}")
    after_alone = registered_error_mm(truth, calibrated(os.path.join(work, "planes-only.json")),
                                      random.Random(seed + 1))
    predicted_alone = alone["predicted_accuracy_mm"]
    print(f"{label}, planes alone: {before:.4f} -> {after_alone:.4f} mm; predicted "
          f"{predicted_alone:.4f} mm (the blind scale's tolerance included)")
    check(after_alone < before and after_alone <= 1.5 * predicted_alone,
          f"{label}: planes alone leave the arm no worse than the drawing and within 1.5x of "
          f"the accuracy predicted with the scale's tolerance ({after_alone:.4f} < {before:.4f},"
          f" <= 1.5 x {predicted_alone:.4f} mm)")


def bent_planes(args, check):
    """Planes that wave by 0.3 mm (structure, not noise, 0.21 mm RMS): the prior is weighed
    against no less than that (the discrepancy test), and the arm ends no worse than drawn."""
    rng = random.Random(2803)
    truth = true_arm(PAPER3, rng)
    work = os.path.join(args.work, "bent")
    os.makedirs(work, exist_ok=True)
    model_path = os.path.join(work, "nominal.json")
    with open(model_path, "w") as f:
        json.dump(PAPER3, f, indent=1)
    data = os.path.join(work, "touches.csv")
    write_rows(data, 3, plane_touches(truth, rng, wave_mm=0.3), gauge_pairs(truth, rng))
    report = run_fit(args, model_path, data, os.path.join(work, "calibrated.json"))
    before = registered_error_mm(truth, PAPER3, random.Random(2804))
    after = registered_error_mm(truth, calibrated(os.path.join(work, "calibrated.json")),
                                random.Random(2804))
    print(f"bent planes: prior {report['prior']}; {before:.4f} -> {after:.4f} mm")
    check(report["prior"]["scale_mm"] >= 0.3 / math.sqrt(2.0),
          "bent planes: the prior weighed against no less than the waves' 0.21 mm RMS "
          f"({report['prior']['scale_mm']:.3f} mm)")
    check(after < before, f"bent planes: no worse than the drawing ({before:.4f} -> {after:.4f})")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--dhcal", required=True)
    ap.add_argument("--work", default=None)
    ap.add_argument("--wrapper", default="")
    args = ap.parse_args()
    scratch = None
    if args.work is None:
        scratch = tempfile.TemporaryDirectory(prefix="dhcal-touch-")
        args.work = scratch.name
    check = Check()
    one_arm(args, check, "paper3", PAPER3, 2801)
    one_arm(args, check, "arm6", ARM6, 2802)
    bent_planes(args, check)
    print(f"{check.passed} passed, {check.failed} failed")
    return 0 if check.failed == 0 else 1


if __name__ == "__main__":
    sys.exit(main())
