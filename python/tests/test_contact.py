"""Touches through the package (issue #28): the paper's arm, as built, touching a table and a
wall of unknown pose; the rows handed in as arrays (plane ids, no points measured) and read from
the same CSV give the program's fit, number for number."""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

import dhcal
from test_dhcal import assert_fit_equal

ROOT = Path(__file__).resolve().parents[2]
MODEL = ROOT / "host_sim" / "scenarios" / "paper-3dof-model.json"


def tool_point(model: dict, q_deg: np.ndarray) -> np.ndarray:
    """Standard DH, this test's own: A_i = Rz(q + theta) Tz(d) Tx(a) Rx(alpha)."""
    t = np.eye(4)
    for joint, q in zip(model["joints"], q_deg):
        th = np.radians(q + joint.get("theta_offset_deg", 0.0))
        al = np.radians(joint["alpha_deg"])
        ct, st, ca, sa = np.cos(th), np.sin(th), np.cos(al), np.sin(al)
        t = t @ np.array([[ct, -st * ca, st * sa, joint["a_mm"] * ct],
                          [st, ct * ca, -ct * sa, joint["a_mm"] * st],
                          [0.0, sa, ca, joint["d_mm"]], [0.0, 0.0, 0.0, 1.0]])
    return t[:3, 3]


@pytest.fixture(scope="module")
def touches(tmp_path_factory) -> tuple:
    """80 touches of the table z = 500 and the wall x = 300 by the arm as built (a2, a3 and
    the elbow's offset off the drawing); joint 2 turned until the tool point meets the plane."""
    built = json.loads(MODEL.read_text())
    built["joints"][1]["a_mm"] += 1.5
    built["joints"][2]["a_mm"] -= 1.0
    built["joints"][2]["theta_offset_deg"] = 0.4
    rng = np.random.default_rng(28)
    planes = [(np.array([0.0, 0.0, 1.0]), 500.0), (np.array([1.0, 0.0, 0.0]), 300.0)]
    q_rows, ids = [], []
    while len(q_rows) < 80:
        pid = len(q_rows) % 2
        n, h = planes[pid]
        q = np.array([rng.uniform(-60, 60), rng.uniform(20, 120), rng.uniform(-140, -20)])
        for _ in range(30):
            f = n @ tool_point(built, q) - h
            dq = np.array([0.0, 1e-6, 0.0])
            slope = (n @ tool_point(built, q + dq) - h - f) / 1e-6
            if abs(f) < 1e-9 or abs(slope) < 1e-3:
                break
            q[1] -= f / slope
        if abs(f) < 1e-9 and -10.0 < q[1] < 170.0:
            q_rows.append(q)
            ids.append(pid + 1)
    q = np.array(q_rows)
    path = tmp_path_factory.mktemp("contact") / "touches.csv"
    with open(path, "w") as out:
        out.write("q1,q2,q3,plane\n")
        for row, pid in zip(q, ids):
            out.write(",".join(f"{v:.9f}" for v in row) + f",{pid}\n")
    # the values as the file holds them
    q = np.round(q, 9)
    return q, np.array(ids, dtype=float), path


def test_touches_as_arrays_and_as_a_file_equal_the_program(touches, run_cli) -> None:
    q, ids, path = touches
    model = dhcal.load_model(MODEL)
    report = run_cli("fit", "--model", MODEL, "--data", path)
    from_arrays = dhcal.fit(model, dhcal.Measurements(q, plane=ids))
    assert_fit_equal(from_arrays, report)
    assert from_arrays.report["targets"] == report["targets"]
    assert from_arrays.report["prior"] == report["prior"]
    read = dhcal.load_measurements(path, model)
    assert read.xyz_mm is None and read.plane is not None
    assert list(read.plane) == list(ids)
    assert_fit_equal(dhcal.fit(model, read), report)
    # the touches of a table and a wall: two planes; the fit brings the touches far closer to
    # them than the drawing does (the prior's scale: their scatter with the arm as drawn),
    # though the default tolerances keep the larger errors of this arm partly in the residual
    assert [p["touches"] for p in report["targets"]["planes"]] == [40, 40]
    assert report["rms_mm"] < report["prior"]["scale_mm"] / 2.0
    # what touches cannot see is said: the arm's turn about its base axis is blind
    assert any(u["param"] == "theta1" and u["blind"] for u in report["unidentifiable"])


