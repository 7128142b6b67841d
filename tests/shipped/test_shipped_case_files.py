"""The shipped case files under cases/: the sweep file names both executors.

Shipped files only: these tests read files under cases/ and compare what they hold; no drumflow
code runs, so they test no code (marker ``shipped``; tests/shipped holds them apart from the
tests of code). The sweep file through drumflow's own reader: tests/unit/test_sweep_spec.py.
"""

from __future__ import annotations

import tomllib
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]

pytestmark = pytest.mark.shipped


def test_shipped_sweep_file_is_valid_toml_with_both_executors() -> None:
    data = tomllib.loads((ROOT / "cases" / "sweep_smoke.toml").read_text())
    assert data["executor"]["kind"] == "local" and "slurm" in data["executor"]
