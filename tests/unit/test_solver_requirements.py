"""A missing solver skips its tests on a workstation but fails the run under CI (CI=true)."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
TEST = "tests/solver/test_contacts_liggghts.py::test_restitution_uncorrected_is_far_low"


def _pytest_without_solvers(ci: str | None) -> subprocess.CompletedProcess[str]:
    env = {k: v for k, v in os.environ.items() if k != "CI"}
    env["PATH"] = "/nonexistent"  # no liggghts, no mpirun on PATH
    if ci is not None:
        env["CI"] = ci
    return subprocess.run([sys.executable, "-m", "pytest", "-p", "no:cacheprovider", "-q", "-rs", TEST],
                          cwd=ROOT, env=env, capture_output=True, text=True, timeout=300, check=False)


@pytest.mark.parametrize("ci", ["true", "1"])
def test_missing_solver_fails_under_ci(ci: str) -> None:
    out = _pytest_without_solvers(ci)
    assert out.returncode != 0, out.stdout[-2000:]
    assert "missing under CI" in out.stdout and "LIGGGHTS" in out.stdout


def test_missing_solver_skips_on_a_workstation() -> None:
    out = _pytest_without_solvers(None)
    assert out.returncode == 0, out.stdout[-2000:]
    assert "1 skipped" in out.stdout and "not installed: LIGGGHTS" in out.stdout
