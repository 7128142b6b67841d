"""`drumflow check | run | status | stop | post`: a run, from its case file to its observables."""

from __future__ import annotations

import json
import math
import time
from pathlib import Path
from typing import Annotated, Any

import typer
from rich.table import Table

from drumflow.cli._common import clock, load_case_file
from drumflow.cli._guard import console, err_console
from drumflow.cli._progress import StageProgress, resume_hint

__all__ = ["check", "post", "run", "status", "stop"]


def _load_profiled(case_file: Path, fast: bool) -> Any:
    """The case, under the fast profile on ``--fast`` (what it changed printed)."""
    case = load_case_file(case_file)
    if not fast:
        return case
    from drumflow.case import fast_profile

    case, changed = fast_profile(case)
    err_console.print(f"fast profile, as case {case.name}: " + ("; ".join(changed) or "nothing to change"))
    return case


def check(
    case_file: Annotated[Path, typer.Argument(help="case file (TOML)")],
    fast: Annotated[bool, typer.Option("--fast", help="check it under the fast profile")] = False,
) -> None:
    """Validate a case file without running anything."""
    from drumflow.dem.timestep import choose_time_step
    from drumflow.pipeline import refuse_unavailable

    case = _load_profiled(case_file, fast)
    refuse_unavailable(case)
    moved = case.dem_case()  # the parcels under particles.coarse_grain: they set the step
    choice = choose_time_step(moved)
    table = Table(title=f"case {case.name}: valid", show_header=False)
    table.add_row("drum", f"D {case.drum.diameter:g} m, l {case.drum.length:g} m, {case.drum.rpm:g} rpm, "
                  f"tilt {case.drum.tilt_deg:g}°, Froude {case.drum.froude:.3f}")
    table.add_row("lifters", f"{case.lifters.count} × {case.lifters.profile}")
    table.add_row("particles", f"{case.particle_count:,} × {case.particles.diameter * 1e3:g} mm, "
                  f"{case.particle_mass_total:.4g} kg")
    if moved is not case:
        table.add_row("DEM parcels", f"{moved.particle_count:,} × {moved.particles.diameter * 1e3:g} mm "
                      f"(coarse_grain {case.particles.coarse_grain:g}; drag and heat per kg kept)")
    bound = {"rayleigh": "set by run.rayleigh_fraction", "contact": "set by the fastest contact",
             "spin": "set by the bed's spin limit", "user": "run.time_step"}.get(choice.bound or "", "")
    table.add_row("time step", f"{choice.time_step:.3g} s ({choice.mode}, {bound}; "
                  f"{choice.fraction_of_rayleigh:.0%} of Rayleigh {choice.rayleigh_time:.3g} s; "
                  f"{choice.steps_per_contact:.0f} steps per contact)")
    table.add_row("steps", f"{round(case.run.time / choice.time_step):,} for {case.run.time:g} s")
    if choice.spin_time_step_limit is not None:
        ratio = choice.time_step / choice.spin_time_step_limit
        verdict = (f"resolved (the step is {ratio:.2f}× it)" if ratio <= 1.0 else
                   f"the step is {ratio:.2f}× it: the particles' spin in the bed is numerical "
                   "(README, 'The spin limit')")
        dashpot = ("" if case.contacts.tangential_damping else
                   " (contacts.tangential_damping = false: the tangential spring's own)")
        table.add_row("spin limit", f"{choice.spin_time_step_limit:.3g} s for the bed's contacts{dashpot}; "
                      f"{verdict}")
    if case.air.model != "none":
        from drumflow.coupling.spec import interior_spec, largest_biot

        biot = largest_biot(case)
        shells = interior_spec(case)
        table.add_row("heat in the granule",
                      f"{shells.shells} shells per particle (Bi up to {biot:.2g})" if shells is not None
                      else f"lumped (Bi up to {biot:.2g}; one temperature per particle needs Bi well "
                      "below 0.1, else particles.interior = 'shells')")
    console.print(table)


