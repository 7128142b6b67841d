"""The physics floor's shared helpers: one relative error for verification and the ladders."""

from __future__ import annotations

import math

import numpy as np
import pytest

from drumflow.physics.validation import readonly, relative_error


def test_relative_error_of_ordinary_numbers() -> None:
    assert relative_error(1.1, 1.0) == pytest.approx(0.1)
    assert relative_error(-0.9, -1.0) == pytest.approx(0.1)


def test_relative_error_against_a_zero_reference_is_undefined() -> None:
    # Verification once returned |value| here and the ladders NaN; an error relative to zero
    # has no meaning, and NaN fails every check instead of passing a small absolute number.
    assert math.isnan(relative_error(0.0, 0.0))
    assert math.isnan(relative_error(1e-9, 0.0))
    assert math.isnan(relative_error(1.0, -0.0))


def test_relative_error_of_missing_numbers_is_nan() -> None:
    assert math.isnan(relative_error(None, 1.0))
    assert math.isnan(relative_error(1.0, None))
    assert math.isnan(relative_error(math.nan, 1.0))
    assert math.isnan(relative_error(1.0, math.inf))
    assert relative_error(math.inf, 1.0) == math.inf


def test_readonly_locks_the_array() -> None:
    arr = readonly(np.zeros(3))
    with pytest.raises(ValueError):
        arr[0] = 1.0
