"""dhcal: robot DH-parameter calibration, from Python.

The fit, the diagnosis of missing physical effects and the refine loop are the C code the
``dhcal`` command-line program runs (``dhcal fit|diagnose|refine --json``): the results carry
the same numbers under the same names (docs/cli.md, 1.4), read from the program's own JSON
report. Arrays in and out are numpy arrays: joint angles in degrees (N x joints), tool points
in mm (N x 3).

    >>> model = dhcal.load_model("examples/data/compliance/model.json")
    >>> data = dhcal.load_measurements("examples/data/compliance/train.csv", model)
    >>> result = dhcal.fit(model, data.q_deg, data.xyz_mm, directions=data.directions)
    >>> result.rms_mm, result.parameters[0].name
"""
from __future__ import annotations

import ctypes
import json
import math
import os
import tempfile
from dataclasses import dataclass, field
from typing import Any, Dict, Iterable, List, Optional, Tuple, Union

import numpy as np

from . import _native

__all__ = [
    "DhcalError", "DhcalInputError", "Model", "Measurements", "Parameter", "Unidentifiable",
    "Outlier", "Candidate", "FitResult", "Diagnosis", "RefineResult", "load_model",
    "load_measurements", "fit", "diagnose", "refine", "__version__",
]

__version__: str = _native.LIB.dhcal_py_version().decode("ascii")

PathLike = Union[str, "os.PathLike[str]"]


class DhcalError(Exception):
    """A computation dhcal could not make (the program's exit code 1), or bad input.

    ``result`` holds the report when there is one: a fit that did not converge, or whose
    model is no plausible calibration, is reported (as the program prints its report before
    it exits 1) and refused.
    """

    def __init__(self, message: str, code: int = _native.FAILED,
                 result: Optional["FitResult"] = None) -> None:
        super().__init__(message)
        self.message = message
        self.code = code
        self.result = result


class DhcalInputError(DhcalError, ValueError):
    """Bad input (the program's exit code 2): a file that cannot be read or is invalid (the
    message names the file and the line, or the JSON path), a bad effect name, values out of
    range. Also a ``ValueError``."""

    def __init__(self, message: str) -> None:
        super().__init__(message, _native.BAD_INPUT)


def _raise(code: int, err: ctypes.Array, result: Optional["FitResult"] = None) -> None:
    message = err.value.decode("utf-8", "replace")
    if code == _native.BAD_INPUT:
        raise DhcalInputError(message)
    raise DhcalError(message, code, result)


# ---------------------------------------------------------------- models

class Model:
    """A robot model: what a model file holds (docs/formats.md, section 2), loaded and checked
    by the C file layer. Made by :func:`load_model` or by a fit."""

    def __init__(self, handle: int, origin: str) -> None:
        self._handle: Optional[int] = handle
        info = json.loads(_native.take_text(_native.LIB.dhcal_py_model_info(handle)) or "{}")
        self.name: str = info["name"]
        self.n_joints: int = int(info["n_joints"])
        self.has_measurer: bool = bool(info["has_measurer"])
        self.origin: str = origin  # the file it came from, or what made it

    def __del__(self) -> None:
        handle, self._handle = getattr(self, "_handle", None), None
        if handle:
            _native.LIB.dhcal_py_model_free(handle)

    def _ptr(self) -> int:
        if not self._handle:
            raise ValueError("dhcal: this model was freed")
        return self._handle

    def save(self, path: PathLike) -> None:
        """Writes the model file (the C writer: same schema, written to a temporary file and
        renamed over ``path``, so a failure never leaves a half-written file)."""
        err = _native.err_buffer()
        code = _native.LIB.dhcal_py_model_save(self._ptr(), os.fsencode(path), err,
                                               _native.ERR_CAP)
        if code != _native.OK:
            _raise(code, err)

    def to_dict(self) -> Dict[str, Any]:
        """The model file's content as a dict, as :meth:`save` writes it."""
        with tempfile.TemporaryDirectory() as tmp:
            path = os.path.join(tmp, "model.json")
            self.save(path)
            with open(path, encoding="utf-8") as f:
                return json.load(f)

    def __repr__(self) -> str:
        return f"<dhcal.Model '{self.name}', {self.n_joints} joints, from {self.origin}>"


