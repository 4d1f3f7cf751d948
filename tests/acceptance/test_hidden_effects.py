#!/usr/bin/env python3
"""Self-checks of the acceptance data generator (hidden_effects.py): stdlib unittest.

Run: python3 tests/acceptance/test_hidden_effects.py [-v]
"""

import contextlib
import csv
import io
import json
import math
import os
import random
import shutil
import sys
import tempfile
import unittest

sys.dont_write_bytecode = True  # no __pycache__ in the source tree
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import hidden_effects as he  # noqa: E402

DEG = math.pi / 180.0


def rad(q_deg):
    return [v * DEG for v in q_deg]


class ForwardKinematics(unittest.TestCase):
    """Hand-computed poses of the nominal Table 3 arm."""

    def setUp(self):
        self.arm = he.nominal_arm()

    def assertPoint(self, p, expected, tol=1e-9):
        for got, want in zip(p, expected):
            self.assertAlmostEqual(got, want, delta=tol, msg="%r != %r" % (p, expected))

    def test_zero_pose(self):
        # A1 = Tz(433) Rx(90), A2 = Tx(400), A3 = Tx(345): arm stretched along world x.
        self.assertPoint(he.tool_point(self.arm, [0.0, 0.0, 0.0]), (745.0, 0.0, 433.0))

    def test_shoulder_up(self):
        # z1 = -y, so +90 deg about it turns the stretched arm from +x to +z.
        self.assertPoint(he.tool_point(self.arm, rad([0, 90, 0])), (0.0, 0.0, 1178.0))

    def test_base_turn(self):
        self.assertPoint(he.tool_point(self.arm, rad([90, 0, 0])), (0.0, 745.0, 433.0))

    def test_elbow_up(self):
        self.assertPoint(he.tool_point(self.arm, rad([0, 0, 90])), (400.0, 0.0, 778.0))

    def test_planar_closed_form(self):
        # Nominal arm: r = a2 cos q2 + a3 cos(q2+q3), z = 433 + a2 sin q2 + a3 sin(q2+q3).
        rng = random.Random(11)
        for _ in range(50):
            q = [rng.uniform(-3, 3) for _ in range(3)]
            r = 400 * math.cos(q[1]) + 345 * math.cos(q[1] + q[2])
            z = 433 + 400 * math.sin(q[1]) + 345 * math.sin(q[1] + q[2])
            self.assertPoint(he.tool_point(self.arm, q),
                             (r * math.cos(q[0]), r * math.sin(q[0]), z), tol=1e-9)

    def test_hayati_beta_tilts_axis_3(self):
        # A2 = Tx(400) Ry(b): x2 = cos b x1 - sin b z1 with x1 = x, z1 = -y (world), so the
        # forearm leaves the arm's plane: tool (400 + 345 cos b, 345 sin b, 433) at q = 0.
        b = 0.05 * DEG
        self.arm["beta_deg"][1] = 0.05
        self.assertPoint(he.tool_point(self.arm, [0, 0, 0]),
                         (400 + 345 * math.cos(b), 345 * math.sin(b), 433.0), tol=1e-9)

    def test_theta_offset_adds_to_q(self):
        self.arm["theta_deg"][1] = 3.0
        a = he.tool_point(self.arm, rad([10, 20, 30]))
        b = he.tool_point(he.nominal_arm(), rad([10, 23, 30]))
        self.assertPoint(a, b, tol=1e-9)

    def test_frames_are_rigid(self):
        arm = he.true_arm(random.Random(5))
        for f in he.frames(arm, rad([30, 40, -50])):
            r = [row[:3] for row in f[:3]]
            for i in range(3):
                for j in range(3):
                    d = sum(r[k][i] * r[k][j] for k in range(3))
                    self.assertAlmostEqual(d, 1.0 if i == j else 0.0, delta=1e-12)