def run(
    case_file: Annotated[Path, typer.Argument(help="case file (TOML)")],
    out: Annotated[Path | None, typer.Option("--out", "-o", help="run directory")] = None,
    np_: Annotated[int | None, typer.Option("--np", min=1, help="MPI processes")] = None,
    steps: Annotated[
        int | None, typer.Option("--steps", min=1, help="short run: only this many DEM steps")
    ] = None,
    timeout: Annotated[float | None, typer.Option("--timeout", min=1, help="solver time limit, s")] = None,
    force: Annotated[bool, typer.Option("--force", help="reuse a directory of another case")] = False,
    as_json: Annotated[bool, typer.Option("--json", help="print the summary as JSON")] = False,
    fast: Annotated[bool, typer.Option(
        "--fast", help="the fast profile: no tangential dashpot between particles (the contact "
        "step without numerical spin), no conduction, the converged stop (README, 'The fast "
        "profile'); runs as case NAME_fast")] = False,
) -> None:
    """Run a case end to end (geometry, DEM, observables, plots) into a run directory."""
    from drumflow.pipeline import run_case

    case = _load_profiled(case_file, fast)
    out = out or Path("runs") / case.name
    try:
        with StageProgress(err_console) as progress:
            summary = run_case(case, out, processes=np_, steps=steps, timeout=timeout,
                               progress=progress, force=force)
    except KeyboardInterrupt:
        err_console.print(resume_hint(out))
        raise
    _print_summary(summary, out, as_json)
    if summary.get("status", "ok") != "ok":
        err_console.print(f"[bold red]{summary['status']}[/] (see {out}/summary.json)")
        raise typer.Exit(1)


def _print_summary(summary: dict, out: Path, as_json: bool) -> None:
    if as_json:
        console.print_json(json.dumps(summary))
        return
    table = Table(title=f"{summary.get('case')} → {out}", show_header=False)
    keys = [
        ("particles_initial", "particles at start", "{:,}"),
        ("particles_final", "particles at end", "{:,}"),
        ("particles_escaped_through_walls", "escaped through walls", "{:,}"),
        ("mean_temperature_C", "mean temperature at end (°C)", "{:.4f}"),
        ("falling_mass_flow_kg_s", "falling mass flow (kg/s)", "{:.4g}"),
        ("curtain_mass_flow_kg_s", "  of which curtain (kg/s)", "{:.4g}"),
        ("airborne_mass_flow_kg_s", "  airborne: no particle contact (kg/s)", "{:.4g}"),
        ("bed_mass_flow_kg_s", "  the bed: in contact (kg/s)", "{:.4g}"),
        ("wall_time_s", "wall time (s)", "{:.1f}"),
        ("particle_steps_per_s", "particle-steps per second", "{:,.0f}"),
        ("short_run_steps", "short run: DEM steps", "{:,}"),
    ]
    for key, label, fmt in keys:
        if key in summary and summary[key] is not None:
            table.add_row(label, fmt.format(summary[key]))
    console.print(table)


def post(
    run_dir: Annotated[Path, typer.Argument(help="run directory written by `drumflow run`")],
    as_json: Annotated[bool, typer.Option("--json", help="print the summary as JSON")] = False,
) -> None:
    """Recompute observables and plots from a run directory's saved dumps (no solver)."""
    from drumflow.pipeline import post_run

    summary = post_run(run_dir)
    _print_summary(summary, run_dir, as_json)


def stop(
    run_dir: Annotated[Path, typer.Argument(help="run directory of a running `drumflow run`")],
    wait: Annotated[bool, typer.Option("--wait/--no-wait", help="wait until the run has stopped")] = True,
    timeout: Annotated[float, typer.Option("--timeout", min=1, help="longest wait, s")] = 600.0,
) -> None:
    """Stop a run with air cleanly: a restart at its next air update, then exit 130 (resumable)."""
    from drumflow.analysis.run_status import run_status
    from drumflow.dem.stage import request_stop
    from drumflow.errors import RunDirectoryError

    st = run_status(run_dir)
    if not st.running:
        state = "finished" if st.finished else "stopped"
        raise RunDirectoryError(f"{run_dir}: no run is going there ({state}); allowed: the "
                                "directory of a running `drumflow run`")
    request = request_stop(run_dir)
    if st.reached_time_s is None:
        # Geometry and air are not interrupted: the air solve is kept and the DEM stops at its
        # first air update with a restart, so the next `drumflow run` loses nothing.
        err_console.print(f"asked the run in {run_dir} to stop: its DEM has not started, so it "
                          f"stops at the DEM's first air update ({request.name})")
    else:
        err_console.print(f"asked the run in {run_dir} to stop at its next air update ({request.name})")
    if not wait:
        return
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        time.sleep(2.0)
        st = run_status(run_dir)
        if not st.running:
            where = (f"its restart at {st.restart_time_s:.4g} s, step {st.restart_step:,}"
                     if st.restart_time_s is not None else "no restart")
            console.print(f"stopped; `drumflow run` again resumes it from {where}")
            return
    err_console.print(f"still running after {timeout:g} s: see `drumflow status {run_dir}`")
    raise typer.Exit(1)


