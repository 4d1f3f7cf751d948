"""The Python package against the dhcal program on the shipped example data
(examples/data/compliance: a 3-joint arm whose joint 2 bends under gravity,
joint_compliance:2, with 0.05 mm noise), and its error paths."""
from __future__ import annotations

import json
import math
import re
from importlib import metadata
from pathlib import Path

import numpy as np
import pytest

import dhcal
from conftest import EXAMPLE, ROOT, columns

MODEL = EXAMPLE / "model.json"
TRAIN = EXAMPLE / "train.csv"
HELDOUT = EXAMPLE / "heldout.csv"
REL = 1e-12


def close(a: float, b: float, rel: float = REL) -> bool:
    return math.isclose(a, b, rel_tol=rel, abs_tol=1e-300)


def assert_fit_equal(result: dhcal.FitResult, report: dict) -> None:
    """Every number of the program's fit report, equal to REL."""
    for key in ("rms_mm", "mean_mm", "max_mm", "sigma_mm", "heldout_rms_mm",
                "heldout_mean_mm", "cv_rms_mm"):
        if key in report:
            assert close(getattr(result, key), report[key]), key
        else:
            assert getattr(result, key, None) is None, key
    assert result.iterations == report["iterations"]
    assert result.converged == report["converged"]
    assert [p.name for p in result.parameters] == [p["name"] for p in report["parameters"]]
    for p, q in zip(result.parameters, report["parameters"]):
        assert close(p.value, q["value"]), p.name
        assert close(p.std, q["std"]), p.name
    assert [(u.param, list(u.confounded_with)) for u in result.unidentifiable] == \
        [(u["param"], u["confounded_with"]) for u in report["unidentifiable"]]
    assert [(o.row, o.reason) for o in result.outliers] == \
        [(o["row"], o["reason"]) for o in report["outliers"]]
    assert result.adequacy == report["adequacy"]


@pytest.fixture(scope="module")
def model() -> dhcal.Model:
    return dhcal.load_model(MODEL)


@pytest.fixture(scope="module")
def train(model: dhcal.Model) -> dict:
    return columns(TRAIN, model.n_joints)


@pytest.fixture(scope="module")
def heldout(model: dhcal.Model) -> dhcal.Measurements:
    c = columns(HELDOUT, model.n_joints)
    return dhcal.Measurements(c["q_deg"], c["xyz_mm"], c["directions"])


def test_version_is_the_library_s() -> None:
    header = (ROOT / "lib" / "include" / "dhcal" / "dhc_version.h").read_text()
    version = re.search(r'#define DHCAL_VERSION_STRING "([0-9.]+)"', header).group(1)
    assert dhcal.__version__ == version
    assert metadata.version("dhcal") == version


def test_model_loads(model: dhcal.Model) -> None:
    assert (model.name, model.n_joints, model.has_measurer) == ("paper-3dof", 3, True)


def test_fit_equals_the_program(model, train, run_cli) -> None:
    result = dhcal.fit(model, train["q_deg"], train["xyz_mm"], directions=train["directions"])
    report = run_cli("fit", "--model", MODEL, "--data", TRAIN)
    assert_fit_equal(result, report)
    # the example's geometry-only fit leaves the compliance in the residual
    assert 0.3 < result.rms_mm < 0.5
    assert result.parameter("a2").value == pytest.approx(400.0, abs=1.0)
    assert result.model is not None and result.model.n_joints == 3


def test_fit_with_effects_heldout_noise_cv_equals_the_program(model, train, heldout,
                                                              run_cli) -> None:
    result = dhcal.fit(model, train["q_deg"], train["xyz_mm"], ["joint_compliance:2"],
                       heldout, directions=train["directions"], noise=(0.001, 0.05), cv=True)
    report = run_cli("fit", "--model", MODEL, "--data", TRAIN, "--heldout", HELDOUT,
                     "--effects", "joint_compliance:2", "--noise", "0.001,0.05", "--cv")
    assert_fit_equal(result, report)
    assert result.heldout_rms_mm < 0.15  # the compliance fitted: the held-out rows agree


def test_fit_of_read_measurements_equals_the_program(model, run_cli) -> None:
    data = dhcal.load_measurements(TRAIN, model)
    assert data.q_deg.shape == (60, 3) and data.directions is not None
    assert data.temp_c is None and data.t_s is None
    result = dhcal.fit(model, data, geometry="lengths")
    assert_fit_equal(result, run_cli("fit", "--model", MODEL, "--data", TRAIN,
                                     "--geometry", "lengths"))
    assert result.geometry == "lengths"


