#!/usr/bin/env python3
"""Acceptance data with one hidden effect: the paper's 3-DOF arm (Table 3).

Pure Python (stdlib only) and independent of the C library: its own forward kinematics,
gravity moments and wire geometry, written from docs/effects.md, sections 1 and 3.

Arm, joint i (1-based):  A_i = Rz(q_i + theta_i) Tz(d_i) Tx(a_i) Rx(alpha_i) Ry(beta_i)
  nominal alpha = (90, 0, 0) deg, a = (0, 400, 345) mm, d = (433, 0, 0) mm, theta = beta = 0;
  base = identity, tool point (0, 0, 0) in the last frame, gravity (0, 0, -1) in the world.
True arm = nominal + random geometric errors (Gaussian, standard deviations ERR_SD):
  theta_i 0.2 deg, a_i 0.5 mm, d_1 and d_3 0.5 mm, alpha_i 0.2 deg, Hayati beta_2 0.05 deg
  (axes 2-3 nominally parallel: beta_2 replaces d_2, which stays exactly 0).

Hidden effects (q in rad; the library's definitions, docs/effects.md, section 1):
  joint_scale:i       q_eff_i = q_i + s q_i
  joint_harmonic:i    q_eff_i = q_i + A sin q_i + B cos q_i
  joint_backlash:i    q_eff_i = q_i + (b/2) dir_i          (dir_i = +-1, random per pose)
  joint_compliance:i  q_eff_i = q_i + sum_{j>=i} c_ij tau_ij(q),
                      tau_ij = z_{i-1} . ((o_j - o_{i-1}) x g)  [mm, unit weight],
                      frames of the TRUE arm at the MEASURED angles q
  joint_harmonic2:i   q_eff_i = q_i + A sin 2q_i + B cos 2q_i  (two per turn)
  drift_offset        the measured point moves by v (t - t0) over the session: t from the
                      CSV column t_s (~30 s a pose, jittered), t0 the training rows' mean
  drift_scale         the measured point's offset from the base grows by k (t - t0):
                      no t_s column, t = the 0-based row number
                      (held-out rows are another session: no drift there)
  measurer_scale      CSV has raw wire lengths L_k = (1 + s) |p - P_k| + noise
  clean               no effect

Measurer (paper): anchors in its own frame P1 = (0,0,1200), P2 = (0,600,300),
P3 = (0,-600,300) mm; frame in the world at xyz (1300,0,0) mm, rpy (0,0,180) deg,
R = Rz(yaw) Ry(pitch) Rx(roll). Its anchor plane is world x = 1300, facing -x.

Joint ranges (model file and pose sampling), deg:
  q1 [-170, 170]  nearly a full turn: a long ramp for joint_scale:1, and sin/cos of q1 go
                  through most of a period, so joint_scale:1, joint_harmonic:1 and the
                  joint-1 offset are well separated.
  q2 [-10, 170]   upper arm above the shoulder plane; the forearm can never reach z < 0.
  q3 [-150, 150]  forearm folds both ways, short of hitting the upper arm.
"In front of the measurer": the measurer's anchor plane is world x = 1300 mm facing -x;
the arm's reach (at most ~746 mm from the base axis) keeps every tool point at least
~550 mm in front of it, so any joint ranges satisfy it. (Wire/robot interference is not
simulated.) Poses are uniform in these ranges; a pose is rejected when its tool point is
within 150 mm of the anchor plane (never triggers here, kept as a guard) or of the base
(joint 1) axis (the shoulder singularity, where joint 1 is unobservable).
Trilateration turns the 0.05 mm wire noise into ~1.7x larger position noise over this
work space (position_dilution()), so the noise floor sqrt(3) x 0.05 mm applies to
residuals in wire-length space for measurer_scale.

Noise: Gaussian, 0.05 mm per coordinate (x, y, z) or per wire length.

CLI:
  hidden_effects.py --list
  hidden_effects.py --case joint_compliance:2 --seed 7 --out DIR
writes DIR/model.json (nominal model), DIR/train.csv (60 poses), DIR/heldout.csv (40 poses)
and DIR/truth.json (hidden effect, its values, the true geometry, effect size).
"""

