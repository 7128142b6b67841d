"""One fall through a drum curtain crossed by a limited air stream: the element array of the
curtain model (:mod:`drumflow.coolers.curtain`, Wardjiman and Rhodes 2009) as one linear map.

In a drum cell the falling particles form a curtain, and only part of the air crosses it (the
through-curtain stream); the rest flows past (the bypass). The through-curtain stream enters
the curtain at the temperature of the cell's air and crosses it column after column, in
``rows`` rows down the fall, exactly as in the curtain model: every element is
:func:`drumflow.coolers.curtain.element_exchange` (the particles see the mean of the element's
gas inlet and outlet temperatures). A dense curtain therefore saturates the stream: the air
leaves at the particles' temperature, and the heat is limited by how much air passes, not by
the film coefficient.

Every element is linear in the particles' shell temperatures and the gas temperature, and all
elements of one curtain are the same map (same exposure, particle rate and gas rate), so the
whole curtain is built by composing that element map over the grid. Two linear forms come out,
on the state ``[T_1 .. T_n, T_gas_in]``:

* the mean shell temperatures of the particles leaving the bottom (the columns mixed, as they
  are when the particles land in the bed), in the augmented-exposure form of
  :mod:`drumflow.coolers._propagator`, so it replaces the fall's exposure matrix;
* the mean temperature of the through-curtain air leaving the curtain.

Grid. Each column must take only a moderate step of the gas towards the particles: the
element's mean-temperature balance gives the gas a factor ``(1 - x/2) / (1 + x/2)`` per column
(``x`` the column's gas NTU), which approximates ``exp(-x)`` (the exponent is off by
``x^3 / 12`` per column) and turns negative (the gas would overshoot the particles) above
``x = 2``. The columns are chosen so that ``x <= 0.1`` over the first 10 NTU (where the
unsaturated remainder ``exp(-NTU)`` still matters: its exponent is then within 1e-3 of exact)
and ``x <= 1`` beyond (a saturated curtain, whose remainder is below ``exp(-10)``); the rows
split the fall into equal times.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from drumflow.coolers._propagator import exposure_matrix
from drumflow.coolers.curtain import element_exchange
from drumflow.errors import DrumModelError
from drumflow.physics.particle_interior import SphereConduction

FloatArray = NDArray[np.float64]

#: Largest gas NTU one column may take (module notes).
MAX_COLUMN_NTU = 1.0
#: The column NTU over the first :data:`FINE_NTU` of the curtain (module notes).
FINE_COLUMN_NTU = 0.1
FINE_NTU = 10.0
#: Most columns a curtain gets; a thinner through-curtain stream than this allows is refused.
MAX_COLUMNS = 4000


@dataclass(frozen=True)
class CurtainPass:
    """One fall through the curtain as linear maps of ``[T_1 .. T_n, T_gas_in]``.

    Attributes
    ----------
    matrix
        Shape ``(n + 1, n + 1)``: the mean shell temperatures leaving (rows ``< n``) and the gas
        inlet temperature carried on (row ``n``), the form of an exposure matrix.
    gas_out
        Shape ``(n + 1,)``: the mean temperature of the through-curtain air leaving.
    gas_ntu
        ``h A / (m_c c_p)`` of the whole curtain: the particles' surface conductance over the
        through-curtain air's capacity rate (infinite without air).
    rows, columns
        The element grid.
    """

    matrix: FloatArray
    gas_out: FloatArray
    gas_ntu: float
    rows: int
    columns: int


def _element_map(exposure: FloatArray, capacities: FloatArray, particle_rate: float,
                 gas_capacity_rate: float) -> FloatArray:
    """The curtain model's element as a matrix on ``[T_1 .. T_n, T_gas]``.

    :func:`~drumflow.coolers.curtain.element_exchange` is linear in the shell temperatures and
    the gas inlet temperature (with gas throughput, and without it, where the gas takes the
    temperature at which the particles give nothing), so its columns are its answers to the
    unit vectors.
    """
    n = len(capacities)
    mat = np.zeros((n + 1, n + 1))
    for j in range(n + 1):
        shells = np.zeros(n)
        gas = 0.0
        if j < n:
            shells[j] = 1.0
        else:
            gas = 1.0
        out, _, gas_out = element_exchange(exposure, capacities, shells, particle_rate, gas,
                                           gas_capacity_rate)
        mat[:n, j] = out
        mat[n, j] = gas_out
    return mat


def curtain_pass(model: SphereConduction, h_w_m2k: float, fall_time_s: float,
                 particle_rate: float, gas_capacity_rate_w_k: float, rows: int) -> CurtainPass:
    """One fall through a curtain crossed by ``gas_capacity_rate_w_k`` of air (module notes).

    Parameters
    ----------
    model
        The particle-interior solver.
    h_w_m2k
        Film coefficient in the curtain.
    fall_time_s
        Time of one fall.
    particle_rate
        Particles falling through the curtain per second.
    gas_capacity_rate_w_k
        Mass flow times heat capacity of the air crossing the curtain, W/K (0: none).
    rows
        Rows of the element array (equal shares of the fall time and of the air).

    Raises
    ------
    DrumModelError
        When the stream is so thin against the curtain that more than :data:`MAX_COLUMNS`
        columns would be needed.
    """
    if not rows >= 1:
        raise DrumModelError(f"curtain_rows = {rows}: allowed >= 1")
    n = model.shells
    surface_conductance = particle_rate * model.sphere.surface * h_w_m2k * fall_time_s
    if gas_capacity_rate_w_k > 0:
        gas_ntu = surface_conductance / gas_capacity_rate_w_k
        columns = max(1, math.ceil(min(gas_ntu, FINE_NTU) / FINE_COLUMN_NTU - 1e-9),
                      math.ceil(gas_ntu / MAX_COLUMN_NTU - 1e-9))
        if columns > MAX_COLUMNS:
            raise DrumModelError(
                f"through-curtain air capacity rate = {gas_capacity_rate_w_k:.4g} W/K: the curtain "
                f"would need {columns} columns (gas NTU {gas_ntu:.4g}); allowed up to "
                f"{MAX_COLUMNS} (a larger through-curtain flow, or 0 for none)"
            )
    else:
        gas_ntu = math.inf
        columns = 1  # no throughput: the gas takes the particles' temperature, nothing to resolve
    exposure = exposure_matrix(model, h_w_m2k, fall_time_s / rows)
    element = _element_map(exposure, model.capacities, particle_rate / columns,
                           gas_capacity_rate_w_k / rows)
    # Each column's shell temperatures and the gas, as linear forms of the curtain's inputs
    # [T_1 .. T_n, T_gas_in]: every particle enters with the same state, every row's gas at
    # the same inlet temperature.
    entering = np.eye(n, n + 1)
    shells = np.repeat(entering[np.newaxis], columns, axis=0)
    gas_inlet = np.zeros(n + 1)
    gas_inlet[n] = 1.0
    gas_leaving = np.zeros(n + 1)
    stacked = np.empty((n + 1, n + 1))
    for _ in range(rows):
        gas = gas_inlet
        for c in range(columns):
            stacked[:n] = shells[c]
            stacked[n] = gas
            out = element @ stacked
            shells[c] = out[:n]
            gas = out[n]
        gas_leaving += gas
    matrix = np.zeros((n + 1, n + 1))
    matrix[:n] = shells.mean(axis=0)
    matrix[n, n] = 1.0
    return CurtainPass(matrix=matrix, gas_out=gas_leaving / rows, gas_ntu=gas_ntu, rows=rows,
                       columns=columns)