def test_diagnose_names_the_hidden_effect_as_the_program(model, train, heldout,
                                                         run_cli) -> None:
    truth = json.loads((EXAMPLE / "truth.json").read_text())
    result = dhcal.diagnose(model, train["q_deg"], train["xyz_mm"], heldout=heldout,
                            directions=train["directions"], cv=True)
    report = run_cli("diagnose", "--model", MODEL, "--data", TRAIN, "--heldout", HELDOUT,
                     "--cv")
    assert_fit_equal(result, report)
    assert report["candidates"][0]["significant"] and report["candidates"][0]["verdict"] == "named"
    named = report["named"]
    assert named == truth["effect"] == "joint_compliance:2"
    assert result.named is not None and result.named.label == named
    assert close(result.time_pose_r2, report["time_pose_r2"])
    assert len(result.candidates) == len(report["candidates"]) > 5
    for c, d in zip(result.candidates, report["candidates"]):
        assert (c.effect, c.joint, c.significant, c.dof, c.verdict, c.look_alikes) == \
            (d["effect"], d["joint"], d["significant"], d["dof"], d["verdict"],
             tuple(d["look_alikes"]))
        assert close(c.explained, d["explained"]) and close(c.log10_p, d["log10_p"])
        assert list(c.params) == [p["name"] for p in d["params"]]
        assert all(close(c.params[p["name"]], p["value"]) for p in d["params"])
        assert (c.cv_rms_mm is None) == ("cv_rms_mm" not in d)
        if c.cv_rms_mm is not None:
            assert close(c.cv_rms_mm, d["cv_rms_mm"])
    assert result.named.explained > 0.8 and result.named.cv_rms_mm < 0.2
    assert "joint_compliance:2" in result.summary()


def test_refine_equals_the_program_and_saves_its_model(model, train, heldout, run_cli,
                                                      tmp_path: Path) -> None:
    result = dhcal.refine(model, train["q_deg"], train["xyz_mm"], heldout=heldout,
                          directions=train["directions"])
    cli_out = tmp_path / "cli.json"
    report = run_cli("refine", "--model", MODEL, "--data", TRAIN, "--heldout", HELDOUT,
                     "--out", cli_out)
    assert_fit_equal(result, report)
    assert result.effects == report["effects"] == ["joint_compliance:2"]
    assert result.stopped == report["stopped"]
    assert len(result.steps) == len(report["steps"]) == 2
    for s, t in zip(result.steps, report["steps"]):
        assert s["added"] == t["added"]
        assert close(s["rms_mm"], t["rms_mm"]) and close(s["cv_rms_mm"], t["cv_rms_mm"])
    # the compliance found is the one hidden in the data (truth in rad/mm, reported deg/mm)
    truth = json.loads((EXAMPLE / "truth.json").read_text())["effect_values"]["c_rad_per_mm"]
    c22 = result.parameter("compliance2_2")
    assert abs(c22.value - math.degrees(truth["c22"])) < 3 * c22.std
    # the calibrated model, written through the same writer, is the program's byte for byte
    py_out = tmp_path / "py.json"
    result.model.save(py_out)
    assert py_out.read_bytes() == cli_out.read_bytes()


def test_saved_model_is_the_calibrated_model(model, train, run_cli, tmp_path: Path) -> None:
    result = dhcal.fit(model, train["q_deg"], train["xyz_mm"], "joint_compliance:2",
                       directions=train["directions"])
    path = tmp_path / "calibrated.json"
    result.model.save(path)
    # the program compares the saved model with the rows it was fitted to: the fit's RMS
    compare = run_cli("compare", "--model", path, "--data", TRAIN)
    assert compare["rms_mm"] == pytest.approx(result.rms_mm, rel=1e-9)
    assert "joint_compliance:2" in json.loads(path.read_text())["effects"]


def test_load_save_round_trip(model, tmp_path: Path) -> None:
    first, second = tmp_path / "a.json", tmp_path / "b.json"
    model.save(first)
    again = dhcal.load_model(first)
    again.save(second)
    assert first.read_bytes() == second.read_bytes()
    original = json.loads(MODEL.read_text())
    saved = again.to_dict()
    assert saved["name"] == original["name"]
    for j, k in zip(saved["joints"], original["joints"]):
        for key in ("alpha_deg", "a_mm", "d_mm", "min_deg", "max_deg"):
            assert j[key] == k[key], key
    assert saved["measurer"]["anchors_mm"] == original["measurer"]["anchors_mm"]