def load_model(path: PathLike) -> Model:
    """Loads a model file; :class:`DhcalInputError` names the file and the JSON path (or the
    line and column of a syntax error) of a defect."""
    err = _native.err_buffer()
    code = ctypes.c_int(0)
    handle = _native.LIB.dhcal_py_model_load(os.fsencode(path), ctypes.byref(code), err,
                                             _native.ERR_CAP)
    if not handle:
        _raise(code.value, err)
    return Model(handle, os.fspath(path))


# ---------------------------------------------------------------- measurements

@dataclass
class Measurements:
    """Measurement rows: ``q_deg`` (N x joints, degrees), what was measured: ``xyz_mm``
    (N x 3, tool points) or ``wires_mm`` (N x 3, the wire lengths L1..L3 of the model's
    measurer), or both as a file may have both (a model with a measurer fits the wires), and
    the optional columns ``directions`` (N x joints, -1 or +1: the approach direction of each
    joint), ``temp_c`` and ``t_s`` (N each), or None. Touches (docs/formats.md 3.4): ``plane``
    and ``point`` (N each: 0, or the 1-based id of the plane or fixed point the row's tool point
    touched; such a row's ``xyz_mm`` and ``wires_mm`` entries are not read and may be NaN).
    Lengths: ``pair`` and ``distance_mm`` (N each, both or neither: 0, or the 1-based id of the
    length pair the row is one end of, two rows per id; the pair's distance between the two
    rows' tool points in mm on one of its rows at least, 0 elsewhere); a length row measures
    no point either."""

    q_deg: np.ndarray
    xyz_mm: Optional[np.ndarray] = None
    directions: Optional[np.ndarray] = None
    temp_c: Optional[np.ndarray] = None
    t_s: Optional[np.ndarray] = None
    wires_mm: Optional[np.ndarray] = None
    plane: Optional[np.ndarray] = None
    point: Optional[np.ndarray] = None
    pair: Optional[np.ndarray] = None
    distance_mm: Optional[np.ndarray] = None

    def __len__(self) -> int:
        return int(self.q_deg.shape[0])


def load_measurements(path: PathLike, model: Model) -> Measurements:
    """Reads a measurement CSV (docs/formats.md, 4.2) for ``model`` with the C reader the
    program uses; a defect raises :class:`DhcalInputError` naming the file and the line.
    Angles come back in degrees (converted back from the reader's radians: within an ulp of
    the file's values)."""
    err = _native.err_buffer()
    rows = ctypes.c_void_p()
    n = ctypes.c_size_t(0)
    columns = ctypes.c_int(0)
    code = _native.LIB.dhcal_py_rows_load(os.fsencode(path), model._ptr(), ctypes.byref(rows),
                                          ctypes.byref(n), ctypes.byref(columns), err,
                                          _native.ERR_CAP)
    if code != _native.OK:
        _raise(code, err)
    try:
        nr, nj = n.value, model.n_joints
        q = np.empty((nr, nj))
        xyz = np.empty((nr, 3)) if columns.value & 8 else None
        d = np.empty((nr, nj)) if columns.value & 1 else None
        temp = np.empty(nr) if columns.value & 2 else None
        t = np.empty(nr) if columns.value & 4 else None
        wires = np.empty((nr, 3)) if columns.value & 16 else None
        plane = np.empty(nr) if columns.value & 32 else None
        point = np.empty(nr) if columns.value & 64 else None
        pair = np.empty(nr) if columns.value & 128 else None
        dist = np.empty(nr) if columns.value & 128 else None
        _native.LIB.dhcal_py_rows_copy(rows, *(_pointer(a) for a in
                                               (q, xyz, d, temp, t, wires, plane, point, pair,
                                                dist)))
    finally:
        _native.LIB.dhcal_py_rows_free(rows)
    return Measurements(q, xyz, d, temp, t, wires, plane, point, pair, dist)


def _pointer(a: Optional[np.ndarray]) -> Any:
    return None if a is None else a.ctypes.data_as(ctypes.POINTER(ctypes.c_double))


