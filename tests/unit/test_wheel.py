"""A non-editable install works: build the wheel, install it into a fresh virtual environment,
and use it from outside the source tree (templates and data found as package data).

Only drumflow comes from the wheel. Its dependencies (numpy, gmsh, pyvista, ...) are taken from
the test environment through a ``.pth`` line, so the test needs no network and no second copy
of several hundred megabytes; the test asserts that ``drumflow`` itself is imported from the
fresh environment, not from the checkout. The wheel is built without build isolation, with
the test environment's setuptools (>= 77, in the ``test`` extra).
"""

from __future__ import annotations

import json
import os
import shutil
import site
import subprocess
import sys
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest
from support.solvers import LIGGGHTS, requires_solver

ROOT = Path(__file__).resolve().parents[2]

pytestmark = [pytest.mark.wheel, pytest.mark.timeout(900)]


def _run(command: list[str], cwd: Path, timeout: float = 600, env: dict[str, str] | None = None
         ) -> subprocess.CompletedProcess[str]:
    proc = subprocess.run(command, cwd=cwd, capture_output=True, text=True, timeout=timeout,
                          check=False, env=env)
    assert proc.returncode == 0, f"{' '.join(command)}\n{proc.stdout[-2000:]}\n{proc.stderr[-3000:]}"
    return proc


@pytest.fixture(scope="module")
def wheel_venv(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A fresh virtual environment with drumflow installed from a freshly built wheel."""
    tmp = tmp_path_factory.mktemp("wheel")
    # Build from a copy: a build inside the checkout would leave build/ and *.egg-info there.
    src = tmp / "src"
    shutil.copytree(ROOT, src, ignore=shutil.ignore_patterns(
        ".venv", ".git", "runs", "build", "*.egg-info", "__pycache__", ".pytest_cache", "tests"))
    dist = tmp / "dist"
    _run([sys.executable, "-m", "pip", "wheel", "--no-deps", "--no-build-isolation", "-q",
          "-w", str(dist), str(src)], cwd=tmp)
    wheels = list(dist.glob("drumflow-*.whl"))
    assert len(wheels) == 1
    venv = tmp / "venv"
    _run([sys.executable, "-m", "venv", "--without-pip", str(venv)], cwd=tmp)
    python = venv / "bin" / "python"
    _run([sys.executable, "-m", "pip", "--python", str(python), "install", "-q", "--no-deps",
          str(wheels[0])], cwd=tmp)
    purelib = subprocess.run([str(python), "-c", "import sysconfig; print(sysconfig.get_paths()['purelib'])"],
                             capture_output=True, text=True, check=True).stdout.strip()
    # The dependencies: the test environment's site-packages, appended after the fresh one (a
    # .pth in the appended folder, such as the checkout's editable finder, is not processed).
    Path(purelib, "zz_test_dependencies.pth").write_text("\n".join(site.getsitepackages()) + "\n")
    return venv


def _clean_env() -> dict[str, str]:
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "DRUMFLOW_TEMPLATES")}
    return env


def test_wheel_renders_a_deck_and_finds_its_data(wheel_venv: Path, tmp_path: Path) -> None:
    code = """
import json, drumflow, drumflow.dem.deck as deck, drumflow.skips as skips
from drumflow.dem.stage import plan_run
from drumflow.verify.scenes import tiny_drum
case = tiny_drum(air__model="uniform")
choice, plan = plan_run(case)
text = deck.render_deck(deck.deck_context(case, plan, deck.DeckFiles(), coupled=True))
print(json.dumps({"file": drumflow.__file__, "deck": text, "end": deck.end_commands(
    deck.deck_context(case, plan, deck.DeckFiles())), "measured": bool(skips.measured())}))
"""
    proc = _run([str(wheel_venv / "bin" / "python"), "-c", code], cwd=tmp_path, env=_clean_env())
    out = json.loads(proc.stdout)
    assert Path(out["file"]).is_relative_to(wheel_venv), out["file"]
    assert "run" in out["deck"] and "fix" in out["deck"] and "{{" not in out["deck"]
    assert out["end"], "the closing commands (drum_end.in.j2) rendered empty"
    assert out["measured"] is True  # drumflow/data/measured_smoke.json shipped


def test_wheel_writes_the_report(wheel_venv: Path, tmp_path: Path,
                                 write_synthetic_run: Callable[..., Any]) -> None:
    run = write_synthetic_run(tmp_path / "run")
    page = tmp_path / "report.html"
    _run([str(wheel_venv / "bin" / "drumflow"), "report", str(run), "--out", str(page), "--no-3d"],
         cwd=tmp_path, env=_clean_env())
    html = page.read_text()
    assert html.startswith("<!DOCTYPE html>") and "Table 6" in html


@pytest.mark.slow
@pytest.mark.solver
@requires_solver(*LIGGGHTS)  # skipped without LIGGGHTS on a workstation, failed under CI
def test_wheel_runs_verify_quick(wheel_venv: Path, tmp_path: Path) -> None:
    proc = subprocess.run([str(wheel_venv / "bin" / "drumflow"), "verify", "--quick", "--out",
                           str(tmp_path / "verify")], cwd=tmp_path, capture_output=True, text=True,
                          timeout=840, check=False, env=_clean_env())
    assert proc.returncode == 0, proc.stdout[-3000:] + proc.stderr[-3000:]
    assert (tmp_path / "verify" / "verification.json").is_file()
