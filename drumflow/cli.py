"""The drumflow command line: the only place that prints or exits.

Exit codes, one rule for every command (:func:`drumflow.errors.exit_code`, applied by
:func:`drumflow.cli_guard.guard_every_command` at the end of this module): 0 success, 1 a run
failed (solver error, lost particles), 2 bad input (case file, arguments, run directory), 130
interrupted (rerun the same command to resume).
"""

from __future__ import annotations

import json
import math
import signal
import sys
import time
from pathlib import Path
from typing import Annotated, Any

import typer
from rich import box
from rich.markup import escape
from rich.table import Table

from drumflow.cli_cooler import app as cooler_app
from drumflow.cli_cooler.drum import drum as plant
from drumflow.cli_export import export
from drumflow.cli_guard import cli_console, guard_every_command
from drumflow.cli_paper import paper
from drumflow.cli_progress import StageProgress, resume_hint
from drumflow.cli_sweep import sweep

app = typer.Typer(
    add_completion=False,
    no_args_is_help=True,
    pretty_exceptions_enable=False,
    help="CFD-DEM studies of flighted rotary-drum coolers (LIGGGHTS, OpenFOAM).",
)
console = cli_console()
err_console = cli_console(stderr=True)
app.add_typer(cooler_app, name="cooler")
app.command("sweep")(sweep)
app.command("paper")(paper)
app.command("export")(export)
# `drumflow plant RUN_DIR` is `drumflow cooler drum RUN_DIR`: the whole cooler from a slice.
app.command("plant")(plant)


def _load(case_file: Path) -> Any:
    from drumflow.case import load_case

    return load_case(case_file)


def _load_profiled(case_file: Path, fast: bool) -> Any:
    """The case, under the fast profile on ``--fast`` (what it changed printed)."""
    case = _load(case_file)
    if not fast:
        return case
    from drumflow.case import fast_profile

    case, changed = fast_profile(case)
    err_console.print(f"fast profile, as case {case.name}: " + ("; ".join(changed) or "nothing to change"))
    return case


@app.command()
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


@app.command()
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
        ("wall_time_s", "wall time (s)", "{:.1f}"),
        ("particle_steps_per_s", "particle-steps per second", "{:,.0f}"),
        ("short_run_steps", "short run: DEM steps", "{:,}"),
    ]
    for key, label, fmt in keys:
        if key in summary and summary[key] is not None:
            table.add_row(label, fmt.format(summary[key]))
    console.print(table)


@app.command()
def post(
    run_dir: Annotated[Path, typer.Argument(help="run directory written by `drumflow run`")],
    as_json: Annotated[bool, typer.Option("--json", help="print the summary as JSON")] = False,
) -> None:
    """Recompute observables and plots from a run directory's saved dumps (no solver)."""
    from drumflow.pipeline import post_run

    summary = post_run(run_dir)
    _print_summary(summary, run_dir, as_json)


def _duration(seconds: float | None) -> str:
    if seconds is None:
        return "–"
    hours, rest = divmod(int(round(seconds)), 3600)
    return f"{hours}:{rest // 60:02d}:{rest % 60:02d}"


@app.command()
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


@app.command()
def status(
    run_dir: Annotated[Path, typer.Argument(help="run directory written by `drumflow run`")],
    as_json: Annotated[bool, typer.Option("--json", help="print the status as JSON")] = False,
) -> None:
    """Where a run stands (running, interrupted or finished): time reached, pace, ETA, disk."""
    from drumflow.analysis.run_status import RECENT_UPDATES, run_status

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
                 f"{_duration(st.log_age_s)})")
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
        table.add_row("to the end at that pace", _duration(st.eta_s))
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


def _exchanger_rows(table: Table, r, label_suffix: str = "") -> None:  # type: ignore[no-untyped-def]
    rows = [
        ("material inlet T_mi (°C)", f"{r.material_inlet_temperature_c:.2f}"),
        ("material outlet T_mo (°C)", f"{r.material_outlet_temperature_c:.2f}"),
        ("air inlet T_ai (°C)", f"{r.air_inlet_temperature_c:.2f}"),
        ("air outlet T_ao (°C)", f"{r.air_outlet_temperature_c:.2f}"),
        ("thermal power Q_m (kW)", f"{r.heat_removed_w / 1e3:.2f}"),
        ("LMTD_he (°C)", f"{r.lmtd_c:.2f}"),
        ("h (W/(m² K))", f"{r.h_w_m2k:.4g}"),
        ("exchanged heat Q_he (kW)", f"{r.heat_exchanged_w / 1e3:.2f}"),
        ("area A_he (m²)", f"{r.area_m2:.2f}"),
    ]
    for label, value in rows:
        table.add_row(label + label_suffix, value)


