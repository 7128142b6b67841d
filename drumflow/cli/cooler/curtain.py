"""`drumflow cooler curtain CASE`: the particle-curtain model (Wardjiman and Rhodes 2009)."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Annotated

import typer
from rich.table import Table

from drumflow.cli.cooler._app import app, console, guard


@app.command("curtain")
def curtain(
    case_file: Annotated[Path, typer.Argument(help="curtain case file (TOML)")],
    out: Annotated[Path | None, typer.Option("--out", "-o", help="run directory")] = None,
    as_json: Annotated[bool, typer.Option("--json", help="print the result as JSON")] = False,
    force: Annotated[bool, typer.Option("--force", help="reuse a directory of another case")] = False,
) -> None:
    """Heat transfer in a particle curtain crossed by a gas stream (element-array model)."""
    # Imported here so that other commands do not load the model (and scipy) at start-up.
    from drumflow.coolers.model_runs import run_curtain

    with guard():
        run = run_curtain(case_file, out, force)
    case, result, payload, plot = run.case, run.result, run.payload, run.plot
    if as_json:
        console.print_json(json.dumps(payload))
        return
    table = Table(title=f"{case.name}: particle curtain ({case.source or 'curtain model'})",
                  show_header=False)
    table.add_row("heat duty (gas to solids)", f"{result.heat_to_solids_w:.1f} W")
    table.add_row("solids in -> out", f"{case.solids.inlet_temperature_C:.2f} -> "
                  f"{result.solids_outlet_C:.2f} °C")
    table.add_row("gas in -> out (mixed)", f"{case.gas.inlet_temperature_C:.2f} -> "
                  f"{result.gas_outlet_C:.2f} °C")
    table.add_row("h (Ranz-Marshall), Biot", f"{result.h_w_m2k:.1f} W/(m² K), {result.biot:.3f}")
    table.add_row("voidage", f"{result.voidage:.5f}")
    table.add_row("grid M x N, time per row", f"{result.rows} x {result.columns}, "
                  f"{1e3 * result.contact_time_s:.2f} ms")
    table.add_row("energy residual", f"{result.energy_residual:.1e}")
    table.add_row("written", f"{run.root / 'result.json'}, {plot}")
    console.print(table)
