"""Where a run stands, read from its directory while it goes or after: ``drumflow status``.

A paper-scale run takes hours in the background (model one with every particle: about 15 h on
2 cores), and its progress bar is in a log file. This reads what the run writes anyway (the
manifest, the stage markers, LIGGGHTS' own log, the coupling loop's per-update wall times and
the restart files, and the pid of the ``drumflow run`` process in the manifest) and says
whether it still runs, how far it has got, how fast it goes now and when it will end at
that pace, what a resume would start from, and how much disk it holds. No solver is started
and nothing is written.
"""

from __future__ import annotations

import json
import math
import os
import socket
import time
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import pandas as pd

from drumflow.coupling.log import read_coupling, update_walls
from drumflow.coupling.spec import STOPPED_RECORD
from drumflow.dem.stage import LOAD_LOG, restart_files
from drumflow.dem.thermo import COLUMNS, ThermoParser, log_files
from drumflow.errors import DrumflowError, MissingRunFileError
from drumflow.machine_load import contended_stretches, read_load_log, sample_spans
from drumflow.readers import read_json_object
from drumflow.rundir import read_stage_marker

if TYPE_CHECKING:
    from drumflow.case import Case

#: Updates the recent pace is taken over: about two minutes of model one, long enough to even
#: out a slow update, short enough to follow the fall in pace as the curtain forms.
RECENT_UPDATES = 20
#: A run without a process record counts as running while its log is younger than this, s: a
#: paper-scale run writes a thermo row every update (about 15 s for model one).
RUNNING_LOG_AGE_S = 300.0
#: Wall seconds of the load log the status averages other programs' CPU over.
RECENT_LOAD_S = 600.0
#: Bytes read from the end of the newest LIGGGHTS log for its last thermo row.
LOG_TAIL_BYTES = 65536


@dataclass(frozen=True)
class RunStatus:
    """A run directory's state. Times in seconds; ``None`` where the run has not written it.

    Attributes
    ----------
    case, target_time_s
        The case's name and its ``run.time``.
    stages_done
        Stages with a finished marker, in pipeline order.
    finished
        The DEM stage has finished (the run reached its end or its stop rule fired).
    reached_time_s, step, particles
        The last thermo row LIGGGHTS wrote: simulated time, step, particles in the domain.
    particles_initial
        The case's particle count (spheres, after coarse-graining).
    log_age_s
        Wall seconds since the newest LIGGGHTS log was written (a running run writes every
        few seconds).
    process_alive
        Whether the ``drumflow run`` process the manifest records is alive; None when the run
        was started on another host or by a drumflow that did not record it.
    wall_per_simulated_s
        Wall seconds per simulated second over the last :data:`RECENT_UPDATES` coupling updates
        that logged a time (runs with air).
    eta_s
        Wall seconds to ``target_time_s`` at that pace (a lower bound when the pace falls, as
        it does while a curtain forms).
    restart_step, restart_time_s
        The newest restart file, which a resume starts from.
    restarts, restart_bytes
        Restart files kept and their size.
    output_bytes
        Everything else in the run directory.
    stopped_on_request_s
        Where the coupling loop wrote its restart when it was last asked to stop (``drumflow
        stop``, an interrupt, a SLURM time-limit warning), s; None if the last attempt was not.
    other_cores_recent
        Other programs' mean CPU, in cores, over the load log's last :data:`RECENT_LOAD_S`
        (:mod:`drumflow.machine_load`): the pace above is the run's own only when this is near 0.
    contended_s, load_logged_s
        Wall seconds of the load log's contended stretches (others above
        :data:`drumflow.machine_load.BUSY_OTHER_CORES`), and of all it covers; None without a log.
    time_step_s, new_run_time_step_s
        The run's DEM step (it keeps it when resumed) and the step a new run of the same case
        would take with this drumflow (they differ for a run started before "auto" came to
        respect the spin limit); None before the DEM stage has chosen one.
    """

    run_dir: str
    case: str
    target_time_s: float
    stages_done: list[str]
    finished: bool
    reached_time_s: float | None
    step: int | None
    particles: int | None
    particles_initial: int
    log_age_s: float | None
    process_alive: bool | None
    wall_per_simulated_s: float | None
    eta_s: float | None
    restart_step: int | None
    restart_time_s: float | None
    restarts: int
    restart_bytes: int
    output_bytes: int
    stopped_on_request_s: float | None = None
    other_cores_recent: float | None = None
    contended_s: float | None = None
    load_logged_s: float | None = None
    time_step_s: float | None = None
    new_run_time_step_s: float | None = None

    @property
    def running(self) -> bool:
        """The run is going: its recorded process is alive or, without a record to check (an
        older run, another host), its log was written in the last :data:`RUNNING_LOG_AGE_S`."""
        if self.finished:
            return False
        if self.process_alive is not None:
            return self.process_alive
        return self.log_age_s is not None and self.log_age_s < RUNNING_LOG_AGE_S

    def to_dict(self) -> dict[str, Any]:
        return {**asdict(self), "running": self.running}


STAGE_ORDER = ("geometry", "air", "dem", "post")


def _last_thermo_row(log: Path) -> tuple[float, ...] | None:
    with log.open("rb") as fh:
        fh.seek(max(0, log.stat().st_size - LOG_TAIL_BYTES))
        tail = fh.read().decode(errors="replace")
    parser = ThermoParser(columns=COLUMNS)
    for line in tail.splitlines():
        parser(line)
    return parser.rows[-1] if parser.rows else None


