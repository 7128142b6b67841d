"""Shared fixtures: case dictionaries built from the shipped smoke case."""

from __future__ import annotations

import copy
import tomllib
from pathlib import Path
from typing import Any

import pytest

ROOT = Path(__file__).resolve().parents[1]
CASES = ROOT / "cases"


@pytest.fixture()
def smoke_dict() -> dict[str, Any]:
    """The smoke case as nested dictionaries (a fresh copy per test)."""
    with (CASES / "smoke.toml").open("rb") as fh:
        return copy.deepcopy(tomllib.load(fh))


def tiny_case_dict(**overrides: Any) -> dict[str, Any]:
    """A very small drum for real-solver tests: 0.2 m, 6 lifters, 500 particles of 8 mm."""
    with (CASES / "smoke.toml").open("rb") as fh:
        d = tomllib.load(fh)
    d["name"] = "tiny"
    d["drum"].update(diameter=0.2, length=0.048, rpm=30.0)
    d["lifters"].update(count=6, base_height=0.025, lip_length=0.012, thickness=0.003)
    d["particles"].update(count=500)
    d["run"].update(time=1.2, dump_interval=0.01, snapshot_interval=0.1, mass_flow_start=0.6,
                    restart_interval=0.2)
    for key, value in overrides.items():
        section, field = key.split("__")
        d[section][field] = value
    return d
