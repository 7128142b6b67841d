"""Material properties of the grate-cooler model: hot air, clinker, and the packed-bed
heat-transfer correlation of the report (its Section 2.3).

Air
    The report evaluates the air properties "at the film temperature" but tabulates none.
    They come from the project's one air table, read in kelvin up to 2000 K (the clinker
    enters at 1673 K): :mod:`drumflow.physics.air` (its kelvin view, Incropera Table A.4,
    250 K to 2000 K, linear between rows, with the exact enthalpy of that c_p).

Clinker
    c_p(T) = c0 + c1 T and k(T) = k0 + k1 T (T in K), from the case file; the enthalpy
    h(T) = c0 T + c1 T^2 / 2 is exact for that c_p and has a closed-form inverse, which
    gives the "average caloric temperature" of the report (the temperature of the mean
    enthalpy of the layers).

Convection
    Bird, Stewart and Lightfoot, *Transport Phenomena*, 2nd ed., Section 14.5 (the
    Gamson-Thodos-Hougen data as fitted by Stewart), the report's Eqs. (29)-(31)::

        Re  = d_p G0 / ((1 - eps) mu psi)
        j_H = 2.19 Re^(-2/3) + 0.78 Re^(-0.381)
        h   = j_H c_p G0 Pr^(-2/3)

    The report prints Eq. (30) with the Prandtl number to the first power; the Chilton-
    Colburn factor it names is defined with Pr^(2/3), which is what is used
    here. The specific surface of the bed ("convection area factor") is the packed-bed
    value a = 6 (1 - eps) / (psi d_p) of the same section.

Pressure drop
    Not in the report (its air flow is given). For the fan-limited air
    (:mod:`drumflow.coolers.grate.fans`) the bed's pressure gradient is Ergun's equation,
    Bird, Stewart and Lightfoot, 2nd ed., Eq. (6.4-12), with the sphericity in the
    diameter (psi d_p, as in the heat-transfer correlation)::

        -dp/dy = 150 mu (1 - eps)^2 u / (eps^3 (psi d_p)^2) + 1.75 rho (1 - eps) u^2 / (eps^3 psi d_p)

    with u = G0 / rho the superficial velocity, mu from Table A.4 and rho of the ideal gas
    at 1 atm (the bed's few kPa change the density by a few per cent; neglected).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Final

import numpy as np
from numpy.typing import ArrayLike, NDArray

from drumflow.physics.air import ATMOSPHERE, air_density, air_heat_capacity, air_prandtl, air_viscosity

if TYPE_CHECKING:
    from drumflow.coolers.grate.case import GrateCase

__all__ = [
    "STEFAN_BOLTZMANN",
    "ClinkerProperties",
    "bed_specific_surface",
    "ergun_pressure_gradient",
    "packed_bed_h",
    "radiation_conductance",
]

FloatArray = NDArray[np.float64]

STEFAN_BOLTZMANN: Final = 5.670374419e-8
"""Stefan-Boltzmann constant, W/(m2 K4) (CODATA 2018)."""


@dataclass(frozen=True)
class ClinkerProperties:
    """Linear c_p(T) and k(T) of the clinker (T in K) and the enthalpy they imply."""

    cp0: float
    cp1: float
    k0: float
    k1: float

    @classmethod
    def of(cls, case: GrateCase) -> ClinkerProperties:
        c = case.clinker
        return cls(c.heat_capacity, c.heat_capacity_slope, c.conductivity, c.conductivity_slope)

    def heat_capacity(self, t: FloatArray | float) -> FloatArray:
        """c_p(T), J/(kg K)."""
        return np.asarray(self.cp0 + self.cp1 * np.asarray(t), dtype=np.float64)

    def conductivity(self, t: FloatArray | float) -> FloatArray:
        """k(T) of the clinker particle, W/(m K)."""
        return np.asarray(self.k0 + self.k1 * np.asarray(t), dtype=np.float64)

    def enthalpy(self, t: FloatArray | float) -> FloatArray:
        """h(T) = cp0 T + cp1 T^2 / 2, J/kg (zero at 0 K; only differences matter)."""
        tt = np.asarray(t, dtype=np.float64)
        return self.cp0 * tt + 0.5 * self.cp1 * tt * tt

    def temperature(self, h: FloatArray | float) -> FloatArray:
        """Inverse of :meth:`enthalpy` (the caloric temperature of a mixed enthalpy)."""
        hh = np.asarray(h, dtype=np.float64)
        if self.cp1 == 0.0:
            return hh / self.cp0
        # Stable root of cp1/2 T^2 + cp0 T - h = 0 (no cancellation for small cp1).
        return 2.0 * hh / (self.cp0 + np.sqrt(self.cp0 * self.cp0 + 2.0 * self.cp1 * hh))

    def secant(self, t1: FloatArray, t2: FloatArray) -> FloatArray:
        """[h(t1) - h(t2)] / (t1 - t2): exact for a linear c_p, c_p at the mean."""
        return self.cp0 + 0.5 * self.cp1 * (t1 + t2)


def bed_specific_surface(porosity: float, diameter: float, sphericity: float) -> float:
    """Particle surface per bed volume of a packed bed, 1/m: a = 6 (1 - eps) / (psi d_p)."""
    return 6.0 * (1.0 - porosity) / (sphericity * diameter)


def packed_bed_h(mass_flux: ArrayLike, film_temperature: ArrayLike, *, diameter: float,
                 porosity: float, sphericity: float) -> FloatArray:
    """Gas-to-particle heat-transfer coefficient of a packed bed, W/(m2 K).

    Parameters
    ----------
    mass_flux
        Superficial air mass flux G0 through the bed, kg/(m2 s).
    film_temperature
        (T_solid + T_air) / 2, K, where the air properties are taken (the report's rule).
    diameter, porosity, sphericity
        Particle diameter (m), bed porosity and particle sphericity psi.

    Returns
    -------
    numpy.ndarray
        h; zero where the mass flux is zero (the correlation gives h ~ G0^(1/3) -> 0).
    """
    g = np.asarray(mass_flux, dtype=np.float64)
    mu = air_viscosity(film_temperature)
    re = diameter * g / ((1.0 - porosity) * mu * sphericity)
    safe = np.maximum(re, 1e-300)
    j_h = 2.19 * safe ** (-2.0 / 3.0) + 0.78 * safe ** (-0.381)
    h = j_h * air_heat_capacity(film_temperature) * g * air_prandtl(film_temperature) ** (-2.0 / 3.0)
    return np.where(re > 0.0, h, 0.0)


def ergun_pressure_gradient(mass_flux: ArrayLike, temperature: ArrayLike, *, diameter: float,
                            porosity: float, sphericity: float,
                            pressure: float = ATMOSPHERE) -> FloatArray:
    """Pressure drop per bed height of air flowing through a packed bed (Ergun), Pa/m.

    Parameters
    ----------
    mass_flux
        Superficial air mass flux G0 through the bed, kg/(m2 s).
    temperature
        Air temperature, K (viscosity from Table A.4, density of the ideal gas).
    diameter, porosity, sphericity
        Particle diameter (m), bed porosity and particle sphericity psi.
    pressure
        Absolute pressure of the air, Pa.

    Returns
    -------
    numpy.ndarray
        150 mu (1 - eps)^2 u / (eps^3 (psi d)^2) + 1.75 rho (1 - eps) u^2 / (eps^3 psi d),
        with u = G0 / rho.
    """
    g = np.asarray(mass_flux, dtype=np.float64)
    rho = air_density(temperature, pressure)
    mu = air_viscosity(temperature)
    d_eff = sphericity * diameter
    eps3 = porosity**3
    u = g / rho
    viscous = 150.0 * mu * (1.0 - porosity) ** 2 * u / (eps3 * d_eff * d_eff)
    inertial = 1.75 * rho * (1.0 - porosity) * u * u / (eps3 * d_eff)
    return np.asarray(viscous + inertial, dtype=np.float64)


def radiation_conductance(case: GrateCase, n: int) -> float:
    """sigma eps_s (1 - eps) dx W of one top cell, W/K^4 (zero with radiation off)."""
    if not case.model.radiation:
        return 0.0
    c = case.clinker
    dx = case.cooler.length / n
    return STEFAN_BOLTZMANN * c.emissivity * (1.0 - c.bed_porosity) * dx * case.cooler.width
