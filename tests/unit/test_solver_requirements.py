"""A missing requirement (a solver, Chromium, CoolProp; support/requirements.py) skips its tests
on a workstation but fails the run under CI (CI=true), naming what is missing."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest
from support.requirements import missing, missing_modules, missing_programs

ROOT = Path(__file__).resolve().parents[2]
TEST = "tests/solver/test_contacts_liggghts.py::test_restitution_uncorrected_is_far_low"
CHROMIUM_TEST = "tests/unit/test_report_chromium.py::test_report_renders_in_chromium"
COOLPROP_TEST = "tests/unit/test_grate_air_properties.py::test_hottest_rows_stay_near_coolprop[1600.0]"


def _pytest_without(test: str, ci: str | None, **env_over: str) -> subprocess.CompletedProcess[str]:
    env = {k: v for k, v in os.environ.items() if k != "CI"}
    env.update(env_over)
    if ci is not None:
        env["CI"] = ci
    return subprocess.run([sys.executable, "-m", "pytest", "-p", "no:cacheprovider", "-q", "-rs", test],
                          cwd=ROOT, env=env, capture_output=True, text=True, timeout=300, check=False)


def _pytest_without_solvers(ci: str | None) -> subprocess.CompletedProcess[str]:
    return _pytest_without(TEST, ci, PATH="/nonexistent")  # no liggghts, no mpirun on PATH


def _shadowed_coolprop(tmp_path: Path) -> str:
    """A folder for PYTHONPATH whose ``CoolProp`` package fails to import, as a broken install."""
    package = tmp_path / "shadow" / "CoolProp"
    package.mkdir(parents=True)
    (package / "__init__.py").write_text('raise ImportError("CoolProp shadowed by the test")\n')
    return str(package.parent)


@pytest.mark.parametrize("ci", ["true", "1"])
def test_missing_solver_fails_under_ci(ci: str) -> None:
    out = _pytest_without_solvers(ci)
    assert out.returncode != 0, out.stdout[-2000:]
    assert "missing under CI" in out.stdout and "LIGGGHTS" in out.stdout


def test_missing_solver_skips_on_a_workstation() -> None:
    out = _pytest_without_solvers(None)
    assert out.returncode == 0, out.stdout[-2000:]
    assert "1 skipped" in out.stdout and "not installed: LIGGGHTS" in out.stdout


@pytest.mark.parametrize("what", ["chromium", "coolprop"])
def test_missing_chromium_or_coolprop_fails_under_ci_and_skips_elsewhere(what: str, tmp_path: Path) -> None:
    if what == "chromium":
        test, env, name = CHROMIUM_TEST, {"PATH": "/nonexistent"}, "Chromium"
    else:
        test, env, name = COOLPROP_TEST, {"PYTHONPATH": _shadowed_coolprop(tmp_path)}, "CoolProp"
    failed = _pytest_without(test, "true", **env)
    assert failed.returncode == 1, failed.stdout[-2000:]
    assert "1 error" in failed.stdout, failed.stdout[-2000:]  # failed in its setup
    assert "missing under CI (not installed)" in failed.stdout and name in failed.stdout
    skipped = _pytest_without(test, None, **env)
    assert skipped.returncode == 0, skipped.stdout[-2000:]
    assert "1 skipped" in skipped.stdout and f"not installed: {name}" in skipped.stdout


def test_the_rule_itself(monkeypatch: pytest.MonkeyPatch) -> None:
    """In process: CI set to true, 1 or yes fails; unset, empty or false skips."""
    for ci in ("true", "1", "YES"):
        monkeypatch.setenv("CI", ci)
        with pytest.raises(pytest.fail.Exception, match=r"missing under CI \(no cluster\): SLURM"):
            missing("SLURM", "no cluster")
    for ci in ("", "false"):
        monkeypatch.setenv("CI", ci)
        with pytest.raises(pytest.skip.Exception, match="not installed: SLURM"):
            missing("SLURM")
    monkeypatch.delenv("CI")
    with pytest.raises(pytest.skip.Exception):
        missing("SLURM")


def test_what_is_found_missing() -> None:
    assert missing_programs([sys.executable, "no-such-program-drumflow"]) == ["no-such-program-drumflow"]
    assert missing_modules(["json", "no_such_module_drumflow.sub"]) == ["no_such_module_drumflow.sub"]
