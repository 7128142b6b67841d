"""Shared hooks and fixtures: solver requirements (see ``support/solvers.py``) and the smoke case.

Test modules import helpers from ``support`` (on the path through ``pythonpath``), never from
this file or from another test file.
"""

from __future__ import annotations

import copy
import shutil
import tomllib
from typing import Any

import pytest
from support.solvers import CASES, SOLVER_NAMES, under_ci


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