def _array(name: str, value: Any, shape: Tuple[Optional[int], ...]) -> np.ndarray:
    """value as a C-ordered float64 array of the shape (None: any length), every entry
    finite; ValueError otherwise."""
    try:
        a = np.ascontiguousarray(value, dtype=np.float64)
    except (TypeError, ValueError) as e:
        raise ValueError(f"dhcal: {name}: not an array of numbers ({e})") from None
    if len(shape) == 2 and a.ndim == 1 and shape[1] == 1:
        a = a.reshape(-1, 1)
    if a.ndim != len(shape) or any(want is not None and got != want
                                   for got, want in zip(a.shape, shape)):
        want_text = " x ".join("N" if s is None else str(s) for s in shape)
        raise ValueError(f"dhcal: {name}: shape {a.shape}, expected {want_text}")
    bad = ~np.isfinite(a)
    if bad.any():
        where = np.argwhere(bad)[0]
        raise ValueError(f"dhcal: {name}: row {int(where[0]) + 1} holds {a[tuple(where)]}: "
                         "every value must be a finite number")
    return a


class _Rows:
    """Measurement arrays checked and held for one call (ctypes keeps only pointers)."""

    def __init__(self, what: str, model: Model, m: Measurements) -> None:
        q = _array(f"{what} q_deg", m.q_deg, (None, model.n_joints))
        n = q.shape[0]
        if n == 0:
            raise ValueError(f"dhcal: {what}: no rows")
        if (m.xyz_mm is None and m.wires_mm is None and m.plane is None and m.point is None
                and m.pair is None):
            raise ValueError(f"dhcal: {what}: xyz_mm or wires_mm (N x 3, mm) is required, or "
                             "the touches' plane or point ids, or the lengths' pair ids")
        if (m.pair is None) != (m.distance_mm is None):
            raise ValueError(f"dhcal: {what}: pair and distance_mm go together")
        ids = [None if v is None else _array(f"{what} {name}", v, (n,))
               for v, name in ((m.plane, "plane"), (m.point, "point"), (m.pair, "pair"),
                               (m.distance_mm, "distance_mm"))]
        touch = np.zeros(n, dtype=bool)
        for a in ids[:3]:
            if a is not None:
                touch |= a != 0.0
        self.arrays = [q]
        optional = [(m.xyz_mm, "xyz_mm", (n, 3)),
                    (m.directions, "directions", (n, model.n_joints)), (m.temp_c, "temp_c", (n,)),
                    (m.t_s, "t_s", (n,)), (m.wires_mm, "wires_mm", (n, 3))]
        for v, name, shape in optional:
            if v is not None and name in ("xyz_mm", "wires_mm") and touch.any():
                # a touch row measures nothing: its entries are not read (NaN allowed)
                v = np.array(v, dtype=np.float64, copy=True)
                if v.ndim == 2 and v.shape[0] == n:
                    v[touch] = 0.0
            self.arrays.append(None if v is None else _array(f"{what} {name}", v, shape))
        self.arrays += ids
        self.c = _native.Rows(n, *(_pointer(a) for a in self.arrays))


def _measurements(q_deg: Any, xyz_mm: Any, directions: Any, temp_c: Any, t_s: Any,
                  wires_mm: Any) -> Measurements:
    if isinstance(q_deg, Measurements):
        if xyz_mm is not None or wires_mm is not None:
            raise TypeError("dhcal: give Measurements alone, or q_deg and xyz_mm or wires_mm")
        return q_deg
    if xyz_mm is None and wires_mm is None:
        raise TypeError("dhcal: xyz_mm or wires_mm (N x 3, mm) is required with q_deg")
    return Measurements(q_deg, xyz_mm, directions, temp_c, t_s, wires_mm)


def _heldout(heldout: Any) -> Optional[Measurements]:
    if heldout is None or isinstance(heldout, Measurements):
        return heldout
    if isinstance(heldout, (tuple, list)) and len(heldout) in (2, 3):
        return Measurements(*heldout)
    raise TypeError("dhcal: heldout must be Measurements or (q_deg, xyz_mm[, directions])")


# ---------------------------------------------------------------- results

@dataclass(frozen=True)
class Parameter:
    """An identified parameter in display units (docs/cli.md, 1.4): angles in degrees,
    compliances in degrees per mm of moment arm, lengths in mm."""

    name: str
    value: float
    std: float


@dataclass(frozen=True)
class Unidentifiable:
    """A parameter kept at its input value, and those it trades off with."""

    param: str
    confounded_with: Tuple[str, ...]


@dataclass(frozen=True)
class Outlier:
    """A row left out of the fit: 1-based row number, its error, and why (joint_range,
    beyond_reach, robust, residual)."""

    row: int
    error_mm: float
    reason: str