class GravityMoments(unittest.TestCase):
    def test_closed_form_nominal(self):
        arm = he.nominal_arm()
        a2, a3 = 400.0, 345.0
        rng = random.Random(3)
        for _ in range(100):
            q = [rng.uniform(-math.pi, math.pi) for _ in range(3)]
            tau = he.gravity_moments(arm, q)
            c2, c23 = math.cos(q[1]), math.cos(q[1] + q[2])
            for j in range(3):
                self.assertAlmostEqual(tau[0][j], 0.0, delta=1e-9)  # axis 1 vertical
            self.assertAlmostEqual(tau[1][1], -a2 * c2, delta=1e-9)
            self.assertAlmostEqual(tau[1][2], -(a2 * c2 + a3 * c23), delta=1e-9)
            self.assertAlmostEqual(tau[2][2], -a3 * c23, delta=1e-9)
            self.assertEqual((tau[1][0], tau[2][0], tau[2][1]), (0.0, 0.0, 0.0))

    def test_sign_is_physical(self):
        # Arm stretched forward: gravity pulls the tool down, i.e. towards negative q2.
        tau = he.gravity_moments(he.nominal_arm(), [0.0, 0.0, 0.0])
        self.assertAlmostEqual(tau[1][2], -745.0, delta=1e-9)
        sc = he.Scenario("joint_compliance:2", 1)
        q = [0.0, 0.0, 0.0]
        q_eff = he.effective_angles(sc.case, sc.effect, sc.arm, q, [1, 1, 1])
        self.assertLess(q_eff[1], 0.0)
        p0, p1 = he.tool_point(sc.arm, q), he.tool_point(sc.arm, q_eff)
        self.assertLess(p1[2], p0[2])


class Measurer(unittest.TestCase):
    def test_anchors_in_world(self):
        want = [(1300, 0, 1200), (1300, -600, 300), (1300, 600, 300)]
        for got, w in zip(he.anchors_world(), want):
            for a, b in zip(got, w):
                self.assertAlmostEqual(a, b, delta=1e-9)

    def test_trilateration_round_trip(self):
        rng = random.Random(17)
        arm = he.true_arm(rng)
        for q_deg, _ in he.sample_poses(rng, 200, arm):
            p = he.tool_point(arm, rad(q_deg))
            back = he.trilaterate(he.wire_lengths(p))
            for a, b in zip(p, back):
                self.assertAlmostEqual(a, b, delta=1e-7)

    def test_paper_closed_form_agrees(self):
        # dhc_trilat.h: y = (L3^2 - L2^2)/(4b), z = (L2^2 + L3^2 - 2(L1^2 - a^2 + b^2 + c^2))
        # / (4(a - c)), x = +sqrt(L1^2 - y^2 - (z - a)^2) in the measurer frame.
        a, b, c = 1200.0, 600.0, 300.0
        rng = random.Random(23)
        t = he.measurer_frame()
        for _ in range(100):
            p = (rng.uniform(-700, 700), rng.uniform(-700, 700), rng.uniform(100, 1200))
            l1, l2, l3 = he.wire_lengths(p)
            y = (l3 ** 2 - l2 ** 2) / (4 * b)
            z = (l2 ** 2 + l3 ** 2 - 2 * (l1 ** 2 - a ** 2 + b ** 2 + c ** 2)) / (4 * (a - c))
            x = math.sqrt(l1 ** 2 - y ** 2 - (z - a) ** 2)
            w = he.apply(t, (x, y, z))
            for u, v in zip(w, p):
                self.assertAlmostEqual(u, v, delta=1e-7)
            for u, v in zip(he.trilaterate((l1, l2, l3)), p):
                self.assertAlmostEqual(u, v, delta=1e-7)

    def test_scaled_lengths(self):
        p = (500.0, 100.0, 700.0)
        for l0, l1 in zip(he.wire_lengths(p), he.wire_lengths(p, 1e-3)):
            self.assertAlmostEqual(l1, 1.001 * l0, delta=1e-9)

    def test_inconsistent_lengths_raise(self):
        with self.assertRaises(ValueError):
            he.trilaterate((10.0, 10.0, 10.0))

    def test_position_dilution(self):
        # Far in front of the anchors the three wires are nearly parallel: depth is
        # measured directly but the lateral position only through small angles.
        self.assertGreater(he.position_dilution((0.0, 0.0, 700.0)), 1.0)