def test_a_row_touching_two_targets_is_refused(touches) -> None:
    q, ids, _ = touches
    model = dhcal.load_model(MODEL)
    point = np.zeros(len(ids))
    point[3] = 1.0
    with pytest.raises(dhcal.DhcalInputError, match="row 4 touches plane 2 and point 1"):
        dhcal.fit(model, dhcal.Measurements(q, plane=ids, point=point))
    bad = ids.copy()
    bad[0] = 9.0
    with pytest.raises(dhcal.DhcalInputError, match="row 1, column 'plane': 9 is not 0 or one"):
        dhcal.fit(model, dhcal.Measurements(q, plane=bad))


def all_blind(report: dict) -> set:
    """What the report calls blind: held (unidentifiable) or left to the prior (fitted)."""
    return ({u["param"] for u in report["unidentifiable"] if u["blind"]}
            | {p["name"] for p in report["parameters"] if p.get("blind")})


def test_lengths_as_arrays_and_as_a_file_equal_the_program(touches, run_cli, tmp_path) -> None:
    """The touches and six gauge lengths between two poses each (pair ids, the distance on
    the first row): the package equals the program, and the lengths see what the planes
    alone leave blind."""
    q, ids, _ = touches
    built = json.loads(MODEL.read_text())
    built["joints"][1]["a_mm"] += 1.5
    built["joints"][2]["a_mm"] -= 1.0
    built["joints"][2]["theta_offset_deg"] = 0.4
    rng = np.random.default_rng(7)
    ends = np.round(np.column_stack([rng.uniform(-60, 60, 12), rng.uniform(20, 120, 12),
                                     rng.uniform(-140, -20, 12)]), 9)
    pair = np.repeat(np.arange(1.0, 7.0), 2)
    dist = np.zeros(12)
    for k in range(6):
        d = np.linalg.norm(tool_point(built, ends[2 * k]) - tool_point(built, ends[2 * k + 1]))
        dist[2 * k] = round(float(d), 6)
    all_q = np.vstack([q, ends])
    plane = np.concatenate([ids, np.zeros(12)])
    pairs = np.concatenate([np.zeros(len(ids)), pair])
    dists = np.concatenate([np.zeros(len(ids)), dist])
    path = tmp_path / "touches-and-lengths.csv"
    with open(path, "w") as out:
        out.write("q1,q2,q3,plane,pair,distance_mm\n")
        for row, pl, pa, di in zip(all_q, plane, pairs, dists):
            out.write(",".join(f"{v:.9f}" for v in row) + (f",{int(pl)},," if pl else
                      f",,{int(pa)}," + (f"{di:.6f}" if di else "")) + "\n")
    model = dhcal.load_model(MODEL)
    report = run_cli("fit", "--model", MODEL, "--data", path)
    arrays = dhcal.fit(model, dhcal.Measurements(all_q, plane=plane, pair=pairs,
                                                 distance_mm=dists))
    assert_fit_equal(arrays, report)
    read = dhcal.load_measurements(path, model)
    assert list(read.pair) == list(pairs) and list(read.distance_mm) == list(dists)
    assert_fit_equal(dhcal.fit(model, read), report)
    # the exact lengths are judged by their own scatter, not the touches': the prior holds the
    # arm's scale off the truth, and no length is left out for it
    assert report["outliers"] == [], report["outliers"]
    planes_only = run_cli("fit", "--model", MODEL, "--data", touches[2])
    blind, blind_planes = all_blind(report), all_blind(planes_only)
    assert blind < blind_planes, (blind, blind_planes)
    with pytest.raises(ValueError, match="pair and distance_mm go together"):
        dhcal.fit(model, dhcal.Measurements(all_q, plane=plane, pair=pairs))
    odd = pairs.copy()
    odd[-1] = 7.0
    with pytest.raises(dhcal.DhcalInputError, match="pair 6 has one row"):
        dhcal.fit(model, dhcal.Measurements(all_q, plane=plane, pair=odd, distance_mm=dists))