import argparse
import csv
import json
import math
import os
import random
import sys

# ---------------------------------------------------------------------------------------
# Constants of the scenario
# ---------------------------------------------------------------------------------------
N_JOINTS = 3
NOMINAL = {
    "alpha_deg": [90.0, 0.0, 0.0],
    "a_mm": [0.0, 400.0, 345.0],
    "d_mm": [433.0, 0.0, 0.0],
    "theta_deg": [0.0, 0.0, 0.0],
    "beta_deg": [0.0, 0.0, 0.0],
}
RANGES_DEG = [(-170.0, 170.0), (-10.0, 170.0), (-150.0, 150.0)]
GRAVITY = (0.0, 0.0, -1.0)
TOOL_MM = (0.0, 0.0, 0.0)
ANCHORS_MEAS = [(0.0, 0.0, 1200.0), (0.0, 600.0, 300.0), (0.0, -600.0, 300.0)]
MEAS_XYZ = (1300.0, 0.0, 0.0)
MEAS_RPY_DEG = (0.0, 0.0, 180.0)

NOISE_MM = 0.05
N_TRAIN = 60
N_HELDOUT = 40
MIN_CLEARANCE_MM = 150.0
Q_DECIMALS = 6  # measured angles are rounded to 1e-6 deg before use (what the CSV holds)

# Geometric errors of the true arm: standard deviations.
ERR_SD = {"theta_deg": 0.2, "a_mm": 0.5, "d_mm": 0.5, "alpha_deg": 0.2, "beta2_deg": 0.05}

# Effect magnitudes: nominal size x uniform(0.7, 1.3) (never near zero, so every case is
# observable), random sign where the sign is not physical.
EFFECT_SIZE = {
    "joint_scale": 2e-3,        # 1
    "joint_harmonic": 1e-3,     # rad, A and B each
    "joint_backlash": 0.3,      # deg, full play b (> 0)
    # rad/mm (> 0: the joint yields to the gravity moment). Chosen for 0.5-1.5 mm at the
    # tool (docs/effects.md, section 3): joint 2 sees up to ~745 mm of moment arm, joint 3
    # only ~345 mm.
    "joint_compliance:2": {"c22": 1.2e-6, "c23": 1.8e-6},
    "joint_compliance:3": {"c33": 1.0e-5},
    "measurer_scale": 1e-3,     # 1
    "joint_harmonic2": 1e-3,    # rad, A and B each
    "drift_offset": 3e-4,       # mm/s per axis: ~0.5 mm over a 30-minute session
    "drift_scale": 2.5e-5,      # per row: ~0.5 mm at 700 mm from the base over 60 rows
}
SECONDS_PER_POSE = 30.0
# Joints where each effect is observable. joint_compliance:1 is excluded: axis 1 is
# vertical, so tau_1j = z_0 . (r x g) = 0 for every pose (gravity has no moment about it).
CASES = (
    ["joint_scale:%d" % i for i in (1, 2, 3)]
    + ["joint_harmonic:%d" % i for i in (1, 2, 3)]
    + ["joint_backlash:%d" % i for i in (1, 2, 3)]
    + ["joint_compliance:%d" % i for i in (2, 3)]
    + ["joint_harmonic2:1", "drift_offset", "drift_scale"]
    + ["measurer_scale", "clean"]
)


# ---------------------------------------------------------------------------------------
# Small 3-D / homogeneous-transform algebra (4x4 as lists of rows)
# ---------------------------------------------------------------------------------------
def mat_mul(a, b):
    return [[sum(a[i][k] * b[k][j] for k in range(4)) for j in range(4)] for i in range(4)]


def rot_x(t):
    c, s = math.cos(t), math.sin(t)
    return [[1, 0, 0, 0], [0, c, -s, 0], [0, s, c, 0], [0, 0, 0, 1]]