@app.command()
def exchanger(
    case_file: Annotated[
        Path, typer.Argument(help="case file (TOML); its plant and air sections give the streams")
    ],
    h: Annotated[float, typer.Option("--h", help="heat-transfer coefficient, W/(m² K)")],
    area: Annotated[float | None, typer.Option("--area", help="exchange area A_he, m²: solve T_mo")] = None,
    outlet_temperature: Annotated[
        float | None,
        typer.Option("--outlet-temperature", help="material outlet T_mo, °C: solve A_he "
                     "(default: plant.material_outlet_temperature_C when --area is not given)"),
    ] = None,
    as_json: Annotated[bool, typer.Option("--json", help="print the result as JSON")] = False,
) -> None:
    """The cooler as a counter-current exchanger (Eqs. 42-48, Table 7)."""
    from drumflow.analysis.exchanger import counter_current_exchanger
    from drumflow.analysis.methodology import exchanger_to_dict, plant_streams

    case = _load(case_file)
    if area is not None and outlet_temperature is not None:
        raise typer.BadParameter("give --area or --outlet-temperature, not both")
    if area is None and outlet_temperature is None:
        outlet_temperature = case.plant.material_outlet_temperature_C
        if outlet_temperature is None:
            raise typer.BadParameter(
                "give --area A (solve T_mo) or --outlet-temperature T (solve A_he), or set "
                "plant.material_outlet_temperature_C in the case"
            )
    result = counter_current_exchanger(
        h_w_m2k=h, area_m2=area, material_outlet_temperature_c=outlet_temperature,
        **plant_streams(case),
    )
    if as_json:
        console.print_json(json.dumps({"case": case.name, **exchanger_to_dict(result)}))
        return
    solved = "T_mo" if area is not None else "A_he"
    table = Table(title=f"{case.name}: counter-current exchanger, solved for {solved}", show_header=False)
    _exchanger_rows(table, result)
    console.print(table)


@app.command()
def predict(
    run_dir: Annotated[Path, typer.Argument(help="reference run directory (a run of the case, with air)")],
    h: Annotated[
        float | None, typer.Option("--h", help="fixed h, W/(m² K) (default: the run's mean h)")
    ] = None,
    fit_with: Annotated[
        list[Path] | None,
        typer.Option("--fit-with", help="more run directories: fit Nu = a Re^b Pr^c to all runs "
                     "and use it instead of a fixed h (repeat the option)"),
    ] = None,
    rpm: Annotated[float | None, typer.Option("--rpm", help="new rotation speed, 1/min")] = None,
    air_flow: Annotated[float | None, typer.Option("--air-flow", help="new air mass flow, kg/s")] = None,
    feed_rate: Annotated[float | None, typer.Option("--feed-rate", help="new feed rate, kg/s")] = None,
    particle_diameter: Annotated[
        float | None, typer.Option("--particle-diameter", help="new particle diameter, m")
    ] = None,
    conductivity: Annotated[
        str, typer.Option("--conductivity", help="k in Nu = h Dp / k: 'air' or 'particle' (the paper's)")
    ] = "air",
    assumptions: Annotated[
        bool, typer.Option("--assumptions", help="also print the scaling assumptions")
    ] = False,
    as_json: Annotated[bool, typer.Option("--json", help="print the prediction as JSON")] = False,
) -> None:
    """Predict the plant outlet temperatures at a new rpm, air flow, feed rate or particle size."""
    from drumflow.analysis.methodology import analyse_run, fit_runs
    from drumflow.analysis.predict import predict_plant

    if fit_with and h is not None:
        raise typer.BadParameter("give --h or --fit-with, not both")
    reference = analyse_run(run_dir, nusselt_conductivity=conductivity)  # type: ignore[arg-type]
    source = (
        fit_runs([reference, *fit_with], nusselt_conductivity=conductivity)  # type: ignore[arg-type]
        if fit_with
        else (reference.h_mean_w_m2k if h is None else h)
    )
    pred = predict_plant(
        source, reference.case, reference=reference, rpm=rpm, air_mass_flow=air_flow,
        feed_rate=feed_rate, particle_diameter=particle_diameter,
        nusselt_conductivity=conductivity,  # type: ignore[arg-type]
    )
    if as_json:
        console.print_json(json.dumps(pred.to_dict()))
        return
    table = Table(title=f"{reference.case.name}: plant prediction (h from {pred.h_source})")
    table.add_column("")
    table.add_column("case", justify="right")
    table.add_column("predicted", justify="right")
    ref, new = pred.reference, pred.conditions
    ex0, ex1 = pred.reference_exchanger, pred.exchanger
    for label, a, b, fmt in [
        ("rotation (rpm)", ref.rpm, new.rpm, "{:.4g}"),
        ("air flow (kg/s)", ref.air_mass_flow_kg_s, new.air_mass_flow_kg_s, "{:.4g}"),
        ("feed rate (kg/s)", ref.feed_rate_kg_s, new.feed_rate_kg_s, "{:.4g}"),
        ("particle diameter (mm)", ref.particle_diameter_m * 1e3, new.particle_diameter_m * 1e3, "{:.4g}"),
        ("Re", pred.reference_reynolds, pred.reynolds, "{:.5g}"),
        ("h (W/(m² K))", pred.reference_h_w_m2k, pred.h_w_m2k, "{:.4g}"),
        ("area A_he (m²)", pred.reference_exchanger_area_m2, pred.exchanger_area_m2, "{:.2f}"),
        ("material outlet T_mo (°C)", ex0.material_outlet_temperature_c,
         ex1.material_outlet_temperature_c, "{:.2f}"),
        ("air outlet T_ao (°C)", ex0.air_outlet_temperature_c, ex1.air_outlet_temperature_c, "{:.2f}"),
        ("thermal power Q_m (kW)", ex0.heat_removed_w / 1e3, ex1.heat_removed_w / 1e3, "{:.2f}"),
    ]:
        table.add_row(label, fmt.format(a), fmt.format(b))
    console.print(table)
    for warning in pred.warnings:
        err_console.print(f"[bold yellow]warning:[/] {warning}", highlight=False)
    if assumptions:
        for i, text in enumerate(pred.assumptions, 1):
            console.print(f"{i}. {text}", highlight=False)


