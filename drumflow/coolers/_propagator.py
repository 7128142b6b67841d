"""Exact linear maps of the shared particle-interior solver over a fixed exposure.

A Crank-Nicolson step of :class:`~drumflow.physics.particle_interior.SphereConduction` at a
constant film coefficient ``h`` and gas temperature ``T_g`` is affine in the shell temperatures
and in ``T_g``: ``T1 = S T0 + u T_g``. So ``advance`` over any number of equal steps is the
``k``-th power of that step, and a whole exposure (a fall through a curtain, a stay in the bed)
is one matrix. The models build that matrix once per (h, duration) by calling the shared
solver's :meth:`~SphereConduction.step` on the unit vectors, then apply it to every particle
state with a matrix product. The result is the solver's own ``advance`` to round-off (tested
in ``tests/unit/test_curtain.py``), with none of its per-step Python cost, which is what makes
a whole drum of thousands of cascades and a what-if table run in seconds.

State vectors are augmented with the gas temperature: ``[T_1 .. T_n, T_g]``. The gas
temperature is constant during an exposure, so its row is the identity.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from drumflow.physics.particle_interior import SphereConduction

FloatArray = NDArray[np.float64]


def step_matrix(model: SphereConduction, h: float, dt: float) -> FloatArray:
    """Augmented matrix of one Crank-Nicolson step of the shared solver.

    Parameters
    ----------
    model
        The particle-interior solver.
    h
        Film coefficient, W/(m^2 K) (0 insulated, ``inf`` surface at the gas temperature).
    dt
        Step, s.

    Returns
    -------
    numpy.ndarray
        Shape ``(n + 1, n + 1)``: columns ``j < n`` are the step applied to the unit shell
        vectors at zero gas temperature, column ``n`` the step of a zero particle in unit gas.
    """
    n = model.shells
    mat = np.zeros((n + 1, n + 1))
    for j in range(n):
        unit = np.zeros(n)
        unit[j] = 1.0
        mat[:n, j], _ = model.step(unit, h, 0.0, dt)
    mat[:n, n], _ = model.step(np.zeros(n), h, 1.0, dt)
    mat[n, n] = 1.0
    return mat


def exposure_matrix(model: SphereConduction, h: float, duration: float,
                    max_step: float | None = None) -> FloatArray:
    """Augmented matrix of ``model.advance(T, h, T_g, duration, max_step)``.

    The step count and length are those ``advance`` uses (equal steps no longer than
    ``max_step``, default the solver's :attr:`~SphereConduction.default_step`).
    """
    size = model.shells + 1
    if duration < 0 or not math.isfinite(duration):
        raise ValueError(f"duration = {duration!r}: must be a finite number >= 0")
    if duration == 0:
        return np.eye(size)
    limit = max_step if max_step is not None else model.default_step
    count = max(1, math.ceil(duration / limit - 1e-12))
    return np.linalg.matrix_power(step_matrix(model, h, duration / count), count)


def apply(matrix: FloatArray, temperatures: FloatArray, gas_temperature: float) -> FloatArray:
    """Shell temperatures after the exposure ``matrix`` at a gas temperature."""
    n = len(temperatures)
    return np.asarray(matrix[:n, :n] @ temperatures + matrix[:n, n] * gas_temperature)
