"""The drumflow command line: the only place that prints or exits.

Exit codes: 0 success, 1 a run failed (solver error, lost particles), 2 bad input (case file,
arguments, run directory), 130 interrupted (rerun the same command to resume).
"""

from __future__ import annotations

import json
import sys
from pathlib import Path
from typing import Annotated, Optional

import typer
from rich.console import Console
from rich.progress import (
    BarColumn,
    Progress,
    TextColumn,
    TimeElapsedColumn,
    TimeRemainingColumn,
)
from rich.table import Table

from drumflow.errors import CaseError, DrumflowError, LostParticlesError, RunDirectoryError

app = typer.Typer(
    add_completion=False,
    no_args_is_help=True,
    pretty_exceptions_enable=False,
    help="CFD-DEM studies of flighted rotary-drum coolers (LIGGGHTS, OpenFOAM).",
)
console = Console()
err_console = Console(stderr=True)


def _fail(exc: BaseException, code: int) -> None:
    err_console.print(f"[bold red]error:[/] {exc}", highlight=False)
    raise typer.Exit(code)


def _load(case_file: Path):  # type: ignore[no-untyped-def]
    from drumflow.case import load_case

    return load_case(case_file)


@app.command()
def check(case_file: Annotated[Path, typer.Argument(help="case file (TOML)")]) -> None:
    """Validate a case file without running anything."""
    try:
        case = _load(case_file)
        from drumflow.dem.timestep import choose_time_step
        from drumflow.pipeline import refuse_unavailable

        refuse_unavailable(case)
        choice = choose_time_step(case)
    except CaseError as exc:
        _fail(exc, 2)
        return
    table = Table(title=f"case {case.name}: valid", show_header=False)
    table.add_row("drum", f"D {case.drum.diameter:g} m, l {case.drum.length:g} m, {case.drum.rpm:g} rpm, "
                  f"tilt {case.drum.tilt_deg:g}°, Froude {case.drum.froude:.3f}")
    table.add_row("lifters", f"{case.lifters.count} × {case.lifters.profile}")
    table.add_row("particles", f"{case.particle_count:,} × {case.particles.diameter * 1e3:g} mm, "
                  f"{case.particle_mass_total:.4g} kg")
    table.add_row("time step", f"{choice.time_step:.3g} s ({choice.mode}; {choice.fraction_of_rayleigh:.0%} "
                  f"of Rayleigh {choice.rayleigh_time:.3g} s; {choice.steps_per_contact:.0f} steps per contact)")
    table.add_row("steps", f"{round(case.run.time / choice.time_step):,} for {case.run.time:g} s")
    console.print(table)


@app.command()
def run(
    case_file: Annotated[Path, typer.Argument(help="case file (TOML)")],
    out: Annotated[Optional[Path], typer.Option("--out", "-o", help="run directory")] = None,
    np_: Annotated[Optional[int], typer.Option("--np", min=1, help="MPI processes")] = None,
    steps: Annotated[Optional[int], typer.Option("--steps", min=1, help="short run: only this many DEM steps")] = None,
    timeout: Annotated[Optional[float], typer.Option("--timeout", min=1, help="solver time limit, s")] = None,
    force: Annotated[bool, typer.Option("--force", help="reuse a directory of another case")] = False,
    as_json: Annotated[bool, typer.Option("--json", help="print the summary as JSON")] = False,
) -> None:
    """Run a case end to end (geometry, DEM, observables, plots) into a run directory."""
    from drumflow.pipeline import run_case

    try:
        case = _load(case_file)
    except CaseError as exc:
        _fail(exc, 2)
        return
    out = out or Path("runs") / case.name
    columns = (
        TextColumn("[bold]{task.description}"),
        BarColumn(),
        TextColumn("{task.fields[sim]}"),
        TimeElapsedColumn(),
        TextColumn("ETA"),
        TimeRemainingColumn(),
    )
    try:
        with Progress(*columns, console=err_console, transient=False) as bar:
            tasks: dict[str, int] = {}

            def progress(stage: str, done: float, total: float) -> None:
                if stage not in tasks:
                    tasks[stage] = bar.add_task(stage, total=total, sim="")
                sim = f"{done:.3f}/{total:.3f} s simulated" if stage == "dem" else ""
                bar.update(tasks[stage], completed=done, sim=sim)

            summary = run_case(case, out, processes=np_, steps=steps, timeout=timeout,
                               progress=progress, force=force)
    except (CaseError, RunDirectoryError) as exc:
        _fail(exc, 2)
        return
    except LostParticlesError as exc:
        _fail(exc, 1)
        return
    except DrumflowError as exc:
        _fail(exc, 1)
        return
    except KeyboardInterrupt:
        err_console.print(f"interrupted; run the same command again to resume into {out}")
        raise typer.Exit(130) from None
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

    try:
        summary = post_run(run_dir)
    except DrumflowError as exc:
        _fail(exc, 2)
        return
    _print_summary(summary, run_dir, as_json)


def main() -> None:
    """Console-script entry point."""
    try:
        app()
    except KeyboardInterrupt:
        sys.exit(130)


if __name__ == "__main__":
    main()
