"""The paper comparison's results: what each model directory gives beside Burgos-Florez et al. (2019).

For each model directory (a ``drumflow run`` directory, or the small results shipped from one by
``studies/ship_paper_run.py``, which keeps the same layout without the dumps) this module
gathers what the paper reports and drumflow measured, as plain data (:class:`PaperRun`):

* the run's record: simulated time reached against the case's, wall time, machine;
* the methodology (Tables 6-7, Eqs. 34-55, with the paper's particle conductivity in Nu), when
  the run is long enough, else the reason;
* the mean temperature at 3.5 s (Tables 3-4) when the run got there;
* the h the coupling applied over every particle's surface, from its log
  (:func:`drumflow.analysis.published.coupling_h`), and, from the last snapshot sampled in the air
  field, the h of the bed and of the airborne particles separately
  (:mod:`drumflow.analysis.air_side`);
* the comparison rows (:func:`drumflow.analysis.published.compare_with_paper`).

:mod:`drumflow.report.paper_page` turns them into the page and its files. Nothing here starts a
solver; the only work on a run directory is reading it, and caching what it derives
(``post/methodology.json``, ``post/steps.csv``, ``post/air_side.json``, and the Figure 6
pictures drawn by :mod:`drumflow.report.snapshots` and :mod:`drumflow.report.animation`) in the
run's ``post/`` folder. A shipped directory is only read.
"""

from __future__ import annotations

import json
import os
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Literal

import pandas as pd

from drumflow._json import json_safe
from drumflow.analysis.methodology import analyse_run, write_methodology
from drumflow.analysis.methodology_result import MethodologyResult
from drumflow.analysis.published import (
    ComparisonRow,
    CouplingH,
    Model,
    compare_with_paper,
    coupling_h,
    temperature_at,
)
from drumflow.case import Case, load_case
from drumflow.errors import AnalysisInputError, BadFileError, DrumflowError, RunDirectoryError
from drumflow.readers import reaches_time, read_csv, read_json_object_if_present
from drumflow.report.animation import ANIMATION, render_animation
from drumflow.report.snapshots import render_last_snapshot, render_snapshot_panels
from drumflow.rundir import RunDir, cpu_model

__all__ = [
    "AIR_SIDE",
    "AT_S",
    "CROSSINGS_SUMMARY",
    "MODEL_DIRS",
    "PARTICLES_3D",
    "PARTICLES_TIMES",
    "RUN_RECORD",
    "PaperRun",
    "air_side_of_run",
    "collect_paper_run",
    "find_model_dirs",
    "is_shipped",
    "needs_post",
    "run_record",
]



#: The directory of each model under ``--out`` or ``--from``.
MODEL_DIRS: dict[Model, str] = {"one": "model_one", "two": "model_two"}
#: Tables 3 and 4 read the mean temperature at this time.
AT_S = 3.5
#: Derived files, cached in (or shipped with) a model directory.
RUN_RECORD = "run_record.json"
AIR_SIDE = "air_side.json"
PARTICLES_3D = "particles_3d.png"
#: Figure 6 as the paper draws it: the section at several times, coloured by temperature.
PARTICLES_TIMES = "particles_times.png"
CROSSINGS_SUMMARY = "crossings_summary.csv"


# ------------------------------------------------------------------------------ run parts


def is_shipped(root: Path) -> bool:
    """True for shipped results (a run record and no dumps), False for a run directory."""
    return (root / RUN_RECORD).is_file() and not (root / "dem" / "dumps").is_dir()


#: Columns of post/mean_temperature.csv the page reads, every value a finite number.
_SERIES_COLUMNS = ("time_s", "mean_temperature_C")
#: Columns of post/air_heat.csv the page reads (the wall times may be empty).
_AIR_HEAT_COLUMNS = ("step", "time_s", "steps", "heat_to_particles_W")


def _read_series(run: RunDir) -> pd.DataFrame:
    """post/mean_temperature.csv, checked, and refused when it ends before the run does."""
    series = read_csv(run.mean_temperature_csv, "mean particle temperature per output step",
                      columns=_SERIES_COLUMNS, finite=_SERIES_COLUMNS, min_rows=1)
    reaches_time(run.mean_temperature_csv, float(series["time_s"].iloc[-1]), run.summary_path)
    return series

def _loop_time_s(run: RunDir) -> float | None:
    """LIGGGHTS' loop time summed over every run of every attempt (first run and resumes).

    The wall time a stopped and resumed run actually computed: a span of file times would
    count the hours between two sessions. Set-up, restart reading and the coupling loop's
    Python are not in it (``drumflow profile`` has them).
    """
    from drumflow.dem.thermo import loop_time_s

    found = [t for log in run.dem_logs() if (t := loop_time_s(log.read_text(errors="replace"))) is not None]
    return sum(found) if found else None


