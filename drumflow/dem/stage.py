"""DEM stage: LIGGGHTS deck, particle placement, the run itself, and resuming it.

Entry point :func:`run` (``run(case, rundir, runner, inputs) -> DemResult``). The deck is
rendered from the package template ``drumflow/dem/templates/drum.in.j2``; the run goes through
:class:`drumflow.runner.Runner` under ``mpirun`` (or, with air, through the coupling loop of
:mod:`drumflow.coupling.driver`, whose input file the coupling spec writes). An interrupted run
restarts from its newest LIGGGHTS restart file; a finished run is reused.

The time step is chosen once, by :func:`plan_run`, which the pipeline calls; the stage receives
the plan in :class:`DemInputs`.
"""

from __future__ import annotations

import json
import re
import time
from collections.abc import Callable
from dataclasses import asdict, dataclass, replace
from pathlib import Path
from typing import TYPE_CHECKING, Any

from drumflow.case import load_case
from drumflow.coupling.spec import (
    COUPLING_FILE,
    STOP_REQUEST,
    STOPPED_RECORD,
    CouplingSpec,
    driver_command,
)
from drumflow.coupling.stop import STOP_RECORD, stop_rule
from drumflow.dem.deck import (
    RESUME_MESH_PATTERN,
    DeckFiles,
    StepPlan,
    deck_context,
    end_commands,
    plan_steps,
    render_deck,
    short_plan,
)
from drumflow.dem.dumps import pack_dumps
from drumflow.dem.placement import place_particles, write_data_file
from drumflow.dem.stability import (
    LOST_PREFIX,
    OVERLAP_EVERY_ROWS,
    StabilityLimits,
    StabilityMonitor,
    stability_limits,
)
from drumflow.dem.state import (
    StartState,
    data_file_text,
    load_start_state,
    start_step,
    temperature_file_text,
)
from drumflow.dem.thermo import ThermoParser
from drumflow.dem.timestep import TimeStepChoice, choose_time_step
from drumflow.errors import (
    InsertionError,
    LostParticlesError,
    RunDirectoryError,
    RunStoppedError,
    SolverError,
    StartStateError,
    UnstableRunError,
)
from drumflow.rundir import hash_text
from drumflow.runner import StopRun

if TYPE_CHECKING:
    from drumflow.case import Case
    from drumflow.geometry.stage import GeometryResult
    from drumflow.rundir import RunDir
    from drumflow.runner import Runner

__all__ = ["DemInputs", "DemResult", "ProgressCallback", "clear_stop_request", "dem_key", "kept_time_step",
           "plan_run", "request_stop", "run"]

#: progress(stage, done, total): simulated seconds done out of the total.
ProgressCallback = Callable[[str, float, float], None]

_LOST_RE = re.compile(r"Lost atoms")
#: The machine's load while the DEM ran (drumflow.machine_load), beside its log: every
#: attempt of a resumed run appends to it.
LOAD_LOG = "machine_load.csv"


@dataclass(frozen=True)
class DemInputs:
    """What the DEM stage needs besides the case.

    Attributes
    ----------
    geometry
        The geometry stage's walls.
    choice, plan
        The time step and the step plan (:func:`plan_run`, chosen once per run).
    processes
        MPI processes (the launch profile's choice for the case).
    coupling
        Air acting on the particles; the run then goes through the coupling loop.
    steps
        Stop after this many DEM steps (a short start-up check of a large case); ``plan`` is
        then already the short plan.
    timeout
        Wall-clock limit for LIGGGHTS, s.
    extra_commands
        LIGGGHTS lines run just before the main run (verification and stress scenes); they
        are part of the stage key.
    progress
        ``progress("dem", simulated_s, total_s)``.
    """

    geometry: GeometryResult
    choice: TimeStepChoice
    plan: StepPlan
    processes: int = 1
    coupling: CouplingSpec | None = None
    steps: int | None = None
    timeout: float | None = None
    extra_commands: str = ""
    progress: ProgressCallback | None = None

    @classmethod
    def for_case(cls, case: Case, geometry: GeometryResult, **kwargs: Any) -> DemInputs:
        """Inputs with the case's time step and plan (:func:`plan_run`)."""
        choice, plan = plan_run(case, kwargs.get("steps"))
        return cls(geometry, choice, plan, **kwargs)


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
    time_step_choice: dict[str, Any]
    log: str
    #: The 'converged' stop rule's verdict (``dem/coupling/stop.json``); None for a fixed run.
    stop: dict[str, Any] | None = None
    #: True when this call found the stage finished and ran nothing.
    reused: bool = False


