"""Properties of dry air at 1 atm, interpolated linearly from a published table.

The paper (Burgos-Florez et al., Processes 2019, 7, 673, Section 2.4) evaluates the Prandtl
number and kinematic viscosity of air "by linear interpolation of published" values at the
mean air temperature. This module does the same with :func:`numpy.interp` on the air table of

    F. P. Incropera, D. P. DeWitt, T. L. Bergman, A. S. Lavine,
    *Fundamentals of Heat and Mass Transfer*, 6th ed., Wiley, 2007,
    Table A.4 "Thermophysical properties of gases at atmospheric pressure", Air.

Rows 200 K to 600 K are copied (the cooler works between 30 and 90 deg C, i.e. 303-363 K;
the wider span keeps the interpolation from stopping at the edge of a real run):

=====  ========  ===========  ============  ============  ============  =====
T      rho       c_p          mu * 1e7      nu * 1e6      k * 1e3       Pr
(K)    (kg/m3)   (kJ/(kg K))  (N s/m2)      (m2/s)        (W/(m K))     (-)
=====  ========  ===========  ============  ============  ============  =====
200    1.7458    1.007        132.5         7.590         18.1          0.737
250    1.3947    1.006        159.6         11.44         22.3          0.720
300    1.1614    1.007        184.6         15.89         26.3          0.707
350    0.9950    1.009        208.2         20.92         30.0          0.700
400    0.8711    1.014        230.1         26.41         33.8          0.690
450    0.7740    1.021        250.7         32.39         37.3          0.686
500    0.6964    1.030        270.1         38.79         40.7          0.684
550    0.6329    1.040        288.4         45.57         43.9          0.683
600    0.5804    1.051        305.8         52.69         46.9          0.685
=====  ========  ===========  ============  ============  ============  =====

Temperatures in this package are in degrees Celsius; they are converted with
``T[K] = T[deg C] + 273.15``. Outside 200-600 K (-73.15 to 326.85 deg C) the functions raise
:class:`~drumflow.errors.AnalysisInputError` instead of extrapolating.

Note that the paper's own Figure 9 quotes ``Pr = 0.7282`` at the 30 deg C air inlet, which is the
value of Cengel's air table (Table A-15, 30 deg C) rather than Incropera's (0.7066 at 303.15 K
here); the two tables differ by about 3 % in Pr, which matters only when comparing absolute
values with the paper, not for the method.

The solvers (OpenFOAM's incompressible air, the DEM drag) use the ideal-gas density at the case's
inlet temperature and pressure instead of the 1 atm table column; :func:`ideal_gas_density` is the
one place it is computed.
"""

from __future__ import annotations

from bisect import bisect_right
from dataclasses import dataclass
from typing import Final

import numpy as np
from numpy.typing import ArrayLike, NDArray

from drumflow.errors import AnalysisInputError

__all__ = [
    "KELVIN_OFFSET",
    "R_AIR",
    "TABLE",
    "TABLE_T_C",
    "TABLE_T_K",
    "T_MAX_C",
    "T_MIN_C",
    "AirProperties",
    "air_properties",
    "density",
    "dynamic_viscosity",
    "ideal_gas_density",
    "kinematic_viscosity",
    "prandtl",
    "specific_heat",
    "thermal_conductivity",
    # the kelvin view (hot air to 2000 K)
    "AIR_MOLAR_MASS",
    "AIR_T_MAX",
    "AIR_T_MIN",
    "ATMOSPHERE",
    "GAS_CONSTANT",
    "air_conductivity",
    "air_density",
    "air_enthalpy",
    "air_enthalpy_scalar",
    "air_heat_capacity",
    "air_prandtl",
    "air_temperature_from_enthalpy",
    "air_viscosity",
]

KELVIN_OFFSET: Final = 273.15
"""Offset between kelvin and degrees Celsius."""

R_AIR: Final = 287.05
"""Specific gas constant of dry air (J/(kg K))."""

