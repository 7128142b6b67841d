"""Two-particle verification of LIGGGHTS' contact physics against what drumflow asks of it.

* Restitution: two equal spheres collide head-on without gravity at drumflow's default time
  step for the material and impact speed; the realised coefficient of restitution
  |v_rel after| / |v_rel before| must match the input within 2%.
* Contact conduction: two touching spheres held in place (``fix freeze``) with a set overlap
  exchange heat; the realised conductance must match the paper's Eq. 24,
  q = 4 r_c k (T_j - T_i) with 1/k = 1/k_i + 1/k_j and r_c the Hertzian contact radius
  sqrt(R* delta), within 2%.

LIGGGHTS 3.8's ``heat/gran/conduction`` (``contact_area overlap``) computes
q = 4 k sqrt(A) (T_j - T_i) with the same k = k_i k_j / (k_i + k_j) but A the area of the
geometric intersection circle of the two spheres, A = pi a^2, a^2 = R delta - delta^2 / 4 for
equal spheres of radius R. With r_c^2 = R delta / 2 that is

    sqrt(A) / r_c = sqrt(2 pi) sqrt(1 - delta / (4 R)),

a pure geometric constant, sqrt(2 pi) = 2.5066, to within delta / (8 R) (0.0125% at
delta / R = 1e-3). Since k enters q linearly, handing LIGGGHTS k / sqrt(2 pi) reproduces Eq. 24
exactly in that limit: :func:`liggghts_conductivity`. A softened Young's modulus enlarges
delta by (E*_orig / E*)^(2/3) at the same force; ``area_correction yes`` with a
``youngsModulusOriginal`` table scales delta back by (E* / E*_orig)^(2/3) (LIGGGHTS'
1 / stressStrainExponent for Hertz) before the area is formed, so the same factor serves at
any modulus.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass
from pathlib import Path

import pandas as pd

from drumflow.dem.conduction import liggghts_conductivity
from drumflow.dem.deck import SOFT_PARTICLE_LIMIT, render_deck
from drumflow.dem.restitution import calibrate_restitution, realised_restitution
from drumflow.dem.thermo import ThermoParser
from drumflow.dem.timestep import (
    MIN_STEPS_PER_CONTACT,
    hertz_contact_time,
    rayleigh_time,
)
from drumflow.physics.validation import relative_error
from drumflow.runner import Runner
from drumflow.verify.checks import Check

#: The smoke case's particle material (cases/smoke.toml) and the paper's NPK properties.
DIAMETER = 0.008
DENSITY = 1050.0
YOUNGS_MODULUS = 5.0e6
PAPER_YOUNGS_MODULUS = 517.0e3
POISSON = 0.45
CONDUCTIVITY = 0.18596
HEAT_CAPACITY = 1465.38
#: drumflow's default fraction of the Rayleigh time (``run.rayleigh_fraction``).
RAYLEIGH_FRACTION = 0.2
#: Relative impact speed of the collision checks: free fall across the 0.4 m smoke drum gives
#: 2.8 m/s (the bound the default time step is set for); particles cascading down the bed
#: meet at around 2 m/s; drumflow's restitution correction is made at half the bound, 1.4 m/s.
IMPACT_SPEED = 2.0
SMOKE_IMPACT_BOUND = math.sqrt(2.0 * 9.81 * 0.4)


_COLUMNS = ("step", "time", "vx1", "vx2", "x1", "x2", "T1", "T2", "q1")


# ---------------------------------------------------------------------------------------------
# Pure helpers (unit-tested without a solver)
# ---------------------------------------------------------------------------------------------


def effective_modulus(youngs_modulus: float, poisson: float) -> float:
    """E* of two spheres of the same material, Pa: E / (2 (1 - nu^2)) (as LIGGGHTS forms it)."""
    return youngs_modulus / (2.0 * (1.0 - poisson**2))


def reference_overlap(
    overlap: float, youngs_modulus: float, reference_modulus: float | None = None
) -> float:
    """The overlap the same contact force gives at ``reference_modulus``, m.

    Hertz: F = 4/3 E* sqrt(R*) delta^(3/2), so at equal force delta scales as E*^(-2/3). This is
    what LIGGGHTS' ``area_correction`` does to delta; with no reference the overlap is kept.
    """
    if reference_modulus is None:
        return overlap
    return overlap * (youngs_modulus / reference_modulus) ** (2.0 / 3.0)


def hertz_contact_radius(radius_i: float, radius_j: float, overlap: float) -> float:
    """Hertzian contact radius r_c = sqrt(R* delta), m, with 1/R* = 1/R_i + 1/R_j."""
    r_eff = radius_i * radius_j / (radius_i + radius_j)
    return math.sqrt(r_eff * overlap)


def harmonic_conductivity(k_i: float, k_j: float) -> float:
    """The paper's contact conductivity k, W/(m K): 1/k = 1/k_i + 1/k_j (Eq. 25)."""
    return k_i * k_j / (k_i + k_j)


