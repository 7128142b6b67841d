"""The LIGGGHTS settings the settings study compares (:data:`VARIANTS`), and how each one edits
the baseline deck (:func:`apply_variant`).

A variant is a set of changes to the deck a run resumes from: the neighbour skin and rebuild
rule, the atom sort, the processor grid, the time step (with the restitution recalibrated for
it), the shell as a moving mesh, and diagnostics that switch physics off. Every edit replaces
exactly one line of the deck, or refuses with :class:`~drumflow.errors.SettingsStudyError`.
:mod:`drumflow.bench.settings` runs them.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass

from drumflow.case import Case
from drumflow.coupling.spec import OVERLAP_OFF
from drumflow.dem.restitution import calibrate_case
from drumflow.errors import SettingsStudyError

__all__ = ["VARIANTS", "Variant", "apply_variant", "replace_deck_line", "variant_steps"]


@dataclass(frozen=True)
class Variant:
    """One set of LIGGGHTS settings, as changes to the baseline deck (LIGGGHTS 3.8 syntax).

    Attributes
    ----------
    name, description
        For the table.
    skin_factor
        The ``neighbor`` skin times this.
    neigh_modify
        Replaces the arguments of the deck's ``neigh_modify`` line.
    atom_modify
        An ``atom_modify`` line after ``read_restart`` (``sort`` may change at any time).
    processors
        Replaces the ``processors`` grid (``{np}`` is the rank count); ``processors`` must come
        before the box is defined, i.e. before ``read_restart``, where the deck has it.
    min_ranks
        Skipped with fewer MPI ranks.
    time_step_factor
        The deck's time step times this. The variant runs ``--steps / factor`` steps (the same
        simulated time as the baseline, so that its speed-up is per simulated second), the air is
        updated every ``interval / factor`` steps (the same period in time) and the coupling
        loop's clock starts at the restart's time (``clock_origin``).
    moving_shell
        The shell as a rotating mesh (``move/mesh``) like the lifters, instead of the static
        shell with a surface velocity: the wall treatment of the conservative reference.
    no_conduction
        ``run.conduction = false`` as drumflow runs it: no heat fix in the deck (the restart's
        temperatures go into a plain per-atom ``Temp``), and the coupling loop integrates the
        temperatures. Changes the physics a user set: the row says what it does to the answer.
    no_overlap
        The thermo rows without the largest-overlap column (a constant in its place), so
        that LIGGGHTS does not gather every contact's overlap on any thermo step: the cost of
        the stability monitor's overlap check. Output only: the trajectories are the same.
    overlap_every_row
        The overlap column evaluated on every thermo row, as before the coupling loop left it
        out of most (``overlap_every``).
    bed_restitution
        The restitution calibrated at the median particle-particle impact speed measured in the
        run's last snapshot at or before the restart (:func:`bed_impact_speed`), instead of the
        typical speed (half the free-fall speed): exact for the impacts the bed has.
    no_rolling_friction
        Rolling friction coefficients 0 (a diagnostic that changes the physics: what the
        constant-directional-torque model contributes to a difference between settings).
    no_tangential_damping
        ``tangential_damping off`` on the particle-particle contacts (a diagnostic that changes
        the physics): whether the tangential dashpot, explicit in the time integration and
        acting on the stiff rotational modes of enduring contacts, is what the step changes.
    """

    name: str
    description: str
    skin_factor: float = 1.0
    neigh_modify: str | None = None
    atom_modify: str | None = None
    processors: str | None = None
    min_ranks: int = 1
    time_step_factor: float = 1.0
    moving_shell: bool = False
    no_conduction: bool = False
    no_overlap: bool = False
    overlap_every_row: bool = False
    bed_restitution: bool = False
    no_rolling_friction: bool = False
    no_tangential_damping: bool = False


#: What is compared. The deck's own settings are the baseline: ``neighbor SKIN bin`` (half a
#: particle diameter unless the case sets it), ``neigh_modify delay 0`` (LIGGGHTS' every 1 check
#: yes), LIGGGHTS' default sort (``atom_modify sort 1000 0.0``: every 1000 steps, bins of half
#: the neighbour cutoff) and the default processor grid for the rank count.
VARIANTS: list[Variant] = [
    Variant("baseline", "the run's deck, default processor grid for --np"),
    Variant("skin_x0.5", "neighbour skin halved (shorter lists, more rebuilds)", skin_factor=0.5),
    Variant("skin_x2", "neighbour skin doubled (longer lists, fewer rebuilds)", skin_factor=2.0),
    Variant("neigh_every5_check", "check for a rebuild every 5 steps only",
            neigh_modify="delay 0 every 5 check yes"),
    Variant("neigh_every1_nocheck", "rebuild at every step (upper bound of the list cost)",
            neigh_modify="delay 0 every 1 check no"),
    Variant("sort_off", "no spatial sorting of atoms", atom_modify="sort 0 0.0"),
    Variant("sort_every100", "spatial sort every 100 steps (default bins)", atom_modify="sort 100 0.0"),
    Variant("grid_axis", "processor grid along the drum axis (z)", processors="1 1 {np}", min_ranks=2),
    Variant("grid_x", "processor grid across the drum, along x", processors="{np} 1 1", min_ranks=2),
    Variant("grid_y", "processor grid across the drum, along y (gravity)", processors="1 {np} 1",
            min_ranks=2),
    Variant("no_conduction", "no particle-particle conduction: no heat fix, the coupling loop "
            "integrates the temperatures (run.conduction = false)", no_conduction=True),
    Variant("no_overlap", "thermo rows without the largest-overlap compute (the stability "
            "monitor's overlap check)", no_overlap=True),
    Variant("overlap_every_row", "the largest-overlap compute on every thermo row (drumflow "
            "before the loop evaluated it on every 10th)", overlap_every_row=True),
    # The time-to-answer reference of issue 11: half the default step (20 steps per Hertz
    # contact at the free-fall speed instead of 10; 10 % of the Rayleigh time is longer for the
    # paper's soft particles) and the moving-mesh shell; then also on the grid across the drum,
    # i.e. the reference as drumflow ran it before the axial grid.
    Variant("conservative", "half the time step (20 steps per contact) and the moving-mesh shell",
            time_step_factor=0.5, moving_shell=True),
    # Its two parts on their own: which one moves the bed (model one's kinetic energy).
    Variant("half_step", "half the time step (20 steps per contact), the static shell",
            time_step_factor=0.5),
    Variant("moving_shell", "the moving-mesh shell, the default time step", moving_shell=True),
    # A quarter of the step: with the default and the half step, a convergence sequence that
    # says whether the half step (the reference's) has itself converged the bed's motion.
    Variant("quarter_step", "a quarter of the time step (40 steps per contact), the static shell",
            time_step_factor=0.25),
    # The restitution calibrated where the bed's impacts are, at both steps: does the step still
    # move the bed then?
    Variant("bed_restitution", "restitution calibrated at the bed's median impact speed",
            bed_restitution=True),
    Variant("half_step_bed_restitution", "half the time step, restitution calibrated at the bed's "
            "median impact speed", time_step_factor=0.5, bed_restitution=True),
    # ...and without rolling friction at both steps (diagnostic: changes the physics).
    Variant("no_rolling_friction", "rolling friction off (diagnostic)", no_rolling_friction=True),
    Variant("half_step_no_rolling_friction", "half the time step, rolling friction off (diagnostic)",
            time_step_factor=0.5, no_rolling_friction=True),
    # ...and without the particles' tangential dashpot at the default step (diagnostic).
    Variant("no_tangential_damping", "tangential damping off between particles (diagnostic)",
            no_tangential_damping=True),
    Variant("conservative_grid_x", "conservative, on the processor grid across the drum (x)",
            time_step_factor=0.5, moving_shell=True, processors="{np} 1 1", min_ranks=2),
    # The fast profile (README, 'The fast profile') from a run at the contact step: what
    # `drumflow run --fast` changes in the deck, side by side with half_step (the 'auto' step).
    Variant("fast", "the fast profile: tangential dashpot off between particles and conduction "
            "off, at the run's step (the contact step)", no_tangential_damping=True,
            no_conduction=True),
]


def replace_deck_line(deck: str, pattern: str, line: str) -> str:
    """The deck with its one line matching ``pattern`` replaced by ``line``."""
    new, count = re.subn(pattern, line, deck, flags=re.M)
    if count != 1:
        raise SettingsStudyError(f"deck: expected one line matching {pattern!r}, found {count}")
    return new


def _scale_value(deck: str, keyword: str, factor: float, fmt: str, suffix: str = "") -> str:
    """The deck with the number after ``keyword`` (the one line ``keyword VALUE[suffix]``)
    times ``factor``, written with ``fmt``."""
    m = re.search(rf"^{keyword}\s+(\S+){suffix}\s*$", deck, flags=re.M)
    if m is None:
        raise SettingsStudyError(f"deck: no `{keyword} VALUE` line")
    value = fmt.format(float(m.group(1)) * factor)
    return replace_deck_line(deck, rf"^{keyword}\s+.*$", f"{keyword:<16}{value}")


def apply_variant(deck: str, variant: Variant, ranks: int, case: Case,
                  bed_speed: float | None = None) -> str:
    """The baseline deck with the variant's settings; ``case`` calibrates the restitution of a
    variant with another time step, at ``bed_speed`` (m/s) for a ``bed_restitution`` variant."""
    if variant.skin_factor != 1.0:
        deck = _scale_value(deck, "neighbor", variant.skin_factor, "{:.6g} bin", suffix=r"\s+bin")
    if variant.neigh_modify is not None:
        deck = replace_deck_line(deck, r"^neigh_modify\s+.*$", f"neigh_modify    {variant.neigh_modify}")
    if variant.atom_modify is not None:
        m = re.search(r"^read_restart\s+.*$", deck, flags=re.M)
        if m is None:
            raise SettingsStudyError("deck: no read_restart line")
        deck = deck[:m.end()] + f"\natom_modify     {variant.atom_modify}" + deck[m.end():]
    if variant.processors is not None:
        deck = replace_deck_line(deck, r"^processors\s+.*$",
                             f"processors      {variant.processors.format(np=ranks)}")
    if variant.time_step_factor != 1.0:
        deck = _scale_value(deck, "timestep", variant.time_step_factor, "{:.12g}")
    if variant.bed_restitution:
        if bed_speed is None:
            raise SettingsStudyError(f"variant {variant.name}: no measured impact speed of the bed")
        deck = _restitution_at(deck, case, bed_speed)
    elif variant.time_step_factor != 1.0:
        deck = _restitution_at(deck, case)
    if variant.no_rolling_friction:
        deck = _pair_property(deck, "m5", "coefficientRollingFriction", "0", "0")
    if variant.no_tangential_damping:
        pair = r"^pair_style\s+gran\s.*$"
        m = re.search(pair, deck, flags=re.M)
        if m is None:
            raise SettingsStudyError("deck: no `pair_style gran` line")
        deck = replace_deck_line(deck, pair, m.group(0).rstrip() + " tangential_damping off")
    if variant.moving_shell:
        pattern = (r"^fix shell all mesh/surface file (\S+) type 2 surface_ang_vel origin (\S+ \S+ \S+) "
                   r"axis (\S+ \S+ \S+) omega (\S+)\s*$")
        m = re.search(pattern, deck, flags=re.M)
        if m is None:
            raise SettingsStudyError("deck: no static shell (surface_ang_vel) to turn into a moving mesh")
        period = 2.0 * math.pi / float(m.group(4))
        deck = replace_deck_line(deck, r"^fix shell all mesh/surface .*$",
                             f"fix shell all mesh/surface file {m.group(1)} type 2")
        walls = re.search(r"^fix walls all wall/gran .*$", deck, flags=re.M)
        if walls is None:
            raise SettingsStudyError("deck: no `fix walls` line")
        line = (f"\nfix spin_shell all move/mesh mesh shell rotate origin {m.group(2)} axis {m.group(3)} "
                f"period {period:.12g}")
        deck = deck[:walls.end()] + line + deck[walls.end():]
    if variant.no_conduction:
        # Same fix ID and style as the per-atom temperature heat/gran/conduction creates, so
        # read_restart hands it the restart's temperatures.
        deck = replace_deck_line(deck, r"^fix heat all heat/gran/conduction .*$",
                             "fix Temp all property/atom Temp scalar yes no no 0.")
    if variant.no_overlap:
        # An unreferenced compute is never evaluated; the column keeps its place for the readers.
        if re.search(r"^variable\s+overlap\s+equal\s+c_overlap_max\s*$", deck, flags=re.M):
            deck = replace_deck_line(deck, r"^variable\s+overlap\s+equal\s+.*$", OVERLAP_OFF)
        else:  # a deck from before the overlap variable
            m = re.search(r"^thermo_style\s+.*\bc_overlap_max\b.*$", deck, flags=re.M)
            if m is None:
                raise SettingsStudyError("deck: no thermo_style line with c_overlap_max")
            line = m.group(0).replace("c_overlap_max", "v_no_overlap")
            deck = (deck[:m.start()] + OVERLAP_OFF.replace("overlap", "no_overlap", 1) + "\n"
                    + line + deck[m.end():])
    return deck


def _restitution_at(deck: str, case: Case, speed: float | None = None) -> str:
    """The deck's restitution coefficients calibrated for its (new) time step, as a run at that
    step has them (drumflow.dem.restitution), exact at ``speed`` (default: the typical speed):
    LIGGGHTS' realised restitution depends on the steps per contact, so the baseline's
    coefficients at half the step realise e_pp 0.111 instead of the case's 0.1 (paper model one)."""
    m = re.search(r"^timestep\s+(\S+)\s*$", deck, flags=re.M)
    if m is None:
        raise SettingsStudyError("deck: no `timestep` line")
    calibrated = calibrate_case(case, float(m.group(1)), speed)
    e_pp = f"{calibrated['particle_particle'].liggghts_value:.6g}"
    e_pw = f"{calibrated['particle_wall'].liggghts_value:.6g}"
    return _pair_property(deck, "m3", "coefficientRestitution", e_pp, e_pw)


def _pair_property(deck: str, fix_id: str, name: str, pp: str, pw: str) -> str:
    """The deck with its ``fix ID all property/global NAME peratomtypepair 2`` line set to
    particle-particle ``pp`` and particle-wall ``pw`` (type 1 the particles, 2 the walls, as
    drum.in.j2 writes them; wall-wall is never used and takes ``pw``)."""
    return replace_deck_line(deck, rf"^fix {fix_id} all property/global {name} .*$",
                         f"fix {fix_id} all property/global {name} peratomtypepair 2 "
                         f"{pp} {pw} {pw} {pw}")


def variant_steps(steps: int, variant: Variant) -> int:
    """DEM steps of a variant: the baseline's simulated time at the variant's time step."""
    return max(1, round(steps / variant.time_step_factor))