def _add_loop_options(spec_path: Path, case: Case, plan: StepPlan, checkpoint: str | None) -> None:
    """Give the coupling loop the 'converged' stop rule, the in-memory crossings, the rows
    the overlap bound is evaluated on (:data:`~drumflow.dem.stability.OVERLAP_EVERY_ROWS`) and
    the restart pattern it writes when interrupted (None: a run that is never resumed)."""
    extra: dict[str, Any] = {"overlap_every": OVERLAP_EVERY_ROWS * plan.thermo_step}
    if checkpoint is not None:
        extra["checkpoint"] = checkpoint
    rule = stop_rule(case, plan.steps * plan.time_step, plan.dump_every)
    if rule is not None:
        extra["stop"] = rule
    if case.run.crossings == "loop":
        extra["crossings"] = "loop"
    spec = json.loads(spec_path.read_text())
    spec.update(extra, particles=case.particle_count)
    spec_path.write_text(json.dumps(spec, indent=2))


def _stop_record(rundir: RunDir) -> dict[str, Any] | None:
    """The stop rule's verdict left by the coupling loop, or None."""
    path = rundir.dem / STOP_RECORD
    return json.loads(path.read_text()) if path.exists() else None


def plan_run(case: Case, steps: int | None = None,
             choice: TimeStepChoice | None = None) -> tuple[TimeStepChoice, StepPlan]:
    """The one choice of the DEM time step for a run (``choice``, e.g. :func:`kept_time_step`,
    or :func:`choose_time_step`'s), and the step plan that follows from it (cut to ``steps``
    for a short start-up run)."""
    if choice is None:
        choice = choose_time_step(case)
    plan = plan_steps(case, choice)
    return choice, plan if steps is None else short_plan(plan, steps)


def kept_time_step(case: Case, rundir: RunDir, steps: int | None = None) -> TimeStepChoice | None:
    """The time step a run of ``case`` in ``rundir`` started with, when ``drumflow run`` will
    resume it (a restart to resume from) or reuse it (its DEM stage finished); else None.

    A run keeps its step for life, even when a later drumflow chooses another for the same case
    (as "auto" did when it came to respect the spin limit): a change of step at a restart would
    put LIGGGHTS' step counter at another time, and would change the air-update interval and
    with it the stage's key, so the run would start afresh and delete its restarts.
    """
    record = rundir.manifest.get("time_step")
    key = str(rundir.manifest.get("dem_key", ""))
    if steps is not None or not record or ":steps=" in key or key.split(":")[0] != case.hash():
        return None
    finished = (rundir.finished_key("dem") or "").split(":")[0] == case.hash()
    if latest_restart(rundir.dem_restart) is None and not finished:
        return None
    known = set(TimeStepChoice.__dataclass_fields__)
    return TimeStepChoice(**{k: v for k, v in record.items() if k in known})


def dem_key(case: Case, steps: int | None) -> str:
    """What the DEM stage depends on: the whole case, and a short-run step limit."""
    return case.hash() + (f":steps={steps}" if steps else "")


def _stage_key(case: Case, inputs: DemInputs) -> str:
    key = dem_key(case, inputs.steps)
    if inputs.extra_commands:
        key += f":extra={hash_text(inputs.extra_commands)}"
    if inputs.coupling is not None:
        key += inputs.coupling.key
    return key