def eq24_heat_flow(contact_radius: float, k_i: float, k_j: float, T_i: float, T_j: float) -> float:
    """Heat flow into particle i, W: q = 4 r_c k (T_j - T_i) (the paper's Eq. 24)."""
    return 4.0 * contact_radius * harmonic_conductivity(k_i, k_j) * (T_j - T_i)


def geometric_overlap_area(radius_i: float, radius_j: float, distance: float) -> float:
    """Area of the intersection circle of two spheres at centre distance ``distance``, m^2.

    The formula of LIGGGHTS 3.8's ``heat/gran/conduction`` with ``contact_area overlap``.
    """
    r, a, b = distance, radius_i, radius_j
    return -math.pi / 4.0 * ((r - a - b) * (r + a - b) * (r - a + b) * (r + a + b)) / (r * r)


def liggghts_heat_flow(
    radius: float, overlap: float, k_i: float, k_j: float, T_i: float, T_j: float,
    youngs_modulus: float | None = None, reference_modulus: float | None = None,
) -> float:
    """Heat flow into particle i that LIGGGHTS 3.8 computes for equal spheres, W.

    ``contact_area overlap``: q = 4 k_i k_j / (k_i + k_j) sqrt(A) (T_j - T_i), A the geometric
    intersection area; with ``area_correction yes`` the overlap is first scaled to the
    reference modulus (pass both moduli).
    """
    if youngs_modulus is not None and reference_modulus is not None:
        overlap = reference_overlap(overlap, youngs_modulus, reference_modulus)
    area = geometric_overlap_area(radius, radius, 2.0 * radius - overlap)
    return 4.0 * harmonic_conductivity(k_i, k_j) * math.sqrt(area) * (T_j - T_i)


def default_time_step(
    radius: float, density: float, youngs_modulus: float, poisson: float, impact_speed: float,
    rayleigh_fraction: float = RAYLEIGH_FRACTION,
) -> float:
    """drumflow's contact time step rule at a given impact speed, s.

    min(fraction t_Rayleigh, t_Hertz / MIN_STEPS_PER_CONTACT), as
    :func:`drumflow.dem.timestep.choose_time_step` does with the case's impact velocity for
    ``run.time_step = "contact"`` (``"auto"`` also stays below the bed's spin limit, which
    needs a bed: these checks collide two particles).
    """
    t_r = rayleigh_time(radius, density, youngs_modulus, poisson)
    t_h = hertz_contact_time(radius, density, youngs_modulus, poisson, impact_speed)
    return min(rayleigh_fraction * t_r, t_h / MIN_STEPS_PER_CONTACT)


