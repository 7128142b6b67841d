"""Collision speeds in a drum, from the case alone: a bound (the DEM step is made safe at it)
and a typical speed (the restitution correction is made exact at it).

Apart from :mod:`~drumflow.dem.timestep` and :mod:`~drumflow.dem.restitution` because both
use them and the time step's spin check uses the restitution: here, neither imports the other
to learn a speed.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from drumflow.case import Case

__all__ = ["G", "impact_velocity", "typical_impact_velocity"]

G = 9.81


def impact_velocity(case: Case) -> float:
    """A bound on collision speeds in the drum: free fall across the diameter, or the wall speed."""
    return max(math.sqrt(2.0 * G * case.drum.diameter), case.drum.omega * case.drum.radius)


def typical_impact_velocity(case: Case) -> float:
    """A typical collision speed in the cascade, m/s: half of :func:`impact_velocity`.

    Particles rarely fall the whole diameter before meeting another; the restitution
    correction (:mod:`drumflow.dem.restitution`) is made at this speed, while the time step is
    bounded at the full one (the shortest contacts).
    """
    return 0.5 * impact_velocity(case)
