"""Material properties of the grate-cooler model: hot air, clinker, and the packed-bed
heat-transfer correlation of the report (its Section 2.3).

Air
    The report evaluates the air properties "at the film temperature" but tabulates none.
    The project's own air table (:mod:`drumflow.air_properties`) stops at 600 K,
    far below the 1673 K clinker inlet, so this module carries the high-temperature rows of
    the same source: Incropera, DeWitt, Bergman, Lavine, *Fundamentals of Heat and Mass
    Transfer*, 6th ed., Table A.4 (air at 1 atm), 250 K to 2000 K. Properties are linear
    in temperature between rows; the enthalpy is the exact integral of that piecewise-linear
    c_p, so an energy balance written with :func:`air_enthalpy` closes to round-off.

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

from bisect import bisect_right
from typing import Final

import numpy as np
from numpy.typing import ArrayLike, NDArray

__all__ = [
    "AIR_T_MAX",
    "AIR_T_MIN",
    "STEFAN_BOLTZMANN",
    "ATMOSPHERE",
    "AIR_MOLAR_MASS",
    "GAS_CONSTANT",
    "air_conductivity",
    "air_density",
    "air_enthalpy",
    "air_enthalpy_scalar",
    "air_heat_capacity",
    "air_prandtl",
    "air_temperature_from_enthalpy",
    "air_viscosity",
    "bed_specific_surface",
    "ergun_pressure_gradient",
    "packed_bed_h",
]

FloatArray = NDArray[np.float64]

STEFAN_BOLTZMANN: Final = 5.670374419e-8
"""Stefan-Boltzmann constant, W/(m2 K4) (CODATA 2018)."""

GAS_CONSTANT: Final = 8.314462618
"""Molar gas constant, J/(mol K) (CODATA 2018)."""

AIR_MOLAR_MASS: Final = 0.0289644
"""Molar mass of dry air, kg/mol (US Standard Atmosphere 1976)."""

ATMOSPHERE: Final = 101325.0
"""Pressure of the air in the bed and at the fans, Pa (the bed's few kPa are neglected)."""

# Incropera 6th ed., Table A.4, air at 1 atm: T (K), c_p (kJ/(kg K)), mu * 1e7 (N s/m2),
# k * 1e3 (W/(m K)), Pr. Rows 250-600 K are the same as drumflow.air_properties.
_ROWS: Final = (
    (250.0, 1.006, 159.6, 22.3, 0.720),
    (300.0, 1.007, 184.6, 26.3, 0.707),
    (350.0, 1.009, 208.2, 30.0, 0.700),
    (400.0, 1.014, 230.1, 33.8, 0.690),
    (450.0, 1.021, 250.7, 37.3, 0.686),
    (500.0, 1.030, 270.1, 40.7, 0.684),
    (550.0, 1.040, 288.4, 43.9, 0.683),
    (600.0, 1.051, 305.8, 46.9, 0.685),
    (650.0, 1.063, 322.5, 49.7, 0.690),
    (700.0, 1.075, 338.8, 52.4, 0.695),
    (750.0, 1.087, 354.6, 54.9, 0.702),
    (800.0, 1.099, 369.8, 57.3, 0.709),
    (850.0, 1.110, 384.3, 59.6, 0.716),
    (900.0, 1.121, 398.1, 62.0, 0.720),
    (950.0, 1.131, 411.3, 64.3, 0.723),
    (1000.0, 1.141, 424.4, 66.7, 0.726),
    (1100.0, 1.159, 449.0, 71.5, 0.728),
    (1200.0, 1.175, 473.0, 76.3, 0.728),
    (1300.0, 1.189, 496.0, 82.0, 0.719),
    (1400.0, 1.207, 530.0, 91.0, 0.703),
    (1500.0, 1.230, 557.0, 100.0, 0.685),
    (1600.0, 1.248, 584.0, 106.0, 0.688),
    (1700.0, 1.267, 611.0, 113.0, 0.685),
    (1800.0, 1.286, 637.0, 120.0, 0.683),
    (1900.0, 1.307, 663.0, 128.0, 0.677),
    (2000.0, 1.337, 689.0, 137.0, 0.672),
)
_TABLE = np.asarray(_ROWS, dtype=np.float64)
_T: Final = _TABLE[:, 0].copy()
_CP: Final = 1e3 * _TABLE[:, 1]
_MU: Final = 1e-7 * _TABLE[:, 2]
_K: Final = 1e-3 * _TABLE[:, 3]
_PR: Final = _TABLE[:, 4].copy()
# Enthalpy at the table rows (J/kg, zero at 250 K): trapezoids are exact for linear c_p.
_H: Final = np.concatenate(([0.0], np.cumsum(0.5 * (_CP[1:] + _CP[:-1]) * np.diff(_T))))
_SLOPE: Final = np.diff(_CP) / np.diff(_T)

AIR_T_MIN: Final = float(_T[0])
"""Lowest air temperature of the table, K."""
AIR_T_MAX: Final = float(_T[-1])
"""Highest air temperature of the table, K."""


def _clip(temperature: ArrayLike) -> FloatArray:
    # The case validator keeps every inlet inside the table and the solution stays between
    # the air and clinker inlet temperatures; clipping only guards the first iterates.
    return np.clip(np.asarray(temperature, dtype=np.float64), AIR_T_MIN, AIR_T_MAX)


def air_heat_capacity(temperature: ArrayLike) -> FloatArray:
    """Specific heat capacity of air at 1 atm, J/(kg K), at temperature(s) in K."""
    return np.interp(_clip(temperature), _T, _CP)


def air_viscosity(temperature: ArrayLike) -> FloatArray:
    """Dynamic viscosity of air at 1 atm, Pa s, at temperature(s) in K."""
    return np.interp(_clip(temperature), _T, _MU)


def air_conductivity(temperature: ArrayLike) -> FloatArray:
    """Thermal conductivity of air at 1 atm, W/(m K), at temperature(s) in K."""
    return np.interp(_clip(temperature), _T, _K)


def air_prandtl(temperature: ArrayLike) -> FloatArray:
    """Prandtl number of air at 1 atm at temperature(s) in K."""
    return np.interp(_clip(temperature), _T, _PR)


def air_enthalpy(temperature: ArrayLike) -> FloatArray:
    """Specific enthalpy of air, J/kg, zero at 250 K: the exact integral of the tabulated
    piecewise-linear c_p (so differences of it are the heat a stream takes up)."""
    t = _clip(temperature)
    k = np.clip(np.searchsorted(_T, t, side="right") - 1, 0, len(_T) - 2)
    dt = t - _T[k]
    return _H[k] + _CP[k] * dt + 0.5 * _SLOPE[k] * dt * dt


_T_LIST: Final = _T.tolist()
_H_LIST: Final = _H.tolist()
_CP_LIST: Final = _CP.tolist()
_SLOPE_LIST: Final = _SLOPE.tolist()


def air_enthalpy_scalar(temperature: float) -> tuple[float, float]:
    """:func:`air_enthalpy` and :func:`air_heat_capacity` of one temperature, in plain
    Python (the freeboard's per-cell Newton iteration calls it thousands of times)."""
    t = min(max(temperature, AIR_T_MIN), AIR_T_MAX)
    k = min(max(bisect_right(_T_LIST, t) - 1, 0), len(_T_LIST) - 2)
    dt = t - _T_LIST[k]
    return (_H_LIST[k] + _CP_LIST[k] * dt + 0.5 * _SLOPE_LIST[k] * dt * dt,
            _CP_LIST[k] + _SLOPE_LIST[k] * dt)


def air_temperature_from_enthalpy(enthalpy: ArrayLike) -> FloatArray:
    """Inverse of :func:`air_enthalpy` (exact: a quadratic per table interval)."""
    h = np.clip(np.asarray(enthalpy, dtype=np.float64), _H[0], _H[-1])
    k = np.clip(np.searchsorted(_H, h, side="right") - 1, 0, len(_T) - 2)
    a = 0.5 * _SLOPE[k]
    b = _CP[k]
    c = _H[k] - h
    # Root of a dt^2 + b dt + c = 0 in the stable form (no cancellation when a -> 0).
    dt = -2.0 * c / (b + np.sqrt(np.maximum(b * b - 4.0 * a * c, 0.0)))
    return _T[k] + dt


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


def air_density(temperature: ArrayLike, pressure: float = ATMOSPHERE) -> FloatArray:
    """Density of air as an ideal gas, rho = p M / (R T), kg/m3, at temperature(s) in K.

    Ideal gas rather than Table A.4's density column: at 1 atm and 250-2000 K the two agree
    to the table's rounding, and the ideal gas has no interpolation error between rows.
    """
    return pressure * AIR_MOLAR_MASS / (GAS_CONSTANT * _clip(temperature))


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