@app.command()
def report(
    run_dirs: Annotated[list[Path], typer.Argument(help="run directories (one run or a sweep)")],
    out: Annotated[Path, typer.Option("--out", "-o", help="HTML file to write")],
    conductivity: Annotated[
        str, typer.Option("--conductivity", help="k in Nu = h Dp / k: 'air' or 'particle' (the paper's)")
    ] = "air",
    render_3d: Annotated[
        bool, typer.Option("--3d/--no-3d", help="PyVista picture of the last snapshot")
    ] = True,
    as_json: Annotated[bool, typer.Option("--json", help="print the report path as JSON")] = False,
) -> None:
    """One self-contained HTML page: case, Tables 6-8, Figures 4, 6-9, manifest."""
    from drumflow.readers import output_file
    from drumflow.report.html import write_report

    output_file(out)  # before any analysis: a folder there would fail only at the end

    def note(text: str) -> None:
        # On stderr: the page holds them too, but "report written" alone would hide them.
        err_console.print(f"[yellow]note:[/] {escape(text)}", highlight=False)

    path = write_report(run_dirs, out, nusselt_conductivity=conductivity,  # type: ignore[arg-type]
                        render_3d=render_3d, on_note=note)
    if as_json:
        console.print_json(json.dumps({"report": str(path), "runs": [str(p) for p in run_dirs]}))
        return
    console.print(f"report written to {path}", highlight=False)


@app.command()
def methodology(
    run_dir: Annotated[Path, typer.Argument(help="run directory written by `drumflow run` (with air)")],
    conductivity: Annotated[
        str, typer.Option("--conductivity", help="k in Nu = h Dp / k: 'air' or 'particle' (the paper's)")
    ] = "air",
    falling_mass: Annotated[
        str, typer.Option("--falling-mass", help="'mean' (the paper's averaged m_mf) or 'per_step'")
    ] = "mean",
    as_json: Annotated[bool, typer.Option("--json", help="print the result as JSON")] = False,
) -> None:
    """Heat-transfer coefficient, Nu/Re/Pr and the exchanger model of one run (Tables 6-7)."""
    from drumflow.analysis.methodology import analyse_run, write_methodology

    result = analyse_run(run_dir, nusselt_conductivity=conductivity,  # type: ignore[arg-type]
                         falling_mass=falling_mass)  # type: ignore[arg-type]
    json_path, csv_path = write_methodology(run_dir, result)
    if as_json:
        console.print_json(json.dumps(result.to_dict()))
        return
    table = Table(title=f"{result.case.name}: heat transfer (Table 6) → {json_path}", show_header=False)
    table.add_row("time step dt (s)", f"{result.dt_s:.4g}")
    table.add_row("air mass per step (kg)", f"{result.air_mass_per_step_kg:.4g}")
    table.add_row("falling mass per step (kg)", f"{result.falling_mass_per_step_kg:.4g}")
    table.add_row("falling area A_fp (m²)", f"{result.falling_area_m2:.4g}")
    table.add_row("mean h (W/(m² K))", f"{result.h_mean_w_m2k:.4g}")
    table.add_row("valid steps", f"{result.n_valid:,} of {result.n_steps:,}")
    _exchanger_rows(table, result.exchanger, " [model]")
    if result.plant_exchanger is not None:
        _exchanger_rows(table, result.plant_exchanger, " [plant]")
    console.print(table)
    for warning in result.warnings:
        err_console.print(f"[bold yellow]warning:[/] {warning}", highlight=False)
    console.print(f"per-step table: {csv_path}", highlight=False)


