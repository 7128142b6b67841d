"""Render the LIGGGHTS input deck from the package templates (``drumflow/dem/templates/``).

The template knows LIGGGHTS' syntax; this module only computes the values that go into it
(material tables, gravity vector, step counts), so the physics stays testable without a solver.
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import jinja2

from drumflow.coupling.interior import shell_fix_command
from drumflow.dem.conduction import liggghts_conductivity
from drumflow.dem.restitution import calibrate_case
from drumflow.dem.stability import CHECK_EVERY_STEPS
from drumflow.dem.timestep import TimeStepChoice
from drumflow.errors import GeometryError
from drumflow.physics.drum_frame import drum_angle

if TYPE_CHECKING:
    from drumflow.case import Case

#: Young's modulus below which LIGGGHTS 3.8 needs ``soft_particles yes``.
SOFT_PARTICLE_LIMIT = 5.0e6


def _loader() -> jinja2.BaseLoader:
    """The shipped templates (package data), or ``DRUMFLOW_TEMPLATES`` when set.

    Package data is read through jinja2's :class:`~jinja2.PackageLoader` (importlib
    resources), so an installed wheel finds the templates as well as an editable checkout.
    """
    env = os.environ.get("DRUMFLOW_TEMPLATES")
    if env:
        return jinja2.FileSystemLoader(env)
    return jinja2.PackageLoader("drumflow.dem", "templates")


def _environment() -> jinja2.Environment:
    return jinja2.Environment(
        loader=_loader(),
        undefined=jinja2.StrictUndefined,  # a missing value is an error, never an empty string
        keep_trailing_newline=True,
        trim_blocks=True,
        lstrip_blocks=True,
    )


@dataclass(frozen=True)
class DeckFiles:
    """Paths the deck refers to, relative to the DEM working directory."""

    data_file: str = "particles.data"
    stl_file: str = "../geometry/walls.stl"
    #: The lifters as their own moving mesh (static shell); "" = one moving mesh for all.
    lifters_stl_file: str = ""
    #: The shell STL is the bare cylinder, static with a surface velocity.
    static_shell: bool = False
    cross_pattern: str = "dumps/cross.*.txt"
    snapshot_pattern: str = "dumps/snap.*.txt"
    restart_pattern: str = "restart/drum.*.restart"
    #: The state at the end, numbered like the others (LIGGGHTS puts the step for the "*"), so
    #: that it is the newest restart: what a settings study or a longer run starts from. A
    #: separate final.restart was a third copy of the same state at the end of a run.
    final_restart: str = "restart/drum.*.restart"
    #: A start state's particle temperatures (``variable atomfile``, drumflow.dem.state).
    start_temperatures: str = "start_temperatures.txt"
    #: The end plates turning with the shell (``drum.ends = "rotating"``); "" = none.
    ends_stl_file: str = ""


@dataclass(frozen=True)
class StepPlan:
    """How the simulated time maps onto DEM steps."""

    time_step: float
    steps: int
    dump_every: int  # crossing dump and thermo (mean temperature) output
    snapshot_every: int
    restart_every: int
    #: Thermo rows (the stability monitor's input) every this many steps; divides dump_every.
    thermo_every: int = 0

    @property
    def dump_interval(self) -> float:
        return self.dump_every * self.time_step

    @property
    def thermo_step(self) -> int:
        """Steps between thermo rows (plans made before thermo_every existed print one per
        output step)."""
        return self.thermo_every or self.dump_every


def plan_steps(case: Case, choice: TimeStepChoice) -> StepPlan:
    """Step counts for the run; output intervals are whole multiples of the output step."""
    dt = choice.time_step
    raw = max(1, round(case.run.dump_interval / dt))
    # The output step is split into equal thermo intervals of at most CHECK_EVERY_STEPS (the
    # stability monitor reads every thermo row), rounding it by less than 1/parts.
    parts = math.ceil(raw / CHECK_EVERY_STEPS)
    thermo_every = math.ceil(raw / parts)
    dump_every = thermo_every * parts
    # A whole number of output steps, so that the last output falls on the last step.
    steps = math.ceil(case.run.time / dt / dump_every - 1e-9) * dump_every

    def multiple(interval: float) -> int:
        return max(dump_every, round(interval / dt / dump_every) * dump_every)

    return StepPlan(dt, steps, dump_every, multiple(case.run.snapshot_interval),
                    multiple(case.run.restart_interval), thermo_every)


def short_plan(plan: StepPlan, steps: int) -> StepPlan:
    """A plan for only ``steps`` steps (start-up check): output at its end, no restarts."""
    every = min(plan.dump_every, steps)
    return StepPlan(plan.time_step, steps, every, min(plan.snapshot_every, steps), 0,
                    math.gcd(plan.thermo_every or every, every))


def crossing_band(case: Case, plan: StepPlan) -> float:
    """Half-width of the crossing dump's band around y = 0, m.

    Wider than the farthest a particle moves in one output step (free fall across the drum
    plus the wall speed, with 50% margin), plus a diameter.
    """
    v_max = math.sqrt(2.0 * 9.81 * case.drum.diameter) + case.drum.omega * case.drum.radius
    return 1.5 * v_max * plan.dump_every * plan.time_step + case.particles.diameter


def gravity_vector(tilt_deg: float) -> tuple[float, float, float]:
    """Unit gravity direction in drum coordinates: down in y, and along +z by the tilt."""
    t = math.radians(tilt_deg)
    return (0.0, -math.cos(t), math.sin(t))


#: Particle diameters of section length each rank needs before the domain is split along the
#: drum axis: below it the ghost layers (one diameter plus the skin on each inner face) become a
#: large share of a rank's particles and the split across the drum is kept. Measured down to
#: 6.25 (paper model one at 2 ranks, where the axial split won once the bed cascaded); thinner
#: slabs are not measured.
AXIAL_SPLIT_MIN_DIAMETERS = 6.0


def processors_grid(case: Case, processes: int) -> str:
    """MPI decomposition: along the drum axis unless the section is too thin for it.

    The bed is uniform along the axis, so slabs along z carry equal loads; across the drum
    (x) the load follows the bed, which the rotation piles up on the rising side. Measured on
    paper model two at 3.47 s (299,164 particles, 1 m, 2 ranks, 204 steps from one restart,
    ``drumflow bench --from``): the split along z ran 1.61 times faster than the
    split along x (878k against 546k particle-steps per second; 1 rank: 438k), with
    communication and waiting down from 27 % to 8 % of the loop. Paper model one (0.1 m of
    8 mm particles, 6.25 diameters per rank at 2 ranks): a tie at 0.5 s (1.88 M against
    1.90 M), 1.30 times faster along z at 1.5 s (2.02 M against 1.56 M), as the bed piled up
    on the rising side (63 % of the particles on one rank at 1 s). A thinner slice (the smoke
    drum at 2 ranks: 5 diameters per rank) keeps the split across x, which is not measured
    against z at those thicknesses.
    """
    n = processes
    if n == 1:
        return "1 1 1"
    if case.drum.length / n >= AXIAL_SPLIT_MIN_DIAMETERS * case.particles.diameter:
        return f"1 1 {n}"
    # A thin slice holds its bed at the bottom: splitting left/right spreads it over the ranks.
    return f"{n} 1 1"


def neighbor_skin(case: Case) -> float:
    """Neighbour-list skin, m (half a particle diameter unless the case sets it)."""
    if case.run.neighbor_skin == "auto":
        return 0.5 * case.particles.diameter
    return float(case.run.neighbor_skin)


#: A resumed deck writes the turning mesh (the lifters, or the whole moving shell) once, at its
#: set-up, as LIGGGHTS read it from the restart: drumflow.verify.resume checks its angle against
#: the air's from this file, so the restart need not be kept for it. "*" is the step.
RESUME_MESH_PATTERN = "mesh_at_resume.*.stl"


def turning_mesh(files: DeckFiles) -> str:
    """The LIGGGHTS mesh that turns with the drum: ``lifters`` (static shell), ``shell``
    (moving-mesh shell with its lifters), or "" (a static shell without lifters: nothing turns)."""
    if not files.static_shell:
        return "shell"
    return "lifters" if files.lifters_stl_file else ""


def start_angle_deg(case: Case, plan: StepPlan, step: int) -> float:
    """The drum angle at ``step`` (omega t, counter-clockwise about +z), degrees in [0, 360): the
    turning mesh of a run from a start state is read in at it. The angle is that of the run's
    own clock (step times its time step), which the coupling loop samples the air at."""
    return math.degrees(drum_angle(case.drum.omega, step * plan.time_step)) % 360.0


def deck_context(
    case: Case,
    plan: StepPlan,
    files: DeckFiles = DeckFiles(),
    resume_from: str | None = None,
    extra_commands: str = "",
    coupled: bool = False,
    processes: int = 1,
    shells: int = 0,
    start_step: int | None = None,
) -> dict[str, Any]:
    """All values the template needs.

    ``extra_commands`` are LIGGGHTS lines placed just before the run (verification scenes);
    ``processes`` is the MPI process count the domain is decomposed for (from the launch
    profile, :meth:`drumflow.runner.LaunchProfile.processes_for`); ``shells`` the shells per
    particle the coupling loop advances (``particles.interior = "shells"``; 0: lumped);
    ``start_step`` the step a run from a start state begins at (``run.start_state``,
    :mod:`drumflow.dem.state`: the particles file then holds the state's particles,
    ``files.start_temperatures`` their temperatures).
    """
    p = case.particles
    cc = case.contacts
    if case.drum.ends == "rotating" and not files.ends_stl_file:
        raise GeometryError("drum.ends = 'rotating' needs the end plates' STL (DeckFiles.ends_stl_file, "
                         "written by the geometry stage)")
    restitution = calibrate_case(case, plan.time_step)
    E_wall = cc.wall_youngs_modulus if cc.wall_youngs_modulus is not None else p.youngs_modulus
    return {
        "case_name": case.name,
        "processors": processors_grid(case, processes),
        "soft_particles": min(p.youngs_modulus, E_wall) < SOFT_PARTICLE_LIMIT,
        "resume": resume_from is not None,
        "restart_file": resume_from or "",
        # A start state's deck writes the turning mesh at its set-up too: the lifters must
        # stand at the state's angle (measured as drumflow.verify.resume measures a resume's).
        "resume_mesh": (turning_mesh(files)
                        if resume_from is not None or start_step is not None else ""),
        "start_state": resume_from is None and start_step is not None,
        "start_step": start_step or 0,
        "start_temperatures": files.start_temperatures,
        "start_angle_deg": f"{start_angle_deg(case, plan, start_step or 0):.12g}",
        "resume_mesh_pattern": RESUME_MESH_PATTERN,
        "data_file": files.data_file,
        "skin": f"{neighbor_skin(case):.6g}",
        "E_particle": f"{p.youngs_modulus:.9g}",
        "E_wall": f"{E_wall:.9g}",
        "nu_particle": f"{p.poisson_ratio:.6g}",
        "nu_wall": f"{p.poisson_ratio:.6g}",
        # The coefficients whose realised restitution at this time step is the case's
        # (drumflow.dem.restitution): LIGGGHTS' discrete contact loses more than it is told.
        "e_pp": f"{restitution['particle_particle'].liggghts_value:.6g}",
        "e_pw": f"{restitution['particle_wall'].liggghts_value:.6g}",
        "mu_pp": f"{cc.particle_particle.friction:.6g}",
        "mu_pw": f"{cc.particle_wall.friction:.6g}",
        "mur_pp": f"{cc.particle_particle.rolling_friction:.6g}",
        "mur_pw": f"{cc.particle_wall.rolling_friction:.6g}",
        "tangential_damping": cc.tangential_damping,
        # LIGGGHTS' conduction is sqrt(2 pi) times Eq. 24's for the same k (a pure geometric
        # factor: sqrt of the overlap area against the Hertzian contact radius), and k enters
        # linearly, so LIGGGHTS gets k / sqrt(2 pi). See drumflow.verify.contacts.
        # run.conduction = false: zero conductivity, the one way to switch contact conduction
        # off in LIGGGHTS 3.8 (drum.in.j2).
        "k_particle": f"{liggghts_conductivity(p.conductivity) if case.run.conduction else 0.0:.9g}",
        # Softened for speed: the conduction contact area still refers to the real modulus.
        "E_reference_particle": f"{p.youngs_modulus_reference or p.youngs_modulus:.9g}",
        "E_reference_wall": f"{(cc.wall_youngs_modulus or p.youngs_modulus_reference or E_wall):.9g}",
        "cp_particle": f"{p.heat_capacity:.9g}",
        "dt": f"{plan.time_step:.9g}",
        "gravity": [f"{g:.9f}" for g in gravity_vector(case.drum.tilt_deg)],
        "stl_file": files.stl_file,
        "lifters_stl_file": files.lifters_stl_file,
        "static_shell": files.static_shell,
        "ends": case.drum.ends,
        "ends_stl_file": files.ends_stl_file,
        "omega": f"{case.drum.omega:.9g}",
        "length": f"{case.drum.length:.9g}",
        "period": f"{60.0 / case.drum.rpm:.9g}",
        "T0": p.initial_temperature_C,
        "temperature_spread": p.initial_temperature_spread_C,
        "thermo_every": plan.thermo_step,
        "dump_every": plan.dump_every,
        "snapshot_every": plan.snapshot_every,
        "cross_pattern": files.cross_pattern,
        "snapshot_pattern": files.snapshot_pattern,
        "band": f"{crossing_band(case, plan):.6g}",
        "restart_every": plan.restart_every,
        "restart_pattern": files.restart_pattern,
        "final_restart": files.final_restart,
        "steps": plan.steps,
        "extra_commands": extra_commands,
        "coupled": coupled,
        "conduction": case.run.conduction,
        "shell_fix": shell_fix_command(shells) if shells else "",
        # Not used by the template: the record of how e_pp and e_pw were chosen (manifest).
        "restitution_calibration": {k: v.as_dict() for k, v in restitution.items()},
    }


def render_deck(context: dict[str, Any], template: str = "drum.in.j2") -> str:
    """Render a deck template with :class:`jinja2.StrictUndefined` (missing values raise)."""
    return _environment().get_template(template).render(**context)


def end_commands(context: dict[str, Any]) -> list[str]:
    """The deck's closing commands (final snapshot, restart) for the coupling loop to issue."""
    text = render_deck(context, "drum_end.in.j2")
    return [ln for ln in text.splitlines() if ln.strip() and not ln.lstrip().startswith("#")]
