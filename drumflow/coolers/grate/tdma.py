"""The tri-diagonal matrix algorithm (TDMA, Thomas 1949) in the report's notation.

A line of balance cells gives ``a_P T_i = a_W T_(i-1) + a_E T_(i+1) + b`` (report Eq. 9 with
the neighbours across the line moved into ``b``). :func:`tdma` solves it with scipy's
banded LU (:func:`scipy.linalg.solve_banded`), which for a band of width three is the
Thomas algorithm with partial pivoting; the line-by-line sweeps of the model call it once per
line.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.linalg import solve_banded

__all__ = ["tdma"]


def tdma(a_w: ArrayLike, a_p: ArrayLike, a_e: ArrayLike, b: ArrayLike) -> NDArray[np.float64]:
    """Solve ``a_p[i] T[i] - a_w[i] T[i-1] - a_e[i] T[i+1] = b[i]`` along one line.

    Parameters
    ----------
    a_w, a_p, a_e, b
        Coefficients of the west (previous) and east (next) neighbours, of the cell itself,
        and the source, each of the line's length; ``a_w[0]`` and ``a_e[-1]`` are ignored
        (no neighbour beyond the ends).

    Returns
    -------
    numpy.ndarray
        The line's temperatures.

    Raises
    ------
    ValueError
        If the arrays differ in length or the matrix is singular.
    """
    west = np.asarray(a_w, dtype=np.float64)
    centre = np.asarray(a_p, dtype=np.float64)
    east = np.asarray(a_e, dtype=np.float64)
    rhs = np.asarray(b, dtype=np.float64)
    n = centre.shape[0]
    if not (west.shape == centre.shape == east.shape == rhs.shape == (n,)):
        raise ValueError("tdma: a_w, a_p, a_e and b must be 1-D arrays of one length")
    band = np.zeros((3, n))
    band[0, 1:] = -east[:-1]  # super-diagonal: coefficient of T[i+1] in row i
    band[1] = centre
    band[2, :-1] = -west[1:]  # sub-diagonal: coefficient of T[i-1] in row i
    try:
        return np.asarray(solve_banded((1, 1), band, rhs, check_finite=False), dtype=np.float64)
    except np.linalg.LinAlgError as exc:
        raise ValueError(f"tdma: singular line system ({exc})") from None
