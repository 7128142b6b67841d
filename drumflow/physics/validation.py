"""Argument checks shared by the analysis modules and the coolers, relative error, read-only arrays.

Every pure function in :mod:`drumflow.analysis` validates its inputs through these helpers so
that a bad value always produces the same kind of message: the argument name, the offending
value and the range that would have been accepted. Keeping one helper per kind of check (in the
style of PyVista's ``_validation`` module) avoids a dozen slightly different wordings.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import TypeVar

import numpy as np
from numpy.typing import ArrayLike, NDArray

from drumflow.errors import AnalysisInputError

__all__ = [
    "AnalysisInputError",
    "as_float_array",
    "check_finite",
    "check_positive",
    "check_range",
    "check_same_length",
    "exactly_one",
    "readonly",
    "relative_error",
]


def check_finite(name: str, value: object) -> float:
    """Return ``value`` as a float, or raise if it is not a finite real number.

    Parameters
    ----------
    name
        Argument name used in the error message.
    value
        The value to check.

    Returns
    -------
    float
        The value converted to ``float``.

    Raises
    ------
    AnalysisInputError
        If the value is not a real scalar or is NaN/infinite.
    """
    if isinstance(value, bool):
        # bool is an int subclass; True as a temperature is almost surely a bug.
        raise AnalysisInputError(name, value, "a finite real number")
    try:
        out = float(value)  # type: ignore[arg-type]
    except (TypeError, ValueError):
        raise AnalysisInputError(name, value, "a finite real number") from None
    if not math.isfinite(out):
        raise AnalysisInputError(name, out, "a finite real number")
    return out


def check_positive(name: str, value: object) -> float:
    """Return ``value`` as a float, or raise unless it is finite and strictly positive.

    Parameters
    ----------
    name
        Argument name used in the error message.
    value
        The value to check.

    Returns
    -------
    float
        The value converted to ``float``.

    Raises
    ------
    AnalysisInputError
        If the value is not finite or is ``<= 0``.
    """
    out = check_finite(name, value)
    if out <= 0.0:
        raise AnalysisInputError(name, out, "a finite number > 0")
    return out


def check_range(
    name: str,
    value: object,
    low: float | None = None,
    high: float | None = None,
    *,
    low_inclusive: bool = True,
    high_inclusive: bool = True,
) -> float:
    """Return ``value`` as a float, or raise unless it lies in the given interval.

    Parameters
    ----------
    name
        Argument name used in the error message.
    value
        The value to check.
    low, high
        Interval bounds; ``None`` means unbounded on that side.
    low_inclusive, high_inclusive
        Whether the bounds themselves are accepted.

    Returns
    -------
    float
        The value converted to ``float``.

    Raises
    ------
    AnalysisInputError
        If the value is not finite or is outside the interval.
    """
    out = check_finite(name, value)
    too_low = low is not None and (out < low or (not low_inclusive and out == low))
    too_high = high is not None and (out > high or (not high_inclusive and out == high))
    if too_low or too_high:
        raise AnalysisInputError(
            name, out, _interval(low, high, low_inclusive, high_inclusive)
        )
    return out


def _interval(
    low: float | None, high: float | None, low_inclusive: bool, high_inclusive: bool
) -> str:
    if low is not None and high is not None:
        left = "[" if low_inclusive else "("
        right = "]" if high_inclusive else ")"
        return f"a value in {left}{low:g}, {high:g}{right}"
    if low is not None:
        return f"a value {'>=' if low_inclusive else '>'} {low:g}"
    if high is not None:
        return f"a value {'<=' if high_inclusive else '<'} {high:g}"
    return "a finite real number"


def as_float_array(
    name: str,
    values: ArrayLike,
    *,
    min_size: int = 1,
    positive: bool = False,
    allow_nan: bool = False,
) -> NDArray[np.float64]:
    """Convert ``values`` to a 1-D float array and check its contents.

    Parameters
    ----------
    name
        Argument name used in the error message.
    values
        Anything :func:`numpy.asarray` accepts; scalars become length-1 arrays.
    min_size
        Minimum number of elements.
    positive
        Require every (non-NaN) element to be ``> 0``.
    allow_nan
        Accept NaN elements (used for per-step series where NaN marks a masked step).
        Infinite values are always rejected.

    Returns
    -------
    numpy.ndarray
        A new 1-D ``float64`` array (a copy, so callers may not alias the input).

    Raises
    ------
    AnalysisInputError
        If the input is not numeric, not 1-D, too short, or has a rejected element; the message
        names the first offending index.
    """
    try:
        arr = np.array(values, dtype=np.float64, copy=True)
    except (TypeError, ValueError):
        raise AnalysisInputError(name, values, "a 1-D sequence of real numbers") from None
    if arr.ndim == 0:
        arr = arr.reshape(1)
    if arr.ndim != 1:
        raise AnalysisInputError(name, f"array of shape {arr.shape}", "a 1-D sequence")
    if arr.size < min_size:
        raise AnalysisInputError(
            name, f"{arr.size} value(s)", f"at least {min_size} value(s)"
        )
    bad = np.isinf(arr) if allow_nan else ~np.isfinite(arr)
    if bad.any():
        i = int(np.flatnonzero(bad)[0])
        what = "finite numbers or NaN" if allow_nan else "finite numbers"
        raise AnalysisInputError(f"{name}[{i}]", float(arr[i]), what)
    if positive:
        with np.errstate(invalid="ignore"):
            nonpos = arr <= 0.0
        if nonpos.any():
            i = int(np.flatnonzero(nonpos)[0])
            raise AnalysisInputError(f"{name}[{i}]", float(arr[i]), "numbers > 0")
    return arr


def check_same_length(arrays: Sequence[tuple[str, NDArray[np.float64]]]) -> int:
    """Raise unless all named arrays have the same length; return that length.

    Parameters
    ----------
    arrays
        ``(name, array)`` pairs; the first one sets the expected length.

    Returns
    -------
    int
        The common length.

    Raises
    ------
    AnalysisInputError
        Naming the first array whose length differs.
    """
    first_name, first = arrays[0]
    n = int(first.shape[0])
    for name, arr in arrays[1:]:
        if arr.shape[0] != n:
            raise AnalysisInputError(
                name, f"{arr.shape[0]} value(s)", f"{n} value(s), as many as {first_name}"
            )
    return n


def exactly_one(**named: object) -> str:
    """Return the name of the single argument that is not ``None``.

    Used where a function accepts one of two alternative inputs (for example a falling mass per
    step or a falling mass flow).

    Raises
    ------
    AnalysisInputError
        If none or more than one of the arguments is given.
    """
    given = [k for k, v in named.items() if v is not None]
    if len(given) != 1:
        names = " or ".join(named)
        shown = ", ".join(given) if given else "none"
        raise AnalysisInputError(names, f"given: {shown}", "exactly one of them")
    return given[0]


def relative_error(value: float | None, reference: float | None) -> float:
    """``|value - reference| / |reference|``, NaN where it has no meaning.

    NaN when either number is missing (None or NaN), when the reference is not finite, and when
    the reference is zero: an error relative to zero is undefined, and returning ``|value|``
    instead (as the verification checks once did) would compare an absolute number with a
    relative tolerance. A NaN error fails every check (it compares false) and leaves a gap in a
    ladder's error column, so an undefined error is never mistaken for a small one. An infinite
    ``value`` against a finite reference gives ``inf``.
    """
    if value is None or reference is None or math.isnan(value) or not math.isfinite(reference):
        return math.nan
    if reference == 0.0:
        return math.nan
    return abs(value - reference) / abs(reference)


_A = TypeVar("_A", bound=np.ndarray)


def readonly(arr: _A) -> _A:
    """Lock an array against writes and return it.

    Frozen dataclass fields can still be mutated in place; the per-step results lock their
    arrays too, so a caller cannot change a result through a returned view.
    """
    arr.setflags(write=False)
    return arr