class Effects(unittest.TestCase):
    """The exact models of docs/effects.md, section 1, noise-free."""

    def check(self, case, dq_fn):
        sc = he.Scenario(case, 3)
        for r in sc.train:
            q = rad(r["q_deg"])
            dq = dq_fn(sc, q, r["dir"])
            want = he.tool_point(sc.arm, [a + b for a, b in zip(q, dq)])
            for a, b in zip(r["p"], want):
                self.assertAlmostEqual(a, b, delta=1e-9)
        return sc

    def test_scale(self):
        for j in (1, 2, 3):
            self.check("joint_scale:%d" % j, lambda sc, q, d, i=j - 1: [
                sc.effect["s"] * q[k] if k == i else 0.0 for k in range(3)])

    def test_harmonic(self):
        for j in (1, 2, 3):
            self.check("joint_harmonic:%d" % j, lambda sc, q, d, i=j - 1: [
                sc.effect["A_rad"] * math.sin(q[k]) + sc.effect["B_rad"] * math.cos(q[k])
                if k == i else 0.0 for k in range(3)])

    def test_backlash(self):
        for j in (1, 2, 3):
            sc = self.check("joint_backlash:%d" % j, lambda sc, q, d, i=j - 1: [
                0.5 * sc.effect["b_rad"] * d[k] if k == i else 0.0 for k in range(3)])
            dirs = [r["dir"][j - 1] for r in sc.train]
            self.assertIn(1, dirs)
            self.assertIn(-1, dirs)
            self.assertGreater(sc.effect["b_rad"], 0.0)

    def test_compliance(self):
        def dq2(sc, q, d):
            t = he.gravity_moments(sc.arm, q)
            c = sc.effect["c_rad_per_mm"]
            return [0.0, c["c22"] * t[1][1] + c["c23"] * t[1][2], 0.0]

        def dq3(sc, q, d):
            t = he.gravity_moments(sc.arm, q)
            return [0.0, 0.0, sc.effect["c_rad_per_mm"]["c33"] * t[2][2]]

        self.check("joint_compliance:2", dq2)
        self.check("joint_compliance:3", dq3)

    def test_measurer_scale(self):
        sc = he.Scenario("measurer_scale", 3)
        s = sc.effect["s"]
        self.assertGreater(abs(s), 0.5e-3)
        for r in sc.train:
            self.assertEqual(r["p"], r["p_ref"])  # the arm itself has no effect
            for l, w in zip(r["exact"], he.wire_lengths(r["p"])):
                self.assertAlmostEqual(l, (1 + s) * w, delta=1e-9)

    def test_clean_has_no_effect(self):
        sc = he.Scenario("clean", 3)
        self.assertEqual(sc.effect, {})
        for r in sc.train:
            self.assertEqual(r["p"], r["p_ref"])

    def test_effect_sizes(self):
        # Every hidden effect moves the tool (or the wires) by far more than the noise.
        for case in he.CASES:
            size = he.Scenario(case, 5).truth()["effect_size"]
            if case == "clean":
                self.assertEqual(size["tool_rms_mm"], 0.0)
            else:
                self.assertGreater(size["tool_rms_mm"], 0.15, case)
                self.assertLess(size["tool_max_mm"], 4.0, case)
                self.assertGreater(size["measured_rms_mm"], 0.15, case)


