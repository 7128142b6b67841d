"""DEM stage: LIGGGHTS deck, particle placement, the run itself, and resuming it.

The deck is rendered from ``templates/drum.in.j2``; the run goes through
:class:`drumflow.runner.Runner` under ``mpirun``. An interrupted run restarts from its newest
LIGGGHTS restart file; a finished run is reused.
"""

from __future__ import annotations

import json
import re
import time
from collections.abc import Callable
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import TYPE_CHECKING

from drumflow.bench.skips import skips
from drumflow.coupling import driver_command
from drumflow.dem.deck import (
    DeckFiles,
    deck_context,
    end_commands,
    plan_steps,
    render_deck,
    short_plan,
)
from drumflow.dem.placement import place_particles, write_data_file
from drumflow.dem.thermo import ThermoParser
from drumflow.dem.timestep import choose_time_step
from drumflow.dem.stability import LOST_PREFIX, StabilityLimits, StabilityMonitor, stability_limits
from drumflow.errors import InsertionError, LostParticlesError, SolverError, UnstableRunError
from drumflow.rundir import hash_text
from drumflow.runner import StopRun

if TYPE_CHECKING:
    from drumflow.case import Case
    from drumflow.geometry import GeometryResult
    from drumflow.rundir import RunDir
    from drumflow.runner import Runner

__all__ = ["AirCoupling", "DemResult", "ThermoParser", "run_dem", "dem_key"]

#: progress(stage, done, total): simulated seconds done out of the total.
ProgressCallback = Callable[[str, float, float], None]

_LOST_RE = re.compile(r"Lost atoms")


@dataclass(frozen=True)
class AirCoupling:
    """How the air acts on the particles during the DEM run (one-way).

    Attributes
    ----------
    field
        The driver's field spec: ``{"kind": "uniform", "velocity": [ux, uy, uz]}`` or
        ``{"kind": "grid", "path": "/abs/path/field.npz"}``.
    field_key
        Identifies the field (its hash), for the stage key.
    interval
        DEM steps between air updates.
    temperature_C, pressure_kPa
        The air's state (one-way: the air keeps its inlet temperature).
    omega
        Rotation rate of the frame the field was solved in (0 for a uniform field), rad/s.
    """

    field: dict
    field_key: str
    interval: int
    temperature_C: float
    pressure_kPa: float
    omega: float


@dataclass(frozen=True)
class DemResult:
    time_step: float
    steps: int
    dump_every: int
    snapshot_every: int
    particles_initial: int
    particles_final: int
    wall_time_s: float
    particle_steps_per_s: float
    resumed_from_step: int | None
    time_step_choice: dict
    log: str


def dem_key(case: Case, steps: int | None) -> str:
    """What the DEM stage depends on: the whole case, and a short-run step limit."""
    return case.hash() + (f":steps={steps}" if steps else "")


def _latest_restart(folder: Path) -> tuple[Path, int] | None:
    best: tuple[Path, int] | None = None
    for p in folder.glob("drum.*.restart"):
        m = re.search(r"drum\.(\d+)\.restart$", p.name)
        if m and (best is None or int(m.group(1)) > best[1]):
            best = (p, int(m.group(1)))
    return best


def _stability_record(limits: StabilityLimits, monitor: StabilityMonitor, stopped: bool) -> dict:
    return {"limits": limits.as_dict(), "stopped": stopped, "warnings": list(monitor.warnings),
            "max_overlap_m": monitor.max_overlap, "max_kinetic_energy_J": monitor.max_kinetic_energy}


