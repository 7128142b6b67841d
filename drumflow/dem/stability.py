"""Numerical stability of a DEM run: bounds from the scene's physics, checked while it runs.

A run that goes unstable (time step too large for the contact stiffness, a particle trapped
in a wall) does not stop by itself: kinetic energy grows by orders of magnitude within a few
hundred steps, overlaps grow past anything the load explains, particles fly through walls,
and LIGGGHTS keeps writing numbers. drumflow reads every thermo row as it is written
(``step time atoms ke ke_rot T_mean overlap_max cpu``) and stops the run with a diagnosis at
the first row that breaks a bound:

* a non-finite value (kinetic energy or overlap);
* kinetic energy (translation + rotation) above what every particle would carry at
  :data:`SPEED_MARGIN` times the fastest physical speed in the drum (the wall speed or free
  fall across the diameter);
* a particle-particle overlap above :data:`OVERLAP_STOP_FACTOR` times the largest overlap the
  physics explains (the static load at the bottom of the bed, or an impact at free-fall
  speed), and at least 20% of the radius, or above 90% of the diameter in any case;
* particles lost (fewer atoms than at the start) with energy and overlaps sane: a leak
  through the walls rather than a blow-up (reported as lost particles).

LIGGGHTS is told ``thermo_modify lost warn`` so that the row with the lost particles is
printed and reaches the monitor together with the energy that explains it; the monitor stops
the run at that row, and a final count check stands behind it.

A large overlap alone is only a warning (:data:`OVERLAP_WARNING_FRACTION` of the radius): the
paper's 517 kPa particles reach 10-15% of the radius under the static load of a 3 m drum's bed
(estimated by :func:`static_overlap`: 15%), and that case must run.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, field
from typing import TYPE_CHECKING, Any

from drumflow.dem.restitution import pair_properties

if TYPE_CHECKING:
    from drumflow.case import Case

G = 9.81
#: Kinetic energy bound: every particle at this multiple of the fastest physical speed.
SPEED_MARGIN = 3.0
#: Overlap bound: this multiple of the largest overlap the static load or an impact explains.
OVERLAP_STOP_FACTOR = 3.0
#: A maximum overlap above this fraction of the radius is reported (once) as a warning.
OVERLAP_WARNING_FRACTION = 0.1
#: A coupled run evaluates the overlap bound on every this-many-th thermo row only: gathering
#: every contact for it cost 16 % of model one's loop on every row (drumflow bench --from,
#: variant no_overlap, 1.19x), while a blow-up takes hundreds of steps and the kinetic-energy
#: bound, read on every row, sees it first (drumflow.coupling.driver.overlap_wanted).
OVERLAP_EVERY_ROWS = 10
#: Bulk solids fraction of a settled bed (for the static load).
BED_SOLIDS_FRACTION = 0.6


def hertz_overlap(force: float, effective_radius: float, effective_modulus: float) -> float:
    """Overlap of a Hertz contact carrying ``force``, m: F = 4/3 E* sqrt(R*) delta^(3/2)."""
    return (3.0 * force / (4.0 * effective_modulus * math.sqrt(effective_radius))) ** (2.0 / 3.0)


def impact_overlap(speed: float, effective_mass: float, effective_radius: float,
                   effective_modulus: float) -> float:
    """Largest overlap of an elastic Hertz impact at ``speed``, m.

    delta_max = (15 m* v^2 / (16 E* sqrt(R*)))^(2/5).
    """
    ratio = 15.0 * effective_mass * speed**2 / (16.0 * effective_modulus * math.sqrt(effective_radius))
    return ratio**0.4


def bed_depth(case: Case) -> float:
    """Depth of the settled bed at the bottom of the drum, m (circular segment of the fill)."""
    R = case.drum.radius
    solids = case.particle_count * case.particles.volume / (math.pi * R * R * case.drum.length)
    fill = min(solids / BED_SOLIDS_FRACTION, 1.0)
    target = fill * math.pi * R * R
    # Segment area of depth h: R^2 acos((R-h)/R) - (R-h) sqrt(2Rh - h^2); bisect on h.
    lo, hi = 0.0, 2.0 * R
    for _ in range(60):
        h = 0.5 * (lo + hi)
        area = R * R * math.acos((R - h) / R) - (R - h) * math.sqrt(max(2 * R * h - h * h, 0.0))
        lo, hi = (h, hi) if area < target else (lo, h)
    return 0.5 * (lo + hi)


def static_overlap(case: Case) -> float:
    """Overlap at the bottom of the bed under its own weight, m.

    The column of bulk solids above one particle's footprint, rho_b g H d^2, carried by one
    Hertz contact with the particle below.
    """
    p = case.particles
    force = BED_SOLIDS_FRACTION * p.density * G * bed_depth(case) * p.diameter**2
    _, r_eff, e_eff = pair_properties(case, wall=False)
    return hertz_overlap(force, r_eff, e_eff)


@dataclass(frozen=True)
class StabilityLimits:
    """Bounds a healthy run stays within (recorded in the manifest)."""

    particles: int
    radius: float
    fastest_speed: float  # m/s: wall speed or free fall across the diameter
    kinetic_energy_limit: float  # J, translation + rotation
    static_overlap: float  # m
    impact_overlap: float  # m
    overlap_warning: float  # m
    overlap_stop: float  # m

    def as_dict(self) -> dict[str, Any]:
        return asdict(self)


def stability_limits(case: Case) -> StabilityLimits:
    """The scene's bounds, from its geometry, speed and material."""
    from drumflow.dem.collision_speed import impact_velocity

    p = case.particles
    n = case.particle_count
    v = impact_velocity(case)
    m_eff, r_eff, e_eff = pair_properties(case, wall=False)
    static = static_overlap(case)
    impact = impact_overlap(v, m_eff, r_eff, e_eff)
    stop = min(max(OVERLAP_STOP_FACTOR * max(static, impact), 0.2 * p.radius), 0.9 * p.diameter)
    return StabilityLimits(
        particles=n, radius=p.radius, fastest_speed=v,
        kinetic_energy_limit=n * 0.5 * p.mass * (SPEED_MARGIN * v) ** 2,
        static_overlap=static, impact_overlap=impact,
        overlap_warning=OVERLAP_WARNING_FRACTION * p.radius, overlap_stop=stop,
    )