@dataclass(frozen=True)
class Candidate:
    """An effect the diagnosis scored against the fit's residual."""

    effect: str
    joint: Optional[int]
    explained: float
    significant: bool
    log10_p: float
    dof: int
    params: Dict[str, float]
    cv_rms_mm: Optional[float] = None
    verdict: str = ""
    why: str = ""
    look_alikes: Tuple[str, ...] = ()
    screened: bool = False

    @property
    def label(self) -> str:
        """The name ``--effects`` and :func:`fit`'s ``effects`` take: ``joint_compliance:2``."""
        return self.effect if self.joint is None else f"{self.effect}:{self.joint}"


@dataclass
class FitResult:
    """A fit's report (the keys of ``dhcal fit --json``) and the calibrated model."""

    report: Dict[str, Any]
    model: Optional[Model]
    rms_mm: float = field(init=False)
    mean_mm: float = field(init=False)
    max_mm: float = field(init=False)
    iterations: int = field(init=False)
    converged: bool = field(init=False)
    geometry: str = field(init=False)
    parameters: List[Parameter] = field(init=False)
    unidentifiable: List[Unidentifiable] = field(init=False)
    outliers: List[Outlier] = field(init=False)
    sigma_mm: Optional[float] = field(init=False)
    heldout_rms_mm: Optional[float] = field(init=False)
    heldout_mean_mm: Optional[float] = field(init=False)
    cv_rms_mm: Optional[float] = field(init=False)
    adequacy: Optional[Dict[str, Any]] = field(init=False)

    def __post_init__(self) -> None:
        r = self.report
        self.rms_mm, self.mean_mm, self.max_mm = r["rms_mm"], r["mean_mm"], r["max_mm"]
        self.iterations, self.converged = int(r["iterations"]), bool(r["converged"])
        self.geometry = r["geometry"]
        self.parameters = [Parameter(p["name"], p["value"], p["std"]) for p in r["parameters"]]
        self.unidentifiable = [Unidentifiable(u["param"], tuple(u["confounded_with"]))
                               for u in r["unidentifiable"]]
        self.outliers = [Outlier(int(o["row"]), o["error_mm"], o["reason"])
                         for o in r["outliers"]]
        self.sigma_mm = r.get("sigma_mm")
        self.heldout_rms_mm = r.get("heldout_rms_mm")
        self.heldout_mean_mm = r.get("heldout_mean_mm")
        self.cv_rms_mm = r.get("cv_rms_mm")
        self.adequacy = r.get("adequacy")

    def parameter(self, name: str) -> Parameter:
        """The identified parameter called name (KeyError when it is not identified)."""
        for p in self.parameters:
            if p.name == name:
                return p
        raise KeyError(name)

    def summary(self) -> str:
        """The result in a few lines of text."""
        lines = [f"{'converged' if self.converged else 'NOT converged'} after "
                 f"{self.iterations} iterations ({self.geometry} geometry): "
                 f"RMS {self.rms_mm:.4f} mm, max {self.max_mm:.4f} mm"]
        if self.heldout_rms_mm is not None:
            lines.append(f"held-out RMS {self.heldout_rms_mm:.4f} mm")
        if self.cv_rms_mm is not None:
            lines.append(f"cross-validated RMS {self.cv_rms_mm:.4f} mm")
        lines += [f"  {p.name:<18} {p.value:16.8g} +- {p.std:.3g}" for p in self.parameters]
        lines += [f"  not identifiable: {u.param}"
                  + (f" (trades off with {', '.join(u.confounded_with)})"
                     if u.confounded_with else "") for u in self.unidentifiable]
        lines += [f"  outlier: row {o.row}, {o.error_mm:.4f} mm ({o.reason})"
                  for o in self.outliers]
        return "\n".join(lines)


