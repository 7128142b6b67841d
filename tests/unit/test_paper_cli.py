"""`drumflow paper`: bad input exits 2 naming what was wrong, before anything runs; the page is
written from existing directories without a solver.

Each command runs as a real subprocess (``python -m drumflow.cli``), as a user would see it.
"""

from __future__ import annotations

import json
import subprocess
import sys
import tomllib
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest
import tomli_w

CASES = Path(__file__).resolve().parents[2] / "cases"


def _cli(*args: str, cwd: Path | None = None) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-m", "drumflow.cli", "paper", *args], capture_output=True,
                          text=True, timeout=300, check=False, cwd=cwd)


def _bad_model_case(tmp_path: Path) -> str:
    data = tomllib.loads((CASES / "paper_model_one.toml").read_text())
    data["drum"]["rpm"] = -5.0
    path = tmp_path / "bad_model_one.toml"
    path.write_text(tomli_w.dumps(data))
    return str(path)


BAD: list[tuple[str, Callable[[Path], list[str]], list[str]]] = [
    ("model", lambda t: ["--model", "three", "--out", str(t / "out")], ["--model", "three", "'both'"]),
    ("np", lambda t: ["--np", "0", "--out", str(t / "out")], ["--np", "greater than or equal to 1"]),
    ("case_with_both", lambda t: ["--case", str(CASES / "smoke.toml"), "--out", str(t / "out")],
     ["--case", "--model one"]),
    ("case_with_from", lambda t: ["--model", "one", "--case", str(CASES / "smoke.toml"), "--from",
                                  str(t)], ["--from", "--case"]),
    ("bad_case", lambda t: ["--model", "one", "--case", _bad_model_case(t), "--out", str(t / "out")],
     ["drum.rpm = -5"]),
    ("from_missing", lambda t: ["--from", str(t / "nowhere"), "--out", str(t / "out")], ["nowhere"]),
    ("from_empty", lambda t: ["--from", str(t), "--out", str(t / "out")], ["model_one/", "model_two/"]),
]


@pytest.mark.parametrize(("build", "named"), [pytest.param(b, n, id=i) for i, b, n in BAD])
def test_bad_input_exits_2(tmp_path: Path, build: Callable[[Path], list[str]], named: list[str]) -> None:
    out = _cli(*build(tmp_path))
    text = out.stdout + out.stderr
    assert out.returncode == 2, text
    assert "Traceback" not in text
    flat = " ".join(text.replace("│", " ").split())
    for piece in named:
        assert piece in flat, (piece, text)
    # Nothing ran: no model directory was started.
    assert not (tmp_path / "out" / "model_one").exists()


def test_page_from_existing_directories(tmp_path: Path, write_synthetic_run: Callable[..., Any]) -> None:
    """--from on run directories: the comparison is written without any solver."""
    write_synthetic_run(tmp_path / "runs" / "model_one")
    out = _cli("--from", str(tmp_path / "runs"), "--out", str(tmp_path / "out"), "--no-3d", "--json")
    assert out.returncode == 0, out.stderr
    printed = json.loads(out.stdout)
    assert set(printed["models"]) == {"one"}  # model two is absent and is not invented
    rows = {r["quantity"]: r for r in printed["models"]["one"]["comparison"]}
    assert rows["heat-transfer coefficient h"]["paper"] == 60.15
    for name in ("paper.json", "comparison.csv", "paper.html"):
        assert (tmp_path / "out" / name).is_file()
    # The model's derived files are cached in the run's post/ folder.
    assert (tmp_path / "runs" / "model_one" / "post" / "methodology.json").is_file()
