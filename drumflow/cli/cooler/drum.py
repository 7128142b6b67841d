"""`drumflow cooler drum SOURCE` (also `drumflow plant`): the whole cooler from a slice run.

The model work is :func:`drumflow.coolers.plant_from_slice.plant_from_slice`; this module parses
the options and prints what it returns.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import TYPE_CHECKING, Annotated

import typer
from rich.table import Table

from drumflow.cli.cooler._app import app, console, err_console, guard

if TYPE_CHECKING:
    from drumflow.coolers.plant_from_slice import PlantFromSlice, PlantFromSliceFiles

@app.command("drum")
def drum(
    source: Annotated[Path, typer.Argument(
        help="a slice run directory, or a closures JSON file (e.g. docs/plant/smoke_closures.json)")],
    cells: Annotated[int, typer.Option("--cells", help="axial cells")] = 40,
    rpm: Annotated[float | None, typer.Option("--rpm", help="drum speed, 1/min")] = None,
    air_flow: Annotated[float | None, typer.Option("--air-flow", help="air mass flow, kg/s")] = None,
    feed_rate: Annotated[float | None, typer.Option("--feed-rate", help="solids feed, kg/s")] = None,
    particle_diameter: Annotated[float | None, typer.Option(
        "--particle-diameter", help="granule diameter, m")] = None,
    length: Annotated[float | None, typer.Option("--length", help="drum length, m")] = None,
    tilt: Annotated[float | None, typer.Option("--tilt", help="axis tilt, degrees")] = None,
    wall_loss: Annotated[float, typer.Option(
        "--wall-loss", help="wall-loss coefficient U_w, W/(m2 K) over the shell (0 = off)")] = 0.0,
    lumped: Annotated[bool, typer.Option(
        "--lumped", help="lumped particles (Bi -> 0) instead of interior conduction")] = False,
    curtain_air: Annotated[str | None, typer.Option(
        "--curtain-air", help="air through the curtains: m3/s per metre of drum (at the air "
                              "inlet temperature), a periodic slice's heat.json (drumflow "
                              "bed-air --heat: its saturated flow; with --save-closures its air "
                              "closures are saved too), or 'all': all the air meets every "
                              "falling granule (the bound of most contact). Default: the "
                              "closures' own through-curtain air if they carry a slice's, else "
                              "'all'. Every run also reports the outlets over a range of it")
    ] = None,
    sweep: Annotated[bool, typer.Option(
        "--sweep/--no-sweep", help="also run the range of through-curtain flows (table, "
                                   "curtain_air.csv/.png)")] = True,
    closures_start: Annotated[float | None, typer.Option(
        "--start", help="with a run directory: measure the closures from this simulated time "
                        "on, s (default: the case's run.mass_flow_start); e.g. once the "
                        "flights have filled")] = None,
    save_closures: Annotated[Path | None, typer.Option(
        "--save-closures", help="also write the slice closures to this JSON file (a SOURCE "
                                "for later calls, no run directory needed)")] = None,
    out: Annotated[Path | None, typer.Option("--out", "-o", help="run directory")] = None,
    as_json: Annotated[bool, typer.Option("--json", help="print the result as JSON")] = False,
    force: Annotated[bool, typer.Option("--force", help="reuse a directory of another input")] = True,
) -> None:
    """The plant (3 m x 19 m NPK cooler) along its axis from a slice run's closures (`plant` =
    `cooler drum`); what-ifs by option.

    The three ways to the plant: this one models the drum along its axis (curtain, bed, the air
    through the curtains) from a slice's closures; `drumflow predict` scales the paper's
    counter-current exchanger (one h, from a run or a Nu-Re-Pr fit) to new conditions.
    """
    # The models import scipy; loading them here keeps `drumflow --help` and every other
    # command from paying for it at start-up.
    from drumflow.coolers.plant_from_slice import plant_from_slice, write_plant_from_slice

    with guard():
        evaluation = plant_from_slice(
            source, cells=cells, rpm=rpm, air_flow=air_flow, feed_rate=feed_rate,
            particle_diameter=particle_diameter, length=length, tilt=tilt, wall_loss=wall_loss,
            lumped=lumped, curtain_air=curtain_air, sweep=sweep, closures_start=closures_start,
            save_closures=save_closures)
        files = write_plant_from_slice(evaluation, out, force=force)
    if as_json:
        console.print_json(json.dumps(evaluation.to_dict(), default=float))
        return
    for w in evaluation.warnings:
        err_console.print(f"[yellow]warning:[/] {w}", highlight=False)
    _print_outlets(evaluation)
    if evaluation.mixing_bounds:
        _print_mixing_bounds(evaluation)
    if evaluation.points:
        _print_curtain_air(evaluation)
    _print_model(evaluation, files, save_closures)


def _print_outlets(evaluation: PlantFromSlice) -> None:
    """The model's outlets beside the plant's measured ones, the paper's exchanger and the
    textbook coefficient."""
    from drumflow.coolers.plant_from_slice import PAPER_TABLE7

    result, base, exchanger, textbook = (evaluation.result, evaluation.base, evaluation.exchanger,
                                         evaluation.textbook)
    table = Table(title=f"plant prediction from slice '{evaluation.closures.case_name}' "
                  f"({evaluation.options.cells} cells)")
    table.add_column("")
    table.add_column("NPK out (°C)", justify="right")
    table.add_column("air out (°C)", justify="right")
    table.add_row("drumflow drum model", f"{result.material_outlet_c:.2f}", f"{result.air_outlet_c:.2f}")
    if not evaluation.what_if:
        table.add_row("plant, measured", f"{base.measured_material_outlet_c:g}",
                      f"{base.measured_air_outlet_c:g}")
        table.add_row("paper's exchanger (Table 7)", f"{PAPER_TABLE7['material_outlet_C']:.2f}",
                      f"{PAPER_TABLE7['air_outlet_C']:.2f}")
    else:
        table.add_row("paper's exchanger h, A_he", f"{exchanger.material_outlet_temperature_c:.2f}",
                      f"{exchanger.air_outlet_temperature_c:.2f}")
    table.add_row(f"textbook Ua = {evaluation.textbook_ua:.0f} W/(m³ K)",
                  f"{textbook.material_outlet_temperature_c:.2f}",
                  f"{textbook.air_outlet_temperature_c:.2f}")
    console.print(table)


def _print_mixing_bounds(evaluation: PlantFromSlice) -> None:
    """The outlets at the slice's bounds of the heat's mixing: the closure's own uncertainty."""
    table = Table(title=f"through-curtain air from the slice ({evaluation.curtain_air_from}) "
                        "and at its bounds of the heat's mixing")
    table.add_column("")
    table.add_column("through curtains (m³/s per m)", justify="right")
    table.add_column("NPK out (°C)", justify="right")
    table.add_column("air out (°C)", justify="right")
    result = evaluation.result
    table.add_row("the slice's closure", f"{evaluation.curtain_air:.3g}",
                  f"{result.material_outlet_c:.2f}", f"{result.air_outlet_c:.2f}")
    for name, point in evaluation.mixing_bounds.items():
        table.add_row(f"{name} bound", f"{point.curtain_air_m3_s_m:.3g}",
                      f"{point.material_outlet_c:.2f}", f"{point.air_outlet_c:.2f}")
    console.print(table)


