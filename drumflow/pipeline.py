"""The pipeline: case -> geometry -> DEM -> (air) -> observables -> summary and plots.

:func:`run_case` runs every stage into a run directory, skipping finished ones;
:func:`post_run` recomputes the observables and plots from the saved dumps, with no solver.
"""

from __future__ import annotations

import json
import time
from dataclasses import asdict
from pathlib import Path
from typing import Any

import numpy as np

from drumflow.analysis.observables import (
    crossings_from_rows,
    escaped_particles,
    falling_mass_flow,
    falling_mass_per_interval,
    mean_temperature,
)
from drumflow.case import Case, case_to_toml, load_case
from drumflow.dem import ProgressCallback, run_dem
from drumflow.dem.dumps import read_rows, read_series
from drumflow.dem.thermo import read_thermo
from drumflow.errors import CaseError, RunDirectoryError
from drumflow.geometry import build_geometry
from drumflow.report.plots import plot_crossings, plot_mean_temperature, plot_particles
from drumflow.rundir import RunDir
from drumflow.runner import LaunchProfile, Runner

__all__ = ["run_case", "post_run", "refuse_unavailable"]


def refuse_unavailable(case: Case) -> None:
    """Raise :class:`CaseError` for features the case asks for that this version lacks."""
    if case.air.model != "none":
        # Say so before any solver starts, rather than silently run without air.
        raise CaseError(
            [
                f"air.model = {case.air.model!r}: the air field is not available in this "
                "version of drumflow; allowed: 'none'"
            ]
        )


def run_case(
    case: Case,
    out: Path | str,
    processes: int | None = None,
    steps: int | None = None,
    timeout: float | None = None,
    progress: ProgressCallback | None = None,
    force: bool = False,
    profile: LaunchProfile | None = None,
) -> dict[str, Any]:
    """Run a case end to end into ``out`` and return its summary.

    Parameters
    ----------
    case
        The validated case.
    out
        Run directory; a second call with the same case reuses finished stages and resumes an
        interrupted DEM run from its newest restart file.
    processes
        MPI processes (overrides ``run.processes``).
    steps
        Only this many DEM steps (start-up check of a large case); no observables.
    timeout
        Wall-clock limit for the DEM solver, s.
    progress
        ``progress(stage, done, total)`` callback.
    force
        Allow reusing a directory that holds another case's run.
    """
    if processes is not None and processes != case.run.processes:
        data = case.model_dump(mode="json")
        data["run"]["processes"] = processes
        case = Case.model_validate(data)
    refuse_unavailable(case)
    rundir = RunDir(out)
    rundir.bind_case(case.canonical_json(), case.hash(), case_to_toml(case), force=force)
    runner = Runner(profile)
    t0 = time.perf_counter()
    geometry = build_geometry(case, rundir)
    if progress:
        progress("geometry", 1.0, 1.0)
    dem = run_dem(case, rundir, runner, geometry, progress=progress, steps=steps, timeout=timeout)
    if steps is not None:
        summary = {
            "case": case.name,
            "short_run_steps": steps,
            "particles_initial": dem.particles_initial,
            "particles_final": dem.particles_final,
            "wall_time_s": time.perf_counter() - t0,
            "dem": asdict(dem),
        }
        rundir.summary_path.write_text(json.dumps(summary, indent=2))
        return summary
    summary = post_run(rundir.root, case=case)
    summary["wall_time_s"] = time.perf_counter() - t0
    summary["dem_wall_time_s"] = dem.wall_time_s
    summary["particle_steps_per_s"] = dem.particle_steps_per_s
    rundir.summary_path.write_text(json.dumps(summary, indent=2))
    rundir.record("summary", summary)
    return summary