def request_stop(run_dir: Path) -> Path:
    """Ask the coupling loop running in ``run_dir`` to write a restart at its next air update and
    stop (``drumflow stop``); return the request file. ``drumflow run`` then exits with 130 and
    resumes from that restart when run again. A run still in its geometry or air stage keeps
    the request and stops at its DEM's first air update.

    Raises
    ------
    RunDirectoryError
        The run's DEM stage has no coupling loop that looks for the request (no air, or a
        short start-up check).
    """
    dem_dir = Path(run_dir) / "dem"
    spec = dem_dir / COUPLING_FILE
    if spec.is_file():
        stoppable = bool(json.loads(spec.read_text()).get("checkpoint"))
    else:
        # The DEM stage has not started: the case says whether it will have a loop.
        case_file = Path(run_dir) / "case.toml"
        stoppable = case_file.is_file() and load_case(case_file).air.model != "none"
    if not stoppable:
        raise RunDirectoryError(
            f"{Path(run_dir).resolve()}: its DEM run cannot be asked to stop (allowed: a run with "
            "air, air.model 'uniform' or 'cfd', started by this drumflow); stop it with Ctrl-C or "
            "`kill PID`, and it resumes from its last periodic restart")
    request = dem_dir / STOP_REQUEST
    request.write_text(f"stop requested at {time.strftime('%Y-%m-%d %H:%M:%S')} (drumflow stop)\n")
    return request


def clear_stop_request(rundir: RunDir) -> None:
    """Remove a stop request left by an earlier attempt (``drumflow run`` calls this when it
    starts, so a request made while this attempt's geometry or air stage runs is kept)."""
    (rundir.dem / STOP_REQUEST).unlink(missing_ok=True)


def restart_files(folder: Path) -> list[tuple[int, Path]]:
    """The ``drum.STEP.restart`` files of ``folder`` as (step, path), oldest first (other
    files, such as ``final.restart``, are not listed)."""
    found: list[tuple[int, Path]] = []
    for p in folder.glob("drum.*.restart"):
        m = re.fullmatch(r"drum\.(\d+)\.restart", p.name)
        if m:
            found.append((int(m.group(1)), p))
    return sorted(found)


def latest_restart(folder: Path) -> tuple[Path, int] | None:
    """The newest ``drum.STEP.restart`` of ``folder`` and its step, or None."""
    found = restart_files(folder)
    return (found[-1][1], found[-1][0]) if found else None


#: Restart files kept in ``dem/restart`` while a run goes: the newest resumes the run; the one
#: before it is a spare (one at the end, :func:`_tidy_output`). Older ones only take disk (170
#: MB each for paper model two's 299,164 particles, 35 of them in a 17.5 s run), so they are
#: removed as the run goes, the one an attempt resumed from too: what the resume check needs
#: of it, the turning mesh as LIGGGHTS read it, the resumed deck writes at its set-up
#: (:data:`~drumflow.dem.deck.RESUME_MESH_PATTERN`).
KEEP_RESTARTS = 2
#: How often (wall seconds) the run's thermo rows trigger the pruning.
PRUNE_EVERY_S = 60.0


def prune_restarts(folder: Path, keep: int = KEEP_RESTARTS) -> list[Path]:
    """Remove all but the ``keep`` newest ``drum.STEP.restart`` files of ``folder``.

    Safe while LIGGGHTS runs: a file it is still writing is the newest, and the newest are
    kept. Other files are not touched. Returns the removed paths.
    """
    steps = restart_files(folder)
    removed = [p for _, p in steps[:max(0, len(steps) - keep)]]
    for p in removed:
        p.unlink(missing_ok=True)
    return removed


def _tidy_output(restarts: Path, dumps: Path, finished: bool) -> None:
    """Prune restarts and pack snapshots. Housekeeping never stops a run: a file that cannot be
    packed (a snapshot cut short by an earlier kill) stays text, for ``drumflow post`` to name.

    While the run goes, the newest snapshot (perhaps still being written) stays text and the
    newest two restarts stay (the newest may be cut short by a kill). Once it has finished, its
    last restart is complete: only that one stays (the end state, to start a study or a longer
    run from).
    """
    try:
        prune_restarts(restarts, keep=1 if finished else KEEP_RESTARTS)
        pack_dumps(dumps, "snap", keep_newest=0 if finished else 1,
                   skip_unreadable=True)
    except OSError:
        pass  # a full disk or a vanished folder: the run itself will say so if it matters