def rot_y(t):
    c, s = math.cos(t), math.sin(t)
    return [[c, 0, s, 0], [0, 1, 0, 0], [-s, 0, c, 0], [0, 0, 0, 1]]


def rot_z(t):
    c, s = math.cos(t), math.sin(t)
    return [[c, -s, 0, 0], [s, c, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]


def trans(x, y, z):
    return [[1, 0, 0, x], [0, 1, 0, y], [0, 0, 1, z], [0, 0, 0, 1]]


def identity():
    return trans(0.0, 0.0, 0.0)


def apply(t, p):
    return tuple(t[i][0] * p[0] + t[i][1] * p[1] + t[i][2] * p[2] + t[i][3] for i in range(3))


def sub(a, b):
    return (a[0] - b[0], a[1] - b[1], a[2] - b[2])


def dot(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def norm(a):
    return math.sqrt(dot(a, a))


def pose_from_xyz_rpy(xyz, rpy_deg):
    """T = Trans(xyz) Rz(yaw) Ry(pitch) Rx(roll), rpy = [roll, pitch, yaw] (docs/formats.md, 1)."""
    roll, pitch, yaw = (math.radians(v) for v in rpy_deg)
    return mat_mul(trans(*xyz), mat_mul(rot_z(yaw), mat_mul(rot_y(pitch), rot_x(roll))))


# ---------------------------------------------------------------------------------------
# Arm
# ---------------------------------------------------------------------------------------
def nominal_arm():
    return {k: list(v) for k, v in NOMINAL.items()}


def link_transform(arm, i, q_rad):
    """A_i for joint index i (0-based)."""
    t = rot_z(q_rad + math.radians(arm["theta_deg"][i]))
    t = mat_mul(t, trans(0.0, 0.0, arm["d_mm"][i]))
    t = mat_mul(t, trans(arm["a_mm"][i], 0.0, 0.0))
    t = mat_mul(t, rot_x(math.radians(arm["alpha_deg"][i])))
    t = mat_mul(t, rot_y(math.radians(arm["beta_deg"][i])))
    return t


def frames(arm, q_rad):
    """World frames T_0 (base = identity) .. T_N at joint angles q (rad)."""
    out = [identity()]
    for i in range(N_JOINTS):
        out.append(mat_mul(out[-1], link_transform(arm, i, q_rad[i])))
    return out


def tool_point(arm, q_rad):
    return apply(frames(arm, q_rad)[-1], TOOL_MM)


def gravity_moments(arm, q_rad, g=GRAVITY):
    """tau[i][j] (0-based i, j; j >= i, else 0): z_{i-1} . ((o_j - o_{i-1}) x g), mm."""
    fr = frames(arm, q_rad)
    origins = [(f[0][3], f[1][3], f[2][3]) for f in fr]
    axes = [(f[0][2], f[1][2], f[2][2]) for f in fr]
    tau = [[0.0] * N_JOINTS for _ in range(N_JOINTS)]
    for i in range(N_JOINTS):  # joint i+1 turns about z of frame i
        for j in range(i, N_JOINTS):  # weight at the origin of frame j+1
            r = sub(origins[j + 1], origins[i])
            tau[i][j] = dot(axes[i], cross(r, g))
    return tau


# ---------------------------------------------------------------------------------------
# Measurer
# ---------------------------------------------------------------------------------------
def measurer_frame():
    return pose_from_xyz_rpy(MEAS_XYZ, MEAS_RPY_DEG)


def anchors_world():
    t = measurer_frame()
    return [apply(t, p) for p in ANCHORS_MEAS]


def wire_lengths(p, scale=0.0):
    return [(1.0 + scale) * norm(sub(p, a)) for a in anchors_world()]


def anchor_plane_distance(p):
    """Signed distance of p from the anchor plane, positive on the measurer's front side
    (the side its +x axis points to)."""
    t = measurer_frame()
    x_axis = (t[0][0], t[1][0], t[2][0])
    return dot(sub(p, anchors_world()[0]), x_axis)


def trilaterate(lengths):
    """World point from three wire lengths: intersection of three spheres (general
    method, not the paper's closed form), on the measurer's front side."""
    p1, p2, p3 = anchors_world()
    ex = sub(p2, p1)
    d = norm(ex)
    ex = tuple(c / d for c in ex)
    v = sub(p3, p1)
    i = dot(ex, v)
    ey = sub(v, tuple(i * c for c in ex))
    j = norm(ey)
    ey = tuple(c / j for c in ey)
    ez = cross(ex, ey)
    l1, l2, l3 = lengths
    x = (l1 * l1 - l2 * l2 + d * d) / (2.0 * d)
    y = (l1 * l1 - l3 * l3 + i * i + j * j) / (2.0 * j) - (i / j) * x
    h2 = l1 * l1 - x * x - y * y
    if h2 < 0.0:
        raise ValueError("wire lengths %r do not meet at a point" % (lengths,))
    z = math.sqrt(h2)
    base = tuple(p1[k] + x * ex[k] + y * ey[k] for k in range(3))
    cand = [tuple(base[k] + s * z * ez[k] for k in range(3)) for s in (1.0, -1.0)]
    return max(cand, key=anchor_plane_distance)


def position_dilution(p):
    """sqrt(trace((U^T U)^-1) / 3), U the unit wire directions: the RMS 3-D position error
    from trilateration divided by that of direct x, y, z measurement at the same noise."""
    u = []
    for a in anchors_world():
        r = sub(p, a)
        n = norm(r)
        u.append(tuple(c / n for c in r))
    m = [[sum(u[k][r] * u[k][c] for k in range(3)) for c in range(3)] for r in range(3)]
    det = (m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
           - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
           + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]))
    tr_inv = ((m[1][1] * m[2][2] - m[1][2] * m[2][1]) + (m[0][0] * m[2][2] - m[0][2] * m[2][0])
              + (m[0][0] * m[1][1] - m[0][1] * m[1][0])) / det
    return math.sqrt(tr_inv / 3.0)


