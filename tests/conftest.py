"""Shared hooks and fixtures: what a test needs (solvers, programs, Python packages; skipped
without them, failed under CI: ``support/requirements.py``) and the smoke case.

Test modules import helpers from ``support`` (on the path through ``pythonpath``), never from
this file or from another test file.
"""

from __future__ import annotations

import copy
import tomllib
from typing import Any

import pytest
from support.requirements import (
    MODULE_NAMES,
    PROGRAM_NAMES,
    missing,
    missing_modules,
    missing_programs,
)
from support.solvers import CASES, SOLVER_NAMES


def pytest_configure(config: pytest.Config) -> None:
    for marker, needs in (("requires_solver(*programs)", "these solvers on PATH"),
                          ("requires_program(*programs)", "these programs on PATH"),
                          ("requires_module(*modules)", "these Python packages importable")):
        config.addinivalue_line(
            "markers", f"{marker}: needs {needs}; skipped without them, failed without them "
            "under CI=true")


def _args(item: pytest.Item, marker: str) -> list[str]:
    return [a for mark in item.iter_markers(marker) for a in mark.args]


def pytest_runtest_setup(item: pytest.Item) -> None:
    names = {**PROGRAM_NAMES, **SOLVER_NAMES}
    absent = [names.get(p, p) for p in
              missing_programs(_args(item, "requires_solver") + _args(item, "requires_program"))]
    absent += [MODULE_NAMES.get(m, m) for m in missing_modules(_args(item, "requires_module"))]
    if absent:
        missing(", ".join(absent))


@pytest.fixture()
def smoke_dict() -> dict[str, Any]:
    """The smoke case as nested dictionaries (a fresh copy per test)."""
    with (CASES / "smoke.toml").open("rb") as fh:
        return copy.deepcopy(tomllib.load(fh))