def decay_conductance(dT0: float, dTN: float, steps: int, dt: float, mcp_i: float, mcp_j: float) -> float:
    """Contact conductance h (q = h (T_j - T_i)), W/K, from the pair's temperature difference.

    LIGGGHTS updates temperatures explicitly, so the difference shrinks by the exact factor
    1 - h dt (1/(m cp)_i + 1/(m cp)_j) per step; inverting that over ``steps`` steps is exact
    (no linearisation of dT/dt, whatever the run length).
    """
    per_step = (dTN / dT0) ** (1.0 / steps)
    return (1.0 - per_step) / (dt * (1.0 / mcp_i + 1.0 / mcp_j))


# ---------------------------------------------------------------------------------------------
# LIGGGHTS runs
# ---------------------------------------------------------------------------------------------


def _run_pair(work: Path, runner: Runner, context: dict[str, object], timeout: float = 300.0,
              columns: tuple[str, ...] = _COLUMNS) -> pd.DataFrame:
    """Render ``two_particles.in.j2``, run LIGGGHTS on one process, return the thermo table."""
    work.mkdir(parents=True, exist_ok=True)
    deck = render_deck(context, "two_particles.in.j2")
    (work / "in.pair").write_text(deck)
    command = runner.profile.mpi_command(["liggghts", "-in", "in.pair", "-log", "log.liggghts"], 1)
    runner.run("liggghts", command, work, work / "liggghts.out", timeout=timeout)
    parser = ThermoParser(columns=columns)
    for line in (work / "log.liggghts").read_text(errors="replace").splitlines():
        parser(line)
    table = pd.DataFrame(parser.rows, columns=list(columns))
    return table.drop_duplicates("step", keep="last").reset_index(drop=True)


def _base_context(youngs_modulus: float, dt: float) -> dict[str, object]:
    return {
        "soft_particles": youngs_modulus < SOFT_PARTICLE_LIMIT,
        "box": 0.05, "diameter": DIAMETER, "density": DENSITY,
        "youngs_modulus": f"{youngs_modulus:.9g}", "poisson": POISSON,
        "conductivity": f"{CONDUCTIVITY:.9g}", "heat_capacity": HEAT_CAPACITY,
        "youngs_modulus_original": "", "skin": 0.5 * DIAMETER, "dt": f"{dt:.9g}",
        "heat_options": "", "T1": 90.0, "T2": 90.0, "speed": 0.0, "restitution": 0.5,
        "tangential_damping": True,
    }


@dataclass(frozen=True)
class CollisionResult:
    """A head-on collision's outcome."""

    restitution: float  # realised |v_rel after| / |v_rel before|
    replayed: float  # what drumflow.dem.restitution predicts for the same collision
    time_step: float
    contact_time: float
    steps_per_contact: float


def run_collision(
    work: Path, runner: Runner, coefficient: float, youngs_modulus: float, speed: float,
    time_step: float, phase: float = 0.0,
) -> CollisionResult:
    """Collide two equal spheres head-on with ``coefficient`` given to LIGGGHTS.

    The surfaces start ``2 + phase`` steps of approach apart, so ``phase`` sets where within a
    step the first touch falls.
    """
    radius = 0.5 * DIAMETER
    t_h = hertz_contact_time(radius, DENSITY, youngs_modulus, POISSON, speed)
    dt = time_step
    gap = (2.0 + phase) * speed * dt
    # The run ends well after the (elastic) contact time, which damping only shortens.
    steps = math.ceil((gap / speed + 3.0 * t_h) / dt)
    ctx = _base_context(youngs_modulus, dt)
    ctx.update(mode="collision", half_distance=0.5 * (DIAMETER + gap), speed=speed,
               restitution=f"{coefficient:.9g}", steps=steps, thermo_every=steps)
    table = _run_pair(work, runner, ctx)
    first, last = table.iloc[0], table.iloc[-1]
    if float(last["x2"] - last["x1"]) <= DIAMETER:
        raise RuntimeError(f"{work}: the spheres still touch after {steps} steps")
    before = float(first["vx1"] - first["vx2"])
    after = float(last["vx2"] - last["vx1"])
    m_eff, r_eff, e_eff = _pair(youngs_modulus)
    replay = realised_restitution(float(f"{coefficient:.9g}"), dt, m_eff, r_eff, e_eff, speed, phase)
    return CollisionResult(after / before, replay, dt, t_h, t_h / dt)