# ---------------------------------------------------------------------------------------
# Scenario: true arm, hidden effect, poses, measurements
# ---------------------------------------------------------------------------------------
def parse_case(case):
    if case not in CASES:
        raise ValueError("unknown case %r (known: %s)" % (case, ", ".join(CASES)))
    if ":" in case:
        name, j = case.split(":")
        return name, int(j)
    return case, None


def _rng(case, seed, stream):
    # String seeds are hashed with SHA-512 by random.Random: stable across runs and
    # Python versions >= 3.2, independent of PYTHONHASHSEED.
    return random.Random("dhcal-acceptance|%s|%d|%s" % (case, seed, stream))


def true_arm(rng):
    arm = nominal_arm()
    for i in range(N_JOINTS):
        arm["theta_deg"][i] += rng.gauss(0.0, ERR_SD["theta_deg"])
        arm["a_mm"][i] += rng.gauss(0.0, ERR_SD["a_mm"])
        arm["alpha_deg"][i] += rng.gauss(0.0, ERR_SD["alpha_deg"])
    for i in (0, 2):  # d_2 stays 0: Hayati's beta_2 replaces it on the parallel axes 2-3
        arm["d_mm"][i] += rng.gauss(0.0, ERR_SD["d_mm"])
    arm["beta_deg"][1] += rng.gauss(0.0, ERR_SD["beta2_deg"])
    return arm


def _magnitude(rng, size, signed=True):
    v = size * rng.uniform(0.7, 1.3)
    if signed and rng.random() < 0.5:
        v = -v
    return v