@dataclass
class Diagnosis(FitResult):
    """``dhcal diagnose --json``: the fit, and the candidate effects best first."""

    candidates: List[Candidate] = field(init=False)
    time_pose_r2: float = field(init=False)

    def __post_init__(self) -> None:
        super().__post_init__()
        r = self.report
        self.time_pose_r2 = r["time_pose_r2"]
        self.candidates = [
            Candidate(c["effect"], c["joint"], c["explained"], bool(c["significant"]),
                      c["log10_p"], int(c["dof"]), {p["name"]: p["value"] for p in c["params"]},
                      c.get("cv_rms_mm"), c["verdict"], c["why"], tuple(c["look_alikes"]),
                      bool(c["screened"]))
            for c in r["candidates"]]
        self.best_rejected = r.get("best_rejected")

    @property
    def named(self) -> Optional[Candidate]:
        """The effect to add next (``named`` of the report: what ``refine`` adds first), or
        None."""
        label = self.report.get("named")
        return next((c for c in self.candidates if c.label == label), None)

    def summary(self) -> str:
        best = self.named
        if best is not None:
            head = (f"found: add '{best.label}' (cross-validated RMS {best.cv_rms_mm:.4f} mm)")
            if best.look_alikes:
                head += "; these data cannot tell it from " + ", ".join(best.look_alikes)
        elif self.best_rejected:
            head = (f"no missing effect named: the closest, {self.best_rejected['effect']}: "
                    f"{self.best_rejected['why']}")
        else:
            head = "no missing effect named"
        return super().summary() + "\n" + head


@dataclass
class RefineResult(FitResult):
    """``dhcal refine --json``: the final fit, its effects and the steps that led there."""

    effects: List[str] = field(init=False)
    steps: List[Dict[str, Any]] = field(init=False)
    stopped: str = field(init=False)
    geometry_why: Optional[str] = field(init=False)

    def __post_init__(self) -> None:
        super().__post_init__()
        r = self.report
        self.effects = list(r["effects"])
        self.steps = list(r["steps"])
        self.stopped = r["stopped"]
        self.geometry_why = r.get("geometry_why")

    def summary(self) -> str:
        steps = [f"  step {k}: {s['added'] or '(start)'}: RMS {s['rms_mm']:.4f} mm, "
                 f"CV RMS {s['cv_rms_mm']:.4f} mm" for k, s in enumerate(self.steps)]
        return "\n".join([*steps, f"stopped: {self.stopped}",
                          f"effects: {', '.join(self.effects) or '(none)'}", super().summary()])


# ---------------------------------------------------------------- commands

Effects = Union[str, Iterable[str]]


def _run(command: str, model: Model, data: Measurements, effects: Effects,
         heldout: Optional[Measurements], noise: Optional[Tuple[float, float]],
         geometry: Optional[str], cv: bool,
         check_units: bool) -> Tuple[int, Dict[str, Any], Optional[Model], Any]:
    if not isinstance(model, Model):
        raise TypeError("dhcal: model must be a dhcal.Model (dhcal.load_model)")
    train = _Rows("training data", model, data)
    held = _Rows("held-out data", model, heldout) if heldout is not None else None
    effect_list = effects if isinstance(effects, str) else ",".join(effects)
    if check_units:
        # the program's check before any fit: metres, radians, swapped columns, a frame
        err = _native.err_buffer()
        held_c = ctypes.byref(held.c) if held is not None else None
        code = _native.LIB.dhcal_py_units_check(model._ptr(), ctypes.byref(train.c), held_c,
                                                _native.encode(effect_list), err,
                                                _native.ERR_CAP)
        if code != _native.OK:
            _raise(code, err)
    noise_text = None
    if noise is not None:
        joint_deg, meas_mm = (float(v) for v in noise)
        if not (math.isfinite(joint_deg) and math.isfinite(meas_mm)):
            raise ValueError("dhcal: noise must be two finite numbers (joint_deg, meas_mm)")
        noise_text = f"{joint_deg!r},{meas_mm!r}"  # repr: the shortest text of the same double
    report = ctypes.c_void_p()
    fitted = ctypes.c_void_p()
    err = _native.err_buffer()
    code = _native.LIB.dhcal_py_run(
        command.encode(), model._ptr(), ctypes.byref(train.c),
        ctypes.byref(held.c) if held is not None else None, _native.encode(effect_list),
        _native.encode(noise_text), _native.encode(geometry), int(bool(cv)),
        ctypes.byref(report), ctypes.byref(fitted), err, _native.ERR_CAP)
    text = _native.take_text(report.value)
    out_model = Model(fitted.value, f"dhcal.{command}") if fitted.value else None
    return code, json.loads(text) if text is not None else {}, out_model, err