def _coupled_wall(run: RunDir, dt: float | None) -> dict[str, Any] | None:
    from drumflow.coupling.log import coupled_wall_s, read_coupling

    if dt is None or not run.dem_coupling_logs.is_dir():
        return None
    return coupled_wall_s(read_coupling(run.dem_coupling_logs, dt))


def _resumed(run: RunDir) -> bool:
    return any(True for _ in run.dem.glob("log.resume-*.liggghts"))


def _dump_span_s(run: RunDir) -> tuple[float, float] | None:
    """(first, last) modification time of the dump files: when the DEM wrote its output."""
    if not run.dem_dumps.is_dir():
        return None
    times = [p.stat().st_mtime for p in (*run.dem_dumps.glob("*.txt"), *run.dem_dumps.glob("*.npz"))]
    return (min(times), max(times)) if times else None


def run_record(root: Path | str) -> dict[str, Any]:
    """Simulated time reached, wall times and machine of a run (or its shipped record).

    Parameters
    ----------
    root
        A run directory, or shipped results (then their ``run_record.json`` is returned).

    Returns
    -------
    dict
        ``simulated_time_s`` (reached), ``target_time_s`` (the case's ``run.time``),
        ``finished`` (the DEM stage completed), ``wall_time_s`` (the last ``drumflow run`` call,
        from ``summary.json``, or None), ``dem_wall_time_s`` and its ``dem_wall_time_source``,
        ``air_wall_time_s``, ``air_cells``, ``machine`` (platform, processes, cpus, cpu model:
        cpus and cpu are those of the machine reading the run, the run's own for a local run).
    """
    path = Path(root)
    shipped = read_json_object_if_present(path / RUN_RECORD)
    if shipped is not None and is_shipped(path):
        return shipped
    run = RunDir.existing(path)
    summary = read_json_object_if_present(run.summary_path) or {}
    case = run.manifest.get("case") or {}
    target = (case.get("run") or {}).get("time")
    simulated = summary.get("simulated_time_s")
    source = "summary.json"
    if simulated is None and run.mean_temperature_csv.is_file():
        times = read_csv(run.mean_temperature_csv, "mean particle temperature per output step",
                         columns=("time_s",), finite=("time_s",), min_rows=1)["time_s"]
        simulated, source = float(times.iloc[-1]), "post/mean_temperature.csv"
    dt = run.recorded_time_step
    if simulated is None and dt is not None:
        from drumflow.dem.dumps import dump_files

        files = dump_files(run.dem_dumps, "cross")
        if files:
            simulated = int(files[-1].name.split(".")[1]) * dt
            source = "newest dump file"
    # A long run is made of attempts (resumed after interrupts, sometimes paused): the coupling
    # logs time every update of every attempt; summary.json has only the last call.
    dem_wall, dem_source = None, ""
    coupled = _coupled_wall(run, dt)
    if coupled is not None:
        dem_wall = coupled["wall_s"]
        dem_source = "coupling updates, every attempt"
        if coupled["estimated_s"] > 0:
            dem_source += (f" ({coupled['paused_updates']} paused and {coupled['unlogged_updates']} "
                           f"unlogged updates at the others' rate: {coupled['estimated_s']:.0f} s)")
    if dem_wall is None and summary.get("dem_wall_time_s") is not None and not _resumed(run):
        dem_wall = summary["dem_wall_time_s"]
        dem_source = "summary.json (the run's one `drumflow run` call)"
    if dem_wall is None:
        dem_wall, dem_source = _loop_time_s(run), "LIGGGHTS loop time, every attempt"
    if dem_wall is None:
        span = _dump_span_s(run)
        if span is not None:
            dem_wall, dem_source = span[1] - span[0], "first to newest dump file written"
    air = run.manifest.get("air") or {}
    versions = run.manifest.get("versions") or {}
    return {
        "simulated_time_s": simulated,
        "simulated_time_source": source,
        "target_time_s": target,
        "finished": (run.stages / "dem.json").is_file(),
        "wall_time_s": summary.get("wall_time_s"),
        "dem_wall_time_s": dem_wall,
        "dem_wall_time_source": dem_source,
        "air_wall_time_s": air.get("solve_wall_time_s"),
        "air_field_cache_hit": air.get("cache_hit"),
        "air_cells": (air.get("extra") or {}).get("cells"),
        "particle_steps_per_s": summary.get("particle_steps_per_s"),
        "machine": {
            "platform": versions.get("platform"),
            "processes": run.manifest.get("processes"),
            "cpus": os.cpu_count(),
            "cpu": cpu_model(),
        },
        "versions": {k: versions.get(k) for k in ("liggghts", "openfoam", "python")},
    }


