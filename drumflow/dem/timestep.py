"""DEM time-step limits (physics only: no solver, unit-tested on their own).

The Rayleigh time is the period of a Rayleigh surface wave crossing a particle; explicit DEM
with Hertz contacts stays stable and accurate below a fraction of it (commonly 10-40%). The
Hertz contact duration bounds the step from the collision side: a contact must be resolved
by tens of steps for the realised restitution to match the input.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from drumflow.case import Case

G = 9.81


def rayleigh_time(radius: float, density: float, youngs_modulus: float, poisson: float) -> float:
    """Rayleigh time of a sphere, s.

    t_R = pi r sqrt(rho / G) / (0.1631 nu + 0.8766), with shear modulus G = E / (2 (1 + nu)).
    """
    shear = youngs_modulus / (2.0 * (1.0 + poisson))
    return math.pi * radius * math.sqrt(density / shear) / (0.1631 * poisson + 0.8766)


def hertz_contact_time(
    radius: float, density: float, youngs_modulus: float, poisson: float, impact_velocity: float
) -> float:
    """Duration of an elastic Hertz collision of two equal spheres, s.

    t_c = 2.87 (m*^2 / (R* E*^2 v))^(1/5) with m* = m/2, R* = r/2, E* = E / (2 (1 - nu^2)).
    """
    mass = density * 4.0 / 3.0 * math.pi * radius**3
    m_eff = 0.5 * mass
    r_eff = 0.5 * radius
    e_eff = youngs_modulus / (2.0 * (1.0 - poisson**2))
    v = max(impact_velocity, 1e-6)
    return 2.87 * (m_eff**2 / (r_eff * e_eff**2 * v)) ** 0.2


def impact_velocity(case: Case) -> float:
    """A bound on collision speeds in the drum: free fall across the diameter, or the wall speed."""
    return max(math.sqrt(2.0 * G * case.drum.diameter), case.drum.omega * case.drum.radius)


def typical_impact_velocity(case: Case) -> float:
    """A typical collision speed in the cascade, m/s: half of :func:`impact_velocity`.

    Particles rarely fall the whole diameter before meeting another; the restitution
    correction (:mod:`drumflow.dem.restitution`) is made at this speed, while the time step is
    bounded at the full one (the shortest contacts).
    """
    return 0.5 * impact_velocity(case)


@dataclass(frozen=True)
class TimeStepChoice:
    """The DEM time step and where it came from (recorded in the manifest)."""

    time_step: float
    rayleigh_time: float
    hertz_time: float
    fraction_of_rayleigh: float
    steps_per_contact: float
    mode: str  # "auto", "fixed", or "forced" (fixed above the stability limit, on request)

    def as_dict(self) -> dict[str, Any]:
        return asdict(self)


#: A contact must span at least this many steps; fewer and the Hertz force is sampled too
#: coarsely (restitution and overlap drift), so a fixed time step above it is refused.
MIN_STEPS_PER_CONTACT = 10.0


def choose_time_step(case: Case) -> TimeStepChoice:
    """The DEM time step for a case: a fraction of the Rayleigh time, or the user's value.

    Raises
    ------
    CaseError
        When a fixed time step exceeds the Rayleigh time's 0.5 fraction or resolves a contact
        with fewer than :data:`MIN_STEPS_PER_CONTACT` steps.
    """
    from drumflow.errors import CaseError

    p = case.particles
    t_r = rayleigh_time(p.radius, p.density, p.youngs_modulus, p.poisson_ratio)
    t_h = hertz_contact_time(p.radius, p.density, p.youngs_modulus, p.poisson_ratio, impact_velocity(case))
    if case.run.time_step == "auto":
        dt = case.run.rayleigh_fraction * t_r
        dt = min(dt, t_h / MIN_STEPS_PER_CONTACT)
        mode = "auto"
    else:
        dt = float(case.run.time_step)
        mode = "fixed"
        limit = min(0.5 * t_r, t_h / MIN_STEPS_PER_CONTACT)
        if dt > limit and case.run.force_time_step:
            mode = "forced"  # a stress test: the stability monitor will stop it if it blows up
        elif dt > limit:
            raise CaseError(
                [
                    f"run.time_step = {dt:g} s: above the stability limit {limit:.3g} s "
                    f"(half the Rayleigh time {t_r:.3g} s, and at least "
                    f"{MIN_STEPS_PER_CONTACT:g} steps per Hertz contact of {t_h:.3g} s); "
                    "use 'auto' or a smaller value (or run.force_time_step = true to try it)"
                ]
            )
    return TimeStepChoice(
        time_step=dt,
        rayleigh_time=t_r,
        hertz_time=t_h,
        fraction_of_rayleigh=dt / t_r,
        steps_per_contact=t_h / dt,
        mode=mode,
    )
