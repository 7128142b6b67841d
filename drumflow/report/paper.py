"""The paper page: drumflow's runs of the paper's two cases beside Burgos-Florez et al. (2019).

For each model directory (a ``drumflow run`` directory, or the small results shipped from one by
``studies/ship_paper_run.py``, which keeps the same layout without the dumps) this module
gathers what the paper reports and drumflow measured:

* the run's record: simulated time reached against the case's, wall time, machine;
* the methodology (Tables 6-7, Eqs. 34-55, with the paper's particle conductivity in Nu), when
  the run is long enough, else the reason;
* the mean temperature at 3.5 s (Tables 3-4) when the run got there;
* the h the coupling applied over every particle's surface, from its log
  (:func:`drumflow.analysis.paper.coupling_h`), and, from the last snapshot sampled in the air
  field, the h of the bed and of the airborne particles separately
  (:mod:`drumflow.analysis.air_side`);
* the comparison rows (:func:`drumflow.analysis.paper.compare_with_paper`);

and writes ``paper.json``, ``comparison.csv`` and one self-contained HTML page (Tables 3-8 as
paper | drumflow | difference, Figures 4 and 6-9), built from the pieces of
:mod:`drumflow.report.html`. Nothing here starts a solver; the only work on a run directory is
reading it, and caching what it derives (``post/methodology.json``, ``post/steps.csv``,
``post/air_side.json``, ``post/particles_3d.png``) in the run's ``post/`` folder. A shipped
directory is only read.
"""

from __future__ import annotations

import csv
import json
import math
import os
import time
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Literal

import numpy as np
import pandas as pd

from drumflow._json import json_safe
from drumflow.analysis.air_side import lumped_mean_temperature
from drumflow.analysis.correlation import NusseltCorrelation
from drumflow.analysis.methodology import (
    MethodologyResult,
    analyse_run,
    fit_runs,
    write_methodology,
)
from drumflow.analysis.paper import (
    EQ58,
    PAPER_MODELS,
    PAPER_PARTICLE_CONDUCTIVITY,
    ComparisonRow,
    CouplingH,
    Model,
    compare_with_paper,
    coupling_h,
    reynolds_conversion,
    temperature_at,
)
from drumflow.case import Case, load_case
from drumflow.coupling.physics import AirState, ranz_marshall_slip
from drumflow.errors import AnalysisInputError, BadFileError, DrumflowError, RunDirectoryError
from drumflow.readers import reaches_time, read_csv, read_json_object
from drumflow.report.animation import ANIMATION, render_animation
from drumflow.report.html import (
    _fig_uri,
    _Figure,
    _file_uri,
    _fmt,
    _h_figure,
    _Table,
    _table8,
)
from drumflow.rundir import RunDir, cpu_model