def run_dem(
    case: Case,
    rundir: RunDir,
    runner: Runner,
    geometry: GeometryResult,
    progress: ProgressCallback | None = None,
    steps: int | None = None,
    timeout: float | None = None,
    extra_commands: str = "",
    air: AirCoupling | None = None,
) -> DemResult:
    """Run (or resume, or reuse) the DEM stage.

    Parameters
    ----------
    steps
        Stop after this many DEM steps (a short start-up check of a large case).
    timeout
        Wall-clock limit for LIGGGHTS, s.
    extra_commands
        LIGGGHTS lines run just before the main run (verification and stress scenes); they
        are part of the stage key.
    air
        Air acting on the particles; the run then goes through the coupling loop
        (:mod:`drumflow.coupling.driver`) instead of plain LIGGGHTS.

    Raises
    ------
    UnstableRunError
        The stability monitor stopped the run (diagnosis in the message).
    LostParticlesError
        Particles left the domain.
    SolverError
        LIGGGHTS failed otherwise.
    """
    key = dem_key(case, steps) + (f":extra={hash_text(extra_commands)}" if extra_commands else "")
    if air is not None:
        key += f":air={air.field_key}:every={air.interval}"
    done = rundir.stage_done("dem", key)
    if done:
        return DemResult(**done["result"])
    work = rundir.dem
    (work / "dumps").mkdir(parents=True, exist_ok=True)
    (work / "restart").mkdir(parents=True, exist_ok=True)
    choice = choose_time_step(case)
    plan = plan_steps(case, choice)
    if steps is not None:
        plan = short_plan(plan, steps)
    n = case.particle_count
    resume = None
    if steps is None and rundir.manifest.get("dem_key") == key:
        resume = _latest_restart(work / "restart")
    if resume is None:
        for old in (work / "dumps").glob("*.txt"):
            old.unlink()
        stale = [*(work / "restart").glob("*.restart"), *work.glob("log.resume-*.liggghts"),
                 *(work / "coupling").glob("*.csv")]
        for old in stale:
            old.unlink()
        positions = place_particles(case, n)
        write_data_file(case, positions, work / "particles.data", (geometry.box_lo, geometry.box_hi))
    rundir.record("dem_key", key)
    files = DeckFiles(
        stl_file=str(Path("..") / geometry.stl),
        lifters_stl_file=str(Path("..") / geometry.lifters_stl) if geometry.lifters_stl else "",
        static_shell=geometry.wall_motion == "static_shell",
    )
    context = deck_context(
        case,
        plan,
        files,
        resume_from=None if resume is None else str(resume[0].relative_to(work)),
        extra_commands=extra_commands,
        coupled=air is not None,
    )
    deck_name = "in.drum" if resume is None else "in.drum.resume"
    (work / deck_name).write_text(render_deck(context))
    rundir.record("time_step", choice.as_dict())
    rundir.record("restitution", context["restitution_calibration"])
    rundir.record("output_every", plan.dump_every)
    rundir.record("processes", case.process_count)
    rundir.record("skips", skips(case, choice.mode, air is not None, geometry.wall_motion))

    total = plan.steps * plan.time_step
    parser = ThermoParser(
        on_time=(lambda t, _n: progress("dem", min(t, total), total)) if progress else None
    )
    limits = stability_limits(case)
    monitor = StabilityMonitor(limits, forced_time_step=choice.mode == "forced")
    # LIGGGHTS writes (and flushes) its own log, which feeds the progress bar; the runner
    # keeps standard output separately.
    suffix = "" if resume is None else f".resume-{resume[1]}"
    own_log = work / f"log{suffix}.liggghts"
    log = work / f"liggghts{suffix}.out"
    if own_log.exists():
        own_log.unlink()

    def check(returncode: int, lines: list[str]) -> str | None:
        lost = next((ln for ln in reversed(lines) if _LOST_RE.search(ln)), None)
        if lost:
            return lost.strip()
        if not any(line.startswith("Loop time") for line in lines):
            return "LIGGGHTS stopped before finishing its run loop"
        return None

    program = ["liggghts", "-in", deck_name, "-log", own_log.name]
    if air is not None:
        spec = {
            "deck": deck_name,
            "log": own_log.name,
            "total_steps": plan.steps,
            "interval": air.interval,
            "time_step": plan.time_step,
            "omega": air.omega,
            "air_temperature_C": air.temperature_C,
            "air_pressure_kPa": air.pressure_kPa,
            "field": air.field,
            "coupling_log": "coupling/rank{rank}.{start}.csv",
            "tail": end_commands(context),
        }
        (work / "coupling.json").write_text(json.dumps(spec, indent=2))
    if air is None:
        command = runner.profile.mpi_command(program, case.process_count)
    else:
        command = driver_command(runner.profile, case.process_count)

    def on_line(line: str) -> None:
        # Every thermo row goes to the progress bar and to the stability monitor, which stops
        # the run at the first row that breaks a physical bound.
        before = len(parser.rows)
        parser(line)
        if len(parser.rows) == before:
            return
        row = parser.rows[-1]
        diagnosis = monitor.check(int(row[0]), row[1], int(row[2]), row[3], row[4], row[6])
        if diagnosis and diagnosis.startswith(LOST_PREFIX):
            raise StopRun(LostParticlesError(n, int(row[2]), own_log, command, time_s=row[1]))
        if diagnosis:
            raise StopRun(UnstableRunError(diagnosis, int(row[0]), own_log, command))

    t0 = time.perf_counter()
    try:
        runner.run(
            "liggghts", command, work, log, timeout=timeout, on_line=on_line, check=check,
            follow=own_log,
        )
    except (UnstableRunError, LostParticlesError):
        rundir.record("stability", _stability_record(limits, monitor, stopped=True))
        raise
    except SolverError as err:
        if _LOST_RE.search(f"{err.reason} {err.last_error}"):
            last = parser.rows[-1] if parser.rows else None
            final = int(last[2]) if last is not None and int(last[2]) < n else None
            raise LostParticlesError(
                n, final, log, command, time_s=None if last is None else last[1]
            ) from None
        raise
    finally:
        rundir.record_commands([r.as_dict() for r in runner.records if r.program == "liggghts"][-1:])
    wall = time.perf_counter() - t0
    rundir.record("stability", _stability_record(limits, monitor, stopped=False))
    first_atoms = int(parser.rows[0][2]) if parser.rows else 0
    if resume is None and first_atoms != n:
        # read_data silently skips atoms outside the box: the count must be exact at step 0.
        raise InsertionError(n, first_atoms, "LIGGGHTS read fewer particles than were placed")
    final_atoms = int(parser.rows[-1][2]) if parser.rows else n
    if final_atoms != n:
        # The stability monitor should have stopped the run at the first row with fewer atoms;
        # this is a second line of defence, e.g. against a deck edited by hand.
        raise LostParticlesError(n, final_atoms, log, command)
    steps_run = plan.steps - (resume[1] if resume else 0)
    result = DemResult(
        time_step=plan.time_step,
        steps=plan.steps,
        dump_every=plan.dump_every,
        snapshot_every=plan.snapshot_every,
        particles_initial=n,
        particles_final=final_atoms,
        wall_time_s=wall,
        particle_steps_per_s=n * steps_run / wall if wall > 0 else 0.0,
        resumed_from_step=None if resume is None else resume[1],
        time_step_choice=choice.as_dict(),
        log=str(log.relative_to(rundir.root)),
    )
    rundir.mark_done("dem", key, asdict(result), wall)
    return result