def _pair(youngs_modulus: float) -> tuple[float, float, float]:
    mass = DENSITY * math.pi / 6.0 * DIAMETER**3
    return 0.5 * mass, 0.25 * DIAMETER, effective_modulus(youngs_modulus, POISSON)


def restitution_check(
    work: Path, runner: Runner, restitution: float = 0.1, youngs_modulus: float = YOUNGS_MODULUS,
    speed: float = IMPACT_SPEED, steps_per_contact: float | None = None,
    correction: bool = True, phases: int = 8, tolerance: float = 0.02,
) -> Check:
    """Head-on collisions of two equal spheres: realised against input restitution.

    The time step is drumflow's default for the smoke drum (whose fastest impacts are free
    fall across its 0.4 m, 2.8 m/s); the coefficient given to LIGGGHTS is drumflow's
    correction for that step (:mod:`drumflow.dem.restitution`, made at the typical speed
    1.4 m/s); the collisions run at ``speed`` (2.0 m/s by default: off the correction's speed,
    so the check is not circular) at ``phases`` first-touch phases, whose mean is compared
    with the input.

    Parameters
    ----------
    work
        Working folder for the LIGGGHTS runs.
    runner
        Runs LIGGGHTS (one process).
    restitution
        Input coefficient of restitution (drumflow's particle-particle 0.1, wall 0.3).
    youngs_modulus
        Young's modulus, Pa (smoke case 5 MPa; the paper 517 kPa, run with ``soft_particles``).
    speed
        Relative impact speed, m/s.
    steps_per_contact
        Time step t_Hertz(speed) / steps_per_contact instead of drumflow's default rule.
    correction
        Give LIGGGHTS drumflow's corrected coefficient (as a run does); ``False`` passes the
        input through (10 steps per contact then realise 0.08 for 0.1).
    phases
        Collisions at first-touch phases k / phases, k = 0 .. phases - 1.
    tolerance
        Relative tolerance on the mean realised restitution.

    Returns
    -------
    Check
        ``measured`` = mean |v_rel after| / |v_rel before| over the phases.
    """
    t0 = time.perf_counter()
    radius = 0.5 * DIAMETER
    if steps_per_contact is None:
        dt = default_time_step(radius, DENSITY, youngs_modulus, POISSON, SMOKE_IMPACT_BOUND)
    else:
        dt = hertz_contact_time(radius, DENSITY, youngs_modulus, POISSON, speed) / steps_per_contact
    m_eff, r_eff, e_eff = _pair(youngs_modulus)
    coefficient = restitution
    if correction:
        coefficient = calibrate_restitution(
            restitution, dt, m_eff, r_eff, e_eff, 0.5 * SMOKE_IMPACT_BOUND).liggghts_value
    results = [run_collision(work / f"phase{k}", runner, coefficient, youngs_modulus, speed, dt, k / phases)
               for k in range(phases)]
    realised = [r.restitution for r in results]
    mean = sum(realised) / phases
    replay_gap = max(abs(r.restitution - r.replayed) for r in results)
    rule = "drumflow's default rule" if steps_per_contact is None else "t_Hertz / n"
    n = results[0].steps_per_contact
    return Check(
        name=f"restitution_e{restitution:g}_E{youngs_modulus:.3g}_v{speed:g}_n{n:.0f}"
             + ("" if correction else "_uncorrected"),
        measured=mean, expected=restitution,
        error=relative_error(mean, restitution), tolerance=tolerance,
        note=f"two 8 mm spheres, E = {youngs_modulus:.3g} Pa, nu = {POISSON}, head-on at "
             f"{speed:g} m/s, no gravity, mean of {phases} first-touch phases; dt = {dt:.3g} s "
             f"({rule}), {n:.1f} steps per Hertz contact; LIGGGHTS given {coefficient:.4g}",
        wall_time_s=time.perf_counter() - t0,
        details={"time_step_s": dt, "hertz_time_s": results[0].contact_time,
                 "steps_per_contact": n, "liggghts_coefficient": coefficient,
                 "realised_per_phase": realised,
                 "replay_max_abs_difference": replay_gap},
    )


