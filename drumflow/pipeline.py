"""The pipeline: case -> geometry -> air -> coupling spec -> DEM -> observables -> summary and plots.

:func:`run_case` runs every stage into a run directory, skipping finished ones;
:func:`post_run` recomputes the observables and plots from the saved dumps, with no solver.
"""

from __future__ import annotations

import math
import os
import socket
import time
from dataclasses import asdict
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from drumflow import air, dem, geometry
from drumflow.air.stage import AirInputs
from drumflow.analysis.observables import (
    crossings_from_rows,
    escaped_particles,
    falling_mass_flow,
    falling_mass_per_interval,
    mean_temperature,
)
from drumflow.case import Case, case_to_toml, load_case
from drumflow.coupling.crossings import CROSSINGS_RECORD, read_loop_crossings
from drumflow.coupling.log import heat_removed_until, read_coupling
from drumflow.coupling.spec import CouplingSpec, build_coupling
from drumflow.coupling.stop import STOP_RECORD
from drumflow.dem.dumps import read_rows, read_series
from drumflow.dem.stage import (
    DemInputs,
    DemResult,
    ProgressCallback,
    clear_stop_request,
    kept_time_step,
    plan_run,
)
from drumflow.dem.state import load_bed_states, load_start_state
from drumflow.dem.thermo import read_thermo
from drumflow.dem.timestep import TimeStepChoice, choose_time_step
from drumflow.errors import BadFileError, CaseError, RunDirectoryError
from drumflow.readers import read_csv, read_json_object
from drumflow.report.plots import (
    plot_air_heat,
    plot_crossings,
    plot_mean_temperature,
    plot_particles,
)
from drumflow.rundir import RunDir, write_json_atomic
from drumflow.runner import LaunchProfile, Runner
from drumflow.skips import skips

__all__ = ["run_case", "post_run", "refuse_unavailable"]


def refuse_unavailable(case: Case) -> None:
    """Raise :class:`CaseError` for features the case asks for that this version lacks."""
    if case.air.pressure_gradient_force:
        # Say so before any solver starts, rather than silently run without it.
        raise CaseError(
            [
                "air.pressure_gradient_force = true: the pressure-gradient force (Eq. 4) is not "
                "available in this version; allowed: false"
            ]
        )