def _finish(cls: type, code: int, report: Dict[str, Any], model: Optional[Model],
            err: Any) -> Any:
    result = cls(report, model) if report else None
    if code != _native.OK:
        _raise(code, err, result)
    return result


def fit(model: Model, q_deg: Any, xyz_mm: Any = None, effects: Effects = (),
        heldout: Any = None, *, directions: Any = None, temp_c: Any = None, t_s: Any = None,
        wires_mm: Any = None, noise: Optional[Tuple[float, float]] = None,
        geometry: Optional[str] = None, cv: bool = False,
        check_units: bool = True) -> FitResult:
    """Least-squares calibration of ``model`` to the measured tool points, as ``dhcal fit``.

    q_deg: joint angles, N x joints, degrees (or a :class:`Measurements`, then no xyz_mm).
    xyz_mm: measured tool points, N x 3, mm; or wires_mm: the wire lengths L1..L3 of the
    model's measurer, N x 3, mm (the paper's draw-wire instrument). effects: effect names to fit besides the base
    model (``["joint_compliance:2"]`` or ``"base_frame,tool_offset"``). heldout:
    :class:`Measurements` or ``(q_deg, xyz_mm)`` evaluated with the fitted model, never
    fitted. directions, temp_c, t_s: the optional columns. noise: ``(joint_deg, meas_mm)``
    weights every row by its covariance (``--noise``). geometry: ``"offsets"``,
    ``"lengths"`` or ``"full"``. cv: also cross-validate (``cv_rms_mm``). check_units:
    before any fit, compare the data with the nominal model (docs/python.md, 3.1) and refuse
    positions or wire lengths that look like metres, angles that look like radians, two
    swapped columns, and points in another frame than the model's base unless effects has
    ``base_frame``; False goes on regardless.

    Raises ValueError for arrays of the wrong shape or with NaN or infinite values,
    :class:`DhcalInputError` (also a ValueError) for values the measurement rules refuse, a
    bad effect name or data the units check refuses (the message names the cause), and
    :class:`DhcalError` when the fit fails, does not converge or is no plausible calibration
    (``error.result`` holds the report then)."""
    data = _measurements(q_deg, xyz_mm, directions, temp_c, t_s, wires_mm)
    return _finish(FitResult, *_run("fit", model, data, effects, _heldout(heldout), noise,
                                    geometry, cv, check_units))


def diagnose(model: Model, q_deg: Any, xyz_mm: Any = None, effects: Effects = (),
             heldout: Any = None, *, directions: Any = None, temp_c: Any = None,
             t_s: Any = None, wires_mm: Any = None,
             noise: Optional[Tuple[float, float]] = None, geometry: Optional[str] = None,
             cv: bool = False, check_units: bool = True) -> Diagnosis:
    """``dhcal diagnose``: ``refine``'s start and its first judgement: every effect of the
    catalogue the model does not have is screened by the score test, the six best are
    refitted on the same rows and cross-validated on the same folds, and the one whose gain
    holds over the folds, with a size above the noise reference and physical, is named
    (docs/effects.md 6). ``result.named`` is the effect to add next (``refine``'s first
    step), or None; ``result.best_rejected`` the closest that fell short. Arguments as
    :func:`fit`; cv is accepted and changes nothing (the judgement always
    cross-validates)."""
    data = _measurements(q_deg, xyz_mm, directions, temp_c, t_s, wires_mm)
    return _finish(Diagnosis, *_run("diagnose", model, data, effects, _heldout(heldout),
                                    noise, geometry, cv, check_units))


def refine(model: Model, q_deg: Any, xyz_mm: Any = None, effects: Effects = (),
           heldout: Any = None, *, directions: Any = None, temp_c: Any = None,
           t_s: Any = None, wires_mm: Any = None,
           noise: Optional[Tuple[float, float]] = None,
           geometry: Optional[str] = None, check_units: bool = True) -> RefineResult:
    """``dhcal refine``: from the base model plus ``effects`` (the start set), adds the
    effect the judgement names (as :func:`diagnose`) and judges again until none passes;
    held-out rows are evaluated at every step, never used to choose. Arguments as
    :func:`fit`; ``result.model`` is the final calibrated model."""
    data = _measurements(q_deg, xyz_mm, directions, temp_c, t_s, wires_mm)
    return _finish(RefineResult, *_run("refine", model, data, effects, _heldout(heldout),
                                       noise, geometry, False, check_units))
