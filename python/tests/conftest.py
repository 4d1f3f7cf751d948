"""Fixtures: the example dataset and the command-line program the package is compared with."""
from __future__ import annotations

import csv
import json
import os
import subprocess
from pathlib import Path
from typing import Any, Dict, List

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[2]
EXAMPLE = ROOT / "examples" / "data" / "compliance"


@pytest.fixture(scope="session")
def cli() -> Path:
    """The dhcal program of the host build (DHCAL_CLI, else build/host/tools/dhcal). The
    comparisons are the point of this suite: without the program they fail, not skip."""
    path = Path(os.environ.get("DHCAL_CLI", ROOT / "build" / "host" / "tools" / "dhcal"))
    if not os.access(path, os.X_OK):
        pytest.fail(f"no dhcal program at {path}: build the host preset or set DHCAL_CLI")
    return path


@pytest.fixture(scope="session")
def run_cli(cli: Path):
    def run(*args: Any) -> Dict[str, Any]:
        out = subprocess.run([str(cli), *map(str, args), "--json"], check=True,
                             capture_output=True, text=True)
        return json.loads(out.stdout)
    return run


def read_csv(path: Path) -> Dict[str, np.ndarray]:
    """The CSV's columns parsed by Python itself (float() rounds decimal text correctly, as
    the C reader's strtod does), independently of the package's reader."""
    with open(path, newline="") as f:
        rows: List[List[str]] = [r for r in csv.reader(f) if r and not r[0].startswith("#")]
    header, body = rows[0], rows[1:]
    return {name: np.array([float(r[k]) for r in body]) for k, name in enumerate(header)}


def columns(path: Path, n_joints: int) -> Dict[str, np.ndarray]:
    c = read_csv(path)
    return {
        "q_deg": np.column_stack([c[f"q{j + 1}"] for j in range(n_joints)]),
        "xyz_mm": np.column_stack([c["x"], c["y"], c["z"]]),
        "directions": np.column_stack([c[f"dir{j + 1}"] for j in range(n_joints)]),
    }