def draw_effect(case, rng):
    """Values of the hidden effect (the library's units: rad, rad/mm, 1)."""
    name, joint = parse_case(case)
    if name == "clean":
        return {}
    if name == "joint_scale":
        return {"s": _magnitude(rng, EFFECT_SIZE[name])}
    if name == "joint_harmonic":
        return {"A_rad": _magnitude(rng, EFFECT_SIZE[name]),
                "B_rad": _magnitude(rng, EFFECT_SIZE[name])}
    if name == "joint_backlash":
        return {"b_rad": math.radians(_magnitude(rng, EFFECT_SIZE[name], signed=False))}
    if name == "joint_compliance":
        sizes = EFFECT_SIZE[case]
        return {"c_rad_per_mm": {k: _magnitude(rng, v, signed=False)
                                 for k, v in sorted(sizes.items())}}
    if name == "measurer_scale":
        return {"s": _magnitude(rng, EFFECT_SIZE[name])}
    if name == "joint_harmonic2":
        return {"A_rad": _magnitude(rng, EFFECT_SIZE[name]),
                "B_rad": _magnitude(rng, EFFECT_SIZE[name])}
    if name == "drift_offset":
        return {"v_mm_per_s": [_magnitude(rng, EFFECT_SIZE[name]) for _ in range(3)]}
    if name == "drift_scale":
        return {"k_per_row": _magnitude(rng, EFFECT_SIZE[name])}
    raise AssertionError(case)


def pose_times(case, rng, n):
    """Measurement times of n poses (s): ~SECONDS_PER_POSE apart, jittered; the drift
    cases' clock. drift_scale's CSV has no t_s: its clock is the row number."""
    if parse_case(case)[0] == "drift_scale":
        return [float(k) for k in range(n)]
    t, out = 0.0, []
    for _ in range(n):
        t += SECONDS_PER_POSE * rng.uniform(0.8, 1.2)
        out.append(round(t, 3))
    return out


def drifted(case, effect, p, t, t0):
    """The measured point after the session's drift (docs/effects.md, 1), base at the origin."""
    name, _ = parse_case(case)
    if name == "drift_offset":
        return [p[k] + effect["v_mm_per_s"][k] * (t - t0) for k in range(3)]
    if name == "drift_scale":
        return [(1.0 + effect["k_per_row"] * (t - t0)) * p[k] for k in range(3)]
    return list(p)


def effective_angles(case, effect, arm, q_rad, dirs):
    """q_eff from the measured angles (rad) and approach directions, exact model."""
    name, joint = parse_case(case)
    q_eff = list(q_rad)
    if joint is None:
        return q_eff
    i = joint - 1
    if name == "joint_scale":
        q_eff[i] += effect["s"] * q_rad[i]
    elif name == "joint_harmonic":
        q_eff[i] += effect["A_rad"] * math.sin(q_rad[i]) + effect["B_rad"] * math.cos(q_rad[i])
    elif name == "joint_harmonic2":
        q_eff[i] += (effect["A_rad"] * math.sin(2.0 * q_rad[i])
                     + effect["B_rad"] * math.cos(2.0 * q_rad[i]))
    elif name == "joint_backlash":
        q_eff[i] += 0.5 * effect["b_rad"] * dirs[i]
    elif name == "joint_compliance":
        tau = gravity_moments(arm, q_rad)
        for key, c in effect["c_rad_per_mm"].items():
            ii, jj = int(key[1]) - 1, int(key[2]) - 1  # "c23" -> i = 2, j = 3 (1-based)
            assert ii == i and jj >= ii
            q_eff[i] += c * tau[ii][jj]
    return q_eff


def sample_poses(rng, n, arm):
    """n poses uniform over RANGES_DEG (angles rounded as the CSV stores them), with
    random approach directions; rejects tool points near the anchor plane or base axis."""
    poses = []
    while len(poses) < n:
        q_deg = [round(rng.uniform(lo, hi), Q_DECIMALS) for lo, hi in RANGES_DEG]
        dirs = [1 if rng.random() < 0.5 else -1 for _ in range(N_JOINTS)]
        p = tool_point(arm, [math.radians(v) for v in q_deg])
        if anchor_plane_distance(p) < MIN_CLEARANCE_MM:
            continue
        if math.hypot(p[0], p[1]) < MIN_CLEARANCE_MM:
            continue
        poses.append((q_deg, dirs))
    return poses