def _print_curtain_air(evaluation: PlantFromSlice) -> None:
    """The outlets over the through-curtain air, and the flow the measured outlet would need."""
    sweep_table = Table(title="over the air through the curtains (a range; never fitted to "
                              "the plant)")
    sweep_table.add_column("through curtains (m³/s per m)", justify="right")
    sweep_table.add_column("curtains met by the air", justify="right")
    sweep_table.add_column("NPK out (°C)", justify="right")
    sweep_table.add_column("air out (°C)", justify="right")
    sweep_table.add_column("curtain / bed (kW)", justify="right")
    for p in evaluation.points:
        flow = "all" if p.curtain_air_m3_s_m is None else f"{p.curtain_air_m3_s_m:g}"
        passes = "—" if p.curtain_passes is None else f"{p.curtain_passes:.2f}"
        sweep_table.add_row(flow, passes, f"{p.material_outlet_c:.2f}",
                            f"{p.air_outlet_c:.2f}",
                            f"{p.heat_curtain_w / 1e3:.0f} / {p.heat_bed_w / 1e3:.0f}")
    console.print(sweep_table)
    needed = evaluation.needed
    if needed is None:
        return
    if needed.curtain_air_m3_s_m is not None:
        console.print(f"NPK out {needed.target_material_outlet_c:g} °C needs "
                      f"{needed.curtain_air_m3_s_m:.2f} m³/s per metre through the "
                      f"curtains (air out then {needed.air_outlet_c:.1f} °C)")
    else:
        console.print(f"NPK out {needed.target_material_outlet_c:g} °C: {needed.reason}")
    scales = ", ".join(f"{k.replace('_', ' ')} {v['m3_s_per_m']:.2g}"
                       for k, v in evaluation.curtain_scales().items())
    console.print(f"scales (m³/s per m): {scales}")


def _print_model(evaluation: PlantFromSlice, files: PlantFromSliceFiles,
                 save_closures: Path | None) -> None:
    """The model's inner numbers (duty split, residence, falling flow, h) and what it wrote."""
    result, plant, law = evaluation.result, evaluation.plant, evaluation.law
    s = result.scaled
    info = Table(show_header=False, title="model")
    info.add_row("heat duty", f"{result.duty_w / 1e3:.1f} kW (curtain {100 * result.curtain_share:.1f} %,"
                 f" bed {100 * (1 - result.curtain_share):.1f} %, wall {result.wall_loss_w / 1e3:.1f} kW)")
    info.add_row("residence time, hold-up",
                 f"{s.residence_time_s / 60:.1f} min, {s.holdup_kg_per_m * plant.length_m / 1e3:.1f} t "
                 f"(transport K = {law.coefficient:.3f}, {law.calibrated_on})")
    info.add_row("falling flow, cascades/rev", f"{s.falling_mass_flow_kg_s_m:.1f} kg/(s m), "
                 f"{s.cascades_per_revolution:.2f}")
    info.add_row("fall height, time, airborne", f"{s.fall_height_m:.2f} m, {s.fall_time_s:.2f} s, "
                 f"{100 * s.airborne_fraction:.1f} % (slice {100 * s.slice_airborne_fraction:.1f} %)")
    info.add_row("slice fall time: measured / ballistic",
                 f"{s.slice_measured_fall_time_s:.3f} / {s.slice_ballistic_fall_time_s:.3f} s")
    info.add_row("h fall / bed surface, Bi", f"{result.h_fall_w_m2k:.0f} / "
                 f"{result.h_bed_surface_w_m2k:.0f} W/(m² K), Bi {result.biot_fall:.2f}")
    info.add_row("bed surface", f"{s.bed_surface_m2_per_m:.2f} m²/m")
    info.add_row("energy residual", f"{result.energy_residual:.1e}")
    written = f"{files.result}, {files.profile_png}"
    if files.curtain_air_csv is not None:
        written += f", {files.curtain_air_csv}, {files.curtain_air_png}"
    info.add_row("written", written)
    if save_closures is not None:
        info.add_row("closures written", str(save_closures))
    console.print(info)
