"""`drumflow report | methodology | exchanger`: what a finished run says (`paper` and `export`,
the other commands on a run's results, have modules of their own)."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Annotated

import typer
from rich.markup import escape
from rich.table import Table

from drumflow.cli._common import load_case_file
from drumflow.cli._guard import console, err_console

__all__ = ["exchanger", "methodology", "report"]


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
    from drumflow.analysis.methodology_result import exchanger_to_dict, plant_streams
    from drumflow.physics.exchanger import counter_current_exchanger

    case = load_case_file(case_file)
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