@app.command()
def verify(
    quick: Annotated[bool, typer.Option("--quick", help="only what fits in a couple of minutes")] = False,
    out: Annotated[
        Path, typer.Option("--out", "-o", help="where the cases and verification.json go")
    ] = Path("runs/verify"),
) -> None:
    """Run the verification cases (analytic solutions, conservation laws) on the real solvers."""
    from drumflow.readers import output_folder
    from drumflow.verify import run_verification

    output_folder(out)
    table = Table(title="drumflow verify" + (" --quick" if quick else ""))
    for col in ("check", "measured", "expected", "error", "tolerance", ""):
        table.add_column(col, justify="right" if col not in ("check", "") else "left")

    def show(c) -> None:  # type: ignore[no-untyped-def]
        mark = "[green]pass[/]" if c.passed else "[bold red]FAIL[/]"
        err_console.print(f"{mark} {c.name}: error {c.error:.3g} (tolerance {c.tolerance:.3g})",
                          highlight=False)
        table.add_row(c.name, f"{c.measured:.6g} {c.unit}", f"{c.expected:.6g}", f"{c.error:.3g}",
                      f"{c.tolerance:.3g}", mark)

    checks = run_verification(out, quick=quick, on_check=show)
    console.print(table)
    console.print(f"written: {out / 'verification.json'}", highlight=False)
    if not all(c.passed for c in checks):
        raise typer.Exit(1)


@app.command()
def validate(
    name: Annotated[str | None, typer.Argument(help="scene to run (see --list)")] = None,
    list_only: Annotated[bool, typer.Option("--list", help="name each scene, its source and what "
                                            "it measures, and exit")] = False,
    out: Annotated[
        Path, typer.Option("--out", "-o", help="where the runs, validation.json, CSVs and plots go")
    ] = Path("runs/validate"),
    scale: Annotated[
        str | None, typer.Option("--scale", help="small (minutes, a check of the chain), section "
                                 "(periodic section, the comparison) or full (the whole drum)")
    ] = None,
    timeout: Annotated[float | None, typer.Option("--timeout", min=1, help="solver time limit, s")] = None,
) -> None:
    """Compare with experiments: run a validation scene and write validation.json, a CSV and a plot."""
    from drumflow.readers import output_folder
    from drumflow.validate import SCENES

    if list_only or name is None:
        for sc in SCENES.values():
            console.print(f"[bold]{sc.name}[/]: {escape(sc.title)}", highlight=False)
            console.print(f"  source: {escape(sc.source)}", highlight=False)
            for m in sc.measures:
                console.print(f"  measures: {escape(m)}", highlight=False)
            console.print(f"  scales: {', '.join(sc.scales)} (default {sc.scales[0]})", highlight=False)
        if name is None and not list_only:
            raise typer.BadParameter("give a scene name, or --list", param_hint="NAME")
        return
    from drumflow.validate.run import run_validation

    output_folder(out)
    with StageProgress(err_console) as progress:
        record = run_validation(name, out, scale, timeout=timeout, progress=progress)
    table = Table(title=f"drumflow validate {name} ({record['scale']})")
    for col in ("observable", "simulated", "measured", "error", "band", ""):
        table.add_column(col, justify="right" if col not in ("observable", "") else "left")
    for key, m in record["comparison"].items():
        def num(v: Any) -> str:
            return "n/a" if v is None else f"{v:.4g}"
        err = m["error"]
        err_text = "n/a" if err is None else (f"{100 * err:+.1f} %" if m["error_kind"] == "relative"
                                              else f"{1e3 * err:+.1f} mm")
        band = f"{100 * m['band']:g} %" if m["error_kind"] == "relative" else f"{1e3 * m['band']:g} mm"
        table.add_row(key, num(m["simulated"]), num(m["measured"]), err_text, band,
                      "[green]within[/]" if m["within_band"] else "[bold red]outside[/]")
    console.print(table)
    console.print(f"written: {out / 'validation.json'}, {out / record['csv']}, {out / record['plot']}",
                  highlight=False)