def post_run(out: Path | str, case: Case | None = None) -> dict[str, Any]:
    """Recompute observables, tables and plots from a run directory's dumps (no solver).

    Raises
    ------
    RunDirectoryError
        When the directory lacks the case or the dumps.
    """
    root = Path(out).resolve()
    rundir = RunDir(root)
    rundir.require("case.toml", "dem/dumps", "dem/log.liggghts")
    if case is None:
        case = load_case(root / "case.toml")
    ts = rundir.manifest.get("time_step", {}).get("time_step")
    if ts is None:
        raise RunDirectoryError(f"{root}/manifest.json: no DEM time step recorded; rerun the case")
    t0 = time.perf_counter()
    dumps = rundir.dem / "dumps"
    thermo = read_thermo(rundir.dem)
    if thermo.empty:
        raise RunDirectoryError(f"{rundir.dem}: no LIGGGHTS thermo output (log.liggghts)")
    times = thermo["step"].to_numpy() * float(ts)
    T_mean = thermo["T_mean"].to_numpy()
    rows = read_rows(dumps, float(ts), prefix="cross")
    snaps = read_series(dumps, float(ts), prefix="snap")
    read_s = time.perf_counter() - t0
    mass = case.particles.mass
    crossings = crossings_from_rows(rows.times, rows.frame, rows.ids, rows["x"], rows["y"], rows["z"])
    curtain_r = case.drum.radius - case.lifters.base_height
    flow = falling_mass_flow(crossings, mass, start=case.run.mass_flow_start, curtain_radius=curtain_r)
    per_step = falling_mass_per_interval(crossings, times, mass)
    escaped = escaped_particles(snaps["x"], snaps["y"], case.drum.radius, case.particles.radius)
    # Two independent routes to the mean temperature must agree: LIGGGHTS' reduction at every
    # output step, and drumflow's own mass-weighted mean of the full snapshots.
    T_snap = mean_temperature(snaps["T"], mass)
    at = np.searchsorted(thermo["step"].to_numpy(), snaps.steps)
    ok = (at < len(thermo)) & (thermo["step"].to_numpy()[np.minimum(at, len(thermo) - 1)] == snaps.steps)
    mean_check = float(np.max(np.abs(T_snap[ok] - T_mean[at[ok]]))) if ok.any() else float("nan")

    post = rundir.post
    post.mkdir(parents=True, exist_ok=True)
    crossings.to_csv(post / "crossings.csv", index=False, float_format="%.6g")
    np.savetxt(
        post / "mean_temperature.csv",
        np.column_stack([times, T_mean, thermo["atoms"].to_numpy(), np.r_[np.nan, per_step]]),
        delimiter=",",
        header="time_s,mean_temperature_C,particles,falling_mass_kg_in_step",
        comments="",
        fmt="%.10g",
    )
    title = f"{case.name}: {case.particle_count:,} particles of {case.particles.diameter * 1e3:g} mm"
    plot_mean_temperature(times, T_mean, post / "mean_temperature.png", title)
    plot_crossings(crossings, flow, case.drum.length, post / "crossings.png", title)
    plot_particles(snaps["x"][-1], snaps["y"][-1], snaps["T"][-1], case,
                   post / "particles_final.png", f"{title}, t = {snaps.times[-1]:.2f} s",
                   time_s=float(snaps.times[-1]))

    final = int(thermo["atoms"].iloc[-1])
    problems = []
    if final != case.particle_count:
        problems.append(f"{case.particle_count - final} particles left the domain")
    if escaped:
        problems.append(f"{escaped} particles escaped through the walls")
    summary: dict[str, Any] = {
        "case": case.name,
        "status": "ok" if not problems else "failed: " + "; ".join(problems),
        "case_hash": case.hash(),
        "particles_initial": case.particle_count,
        "particles_final": final,
        "particles_escaped_through_walls": escaped,
        "simulated_time_s": float(times[-1]),
        "mean_temperature_C": float(T_mean[-1]),
        "mean_temperature_initial_C": float(T_mean[0]),
        "mean_temperature_check_K": mean_check,
        "falling_mass_flow_kg_s": flow.mass_flow_kg_s,
        "curtain_mass_flow_kg_s": flow.curtain_mass_flow_kg_s,
        "falling_crossings": flow.crossings,
        "falling_window_s": [flow.window_start_s, flow.window_end_s],
        "output_steps": int(len(times)),
        "snapshots": int(len(snaps.times)),
        "post_read_s": read_s,
        "post_wall_time_s": time.perf_counter() - t0,
    }
    old = json.loads(rundir.summary_path.read_text()) if rundir.summary_path.exists() else {}
    # Keep what only the run knows (solver wall time, rates) when post is rerun alone.
    merged = {**old, **summary}
    rundir.summary_path.write_text(json.dumps(merged, indent=2))
    return merged
