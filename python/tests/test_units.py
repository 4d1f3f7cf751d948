"""Units and frames before any fit, from Python (docs/python.md, 3.1): positions in metres,
angles in radians, two swapped columns and points in another frame are refused by fit,
diagnose and refine with a ValueError naming the cause (and no command-line flag);
check_units=False goes on. The data: examples/data/compliance, converted here."""
from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest

import dhcal
from conftest import EXAMPLE, columns

MODEL = EXAMPLE / "model.json"
TRAIN = EXAMPLE / "train.csv"
COMMANDS = (dhcal.fit, dhcal.diagnose, dhcal.refine)


@pytest.fixture(scope="module")
def model() -> dhcal.Model:
    return dhcal.load_model(MODEL)


@pytest.fixture(scope="module")
def train(model: dhcal.Model) -> dict:
    return columns(TRAIN, model.n_joints)


def swapped(a: np.ndarray, i: int, j: int) -> np.ndarray:
    b = a.copy()
    b[:, [i, j]] = b[:, [j, i]]
    return b


def mistakes(train: dict) -> dict:
    q, xyz = train["q_deg"], train["xyz_mm"]
    return {
        "positions look like metres": (q, xyz / 1000.0),
        "joint angles look like radians": (np.radians(q), xyz),
        "columns q2 and q3 look swapped": (swapped(q, 1, 2), xyz),
        "columns x and y look swapped": (q, swapped(xyz, 0, 1)),
    }


def assert_refused(error: pytest.ExceptionInfo, cause: str) -> None:
    message = str(error.value)
    assert isinstance(error.value, ValueError)
    assert error.value.code == 2
    assert message.startswith("training data: ") and cause in message, message
    assert "check_units=False" in message, message
    assert "--" not in message, f"names a command-line flag: {message}"


@pytest.mark.parametrize("command", COMMANDS, ids=lambda c: c.__name__)
def test_each_mistake_is_refused_with_its_cause(model, train, command) -> None:
    for cause, (q, xyz) in mistakes(train).items():
        with pytest.raises(dhcal.DhcalInputError) as e:
            command(model, q, xyz, directions=train["directions"])
        assert_refused(e, cause)


@pytest.mark.parametrize("command", COMMANDS, ids=lambda c: c.__name__)
def test_check_units_false_goes_on(model, train, command) -> None:
    for cause, (q, xyz) in mistakes(train).items():
        try:
            command(model, q, xyz, directions=train["directions"], check_units=False)
        except dhcal.DhcalError as e:  # the computation may fail on such data: not refused
            assert e.code == 1 and "look like" not in e.message, (cause, e.message)


def test_the_data_as_they_are_pass(model, train) -> None:
    for command in COMMANDS:
        command(model, train["q_deg"], train["xyz_mm"], directions=train["directions"])


def test_heldout_rows_are_checked_too(model, train) -> None:
    held = dhcal.load_measurements(EXAMPLE / "heldout.csv", model)
    held.xyz_mm = held.xyz_mm / 1000.0
    with pytest.raises(dhcal.DhcalInputError) as e:
        dhcal.fit(model, train["q_deg"], train["xyz_mm"], heldout=held)
    assert str(e.value).startswith("held-out data: positions look like metres"), str(e.value)


def test_another_frame_needs_base_frame(model, train) -> None:
    turn = math.radians(35.0)
    r = np.array([[math.cos(turn), -math.sin(turn), 0.0],
                  [math.sin(turn), math.cos(turn), 0.0], [0.0, 0.0, 1.0]])
    tracker = train["xyz_mm"] @ r.T + np.array([1500.0, -800.0, 300.0])
    with pytest.raises(dhcal.DhcalInputError) as e:
        dhcal.fit(model, train["q_deg"], tracker, effects=["tool_offset"])
    assert_refused(e, "another frame than the model's base")
    assert "add 'base_frame' to effects" in str(e.value)
    result = dhcal.fit(model, train["q_deg"], tracker, effects=["base_frame", "tool_offset"])
    assert result.rms_mm < 1.0


def test_a_model_in_metres_is_refused(train, tmp_path: Path) -> None:
    m = json.loads(MODEL.read_text())
    for j in m["joints"]:
        j["a_mm"] /= 1000.0
        j["d_mm"] /= 1000.0
    path = tmp_path / "metres.json"
    path.write_text(json.dumps(m))
    small = dhcal.load_model(path)
    with pytest.raises(dhcal.DhcalInputError) as e:
        dhcal.fit(small, train["q_deg"], train["xyz_mm"])
    message = str(e.value)
    assert message.startswith(f"{path}: the model's lengths look like metres"), message
    assert "check_units=False" in message and "--" not in message


def test_wire_lengths_in_metres_are_refused(model, train) -> None:
    """The rows' tool points as the lengths of the model's draw wires, computed here."""
    m = json.loads(MODEL.read_text())["measurer"]
    yaw = math.radians(m["frame"]["rpy_deg"][2])  # the example's frame: a turn about z
    assert m["frame"]["rpy_deg"][:2] == [0.0, 0.0]
    r = np.array([[math.cos(yaw), -math.sin(yaw), 0.0],
                  [math.sin(yaw), math.cos(yaw), 0.0], [0.0, 0.0, 1.0]])
    anchors = np.array(m["anchors_mm"]) @ r.T + np.array(m["frame"]["xyz_mm"])
    wires = np.linalg.norm(train["xyz_mm"][:, None, :] - anchors[None, :, :], axis=2)
    dhcal.fit(model, train["q_deg"], wires_mm=wires, directions=train["directions"])
    with pytest.raises(dhcal.DhcalInputError) as e:
        dhcal.fit(model, train["q_deg"], wires_mm=wires / 1000.0, directions=train["directions"])
    assert_refused(e, "wire lengths look like metres")
