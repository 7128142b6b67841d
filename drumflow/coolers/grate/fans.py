"""Air flow limited by the bed: the clinker bed's Ergun pressure drop against a fan curve.

The report blows a given air mass flow through the bed whatever its height; its grate-speed
optimum (Figure 15) is argued from residence time against bed height, which with the flows
fixed are one effect (README, "Why two trends differ"). A real cooler's air comes from fans:
a thicker bed resists more, and the fans deliver less. This module is that coupling, chosen
with ``air.supply = "fan"`` and a ``[fan]`` section (:class:`~drumflow.coolers.grate.case.Fan`).

Bed
    Every air cell (i, j) of height dy adds Ergun's gradient
    (:func:`~drumflow.coolers.grate.properties.ergun_pressure_gradient`) at the column's mass
    flux G_i = M_i / (dx W) and the cell's mean air temperature (the mean of what enters and
    leaves it, where mu and rho are taken). With the temperature field frozen a column's drop
    is therefore exactly Delta p_i = a_i m + b_i m^2 in the total air flow m (its share
    s_i = M_i / m fixed by ``air.distribution``).

Plenum
    The compartments' shares stay those of ``air.distribution`` (dampers hold them), so the
    fan sees one pressure: the flow-weighted mean of the columns' drops,
    Delta p_bed = sum_i s_i Delta p_i = A m + B m^2 (the fan's flow work m Delta p_bed / rho
    is then the columns' summed flow work). The grate plates, ducts and dampers add no
    resistance here (the report gives none).

Fan
    Delta p_fan = p_0 [1 - (Q / Q_free)^2], Q = m / rho(T_air,in) the volume flow at the fan
    inlet (a fan delivers a volume at its speed); no Q_free: a flat curve (Delta p_fan = p_0,
    a fixed fan pressure).

Operating point
    Delta p_fan = Delta p_bed at the frozen temperatures is the quadratic
    (B + C) m^2 + A m - p_0 = 0 with C = p_0 / (rho_in Q_free)^2, whose positive root is
    m = 2 p_0 / (A + sqrt(A^2 + 4 (B + C) p_0)) (the form without cancellation). The solver
    (:func:`~drumflow.coolers.grate.model.solve_grate`) updates m to it after every sweep, so
    the temperature field and the air flow converge together.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from drumflow.coolers.grate.case import Fan, GrateCase
from drumflow.coolers.grate.properties import ergun_pressure_gradient
from drumflow.physics.air import air_density

__all__ = [
    "BedResistance",
    "bed_resistance",
    "column_pressure_drops",
    "fan_pressure",
    "operating_point",
]

FloatArray = NDArray[np.float64]


@dataclass(frozen=True)
class BedResistance:
    """Delta p_bed = linear m + quadratic m^2 (Pa, m in kg/s) at a frozen temperature field."""

    linear: float
    quadratic: float

    def pressure_drop(self, mass_flow: float) -> float:
        """Flow-weighted mean bed pressure drop at the total air flow ``mass_flow``, Pa."""
        return self.linear * mass_flow + self.quadratic * mass_flow * mass_flow


def _cell_air_temperature(case: GrateCase, air_temperature: FloatArray) -> FloatArray:
    """Mean of the air temperature entering and leaving every air cell, K."""
    below = np.concatenate((np.full((1, air_temperature.shape[1]), case.air.inlet_temperature),
                            air_temperature[:-1]))
    return np.asarray(0.5 * (below + air_temperature), dtype=np.float64)


def _unit_gradients(case: GrateCase, air_temperature: FloatArray) -> tuple[FloatArray, FloatArray]:
    """Ergun's viscous and inertial gradients per unit mass flux, per unit mass flux squared:
    dp/dy = alpha G + beta G^2 in every cell (both independent of G at a fixed T)."""
    c = case.clinker
    t = _cell_air_temperature(case, air_temperature)
    kw = {"diameter": c.particle_diameter, "porosity": c.bed_porosity, "sphericity": c.sphericity}
    at_one = ergun_pressure_gradient(1.0, t, **kw)
    at_two = ergun_pressure_gradient(2.0, t, **kw)
    # alpha + beta = f(1), 2 alpha + 4 beta = f(2): read the two terms off the law itself, so
    # the coupling uses exactly the Ergun function the tests check.
    beta = 0.5 * (at_two - 2.0 * at_one)
    alpha = at_one - beta
    return alpha, beta


def column_pressure_drops(case: GrateCase, air_temperature: FloatArray,
                          column_flow: FloatArray, bed_height: float) -> FloatArray:
    """Pressure drop across the bed of every column of cells, Pa.

    Parameters
    ----------
    case
        The case (particle size, porosity, grate size, air inlet temperature).
    air_temperature
        Air leaving every cell, ``[j, i]`` from the grate up, K.
    column_flow
        Air mass flow through every column, kg/s.
    bed_height
        Bed height H, m (the cells are H / m high).
    """
    m, n = air_temperature.shape
    dy = bed_height / m
    g = column_flow / (case.cooler.length / n * case.cooler.width)
    c = case.clinker
    grad = ergun_pressure_gradient(g[None, :], _cell_air_temperature(case, air_temperature),
                                   diameter=c.particle_diameter, porosity=c.bed_porosity,
                                   sphericity=c.sphericity)
    return np.asarray(grad.sum(axis=0) * dy, dtype=np.float64)


def bed_resistance(case: GrateCase, air_temperature: FloatArray, shares: FloatArray,
                   bed_height: float) -> BedResistance:
    """Coefficients of Delta p_bed(m) = A m + B m^2 at a frozen air temperature field.

    Parameters
    ----------
    case
        The case.
    air_temperature
        Air leaving every cell, ``[j, i]``, K.
    shares
        Fraction of the total air flow through every column (sums to 1).
    bed_height
        Bed height H, m.
    """
    m, n = air_temperature.shape
    dy = bed_height / m
    per_flow = shares / (case.cooler.length / n * case.cooler.width)  # G_i / m, 1/m2
    alpha, beta = _unit_gradients(case, air_temperature)
    a_col = per_flow * alpha.sum(axis=0) * dy
    b_col = per_flow * per_flow * beta.sum(axis=0) * dy
    return BedResistance(float(np.sum(shares * a_col)), float(np.sum(shares * b_col)))


def fan_pressure(fan: Fan, mass_flow: float, inlet_temperature: float) -> float:
    """Pressure rise of the fan curve at an air mass flow (kg/s) drawn at the inlet
    temperature (K), Pa: p_0 [1 - (Q / Q_free)^2], or p_0 for a flat curve."""
    if fan.free_delivery is None:
        return fan.shutoff_pressure
    q = mass_flow / float(air_density(inlet_temperature))
    return fan.shutoff_pressure * (1.0 - (q / fan.free_delivery) ** 2)


def operating_point(fan: Fan, resistance: BedResistance, inlet_temperature: float) -> float:
    """Air mass flow where the fan curve meets the bed's resistance, kg/s.

    The positive root of (B + C) m^2 + A m - p_0 = 0, C = p_0 / (rho_in Q_free)^2 (C = 0 for
    a flat curve); unique because the fan's pressure falls and the bed's rises with m.
    """
    p0 = fan.shutoff_pressure
    c = 0.0
    if fan.free_delivery is not None:
        free_mass = float(air_density(inlet_temperature)) * fan.free_delivery
        c = p0 / (free_mass * free_mass)
    a, b = resistance.linear, resistance.quadratic + c
    return 2.0 * p0 / (a + math.sqrt(a * a + 4.0 * b * p0))
