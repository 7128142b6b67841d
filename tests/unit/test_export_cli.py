"""`drumflow export`: bad input exits 2 with one message and no traceback (no solver needed;
tests/solver/test_export.py exports a real run)."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["--vtk"], "not a directory"),
        ([], "choose one export format: --vtk, --animation or --state"),
        (["--vtk", "--animation"], "choose one export format: --vtk, --animation or --state"),
        (["--vtk", "--time", "1.0"], "--time is for --state"),
        (["--state"], "no case.toml"),
        (["--vtk", "--phases", "2"], "--phases is for --state"),
        (["--state", "--phases", "9"], "--phases"),
        (["--state", "--phases", "2"], "no case.toml"),
    ],
)
def test_export_bad_input(tmp_path: Path, args: list[str], message: str) -> None:
    target = tmp_path / "missing" if args == ["--vtk"] else tmp_path
    out = subprocess.run([sys.executable, "-m", "drumflow.cli", "export", str(target), *args],
                         capture_output=True, text=True, timeout=120, check=False)
    text = out.stdout + out.stderr
    assert out.returncode == 2, text
    assert message in " ".join(text.split())
    assert "Traceback" not in text


def test_export_of_a_directory_without_snapshots(tmp_path: Path) -> None:
    from drumflow.errors import RunDirectoryError
    from drumflow.report.vtk import export_vtk

    (tmp_path / "case.toml").write_text("")
    with pytest.raises(RunDirectoryError):
        export_vtk(tmp_path)