def status(
    run_dir: Annotated[Path, typer.Argument(help="run directory written by `drumflow run`")],
    as_json: Annotated[bool, typer.Option("--json", help="print the status as JSON")] = False,
) -> None:
    """Where a run stands (running, interrupted or finished): time reached, pace, ETA, disk."""
    from drumflow.analysis.run_status import RECENT_UPDATES, run_status
    from drumflow.dem.stage import LOAD_LOG

    st = run_status(run_dir)
    if as_json:
        console.print_json(json.dumps(st.to_dict()))
        return
    table = Table(title=f"{st.case} → {run_dir}", show_header=False)
    if st.finished:
        state = "finished"
    elif st.running:
        state = "running" + (f" (log written {st.log_age_s:.0f} s ago)" if st.log_age_s is not None else "")
    elif st.stopped_on_request_s is not None:
        state = (f"stopped on request at {st.stopped_on_request_s:.4g} s, after writing a restart "
                 "there: run `drumflow run` again to resume")
    elif st.reached_time_s is not None:
        how = "its process has ended" if st.process_alive is False else "no process recorded"
        state = (f"stopped: run `drumflow run` again to resume ({how}; log idle for "
                 f"{clock(st.log_age_s)})")
    else:
        state = f"DEM not started (stages done: {', '.join(st.stages_done) or 'none'})"
    table.add_row("state", state)
    if st.reached_time_s is not None:
        share = st.reached_time_s / st.target_time_s if st.target_time_s else 0.0
        table.add_row("simulated", f"{st.reached_time_s:.3f} of {st.target_time_s:g} s ({share:.1%}), "
                      f"step {st.step:,}")
        table.add_row("particles", f"{st.particles:,} of {st.particles_initial:,}")
    if st.wall_per_simulated_s is not None:
        table.add_row("pace (last updates)", f"{st.wall_per_simulated_s:,.0f} wall s per simulated s "
                      f"(last {RECENT_UPDATES} air updates)")
    if st.eta_s is not None:
        table.add_row("to the end at that pace", clock(st.eta_s))
    if st.other_cores_recent is not None and st.load_logged_s is not None:
        table.add_row("other programs", f"{st.other_cores_recent:.2f} cores over the last 10 min; "
                      f"contended {clock(st.contended_s or 0.0)} of {clock(st.load_logged_s)} logged "
                      f"(dem/{LOAD_LOG})")
    if st.restart_step is not None:
        table.add_row("a resume starts from", f"restart of step {st.restart_step:,} "
                      f"({st.restart_time_s:.3f} s)" if st.restart_time_s is not None
                      else f"restart of step {st.restart_step:,}")
    if st.time_step_s is not None:
        kept = ("" if st.new_run_time_step_s is None
                or math.isclose(st.new_run_time_step_s, st.time_step_s, rel_tol=1e-9)
                else f"; kept on resume: a new run of this case would take {st.new_run_time_step_s:.3g} s "
                "(README, 'The spin limit')")
        table.add_row("time step", f"{st.time_step_s:.3g} s{kept}")
    table.add_row("disk", f"{st.output_bytes / 1e9:.2f} GB output, {st.restart_bytes / 1e9:.2f} GB in "
                  f"{st.restarts} restart file(s)")
    console.print(table)

