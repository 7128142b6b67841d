"""The regular grid the air field is resampled onto (:class:`drumflow.air.field.AirField`).

The grid covers the whole drum in the frame that turns with it (x, y across, z along the
axis): :func:`grid_spacing` sizes it, :func:`grid_axes` lays it out, :func:`fluid_mask_xy`
says which nodes are air, and :func:`local_linear_fit` fills the fluid nodes from the
OpenFOAM cell centres.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

if TYPE_CHECKING:
    from drumflow.case import Case

__all__ = ["MAX_GRID_NODES", "fluid_mask_xy", "grid_axes", "grid_spacing", "local_linear_fit"]

#: Largest number of grid nodes :func:`grid_spacing` allows (about 0.5 GB of float64 vectors).
MAX_GRID_NODES = 20_000_000


def grid_spacing(case: Case) -> float:
    """Default grid spacing, m: a quarter of the bulk CFD cell (half the near-wall cell), at
    most D/80.

    Finer than the CFD cells it samples, so trilinear interpolation adds little to the CFD's
    own error (on the smoke drum, halving the spacing from 0.01 m to 0.005 m cut the median
    difference from the cell values within 5 mm of a wall from 0.31 to 0.18 m/s; away from the
    walls it is below 0.01 m/s); grown if the grid would pass :data:`MAX_GRID_NODES`.
    """
    from drumflow.geometry.fluid import fluid_mesh_size

    D, L = case.drum.diameter, case.drum.length
    h = min(0.25 * fluid_mesh_size(case), D / 80.0)
    nodes = (D / h + 1) ** 2 * (L / h + 1)
    if nodes > MAX_GRID_NODES:
        h *= (nodes / MAX_GRID_NODES) ** (1.0 / 3.0)
    return h


def grid_axes(case: Case, spacing: float) -> tuple[list[NDArray[np.float64]], NDArray, NDArray]:
    """The grid's axes (x, y, z node coordinates) at about ``spacing``, its lower corner and
    its actual step along each axis."""
    R, L = case.drum.radius, case.drum.length
    lo = np.array([-R, -R, 0.0])
    hi = np.array([R, R, L])
    n = np.maximum(2, np.ceil((hi - lo) / spacing - 1e-9).astype(int) + 1)
    axes = [np.linspace(lo[i], hi[i], n[i]) for i in range(3)]
    return axes, lo, (hi - lo) / (n - 1)


def fluid_mask_xy(case: Case, x: NDArray[np.float64], y: NDArray[np.float64]) -> NDArray[np.bool_]:
    """True where cross-section points (x, y) are air: inside the shell and outside the lifters."""
    from drumflow.geometry.lifters import distance_to_lifters

    pts = np.column_stack([np.ravel(x), np.ravel(y)])
    inside = np.hypot(pts[:, 0], pts[:, 1]) < case.drum.radius
    if case.lifters.count > 0:
        inside &= distance_to_lifters(pts, case.drum.radius, case.lifters) > 0.0
    return inside.reshape(np.shape(x))


def local_linear_fit(
    support: NDArray[np.float64],
    values: NDArray[np.float64],
    query: NDArray[np.float64],
    k: int = 12,
    tree: Any = None,
    chunk: int = 65_536,
) -> NDArray[np.float64]:
    """Values at ``query`` points from a weighted linear fit to the ``k`` nearest support points.

    At each query point q, ``a + B (x - q)`` is fitted by least squares to the k nearest
    support values with weights 1 / (d / d_k + 0.001)^2 (d_k: the k-th distance), and ``a`` is
    the answer: exact for fields linear in x, y, z, second-order accurate for smooth ones.
    The result is clipped to the neighbours' range, so near walls, where the fit
    extrapolates from one side, it never overshoots. A tiny ridge term on the gradient keeps
    degenerate (coplanar) neighbourhoods solvable.

    Parameters
    ----------
    support
        (n, 3) points carrying data (cell centres, boundary face centres).
    values
        (n, c) data at them.
    query
        (m, 3) points to evaluate at.
    k
        Neighbours per fit (at least 4 are needed for a 3D linear fit).
    tree
        A :class:`scipy.spatial.cKDTree` of ``support``, if one is at hand.
    chunk
        Query points per vectorised batch (bounds the memory to ~ chunk * k * 100 bytes).

    Notes
    -----
    Chosen over Delaunay interpolation of the cell centres (bounded and exact, but Qhull's
    triangulation and point location took 60 s for 320k grid nodes in the 3 m drum's
    170k cells, and 180 s for 2.4M) and over pyvista's probe (133k points/s): this takes a
    few seconds per million nodes.
    """
    from scipy.spatial import cKDTree

    support = np.asarray(support, dtype=float)
    values = np.asarray(values, dtype=float)
    query = np.asarray(query, dtype=float)
    if values.ndim == 1:
        values = values[:, None]
    out = np.empty((len(query), values.shape[1]))
    if len(query) == 0:
        return out
    k = min(k, len(support))
    tree = cKDTree(support) if tree is None else tree
    eye = np.eye(3)
    for s in range(0, len(query), chunk):
        q = query[s : s + chunk]
        d, idx = tree.query(q, k=k)
        if k == 1:
            out[s : s + chunk] = values[idx]
            continue
        scale = d[:, -1:] + 1e-300
        D = (support[idx] - q[:, None, :]) / scale[:, :, None]
        w = 1.0 / (d / scale + 1e-3) ** 2
        A = np.concatenate([np.ones(D.shape[:2] + (1,)), D], axis=2)
        Aw = A * w[:, :, None]
        N = np.einsum("mki,mkj->mij", Aw, A)
        N[:, 1:, 1:] += 1e-9 * w.sum(axis=1)[:, None, None] * eye
        V = values[idx]
        coef = np.linalg.solve(N, np.einsum("mki,mkc->mic", Aw, V))
        est = coef[:, 0, :]
        np.clip(est, V.min(axis=1), V.max(axis=1), out=est)
        out[s : s + chunk] = est
    return out