def _stability_record(limits: StabilityLimits, monitor: StabilityMonitor, stopped: bool) -> dict[str, Any]:
    return {"limits": limits.as_dict(), "stopped": stopped, "warnings": list(monitor.warnings),
            "max_overlap_m": monitor.max_overlap, "max_kinetic_energy_J": monitor.max_kinetic_energy}


def _prepare_workdir(case: Case, rundir: RunDir, inputs: DemInputs, key: str,
                     state: StartState | None = None) -> tuple[Path, int] | None:
    """Create the DEM folders; return the restart to resume from, or start afresh (stale
    outputs removed, particles placed, or taken from the start state ``state``)."""
    rundir.dem_dumps.mkdir(parents=True, exist_ok=True)
    rundir.dem_restart.mkdir(parents=True, exist_ok=True)
    resume = None
    if inputs.steps is None and rundir.manifest.get("dem_key") == key:
        resume = latest_restart(rundir.dem_restart)
    if resume is None:
        stale = [*rundir.dem_dumps.glob("*.txt"), *rundir.dem_dumps.glob("*.npz*"),
                 *rundir.dem_restart.glob("*.restart"),
                 *rundir.dem.glob("log.resume-*.liggghts"), *rundir.dem_coupling_logs.glob("*.csv"),
                 *rundir.dem.glob(RESUME_MESH_PATTERN),
                 *rundir.dem_coupling_logs.glob("*.json")]
        for old in stale:
            old.unlink()
        box = (inputs.geometry.box_lo, inputs.geometry.box_hi)
        if state is not None:
            (rundir.dem / "particles.data").write_text(data_file_text(state, case, box))
            (rundir.dem / DeckFiles.start_temperatures).write_text(temperature_file_text(state))
        else:
            positions = place_particles(case, case.particle_count)
            write_data_file(case, positions, rundir.dem / "particles.data", box)
    rundir.record("dem_key", key)
    return resume


def write_deck(case: Case, rundir: RunDir, inputs: DemInputs,
                resume: tuple[Path, int] | None,
                first_step: int | None = None) -> tuple[str, dict[str, Any]]:
    """Render the deck (fresh, from a start state at ``first_step``, or resume) and record what
    it chose; return its name and context."""
    geometry = inputs.geometry
    files = DeckFiles(
        stl_file=str(Path("..") / geometry.stl),
        lifters_stl_file=str(Path("..") / geometry.lifters_stl) if geometry.lifters_stl else "",
        static_shell=geometry.wall_motion == "static_shell",
        ends_stl_file=str(Path("..") / geometry.ends_stl) if geometry.ends_stl else "",
    )
    context = deck_context(
        case,
        inputs.plan,
        files,
        resume_from=None if resume is None else str(resume[0].relative_to(rundir.dem)),
        extra_commands=inputs.extra_commands,
        coupled=inputs.coupling is not None,
        processes=inputs.processes,
        shells=(inputs.coupling.interior.shells
                if inputs.coupling is not None and inputs.coupling.interior is not None else 0),
        start_step=first_step if resume is None else None,
    )
    deck_name = "in.drum" if resume is None else "in.drum.resume"
    (rundir.dem / deck_name).write_text(render_deck(context))
    rundir.record("time_step", inputs.choice.as_dict())
    rundir.record("restitution", context["restitution_calibration"])
    rundir.record("output_every", inputs.plan.dump_every)
    rundir.record("processes", inputs.processes)
    return deck_name, context


def finished_loop(returncode: int, lines: list[str]) -> str | None:
    """A runner ``check``: LIGGGHTS can exit 0 after losing atoms or before its run loop."""
    lost = next((ln for ln in reversed(lines) if _LOST_RE.search(ln)), None)
    if lost:
        return lost.strip()
    if not any(line.startswith("Loop time") for line in lines):
        return "LIGGGHTS stopped before finishing its run loop"
    return None


