"""`drumflow export RUN_DIR --vtk | --animation`: a run directory as ParaView files, or as an
animated GIF of the section coloured by temperature (Figure 6 in motion).

Exit codes (:func:`drumflow.errors.exit_code`): 0 written, 2 bad input (no format chosen, not a
run directory, missing snapshots or geometry).
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Annotated, Optional

import typer
from rich.table import Table

from drumflow.cli_guard import cli_console
from drumflow.errors import RunDirectoryError

console = cli_console()


def export(
    run_dir: Annotated[Path, typer.Argument(help="run directory written by `drumflow run`")],
    vtk: Annotated[bool, typer.Option(
        "--vtk", help="particles (.vtu + .pvd), walls at each snapshot's drum angle, air (.vti)")] = False,
    animation: Annotated[bool, typer.Option(
        "--animation", help="the section coloured by temperature at every snapshot, as a GIF "
        "(RUN_DIR/post/section_temperature.gif unless --out)")] = False,
    speed: Annotated[float, typer.Option(
        "--seconds-per-simulated-second", min=0.01, max=100.0,
        help="--animation: playback seconds per simulated second")] = 1.0,
    out: Annotated[Optional[Path], typer.Option(
        "--out", "-o", help="output folder (--vtk, default RUN_DIR/vtk) or GIF file (--animation)")] = None,
    as_json: Annotated[bool, typer.Option("--json", help="print what was written as JSON")] = False,
) -> None:
    """Write a run's snapshots, walls and air field for ParaView, or its section animation."""
    from drumflow.report.vtk import export_vtk

    if vtk == animation:
        raise RunDirectoryError("choose one export format: --vtk or --animation")
    if animation:
        _animation(run_dir, out, speed, as_json)
        return
    result = export_vtk(run_dir, out)
    if as_json:
        console.print_json(json.dumps(result.as_dict()))
        return
    table = Table(title=f"{run_dir} → {result.out}", show_header=False)
    times = result.times_s
    table.add_row("particles", f"{result.particles_pvd}: {len(times)} snapshots, "
                  f"t = {times[0]:.3g}-{times[-1]:.3g} s, {max(result.particles):,} particles")
    table.add_row("walls", f"{result.walls_pvd}: turned by the drum angle at each snapshot")
    table.add_row("air", result.air or "none (the run has no air)")
    table.add_row("size", f"{result.bytes_written / 1e6:.2f} MB binary "
                  f"(text snapshots: {result.snapshot_text_bytes / 1e6:.2f} MB)")
    console.print(table)
    console.print(f"open in ParaView: paraview {Path(result.out) / result.particles_pvd} "
                  f"{Path(result.out) / result.walls_pvd}", highlight=False)


def _animation(run_dir: Path, out: Path | None, speed: float, as_json: bool) -> None:
    from drumflow.case import load_case
    from drumflow.report.animation import render_animation
    from drumflow.rundir import RunDir

    run = RunDir.existing(run_dir)
    result = render_animation(run, load_case(run.case_toml), out, seconds_per_simulated_second=speed)
    if as_json:
        console.print_json(json.dumps(result.as_dict()))
        return
    times = result.times_s
    console.print(f"{result.path}: {result.frames} frames, t = {times[0]:.3g}-{times[-1]:.3g} s at "
                  f"{result.fps:.3g} frames/s, colour scale {result.temperature_range_C[0]:.2f}-"
                  f"{result.temperature_range_C[1]:.2f} °C", highlight=False)
    if result.skipped:
        console.print(f"[yellow]unreadable snapshots skipped: {', '.join(result.skipped)}[/yellow]")