def test_save_to_a_missing_directory_names_it(model, tmp_path: Path) -> None:
    target = tmp_path / "missing" / "m.json"
    with pytest.raises(dhcal.DhcalError, match="missing"):
        model.save(target)
    assert not target.exists()


def test_bad_model_file_names_file_and_line(tmp_path: Path) -> None:
    bad = tmp_path / "broken.json"
    bad.write_text('{\n  "name": "x",\n  "joints": [\n    {"alpha_deg": 90,,}\n  ]\n}\n')
    with pytest.raises(dhcal.DhcalInputError) as e:
        dhcal.load_model(bad)
    assert isinstance(e.value, ValueError) and e.value.code == 2
    assert re.search(r"broken\.json:4:", str(e.value)), str(e.value)


def test_bad_model_value_names_the_json_path(tmp_path: Path) -> None:
    doc = json.loads(MODEL.read_text())
    doc["joints"][1]["a_mm"] = "long"
    bad = tmp_path / "typed.json"
    bad.write_text(json.dumps(doc))
    with pytest.raises(dhcal.DhcalInputError, match=r"typed\.json.*joints\[1\]\.a_mm"):
        dhcal.load_model(bad)


def test_bad_csv_names_file_and_line(model, tmp_path: Path) -> None:
    bad = tmp_path / "rows.csv"
    bad.write_text("# comment\nq1,q2,q3,x,y,z\n1,2,3,4,5,6\n1,2,abc,4,5,6\n")
    with pytest.raises(dhcal.DhcalInputError, match=r"rows\.csv:4: column 'q3'"):
        dhcal.load_measurements(bad, model)


def test_missing_file_is_named(tmp_path: Path) -> None:
    with pytest.raises(dhcal.DhcalInputError, match="nowhere.json"):
        dhcal.load_model(tmp_path / "nowhere.json")


def test_nan_and_shapes_are_value_errors(model, train) -> None:
    q = train["q_deg"].copy()
    q[7, 1] = np.nan
    with pytest.raises(ValueError, match="row 8"):
        dhcal.fit(model, q, train["xyz_mm"])
    xyz = train["xyz_mm"].copy()
    xyz[0, 2] = np.inf
    with pytest.raises(ValueError, match="xyz_mm"):
        dhcal.diagnose(model, train["q_deg"], xyz)
    with pytest.raises(ValueError, match="shape"):
        dhcal.fit(model, train["q_deg"][:, :2], train["xyz_mm"])
    with pytest.raises(ValueError, match="shape"):
        dhcal.fit(model, train["q_deg"], train["xyz_mm"][:-1])
    with pytest.raises(ValueError, match="noise"):
        dhcal.fit(model, train["q_deg"], train["xyz_mm"], noise=(float("nan"), 0.05))


def test_values_the_csv_rules_refuse(model, train) -> None:
    q = train["q_deg"].copy()
    q[3, 1] = 800.0
    with pytest.raises(dhcal.DhcalInputError,
                       match=r"training data: row 4, column 'q2': 800 is not inside "
                             r"\[-720, 720\] deg"):
        dhcal.fit(model, q, train["xyz_mm"])
    d = train["directions"].copy()
    d[5, 0] = 0.5
    with pytest.raises(ValueError, match=r"row 6, column 'dir1': 0.5 is not -1 or \+1"):
        dhcal.fit(model, train["q_deg"], train["xyz_mm"], directions=d)


def test_bad_effect_is_an_input_error(model, train) -> None:
    with pytest.raises(dhcal.DhcalInputError, match="joint_compliance:9"):
        dhcal.fit(model, train["q_deg"], train["xyz_mm"], ["joint_compliance:9"])


def test_bad_geometry_is_an_input_error(model, train) -> None:
    with pytest.raises(dhcal.DhcalInputError, match="everything"):
        dhcal.fit(model, train["q_deg"], train["xyz_mm"], geometry="everything")


def test_too_few_rows_fail_the_computation(model, train) -> None:
    with pytest.raises(dhcal.DhcalError) as e:
        dhcal.fit(model, train["q_deg"][:3], train["xyz_mm"][:3])
    assert not isinstance(e.value, ValueError) and e.value.code == 1
    assert "under-determine" in str(e.value)