class Scenarios(unittest.TestCase):
    def test_case_list(self):
        self.assertEqual(len(he.CASES), 16)
        self.assertEqual(len(set(he.CASES)), 16)
        self.assertNotIn("joint_compliance:1", he.CASES)

    def test_drift_grows_over_the_session_and_only_there(self):
        for case, column in (("drift_offset", True), ("drift_scale", False)):
            sc = he.Scenario(case, 3)
            dev = [he.norm(he.sub(r["p"], r["p_ref"])) for r in sc.train]
            # linear in t about the session's mean time: largest at the ends, ~0 mid-way
            self.assertGreater(max(dev[:5] + dev[-5:]), 0.3, case)
            self.assertLess(min(dev), 0.05, case)
            for r in sc.heldout:  # another session
                self.assertEqual(r["p"], r["p_ref"])
            with tempfile.TemporaryDirectory() as d:
                sc.write(d)
                with open(os.path.join(d, "train.csv")) as f:
                    header = [l for l in f if not l.startswith("#")][0].strip().split(",")
            self.assertEqual("t_s" in header, column, case)
        t = he.pose_times("drift_offset", he._rng("drift_offset", 3, "x"), 60)
        self.assertTrue(all(b > a for a, b in zip(t, t[1:])))
        self.assertAlmostEqual(t[-1] / 60.0, he.SECONDS_PER_POSE, delta=3.0)

    def test_true_geometry(self):
        arm = he.Scenario("clean", 4).arm
        self.assertEqual(arm["d_mm"][1], 0.0)
        self.assertNotEqual(arm["beta_deg"][1], 0.0)
        self.assertEqual(arm["beta_deg"][0], 0.0)
        self.assertEqual(arm["beta_deg"][2], 0.0)
        for k in ("alpha_deg", "a_mm", "d_mm", "theta_deg"):
            for i in range(3):
                self.assertLess(abs(arm[k][i] - he.NOMINAL[k][i]), 2.5)

    def test_poses_in_range_and_clear(self):
        sc = he.Scenario("joint_scale:1", 9)
        self.assertEqual(len(sc.train), he.N_TRAIN)
        self.assertEqual(len(sc.heldout), he.N_HELDOUT)
        for r in sc.train + sc.heldout:
            for v, (lo, hi) in zip(r["q_deg"], he.RANGES_DEG):
                self.assertTrue(lo <= v <= hi)
            self.assertGreaterEqual(math.hypot(r["p_ref"][0], r["p_ref"][1]),
                                    he.MIN_CLEARANCE_MM)
            self.assertGreaterEqual(he.anchor_plane_distance(r["p_ref"]), he.MIN_CLEARANCE_MM)
        # Spread over the work space: each joint covers most of its range.
        for i, (lo, hi) in enumerate(he.RANGES_DEG):
            qs = [r["q_deg"][i] for r in sc.train]
            self.assertGreater(max(qs) - min(qs), 0.8 * (hi - lo))

    def test_train_and_heldout_differ(self):
        sc = he.Scenario("clean", 1)
        self.assertNotEqual(sc.train_poses[0], sc.heldout_poses[0])

    def test_deterministic_and_seeded(self):
        a = he.Scenario("joint_harmonic:2", 7)
        b = he.Scenario("joint_harmonic:2", 7)
        c = he.Scenario("joint_harmonic:2", 8)
        self.assertEqual(a.train, b.train)
        self.assertEqual(a.effect, b.effect)
        self.assertNotEqual(a.train_poses, c.train_poses)
        self.assertNotEqual(a.effect, c.effect)

    def test_noise_level_clean(self):
        sc = he.Scenario("clean", 21)
        res = [m - e for r in sc.train + sc.heldout for m, e in zip(r["meas"], r["exact"])]
        n = len(res)
        mean = sum(res) / n
        std = math.sqrt(sum((x - mean) ** 2 for x in res) / (n - 1))
        # 300 values: the sample std is within ~4 % (1 sigma) of 0.05; allow 15 %.
        self.assertAlmostEqual(std, he.NOISE_MM, delta=0.15 * he.NOISE_MM)
        self.assertLess(abs(mean), 4 * he.NOISE_MM / math.sqrt(n))

    def test_noise_level_wires(self):
        sc = he.Scenario("measurer_scale", 21)
        res = [m - e for r in sc.train + sc.heldout for m, e in zip(r["meas"], r["exact"])]
        std = math.sqrt(sum(x * x for x in res) / len(res))
        self.assertAlmostEqual(std, he.NOISE_MM, delta=0.15 * he.NOISE_MM)


