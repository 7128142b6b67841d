"""`drumflow export RUN_DIR --vtk`: a run directory as ParaView files.

Exit codes (:func:`drumflow.errors.exit_code`): 0 written, 2 bad input (no format chosen, not a
run directory, missing snapshots or geometry).
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Annotated, Optional

import typer
from rich.console import Console
from rich.table import Table

from drumflow.errors import RunDirectoryError

console = Console()


def export(
    run_dir: Annotated[Path, typer.Argument(help="run directory written by `drumflow run`")],
    vtk: Annotated[bool, typer.Option(
        "--vtk", help="particles (.vtu + .pvd), walls at each snapshot's drum angle, air (.vti)")] = False,
    out: Annotated[Optional[Path], typer.Option(
        "--out", "-o", help="output folder (default RUN_DIR/vtk)")] = None,
    as_json: Annotated[bool, typer.Option("--json", help="print what was written as JSON")] = False,
) -> None:
    """Write a run's snapshots, walls and air field for ParaView."""
    from drumflow.report.vtk import export_vtk

    if not vtk:
        raise RunDirectoryError("no export format chosen; allowed: --vtk")
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