def test_calls_do_not_leak_into_each_other(model, train) -> None:
    """The analysis caches rows by the samples' address: new arrays of the same shape must
    give their own fit, and the first data their first fit again."""
    first = dhcal.fit(model, train["q_deg"], train["xyz_mm"], directions=train["directions"])
    shifted = train["xyz_mm"] + np.array([0.0, 0.0, 2.0])
    moved = dhcal.fit(model, train["q_deg"], shifted, directions=train["directions"])
    again = dhcal.fit(model, train["q_deg"], train["xyz_mm"], directions=train["directions"])
    assert moved.parameter("d1").value == pytest.approx(first.parameter("d1").value + 2.0,
                                                        abs=1e-3)
    assert again.rms_mm == first.rms_mm
    assert [p.value for p in again.parameters] == [p.value for p in first.parameters]


def test_threads_take_turns(model, train) -> None:
    """The C side keeps static workspaces; PyDLL holds the interpreter lock through each call,
    so fits from several threads give what one thread gives."""
    from concurrent.futures import ThreadPoolExecutor
    args = [(train["q_deg"], train["xyz_mm"] + np.array([0.0, 0.0, dz])) for dz in (0, 1, 2, 3)]
    serial = [dhcal.fit(model, q, x).rms_mm for q, x in args]
    with ThreadPoolExecutor(4) as pool:
        threaded = list(pool.map(lambda a: dhcal.fit(model, *a).rms_mm, args * 3))
    assert threaded == serial * 3


def test_readme_session_is_true(tmp_path: Path, monkeypatch) -> None:
    """python/README.md's session, run as a doctest: its printed numbers are the package's."""
    import doctest
    text = (ROOT / "python" / "README.md").read_text()
    session = re.search(r"```python\n(.*?)```", text, re.S).group(1)
    monkeypatch.chdir(ROOT)
    session = session.replace('"calibrated.json"', repr(str(tmp_path / "calibrated.json")))
    test = doctest.DocTestParser().get_doctest(session, {}, "README", "python/README.md", 0)
    runner = doctest.DocTestRunner(optionflags=doctest.NORMALIZE_WHITESPACE)
    runner.run(test)
    assert runner.failures == 0 and runner.tries > 8
    assert dhcal.load_model(tmp_path / "calibrated.json").n_joints == 3


def test_time_and_temperature_columns_as_the_program(model, train, run_cli,
                                                     tmp_path: Path) -> None:
    """t_s and temp_c reach the C side as the CSV's columns do: the diagnosis, whose drift
    and thermal candidates read them, equals the program's on the same rows in a file."""
    n = train["q_deg"].shape[0]
    t_s = np.arange(n) * 37.5 + 1000.0 + 20.0 * (np.arange(n) % 7)  # not the row number
    temp_c = 20.0 + 0.05 * np.arange(n) + 0.25 * np.sin(np.arange(n))
    path = tmp_path / "timed.csv"
    with open(path, "w") as f:
        f.write("q1,q2,q3,dir1,dir2,dir3,x,y,z,temp_c,t_s\n")
        for i in range(n):
            values = [*train["q_deg"][i], *train["directions"][i], *train["xyz_mm"][i],
                      temp_c[i], t_s[i]]
            f.write(",".join(repr(float(v)) for v in values) + "\n")
    result = dhcal.diagnose(model, train["q_deg"], train["xyz_mm"],
                            directions=train["directions"], temp_c=temp_c, t_s=t_s)
    report = run_cli("diagnose", "--model", MODEL, "--data", path)
    assert_fit_equal(result, report)
    assert close(result.time_pose_r2, report["time_pose_r2"])
    assert [(c.label, c.significant) for c in result.candidates] == \
        [(f'{d["effect"]}:{d["joint"]}' if d["joint"] else d["effect"], d["significant"])
         for d in report["candidates"]]
    assert any(c.effect == "thermal_scale" for c in result.candidates)
    assert all(close(c.explained, d["explained"])
               for c, d in zip(result.candidates, report["candidates"]))
    untimed = dhcal.diagnose(model, train["q_deg"], train["xyz_mm"],
                             directions=train["directions"])
    assert untimed.time_pose_r2 != result.time_pose_r2  # the times were used
    assert not any(c.effect == "thermal_scale" for c in untimed.candidates)
    read = dhcal.load_measurements(path, model)
    assert np.array_equal(read.t_s, t_s) and np.array_equal(read.temp_c, temp_c)