def air_side_of_run(root: Path | str) -> dict[str, Any]:
    """The h the particles of the last readable snapshot see in the run's air field.

    Returns
    -------
    dict
        :class:`~drumflow.analysis.air_side.AirSideSample` as a dict, with ``snapshot`` (file
        name) and ``field_cells``.

    Raises
    ------
    RunDirectoryError
        Without ``air/field.npz``, a recorded time step or a readable snapshot.
    """
    from drumflow.air.field import AirField
    from drumflow.analysis.air_side import sample_air_side
    from drumflow.dem.dumps import dump_files, read_dump

    run = RunDir.existing(root)
    run.require(run.case_toml, run.air_field)
    case = load_case(run.case_toml)
    dt = run.recorded_time_step
    if dt is None:
        raise RunDirectoryError(f"{run.manifest_path}: no DEM time step recorded")
    snaps = dump_files(run.dem_dumps, "snap")
    for path in reversed(snaps):
        try:
            snap = read_dump(path)  # the newest may still be being written by a live run
        except (RunDirectoryError, ValueError):
            continue
        if len(snap) == 0:
            continue
        field = AirField.from_npz(run.air_field)
        sample = sample_air_side(case, field, snap.columns, snap.step * dt)
        return {**sample.to_dict(), "snapshot": path.name, "field_cells": field.meta.get("cells")}
    raise RunDirectoryError(f"{run.dem_dumps}: no readable particle snapshot (snap.*.txt or .npz)")

