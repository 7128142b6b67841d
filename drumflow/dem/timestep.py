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

from drumflow.dem.collision_speed import G, impact_velocity

if TYPE_CHECKING:
    from drumflow.case import Case

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


#: Contacts per particle in the packed bed for :func:`spin_mode`: a dense random
#: packing of frictional spheres has 4.5-6; the upper end, so the limit is not optimistic.
BED_CONTACTS = 6
#: Solid fraction of the packed bed for :func:`bed_contact_overlap` (random packing, 0.55-0.64).
BED_SOLID_FRACTION = 0.6


def verlet_damping_limit(damping_ratio: float) -> float:
    """Largest ``omega dt`` at which a damped linear oscillator stays stable under LIGGGHTS'
    velocity Verlet, whose dashpots use the half-step velocity: ``2 (sqrt(1 + zeta^2) - zeta)``.

    2 without damping; about ``1 / zeta`` for a heavily damped mode, i.e. the explicit dashpot's
    own limit ``dt < 2 m / c``. (The amplification matrix of the scheme applied to
    ``x'' + 2 zeta omega x' + omega^2 x = 0`` has spectral radius 1 there; the unit tests check
    it against the eigenvalues.)
    """
    if damping_ratio < 0.0:
        raise ValueError(f"damping_ratio = {damping_ratio!r}: must be >= 0")
    return 2.0 * (math.sqrt(1.0 + damping_ratio**2) - damping_ratio)


@dataclass(frozen=True)
class SpinMode:
    """The fastest rotational mode of a particle in enduring contacts (:func:`spin_mode`)."""

    frequency: float  # rad/s
    damping_ratio: float
    time_step_limit: float  # s: above it, velocity Verlet excites the mode instead of damping it

    def as_dict(self) -> dict[str, Any]:
        return asdict(self)


def spin_mode(radius: float, density: float, youngs_modulus: float, poisson: float,
              restitution: float, overlap: float, contacts: int = BED_CONTACTS,
              damped: bool = True) -> SpinMode:
    """The spin of a particle against ``contacts`` equal neighbours spinning the other way, the
    fastest rotational mode of a packed bed, with LIGGGHTS' Hertz tangential spring and dashpot.

    At each contact the surfaces slide at ``2 a w`` (w the spin rate, ``a = r - delta / 2`` the
    lever arm to the contact point, as LIGGGHTS takes it), against the tangential spring
    ``k_t = 8 G* sqrt(R* delta)`` and dashpot ``g_t = 2 sqrt(5/6) |beta| sqrt(k_t m*)``
    (``beta = ln e / sqrt(ln^2 e + pi^2)``, ``m* = m / 2``), so with ``I = 2/5 m r^2``:
    ``omega^2 = 2 n k_t a^2 / I`` and ``2 zeta omega = 2 n g_t a^2 / I``. The dashpot is
    designed for the translational mass ``m*``, but spin moves only ``I / a^2`` (about 0.4 m):
    the rotational mode is damped beyond critical, and its explicit dashpot limits the step
    (:func:`verlet_damping_limit`). Above that step the dashpot excites the spin at every step
    until the contact slides (Coulomb): a numerical spin the bed keeps. For ``contacts = 1``
    this is two particles spinning the same way on one contact, which LIGGGHTS reproduces
    (tests/solver/test_spin_liggghts.py). Without the dashpot (``damped = False``,
    ``contacts.tangential_damping = false``) the spring alone limits the step, at
    ``omega dt = 2``, about twice as far: LIGGGHTS reproduces that too.

    Parameters
    ----------
    radius, density, youngs_modulus, poisson
        The particles (m, kg/m3, Pa, -).
    restitution
        The restitution coefficient LIGGGHTS is given (after the step's calibration).
    overlap
        Normal overlap of the contacts, m (:func:`bed_contact_overlap`).
    contacts
        Contacts per particle.
    damped
        Whether the contacts have the tangential dashpot (LIGGGHTS' default).
    """
    if not 0.0 < restitution < 1.0:
        raise ValueError(f"restitution = {restitution!r}: must be in (0, 1)")
    if not 0.0 < overlap < radius:
        raise ValueError(f"overlap = {overlap!r}: must be in (0, radius)")
    mass = density * 4.0 / 3.0 * math.pi * radius**3
    inertia = 0.4 * mass * radius**2
    arm = radius - 0.5 * overlap
    shear = youngs_modulus / (2.0 * (1.0 + poisson))
    g_eff = shear / (2.0 * (2.0 - poisson))
    k_t = 8.0 * g_eff * math.sqrt(0.5 * radius * overlap)
    log_e = math.log(restitution)
    beta = abs(log_e) / math.sqrt(log_e**2 + math.pi**2)
    g_t = 2.0 * math.sqrt(5.0 / 6.0) * beta * math.sqrt(k_t * 0.5 * mass)
    omega = math.sqrt(2.0 * contacts * k_t * arm**2 / inertia)
    zeta = 2.0 * contacts * g_t * arm**2 / inertia / (2.0 * omega) if damped else 0.0
    return SpinMode(omega, zeta, verlet_damping_limit(zeta) / omega)