@app.command()
def bench(
    case_file: Annotated[Path, typer.Argument(help="reference scene: a case file (TOML)")],
    out: Annotated[Path | None, typer.Option("--out", "-o", help="bench directory")] = None,
    rungs: Annotated[
        str | None, typer.Option("--rungs", help="comma-separated rung names (default: all)")
    ] = None,
    time_s: Annotated[
        float | None,
        typer.Option("--time", min=0.01, help="simulated time per rung, s (default: the case's)"),
    ] = None,
    timeout: Annotated[
        float | None, typer.Option("--timeout", min=1, help="solver time limit per rung, s")
    ] = None,
    list_only: Annotated[bool, typer.Option("--list", help="list the rungs and exit")] = False,
    speed_only: Annotated[
        bool, typer.Option("--speed-only", help="no reference rung: run times only")
    ] = False,
    from_run: Annotated[
        Path | None, typer.Option("--from", help="LIGGGHTS settings side by side from a restart of "
                                  "this coupled run of the case (paper scale: the cascading bed)")
    ] = None,
    steps: Annotated[
        int, typer.Option("--steps", min=1, help="with --from: DEM steps per variant")
    ] = 400,
    restart: Annotated[
        int | None, typer.Option("--restart", min=0, help="with --from: restart step (default: newest)")
    ] = None,
    ranks: Annotated[
        int | None, typer.Option("--np", min=1, help="with --from: MPI ranks (default: the case's)")
    ] = None,
) -> None:
    """Run time against error: a ladder of settings on one scene -> results.csv and pareto.png.

    With --from RUN_DIR: LIGGGHTS' settings (neighbour skin, rebuild rule, sorting, processor
    grid, the conservative reference) side by side from one restart of that run -> settings.csv.
    """
    from drumflow.readers import output_folder

    if out is not None:
        output_folder(out)
    case = _load(case_file)
    if from_run is not None:
        if time_s is not None or speed_only:
            raise typer.BadParameter("--time and --speed-only are for the ladder from a fresh "
                                     "start, not with --from", param_hint="--from")
        _bench_from_run(case, from_run, out, rungs, steps, restart, ranks, timeout, list_only)
        return
    from drumflow.bench import run_bench
    from drumflow.bench.ladder import ladder, select
    from drumflow.case import case_from_dict

    if time_s is not None:
        data = case.model_dump(mode="json")
        data["run"]["time"] = time_s
        data["run"]["mass_flow_start"] = min(case.run.mass_flow_start, 0.5 * time_s)
        case = case_from_dict(data, source=case_file)
    names = [n.strip() for n in rungs.split(",") if n.strip()] if rungs else None
    try:
        chosen = select(ladder(case), names, speed_only)
    except ValueError as exc:  # an unknown rung name: bad input, exit 2 through click
        raise typer.BadParameter(str(exc), param_hint="--rungs") from None
    if list_only:
        for r in chosen:
            console.print(f"{r.name:18s} {r.group:12s} {r.description}", highlight=False)
        return
    out = out or Path("runs") / "bench" / case.name
    t0 = time.monotonic()

    def on_rung(rung, index: int, total: int, row: dict) -> None:  # type: ignore[no-untyped-def]
        elapsed = time.monotonic() - t0
        eta = elapsed / (index + 1) * (total - index - 1)
        wall = row.get("dem_wall_time_s")
        wall_txt = f"{wall:.1f} s" if isinstance(wall, (int, float)) else "-"
        err_console.print(f"[{index + 1}/{total}] {rung.name}: {row['status'][:120]}, DEM {wall_txt} "
                          f"(elapsed {elapsed / 60:.1f} min, ETA {eta / 60:.1f} min)", highlight=False)

    try:
        result = run_bench(case, out, names, timeout=timeout, on_rung=on_rung, speed_only=speed_only)
    except KeyboardInterrupt:
        err_console.print(f"run the same command again to resume into {out}")
        raise
    cols = [("rung", "rung", "{}"), ("dt/t_R", "fraction_of_rayleigh", "{:.2f}"),
            ("DEM s", "dem_wall_time_s", "{:.1f}"), ("speed-up", "speedup_vs_conservative", "{:.2f}"),
            ("err T", "err_temperature", "{:.2%}"), ("err h", "err_h", "{:.2%}"),
            ("err ṁ", "err_mass_flow", "{:.2%}"), ("front", "pareto", "{}")]
    console.print(_frame_table(f"drumflow bench {case.name} → {out}", result.table, cols))
    console.print(f"written: {result.csv}, {result.json}, {result.plot}", highlight=False)
    failed = [str(r["rung"]) for _, r in result.table.iterrows() if str(r["status"]).startswith("failed")]
    if failed:
        # A rung whose run failed is a failed run (exit 1), even though the table was written.
        err_console.print(f"[bold red]failed rung(s):[/] {', '.join(failed)}", highlight=False)
        raise typer.Exit(1)


def _frame_table(title: str, frame: Any, cols: list[tuple[str, str, str]], clip: int | None = None,
                 box_style: box.Box = box.HEAVY_HEAD) -> Table:
    """A table of a results frame: one column per (title, key, format); a missing or NaN value
    is blank; each cell cut to ``clip`` characters (a long status)."""
    table = Table(title=title, box=box_style)
    for column, _, _ in cols:
        table.add_column(column)
    for _, r in frame.iterrows():
        cells = []
        for _, key, fmt in cols:
            v = r.get(key)
            cells.append("" if v is None or (isinstance(v, float) and v != v) else fmt.format(v)[:clip])
        table.add_row(*cells)
    return table


