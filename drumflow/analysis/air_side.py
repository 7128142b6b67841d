"""What the one-way air does to the particles of a snapshot: the heat-transfer coefficient each
particle sees, split into the falling curtain and the bed, and the mean temperature it implies.

With one-way air (the paper's set-up and drumflow's), the air reaches every particle, in the
bed as in the curtain, at the velocity of the air field where the particle sits; the particle
motion only enters through the slip velocity. So the mean temperature follows the lumped
solution of one particle at the surface-mean Ranz-Marshall h of the particles' slip
velocities (the same correlation and air state the coupling applies:
:func:`drumflow.physics.particle_air.ranz_marshall_h`). This module computes that h from a
snapshot and an air field, with no solver:

- :func:`sample_air_side` gives the h each particle sees, its mean over all particles, over
  the bed and over the airborne (falling) particles, and their shares of the heat removed;
- :func:`lumped_mean_temperature` integrates the mean temperature with a time-varying h.

It answers "what decides the mean temperature at 3.5 s" by measurement: the same snapshot
sampled in air fields of different meshes, or with the paper's h, gives the temperature each
would produce.

Airborne: a particle falling faster than anything the turning shell could carry it, i.e. with
a downward velocity larger than the shell speed omega R plus 0.5 m/s (the speed a particle
reaches after a free fall of about 1.3 cm, so a particle leaving a lifter counts within a few
milliseconds, while the bed's avalanching surface layer, which slides at well under 0.5 m/s
relative to the shell, does not).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import asdict, dataclass
from typing import Any, Protocol

import numpy as np
from numpy.typing import NDArray

from drumflow.case import Case
from drumflow.physics.particle_air import AirState, lumped_cooling, ranz_marshall_h

#: Margin over the shell speed beyond which a downward-moving particle counts as airborne, m/s.
AIRBORNE_MARGIN_M_S = 0.5


class _Sampler(Protocol):
    """Anything with ``sample_lab(points, time_s)`` (:class:`drumflow.air.field.AirField`)."""

    def sample_lab(self, points: NDArray[np.float64], time_s: float) -> NDArray[np.float64]: ...


@dataclass(frozen=True)
class AirSideSample:
    """The air side of one snapshot.

    Attributes
    ----------
    time_s
        Simulated time of the snapshot.
    particles, airborne
        Particle count, and how many are airborne.
    mean_temperature_C
        Mass-weighted mean particle temperature.
    h_mean_w_m2k, h_bed_w_m2k, h_airborne_w_m2k
        Surface-weighted mean Ranz-Marshall h over all, bed and airborne particles
        (``nan`` where a group is empty).
    slip_mean_m_s, slip_bed_m_s, slip_airborne_m_s
        Mean slip speed |u_air - v_p| of the same groups.
    heat_rate_w
        Heat the air removes at this instant: sum of h A (T_p - T_air).
    airborne_heat_share
        Share of ``heat_rate_w`` removed from airborne particles.
    """

    time_s: float
    particles: int
    airborne: int
    mean_temperature_C: float
    h_mean_w_m2k: float
    h_bed_w_m2k: float
    h_airborne_w_m2k: float
    slip_mean_m_s: float
    slip_bed_m_s: float
    slip_airborne_m_s: float
    heat_rate_w: float
    airborne_heat_share: float

    def to_dict(self) -> dict[str, Any]:
        return asdict(self)


def airborne_mask(case: Case, velocity: NDArray[np.float64]) -> NDArray[np.bool_]:
    """Particles falling faster than the shell could carry them (module docstring)."""
    limit = case.drum.omega * case.drum.radius + AIRBORNE_MARGIN_M_S
    return np.asarray(velocity[:, 1] < -limit)


def _mean(values: NDArray[np.float64], mask: NDArray[np.bool_]) -> float:
    return float(values[mask].mean()) if mask.any() else math.nan


def sample_air_side(case: Case, field: _Sampler, columns: dict[str, NDArray[np.float64]],
                    time_s: float, air: AirState | None = None) -> AirSideSample:
    """The h each particle of a snapshot sees, and its means over the bed and the curtain.

    Parameters
    ----------
    case
        The case (drum speed and radius, air temperature and pressure).
    field
        The air field, sampled in the laboratory frame at ``time_s``.
    columns
        Snapshot columns ``x y z vx vy vz radius T`` (a :class:`drumflow.dem.dumps.Snapshot`'s
        ``columns``), SI units, T in degrees C.
    time_s
        Simulated time of the snapshot (sets the drum angle of the air field).
    air
        Air state; default: the case's inlet air, as the coupling uses it.
    """
    air = air or AirState.at(case.air.inlet_temperature_C, case.air.pressure_kPa)
    points = np.column_stack([columns["x"], columns["y"], columns["z"]])
    velocity = np.column_stack([columns["vx"], columns["vy"], columns["vz"]])
    diameter = 2.0 * columns["radius"]
    slip = np.linalg.norm(field.sample_lab(points, time_s) - velocity, axis=1)
    h = ranz_marshall_h(slip, diameter, air)
    area = math.pi * diameter**2
    mass = diameter**3  # proportional to mass at one density
    temperature = columns["T"]
    q = h * area * (temperature - air.temperature_C)
    falling = airborne_mask(case, velocity)
    bed = ~falling

    def surface_mean(mask: NDArray[np.bool_]) -> float:
        return float(np.sum(h[mask] * area[mask]) / np.sum(area[mask])) if mask.any() else math.nan

    total_q = float(q.sum())
    return AirSideSample(
        time_s=time_s,
        particles=len(h),
        airborne=int(falling.sum()),
        mean_temperature_C=float(np.sum(mass * temperature) / np.sum(mass)),
        h_mean_w_m2k=surface_mean(np.ones_like(falling)),
        h_bed_w_m2k=surface_mean(bed),
        h_airborne_w_m2k=surface_mean(falling),
        slip_mean_m_s=float(slip.mean()),
        slip_bed_m_s=_mean(slip, bed),
        slip_airborne_m_s=_mean(slip, falling),
        heat_rate_w=total_q,
        airborne_heat_share=float(q[falling].sum() / total_q) if total_q != 0 else math.nan,
    )


def lumped_h(case: Case, temperature_C: float, time_s: float) -> float:
    """The constant h, W/(m2 K), at which the case's lumped particles reach ``temperature_C`` at
    ``time_s`` from its initial temperature: :func:`lumped_mean_temperature` solved for h,
    ``h = rho cp D / (6 t) ln((T0 - T_air) / (T - T_air))``.

    How a published mean temperature becomes the h the lumped slice would need (the paper's
    Tables 3-4 per mesh). NaN when ``temperature_C`` is not between the air's and the initial
    temperature.
    """
    p = case.particles
    t_air = case.air.inlet_temperature_C
    excess = temperature_C - t_air
    if not (time_s > 0.0 and excess != 0.0):
        return math.nan  # at the air's temperature only an infinite h gets there
    ratio = (p.initial_temperature_C - t_air) / excess
    if not (ratio >= 1.0 and math.isfinite(ratio)):
        return math.nan
    return p.density * p.heat_capacity * p.diameter / (6.0 * time_s) * math.log(ratio)


def lumped_mean_temperature(case: Case, h_w_m2k: Callable[[float], float] | float,
                            times: NDArray[np.float64], start_C: float | None = None,
                            start_time: float = 0.0) -> NDArray[np.float64]:
    """Mean temperature of particles that all see one (possibly time-varying) h.

    dT/dt = -6 h (T - T_air) / (rho cp D): the lumped solution the one-way slice follows
    (Bi is not small for NPK, but the coupling treats each particle as lumped, as the paper's
    does, so this is the reference for the slice, not for a real granule).

    Parameters
    ----------
    h_w_m2k
        A constant, or h as a function of time (piecewise: integrated with the trapezoidal
        rule on ``times``).
    times
        Increasing times, s, at which the temperature is returned.
    start_C, start_time
        The temperature at ``start_time`` (default: the case's initial temperature at 0).
    """
    p = case.particles
    rate = 6.0 / (p.density * p.heat_capacity * p.diameter)
    t_air = case.air.inlet_temperature_C
    t0 = p.initial_temperature_C if start_C is None else start_C
    grid = np.concatenate([[start_time], np.asarray(times, float)])
    if callable(h_w_m2k):
        hv = np.array([h_w_m2k(t) for t in grid])
    else:
        hv = np.full(grid.shape, float(h_w_m2k))
    exponent = np.concatenate([[0.0], np.cumsum(0.5 * (hv[1:] + hv[:-1]) * np.diff(grid))]) * rate
    return lumped_cooling(t0, t_air, exponent[1:])