@dataclass
class StabilityMonitor:
    """Checks thermo rows against :class:`StabilityLimits`.

    ``check`` returns a diagnosis (one line: what broke, when, and the likely cause) for the
    first row that breaks a bound, else ``None``; warnings collect in ``warnings``.
    """

    limits: StabilityLimits
    forced_time_step: bool = False
    warnings: list[str] = field(default_factory=list)
    max_overlap: float = 0.0
    max_kinetic_energy: float = 0.0

    def check(self, step: int, time: float, atoms: int, ke: float, ke_rot: float,
              overlap: float | None) -> str | None:
        lim = self.limits
        when = f"at step {step} ({time:.4g} s simulated)"
        cause = (" The time step was forced above the stability limit: use time_step = 'auto'."
                 if self.forced_time_step else
                 " Likely causes: a time step too large for the contact stiffness, or particles "
                 "caught in a wall; try a smaller run.rayleigh_fraction.")
        lost = lim.particles - atoms
        also_lost = f"; {lost} of {lim.particles} particles already left the drum" if lost > 0 else ""
        values = [ke, ke_rot] + ([overlap] if overlap is not None else [])
        if not all(math.isfinite(x) for x in values):
            return (f"non-finite kinetic energy or overlap {when}: the integration has "
                    f"diverged{also_lost}." + cause)
        energy = ke + ke_rot
        self.max_kinetic_energy = max(self.max_kinetic_energy, energy)
        if energy > lim.kinetic_energy_limit:
            return (f"kinetic energy running away {when}: {energy:.3g} J, above "
                    f"{lim.kinetic_energy_limit:.3g} J (every particle at {SPEED_MARGIN:g} times "
                    f"the fastest physical speed, {lim.fastest_speed:.3g} m/s){also_lost}." + cause)
        if overlap is not None and overlap > 0.0:
            self.max_overlap = max(self.max_overlap, overlap)
            if overlap > lim.overlap_stop:
                return (f"particle overlap growing far past the load {when}: {overlap:.3g} m "
                        f"({overlap / lim.radius:.0%} of the radius), above {lim.overlap_stop:.3g} m "
                        f"(static load {lim.static_overlap:.2g} m, impact at "
                        f"{lim.fastest_speed:.3g} m/s {lim.impact_overlap:.2g} m){also_lost}." + cause)
            if overlap > lim.overlap_warning and not self.warnings:
                self.warnings.append(
                    f"large overlap {when}: {overlap:.3g} m ({overlap / lim.radius:.0%} of the "
                    f"radius; the static load explains {lim.static_overlap / lim.radius:.0%}, an "
                    f"impact at {lim.fastest_speed:.3g} m/s {lim.impact_overlap / lim.radius:.0%}). "
                    "Results stand; a stiffer Young's modulus would reduce it."
                )
        if lost > 0:
            # Energy and overlaps are sane: a leak (a gap in the walls), not a blow-up.
            return f"{LOST_PREFIX}{lost} of {lim.particles} particles left the drum {when}."
        return None


#: Prefix of the diagnosis of particles lost without any sign of instability.
LOST_PREFIX = "lost: "


#: Thermo rows are checked at least this often (steps): a blow-up grows by orders of
#: magnitude within a few hundred steps. The extra reductions cost under 1% of a step's work.
CHECK_EVERY_STEPS = 100
