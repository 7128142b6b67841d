"""Shared fixtures: case dictionaries built from the shipped smoke case; solver requirements.

A test that needs an external program says so with ``@requires_solver("liggghts", "mpirun")``
(or as a module's ``pytestmark``). When a program is missing the test is skipped on a
developer's machine, but fails under CI (``CI`` set to true, as every CI service does): a
broken install must not turn the solver suite into a pass.
"""

from __future__ import annotations

import copy
import os
import shutil
import tomllib
from pathlib import Path
from typing import Any

import pytest

ROOT = Path(__file__).resolve().parents[1]
CASES = ROOT / "cases"

#: What each program is, for the message when it is missing.
SOLVER_NAMES = {
    "liggghts": "LIGGGHTS (scripts/install.sh)",
    "mpirun": "an MPI launcher (scripts/install.sh)",
    "simpleFoam": "OpenFOAM (simpleFoam; scripts/install.sh)",
}
LIGGGHTS = ("liggghts", "mpirun")
OPENFOAM = ("simpleFoam",)


def requires_solver(*programs: str) -> pytest.MarkDecorator:
    """Mark a test (or module) as needing these programs on PATH."""
    return pytest.mark.requires_solver(*programs)


def under_ci() -> bool:
    """True when the ``CI`` environment variable says so (``true``, ``1`` or ``yes``)."""
    return os.environ.get("CI", "").strip().lower() in {"true", "1", "yes"}


def pytest_configure(config: pytest.Config) -> None:
    config.addinivalue_line(
        "markers", "requires_solver(*programs): needs these programs on PATH; skipped without "
        "them, failed without them under CI=true")


def pytest_runtest_setup(item: pytest.Item) -> None:
    missing = sorted({p for mark in item.iter_markers("requires_solver") for p in mark.args
                      if shutil.which(p) is None})
    if not missing:
        return
    what = ", ".join(SOLVER_NAMES.get(p, p) for p in missing)
    if under_ci():
        pytest.fail(f"missing under CI: {what}; a solver test cannot be skipped there", pytrace=False)
    pytest.skip(f"not installed: {what}")


@pytest.fixture()
def smoke_dict() -> dict[str, Any]:
    """The smoke case as nested dictionaries (a fresh copy per test)."""
    with (CASES / "smoke.toml").open("rb") as fh:
        return copy.deepcopy(tomllib.load(fh))


def tiny_case_dict(**overrides: Any) -> dict[str, Any]:
    """A very small drum for real-solver tests: 0.2 m, 6 lifters, 500 particles of 8 mm."""
    from drumflow.verify.scenes import tiny_drum_dict

    return tiny_drum_dict(**overrides)