def wire_lengths(model_path: Path, xyz_mm: np.ndarray) -> np.ndarray:
    """The paper's draw-wire lengths L1..L3 of the tool points, computed here from the model
    file's measurer block (anchors in the measurer's frame, the frame's rpy a z-y-x turn):
    |R^T (p - t) - anchor_k| (no scale or offset effect)."""
    meas = json.loads(model_path.read_text())["measurer"]
    roll, pitch, yaw = np.radians(meas["frame"]["rpy_deg"])
    cx, sx, cy, sy, cz, sz = (math.cos(roll), math.sin(roll), math.cos(pitch),
                              math.sin(pitch), math.cos(yaw), math.sin(yaw))
    rot = (np.array([[cz, -sz, 0], [sz, cz, 0], [0, 0, 1]]) @
           np.array([[cy, 0, sy], [0, 1, 0], [-sy, 0, cy]]) @
           np.array([[1, 0, 0], [0, cx, -sx], [0, sx, cx]]))
    local = (xyz_mm - np.array(meas["frame"]["xyz_mm"])) @ rot
    anchors = np.array(meas["anchors_mm"])
    return np.linalg.norm(local[:, None, :] - anchors[None, :, :], axis=2)


def test_wire_lengths_fit_as_the_program(model, train, run_cli, tmp_path: Path) -> None:
    """The paper's instrument: wire lengths in, the fit in wire-length space, equal to the
    program's on the same rows in a file; and the calibration it gives is the one the tool
    points give (same arm, same noise seen through the wires)."""
    wires = wire_lengths(MODEL, train["xyz_mm"])
    path = tmp_path / "wires.csv"
    with open(path, "w") as f:
        f.write("q1,q2,q3,dir1,dir2,dir3,L1,L2,L3\n")
        for i in range(wires.shape[0]):
            values = [*train["q_deg"][i], *train["directions"][i], *wires[i]]
            f.write(",".join(repr(float(v)) for v in values) + "\n")
    result = dhcal.fit(model, train["q_deg"], wires_mm=wires, effects=["joint_compliance:2"],
                       directions=train["directions"])
    report = run_cli("fit", "--model", MODEL, "--data", path, "--effects", "joint_compliance:2")
    assert_fit_equal(result, report)
    points = dhcal.fit(model, train["q_deg"], train["xyz_mm"], ["joint_compliance:2"],
                       directions=train["directions"])
    assert result.rms_mm < 0.15  # wire residuals of the compliance fitted: near the noise
    assert result.parameter("a2").value == pytest.approx(points.parameter("a2").value,
                                                         abs=0.1)
    read = dhcal.load_measurements(path, model)
    assert read.xyz_mm is None and np.array_equal(read.wires_mm, wires)
    assert_fit_equal(dhcal.fit(model, read, effects=["joint_compliance:2"]), report)


def test_wire_lengths_need_a_measurer(train, tmp_path: Path) -> None:
    data = json.loads(MODEL.read_text())
    del data["measurer"]
    (tmp_path / "bare.json").write_text(json.dumps(data))
    bare = dhcal.load_model(tmp_path / "bare.json")
    wires = wire_lengths(MODEL, train["xyz_mm"])
    with pytest.raises(dhcal.DhcalInputError, match="measurer"):
        dhcal.fit(bare, train["q_deg"], wires_mm=wires)
    with pytest.raises(ValueError, match="wires_mm"):
        dhcal.fit(bare, train["q_deg"], wires_mm=wires[:, :2])
    with pytest.raises(TypeError, match="xyz_mm or wires_mm"):
        dhcal.fit(bare, train["q_deg"])


def test_heldout_measured_otherwise_is_refused_as_the_program_does(model, train,
                                                                   heldout) -> None:
    """Training rows of wire lengths, held-out rows of tool points: errors of two kinds are
    not comparable (the program's rule, dhcal_samples_check_held)."""
    wires = wire_lengths(MODEL, train["xyz_mm"])
    with pytest.raises(dhcal.DhcalInputError, match="measured like the training rows"):
        dhcal.fit(model, train["q_deg"], wires_mm=wires, heldout=heldout,
                  directions=train["directions"])


def test_errors_name_the_functions_arguments_not_the_programs_options(model, train) -> None:
    """The desk library says '--effects: ...' to the program's user; a Python caller reads
    the argument's name (issue 29)."""
    with pytest.raises(ValueError) as e:
        dhcal.fit(model, train["q_deg"], train["xyz_mm"], effects=("gremlins",))
    assert str(e.value).startswith("effects: 'gremlins' is not an effect"), str(e.value)
    assert "--" not in str(e.value)
    with pytest.raises(ValueError) as e:
        dhcal.fit(model, train["q_deg"], train["xyz_mm"], geometry="most")
    assert "--geometry" not in str(e.value) and "geometry" in str(e.value), str(e.value)
