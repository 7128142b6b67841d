"""`drumflow predict`: the plant's outlets at new conditions from a run's h or a Nu-Re-Pr fit
(the exchanger model of the paper). `drumflow plant` (= `drumflow cooler drum`) is in
:mod:`drumflow.cli.cooler.drum`: the axial whole-drum model from a slice's closures."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Annotated

import typer
from rich.table import Table

from drumflow.cli._guard import console, err_console

__all__ = ["predict"]


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
    """The plant's outlets at a new rpm, air flow, feed rate or particle size by the paper's
    exchanger (one h from a run or a Nu-Re-Pr fit; `plant` models the drum along its axis).

    The three ways to the plant: this one scales the paper's counter-current exchanger (Eqs.
    42-48) to new conditions; `drumflow plant` (= `drumflow cooler drum`) models the drum along
    its axis from a slice's closures (curtain, bed, the air through the curtains).
    """
    from drumflow.analysis.methodology import analyse_run, fit_runs
    from drumflow.coolers.prediction import predict_plant

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