def _bench_from_run(case: Any, run_dir: Path, out: Path | None, rungs: str | None, steps: int,
                    restart: int | None, ranks: int | None, timeout: float | None,
                    list_only: bool) -> None:
    from drumflow.bench.settings import VARIANTS, run_settings_study

    if list_only:
        for v in VARIANTS:
            console.print(f"{v.name:22s} {v.description}", highlight=False)
        return
    names = [n.strip() for n in rungs.split(",") if n.strip()] if rungs else None
    out = out or Path("runs") / "bench" / case.name / "settings"
    ranks = ranks or case.run.processes
    t0 = time.monotonic()

    def on_variant(variant, index: int, total: int, row: dict | None) -> None:  # type: ignore[no-untyped-def]
        elapsed = time.monotonic() - t0
        if row is None:
            err_console.print(f"[{index + 1}/{total}] {variant.name}: {steps} steps of the baseline's "
                              f"time from the restart on {ranks} rank(s)... (elapsed {elapsed / 60:.1f} "
                              "min)", highlight=False)
            return
        eta = elapsed / (index + 1) * (total - index - 1)
        err_console.print(f"  {row['particle_steps_per_s']:,.0f} particle-steps/s, physics "
                          f"{'ok' if row['physics_ok'] else 'CHANGED'} (ETA {eta / 60:.1f} min)",
                          highlight=False)

    result = run_settings_study(case, run_dir, out, steps=steps, ranks=ranks, restart_step=restart,
                                only=names, timeout=timeout or 3600.0, on_variant=on_variant)
    cols = [("variant", "variant", "{}"), ("status", "status", "{}"),
            ("wall s", "coupled_wall_s", "{:.1f}"), ("particle-steps/s", "particle_steps_per_s", "{:,.0f}"),
            ("speed-up", "speedup_vs_baseline", "{:.2f}"), ("pair %", "pair_pct", "{:.0f}"),
            ("neigh %", "neigh_pct", "{:.0f}"), ("walls %", "walls_pct", "{:.0f}"),
            ("physics", "physics_ok", "{}")]
    console.print(_frame_table(f"drumflow bench {case.name} --from {run_dir} → {out}", result.table,
                               cols, clip=40, box_style=box.SIMPLE))
    if result.resumed:
        console.print(f"kept from the interrupted study: {', '.join(result.resumed)}", highlight=False)
    console.print(f"written: {result.csv}, {result.json}", highlight=False)
    if result.failed:
        err_console.print(f"[bold red]failed variant(s):[/] {', '.join(result.failed)}", highlight=False)
        raise typer.Exit(1)


@app.command()
def profile(
    run_dir: Annotated[Path, typer.Argument(help="run directory written by `drumflow run`")],
    window: Annotated[
        float, typer.Option("--window", min=1e-6, help="summary window, simulated seconds")
    ] = 0.5,
    out: Annotated[
        Path | None, typer.Option("--out", "-o", help="folder for profile.csv and profile.png "
                                  "(default: RUN_DIR/post)")
    ] = None,
    as_json: Annotated[bool, typer.Option("--json", help="print the windows as JSON")] = False,
) -> None:
    """Where the time goes: LIGGGHTS' timing breakdowns and the coupling loop's wall times."""
    from drumflow.bench.profile import profile_run, write_profile
    from drumflow.readers import output_folder
    from drumflow.rundir import RunDir

    if out is not None:
        output_folder(out)  # checked first: the profile of a long run takes a while
    result = profile_run(run_dir, window_s=window)
    folder = out or RunDir.existing(run_dir).post
    paths = write_profile(result, folder, title=f"{run_dir.name}: where the time goes")
    if as_json:
        console.print_json(json.dumps({"windows": json.loads(result.windows.to_json(orient="records")),
                                       "files": {k: str(v) for k, v in paths.items()}}))
        return
    # Comm without the fixes' own communication, which LIGGGHTS also counts in the fixes.
    table = Table(title=f"{run_dir.name}: where the time goes, per {window:g} s simulated "
                  "(% of LIGGGHTS' loop in sampled intervals; comm outside the fixes)")
    cols = [("window (s)", None, ""), ("steps", "steps", "{:,.0f}"), ("pair", "pair_pct", "{:.1f}"),
            ("neigh", "neigh_pct", "{:.1f}"), ("walls", "walls_pct", "{:.1f}"),
            ("conduction", "conduction_pct", "{:.1f}"), ("air drag", "air_drag_pct", "{:.1f}"),
            ("comm", "comm_outside_fixes_pct", "{:.1f}"), ("output", "output_pct", "{:.1f}"),
            ("other", "other_net_pct", "{:.1f}"), ("neighs/atom", "neighs_per_atom", "{:.2f}"),
            ("builds/1000", "neighbor_builds_per_1000_steps", "{:.1f}"),
            ("Python %", "python_share", "{:.1%}"), ("particle-steps/s", "particle_steps_per_s", "{:,.0f}")]
    for title, _, _ in cols:
        table.add_column(title, justify="left" if title.startswith("window") else "right")
    for _, w in result.windows.iterrows():
        cells = [f"{w['window_start_s']:g}-{w['window_end_s']:g}"]
        for _, key, fmt in cols[1:]:
            value = w.get(key)
            cells.append("-" if value is None or value != value else fmt.format(value))
        table.add_row(*cells)
    console.print(table)
    console.print(f"{len(result.intervals)} sampled intervals; written: "
                  + ", ".join(str(p) for p in paths.values()), highlight=False)


