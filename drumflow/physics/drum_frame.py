"""The drum's frame: its angle at a time and the rotation between the lab and the drum.

The drum turns counter-clockwise about +z (as LIGGGHTS' ``fix move/mesh ... rotate`` turns it)
at ``omega`` rad/s, so at time ``t`` it has turned by ``omega t`` (not wrapped). The air field
is solved once in the drum frame and sampled at lab points turned back by that angle; the
snapshots' lifters, the pictures and the saved states use the same angle. One definition here
(rather than in :mod:`drumflow.geometry`) because every floor above needs it, down to the DEM
state and the coupling loop, and it is kinematics, not a shape: a solid-body rotation.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike, NDArray

__all__ = ["drum_angle", "rotate_about_axis", "rotate_to_drum_frame", "rotate_to_lab_frame"]


def drum_angle(omega: float, time_s: float) -> float:
    """The drum's angle at ``time_s``, rad: ``omega t`` (counter-clockwise about +z, not wrapped).

    Parameters
    ----------
    omega
        The drum's angular speed, rad/s (``case.drum.omega``).
    time_s
        Simulated time since the drum's reference position (angle 0 at t = 0), s.
    """
    return omega * time_s


def rotate_about_axis(points: ArrayLike, angle: float) -> NDArray[np.float64]:
    """Points or vectors (..., 3) turned by ``angle`` (rad) counter-clockwise about the z axis."""
    v = np.asarray(points, dtype=float)
    c, s = math.cos(angle), math.sin(angle)
    out = np.empty(v.shape, dtype=float)
    out[..., 0] = c * v[..., 0] - s * v[..., 1]
    out[..., 1] = s * v[..., 0] + c * v[..., 1]
    out[..., 2] = v[..., 2]
    return out


def rotate_to_drum_frame(points: ArrayLike, angle: float) -> NDArray[np.float64]:
    """Lab-frame points or vectors (..., 3) in drum-frame coordinates.

    Parameters
    ----------
    points
        Lab-frame positions (or vectors), shape (..., 3).
    angle
        The drum's rotation angle since the field's reference instant, :func:`drum_angle`, rad.
        The drum turns counter-clockwise about +z, so this rotates by ``-angle``.
    """
    return rotate_about_axis(points, -angle)


def rotate_to_lab_frame(vectors: ArrayLike, angle: float) -> NDArray[np.float64]:
    """Drum-frame vectors or points (..., 3) in lab-frame components (rotation by ``+angle``)."""
    return rotate_about_axis(vectors, angle)