def kept_step_rule(case: Case, kept: TimeStepChoice) -> str:
    """The rule a kept step follows today, for the run's ``skips`` record: a step an older
    "auto" chose is today's ``"contact"`` rule when it equals that rule's step (the "auto"
    before the spin limit), else its recorded mode."""
    data = case.model_dump(mode="json")
    data["run"]["time_step"] = "contact"
    contact = choose_time_step(Case.model_validate(data))
    if kept.mode == "auto" and math.isclose(contact.time_step, kept.time_step, rel_tol=1e-9):
        return "contact"
    return kept.mode


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
    if not (Path(out) / "manifest.json").exists():
        # A refused case leaves nothing behind: the time-step check (a fixed run.time_step above
        # the stability limit) runs before the run directory is made. A directory with a run
        # in it may keep the step it started with (kept_time_step), so it is checked there.
        choose_time_step(case.dem_case())
    # A start state that does not fit the case is refused before any stage runs (geometry and
    # air take minutes at paper scale).
    load_start_state(case)
    bed_states = tuple(load_bed_states(case))
    runner = Runner(profile)
    rundir = RunDir(out)
    rundir.bind_case(case.canonical_json(), case.hash(), case_to_toml(case), force=force,
                     versions=runner.profile.software_versions())
    # Who runs in this directory: `drumflow status` tells a live run from one that was killed.
    rundir.record("process", {"pid": os.getpid(), "host": socket.gethostname(),
                              "started": time.time()})
    # A stop request of an earlier attempt is stale; one made from now on is kept for the DEM.
    clear_stop_request(rundir)
    t0 = time.perf_counter()
    # What the DEM moves: the particles, or with particles.coarse_grain their parcels. Geometry,
    # time step and DEM follow the parcels; the air and its coupling the real particles.
    moved = case.dem_case()
    shape = geometry.run(moved, rundir, runner)
    if progress:
        progress("geometry", 1.0, 1.0)
    # The one choice of the time step and the processes: the air coupling and the DEM stage
    # both use them. A run being resumed keeps the step it started with.
    kept = kept_time_step(moved, rundir, steps)
    choice, plan = plan_run(moved, steps, kept)
    step_rule = choice.mode
    if kept is not None:
        now = choose_time_step(moved)
        if not math.isclose(now.time_step, kept.time_step, rel_tol=1e-12):
            rundir.record("time_step_kept", {
                "time_step": kept.time_step, "drumflow_now_chooses": now.as_dict(),
                "why": "a run keeps the step it started with; start it afresh in another "
                       "directory for the new step"})
            step_rule = kept_step_rule(moved, kept)
    nprocs = runner.profile.processes_for(moved)
    coupling = _air(case, rundir, runner, AirInputs(processes=nprocs, progress=progress,
                                                    bed_states=bed_states),
                    plan.time_step, plan.dump_every)
    rundir.record("skips", skips(moved, step_rule, coupling is not None, shape.wall_motion, nprocs))
    inputs = DemInputs(shape, choice, plan, processes=nprocs, coupling=coupling, steps=steps,
                       timeout=timeout, progress=progress)
    result = dem.run(moved, rundir, runner, inputs)
    if steps is not None:
        return _short_run_summary(moved, rundir, result, steps, t0)
    earlier = _earlier_wall_time(rundir) if result.reused else None
    summary = post_run(rundir.root, case=case)
    summary["wall_time_s"] = time.perf_counter() - t0
    if earlier is not None:
        # A call that found the run finished keeps the run's own wall time: its few seconds
        # overwrote it once, and the run's cost was lost to its summary.
        summary["reuse_wall_time_s"], summary["wall_time_s"] = summary["wall_time_s"], earlier
    summary["dem_wall_time_s"] = result.wall_time_s
    summary["particle_steps_per_s"] = result.particle_steps_per_s
    # Whole or not at all: a sweep's monitor reads members' summaries while they run.
    write_json_atomic(rundir.summary_path, summary)
    rundir.record("summary", summary)
    return summary


def _earlier_wall_time(rundir: RunDir) -> float | None:
    """The wall time of the run an earlier call finished (its summary), None without one."""
    if not rundir.summary_path.exists():
        return None
    try:
        wall = read_json_object(rundir.summary_path, "the run's summary").get("wall_time_s")
    except BadFileError:
        return None  # a damaged summary is written again by this call
    return float(wall) if isinstance(wall, int | float) and math.isfinite(wall) else None


def _air(case: Case, rundir: RunDir, runner: Runner, inputs: AirInputs, time_step: float,
         dump_every: int) -> CouplingSpec | None:
    """The air stage's field and the coupling spec built from it (``None`` without air)."""
    try:
        field = air.run(case, rundir, runner, inputs)
    finally:
        # Every OpenFOAM program run (or failed) goes into the manifest with its timing.
        rundir.record_commands([r.as_dict() for r in runner.records])
    if field is None:
        return None
    coupling = build_coupling(case, field.source, time_step, dump_every)
    field.summary.coupling_interval_steps = coupling.interval
    rundir.record("air", field.summary.as_dict())
    return coupling


def _short_run_summary(case: Case, rundir: RunDir, result: DemResult, steps: int,
                       t0: float) -> dict[str, Any]:
    summary = {
        "case": case.name,
        "short_run_steps": steps,
        "particles_initial": result.particles_initial,
        "particles_final": result.particles_final,
        "wall_time_s": time.perf_counter() - t0,
        "dem": asdict(result),
    }
    write_json_atomic(rundir.summary_path, summary)
    return summary


