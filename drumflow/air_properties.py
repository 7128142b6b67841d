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
]

KELVIN_OFFSET: Final = 273.15
"""Offset between kelvin and degrees Celsius."""

R_AIR: Final = 287.05
"""Specific gas constant of dry air (J/(kg K))."""

# Table columns in SI units. The tuples are the source of truth; the read-only arrays below are
# built from them so a caller cannot modify the table through a returned view.
_T_K: Final = (200.0, 250.0, 300.0, 350.0, 400.0, 450.0, 500.0, 550.0, 600.0)
_RHO: Final = (1.7458, 1.3947, 1.1614, 0.9950, 0.8711, 0.7740, 0.6964, 0.6329, 0.5804)
_CP: Final = tuple(1e3 * v for v in (1.007, 1.006, 1.007, 1.009, 1.014, 1.021, 1.030, 1.040, 1.051))
_MU: Final = tuple(
    1e-7 * v for v in (132.5, 159.6, 184.6, 208.2, 230.1, 250.7, 270.1, 288.4, 305.8)
)
_NU: Final = tuple(
    1e-6 * v for v in (7.590, 11.44, 15.89, 20.92, 26.41, 32.39, 38.79, 45.57, 52.69)
)
_K: Final = tuple(1e-3 * v for v in (18.1, 22.3, 26.3, 30.0, 33.8, 37.3, 40.7, 43.9, 46.9))
_PR: Final = (0.737, 0.720, 0.707, 0.700, 0.690, 0.686, 0.684, 0.683, 0.685)


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