def simulate(case, effect, arm, poses, rng_noise=None, times=None):
    """Rows of measurements: list of dicts with q (deg), dir, p_true (no noise), p_ref
    (without the effect), and meas (x,y,z or L1..L3, with noise when rng_noise is given).
    times: the drift cases' clock per pose (None: a session without drift)."""
    name, _ = parse_case(case)
    rows = []
    t0 = sum(times) / len(times) if times else 0.0
    for k, (q_deg, dirs) in enumerate(poses):
        q = [math.radians(v) for v in q_deg]
        p_ref = tool_point(arm, q)
        p = tool_point(arm, effective_angles(case, effect, arm, q, dirs))
        if times:
            p = drifted(case, effect, p, times[k], t0)
        if name == "measurer_scale":
            exact = wire_lengths(p, effect["s"])
            ref = wire_lengths(p)
            p_apparent = trilaterate(exact)  # where the scaled wires put the tool
        else:
            exact = list(p)
            ref = list(p_ref)
            p_apparent = p
        meas = [v + (rng_noise.gauss(0.0, NOISE_MM) if rng_noise else 0.0) for v in exact]
        rows.append({"q_deg": q_deg, "dir": dirs, "p": p, "p_ref": p_ref,
                     "p_apparent": p_apparent, "exact": exact, "ref": ref, "meas": meas,
                     "t_s": times[k] if times else None})
    return rows


def model_json(name="paper-3dof"):
    return {
        "name": name,
        "joints": [{"alpha_deg": NOMINAL["alpha_deg"][i], "a_mm": NOMINAL["a_mm"][i],
                    "d_mm": NOMINAL["d_mm"][i], "theta_offset_deg": NOMINAL["theta_deg"][i],
                    "min_deg": RANGES_DEG[i][0], "max_deg": RANGES_DEG[i][1]}
                   for i in range(N_JOINTS)],
        "tool_mm": list(TOOL_MM),
        "base": {"xyz_mm": [0.0, 0.0, 0.0], "rpy_deg": [0.0, 0.0, 0.0]},
        "gravity": list(GRAVITY),
        "measurer": {"anchors_mm": [list(a) for a in ANCHORS_MEAS],
                     "frame": {"xyz_mm": list(MEAS_XYZ), "rpy_deg": list(MEAS_RPY_DEG)}},
    }


def effect_size(rows):
    """Size of the hidden effect over the poses, noise-free:
    tool_rms_mm / tool_max_mm: RMS / max of |p_with_effect - p_without| (3-D, mm), where
      for measurer_scale p_with_effect is the apparent tool point, trilaterated from the
      scaled wire lengths (the arm itself is unchanged);
    measured_rms_mm: RMS of the 3-vector (x,y,z or L1..L3) exact minus effect-free, in the
      space the CSV holds."""
    n = len(rows)
    dev = [norm(sub(r["p_apparent"], r["p_ref"])) for r in rows]
    tool = math.sqrt(sum(d * d for d in dev) / n)
    meas = math.sqrt(sum(sum((a - b) ** 2 for a, b in zip(r["exact"], r["ref"]))
                         for r in rows) / n)
    return {"tool_rms_mm": tool, "tool_max_mm": max(dev), "measured_rms_mm": meas}