# Incropera 6th ed., Table A.4, air at 1 atm, 200 K to 2000 K: T (K), c_p (kJ/(kg K)),
# mu * 1e7 (N s/m2), k * 1e3 (W/(m K)), Pr. This is the one air table of drumflow: the drum's
# deg-C view below reads its rows to 600 K (with the rho and nu columns, copied only that far),
# the grate cooler's kelvin view (end of this module) reads it from 250 K to 2000 K.
_ROWS: Final = (
    (200.0, 1.007, 132.5, 18.1, 0.737),
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
# rho (kg/m3) and nu * 1e6 (m2/s) of the rows 200-600 K (the drum's range; the solvers and the
# grate take the ideal-gas density instead).
_RHO_NU: Final = (
    (1.7458, 7.590), (1.3947, 11.44), (1.1614, 15.89), (0.9950, 20.92), (0.8711, 26.41),
    (0.7740, 32.39), (0.6964, 38.79), (0.6329, 45.57), (0.5804, 52.69),
)
_DRUM_ROWS: Final = _ROWS[: len(_RHO_NU)]

# Table columns of the deg-C view in SI units. The tuples are the source of truth; the read-only
# arrays below are built from them so a caller cannot modify the table through a returned view.
_T_K: Final = tuple(row[0] for row in _DRUM_ROWS)
_RHO: Final = tuple(rho for rho, _ in _RHO_NU)
_CP: Final = tuple(1e3 * row[1] for row in _DRUM_ROWS)
_MU: Final = tuple(1e-7 * row[2] for row in _DRUM_ROWS)
_NU: Final = tuple(1e-6 * nu for _, nu in _RHO_NU)
_K: Final = tuple(1e-3 * row[3] for row in _DRUM_ROWS)
_PR: Final = tuple(row[4] for row in _DRUM_ROWS)


def _frozen(values: tuple[float, ...]) -> NDArray[np.float64]:
    arr = np.asarray(values, dtype=np.float64)
    arr.setflags(write=False)
    return arr


TABLE_T_K: Final = _frozen(_T_K)
"""Table temperatures (K)."""
TABLE_T_C: Final = _frozen(tuple(t - KELVIN_OFFSET for t in _T_K))
"""Table temperatures (deg C)."""
TABLE: Final = {
    "density": _frozen(_RHO),
    "specific_heat": _frozen(_CP),
    "dynamic_viscosity": _frozen(_MU),
    "kinematic_viscosity": _frozen(_NU),
    "thermal_conductivity": _frozen(_K),
    "prandtl": _frozen(_PR),
}
"""Property columns in SI units (kg/m3, J/(kg K), Pa s, m2/s, W/(m K), -), same order as
:data:`TABLE_T_K`."""

T_MIN_C: Final = float(TABLE_T_C[0])
"""Lowest temperature covered by the table (deg C)."""
T_MAX_C: Final = float(TABLE_T_C[-1])
"""Highest temperature covered by the table (deg C)."""

FloatOrArray = float | NDArray[np.float64]


def _interp(column: str, temperature_c: ArrayLike, name: str) -> FloatOrArray:
    t = np.asarray(temperature_c, dtype=np.float64)
    # NaN compares false with both bounds, so test "inside" rather than "outside" to catch it.
    inside = (t >= T_MIN_C) & (t <= T_MAX_C)
    if not np.all(inside):
        bad = t[~inside] if t.ndim else t
        first = float(np.ravel(bad)[0])
        raise AnalysisInputError(
            name,
            first,
            f"a temperature in [{T_MIN_C:g}, {T_MAX_C:g}] deg C "
            "(range of Incropera Table A.4 used here; no extrapolation)",
        )
    out = np.interp(t, TABLE_T_C, TABLE[column])
    return float(out) if out.ndim == 0 else out


def prandtl(temperature_c: ArrayLike, *, name: str = "temperature_c") -> FloatOrArray:
    """Prandtl number of dry air at 1 atm.

    Parameters
    ----------
    temperature_c
        Air temperature (deg C), scalar or array.
    name
        Argument name reported if the temperature is outside the table.

    Returns
    -------
    float or numpy.ndarray
        Pr (-); a float for scalar input.

    Raises
    ------
    AnalysisInputError
        If a temperature is NaN or outside [-73.15, 326.85] deg C.
    """
    return _interp("prandtl", temperature_c, name)


def kinematic_viscosity(temperature_c: ArrayLike, *, name: str = "temperature_c") -> FloatOrArray:
    """Kinematic viscosity of dry air at 1 atm (m2/s).

    Parameters
    ----------
    temperature_c
        Air temperature (deg C), scalar or array.
    name
        Argument name reported if the temperature is outside the table.

    Returns
    -------
    float or numpy.ndarray
        nu (m2/s); a float for scalar input.

    Raises
    ------
    AnalysisInputError
        If a temperature is NaN or outside the table.
    """
    return _interp("kinematic_viscosity", temperature_c, name)


def dynamic_viscosity(temperature_c: ArrayLike, *, name: str = "temperature_c") -> FloatOrArray:
    """Dynamic viscosity of dry air at 1 atm (Pa s).

    Parameters
    ----------
    temperature_c
        Air temperature (deg C), scalar or array.
    name
        Argument name reported if the temperature is outside the table.

    Returns
    -------
    float or numpy.ndarray
        mu (Pa s); a float for scalar input.

    Raises
    ------
    AnalysisInputError
        If a temperature is NaN or outside the table.
    """
    return _interp("dynamic_viscosity", temperature_c, name)


def thermal_conductivity(temperature_c: ArrayLike, *, name: str = "temperature_c") -> FloatOrArray:
    """Thermal conductivity of dry air at 1 atm (W/(m K)).

    Parameters
    ----------
    temperature_c
        Air temperature (deg C), scalar or array.
    name
        Argument name reported if the temperature is outside the table.

    Returns
    -------
    float or numpy.ndarray
        k (W/(m K)); a float for scalar input.

    Raises
    ------
    AnalysisInputError
        If a temperature is NaN or outside the table.
    """
    return _interp("thermal_conductivity", temperature_c, name)


def density(temperature_c: ArrayLike, *, name: str = "temperature_c") -> FloatOrArray:
    """Density of dry air at 1 atm (kg/m3).

    Parameters
    ----------
    temperature_c
        Air temperature (deg C), scalar or array.
    name
        Argument name reported if the temperature is outside the table.

    Returns
    -------
    float or numpy.ndarray
        rho (kg/m3); a float for scalar input.

    Raises
    ------
    AnalysisInputError
        If a temperature is NaN or outside the table.
    """
    return _interp("density", temperature_c, name)


def specific_heat(temperature_c: ArrayLike, *, name: str = "temperature_c") -> FloatOrArray:
    """Specific heat at constant pressure of dry air at 1 atm (J/(kg K)).

    Parameters
    ----------
    temperature_c
        Air temperature (deg C), scalar or array.
    name
        Argument name reported if the temperature is outside the table.

    Returns
    -------
    float or numpy.ndarray
        c_p (J/(kg K)); a float for scalar input.

    Raises
    ------
    AnalysisInputError
        If a temperature is NaN or outside the table.
    """
    return _interp("specific_heat", temperature_c, name)


@dataclass(frozen=True)
class AirProperties:
    """All tabulated properties of dry air at one temperature.

    Attributes
    ----------
    temperature_c
        Temperature (deg C).
    density
        rho (kg/m3).
    specific_heat
        c_p (J/(kg K)).
    dynamic_viscosity
        mu (Pa s).
    kinematic_viscosity
        nu (m2/s).
    thermal_conductivity
        k (W/(m K)).
    prandtl
        Pr (-).
    """

    temperature_c: float
    density: float
    specific_heat: float
    dynamic_viscosity: float
    kinematic_viscosity: float
    thermal_conductivity: float
    prandtl: float


def air_properties(temperature_c: float, *, name: str = "temperature_c") -> AirProperties:
    """Every tabulated property of dry air at one temperature.

    Parameters
    ----------
    temperature_c
        Air temperature (deg C).
    name
        Argument name reported if the temperature is outside the table.

    Returns
    -------
    AirProperties
        Interpolated properties.

    Raises
    ------
    AnalysisInputError
        If the temperature is not a finite scalar inside the table.
    """
    t = np.asarray(temperature_c, dtype=np.float64)
    if t.ndim != 0:
        raise AnalysisInputError(name, f"array of shape {t.shape}", "a scalar temperature")
    props = {col: float(_interp(col, t, name)) for col in TABLE}
    return AirProperties(temperature_c=float(t), **props)


def ideal_gas_density(temperature_c: float, pressure_kpa: float = 101.325) -> float:
    """Ideal-gas density of dry air, rho = p / (R_air T) (kg/m3).

    The air in the drum is treated as incompressible at this density (the paper: "constant
    density gas"), evaluated at the inlet temperature and pressure of the case.

    Parameters
    ----------
    temperature_c
        Air temperature (deg C).
    pressure_kpa
        Absolute pressure (kPa).

    Returns
    -------
    float
        rho (kg/m3).
    """
    return pressure_kpa * 1e3 / (R_AIR * (temperature_c + KELVIN_OFFSET))


# -- the kelvin view: hot air to 2000 K (the grate cooler) ----------------------------------
# Properties linear in temperature between rows, clipped (not refused) at the ends: the grate's
# case validator keeps every inlet inside the table and its solution stays between the air and
# clinker inlet temperatures, so clipping only guards the first iterates. The enthalpy is the
# exact integral of the piecewise-linear c_p, so an energy balance closes to round-off.

FloatArray = NDArray[np.float64]

GAS_CONSTANT: Final = 8.314462618
"""Molar gas constant, J/(mol K) (CODATA 2018)."""

AIR_MOLAR_MASS: Final = 0.0289644
"""Molar mass of dry air, kg/mol (US Standard Atmosphere 1976)."""

ATMOSPHERE: Final = 101325.0
"""Pressure of the air in the bed and at the fans, Pa (the bed's few kPa are neglected)."""

# From 250 K, as the grate model has always read it: its enthalpy is zero there and its
# temperatures are clipped there (the 200 K row would move both).
_HOT = np.asarray(_ROWS[1:], dtype=np.float64)
_T_HOT: Final = _HOT[:, 0].copy()
_CP_HOT: Final = 1e3 * _HOT[:, 1]
_MU_HOT: Final = 1e-7 * _HOT[:, 2]
_K_HOT: Final = 1e-3 * _HOT[:, 3]
_PR_HOT: Final = _HOT[:, 4].copy()
# Enthalpy at the table rows (J/kg, zero at 250 K): trapezoids are exact for linear c_p.
_H: Final = np.concatenate(([0.0], np.cumsum(0.5 * (_CP_HOT[1:] + _CP_HOT[:-1]) * np.diff(_T_HOT))))
_SLOPE: Final = np.diff(_CP_HOT) / np.diff(_T_HOT)

AIR_T_MIN: Final = float(_T_HOT[0])
"""Lowest air temperature of the table, K."""
AIR_T_MAX: Final = float(_T_HOT[-1])
"""Highest air temperature of the table, K."""


def _clip(temperature: ArrayLike) -> FloatArray:
    return np.clip(np.asarray(temperature, dtype=np.float64), AIR_T_MIN, AIR_T_MAX)


def air_heat_capacity(temperature: ArrayLike) -> FloatArray:
    """Specific heat capacity of air at 1 atm, J/(kg K), at temperature(s) in K."""
    return np.interp(_clip(temperature), _T_HOT, _CP_HOT)


def air_viscosity(temperature: ArrayLike) -> FloatArray:
    """Dynamic viscosity of air at 1 atm, Pa s, at temperature(s) in K."""
    return np.interp(_clip(temperature), _T_HOT, _MU_HOT)


def air_conductivity(temperature: ArrayLike) -> FloatArray:
    """Thermal conductivity of air at 1 atm, W/(m K), at temperature(s) in K."""
    return np.interp(_clip(temperature), _T_HOT, _K_HOT)


def air_prandtl(temperature: ArrayLike) -> FloatArray:
    """Prandtl number of air at 1 atm at temperature(s) in K."""
    return np.interp(_clip(temperature), _T_HOT, _PR_HOT)


def air_enthalpy(temperature: ArrayLike) -> FloatArray:
    """Specific enthalpy of air, J/kg, zero at 250 K: the exact integral of the tabulated
    piecewise-linear c_p (so differences of it are the heat a stream takes up)."""
    t = _clip(temperature)
    k = np.clip(np.searchsorted(_T_HOT, t, side="right") - 1, 0, len(_T_HOT) - 2)
    dt = t - _T_HOT[k]
    return _H[k] + _CP_HOT[k] * dt + 0.5 * _SLOPE[k] * dt * dt


_T_LIST: Final = _T_HOT.tolist()
_H_LIST: Final = _H.tolist()
_CP_LIST: Final = _CP_HOT.tolist()
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
    k = np.clip(np.searchsorted(_H, h, side="right") - 1, 0, len(_T_HOT) - 2)
    a = 0.5 * _SLOPE[k]
    b = _CP_HOT[k]
    c = _H[k] - h
    # Root of a dt^2 + b dt + c = 0 in the stable form (no cancellation when a -> 0).
    dt = -2.0 * c / (b + np.sqrt(np.maximum(b * b - 4.0 * a * c, 0.0)))
    return _T_HOT[k] + dt


def air_density(temperature: ArrayLike, pressure: float = ATMOSPHERE) -> FloatArray:
    """Density of air as an ideal gas, rho = p M / (R T), kg/m3, at temperature(s) in K.

    Ideal gas rather than Table A.4's density column: at 1 atm and 250-2000 K the two agree
    to the table's rounding, and the ideal gas has no interpolation error between rows.
    """
    return pressure * AIR_MOLAR_MASS / (GAS_CONSTANT * _clip(temperature))