def write_crossings_csv(path: Path, crossings: pd.DataFrame) -> None:
    """``post/crossings.csv``: ``time,id,x,z`` (and ``in_contact`` where the coupling loop
    counted contacts: 1 touching another particle at the crossing, 0 airborne, empty unknown),
    6 significant digits (``%.6g``, ``id`` whole).

    Formatted row by row in Python, which is 2.5 times faster than pandas' ``to_csv`` with a
    ``float_format`` (3.6 s for model one's 500,000 crossings of 17.5 s, most of ``drumflow
    post``); the text is the same.
    """
    columns = (crossings["time"].to_numpy(float), crossings["id"].to_numpy(np.int64),
               crossings["x"].to_numpy(float), crossings["z"].to_numpy(float))
    contact = (crossings["in_contact"].to_numpy(float) if "in_contact" in crossings.columns
               else np.full(len(crossings), np.nan))
    with path.open("w") as fh:
        if not np.isfinite(contact).any():
            fh.write("time,id,x,z\n")
            fh.writelines(f"{t:.6g},{i},{x:.6g},{z:.6g}\n" for t, i, x, z in zip(*columns, strict=True))
            return
        fh.write("time,id,x,z,in_contact\n")
        fh.writelines(f"{t:.6g},{i},{x:.6g},{z:.6g},{'' if c != c else int(c)}\n"
                      for t, i, x, z, c in zip(*columns, contact, strict=True))


def _finite_or_none(value: float) -> float | None:
    return value if math.isfinite(value) else None