class Files(unittest.TestCase):
    def setUp(self):
        self.dir = tempfile.mkdtemp(prefix="dhcal-he-")

    def tearDown(self):
        shutil.rmtree(self.dir)

    def read_csv(self, path):
        with open(path, newline="") as f:
            lines = f.read().splitlines()
        self.assertTrue(lines[0].startswith("#"))
        data = [l for l in lines if not l.startswith("#")]
        rows = list(csv.DictReader(data))
        return lines[0], data[0].split(","), rows

    def test_cli_writes_case(self):
        out = os.path.join(self.dir, "c2")
        buf = io.StringIO()
        with contextlib.redirect_stdout(buf):
            rc = he.main(["--case", "joint_compliance:2", "--seed", "7", "--out", out])
        self.assertEqual(rc, 0)
        self.assertIn("joint_compliance:2 seed 7", buf.getvalue())
        with open(os.path.join(out, "model.json")) as f:
            model = json.load(f)
        self.assertEqual(len(model["joints"]), 3)
        for j, lo_hi in zip(model["joints"], he.RANGES_DEG):
            self.assertEqual(set(j), {"alpha_deg", "a_mm", "d_mm", "theta_offset_deg",
                                      "min_deg", "max_deg"})
            self.assertEqual((j["min_deg"], j["max_deg"]), lo_hi)
        self.assertEqual([j["a_mm"] for j in model["joints"]], [0.0, 400.0, 345.0])
        self.assertEqual(model["gravity"], [0.0, 0.0, -1.0])
        self.assertIn("measurer", model)
        self.assertNotIn("effects", model)  # nominal model: nothing hidden leaks

        comment, header, rows = self.read_csv(os.path.join(out, "train.csv"))
        self.assertIn("case=joint_compliance:2", comment)
        self.assertIn("seed=7", comment)
        self.assertEqual(header, ["q1", "q2", "q3", "dir1", "dir2", "dir3", "x", "y", "z"])
        self.assertEqual(len(rows), he.N_TRAIN)
        _, _, held = self.read_csv(os.path.join(out, "heldout.csv"))
        self.assertEqual(len(held), he.N_HELDOUT)

        with open(os.path.join(out, "truth.json")) as f:
            truth = json.load(f)
        self.assertEqual(truth["effect"], "joint_compliance:2")
        self.assertEqual(truth["seed"], 7)
        self.assertEqual(set(truth["effect_values"]["c_rad_per_mm"]), {"c22", "c23"})

        # The CSV holds exactly the measured angles the data were computed from.
        sc = he.Scenario("joint_compliance:2", 7)
        for r, want in zip(rows, sc.train):
            self.assertEqual([float(r["q%d" % k]) for k in (1, 2, 3)], want["q_deg"])
            self.assertEqual([int(r["dir%d" % k]) for k in (1, 2, 3)], want["dir"])
            for key, v in zip("xyz", want["meas"]):
                self.assertAlmostEqual(float(r[key]), v, delta=1e-6)

    def test_wire_case_columns(self):
        out = os.path.join(self.dir, "ms")
        he.generate("measurer_scale", 3, out)
        _, header, rows = self.read_csv(os.path.join(out, "heldout.csv"))
        self.assertEqual(header, ["q1", "q2", "q3", "dir1", "dir2", "dir3", "L1", "L2", "L3"])
        for r in rows:
            lengths = [float(r["L%d" % k]) for k in (1, 2, 3)]
            he.trilaterate(lengths)  # consistent: the lengths meet at a point
        with open(os.path.join(out, "truth.json")) as f:
            self.assertEqual(json.load(f)["effect"], "measurer_scale")

    def test_clean_truth(self):
        out = os.path.join(self.dir, "clean")
        he.generate("clean", 3, out)
        with open(os.path.join(out, "truth.json")) as f:
            truth = json.load(f)
        self.assertIsNone(truth["effect"])

    def test_list(self):
        buf = io.StringIO()
        with contextlib.redirect_stdout(buf):
            self.assertEqual(he.main(["--list"]), 0)
        self.assertEqual(buf.getvalue().split(), list(he.CASES))


if __name__ == "__main__":
    unittest.main()