@app.command()
def answer(
    run_dir: Annotated[Path, typer.Argument(help="run directory after `drumflow post`, or a shipped "
                                            "results folder (case.toml, post/)")],
    tolerance: Annotated[
        float, typer.Option("--tolerance", help="the stop rule's largest relative half-width, and "
                            "how close to the reference counts as settled")
    ] = 0.01,
    every: Annotated[
        float, typer.Option("--every", help="spacing of the replayed end times, simulated seconds")
    ] = 0.1,
    rate: Annotated[
        float | None, typer.Option("--rate", help="particle-steps per wall second for updates "
                                   "without logged wall times (default: the logged ones', else "
                                   "run_record.json)")
    ] = None,
    out: Annotated[
        Path | None, typer.Option("--out", "-o", help="folder for answer.csv, answer.json and "
                                  "answer.png (default: RUN_DIR/post)")
    ] = None,
    as_json: Annotated[bool, typer.Option("--json", help="print answer.json instead of a table")] = False,
) -> None:
    """Time to answer: what a run stopped earlier would report, and when the stop rule fires."""
    from drumflow.bench.answer import QUANTITIES, replay_answer, write_answer
    from drumflow.readers import output_folder
    from drumflow.rundir import RunDir

    if out is not None:
        output_folder(out)  # checked first: the replay of a long run takes a while
    replay = replay_answer(run_dir, tolerance=tolerance, settle_tolerance=tolerance,
                           check_interval_s=every, particle_steps_per_s=rate)
    folder = out or RunDir.existing(run_dir).post
    paths = write_answer(replay, folder, title=f"{run_dir.name}: time to answer")
    summary = replay.to_dict()
    if as_json:
        console.print_json(json.dumps({**summary, "files": {k: str(v) for k, v in paths.items()}}))
        return
    table = Table(title=f"{run_dir.name}: what a run stopped at t reports (Δ: against "
                  f"{replay.reference_time_s:.4g} s; rule: widest interval, fires at ±{tolerance:.0%})",
                  box=box.SIMPLE, padding=(0, 1))
    cols = [("t s", "time_s", "{:.2f}"), ("T3.5 °C", "temperature_C", "{:.3f}"),
            ("Δ", "rel_temperature", "{:+.2%}"), ("ṁ kg/s", "mass_flow_kg_s", "{:.2f}"),
            ("Δ", "rel_mass_flow", "{:+.1%}"), ("h W/m²K", "h_W_m2K", "{:.2f}"),
            ("Δ", "rel_h", "{:+.2%}"), ("rule ±", "converged", "{}"), ("wall s", "wall_s", "{:,.0f}")]
    for title, _, _ in cols:
        table.add_column(title, justify="right")
    for _, row in replay.table.iterrows():
        cells = []
        for _, key, fmt in cols:
            value = row[key]
            if key == "converged":
                # The wider of the two intervals the rule compares with the tolerance.
                widest = max(row["monitor_h_rel_half_width"], row["monitor_mass_flow_rel_half_width"])
                cells.append("fires" if value else "-" if widest != widest else f"{widest:.1%}")
            else:
                cells.append("-" if value is None or value != value else fmt.format(value))
        table.add_row(*cells)
    console.print(table)
    rule = summary["rule"]
    if rule["first_fire_s"] is None:
        console.print(f"stop rule: {rule['reason']}", highlight=False)
    else:
        console.print(f"stop rule: fires at {rule['first_fire_s']:.4g} s (wall "
                      f"{rule['wall_at_first_fire_s'] or float('nan'):,.0f} s): {rule['reason']}",
                      highlight=False)
    for name, (_, label) in QUANTITIES.items():
        when = replay.settled_s[name]
        value = summary["reference"]["values"][name]
        console.print(f"{label} = {value:.6g}: within {tolerance:.0%} from "
                      f"{'never' if when is None else f'{when:.4g} s'}", highlight=False)
    steady = replay.settled_s["steady_mass_flow"]
    ref = summary["reference"]
    console.print(f"falling mass flow of the cascading bed (window from "
                  f"{ref['steady_start_s']:.3g} s, MSER) = {ref['steady_mass_flow_kg_s']:.6g}: within "
                  f"{tolerance:.0%} from {'never' if steady is None else f'{steady:.4g} s'}",
                  highlight=False)
    wall = replay.wall
    console.print(f"wall time: {wall['source']} (rate {wall['particle_steps_per_s'] or float('nan'):,.0f} "
                  f"particle-steps/s from {wall['rate_source']})", highlight=False)
    for note in replay.notes:
        console.print(f"note: {note}", highlight=False)
    console.print("written: " + ", ".join(str(p) for p in paths.values()), highlight=False)


