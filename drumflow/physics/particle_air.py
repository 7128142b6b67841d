"""Air acting on particles: drag (Schiller-Naumann) and convection (Ranz-Marshall; Gunn in beds).

Physics only, vectorised over particles and free of any solver, so it is unit-tested against
closed forms. The same functions give the analytic references of the verification cases
(lumped cooling, terminal velocity).

Equations of Burgos-Florez et al. (2019): drag F_d = 1/2 C_d rho A_p |V_s| V_s (Eq. 3) with the
Schiller-Naumann C_d; pressure-gradient force F_p = -V_p grad p (Eq. 4); convective heat
Q = h A_s (T - T_p) (Eq. 21) with Nu = h D_p / k_f (Eq. 22) = 2 (1 + 0.3 Re^0.5 Pr^(1/3))
(Eq. 23, Ranz-Marshall). Among many particles (a bed, a dense curtain): Gunn's (1978) Nusselt
number at the local voidage (:func:`gunn_nusselt`, :func:`gunn_h`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray
from scipy.optimize import brentq

from drumflow.physics import air as air_table


@dataclass(frozen=True)
class AirState:
    """Air properties at one temperature and pressure (one-way coupling: the air keeps them)."""

    temperature_C: float
    density: float  # kg/m3, ideal gas at the given pressure
    viscosity: float  # Pa s (dynamic)
    conductivity: float  # W/(m K)
    prandtl: float

    @classmethod
    def at(cls, temperature_C: float, pressure_kPa: float = 101.325) -> AirState:
        """Air at a temperature (Incropera Table A.4 for mu, k, Pr; ideal gas for rho)."""
        rho = air_table.ideal_gas_density(temperature_C, pressure_kPa)
        return cls(
            temperature_C=temperature_C,
            density=rho,
            viscosity=float(air_table.dynamic_viscosity(temperature_C)),
            conductivity=float(air_table.thermal_conductivity(temperature_C)),
            prandtl=float(air_table.prandtl(temperature_C)),
        )


def schiller_naumann_cd(reynolds: NDArray[np.float64] | float) -> NDArray[np.float64]:
    """Drag coefficient of a sphere: 24/Re (1 + 0.15 Re^0.687) up to Re = 1000, then 0.44.

    Zero Reynolds number gives an infinite coefficient; callers multiply by |V_s|^2, so the
    force is formed as :func:`drag_force` does, without dividing by zero.
    """
    re = np.asarray(reynolds, dtype=float)
    with np.errstate(divide="ignore"):
        cd = np.where(re < 1000.0, 24.0 / re * (1.0 + 0.15 * re**0.687), 0.44)
    return cd


def drag_force(
    air_velocity: NDArray[np.float64],
    particle_velocity: NDArray[np.float64],
    diameter: NDArray[np.float64] | float,
    air: AirState,
) -> NDArray[np.float64]:
    """Schiller-Naumann drag on spheres, N, shape (n, 3) (Eq. 3).

    Written as F = 3 pi mu d V_s (1 + 0.15 Re^0.687) below Re = 1000 (Stokes times the
    correction, finite at zero slip) and 0.44 * 1/2 rho A |V_s| V_s above.
    """
    slip = np.asarray(air_velocity, float) - np.asarray(particle_velocity, float)
    speed = np.linalg.norm(slip, axis=1)
    d = np.broadcast_to(np.asarray(diameter, float), speed.shape)
    re = air.density * speed * d / air.viscosity
    stokes = 3.0 * math.pi * air.viscosity * d * (1.0 + 0.15 * re**0.687)
    newton = 0.44 * 0.5 * air.density * (math.pi / 4.0) * d**2 * speed
    coeff = np.where(re < 1000.0, stokes, newton)
    return coeff[:, None] * slip


def ranz_marshall_h(
    slip_speed: NDArray[np.float64] | float, diameter: NDArray[np.float64] | float, air: AirState
) -> NDArray[np.float64]:
    """Heat-transfer coefficient, W/(m2 K), from Nu = 2 (1 + 0.3 Re^0.5 Pr^(1/3)) (Eq. 23)."""
    d = np.asarray(diameter, float)
    re = air.density * np.asarray(slip_speed, float) * d / air.viscosity
    nu = 2.0 * (1.0 + 0.3 * np.sqrt(re) * air.prandtl ** (1.0 / 3.0))
    return nu * air.conductivity / d


def ranz_marshall_slip(h: float, diameter: float, air: AirState) -> float:
    """The slip speed, m/s, at which :func:`ranz_marshall_h` gives ``h``: Eq. 23 solved for Re.

    Used to say what air speed a published h needs in the same correlation. NaN when ``h`` is
    at or below the still-air limit ``2 k / d`` (no slip gives less).
    """
    nu = h * diameter / air.conductivity
    root_re = (0.5 * nu - 1.0) / (0.3 * air.prandtl ** (1.0 / 3.0))
    if not root_re > 0.0:
        return math.nan
    return float(root_re**2 * air.viscosity / (air.density * diameter))


def convective_heat(
    air_velocity: NDArray[np.float64],
    particle_velocity: NDArray[np.float64],
    particle_temperature: NDArray[np.float64],
    diameter: NDArray[np.float64] | float,
    air: AirState,
) -> NDArray[np.float64]:
    """Heat to each particle, W (negative when the particle cools): h pi d^2 (T_air - T_p)."""
    slip = np.linalg.norm(np.asarray(air_velocity, float) - np.asarray(particle_velocity, float), axis=1)
    d = np.broadcast_to(np.asarray(diameter, float), slip.shape)
    h = ranz_marshall_h(slip, d, air)
    return h * math.pi * d**2 * (air.temperature_C - np.asarray(particle_temperature, float))


#: Voidage range of Gunn's (1978) correlation.
GUNN_VOIDAGE = (0.35, 1.0)


def gunn_nusselt(
    reynolds: NDArray[np.float64] | float,
    prandtl: float,
    voidage: NDArray[np.float64] | float,
) -> NDArray[np.float64]:
    """Gas-particle Nusselt number in fixed and fluidised beds (D.J. Gunn, Int. J. Heat Mass
    Transfer 21 (1978) 467-476):

    Nu = (7 - 10 eps + 5 eps^2)(1 + 0.7 Re^0.2 Pr^(1/3)) + (1.33 - 2.4 eps + 1.2 eps^2) Re^0.7 Pr^(1/3)

    with Re = rho u d / mu on the *superficial* slip speed u = eps |U_gas - v_p| (U_gas
    interstitial), for 0.35 <= eps <= 1 and Re <= 1e5. At eps = 1 and Re = 0 it gives Nu = 2,
    the still-air sphere.

    Raises
    ------
    drumflow.errors.AnalysisInputError
        A voidage outside 0.35..1, or a negative or non-finite Reynolds number.
    """
    from drumflow.errors import AnalysisInputError

    eps = np.asarray(voidage, float)
    re = np.asarray(reynolds, float)
    lo, hi = GUNN_VOIDAGE
    if np.any(~((eps >= lo) & (eps <= hi))):
        bad = eps[~((eps >= lo) & (eps <= hi))].ravel()[0]
        raise AnalysisInputError("voidage", float(bad), f"Gunn's range {lo}..{hi}")
    if np.any(~(re >= 0.0)) or np.any(~np.isfinite(re)):
        raise AnalysisInputError("reynolds", re[~(np.isfinite(re) & (re >= 0.0))].ravel()[0],
                                 "finite numbers >= 0")
    pr3 = prandtl ** (1.0 / 3.0)
    return np.asarray((7.0 - 10.0 * eps + 5.0 * eps**2) * (1.0 + 0.7 * re**0.2 * pr3)
                      + (1.33 - 2.4 * eps + 1.2 * eps**2) * re**0.7 * pr3, dtype=float)


def gunn_h(
    superficial_slip: NDArray[np.float64] | float,
    voidage: NDArray[np.float64] | float,
    diameter: float,
    air: AirState,
) -> NDArray[np.float64]:
    """Heat-transfer coefficient, W/(m2 K), of a particle of ``diameter`` (m) in a bed of
    ``voidage`` at the superficial slip speed (m/s): Nu k_air / d, Nu by :func:`gunn_nusselt`."""
    re = air.density * np.asarray(superficial_slip, float) * diameter / air.viscosity
    return gunn_nusselt(re, air.prandtl, voidage) * air.conductivity / diameter


# -- analytic references ------------------------------------------------------------------
def lumped_cooling(
    T0: float, T_air: float, exposure: NDArray[np.float64] | float
) -> NDArray[np.float64]:
    """Exact lumped (Bi -> 0) cooling: ``T_air + (T0 - T_air) exp(-exposure)``.

    ``exposure`` is the integral of ``h A / (m c_p)`` over the time the particle has spent in
    the air (dimensionless): ``t h A / (m c_p)`` at constant h, a trapezoidal sum when h
    changes. The one place drumflow writes the lumped solution; :func:`lumped_temperature`,
    :func:`drumflow.physics.particle_interior.lumped_mean_temperature` and the air-side
    reference with h changing in time (:func:`drumflow.analysis.air_side.lumped_mean_temperature`)
    all go through it.
    """
    return np.asarray(T_air + (T0 - T_air) * np.exp(-np.asarray(exposure, float)), dtype=float)


def lumped_temperature(
    t: NDArray[np.float64] | float, T0: float, T_air: float, h: float, mass: float, cp: float, area: float
) -> NDArray[np.float64]:
    """Exact lumped cooling at constant h: T_air + (T0 - T_air) exp(-t h A / (m cp))."""
    rate = h * area / (mass * cp)
    return lumped_cooling(T0, T_air, rate * np.asarray(t, float))


def terminal_velocity(diameter: float, particle_density: float, air: AirState, g: float = 9.81) -> float:
    """Settling speed where Schiller-Naumann drag balances the weight (no buoyancy), m/s.

    Buoyancy is left out because the DEM applies full gravity and the pressure-gradient force
    (which would carry it) is optional.
    """
    mass = particle_density * math.pi / 6.0 * diameter**3

    def balance(v: float) -> float:
        f = drag_force(np.array([[0.0, 0.0, 0.0]]), np.array([[0.0, 0.0, -v]]), diameter, air)
        return float(f[0, 2]) - mass * g

    upper = 1.0
    while balance(upper) < 0:
        upper *= 2.0
    return float(brentq(balance, 1e-9, upper, xtol=1e-12, rtol=1e-12))


def auto_coupling_interval(
    time_step: float,
    diameter: float,
    particle_density: float,
    heat_capacity: float,
    air: AirState,
    max_slip: float,
    cap: int,
) -> int:
    """DEM steps between air updates so that the coupling error stays near 0.1% of the heat.

    Between updates the convective heat uses the particle temperature of the last update; for
    lumped cooling the relative error of that explicit hold is about N dt / (2 tau) with tau =
    m cp / (h A). Holding N dt <= 0.002 tau (at the largest slip, hence the shortest tau) keeps
    it at 0.1%. The drag is held for the same interval; its momentum response time is far
    longer than a few milliseconds for millimetre particles, so heat sets the limit. The
    N-sweep of the verification suite measures the real error.
    """
    mass = particle_density * math.pi / 6.0 * diameter**3
    h = float(ranz_marshall_h(max_slip, diameter, air))
    tau = mass * heat_capacity / (h * math.pi * diameter**2)
    return int(max(1, min(cap, math.floor(0.002 * tau / time_step))))
