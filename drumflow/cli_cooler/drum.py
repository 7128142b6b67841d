"""`drumflow cooler drum SOURCE`: the whole cooler from a slice run (alias `drumflow plant`)."""

from __future__ import annotations

import json
import math
import time
from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Any

import typer
from pydantic import BaseModel, ConfigDict
from rich.table import Table

from drumflow.cli_cooler._app import app, console, err_console, guard

if TYPE_CHECKING:
    from drumflow.analysis.closures import SliceClosures
    from drumflow.analysis.predict import PlantSpec
    from drumflow.coolers.curtain_air import CurtainAirPoint
    from drumflow.coolers.drum import DrumResult

#: Table 7 of the paper, model one: its exchanger prediction of the plant.
PAPER_TABLE7 = {"material_outlet_C": 40.90, "air_outlet_C": 69.73}


class DrumInputs(BaseModel):
    """What one `drumflow cooler drum` evaluation depends on (bound to its run directory)."""

    model_config = ConfigDict(extra="forbid", frozen=True)

    source: str
    closures: dict[str, Any]
    plant: dict[str, Any]
    options: dict[str, Any]


def _closures(source: Path, start: float | None) -> SliceClosures:
    from drumflow.analysis.closures import extract_closures, load_closures
    from drumflow.coolers.drum import DrumModelError

    if source.is_dir():
        return extract_closures(source, start_s=start)
    if start is not None:
        # A closures file was measured over its own window (its `window_s`); silently ignoring
        # the option would hand back closures the user did not ask for.
        raise DrumModelError(f"--start = {start:g} s: allowed only with a slice run directory "
                             f"as SOURCE; {source} is a closures file (measured over its "
                             "own window_s)")
    return load_closures(source)


def plot_drum(result: DrumResult, path: Path, title: str) -> Path:
    """Axial temperature profiles and the heat removed per metre, curtain and bed."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    plant = result.plant
    fig, (ax, bx) = plt.subplots(2, 1, figsize=(7.0, 6.4), dpi=120, sharex=True,
                                 gridspec_kw={"height_ratios": [3, 2]})
    ax.plot(result.z_m, result.solids_c, "-", color="tab:brown", lw=2, label="solids (mean)")
    ax.plot(result.z_m, result.air_c, "--", color="tab:blue", lw=2, label="air")
    if plant.measured_material_outlet_c is not None:
        ax.plot([plant.length_m], [plant.measured_material_outlet_c], "s", color="tab:brown",
                ms=8, mfc="none", label=f"plant, measured NPK out {plant.measured_material_outlet_c:g} °C")
    if plant.measured_air_outlet_c is not None:
        ax.plot([0.0], [plant.measured_air_outlet_c], "o", color="tab:blue", ms=8, mfc="none",
                label=f"plant, measured air out {plant.measured_air_outlet_c:g} °C")
    ax.annotate("solids in →", (0, plant.material_inlet_temperature_c), fontsize=8,
                xytext=(4, -12), textcoords="offset points")
    ax.annotate("← air in", (plant.length_m, plant.air_inlet_temperature_c), fontsize=8,
                xytext=(-40, 6), textcoords="offset points")
    ax.set_ylabel("temperature (°C)")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8, loc="upper right")
    ax.set_title(title, fontsize=10)
    dz = plant.length_m / len(result.cell_curtain_w)
    centres = 0.5 * (result.z_m[1:] + result.z_m[:-1])
    bx.plot(centres, result.cell_curtain_w / dz / 1e3, "-", color="tab:orange", label="curtain")
    bx.plot(centres, result.cell_bed_w / dz / 1e3, "-", color="tab:green", label="bed surface")
    if result.wall_loss_w > 0:
        bx.plot(centres, result.cell_wall_w / dz / 1e3, "-", color="tab:gray", label="wall loss")
    bx.set_xlabel("distance from the solids inlet (m)")
    bx.set_ylabel("heat removed (kW/m)")
    bx.grid(alpha=0.3)
    bx.legend(fontsize=8)
    bx.set_xlim(-0.02 * plant.length_m, 1.02 * plant.length_m)  # keep the outlet markers whole
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)
    return path


def plot_curtain_air(points: list[CurtainAirPoint], plant: PlantSpec, path: Path,
                     title: str) -> Path:
    """NPK and air outlets over the through-curtain flow, with the all-air limit and the
    plant's measured outlets."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    finite = [p for p in points if p.curtain_air_m3_s_m is not None]
    limit = [p for p in points if p.curtain_air_m3_s_m is None]
    q = [p.curtain_air_m3_s_m or 0.0 for p in finite]
    fig, ax = plt.subplots(figsize=(7.0, 4.6), dpi=120)
    ax.plot(q, [p.material_outlet_c for p in finite], "o-", color="tab:brown", label="NPK out")
    ax.plot(q, [p.air_outlet_c for p in finite], "s--", color="tab:blue", label="air out")
    for p in limit:
        ax.axhline(p.material_outlet_c, color="tab:brown", lw=0.8, ls=":",
                   label=f"all air meets the curtain: NPK {p.material_outlet_c:.1f} °C")
        ax.axhline(p.air_outlet_c, color="tab:blue", lw=0.8, ls=":",
                   label=f"all air meets the curtain: air {p.air_outlet_c:.1f} °C")
    if plant.measured_material_outlet_c is not None:
        ax.axhspan(plant.measured_material_outlet_c - 3, plant.measured_material_outlet_c + 3,
                   color="tab:brown", alpha=0.12,
                   label=f"plant NPK out {plant.measured_material_outlet_c:g} ± 3 °C")
    if plant.measured_air_outlet_c is not None:
        ax.axhline(plant.measured_air_outlet_c, color="tab:blue", lw=1.5, alpha=0.4,
                   label=f"plant air out {plant.measured_air_outlet_c:g} °C (a check)")
    ax.set_xlabel("air through the curtains (m³/s per metre of drum)")
    ax.set_ylabel("outlet temperature (°C)")
    ax.set_xscale("symlog", linthresh=1.0)
    ax.set_xlim(left=0.0)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7, loc="center right")
    ax.set_title(title, fontsize=9)
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)
    return path