@dataclass(frozen=True)
class SpinResult:
    """Two held particles spinning on one contact (:func:`run_spin`)."""

    time_step: float
    predicted_limit: float  # s, drumflow.dem.timestep.spin_mode for one contact
    energy_ratio: float  # rotational energy at the end over the start
    peak_energy_ratio: float  # the largest rotational energy of the run over the start

    @property
    def damped(self) -> bool:
        return self.energy_ratio < 1.0


def run_spin(work: Path, runner: Runner, time_step_factor: float, overlap_fraction: float = 0.19,
             restitution: float = 0.1205, youngs_modulus: float = PAPER_YOUNGS_MODULUS,
             spin: float = 1.0, steps: int = 400, tangential_damping: bool = True) -> SpinResult:
    """Two equal spheres held with overlap ``overlap_fraction`` * r, both spinning at ``spin``
    rad/s the same way (their surfaces slide at the contact, against its tangential spring
    and dashpot), at ``time_step_factor`` times the step limit :func:`spin_mode` predicts.

    Below the limit the dashpot damps the spin away; above it the spin grows until the contact
    slides. Rolling friction is off (its constant torque would mask the spring). The defaults
    are paper model one's particles at its bed overlap and its default step's coefficient.
    ``tangential_damping = False`` takes the dashpot off (``contacts.tangential_damping``), and
    ``time_step_factor`` then refers to the spring's own limit, ``omega dt = 2``.
    """
    from drumflow.dem.timestep import spin_mode

    radius = 0.5 * DIAMETER
    overlap = overlap_fraction * radius
    limit = spin_mode(radius, DENSITY, youngs_modulus, POISSON, restitution, overlap,
                      contacts=1, damped=tangential_damping).time_step_limit
    dt = time_step_factor * limit
    half = 0.5 * (DIAMETER - overlap)
    box = 0.05
    work.mkdir(parents=True, exist_ok=True)
    (work / "spin.data").write_text(
        "two spheres spinning the same way\n\n2 atoms\n1 atom types\n\n"
        + "".join(f"{-box} {box} {a}lo {a}hi\n" for a in "xyz")
        + f"\nAtoms\n\n1 1 {DIAMETER} {DENSITY} {-half:.12g} 0 0\n2 1 {DIAMETER} {DENSITY} {half:.12g} 0 0\n"
        + f"\nVelocities\n\n1 0 0 0 0 0 {spin:.12g}\n2 0 0 0 0 0 {spin:.12g}\n")
    ctx = _base_context(youngs_modulus, dt)
    ctx.update(mode="spin", restitution=f"{restitution:.9g}", rolling_friction=0.0, steps=steps,
               thermo_every=max(1, steps // 40), tangential_damping=tangential_damping)
    table = _run_pair(work, runner, ctx, columns=("step", "time", "rke"))
    first, last = float(table["rke"].iloc[0]), float(table["rke"].iloc[-1])
    return SpinResult(dt, limit, last / first, float(table["rke"].max()) / first)


@dataclass(frozen=True)
class ConductionResult:
    """Realised and expected heat flow of a held contact."""

    q_liggghts: float  # W into the colder particle at the start, from the temperature decay
    q_flux_output: float  # W, LIGGGHTS' own heatFlux of that particle at the last step, scaled
    q_eq24: float  # W, Eq. 24 with the real conductivity and the Hertzian contact radius
    time_step: float
    steps: int

    @property
    def ratio(self) -> float:
        return self.q_liggghts / self.q_eq24


def run_conduction(
    work: Path, runner: Runner, youngs_modulus: float = YOUNGS_MODULUS,
    overlap_fraction: float = 1e-3, heat_options: str = "", reference_modulus: float | None = None,
    conductivity_scale: float = 1.0, steps: int = 2000, T_i: float = 80.0, T_j: float = 100.0,
) -> ConductionResult:
    """Two spheres held with overlap ``overlap_fraction`` * R; heat flow against Eq. 24.

    ``reference_modulus`` both writes the ``youngsModulusOriginal`` table (only read by
    LIGGGHTS with ``area_correction yes``) and sets the overlap Eq. 24 is evaluated at:
    the geometric one scaled to the reference modulus at equal force. ``conductivity_scale``
    multiplies the conductivity given to LIGGGHTS (Eq. 24 always uses the real one).
    """
    radius = 0.5 * DIAMETER
    overlap = overlap_fraction * radius
    dt = default_time_step(radius, DENSITY, youngs_modulus, POISSON, IMPACT_SPEED)
    ctx = _base_context(youngs_modulus, dt)
    ctx.update(mode="conduction", half_distance=0.5 * (DIAMETER - overlap), steps=steps,
               thermo_every=steps, heat_options=heat_options, T1=T_i, T2=T_j,
               conductivity=f"{CONDUCTIVITY * conductivity_scale:.12g}",
               youngs_modulus_original=f"{reference_modulus:.9g}" if reference_modulus else "")
    table = _run_pair(work, runner, ctx)
    first, last = table.iloc[0], table.iloc[-1]
    mass = DENSITY * math.pi / 6.0 * DIAMETER**3
    mcp = mass * HEAT_CAPACITY
    n = int(last["step"] - first["step"])
    h = decay_conductance(float(first["T2"] - first["T1"]), float(last["T2"] - last["T1"]), n, dt, mcp, mcp)
    dT_last = float(last["T2"] - last["T1"])
    r_c = hertz_contact_radius(radius, radius, reference_overlap(overlap, youngs_modulus, reference_modulus))
    return ConductionResult(
        q_liggghts=h * (T_j - T_i),
        q_flux_output=float(last["q1"]) * (T_j - T_i) / dT_last,
        q_eq24=eq24_heat_flow(r_c, CONDUCTIVITY, CONDUCTIVITY, T_i, T_j),
        time_step=dt, steps=n,
    )


#: drumflow's conduction setting: the overlap area, corrected to the reference modulus,
#: and the conductivity divided by sqrt(2 pi) (see the module docstring).
DRUMFLOW_HEAT_OPTIONS = "contact_area overlap area_correction yes"


def contact_conduction_check(
    work: Path, runner: Runner, youngs_modulus: float = YOUNGS_MODULUS,
    reference_modulus: float | None = None, overlap_fraction: float = 1e-3,
    tolerance: float = 0.02,
) -> Check:
    """Held contact: heat flow with drumflow's conduction setting against Eq. 24.

    Parameters
    ----------
    work
        Working folder for the LIGGGHTS run.
    runner
        Runs LIGGGHTS (one process).
    youngs_modulus
        The simulated Young's modulus, Pa.
    reference_modulus
        The modulus the contact area refers to (``youngsModulusOriginal``), Pa; ``None`` = the
        simulated one (no correction).
    overlap_fraction
        Geometric overlap as a fraction of the radius, set by the positions and held by
        ``fix freeze``.
    tolerance
        Relative tolerance on the heat flow.

    Returns
    -------
    Check
        ``measured`` = q from LIGGGHTS' temperature decay, ``expected`` = Eq. 24 with the
        Hertzian contact radius sqrt(R* delta_ref), delta_ref the set overlap scaled to the
        reference modulus at equal force.
    """
    t0 = time.perf_counter()
    ref = reference_modulus if reference_modulus is not None else youngs_modulus
    res = run_conduction(work, runner, youngs_modulus, overlap_fraction, DRUMFLOW_HEAT_OPTIONS,
                         reference_modulus=ref,
                         conductivity_scale=liggghts_conductivity(1.0))
    return Check(
        name=f"contact_conduction_eq24_E{youngs_modulus:.3g}",
        measured=res.q_liggghts, expected=res.q_eq24,
        error=relative_error(res.q_liggghts, res.q_eq24), tolerance=tolerance, unit="W",
        note=f"two 8 mm spheres held by fix freeze at overlap {overlap_fraction:g} R (geometric), "
             f"E = {youngs_modulus:.3g} Pa, reference E = {ref:.3g} Pa, 20 K apart; "
             f"'{DRUMFLOW_HEAT_OPTIONS}', k / sqrt(2 pi) given to LIGGGHTS",
        wall_time_s=time.perf_counter() - t0,
        details={"ratio": res.ratio, "q_heatflux_output_W": res.q_flux_output,
                 "time_step_s": res.time_step, "steps": res.steps},
    )


# ---------------------------------------------------------------------------------------------
# Particle-wall collision
# ---------------------------------------------------------------------------------------------

#: One particle meets a flat wall (the drum's wall contact model, a primitive plane) head-on.
#: Written here rather than as a template: it is only ever rendered by this check.
_WALL_DECK = """\
# One particle hitting a flat wall head-on, for drumflow's particle-wall restitution check.
atom_style      granular
atom_modify     map array
boundary        f f f
newton          off
communicate     single vel yes
units           si
{soft}
region          box block -0.02 0.02 -0.02 0.02 -0.01 0.05 units box
create_box      2 box
create_atoms    1 single 0 0 {z0:.12g} units box
set             atom 1 diameter {diameter} density {density}
fix m1 all property/global youngsModulus peratomtype {E:.9g} {E_wall:.9g}
fix m2 all property/global poissonsRatio peratomtype {nu} {nu}
fix m3 all property/global coefficientRestitution peratomtypepair 2 {e:.9g} {e:.9g} {e:.9g} {e:.9g}
fix m4 all property/global coefficientFriction peratomtypepair 2 0.2 0.2 0.2 0.2
fix m5 all property/global coefficientRollingFriction peratomtypepair 2 0.05 0.05 0.05 0.05
pair_style      gran model hertz tangential history rolling_friction cdt
pair_coeff      * *
neighbor        {skin} bin
neigh_modify    delay 0
timestep        {dt:.9g}
fix walls all wall/gran model hertz tangential history rolling_friction cdt primitive type 2 zplane 0.0
fix integrate all nve/sphere
velocity        all set 0 0 {v:.9g} units box
variable vz1 equal vz[1]
variable z1 equal z[1]
thermo_style    custom step v_vz1 v_z1
thermo          {steps}
thermo_modify   norm no flush yes format float %.15g
run             {steps}
"""


def run_wall_collision(
    work: Path, runner: Runner, coefficient: float, youngs_modulus: float, wall_modulus: float,
    speed: float, time_step: float, phase: float = 0.0,
) -> float:
    """Drop one sphere head-on onto a plane wall; return |v_z after| / |v_z before|."""
    radius = 0.5 * DIAMETER
    mass = DENSITY * math.pi / 6.0 * DIAMETER**3
    e_eff = 1.0 / ((1 - POISSON**2) / youngs_modulus + (1 - POISSON**2) / wall_modulus)
    t_h = hertz_contact_time_effective(mass, radius, e_eff, speed)
    gap = (2.0 + phase) * speed * time_step
    steps = math.ceil((gap / speed + 3.0 * t_h) / time_step)
    work.mkdir(parents=True, exist_ok=True)
    deck = _WALL_DECK.format(
        soft="soft_particles  yes" if youngs_modulus < SOFT_PARTICLE_LIMIT else "",
        z0=radius + gap, diameter=DIAMETER, density=DENSITY, E=youngs_modulus, E_wall=wall_modulus,
        nu=POISSON, e=coefficient, skin=0.5 * DIAMETER, dt=time_step, v=-speed, steps=steps)
    (work / "in.wall").write_text(deck)
    command = runner.profile.mpi_command(["liggghts", "-in", "in.wall", "-log", "log.liggghts"], 1)
    runner.run("liggghts", command, work, work / "liggghts.out", timeout=300)
    parser = ThermoParser(columns=("step", "vz1", "z1"))
    for line in (work / "log.liggghts").read_text(errors="replace").splitlines():
        parser(line)
    table = pd.DataFrame(parser.rows, columns=["step", "vz1", "z1"]).drop_duplicates("step", keep="last")
    first, last = table.iloc[0], table.iloc[-1]
    if float(last["z1"]) <= radius:
        raise RuntimeError(f"{work}: the sphere still touches the wall after {steps} steps")
    return float(last["vz1"]) / -float(first["vz1"])


def hertz_contact_time_effective(m_eff: float, r_eff: float, e_eff: float, speed: float) -> float:
    """Elastic Hertz contact time 2.87 (m*^2 / (R* E*^2 v))^(1/5), s (as for two spheres)."""
    return 2.87 * (m_eff**2 / (r_eff * e_eff**2 * speed)) ** 0.2


def wall_restitution_check(
    work: Path, runner: Runner, restitution: float = 0.3, speed: float = IMPACT_SPEED,
    correction: bool = True, phases: int = 8, tolerance: float = 0.02,
) -> Check:
    """A particle hits a plane wall head-on: realised against input restitution.

    As a run of the tiny drum does it: drumflow's default time step for the case and the
    particle-wall coefficient :func:`drumflow.dem.restitution.calibrate_case` gives LIGGGHTS
    (made at the case's typical impact speed, 1.4 m/s); the collision runs at ``speed``
    (2 m/s: off the correction's speed) at ``phases`` first-touch phases, whose mean is
    compared with the case's particle-wall coefficient. ``correction=False`` passes the input
    through, as ``run.restitution_correction = false`` does.
    """
    from drumflow.dem.restitution import calibrate_case
    from drumflow.dem.timestep import choose_time_step
    from drumflow.verify.scenes import tiny_drum

    t0 = time.perf_counter()
    case = tiny_drum(contacts__particle_wall={"friction": 0.2, "restitution": restitution,
                                              "rolling_friction": 0.05},
                     run__restitution_correction=correction)
    plan = choose_time_step(case)
    dt = float(plan.time_step)
    calibration = calibrate_case(case, dt)["particle_wall"]
    coefficient = calibration.liggghts_value
    wall_modulus = case.contacts.wall_youngs_modulus or case.particles.youngs_modulus
    realised = [run_wall_collision(work / f"phase{k}", runner, coefficient, case.particles.youngs_modulus,
                                   wall_modulus, speed, dt, k / phases) for k in range(phases)]
    mean = sum(realised) / phases
    return Check(
        name=f"wall_restitution_e{restitution:g}_v{speed:g}" + ("" if correction else "_uncorrected"),
        measured=mean, expected=restitution, error=relative_error(mean, restitution),
        tolerance=tolerance,
        note=f"one 8 mm sphere (E = {case.particles.youngs_modulus:.3g} Pa) head-on onto a plane "
             f"wall (E = {wall_modulus:.3g} Pa) at {speed:g} m/s, no gravity, mean of {phases} "
             f"first-touch phases; the tiny drum's dt = {dt:.3g} s, "
             f"{calibration.steps_per_contact:.1f} steps per contact; LIGGGHTS given {coefficient:.4g}",
        reference="the case's input coefficient of restitution",
        wall_time_s=time.perf_counter() - t0,
        details={"time_step_s": dt, "liggghts_coefficient": coefficient, "realised_per_phase": realised,
                 "calibration": calibration.as_dict()},
    )
