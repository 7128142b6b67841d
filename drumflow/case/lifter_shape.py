"""The shape of the lifters a case describes, as plain numpy geometry (no mesher).

Each lifter is a union of oriented rectangles (the radial base plate, and the lip for
``angled`` and ``L`` profiles) in the drum's cross-section plane (x, y), with the drum axis on
z and the drum turning counter-clockwise seen from +z. The case's own check (particles must
pass between the lifters, :func:`lifter_gap`) and the geometry stage (mesh, placement,
pictures: :mod:`drumflow.geometry.lifters`) use these same shapes; they sit with the case so
that the case, on the floor, needs no stage above it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

if TYPE_CHECKING:
    from drumflow.case.sections import Lifters

__all__ = ["SHELL_OVERLAP", "Plate", "all_plates", "lifter_angles", "lifter_gap", "lifter_plates"]

#: How far the base plate reaches past the shell, as a multiple of its thickness. The overlap
#: makes the boolean cut of lifters from the drum disk clean (no sliver faces at the shell).
SHELL_OVERLAP = 1.0


@dataclass(frozen=True)
class Plate:
    """An oriented rectangle: centre, unit axis along its length, half-length, half-width."""

    center: tuple[float, float]
    axis: tuple[float, float]
    half_length: float
    half_width: float

    def corners(self) -> NDArray[np.float64]:
        """The four corners, counter-clockwise, as a (4, 2) array."""
        c = np.asarray(self.center)
        u = np.asarray(self.axis)
        v = np.array([-u[1], u[0]])
        a, b = self.half_length, self.half_width
        return np.array([c - a * u - b * v, c + a * u - b * v, c + a * u + b * v, c - a * u + b * v])

    def signed_distance(self, points: NDArray[np.float64]) -> NDArray[np.float64]:
        """Signed distance from (n, 2) points to the rectangle (negative inside)."""
        p = np.asarray(points, dtype=float) - np.asarray(self.center)
        u = np.asarray(self.axis)
        v = np.array([-u[1], u[0]])
        s = np.abs(p @ u) - self.half_length
        w = np.abs(p @ v) - self.half_width
        outside = np.hypot(np.maximum(s, 0.0), np.maximum(w, 0.0))
        inside = np.minimum(np.maximum(s, w), 0.0)
        return outside + inside


def lifter_plates(radius: float, lifters: Lifters, angle: float) -> list[Plate]:
    """The plates of one lifter whose base sits at polar angle ``angle`` (rad).

    Parameters
    ----------
    radius
        Inner shell radius, m.
    lifters
        The case's lifter description.
    angle
        Polar angle of the base plate's centre line, rad.
    """
    e_r = np.array([math.cos(angle), math.sin(angle)])
    e_t = np.array([-math.sin(angle), math.cos(angle)])  # direction of rotation
    h, t = lifters.base_height, lifters.thickness
    ext = SHELL_OVERLAP * t
    base_center = (radius - h + 0.5 * (h + ext)) * e_r
    plates = [Plate(tuple(base_center), tuple(e_r), 0.5 * (h + ext), 0.5 * t)]
    if lifters.profile != "straight" and lifters.lip_length > 0:
        alpha = math.radians(90.0 if lifters.profile == "L" else lifters.lip_angle_deg)
        d = math.cos(alpha) * e_r + math.sin(alpha) * e_t
        tip = (radius - h) * e_r
        # The lip starts half a thickness behind the tip so that it overlaps the base plate.
        start = tip - 0.5 * t * d
        length = lifters.lip_length + 0.5 * t
        plates.append(Plate(tuple(start + 0.5 * length * d), tuple(d), 0.5 * length, 0.5 * t))
    return plates


def lifter_angles(count: int, offset: float = 0.0) -> NDArray[np.float64]:
    """Polar angles of evenly spaced lifters, rad."""
    return offset + 2.0 * math.pi * np.arange(count) / max(count, 1)


def all_plates(radius: float, lifters: Lifters, offset: float = 0.0) -> list[Plate]:
    """Every plate of every lifter."""
    return [
        p for a in lifter_angles(lifters.count, offset) for p in lifter_plates(radius, lifters, a)
    ]


def _segment_point_distance(a: NDArray, b: NDArray, p: NDArray) -> float:
    ab = b - a
    t = float(np.clip(np.dot(p - a, ab) / max(np.dot(ab, ab), 1e-300), 0.0, 1.0))
    return float(np.linalg.norm(a + t * ab - p))


def _polygon_distance(pa: NDArray, pb: NDArray) -> float:
    # Valid for disjoint convex polygons: the closest pair always involves a vertex.
    best = math.inf
    for poly, other in ((pa, pb), (pb, pa)):
        for i in range(len(other)):
            a, b = other[i], other[(i + 1) % len(other)]
            for p in poly:
                best = min(best, _segment_point_distance(a, b, p))
    return best


def lifter_gap(radius: float, lifters: Lifters) -> float:
    """Smallest clearance between two neighbouring lifters (plate to plate), m.

    Only the part inside the shell counts: the base plates' overlap beyond the shell is
    clipped away by the shell itself, so it is ignored here by measuring inside the drum.
    """
    if lifters.count < 2:
        return 2.0 * radius
    first = lifter_plates(radius, lifters, 0.0)
    second = lifter_plates(radius, lifters, 2.0 * math.pi / lifters.count)
    gap = min(_polygon_distance(p.corners(), q.corners()) for p in first for q in second)
    return gap
