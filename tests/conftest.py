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
    from drumflow.verify.scenes import tiny_drum_dict

    return tiny_drum_dict(**overrides)