def bed_contact_overlap(case: Case) -> float:
    """The Hertz overlap of a contact at the bottom of the bed at rest, m: the weight of the
    column above one particle (depth of the circular segment the particles fill at
    :data:`BED_SOLID_FRACTION`, times ``d^2``) on one contact."""
    from scipy.optimize import brentq  # here: importing this module stays light (CLI start-up)

    p = case.particles
    r_drum = case.drum.radius
    bulk = case.particle_mass_total / p.density / BED_SOLID_FRACTION
    area = min(bulk / case.drum.length, 0.999 * math.pi * r_drum**2)

    def segment(h: float) -> float:
        return r_drum**2 * math.acos((r_drum - h) / r_drum) - (r_drum - h) * math.sqrt(2 * r_drum * h - h * h)

    depth = brentq(lambda h: segment(h) - area, 0.0, 2.0 * r_drum)
    force = p.density * BED_SOLID_FRACTION * G * depth * p.diameter**2
    e_eff = p.youngs_modulus / (2.0 * (1.0 - p.poisson_ratio**2))
    return float((3.0 * force / (4.0 * e_eff * math.sqrt(0.5 * p.radius))) ** (2.0 / 3.0))


def bed_spin_mode(case: Case, time_step: float) -> SpinMode:
    """:func:`spin_mode` of the case's particle-particle contacts at the bottom of its bed
    (:func:`bed_contact_overlap`), with the restitution coefficient a run at ``time_step``
    gives LIGGGHTS (:func:`drumflow.dem.restitution.calibrate_case`), with or without the
    tangential dashpot as the case has it (``contacts.tangential_damping``)."""
    from drumflow.dem.restitution import calibrate_case  # scipy: imported when needed

    p = case.particles
    coefficient = calibrate_case(case, time_step)["particle_particle"].liggghts_value
    return spin_mode(p.radius, p.density, p.youngs_modulus, p.poisson_ratio, coefficient,
                     min(bed_contact_overlap(case), 0.5 * p.radius),
                     damped=case.contacts.tangential_damping)


@dataclass(frozen=True)
class TimeStepChoice:
    """The DEM time step and where it came from (recorded in the manifest)."""

    time_step: float
    rayleigh_time: float
    hertz_time: float
    fraction_of_rayleigh: float
    steps_per_contact: float
    #: "auto" (contacts and the bed's spin resolved), "contact" (contacts only), "fixed", or
    #: "forced" (fixed above the stability limit, on request).
    mode: str
    #: The step above which the tangential dashpot excites the spin of the bed's enduring
    #: contacts (:func:`bed_spin_mode`); "auto" stays below :data:`SPIN_LIMIT_FRACTION` of it.
    spin_time_step_limit: float | None = None
    #: What set the step: "rayleigh", "contact", "spin" or "user" (None in older records).
    bound: str | None = None

    def as_dict(self) -> dict[str, Any]:
        return asdict(self)


#: A contact must span at least this many steps; fewer and the Hertz force is sampled too
#: coarsely (restitution and overlap drift), so a fixed time step above it is refused.
MIN_STEPS_PER_CONTACT = 10.0
#: "auto" keeps the step at or below this fraction of the bed's spin limit
#: (:func:`bed_spin_mode`). Above the limit the spin is numerical, and on paper model two's
#: parcels it raised the cascading bed's falling mass flow by 5.5 % over 17.5 s (README, 'The
#: spin limit'). Why 0.8: the limit is sharp (LIGGGHTS' own, bisected, within 1.5 % of the
#: prediction), half the old step (0.82 of the limit) gave model one's bed the energies of a
#: quarter of it to 0.5 %, and with n contacts per particle the limit goes about as 1 / n, so
#: 0.8 still covers particles with 7.5 contacts where the limit assumes :data:`BED_CONTACTS`.
SPIN_LIMIT_FRACTION = 0.8


def _below_spin_limit(case: Case, time_step: float) -> float:
    """The largest step at or below ``time_step`` that is at most :data:`SPIN_LIMIT_FRACTION`
    of the bed's spin limit at that step (the limit moves a little with the step, through the
    restitution coefficient calibrated for it: a few fixed-point passes settle it)."""
    dt = time_step
    for _ in range(20):
        cap = SPIN_LIMIT_FRACTION * bed_spin_mode(case, dt).time_step_limit
        if dt <= cap * (1.0 + 1e-9):
            return dt
        dt = cap
    return dt


def choose_time_step(case: Case) -> TimeStepChoice:
    """The DEM time step for a case: for ``run.time_step = "auto"`` the largest step that keeps
    :data:`MIN_STEPS_PER_CONTACT` steps in the fastest contact, stays below
    ``run.rayleigh_fraction`` of the Rayleigh time and below :data:`SPIN_LIMIT_FRACTION` of the
    bed's spin limit; ``"contact"`` leaves out the spin limit (faster where it binds, in beds
    of soft, deeply overlapping particles, whose spin is then numerical: README 'The spin
    limit'); a number is the user's step.

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
    if case.run.time_step in ("auto", "contact"):
        mode = str(case.run.time_step)
        by_rayleigh = case.run.rayleigh_fraction * t_r
        by_contact = t_h / MIN_STEPS_PER_CONTACT
        dt, bound = (by_rayleigh, "rayleigh") if by_rayleigh <= by_contact else (by_contact, "contact")
        if mode == "auto":
            capped = _below_spin_limit(case, dt)
            if capped < dt:
                dt, bound = capped, "spin"
    else:
        dt = float(case.run.time_step)
        mode, bound = "fixed", "user"
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
        spin_time_step_limit=bed_spin_mode(case, dt).time_step_limit,
        bound=bound,
    )