class _RowWatcher:
    """Every thermo row goes to the progress bar and to the stability monitor, which stops the
    run at the first row that breaks a physical bound."""

    def __init__(self, case: Case, inputs: DemInputs, own_log: Path, restarts: Path,
                 dumps: Path) -> None:
        total = inputs.plan.steps * inputs.plan.time_step
        progress = inputs.progress
        self.parser = ThermoParser(
            on_time=(lambda t, _n: progress("dem", min(t, total), total)) if progress else None
        )
        self.limits = stability_limits(case)
        self.monitor = StabilityMonitor(self.limits, forced_time_step=inputs.choice.mode == "forced")
        self.particles = case.particle_count
        self.own_log = own_log
        self.command: list[str] = []
        self.restarts = restarts
        self.dumps = dumps
        self._pruned_at = time.monotonic()

    def __call__(self, line: str) -> None:
        before = len(self.parser.rows)
        self.parser(line)
        if len(self.parser.rows) == before:
            return
        if time.monotonic() - self._pruned_at > PRUNE_EVERY_S:
            _tidy_output(self.restarts, self.dumps, finished=False)
            self._pruned_at = time.monotonic()
        row = self.parser.rows[-1]
        diagnosis = self.monitor.check(int(row[0]), row[1], int(row[2]), row[3], row[4], row[6])
        if diagnosis and diagnosis.startswith(LOST_PREFIX):
            raise StopRun(LostParticlesError(self.particles, int(row[2]), self.own_log, self.command,
                                             time_s=row[1]))
        if diagnosis:
            raise StopRun(UnstableRunError(diagnosis, int(row[0]), self.own_log, self.command))

    def record(self, stopped: bool) -> dict[str, Any]:
        return _stability_record(self.limits, self.monitor, stopped)


def _launch(case: Case, rundir: RunDir, runner: Runner, inputs: DemInputs, deck_name: str,
            context: dict[str, Any], suffix: str) -> tuple[_RowWatcher, Path, float]:
    """Run LIGGGHTS (or the coupling loop) with the stability monitor; return the watcher, the
    standard-output log and the wall time. Restarts are pruned and snapshots packed as it goes."""
    work = rundir.dem
    # LIGGGHTS writes (and flushes) its own log, which feeds the progress bar; the runner
    # keeps standard output separately.
    own_log = work / f"log{suffix}.liggghts"
    log = work / f"liggghts{suffix}.out"
    if own_log.exists():
        own_log.unlink()
    stop_request: Path | None = None
    if inputs.coupling is None:
        # LIGGGHTS alone cannot be asked to stop: an interrupt resumes from the last restart.
        command = runner.profile.liggghts_command(deck_name, own_log.name, inputs.processes)
    else:
        spec_path = inputs.coupling.write_driver_file(work, deck_name, own_log.name,
                                                      inputs.plan.steps, inputs.plan.time_step,
                                                      end_commands(context), inputs.plan.thermo_step)
        # A short start-up check is never resumed: it writes no restart when interrupted.
        resumable = inputs.steps is None
        _add_loop_options(spec_path, case, inputs.plan,
                          DeckFiles.restart_pattern if resumable else None)
        command = driver_command(runner.profile, inputs.processes, COUPLING_FILE)
        stop_request = work / STOP_REQUEST if resumable else None
    watcher = _RowWatcher(case, inputs, own_log, rundir.dem_restart, rundir.dem_dumps)
    watcher.command = command
    stopped_record = work / STOPPED_RECORD
    stopped_record.unlink(missing_ok=True)
    t0 = time.perf_counter()
    try:
        runner.run("liggghts", command, work, log, timeout=inputs.timeout, on_line=watcher,
                   check=finished_loop, follow=own_log, stop_request=stop_request,
                   load_log=work / LOAD_LOG)
        if stopped_record.exists():
            # `drumflow stop`: the loop wrote a restart and ended before the run's end; the
            # manifest says so rather than "ok".
            runner.records[-1].status = "stopped on request"
            _tidy_output(rundir.dem_restart, rundir.dem_dumps, finished=False)
            where = json.loads(stopped_record.read_text())
            raise RunStoppedError(int(where["step"]), float(where["time_s"]))
    except (UnstableRunError, LostParticlesError):
        rundir.record("stability", watcher.record(stopped=True))
        raise
    except SolverError as err:
        if _LOST_RE.search(f"{err.reason} {err.last_error}"):
            rows = watcher.parser.rows
            last = rows[-1] if rows else None
            n = case.particle_count
            final = int(last[2]) if last is not None and int(last[2]) < n else None
            raise LostParticlesError(
                n, final, log, command, time_s=None if last is None else last[1]
            ) from None
        raise
    finally:
        rundir.record_commands([r.as_dict() for r in runner.records if r.program == "liggghts"][-1:])
    wall = time.perf_counter() - t0
    _tidy_output(rundir.dem_restart, rundir.dem_dumps, finished=True)
    rundir.record("stability", watcher.record(stopped=False))
    return watcher, log, wall