def _recent_pace(coupling_dir: Path, time_step: float) -> float | None:
    if not coupling_dir.is_dir():
        return None
    coupling = read_coupling(coupling_dir, time_step)
    if coupling.empty:
        return None
    updates = update_walls(coupling)
    updates = updates[~updates["paused"].astype(bool)].tail(RECENT_UPDATES)
    simulated = float((updates["steps"] * time_step).sum())
    return float(updates["wall_s"].sum()) / simulated if simulated > 0 else None


def _stopped_on_request(dem: Path) -> float | None:
    path = dem / STOPPED_RECORD  # removed when the next attempt starts
    try:
        return float(json.loads(path.read_text())["time_s"])
    except (OSError, ValueError, KeyError, TypeError):
        return None


def process_alive(record: dict[str, Any] | None) -> bool | None:
    """Whether the process of a manifest's ``process`` record (pid, host) still runs drumflow:
    None for another host or no record. The command line is checked too, so that a pid reused
    by another program after a reboot does not read as a live run."""
    if not record or record.get("host") != socket.gethostname():
        return None
    pid = int(record["pid"])
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:  # alive, another user's
        pass
    cmdline = Path(f"/proc/{pid}/cmdline")
    if cmdline.exists():
        try:
            return b"drumflow" in cmdline.read_bytes()
        except OSError:
            return False
    return True


def run_status(run_dir: Path | str, now: float | None = None) -> RunStatus:
    """Read a run directory's state (see :class:`RunStatus`).

    Parameters
    ----------
    run_dir
        A directory made by ``drumflow run`` (finished, running or interrupted).
    now
        The wall clock to measure the log's age against (default: now).

    Raises
    ------
    MissingRunFileError
        ``run_dir`` has no ``manifest.json``: not a run directory, or one whose run has not
        started.
    BadFileError
        Its ``manifest.json`` is not a readable JSON object (cut short, not UTF-8), or a
        stage marker (``stages/*.json``) is damaged.
    """
    from drumflow.case import load_case

    root = Path(run_dir)
    manifest_path = root / "manifest.json"
    if not manifest_path.is_file():
        raise MissingRunFileError(manifest_path.resolve(), "the run's manifest")
    # The manifest is replaced atomically (RunDir.save): one that does not parse was damaged.
    manifest = read_json_object(manifest_path, "the run's manifest")
    case = load_case(root / "case.toml")
    # Each marker read, not only listed: a damaged one is refused naming it (read_stage_marker
    # says why it is not taken as "stage not finished"), not reported as a finished run.
    markers = sorted((root / "stages").glob("*.json"))
    for marker in markers:
        read_stage_marker(marker)
    stages = {p.stem for p in markers}
    done = [s for s in STAGE_ORDER if s in stages] + sorted(stages - set(STAGE_ORDER))
    time_step = (manifest.get("time_step") or {}).get("time_step")

    dem = root / "dem"
    logs = log_files(dem) if dem.is_dir() else []
    row = _last_thermo_row(logs[-1]) if logs else None
    age = None
    if logs:
        age = (time.time() if now is None else now) - max(p.stat().st_mtime for p in logs)

    pace = _recent_pace(dem / "coupling", float(time_step)) if time_step else None
    reached = row[1] if row is not None else None
    finished = "dem" in stages
    eta = None
    if pace is not None and reached is not None and not finished:
        eta = max(0.0, case.run.time - reached) * pace

    restarts = restart_files(dem / "restart") if (dem / "restart").is_dir() else []
    restart_bytes = sum(p.stat().st_size for _, p in restarts)
    total = sum(p.stat().st_size for p in root.rglob("*") if p.is_file())
    newest = restarts[-1][0] if restarts else None
    return RunStatus(
        run_dir=str(root),
        case=case.name,
        target_time_s=case.run.time,
        stages_done=done,
        finished=finished,
        reached_time_s=reached,
        step=None if row is None else int(row[0]),
        particles=None if row is None else int(row[2]),
        particles_initial=case.dem_case().particle_count,
        log_age_s=age,
        process_alive=process_alive(manifest.get("process")),
        wall_per_simulated_s=pace,
        eta_s=eta,
        restart_step=newest,
        restart_time_s=(newest * float(time_step)
                        if newest is not None and time_step and math.isfinite(float(time_step)) else None),
        restarts=len(restarts),
        restart_bytes=restart_bytes,
        output_bytes=total - restart_bytes,
        stopped_on_request_s=_stopped_on_request(dem),
        **_machine_load(dem / LOAD_LOG),
        time_step_s=float(time_step) if time_step else None,
        new_run_time_step_s=_new_run_time_step(case) if time_step else None,
    )


def _machine_load(path: Path) -> dict[str, float | None]:
    """The load log's recent contention and its contended share (None without a log)."""
    none: dict[str, float | None] = {"other_cores_recent": None, "contended_s": None,
                                     "load_logged_s": None}
    if not path.is_file():
        return none
    try:
        table = read_load_log(path)
    except (ValueError, OSError, pd.errors.ParserError, pd.errors.EmptyDataError):
        return none  # a status must stay readable; the log is a diagnostic
    if table.empty:
        return none
    times = table["time_unix"].to_numpy(float)
    recent = table[times >= times[-1] - RECENT_LOAD_S]
    stretches = contended_stretches(table)
    logged = float(sample_spans(times).sum())
    return {"other_cores_recent": float(recent["other_cores"].mean()),
            "contended_s": float(sum(end - start for start, end, _ in stretches)),
            "load_logged_s": logged}


def _new_run_time_step(case: Case) -> float | None:
    """The step this drumflow would give a new run of ``case``; None where it would refuse the
    case now (the status of an existing run must still be readable)."""
    from drumflow.dem.timestep import choose_time_step

    try:
        return choose_time_step(case.dem_case()).time_step
    except DrumflowError:
        return None