def _curtain_air_option(value: str) -> float | None:
    """``--curtain-air``: 'all' (None) or a flow in m3/s per metre of drum."""
    from drumflow.coolers.drum import MAX_CURTAIN_AIR_M3_S_M, DrumModelError

    allowed = (f"allowed 'all' or 0 to {MAX_CURTAIN_AIR_M3_S_M:g} m3/s per metre of drum")
    if value.strip().lower() == "all":
        return None
    try:
        flow = float(value)
    except ValueError:
        raise DrumModelError(f"--curtain-air = {value}: {allowed}") from None
    if not (math.isfinite(flow) and 0.0 <= flow <= MAX_CURTAIN_AIR_M3_S_M):
        raise DrumModelError(f"--curtain-air = {value}: {allowed}")
    return flow


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
    curtain_air: Annotated[str, typer.Option(
        "--curtain-air", help="air through the curtains, m3/s per metre of drum (at the air "
                              "inlet temperature), or 'all': all the air meets every falling "
                              "granule (the default: the one setting not chosen from the "
                              "plant; the bound of most contact). Every run also reports the "
                              "outlets over a range of it")] = "all",
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
    """Predict the paper's plant (3 m x 19 m NPK cooler) from slice closures; what-ifs by option."""
    # The models import scipy; loading them here keeps `drumflow --help` and every other
    # command from paying for it at start-up.
    from drumflow.analysis.predict import PAPER_PLANT
    from drumflow.coolers._rundir import open_cooler_run, write_result
    from drumflow.coolers._transport import calibrate
    from drumflow.coolers.curtain_air import (
        curtain_air_for_outlet,
        curtain_air_scales,
        sweep_curtain_air,
    )
    from drumflow.coolers.drum import (
        DrumModelError,
        DrumOptions,
        extrapolation_warnings,
        paper_exchanger,
        solve_drum,
        volumetric_coefficient_estimate,
    )
    from drumflow.coolers.plant_balance import measured_balance

    with guard():
        for name, value, most in (("--cells", cells, 5000), ("--rpm", rpm, 60.0),
                                  ("--air-flow", air_flow, 1000.0), ("--feed-rate", feed_rate, 1000.0),
                                  ("--particle-diameter", particle_diameter, None),
                                  ("--length", length, 200.0), ("--tilt", tilt, 30.0)):
            # Upper bounds as the drum case's own (drum.rpm, air.mass_flow, plant.length,
            # drum.tilt_deg; DrumOptions' cells): beyond them the model fails somewhere else and
            # blames another quantity (--length 1e300 was reported as "cells = 40").
            if value is not None and not (value > 0 and (most is None or value <= most)):
                upper = "" if most is None else f" and <= {most:g}"
                raise DrumModelError(f"{name} = {value:g}: allowed > 0{upper}")
        if not 0 <= wall_loss <= 1000:
            raise DrumModelError(f"--wall-loss = {wall_loss:g}: allowed >= 0 and <= 1000 W/(m2 K)")
        if closures_start is not None and not closures_start >= 0:
            raise DrumModelError(f"--start = {closures_start}: allowed >= 0 s (simulated time)")
        curtain_flow = _curtain_air_option(curtain_air)
        if particle_diameter is not None and particle_diameter > 0.05:
            raise DrumModelError(f"--particle-diameter = {particle_diameter}: allowed <= 0.05 m "
                                 "(give it in metres)")
        closures = _closures(source, closures_start)
        base = PAPER_PLANT
        # The transport law's one constant comes from the plant's measured residence time
        # (30 min), never from its outlet temperatures.
        assert base.residence_time_s is not None
        law = calibrate(base, base.residence_time_s)
        plant: PlantSpec = base.changed(rpm=rpm, air_mass_flow_kg_s=air_flow,
                                        feed_rate_kg_s=feed_rate,
                                        particle_diameter_m=particle_diameter,
                                        length_m=length, tilt_deg=tilt)
        options = DrumOptions(cells=cells, wall_loss_w_m2k=wall_loss, lumped_particles=lumped,
                              curtain_air_m3_s_m=curtain_flow)
        start = time.perf_counter()
        result = solve_drum(plant, closures, law, options)
        wall = time.perf_counter() - start
        if save_closures is not None:
            # After the model accepted the inputs: a refused command writes nothing.
            closures.write(save_closures)
        warnings = extrapolation_warnings(plant, base, closures, result.scaled) + result.warnings
        ua, textbook = volumetric_coefficient_estimate(plant)
        exchanger = paper_exchanger(plant)
        what_if = plant != base
        # The through-curtain flow is the closure no slice measures yet: show what it changes.
        points: list[CurtainAirPoint] = []
        needed = None
        if sweep:
            points = sweep_curtain_air(plant, closures, law, options)
            if not what_if and base.measured_material_outlet_c is not None:
                needed = curtain_air_for_outlet(plant, closures, law, options,
                                                base.measured_material_outlet_c, points)
        curtain_payload: dict[str, Any] = {
            "setting_m3_s_per_m": curtain_flow,
            "default_note": "default 'all': all the air meets every falling granule, the limit "
                            "of most contact and the one setting not chosen from the plant; the "
                            "through-curtain flow awaits a two-way-coupled slice closure and "
                            "is never fitted to the plant's outlets",
            "sweep": [p.to_dict() for p in points],
            "needed_for_measured_material_outlet": needed.to_dict() if needed else None,
            "scales_m3_s_per_m": curtain_air_scales(plant, result.scaled),
        }
        payload: dict[str, Any] = {
            "source": str(source),
            "slice": closures.to_dict(),
            **result.to_dict(),
            "warnings": warnings,
            "measured": {"material_outlet_C": base.measured_material_outlet_c,
                         "air_outlet_C": base.measured_air_outlet_c} if not what_if else None,
            "paper_exchanger": {
                "material_outlet_C": exchanger.material_outlet_temperature_c,
                "air_outlet_C": exchanger.air_outlet_temperature_c,
                "published_table7": PAPER_TABLE7 if not what_if else None,
                "note": "Table 7 model one: h = 60.15 W/(m2 K), A_he = 1099.28 m2, this plant's streams",
            },
            "curtain_air": curtain_payload,
            "plant_balance": measured_balance(base).to_dict() if not what_if else None,
            "textbook_volumetric": {
                "Ua_W_m3K": ua,
                "material_outlet_C": textbook.material_outlet_temperature_c,
                "air_outlet_C": textbook.air_outlet_temperature_c,
                "note": "Ua = 0.5 G^0.67 / D (Btu/(h ft3 F), G lb/(h ft2), D ft), i.e. "
                        "237 G^0.67 / D in W/(m3 K) with G in kg/(s m2), D in m; attributed to "
                        "McCormick via Perry's (rotary dryers). Checked only against "
                        "Coulson & Richardson Vol. 2, Example 16.5 (0.25 kW/(m3 K) form, "
                        "5 % above): a handbook estimate, not a closure",
            },
        }
        inputs = DrumInputs(source=str(source), closures=closures.to_dict(),
                            plant=payload["plant"], options=payload["options"])
        target = out or Path("runs/cooler/drum") / closures.case_name
        rundir = open_cooler_run(target, "drum", inputs, inputs.model_dump_json(indent=2),
                                 force=force)
        write_result(rundir, payload, wall)
        with (rundir.root / "profile.csv").open("w") as fh:
            fh.write("z_m,solids_C,air_C\n")
            for z, s, a in zip(result.z_m, result.solids_c, result.air_c, strict=True):
                fh.write(f"{z:.6g},{s:.6g},{a:.6g}\n")
        title = (f"{plant.diameter_m:g} m x {plant.length_m:g} m, {plant.rpm:g} rpm, "
                 f"{plant.feed_rate_kg_s:.4g} kg/s NPK, {plant.air_mass_flow_kg_s:g} kg/s air; "
                 f"closures: {closures.case_name}")
        plot = plot_drum(result, rundir.root / "profile.png", title)
        if points:
            with (rundir.root / "curtain_air.csv").open("w") as fh:
                fh.write("curtain_air_m3_s_per_m,material_outlet_C,air_outlet_C,heat_curtain_W,"
                         "heat_bed_W,curtain_passes\n")
                for p in points:
                    flow = "all" if p.curtain_air_m3_s_m is None else f"{p.curtain_air_m3_s_m:.6g}"
                    passes = "" if p.curtain_passes is None else f"{p.curtain_passes:.6g}"
                    fh.write(f"{flow},{p.material_outlet_c:.6g},{p.air_outlet_c:.6g},"
                             f"{p.heat_curtain_w:.6g},{p.heat_bed_w:.6g},{passes}\n")
            plot_curtain_air(points, plant if what_if else base, rundir.root / "curtain_air.png",
                             title)
    if as_json:
        console.print_json(json.dumps(payload, default=float))
        return
    for w in warnings:
        err_console.print(f"[yellow]warning:[/] {w}", highlight=False)
    table = Table(title=f"plant prediction from slice '{closures.case_name}' ({cells} cells)")
    table.add_column("")
    table.add_column("NPK out (°C)", justify="right")
    table.add_column("air out (°C)", justify="right")
    table.add_row("drumflow drum model", f"{result.material_outlet_c:.2f}", f"{result.air_outlet_c:.2f}")
    if not what_if:
        table.add_row("plant, measured", f"{base.measured_material_outlet_c:g}",
                      f"{base.measured_air_outlet_c:g}")
        table.add_row("paper's exchanger (Table 7)", f"{PAPER_TABLE7['material_outlet_C']:.2f}",
                      f"{PAPER_TABLE7['air_outlet_C']:.2f}")
    else:
        table.add_row("paper's exchanger h, A_he", f"{exchanger.material_outlet_temperature_c:.2f}",
                      f"{exchanger.air_outlet_temperature_c:.2f}")
    table.add_row(f"textbook Ua = {ua:.0f} W/(m³ K)", f"{textbook.material_outlet_temperature_c:.2f}",
                  f"{textbook.air_outlet_temperature_c:.2f}")
    console.print(table)
    if points:
        sweep_table = Table(title="over the air through the curtains (not yet measured by a "
                                  "slice; never fitted to the plant)")
        sweep_table.add_column("through curtains (m³/s per m)", justify="right")
        sweep_table.add_column("curtains met by the air", justify="right")
        sweep_table.add_column("NPK out (°C)", justify="right")
        sweep_table.add_column("air out (°C)", justify="right")
        sweep_table.add_column("curtain / bed (kW)", justify="right")
        for p in points:
            flow = "all" if p.curtain_air_m3_s_m is None else f"{p.curtain_air_m3_s_m:g}"
            passes = "—" if p.curtain_passes is None else f"{p.curtain_passes:.2f}"
            sweep_table.add_row(flow, passes, f"{p.material_outlet_c:.2f}",
                                f"{p.air_outlet_c:.2f}",
                                f"{p.heat_curtain_w / 1e3:.0f} / {p.heat_bed_w / 1e3:.0f}")
        console.print(sweep_table)
        if needed is not None:
            if needed.curtain_air_m3_s_m is not None:
                console.print(f"NPK out {needed.target_material_outlet_c:g} °C needs "
                              f"{needed.curtain_air_m3_s_m:.2f} m³/s per metre through the "
                              f"curtains (air out then {needed.air_outlet_c:.1f} °C)")
            else:
                console.print(f"NPK out {needed.target_material_outlet_c:g} °C: {needed.reason}")
            scales = ", ".join(f"{k.replace('_', ' ')} {v['m3_s_per_m']:.2g}"
                               for k, v in curtain_payload["scales_m3_s_per_m"].items())
            console.print(f"scales (m³/s per m): {scales}")
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
    written = f"{rundir.root / 'result.json'}, {plot}"
    if points:
        written += f", {rundir.root / 'curtain_air.csv'}, {rundir.root / 'curtain_air.png'}"
    info.add_row("written", written)
    if save_closures is not None:
        info.add_row("closures written", str(save_closures))
    console.print(info)