def run(case: Case, rundir: RunDir, runner: Runner, inputs: DemInputs) -> DemResult:
    """Run (or resume, or reuse) the DEM stage.

    Raises
    ------
    UnstableRunError
        The stability monitor stopped the run (diagnosis in the message).
    LostParticlesError
        Particles left the domain.
    InsertionError
        LIGGGHTS read fewer particles than were placed.
    SolverError
        LIGGGHTS failed otherwise.
    """
    key = _stage_key(case, inputs)
    done = rundir.stage_done("dem", key)
    if done:
        return DemResult(**{**done["result"], "reused": True})
    state = load_start_state(case)
    first_step = None if state is None else start_step(state, inputs.plan.time_step)
    if state is not None and first_step is not None:
        if inputs.steps is not None:
            # A short start-up check runs its steps from the state's step (the plan counts
            # from step 0, as LIGGGHTS' `run N upto` and the coupling loop's total do).
            inputs = replace(inputs, plan=replace(inputs.plan, steps=first_step + inputs.steps))
        elif inputs.plan.steps <= first_step:
            raise StartStateError(
                case.run.start_state or "", f"the state is at t = {state.time_s:.6g} s, run.time "
                f"= {case.run.time:g} s ends before it: run.time is the end time, counted from 0")
    resume = _prepare_workdir(case, rundir, inputs, key, state)
    if state is not None and resume is None:
        rundir.record("start_state", {
            "file": case.run.start_state, "time_s": state.time_s, "step": first_step,
            "source_case_hash": state.case_hash, "source": state.source,
            "drumflow_version": state.drumflow_version})
    deck_name, context = write_deck(case, rundir, inputs, resume, first_step)
    suffix = "" if resume is None else f".resume-{resume[1]}"
    watcher, log, wall = _launch(case, rundir, runner, inputs, deck_name, context, suffix)
    rows = watcher.parser.rows
    n = case.particle_count
    first_atoms = int(rows[0][2]) if rows else 0
    if resume is None and first_atoms != n:
        # read_data silently skips atoms outside the box: the count must be exact at step 0.
        raise InsertionError(n, first_atoms, "LIGGGHTS read fewer particles than were placed")
    final_atoms = int(rows[-1][2]) if rows else n
    if final_atoms != n:
        # The stability monitor should have stopped the run at the first row with fewer atoms;
        # this is a second line of defence, e.g. against a deck edited by hand.
        raise LostParticlesError(n, final_atoms, log, watcher.command)
    plan = inputs.plan
    stop = _stop_record(rundir)
    steps = int(stop["step"]) if stop else plan.steps
    if stop:
        rundir.record("stop", stop)
    steps_run = steps - (resume[1] if resume else first_step or 0)
    result = DemResult(
        time_step=plan.time_step,
        steps=steps,
        dump_every=plan.dump_every,
        snapshot_every=plan.snapshot_every,
        particles_initial=n,
        particles_final=final_atoms,
        wall_time_s=wall,
        particle_steps_per_s=n * steps_run / wall if wall > 0 else 0.0,
        resumed_from_step=None if resume is None else resume[1],
        time_step_choice=inputs.choice.as_dict(),
        log=str(log.relative_to(rundir.root)),
        stop=stop,
    )
    rundir.mark_done("dem", key, asdict(result), wall)
    return result