def post_run(out: Path | str, case: Case | None = None) -> dict[str, Any]:
    """Recompute observables, tables and plots from a run directory's dumps (no solver).

    Raises
    ------
    RunDirectoryError
        When the directory lacks the case or the dumps.
    """
    rundir = RunDir.existing(out)
    root = rundir.root
    rundir.require(rundir.case_toml, rundir.dem_dumps, rundir.dem_log)
    if case is None:
        case = load_case(rundir.case_toml)
    user_case = case
    # Counts, masses and sizes of what the DEM moved (parcels under coarse-graining).
    case = case.dem_case()
    ts = rundir.manifest.get("time_step", {}).get("time_step")
    if ts is None:
        raise RunDirectoryError(f"{root}/manifest.json: no DEM time step recorded; rerun the case")
    t0 = time.perf_counter()
    dumps = rundir.dem_dumps
    thermo = read_thermo(rundir.dem, every=rundir.manifest.get("output_every"))
    if thermo.empty:
        raise RunDirectoryError(f"{rundir.dem}: no LIGGGHTS thermo output (log.liggghts)")
    times = thermo["step"].to_numpy() * float(ts)
    T_mean = thermo["T_mean"].to_numpy()
    loop_crossings = rundir.dem / CROSSINGS_RECORD
    # run.crossings = "loop": the coupling loop wrote the crossings themselves; else they come
    # from the band dump.
    table = read_loop_crossings(loop_crossings) if loop_crossings.exists() else None
    # A run still going (or killed mid-write) may leave its newest dump cut short: it is left
    # out, and the series end at the last complete crossing dump (the crossings of the next
    # interval need it).
    rows = (None if table is not None
            else read_rows(dumps, float(ts), prefix="cross", skip_partial_newest=True))
    snaps = read_series(dumps, float(ts), prefix="snap", skip_partial_newest=True)
    skipped = [*(rows.skipped if rows is not None else ()), *snaps.skipped]
    if rows is not None and rows.skipped:
        thermo = thermo[thermo["step"] <= int(rows.steps[-1])].reset_index(drop=True)
        times = thermo["step"].to_numpy() * float(ts)
        T_mean = thermo["T_mean"].to_numpy()
    read_s = time.perf_counter() - t0
    mass = case.particles.mass
    if table is not None:
        crossings = table
    else:
        assert rows is not None
        crossings = crossings_from_rows(rows.times, rows.frame, rows.ids, rows["x"], rows["y"],
                                        rows["z"])
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
    write_crossings_csv(rundir.crossings_csv, crossings)
    np.savetxt(
        rundir.mean_temperature_csv,
        np.column_stack([times, T_mean, thermo["atoms"].to_numpy(), np.r_[np.nan, per_step]]),
        delimiter=",",
        header="time_s,mean_temperature_C,particles,falling_mass_kg_in_step",
        comments="",
        fmt="%.10g",
    )
    title = f"{case.name}: {case.particle_count:,} particles of {case.particles.diameter * 1e3:g} mm"
    plot_mean_temperature(times, T_mean, rundir.mean_temperature_plot, title)
    plot_crossings(crossings, flow, case.drum.length, rundir.crossings_plot, title)
    plot_particles(snaps["x"][-1], snaps["y"][-1], snaps["T"][-1], case,
                   rundir.particles_plot, f"{title}, t = {snaps.times[-1]:.2f} s",
                   time_s=float(snaps.times[-1]))

    air_info = _post_air(rundir, case, float(ts), times, T_mean)
    closures_info = _post_closures(rundir)

    final = int(thermo["atoms"].iloc[-1])
    problems = []
    if final != case.particle_count:
        problems.append(f"{case.particle_count - final} particles left the domain")
    if escaped:
        problems.append(f"{escaped} particles escaped through the walls")
    summary: dict[str, Any] = {
        "case": case.name,
        "status": "ok" if not problems else "failed: " + "; ".join(problems),
        "case_hash": user_case.hash(),
        **({"coarse_grain": user_case.particles.coarse_grain}
           if user_case.particles.coarse_grain != 1.0 else {}),
        **({"dumps_skipped": [p.name for p in skipped]} if skipped else {}),
        "particles_initial": case.particle_count,
        "particles_final": final,
        "particles_escaped_through_walls": escaped,
        "simulated_time_s": float(times[-1]),
        "mean_temperature_C": float(T_mean[-1]),
        "mean_temperature_initial_C": float(T_mean[0]),
        "mean_temperature_check_K": mean_check,
        "falling_mass_flow_kg_s": flow.mass_flow_kg_s,
        "curtain_mass_flow_kg_s": flow.curtain_mass_flow_kg_s,
        # Split by contact (run.crossings = "loop"; null where the contacts are not known).
        "airborne_mass_flow_kg_s": _finite_or_none(flow.airborne_mass_flow_kg_s),
        "bed_mass_flow_kg_s": _finite_or_none(flow.bed_mass_flow_kg_s),
        "falling_crossings": flow.crossings,
        "falling_window_s": [flow.window_start_s, flow.window_end_s],
        "output_steps": int(len(times)),
        "snapshots": int(len(snaps.times)),
        **air_info,
        **closures_info,
        **_stop_info(rundir),
        "post_read_s": read_s,
        "post_wall_time_s": time.perf_counter() - t0,
    }
    # Checked, not guessed at: a damaged summary would lose what only the run knows.
    old = (read_json_object(rundir.summary_path, "the run's summary")
           if rundir.summary_path.exists() else {})
    # Keep what only the run knows (solver wall time, rates) when post is rerun alone.
    merged = {**old, **summary}
    write_json_atomic(rundir.summary_path, merged)
    return merged


def _post_closures(rundir: RunDir) -> dict[str, Any]:
    """``post/closures.json``: what the whole-cooler model needs from the slice, measured from
    the snapshots now, because shipped results keep the closures but not the snapshots. A run
    that has none to give (no snapshot after ``run.mass_flow_start``, nothing airborne) says
    why in the summary instead."""
    from drumflow.analysis.closures import extract_closures

    rundir.closures_json.unlink(missing_ok=True)  # never a stale file beside new series
    try:
        closures = extract_closures(rundir.root)
    except (RunDirectoryError, BadFileError) as exc:
        return {"closures_not_measured": str(exc).splitlines()[0]}
    write_json_atomic(rundir.closures_json, closures.to_dict())
    return {"closures_file": "post/closures.json"}


def _stop_info(rundir: RunDir) -> dict[str, Any]:
    """Why and when a 'converged' run stopped, with its intervals (nothing for a fixed run)."""
    path = rundir.dem / STOP_RECORD
    if not path.exists():
        return {}
    return {"stop": read_json_object(path, "the stop rule's record")}


