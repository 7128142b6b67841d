"""Restitution at a finite time step: LIGGGHTS' discrete collision, and the coefficient to give it.

LIGGGHTS 3.8's Hertz model damps the normal contact with
``F_n = k_n delta - gamma_n v_n``, ``k_n = 4/3 E* sqrt(R* delta)``,
``gamma_n = -2 sqrt(5/6) beta sqrt(S_n m*)``, ``S_n = 2 E* sqrt(R* delta)``,
``beta = ln e / sqrt(ln^2 e + pi^2)``; the velocity-Verlet integrator (``fix nve/sphere``)
evaluates the damping with the half-step velocity, which lags the contact by half a step. The
realised restitution therefore falls short of the input by an error of first order in
dt / t_contact: measured with LIGGGHTS on two 8 mm spheres at e = 0.1, 0.0847 at 10 steps per
Hertz contact, 0.0929 at 20, 0.0963 at 50, 0.0982 at 100 and 0.0991 at 200 (e = 0.3: 0.295 at
10). A stiff low-restitution contact would need about 100 steps per contact to come within 2%.

Instead, :func:`realised_restitution` replays LIGGGHTS' update of one head-on contact in
Python (it reproduces the five numbers above to 4 digits), and :func:`calibrate_restitution`
inverts it: the coefficient handed to LIGGGHTS is the one whose *realised* restitution at the
run's time step equals the case's. The correction depends on the impact speed only through
the number of steps per contact (t_c ~ v^(-1/5)); it is made at the scene's typical impact
speed (:func:`drumflow.dem.collision_speed.typical_impact_velocity`), and ``drumflow verify`` checks
it against real LIGGGHTS collisions at other speeds.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass
from typing import TYPE_CHECKING, Any

from scipy.optimize import brentq

from drumflow.dem.collision_speed import typical_impact_velocity

if TYPE_CHECKING:
    from drumflow.case import Case

_SQRT_5_6 = math.sqrt(5.0 / 6.0)


def _beta(restitution: float) -> float:
    log_e = math.log(restitution)
    return log_e / math.sqrt(log_e * log_e + math.pi * math.pi)


def realised_restitution(
    restitution: float, time_step: float, effective_mass: float, effective_radius: float,
    effective_modulus: float, impact_speed: float, phase: float = 0.0,
) -> float:
    """Restitution LIGGGHTS realises for one head-on Hertz contact at ``time_step``.

    The relative coordinate of the pair is integrated exactly as ``fix nve/sphere`` and
    ``pair gran model hertz`` do (half kick, drift, force from the half-step velocity, half
    kick; attractive damping force allowed, as LIGGGHTS' default ``limitForce off``). The
    spheres start ``2 + phase`` steps of approach apart: ``phase`` in [0, 1) sets where
    within a step the first touch falls, which at 10 steps per contact moves the realised
    value by several percent either way.

    Parameters
    ----------
    restitution
        Coefficient given to LIGGGHTS (``coefficientRestitution``), in (0, 1].
    time_step
        DEM time step, s.
    effective_mass, effective_radius, effective_modulus
        m* (kg), R* (m) and E* (Pa) of the pair; a wall has infinite mass and radius, so
        m* = m and R* = r there.
    impact_speed
        Normal approach speed, m/s.

    Returns
    -------
    float
        |v_n after| / |v_n before|.
    """
    if restitution >= 1.0:
        beta = 0.0
    else:
        beta = _beta(restitution)
    dt = time_step
    gap = (2.0 + phase) * impact_speed * dt
    x, u, force = gap, -impact_speed, 0.0  # separation beyond touching, relative velocity
    touched = False
    # A Hertz contact lasts t_c; 1e6 steps is a generous bound even at 1e4 steps per contact.
    for _ in range(1_000_000):
        u += 0.5 * dt * force / effective_mass
        x += dt * u
        if x < 0.0:
            touched = True
            delta = -x
            root = math.sqrt(effective_radius * delta)
            stiffness = 4.0 / 3.0 * effective_modulus * root
            gamma = -2.0 * _SQRT_5_6 * beta * math.sqrt(2.0 * effective_modulus * root * effective_mass)
            force = stiffness * delta - gamma * u
        else:
            force = 0.0
        u += 0.5 * dt * force / effective_mass
        if touched and x >= 0.0:
            return u / impact_speed
    raise RuntimeError("the replayed collision did not end within 1e6 steps")


@dataclass(frozen=True)
class RestitutionCalibration:
    """What LIGGGHTS is given for one contact pair, and why (recorded in the manifest)."""

    target: float  # the case's coefficient: the one the contact must realise
    liggghts_value: float  # the coefficient written into the deck
    realised_uncorrected: float  # what the target itself would realise at this time step
    realised_corrected: float  # what liggghts_value realises (replayed)
    impact_speed: float
    steps_per_contact: float

    def as_dict(self) -> dict[str, Any]:
        return asdict(self)


#: Contact phases averaged over: where within a step the first touch falls is random in a
#: drum; 16 phases give the mean to 0.4% of 64 (measured at 10 steps per contact).
PHASES = 16


def mean_realised_restitution(
    restitution: float, time_step: float, effective_mass: float, effective_radius: float,
    effective_modulus: float, impact_speed: float, phases: int = PHASES,
) -> float:
    """:func:`realised_restitution` averaged over ``phases`` evenly spaced first-touch phases."""
    total = 0.0
    for k in range(phases):
        total += realised_restitution(restitution, time_step, effective_mass, effective_radius,
                                      effective_modulus, impact_speed, k / phases)
    return total / phases


def calibrate_restitution(
    target: float, time_step: float, effective_mass: float, effective_radius: float,
    effective_modulus: float, impact_speed: float,
) -> RestitutionCalibration:
    """The coefficient whose phase-averaged realised restitution at ``time_step`` is ``target``.

    When even 1.0 falls short (a nearly elastic contact at a coarse step), 1.0 is used and
    ``realised_corrected`` says how far it falls short.
    """

    def realised(e: float) -> float:
        return mean_realised_restitution(e, time_step, effective_mass, effective_radius,
                                         effective_modulus, impact_speed)

    uncorrected = realised(target)
    if abs(uncorrected - target) <= 1e-6 * target:
        value = target
    elif uncorrected < target:
        # The usual case: the discrete contact loses more than the input asks, so the
        # coefficient lies between the target and 1, where the realised value grows with it.
        if realised(1.0) < target:
            value = 1.0
        else:
            value = float(brentq(lambda e: realised(e) - target, target, 1.0, xtol=1e-7, rtol=1e-7))
    else:
        # A step so coarse that the contact gains energy (only with a forced time step): no
        # coefficient repairs that; pass the target through and let the record show it.
        value = target
    t_contact = hertz_time_effective(effective_mass, effective_radius, effective_modulus, impact_speed)
    return RestitutionCalibration(
        target=target, liggghts_value=value, realised_uncorrected=uncorrected,
        realised_corrected=realised(value), impact_speed=impact_speed,
        steps_per_contact=t_contact / time_step,
    )


def hertz_time_effective(effective_mass: float, effective_radius: float,
                         effective_modulus: float, impact_speed: float) -> float:
    """Elastic Hertz contact duration 2.87 (m*^2 / (R* E*^2 v))^(1/5), s."""
    v = max(impact_speed, 1e-9)
    return 2.87 * (effective_mass**2 / (effective_radius * effective_modulus**2 * v)) ** 0.2


def pair_properties(case: Case, wall: bool) -> tuple[float, float, float]:
    """m* (kg), R* (m) and E* (Pa) of a particle-particle or particle-wall contact."""
    p = case.particles
    mass = p.mass
    e_wall = case.contacts.wall_youngs_modulus or p.youngs_modulus
    if wall:
        # The wall (mesh or plane) has the particles' Poisson ratio in the deck.
        e_eff = 1.0 / ((1 - p.poisson_ratio**2) / p.youngs_modulus + (1 - p.poisson_ratio**2) / e_wall)
        return mass, p.radius, e_eff
    return 0.5 * mass, 0.5 * p.radius, p.youngs_modulus / (2.0 * (1.0 - p.poisson_ratio**2))


def calibrate_case(case: Case, time_step: float,
                   speed: float | None = None) -> dict[str, RestitutionCalibration]:
    """Calibrated coefficients of the case's two contact pairs at ``time_step``.

    Keys ``particle_particle`` and ``particle_wall``. With ``run.restitution_correction``
    off, each coefficient is passed through unchanged (and the record shows what it realises).
    ``speed`` is the impact speed the calibration is exact at (m/s; default the scene's typical
    speed, :func:`drumflow.dem.collision_speed.typical_impact_velocity`).
    """
    if speed is None:
        speed = typical_impact_velocity(case)
    out: dict[str, RestitutionCalibration] = {}
    for name, wall in (("particle_particle", False), ("particle_wall", True)):
        target = getattr(case.contacts, name).restitution
        m, r, e = pair_properties(case, wall)
        if case.run.restitution_correction:
            out[name] = calibrate_restitution(target, time_step, m, r, e, speed)
        else:
            realised = mean_realised_restitution(target, time_step, m, r, e, speed)
            out[name] = RestitutionCalibration(
                target, target, realised, realised, speed,
                hertz_time_effective(m, r, e, speed) / time_step,
            )
    return out
