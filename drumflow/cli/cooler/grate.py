"""`drumflow cooler grate CASE [--vary FIELD=START:STOP:COUNT]`: the clinker grate cooler."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Annotated, Any, Optional

import typer
from rich.table import Table

from drumflow.cli.cooler._app import app, console, err_console, guard

_VARY_HELP = (
    "sweep one field: FIELD=START:STOP:COUNT or FIELD=V1,V2,...; FIELD is grate_speed, "
    "clinker_flow, air_flow, clinker_inlet_temperature, air_inlet_temperature, "
    "particle_diameter, bed_porosity, emissivity, length, width, fan_pressure, "
    "fan_free_delivery, or section.field (air_flow only with air.supply = 'fixed': a fan "
    "case solves it)"
)


@app.command("grate")
def grate(
    case_file: Annotated[Path, typer.Argument(help="grate-cooler case file (TOML)")],
    out: Annotated[Optional[Path], typer.Option("--out", "-o", help="run directory")] = None,
    vary: Annotated[Optional[str], typer.Option("--vary", help=_VARY_HELP)] = None,
    force: Annotated[bool, typer.Option("--force", help="reuse a directory of another case")] = False,
    as_json: Annotated[bool, typer.Option("--json", help="print the result as JSON")] = False,
) -> None:
    """Clinker grate cooler: cross-flow balance cells solved by line-by-line TDMA (the
    IIT Madras / NCL report); prints outlet temperatures, recovered heat, efficiency. With
    air.supply = "fan" the air flow is where the fan curve meets the bed's Ergun pressure
    drop (cases/grate_cooler_fans.toml); a --vary study prints where the recovered heat
    and the secondary air are largest."""
    from drumflow.coolers.model_runs import run_grate

    with guard():
        run = run_grate(case_file, out, vary, force)
        if run.vary is None:
            assert run.summary is not None
            _print_single(run.summary, run.root, as_json)
        else:
            _print_sweep(run.vary, run.rows, run.maxima, run.root, as_json)


def _print_single(summary: dict[str, Any], out: Path, as_json: bool) -> None:
    if as_json:
        console.print_json(json.dumps(summary))
        return
    table = Table(title="clinker grate cooler", show_header=True)
    table.add_column("quantity")
    table.add_column("value", justify="right")
    shown = (
        ("clinker outlet (caloric)", f"{summary['clinker_outlet_temperature_K']:.1f} K"),
        ("secondary air (freeboard, kiln end)", f"{summary['secondary_air_temperature_K']:.1f} K"),
        ("heat recovered by the air", f"{summary['heat_recovered_MW']:.2f} MW"),
        (f"air flow ({'fan operating point' if summary['air_supply'] == 'fan' else 'given'})",
         f"{summary['air_flow_kg_s']:.3f} kg/s"),
        ("bed pressure drop (Ergun)", f"{summary['bed_pressure_drop_Pa']:.0f} Pa"),
        ("heat duty (clinker to air inlet T)", f"{summary['heat_duty_MW']:.2f} MW"),
        ("cooler efficiency", f"{100 * summary['cooler_efficiency']:.1f} %"),
        ("radiation bed top -> freeboard", f"{summary['radiation_heat_MW']:.3f} MW"),
        ("bed height", f"{summary['bed_height_m']:.3f} m"),
        ("residence time", f"{summary['residence_time_s']:.0f} s"),
        ("mean h (packed bed)", f"{summary['h_mean_W_m2K']:.0f} W/(m2 K)"),
        ("cells (length x height)", f"{summary['cells'][0]} x {summary['cells'][1]}"),
        ("sweeps / residual", f"{summary['sweeps']} / {summary['residual']:.1e}"),
        ("energy imbalance", f"{summary['energy_imbalance']:.1e}"),
        ("solve time", f"{summary['wall_time_s']:.2f} s"),
    )
    for name, value in shown:
        table.add_row(name, value)
    if "fan_pressure_Pa" in summary:
        table.add_row("fan pressure rise (curve)", f"{summary['fan_pressure_Pa']:.0f} Pa")
    console.print(table)
    err_console.print(f"results in {out}")


def _print_sweep(field: str, rows: list[dict[str, float]], peaks: dict[str, dict[str, Any]],
                 out: Path, as_json: bool) -> None:
    if as_json:
        console.print_json(json.dumps({"vary": field, "rows": rows, "maxima": peaks}))
        return
    table = Table(title=f"clinker grate cooler: varying {field}", show_header=True)
    for name in (field, "clinker outlet (K)", "secondary air (K)", "recovered (MW)",
                 "efficiency (%)", "air (kg/s)", "bed dp (Pa)", "bed height (m)", "solve (s)"):
        table.add_column(name, justify="right")
    for r in rows:
        table.add_row(f"{r[field]:.4g}", f"{r['clinker_outlet_K']:.1f}",
                      f"{r['secondary_air_K']:.1f}", f"{r['heat_recovered_MW']:.2f}",
                      f"{100 * r['efficiency']:.1f}", f"{r['air_flow_kg_s']:.2f}",
                      f"{r['bed_pressure_drop_Pa']:.0f}", f"{r['bed_height_m']:.3f}",
                      f"{r['wall_time_s']:.2f}")
    console.print(table)
    for column, what, unit, digits in (("heat_recovered_MW", "recovered heat", "MW", 2),
                                       ("secondary_air_K", "secondary air", "K", 1)):
        p = peaks[column]
        where = ("inside the range" if p["interior"]
                 else "at the end of the range: no maximum inside it")
        console.print(f"largest {what}: {p['value']:.{digits}f} {unit} at {field} = "
                      f"{p['at']:.4g} ({where})")
    err_console.print(f"results in {out}")