@app.command()
def ladder(
    spec: Annotated[Path, typer.Argument(help="ladder spec (TOML): the rungs' runs, how each "
                                         "stops, the reference")],
    out: Annotated[
        Path | None, typer.Option("--out", "-o", help="folder for ladder.csv, ladder.json and "
                                  "ladder.png (default: the spec's folder)")
    ] = None,
    as_json: Annotated[bool, typer.Option("--json", help="print ladder.json instead of a table")] = False,
) -> None:
    """Time-to-answer ladder: wall time and errors of several runs of a scene against one
    reference run (runs are replayed, not rerun)."""
    from drumflow.bench.time_to_answer import (
        LADDER_QUANTITIES,
        answer_ladder,
        load_ladder_spec,
        write_ladder,
    )
    from drumflow.readers import output_folder

    if out is not None:
        output_folder(out)
    result = answer_ladder(load_ladder_spec(spec))
    paths = write_ladder(result, out or spec.parent)
    if as_json:
        console.print_json(json.dumps({**result.to_dict(),
                                       "files": {k: str(v) for k, v in paths.items()}}))
        return
    answers = result.spec.answers
    table = Table(title=f"{result.spec.title} (errors against '{result.spec.reference}'; "
                  f"answer known within ±{result.spec.tolerance:.0%})", box=box.SIMPLE,
                  padding=(0, 1))
    for title in ("rung", "stop", "at s", "wall h", "faster",
                  *(f"Δ {LADDER_QUANTITIES[q].short}" for q in answers), "known"):
        table.add_column(title, justify="left" if title in ("rung", "stop") else "right")
    for _, row in result.table.iterrows():
        wall = row["wall_s"]
        cells = [row["rung"], row["stop"],
                 "never" if row["stop_time_s"] != row["stop_time_s"] else f"{row['stop_time_s']:.3g}",
                 "-" if wall != wall else f"{wall / 3600:.2f}{'*' if row['wall_estimated'] else ''}",
                 "-" if row["speedup"] != row["speedup"] else f"{row['speedup']:.2f}×",
                 *(f"{row[f'error_{q}']:+.2%}" for q in answers),
                 "yes" if row["within_tolerance"] else "no"]
        table.add_row(*cells)
    console.print(table)
    floor = ", ".join(f"{q} ±{result.noise_floor[q]:.2%}" for q in answers)
    console.print(f"noise floor (the reference's batch-means half-widths): {floor}; "
                  "* wall time estimated (scaled or partly from a rate)", highlight=False)
    for _, row in result.table.iterrows():
        console.print(f"{row['rung']}: {row['note']}", highlight=False)
    console.print("written: " + ", ".join(str(p) for p in paths.values()), highlight=False)


# Last, after every command (and the groups above) is registered: one wrapper for all.
guard_every_command(app)


_interrupts = 0


def _interrupt(signum: int, frame: object) -> None:
    """SIGINT and SIGTERM: say once what happens now, then raise KeyboardInterrupt (a coupled run
    writes a restart at its next air update before it stops; a second interrupt stops at once)."""
    global _interrupts
    _interrupts += 1
    if _interrupts == 1:
        sys.stderr.write(f"\n{signal.Signals(signum).name}: stopping (a run with air first writes a "
                         "restart at its next air update; interrupt again to stop at once)\n")
    raise KeyboardInterrupt


def main() -> None:
    """Console-script entry point."""
    # SIGTERM (`kill`, a SLURM time limit, the end of a login session) ends a command as Ctrl-C
    # does: the runner stops the solver's process group and the run resumes from its restart.
    # Python's default would end the CLI at once and leave mpirun and its ranks running.
    signal.signal(signal.SIGTERM, _interrupt)
    # Python installs its Ctrl-C handler only where SIGINT is not ignored (a background job of
    # a script): an ignored SIGINT stays ignored.
    if signal.getsignal(signal.SIGINT) is signal.default_int_handler:
        signal.signal(signal.SIGINT, _interrupt)
    try:
        app()
    except KeyboardInterrupt:  # Ctrl-C outside a command (while parsing arguments)
        sys.exit(130)


if __name__ == "__main__":
    main()