class Scenario(object):
    """Everything of one case and seed, deterministic."""

    def __init__(self, case, seed):
        self.case = case
        self.seed = int(seed)
        self.name, self.joint = parse_case(case)
        self.arm = true_arm(_rng(case, seed, "geometry"))
        self.effect = draw_effect(case, _rng(case, seed, "effect"))
        self.train_poses = sample_poses(_rng(case, seed, "train-poses"), N_TRAIN, self.arm)
        self.heldout_poses = sample_poses(_rng(case, seed, "heldout-poses"), N_HELDOUT,
                                          self.arm)
        drift = self.name in ("drift_offset", "drift_scale")
        self.train_times = (pose_times(case, _rng(case, seed, "train-times"), N_TRAIN)
                            if drift else None)
        self.train = simulate(case, self.effect, self.arm, self.train_poses,
                              _rng(case, seed, "train-noise"), self.train_times)
        self.heldout = simulate(case, self.effect, self.arm, self.heldout_poses,
                                _rng(case, seed, "heldout-noise"))

    @property
    def wire_data(self):
        return self.name == "measurer_scale"

    def truth(self):
        size = effect_size(self.train + self.heldout)
        return {
            "case": self.case,
            "seed": self.seed,
            "effect": None if self.name == "clean" else self.case,
            "effect_values": self.effect,
            "effect_size": size,
            "noise_mm": NOISE_MM,
            "noise_floor_rms_mm": math.sqrt(3.0) * NOISE_MM,
            "geometry": {
                "joints": [{"alpha_deg": self.arm["alpha_deg"][i], "a_mm": self.arm["a_mm"][i],
                            "d_mm": self.arm["d_mm"][i],
                            "theta_offset_deg": self.arm["theta_deg"][i],
                            "beta_deg": self.arm["beta_deg"][i]} for i in range(N_JOINTS)],
                "tool_mm": list(TOOL_MM),
                "base": {"xyz_mm": [0.0, 0.0, 0.0], "rpy_deg": [0.0, 0.0, 0.0]},
            },
        }

    def write_csv(self, path, rows, label):
        cols = ["q1", "q2", "q3", "dir1", "dir2", "dir3"]
        cols += ["L1", "L2", "L3"] if self.wire_data else ["x", "y", "z"]
        with_time = self.name == "drift_offset" and label == "train"
        if with_time:
            cols.append("t_s")
        with open(path, "w", newline="") as f:
            f.write("# dhcal acceptance case=%s seed=%d set=%s noise_mm=%g\n"
                    % (self.case, self.seed, label, NOISE_MM))
            w = csv.writer(f, lineterminator="\n")
            w.writerow(cols)
            for r in rows:
                w.writerow(["%.*f" % (Q_DECIMALS, v) for v in r["q_deg"]]
                           + ["%d" % d for d in r["dir"]]
                           + ["%.6f" % v for v in r["meas"]]
                           + (["%.3f" % r["t_s"]] if with_time else []))

    def write(self, out_dir):
        os.makedirs(out_dir, exist_ok=True)
        with open(os.path.join(out_dir, "model.json"), "w") as f:
            json.dump(model_json(), f, indent=2)
            f.write("\n")
        self.write_csv(os.path.join(out_dir, "train.csv"), self.train, "train")
        self.write_csv(os.path.join(out_dir, "heldout.csv"), self.heldout, "heldout")
        with open(os.path.join(out_dir, "truth.json"), "w") as f:
            json.dump(self.truth(), f, indent=2, sort_keys=True)
            f.write("\n")


def generate(case, seed, out_dir):
    sc = Scenario(case, seed)
    sc.write(out_dir)
    return sc


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--list", action="store_true", help="print the case names and exit")
    ap.add_argument("--case", help="one of --list")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--out", help="output directory")
    args = ap.parse_args(argv)
    if args.list:
        print("\n".join(CASES))
        return 0
    if not args.case or not args.out:
        ap.error("--case and --out are required (or --list)")
    if args.case not in CASES:
        ap.error("unknown case %r; --list shows the cases" % args.case)
    sc = generate(args.case, args.seed, args.out)
    size = sc.truth()["effect_size"]
    print("%s seed %d -> %s (effect at the tool: RMS %.3f mm, max %.3f mm)"
          % (args.case, args.seed, args.out, size["tool_rms_mm"], size["tool_max_mm"]))
    return 0


if __name__ == "__main__":
    sys.exit(main())
