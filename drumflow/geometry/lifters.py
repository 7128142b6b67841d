"""Lifters (flights) in the drum cross-section: distance to them, their area, the open area.

The plates themselves (:func:`~drumflow.case.lifter_shape.all_plates`) are the case's
(:mod:`drumflow.case.lifter_shape`), so the case's gap check, the mesh, the particle placement
and the pictures use one shape. Plain numpy, no mesher: unit-tested without gmsh.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from drumflow.case.lifter_shape import all_plates

if TYPE_CHECKING:
    from drumflow.case import Case, Lifters


def distance_to_lifters(
    points: NDArray[np.float64], radius: float, lifters: Lifters, offset: float = 0.0
) -> NDArray[np.float64]:
    """Signed distance from (n, 2) cross-section points to the nearest lifter, m."""
    points = np.asarray(points, dtype=float)
    dist = np.full(len(points), np.inf)
    for plate in all_plates(radius, lifters, offset):
        np.minimum(dist, plate.signed_distance(points), out=dist)
    return dist


def lifter_area(radius: float, lifters: Lifters) -> float:
    """Cross-section area of all lifters inside the shell, m^2 (plates may overlap a little)."""
    h, t = lifters.base_height, lifters.thickness
    per = h * t
    if lifters.profile != "straight":
        per += lifters.lip_length * t
    return lifters.count * per


def free_area(case: Case) -> float:
    """Cross-section open to the air: the shell's disk minus the lifters, m^2."""
    return math.pi * case.drum.radius**2 - lifter_area(case.drum.radius, case.lifters)
