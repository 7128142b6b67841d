"""`drumflow cooler grate CASE [--vary FIELD=START:STOP:COUNT]`: the clinker grate cooler."""

from __future__ import annotations

import json
import time
from pathlib import Path
from typing import Annotated, Any, Optional

import typer
from rich.table import Table

from drumflow.cli_cooler._app import app, console, err_console, guard

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
    from drumflow.coolers._rundir import open_cooler_run, write_result
    from drumflow.coolers.grate import plots
    from drumflow.coolers.grate.case import load_grate_case
    from drumflow.coolers.grate.model import solve_grate
    from drumflow.coolers.grate.studies import parse_vary, run_sweep, vary_cases

    with guard():
        case = load_grate_case(case_file)
        sweep_spec = parse_vary(vary) if vary else None
        if sweep_spec is not None:
            # Every varied case checked before the run directory is made: a refused study
            # leaves nothing behind.
            vary_cases(case, *sweep_spec)
        start = time.perf_counter()
        if sweep_spec is None:
            run_out = out or Path("runs/cooler/grate") / case.name
            rundir = open_cooler_run(run_out, "grate", case, case_file.read_text(), force)
            sol = solve_grate(case)
            root = rundir.root
            summary = sol.summary()
            plots.write_profiles(sol, root / "profiles.csv")
            plots.plot_layers(sol, root / "clinker_layers.png",
                              title="clinker temperature at several heights (report Fig. 7/8)")
            plots.plot_layers(sol, root / "air_layers.png", air=True,
                              title="air temperature at several heights (report Fig. 9)")
            plots.plot_air_height(sol, root / "air_height.png")
            plots.plot_fields(sol, root / "fields.png")
            write_result(rundir, {"model": "grate", "case": case.name, **summary},
                         time.perf_counter() - start)
            _print_single(summary, root, as_json)
            return
        field, values = sweep_spec
        short = field.split(".")[-1]
        run_out = out or Path("runs/cooler/grate") / f"{case.name}-{short}"
        rundir = open_cooler_run(run_out, "grate", case, case_file.read_text(), force)
        rundir.record("vary", {"field": field, "values": values})
        sweep = run_sweep(case, field, values)
        root = rundir.root
        rows = sweep.rows()
        plots.write_csv(rows, root / "sweep.csv")
        plots.plot_sweep(sweep, root / "sweep_profiles.png")
        plots.plot_sweep_outlets(sweep, root / "sweep_outlets.png")
        plots.plot_sweep_recovered(sweep, root / "sweep_recovered.png")
        peaks = {column: dict(zip(("at", "value", "interior"), sweep.peak(column), strict=True))
                 for column in ("heat_recovered_MW", "secondary_air_K")}
        write_result(rundir, {"model": "grate", "case": case.name, "vary": field,
                              "air_supply": case.air.supply, "rows": rows, "maxima": peaks},
                     time.perf_counter() - start)
        _print_sweep(field, rows, peaks, root, as_json)


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
