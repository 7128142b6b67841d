"""Fixtures of the unit tests: the synthetic run directory with a known h
(:mod:`support.synthetic_run`) for the methodology, report and predict tests."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import pytest
from support import synthetic_run


@pytest.fixture(scope="session")
def write_synthetic_run() -> Callable[..., Any]:
    """:func:`support.synthetic_run.write_synthetic_run`: a run directory with a known h."""
    return synthetic_run.write_synthetic_run


@pytest.fixture(scope="session")
def synthetic_case_dict() -> Callable[..., dict[str, Any]]:
    """:func:`support.synthetic_run.synthetic_case_dict`: the synthetic run's case as dicts."""
    return synthetic_run.synthetic_case_dict