@dataclass
class PaperRun:
    """What one model directory gives for the comparison.

    Attributes
    ----------
    model, root, kind
        ``"one"`` or ``"two"``; the directory; ``"run"`` or ``"shipped"``.
    case
        The run's case (None if unreadable, with a note).
    record
        :func:`run_record`.
    summary
        ``summary.json`` (None when the run has not finished or been post-processed).
    methodology
        The methodology result (particle conductivity in Nu), or None with ``notes`` saying why.
    temperature_at_s
        The mean temperature at :data:`AT_S`, or None.
    coupling
        The h of the coupling log, or None.
    air_side
        The bed and airborne h of the last snapshot, or None.
    rows
        The comparison with the paper.
    notes
        What could not be done, and why.
    """

    model: Model
    root: Path
    kind: Literal["run", "shipped"]
    case: Case | None
    record: dict[str, Any]
    summary: dict[str, Any] | None
    methodology: MethodologyResult | None
    temperature_at_s: float | None
    coupling: CouplingH | None
    air_side: dict[str, Any] | None
    rows: list[ComparisonRow]
    notes: list[str] = field(default_factory=list)

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready (``paper.json``'s entry for this model)."""
        return json_safe({
            "model": self.model,
            "path": str(self.root),
            "kind": self.kind,
            "case": self.case.name if self.case is not None else None,
            "record": self.record,
            f"mean_temperature_at_{AT_S:g}s_C": self.temperature_at_s,
            "methodology": self.methodology.to_dict() if self.methodology is not None else None,
            "coupling_h": self.coupling.to_dict() if self.coupling is not None else None,
            "air_side_last_snapshot": self.air_side,
            "comparison": [r.to_dict() for r in self.rows],
            "notes": self.notes,
        })


def find_model_dirs(root: Path | str, models: Sequence[Model]) -> dict[Model, Path]:
    """The model directories (``model_one``, ``model_two``) present under ``root``.

    Raises
    ------
    RunDirectoryError
        If ``root`` is not a directory or holds none of the requested models.
    """
    base = Path(root).resolve()
    if not base.is_dir():
        raise RunDirectoryError(f"{base}: not a directory (expected model_one/ and/or model_two/)")
    found = {m: base / MODEL_DIRS[m] for m in models if (base / MODEL_DIRS[m]).is_dir()}
    if not found:
        wanted = " or ".join(f"{MODEL_DIRS[m]}/" for m in models)
        raise RunDirectoryError(f"{base}: holds no {wanted} (run `drumflow paper` or ship a run)")
    return found


def collect_paper_run(root: Path | str, model: Model, *, render_3d: bool = True,
                      render_timeout_s: float = 300.0) -> PaperRun:
    """Everything the paper page shows for one model directory (run or shipped).

    A run directory gets its derived files cached in ``post/`` (methodology, air side, the
    Figure 6 picture); shipped results are only read. Missing parts become notes, never errors,
    except a directory that is not a run at all.

    Raises
    ------
    RunDirectoryError
        If ``root`` is not a run directory or shipped results (no case.toml, no manifest).
    """
    run = RunDir.existing(root)
    kind: Literal["run", "shipped"] = "shipped" if is_shipped(run.root) else "run"
    notes: list[str] = []
    case: Case | None = None
    try:
        case = load_case(run.case_toml)
    except DrumflowError as exc:
        notes.append(f"case not readable: {exc}")
    record = run_record(run.root)
    summary = read_json_object_if_present(run.summary_path)

    methodology: MethodologyResult | None = None
    try:
        methodology = analyse_run(run.root, nusselt_conductivity="particle")
        if kind == "run":
            write_methodology(run.root, methodology)
    except BadFileError:
        # A damaged file is refused: as a note, a cut-short series would pass as a short run.
        raise
    except DrumflowError as exc:
        # Too short, no air, no post-processing yet: the reason is part of the result.
        notes.append(f"methodology (Tables 6-8) not applied: {exc}")

    temperature: float | None = None
    series: pd.DataFrame | None = None
    if run.mean_temperature_csv.is_file():
        series = _read_series(run)
        try:
            temperature = temperature_at(series["time_s"].to_numpy(float),
                                         series["mean_temperature_C"].to_numpy(float), AT_S)
        except ValueError as exc:
            notes.append(f"Tables 3-4 (mean temperature at {AT_S:g} s): {exc}")
    else:
        notes.append(f"no {run.mean_temperature_csv.relative_to(run.root)}: the run has not been "
                     "post-processed (`drumflow post DIR`)")

    coupling: CouplingH | None = None
    if case is not None and series is not None and run.air_heat_csv.is_file():
        try:
            air_heat = read_csv(run.air_heat_csv, "the heat the air took at each coupling update",
                                columns=_AIR_HEAT_COLUMNS, finite=_AIR_HEAT_COLUMNS, min_rows=1)
            coupling = coupling_h(case, air_heat, series)
        except AnalysisInputError as exc:
            notes.append(f"h from the coupling log: {exc}")
    elif case is not None and series is not None:
        notes.append(f"no {run.air_heat_csv.relative_to(run.root)}: no coupling log (a run without air?)")

    air_side = _air_side(run, kind, notes)
    if kind == "run" and case is not None and not (run.post / PARTICLES_TIMES).is_file():
        try:
            render_snapshot_panels(run, case, run.post / PARTICLES_TIMES)
        except (DrumflowError, OSError) as exc:
            notes.append(f"Figure 6 (snapshots over time) not drawn: {exc}")
    if kind == "run" and case is not None and not (run.post / ANIMATION).is_file():
        try:
            render_animation(run, case, run.post / ANIMATION)
        except (DrumflowError, OSError) as exc:
            notes.append(f"Figure 6 in motion (animation) not drawn: {exc}")
    if kind == "run" and render_3d and case is not None:
        target = run.post / PARTICLES_3D
        if not target.is_file():
            try:
                render_last_snapshot(run, case, target, render_timeout_s)
            except (DrumflowError, OSError) as exc:
                notes.append(f"Figure 6 not rendered: {exc}")

    rows = compare_with_paper(
        model, methodology.to_dict() if methodology is not None else None, temperature,
        coupling_h_w_m2k=coupling.h_run_w_m2k if coupling is not None else None)
    return PaperRun(model=model, root=run.root, kind=kind, case=case, record=record,
                    summary=summary, methodology=methodology, temperature_at_s=temperature,
                    coupling=coupling, air_side=air_side, rows=rows, notes=notes)


def needs_post(root: Path | str) -> bool:
    """Whether a run directory's dumps are newer than its ``post/`` tables.

    An interrupted or still running run has dumps but no (or old) ``post/mean_temperature.csv``;
    :func:`drumflow.pipeline.post_run` writes them (the caller runs it: the report stage does
    not import the pipeline). Shipped results and finished runs need nothing.
    """
    path = Path(root)
    if is_shipped(path):
        return False
    run = RunDir.existing(path)
    dumps = ([*run.dem_dumps.glob("*.txt"), *run.dem_dumps.glob("*.npz")]
             if run.dem_dumps.is_dir() else [])
    if not dumps or not run.dem_log.is_file():
        return False
    newest = max(p.stat().st_mtime for p in dumps)
    csv_path = run.mean_temperature_csv
    return not (csv_path.is_file() and csv_path.stat().st_mtime >= newest)


def _air_side(run: RunDir, kind: str, notes: list[str]) -> dict[str, Any] | None:
    cached = run.post / AIR_SIDE
    data = read_json_object_if_present(cached)
    if data is not None:
        return data
    if kind == "shipped":
        notes.append(f"no {cached.relative_to(run.root)} in the shipped results: bed and airborne "
                     "h not available")
        return None
    try:
        data = air_side_of_run(run.root)
    except DrumflowError as exc:
        notes.append(f"bed and airborne h (last snapshot): {exc}")
        return None
    cached.parent.mkdir(parents=True, exist_ok=True)
    cached.write_text(json.dumps(json_safe(data), indent=2, allow_nan=False))
    return data