__all__ = [
    "AT_S",
    "MODEL_DIRS",
    "PaperRun",
    "air_side_of_run",
    "collect_paper_run",
    "find_model_dirs",
    "needs_post",
    "render_last_snapshot",
    "run_record",
    "write_paper",
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


def _read_json(path: Path) -> dict[str, Any] | None:
    """A JSON object of the run, or None when the file is missing; a damaged one (cut short,
    not UTF-8, not an object) is refused by name: dropping it would redraw the page without
    it, and without a word."""
    if not path.exists():
        return None
    return read_json_object(path)


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


def _time_step(run: RunDir) -> float | None:
    value = (run.manifest.get("time_step") or {}).get("time_step")
    return float(value) if value else None


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
    shipped = _read_json(path / RUN_RECORD)
    if shipped is not None and is_shipped(path):
        return shipped
    run = RunDir.existing(path)
    summary = _read_json(run.summary_path) or {}
    case = run.manifest.get("case") or {}
    target = (case.get("run") or {}).get("time")
    simulated = summary.get("simulated_time_s")
    source = "summary.json"
    if simulated is None and run.mean_temperature_csv.is_file():
        times = read_csv(run.mean_temperature_csv, "mean particle temperature per output step",
                         columns=("time_s",), finite=("time_s",), min_rows=1)["time_s"]
        simulated, source = float(times.iloc[-1]), "post/mean_temperature.csv"
    dt = _time_step(run)
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
    dt = _time_step(run)
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


def render_last_snapshot(run: RunDir, case: Case, target: Path, timeout_s: float) -> Path:
    """Figure 6: the last snapshot coloured by temperature (PyVista, in a child process)."""
    from drumflow.dem.dumps import dump_files, read_dump
    from drumflow.report.render import render_particles_isolated

    dt = _time_step(run)
    for path in reversed(dump_files(run.dem_dumps, "snap")):
        try:
            snap = read_dump(path)
        except (RunDirectoryError, ValueError):
            continue
        c = snap.columns
        when = f"t = {snap.step * dt:.3g} s" if dt else f"step {snap.step}"
        target.parent.mkdir(parents=True, exist_ok=True)
        return render_particles_isolated(
            c["x"], c["y"], c["z"], c["T"], target, case.drum.radius, case.drum.length,
            particle_diameter=case.particles.diameter, title=f"{case.name}, {when}",
            timeout_s=timeout_s)
    raise RunDirectoryError(f"{run.dem_dumps}: no readable particle snapshot (snap.*.txt or .npz)")


def render_snapshot_panels(run: RunDir, case: Case, target: Path, panels: int = 4) -> Path:
    """Figure 6 at several times: the cross-section (x-y) of up to ``panels`` snapshots.

    The snapshots are spread evenly over those written (first and last always), drawn with one
    colour scale so that the cooling from panel to panel is visible, and the drum shell drawn
    for scale. Matplotlib only (no rendering process): a few seconds for 300k particles.

    Raises
    ------
    RunDirectoryError
        When the run has no readable snapshot.
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from drumflow.dem.dumps import dump_files, read_dump

    files = dump_files(run.dem_dumps, "snap")
    if not files:
        raise RunDirectoryError(f"{run.dem_dumps}: no particle snapshot (snap.*.txt or .npz)")
    picks = sorted({round(i) for i in np.linspace(0, len(files) - 1, min(panels, len(files)))})
    snaps = []
    for i in picks:
        try:
            snaps.append(read_dump(files[i]))
        except (RunDirectoryError, ValueError):
            continue
    if not snaps:
        raise RunDirectoryError(f"{run.dem_dumps}: no readable particle snapshot")
    dt = _time_step(run)
    t_lo = min(float(np.min(s.columns["T"])) for s in snaps)
    t_hi = max(float(np.max(s.columns["T"])) for s in snaps)
    if not t_hi > t_lo:
        t_hi = t_lo + 0.1
    r = case.drum.radius
    fig, axes = plt.subplots(1, len(snaps), figsize=(3.2 * len(snaps) + 0.8, 3.6), squeeze=False)
    art = None
    for ax, snap in zip(axes[0], snaps, strict=True):
        c = snap.columns
        # Marker area from the particle size in points, so the bed looks like a bed at any scale.
        size = (72.0 * 3.2 * case.particles.diameter / (2.2 * r)) ** 2
        art = ax.scatter(c["x"], c["y"], c=c["T"], s=size, cmap="inferno", vmin=t_lo, vmax=t_hi,
                         linewidths=0, rasterized=True)
        ax.add_patch(plt.Circle((0.0, 0.0), r, fill=False, lw=0.8, color="0.3"))
        ax.set_xlim(-1.05 * r, 1.05 * r)
        ax.set_ylim(-1.05 * r, 1.05 * r)
        ax.set_aspect("equal")
        ax.set_xticks([])
        ax.set_yticks([])
        when = f"t = {snap.step * dt:.2f} s" if dt else f"step {snap.step}"
        ax.set_title(f"{when}\nmean {float(np.mean(c['T'])):.2f} °C", fontsize=9)
    assert art is not None
    fig.colorbar(art, ax=list(axes[0]), shrink=0.8, label="particle temperature (°C)")
    fig.suptitle(f"{case.name}: the section seen along the drum axis, coloured by temperature",
                 fontsize=10)
    target.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(target, dpi=110, bbox_inches="tight")
    plt.close(fig)
    return target


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
    summary = _read_json(run.summary_path)

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
    data = _read_json(cached)
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


# ------------------------------------------------------------------------------ the page


def _anchor(model: str) -> str:
    return f"model-{model}"


def _comparison_table(run: PaperRun) -> _Table:
    rows = [[r.quantity, r.source, _fmt(r.paper), _fmt(r.drumflow), _fmt(r.difference),
             f"{r.relative:+.1%}" if math.isfinite(r.relative) else "–", r.unit] for r in run.rows]
    return _Table(f"Model {run.model}: the paper's Tables 4, 6 and 7 beside drumflow",
                  ["quantity", "paper's source", "paper", "drumflow", "difference", "relative",
                   "unit"], rows,
                  "difference = drumflow - paper. Re: the paper's value converted to drumflow's "
                  "definition (see the top of the page).")


def _duration(seconds: Any) -> str:
    if not isinstance(seconds, (int, float)) or not math.isfinite(seconds):
        return "–"
    return f"{seconds:,.0f} s ({seconds / 3600:.2f} h)"


def _record_table(run: PaperRun) -> _Table:
    r = run.record
    m = r.get("machine") or {}
    target = r.get("target_time_s")
    sim = r.get("simulated_time_s")
    reached = (f"{_fmt(sim)} of {_fmt(target)} s"
               + (f" ({sim / target:.0%})" if isinstance(sim, (int, float)) and target else ""))
    rows = [
        ["simulated time reached", reached + ("" if r.get("finished") else ", not finished")],
        ["wall time of the last `drumflow run` call", _duration(r.get("wall_time_s"))],
        [f"DEM wall time ({r.get('dem_wall_time_source', '')})", _duration(r.get("dem_wall_time_s"))],
        ["air stage wall time (OpenFOAM)" + (", field from the cache" if r.get("air_field_cache_hit")
                                             else ""), _duration(r.get("air_wall_time_s"))],
        ["air cells (paper's mesh 2: "
         f"{PAPER_MODELS[run.model].air_cells:,})", _fmt(r.get("air_cells"))],
        ["particle-steps per second", _fmt(r.get("particle_steps_per_s"))],
        ["machine", f"{m.get('cpu', '?')}, {m.get('cpus', '?')} cpus; {m.get('platform', '?')}"],
        ["MPI processes", _fmt(m.get("processes"))],
    ]
    if run.case is not None:
        rows.insert(0, ["case", f"{run.case.name}: {run.case.particle_count:,} particles of "
                        f"{run.case.particles.diameter * 1e3:g} mm, section {run.case.drum.length:g} m"])
        moved = run.case.dem_case()
        if moved is not run.case:
            # A coarse-grained run answers a sweep's question, not the paper's at 1 %: say so.
            rows.insert(1, ["coarse-grained (particles.coarse_grain)",
                            f"the DEM moved {moved.particle_count:,} parcels of "
                            f"{moved.particles.diameter * 1e3:g} mm ({run.case.particles.coarse_grain:g} "
                            "particle diameters), drag and heat per kg kept; on model two parcels of 2 "
                            "diameters kept the heat answer to 0.3 % and the falling mass flow to about 3 %"])
    return _Table(f"Model {run.model}: the run", ["quantity", "value"], rows)


def _h_table(run: PaperRun) -> _Table:
    paper = PAPER_MODELS[run.model]
    rows: list[list[str]] = [["paper, Table 6 (Eq. 39)", _fmt(paper.h_w_m2k), ""]]
    if run.methodology is not None:
        rows.append(["drumflow, Eq. 39 from the mean temperature (Table 6)",
                     _fmt(run.methodology.h_mean_w_m2k),
                     f"time average over {run.methodology.n_valid:,} steps"])
    if run.coupling is not None:
        rows.append(["drumflow, coupling log: heat / (all particle surface × (T_p − T_air))",
                     _fmt(run.coupling.h_run_w_m2k),
                     f"{run.coupling.updates:,} updates over {run.coupling.time_s:.3g} s"])
    a = run.air_side
    if a is not None:
        share = a.get("airborne_heat_share")
        rows += [
            ["last snapshot: all particles (surface mean, Ranz-Marshall)", _fmt(a.get("h_mean_w_m2k")),
             f"{a.get('snapshot')}, t = {_fmt(a.get('time_s'), 4)} s"],
            ["last snapshot: bed", _fmt(a.get("h_bed_w_m2k")),
             f"slip {_fmt(a.get('slip_bed_m_s'), 3)} m/s"],
            ["last snapshot: airborne (falling)", _fmt(a.get("h_airborne_w_m2k")),
             f"{_fmt(a.get('airborne'))} particles, slip {_fmt(a.get('slip_airborne_m_s'), 3)} m/s, "
             + (f"{share:.1%} of the heat" if isinstance(share, (int, float)) else "")],
        ]
    if run.case is not None:
        # What air speed the paper's h needs in the correlation drumflow applies (Eq. 23), to
        # set beside the slip the particles see: the measured source of the h difference.
        air = AirState.at(run.case.air.inlet_temperature_C, run.case.air.pressure_kPa)
        slip = ranz_marshall_slip(paper.h_w_m2k, run.case.particles.diameter, air)
        seen = a.get("slip_mean_m_s") if a is not None else None
        rows.append(["slip speed the paper's h needs in Ranz-Marshall (Eq. 23), m/s", _fmt(slip, 3),
                     f"the particles see {_fmt(seen, 3)} m/s (last snapshot, mean)"
                     if isinstance(seen, (int, float)) else ""])
    if run.case is not None and run.methodology is not None:
        surface = run.case.particle_count * math.pi * run.case.particles.diameter**2
        rows += [
            ["surface h acts on in the slice: every particle, N π Dp² (m²)", _fmt(surface), ""],
            ["surface Eq. 46 gives h per second: A_fp / dt (m²/s)",
             _fmt(run.methodology.falling_area_m2 / run.methodology.dt_s), "the falling particles"],
        ]
    return _Table(f"Model {run.model}: what h is (W/(m² K))", ["h", "value", ""], rows,
                  "Eq. 39 with Eqs. 35 and 41 is rho Dp cp (−dT/dt) / (6 LMTD): the falling mass "
                  "cancels, so the paper's h is the lumped coefficient over the surface of every "
                  "particle of the slice, the same number the coupling log gives. Eq. 46 then "
                  "applies it only to the surface falling per second.")


def _temperature_figure(run: PaperRun) -> _Figure:
    paper = PAPER_MODELS[run.model]
    number = {"one": "7", "two": "8"}[run.model]
    fig = _Figure(f"Mean particle temperature (Figure {number}; Tables 3-4 at {AT_S:g} s)")
    csv_path = run.root / "post" / "mean_temperature.csv"
    try:
        table = pd.read_csv(csv_path)
        t = table["time_s"].to_numpy(float)
        temp = table["mean_temperature_C"].to_numpy(float)
    except (OSError, ValueError, KeyError) as exc:
        fig.note = f"no mean temperature: {csv_path} could not be read ({exc})"
        return fig
    case = run.case
    t_end = max(float(t[-1]), AT_S)
    grid = np.linspace(0.0, t_end, 200)

    def draw(ax: Any) -> None:
        ax.plot(t, temp, color="tab:red", lw=1.8, label="drumflow")
        if case is not None:
            lumped = lumped_mean_temperature(case, paper.h_w_m2k, grid[1:])
            ax.plot(grid[1:], lumped, color="0.4", lw=1.2, ls="--",
                    label=f"every particle at the paper's h = {paper.h_w_m2k:g} W/(m² K)")
        for value, label, marker in (
            (paper.mean_temperature_3p5s_mesh1_C, "paper, mesh 1", "v"),
            (paper.mean_temperature_3p5s_C, "paper, mesh 2 (chosen)", "o"),
            (paper.mean_temperature_3p5s_mesh3_C, "paper, mesh 3", "^"),
        ):
            ax.plot([AT_S], [value], marker, color="black", ms=6, mfc="none" if "chosen" not in label
                    else "black", label=f"{label}: {value:g} °C")
        ax.set_xlabel("time (s)")
        ax.set_ylabel("mean particle temperature (°C)")
        ax.legend(fontsize=8)
        ax.grid(alpha=0.3)

    fig.uri = _fig_uri(draw)
    fig.caption = (f"from {csv_path.name}; the dashed curve is the lumped cooling of every particle "
                   "at the paper's h (what its Eq. 39 means), the markers Table 4's three meshes")
    return fig


def _run_tables_and_figures(run: PaperRun) -> tuple[list[_Table], list[_Figure]]:
    tables = [_record_table(run), _comparison_table(run), _h_table(run)]
    figures = [_temperature_figure(run)]
    if run.methodology is not None:
        figures.append(_h_figure(run.methodology))
    crossings = _Figure("Particles crossing the axis plane downwards (Figure 4)",
                        uri=_file_uri(run.root / "post" / "crossings.png"))
    if crossings.uri is None:
        crossings.note = "no post/crossings.png"
    figures.append(crossings)
    particles = _Figure("Particles coloured by temperature, last snapshot (Figure 6)",
                        uri=_file_uri(run.root / "post" / PARTICLES_3D))
    if particles.uri is None:
        particles.note = f"no post/{PARTICLES_3D} (3-D rendering off, failed, or not shipped)"
    figures.append(particles)
    over_time = _Figure("The section at several times, coloured by temperature (Figure 6)",
                        uri=_file_uri(run.root / "post" / PARTICLES_TIMES))
    if over_time.uri is None:
        over_time.note = f"no post/{PARTICLES_TIMES} (no snapshot, or not shipped)"
    figures.append(over_time)
    motion = _Figure("Figure 6 in motion: the section at every snapshot, coloured by temperature",
                     uri=_file_uri(run.root / "post" / ANIMATION))
    if motion.uri is None:
        motion.note = f"no post/{ANIMATION} (no snapshot, or not shipped)"
    figures.append(motion)
    air = _file_uri(run.root / "air" / "air_cross_section.png")
    if air is not None:
        figures.append(_Figure("Air field, cross-section", uri=air))
    return tables, figures


def _reynolds_table() -> _Table:
    conv = reynolds_conversion()
    rows = []
    for model, v in conv.per_model.items():
        rows.append([f"model {model}", _fmt(v["re_paper"]), _fmt(v["re_drumflow"]),
                     f"{v['ratio']:.4f}", _fmt(v["v_ai_m_s"], 4), _fmt(v["void_fraction"], 4),
                     _fmt(v["v_max_drumflow_m_s"], 4), _fmt(v["v_max_paper_implied_m_s"], 4)])
    return _Table(
        "Reynolds number: the paper's and drumflow's definitions (Eqs. 51-54)",
        ["", "Re, paper", "Re, drumflow", "ratio", "V_ai (m/s)", "Vf", "v_max drumflow (m/s)",
         "v_max implied by the paper (m/s)"], rows,
        f"One factor {conv.factor:.4f} fits both models to {conv.factor_spread:.2%}: a definition, "
        "not physics. drumflow compares in its own definition; the paper's Re range and Eq. 58 are "
        f"converted (range / {conv.factor:.4f}; a × {conv.factor:.4f}^b × {conv.prandtl_factor:.4f}^c, "
        "the last factor for the paper's Pr table, 0.7282 against drumflow's 0.7066 at 30 °C).")


def _reading() -> list[str]:
    return [
        "Eq. 39 with Eqs. 35 and 41 put in is h = ρ Dp cp (−dT/dt) / (6 LMTD): the falling mass "
        "cancels. The paper's h is therefore the lumped coefficient over the surface of every "
        "particle of the slice, bed and curtain, because its one-way air acts on all of them; "
        "Eq. 46 then applies that h only to the surface falling per second. The coupling log "
        "gives the same coefficient directly (each model's 'what h is' table).",
        "drumflow's Re (Eqs. 51-54 with the whole cross-section and the void factor) is 1.667 "
        "times smaller than the paper's for both models (table below). Every Re on this page is "
        "drumflow's; the paper's are converted.",
        "Table 8's ANOVA counts every time step as an independent observation. Consecutive steps "
        "are not independent: the residuals' lag-1 autocorrelation gives an effective sample "
        "size and wider errors, shown beside the paper-style table.",
    ]


def _figure9(runs: Sequence[PaperRun], corr: NusseltCorrelation | None) -> _Figure:
    from drumflow.analysis.predict import paper_correlation

    fig = _Figure("Nusselt against Reynolds, drumflow's definition (Figure 9)")
    eq58 = paper_correlation()
    conv = reynolds_conversion()
    analysed = [r for r in runs if r.methodology is not None]

    def draw(ax: Any) -> None:
        pr = eq58.prandtl_range[0]
        lo, hi = eq58.reynolds_range
        grid = np.geomspace(lo, hi, 100)
        ax.plot(grid, eq58.predict(grid, pr, warn=False), color="black", lw=1.4,
                label=f"paper's Eq. 58, converted (Re {lo:.0f}-{hi:.0f})")
        for (model, v), marker in zip(conv.per_model.items(), ("s", "D"), strict=True):
            paper = PAPER_MODELS[model]  # type: ignore[index]
            ax.plot([v["re_drumflow"]], [paper.h_w_m2k * paper.particle_diameter_m
                                         / PAPER_PARTICLE_CONDUCTIVITY], marker, color="black",
                    mfc="none", ms=8, label=f"paper, model {model} (Table 6 h)")
        for r in analysed:
            assert r.methodology is not None
            ok = np.isfinite(r.methodology.nusselt) & (r.methodology.nusselt > 0)
            ax.plot(r.methodology.reynolds[ok], r.methodology.nusselt[ok], ".", ms=3, alpha=0.6,
                    label=f"drumflow, model {r.model} (per step)")
        if corr is not None:
            re_all = np.concatenate([r.methodology.reynolds for r in analysed  # type: ignore[union-attr]
                                     if r.methodology is not None])
            re_all = re_all[np.isfinite(re_all)]
            g = np.geomspace(re_all.min(), re_all.max(), 100)
            ax.plot(g, corr.a * g**corr.b * pr**corr.c, color="tab:red", lw=1.2,
                    label=f"drumflow fit: Nu = {corr.a:.4g} Re^{corr.b:.4g} Pr^{corr.c:.4g}")
        lines = [ln.get_xdata() for ln in ax.get_lines()]
        xs = np.concatenate([np.asarray(x, float) for x in lines])
        if xs.size and xs.max() > 10 * xs.min() > 0:
            from matplotlib.ticker import FuncFormatter

            ax.set_xscale("log")
            ax.set_yscale("log")
            # Nu spans less than a decade: plain labels on the minor ticks too, not "3 x 10^0".
            plain = FuncFormatter(lambda v, _: f"{v:g}")
            ax.yaxis.set_major_formatter(plain)
            ax.yaxis.set_minor_formatter(plain)
        else:
            # The paper's range spans less than a decade: a log axis would have no labelled tick.
            ax.ticklabel_format(useOffset=False, style="plain")
        ax.set_xlabel("Re (drumflow's Eqs. 51-54)")
        ax.set_ylabel("Nu = h Dp / k_m (particle conductivity, as the paper)")
        ax.legend(fontsize=7)
        ax.grid(alpha=0.3, which="both")

    fig.uri = _fig_uri(draw, size=(6.4, 4.2))
    fig.caption = ("per-step values of the valid steps; the paper's curve is drawn at drumflow's "
                   "Pr of air at 30 °C, which is its Pr = 0.7282 in the paper's property table")
    if not analysed:
        fig.caption += "; no drumflow run could be analysed yet"
    return fig


def _table8_beside_paper(corr: NusseltCorrelation) -> _Table:
    from drumflow.analysis.predict import paper_correlation

    t = corr.anova
    rows = [
        ["a", f"{EQ58['a']:.6g} (in drumflow's Re and Pr: {paper_correlation().a:.6g})",
         _fmt(corr.a, 6)],
        ["b", _fmt(EQ58["b"], 6), _fmt(corr.b, 6)],
        ["c" + ("" if corr.prandtl_exponent_fitted else " (fixed in drumflow's fit)"),
         _fmt(EQ58["c"], 6), _fmt(corr.c, 6)],
        ["observations (time steps)", _fmt(int(EQ58["observations"])), _fmt(corr.n)],
        ["error degrees of freedom", "4,799", _fmt(t.df_error)],
        ["error sum of squares", "4.05118", _fmt(t.ss_error, 6)],
        ["adjusted R² (%)", _fmt(100 * EQ58["adjusted_r2"], 6), _fmt(100 * corr.adjusted_r_squared, 6)],
    ]
    if corr.serial is not None:
        rows.append(["effective observations (serial correlation)", "–",
                     _fmt(corr.serial.n_effective, 4)])
    return _Table("Table 8 beside the paper", ["", "paper", "drumflow"], rows,
                  "The paper's a is for its own Re and Pr; the value in brackets is the same "
                  "correlation in drumflow's definitions, the one comparable with drumflow's a.")


def build_page(runs: Sequence[PaperRun], source: str) -> tuple[str, dict[str, Any]]:
    """The HTML page and the ``paper.json`` content for some model results."""
    from jinja2 import Environment, PackageLoader, StrictUndefined

    import drumflow

    analysed = [r.methodology for r in runs if r.methodology is not None]
    corr: NusseltCorrelation | None = None
    no_fit = ""
    if len(analysed) < 2:
        no_fit = ("it needs both models analysed (within one run Re changes only through the air "
                  f"viscosity); {len(analysed)} of 2 are")
    else:
        try:
            corr = fit_runs(analysed, nusselt_conductivity="particle")
        except AnalysisInputError as exc:
            no_fit = f"the correlation could not be fitted: {exc}"
    views = []
    for run in runs:
        tables, figures = _run_tables_and_figures(run)
        views.append({"model": run.model, "anchor": _anchor(run.model), "path": str(run.root),
                      "kind": "a drumflow run directory" if run.kind == "run"
                      else "shipped results, no dumps",
                      "name": run.case.name if run.case is not None else run.root.name,
                      "notes": run.notes, "tables": tables, "figures": figures})
    env = Environment(loader=PackageLoader("drumflow.report", "templates"), autoescape=True,
                      undefined=StrictUndefined, trim_blocks=True, lstrip_blocks=True)
    html = env.get_template("paper.html.j2").render(
        title="drumflow: the paper's two cases",
        version=drumflow.__version__,
        generated=time.strftime("%Y-%m-%d %H:%M:%S %z"),
        source=source,
        notes=[],
        runs=views,
        reading=_reading(),
        reynolds=_reynolds_table(),
        table8=([_table8_beside_paper(corr), *_table8(corr)] if corr is not None else None),
        no_fit=no_fit,
        figure9=_figure9(runs, corr),
    )
    data = json_safe({
        "generated": time.strftime("%Y-%m-%dT%H:%M:%S%z"),
        "drumflow_version": drumflow.__version__,
        "source": source,
        "reynolds_conversion": reynolds_conversion().to_dict(),
        "models": {r.model: r.to_dict() for r in runs},
        "table8": _correlation_dict(corr) if corr is not None else {"not_fitted": no_fit},
    })
    return html, data


def _correlation_dict(corr: NusseltCorrelation) -> dict[str, Any]:
    from dataclasses import asdict

    return asdict(corr)


def write_paper(runs: Sequence[PaperRun], out_dir: Path | str, html_path: Path | str | None = None,
                *, source: str = "") -> dict[str, Path]:
    """Write ``paper.json``, ``comparison.csv`` and the HTML page.

    Parameters
    ----------
    runs
        The model results (:func:`collect_paper_run`), at least one.
    out_dir
        Folder of ``paper.json`` and ``comparison.csv`` (created if missing).
    html_path
        The page (default ``out_dir/paper.html``).
    source
        Where the results came from, printed on the page.

    Returns
    -------
    dict
        ``{"json": ..., "csv": ..., "html": ...}`` (absolute paths).

    Raises
    ------
    RunDirectoryError
        If ``runs`` is empty.
    """
    if not runs:
        raise RunDirectoryError("no model directory to compare with the paper")
    out = Path(out_dir).resolve()
    out.mkdir(parents=True, exist_ok=True)
    page = Path(html_path).resolve() if html_path is not None else out / "paper.html"
    html, data = build_page(runs, source)
    json_path = out / "paper.json"
    json_path.write_text(json.dumps(data, indent=2, allow_nan=False) + "\n")
    csv_path = out / "comparison.csv"
    with csv_path.open("w", newline="") as fh:
        writer = csv.writer(fh)
        writer.writerow(["model", "quantity", "source", "paper", "drumflow", "difference",
                         "relative", "unit"])
        for run in runs:
            for r in run.rows:
                writer.writerow([run.model, r.quantity, r.source, f"{r.paper:.10g}",
                                 f"{r.drumflow:.10g}", f"{r.difference:.10g}",
                                 f"{r.relative:.10g}", r.unit])
    page.parent.mkdir(parents=True, exist_ok=True)
    page.write_text(html, encoding="utf-8")
    return {"json": json_path, "csv": csv_path, "html": page}