def _post_air(
    rundir: RunDir,
    case: Case,
    time_step: float,
    times: np.ndarray,
    T_mean: np.ndarray,
) -> dict[str, Any]:
    """Heat the air took from the particles, its plot, and the energy balance check."""
    # Strict: a log cut short would give a wrong heat balance under status "ok".
    coupling = read_coupling(rundir.dem_coupling_logs, time_step, covers_s=float(times[-1]))
    if coupling.empty:
        return {}
    coupling.to_csv(rundir.air_heat_csv, index=False, float_format="%.10g")
    # Up to the last temperature output (a run stopped part way logged one more update).
    removed = heat_removed_until(coupling, float(times[-1]), time_step)
    # The particles' enthalpy loss, from LIGGGHTS' mass-weighted mean temperature: an
    # independent route to the same number (conduction only moves heat between particles).
    loss = case.particle_mass_total * case.particles.heat_capacity * float(T_mean[0] - T_mean[-1])
    closure = abs(loss - removed) / abs(removed) if removed else float("nan")
    plot_air_heat(coupling, rundir.air_heat_plot, f"{case.name}: heat removed by the air")
    recorded = rundir.manifest.get("air", {})
    return {
        "air_model": case.air.model,
        "air_mass_flow_in_kg_s": recorded.get("mass_flow_in_kg_s"),
        "air_mass_flow_out_kg_s": recorded.get("mass_flow_out_kg_s"),
        "air_mean_axial_velocity_m_s": recorded.get("mean_axial_velocity_m_s"),
        "air_coupling_interval_steps": recorded.get("coupling_interval_steps"),
        "air_field_cache_hit": recorded.get("cache_hit"),
        "heat_removed_by_air_J": removed,
        "particle_enthalpy_loss_J": loss,
        "energy_balance_error": closure,
        "mean_heat_removal_W": removed / float(times[-1]) if times[-1] > 0 else float("nan"),
        **_air_warming_summary(rundir, float(times[-1]), removed, time_step),
    }


def _air_warming_summary(rundir: RunDir, until_s: float, removed_J: float,
                         time_step: float) -> dict[str, Any]:
    """With ``air.warming``: what the air carried out (its outlet's enthalpy over the inlet's,
    from the solved temperatures) against the heat the particles gave it, and its outlet
    temperature over the last second. Empty for one-way air."""
    logs = sorted(rundir.dem_coupling_logs.glob("air.*.csv"), key=lambda p: int(p.name.split(".")[1]))
    if not logs:
        return {}
    # A resumed attempt supersedes what earlier attempts logged from its start on, as the
    # coupling logs do.
    parts = []
    for i, log in enumerate(logs):
        table = read_csv(log, "the air's temperature log (air.warming)")
        if i + 1 < len(logs):
            table = table[table["step"] < int(logs[i + 1].name.split(".")[1])]
        parts.append(table)
    air = pd.concat(parts, ignore_index=True)
    air = air[air["time_s"] < until_s - 1e-12]
    held = air["steps"].to_numpy(float) * time_step
    gain = float(np.sum(air["air_enthalpy_gain_W"].to_numpy(float) * held))
    last = air[air["time_s"] >= max(0.0, until_s - 1.0)]
    # The heat the air took over the heat if every particle had met inlet air through the same
    # film (logs written before the column existed have none).
    fresh = (float(np.sum(air["heat_if_fresh_W"].to_numpy(float) * held))
             if "heat_if_fresh_W" in air else math.nan)
    taken = float(np.sum(air["heat_to_air_W"].to_numpy(float) * held))
    return {
        "contact_efficiency": taken / fresh if fresh > 0 else math.nan,
        "air_enthalpy_gain_J": gain,
        "air_energy_balance_error": abs(gain - removed_J) / abs(removed_J) if removed_J else float("nan"),
        "air_outlet_temperature_C": float(last["outlet_C"].mean()),
        "air_max_temperature_C": float(air["max_C"].max()),
    }

