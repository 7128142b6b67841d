"""`drumflow cooler fluid-bed CASE` and `drumflow cooler fit CASE DATA.csv`: the vibrating
fluid-bed cooler with its refrigeration cycle, and the fit of its two parameters."""

from __future__ import annotations

import json
import time
from pathlib import Path
from typing import Annotated, Any, Optional

import typer
from rich.table import Table

from drumflow.cli_cooler._app import app, console, err_console, guard


def _c(kelvin: float | None) -> str:
    return "-" if kelvin is None else f"{kelvin - 273.15:.2f} °C"


@app.command("fluid-bed")
def fluid_bed(
    case_file: Annotated[Path, typer.Argument(help="fluid-bed cooler case file (TOML)")],
    month: Annotated[Optional[int], typer.Option(
        "--month", min=1, max=12, help="run one month of the case's weather table")] = None,
    year: Annotated[bool, typer.Option("--year", help="run every month of the weather table")] = False,
    out: Annotated[Optional[Path], typer.Option("--out", "-o", help="run directory")] = None,
    force: Annotated[bool, typer.Option("--force", help="reuse a directory of another case")] = False,
    as_json: Annotated[bool, typer.Option("--json", help="print the result as JSON")] = False,
) -> None:
    """Vibrating fluid-bed cooler (plug flow, shell conduction in the particle, bubbling-bed
    hydrodynamics, hood losses) with the ammonia cycle that chills section C's air when
    ambient air cannot bring the product below the target."""
    from drumflow.coolers import _fluid_bed_plots as plots
    from drumflow.coolers._rundir import open_cooler_run, write_result
    from drumflow.coolers.fluid_bed import (
        case_conditions,
        load_fluid_bed_case,
        load_weather,
        month_conditions,
        operate,
        operate_year,
        source_cycle_checks,
    )
    from drumflow.errors import CaseError

    with guard():
        if month is not None and year:
            raise CaseError(["--month and --year: give one or the other"])
        case = load_fluid_bed_case(case_file)
        suffix = f"-month{month:02d}" if month is not None else ("-year" if year else "")
        run_out = out or Path("runs/cooler/fluid-bed") / f"{case.name}{suffix}"
        start = time.perf_counter()
        target = case.refrigeration.target_product_temperature_K
        # The model runs (seconds) before the run directory is made: a case it refuses
        # leaves nothing behind.
        if year:
            months = operate_year(case)
            checks = source_cycle_checks(case)
        elif month is not None:
            weather = {m.month: m for m in load_weather(case.weather.table)}[month]
            op = operate(case, month_conditions(case, weather))
            label = f"{weather.name}: "
        else:
            op = operate(case, case_conditions(case))
            label = ""
        rundir = open_cooler_run(run_out, "fluid-bed", case, case_file.read_text(), force)
        root = rundir.root
        if year:
            rows = [{"month": m.month, "name": m.name, **_flat(op.summary())} for m, op in months]
            plots.write_rows_csv(rows, root / "year.csv")
            plots.plot_year(months, root / "year.png", target)
            hottest = max(months, key=lambda mo: mo[1].unit.conditions.ambient_temperature)
            _unit_outputs(plots, hottest[1], root, target, f"{hottest[0].name}: ")
            source_rows = [_source_row(c) for c in checks]
            plots.write_rows_csv(source_rows, root / "source_table_1.csv")
            result: dict[str, Any] = {"model": "fluid-bed", "case": case.name, "year": rows,
                                      "source_table_1": source_rows}
            write_result(rundir, result, time.perf_counter() - start)
            _print_year(rows, source_rows, root, as_json)
            return
        _unit_outputs(plots, op, root, target, label)
        summary = {**_flat(op.summary()), **_sections(op)}
        write_result(rundir, {"model": "fluid-bed", "case": case.name, "month": month, **summary},
                     time.perf_counter() - start)
        _print_single(summary, root, as_json)


@app.command("fit")
def fit(
    case_file: Annotated[Path, typer.Argument(help="fluid-bed cooler case file (TOML)")],
    data: Annotated[Path, typer.Argument(help="operating points CSV: t_ambient_C, rh_pct, "
                                         "t_product_in_C, t_cooled_air_C (empty = ambient), "
                                         "t_product_out_C, t_air_out_C")],
    out: Annotated[Optional[Path], typer.Option("--out", "-o", help="run directory")] = None,
    force: Annotated[bool, typer.Option("--force", help="reuse a directory of another case")] = False,
    as_json: Annotated[bool, typer.Option("--json", help="print the result as JSON")] = False,
) -> None:
    """Fit the fluid-bed cooler's convective efficiency f_c and hood losses hLosses*A to
    measured product and air outlet temperatures (least squares, 95 % intervals)."""
    from drumflow.coolers import _fluid_bed_plots as plots
    from drumflow.coolers._rundir import open_cooler_run, write_result
    from drumflow.coolers.fit import fit_parameters, read_points
    from drumflow.coolers.fluid_bed import load_fluid_bed_case

    with guard():
        case = load_fluid_bed_case(case_file)
        points = read_points(data)
        run_out = out or Path("runs/cooler/fluid-bed") / f"{case.name}-fit"
        start = time.perf_counter()
        # Fitted before the run directory is made: a refused fit leaves nothing behind.
        result = fit_parameters(case, points)
        rundir = open_cooler_run(run_out, "fluid-bed-fit", case, case_file.read_text(), force)
        rundir.record("data", {"file": str(data.resolve()), "points": len(points)})
        root = rundir.root
        plots.plot_fit(result, root / "fit.png")
        rows = [{"measured_product_K": mp, "model_product_K": p, "measured_air_K": ma, "model_air_K": a}
                for mp, p, ma, a in zip(result.measured_product, result.model_product,
                                        result.measured_air, result.model_air)]
        plots.write_rows_csv(rows, root / "fit_residuals.csv")
        summary = result.summary()
        write_result(rundir, {"model": "fluid-bed-fit", "case": case.name, **summary},
                     time.perf_counter() - start)
        if as_json:
            console.print_json(json.dumps(summary, default=float))
            return
        table = Table(title=f"fluid-bed fit: {len(points)} operating points", show_header=True)
        table.add_column("parameter")
        table.add_column("fitted", justify="right")
        table.add_column("95 % interval", justify="right")
        lo, hi = summary["convective_efficiency_ci95"]
        table.add_row("f_c", f"{summary['convective_efficiency']:.4f}", f"{lo:.4f} .. {hi:.4f}")
        lo, hi = summary["h_losses_A_kW_per_K_ci95"]
        table.add_row("hLosses*A (kW/K)", f"{summary['h_losses_A_kW_per_K']:.3f}", f"{lo:.3f} .. {hi:.3f}")
        table.add_row("residual std (K)", f"{summary['residual_std_K']:.3f}", "")
        table.add_row("rms product / air (K)",
                      f"{summary['rms_product_K']:.3f} / {summary['rms_air_K']:.3f}", "")
        console.print(table)
        err_console.print(f"results in {root}")


def _source_row(check: Any) -> dict[str, Any]:
    """The source's Table 1 month beside the consistent cycles (kJ/kg of product)."""
    row, src, river = check.row, check.at_source_temperatures, check.with_river_condensing
    return {
        "month": row.month, "duty_kJ_per_kg": row.duty,
        "evaporating_K": row.evaporating_temperature, "condensing_K": row.condensing_temperature,
        "source_power_kJ_per_kg": row.power, "source_cop": row.cop,
        "carnot_cop": row.carnot_cop, "source_exceeds_carnot": row.exceeds_carnot,
        "consistent_power_kJ_per_kg": src.power / 1e3, "consistent_cop": src.cop,
        "consistent_refrigerant_kg_per_kg": src.refrigerant_flow / 1e3,
        "river_condensing_K": river.condensing_temperature if river else None,
        "river_power_kJ_per_kg": river.power / 1e3 if river else None,
        "river_cop": river.cop if river else None,
        "river_carnot_cop": river.carnot_cop if river else None,
    }


def _unit_outputs(plots: Any, op: Any, root: Path, target: float, label: str) -> None:
    unit = op.unit
    plots.write_profile_csv(unit, root / "profile.csv")
    plots.write_radial_csv(unit, root / "radial_outlet.csv")
    amb = unit.conditions.ambient_temperature - 273.15
    plots.plot_profile(unit, root / "profile.png", target,
                       f"{label}ambient {amb:.1f} °C; product out {_c(unit.product_outlet_temperature)}, "
                       f"air out (measured) {_c(unit.air_measured_temperature)}")
    plots.plot_radial(unit, root / "radial_outlet.png")


def _flat(summary: dict[str, Any]) -> dict[str, Any]:
    out = dict(summary)
    out["notes"] = "; ".join(summary.get("notes", []))
    return out


def _sections(op: Any) -> dict[str, Any]:
    secs = []
    for s in op.unit.sections:
        secs.append({
            "section": s.name, "length_m": s.length, "residence_time_s": s.residence_time,
            "air_in_K": s.air_inlet_temperature, "air_out_K": s.air_outlet_temperature,
            "air_kg_per_s": s.air_mass_flow, "geldart": s.bed.geldart,
            "u_mf_m_per_s": s.bed.min_fluidization_velocity, "u_t_m_per_s": s.bed.terminal_velocity,
            "bubble_diameter_m": s.bed.bubble_diameter,
            "surface_bubble_diameter_m": s.bed.surface_bubble_diameter,
            "bubble_fraction": s.bed.bubble_fraction,
            "dense_phase_voidage": s.bed.dense_phase_voidage, "voidage": s.bed.voidage,
            "bed_height_m": s.bed.bed_height, "reynolds": s.reynolds,
            "vibration_reynolds": s.vibration_reynolds, "vibration_intensity": s.vibration_intensity,
            "nusselt": s.nusselt, "h_W_m2K": s.h_correlation, "fc_h_W_m2K": s.h_effective,
            "biot": s.biot, "ntu": s.ntu, "heat_kW": s.heat / 1e3,
            "product_out_K": s.product_outlet_temperature})
    return {"sections": secs,
            "particle_centre_minus_surface_K": float(op.unit.radial_temperature[0]
                                                     - op.unit.radial_temperature[-1]),
            "product_heat_kW": op.unit.product_heat / 1e3, "loss_kW": op.unit.loss_heat / 1e3}


def _print_single(summary: dict[str, Any], out: Path, as_json: bool) -> None:
    if as_json:
        console.print_json(json.dumps(summary, default=float))
        return
    table = Table(title="vibrating fluid-bed cooler", show_header=True)
    table.add_column("quantity")
    table.add_column("value", justify="right")
    rows = [
        ("ambient air", _c(summary["ambient_K"])),
        ("product out, ambient air only", _c(summary["product_outlet_ambient_only_K"])),
        ("chilled air needed", "yes" if summary["cooling_needed"] else "no"),
        ("product out, as operated", _c(summary["product_outlet_K"])),
        ("air out, measured (after hood)", _c(summary["air_outlet_measured_K"])),
        ("section C supply air", _c(summary["cooled_air_K"])),
        ("air-cooler duty", f"{summary['air_cooler_duty_kJ_per_kg']:.3f} kJ/kg"),
        ("compressor power", f"{summary['compressor_power_kJ_per_kg']:.3f} kJ/kg"),
        ("COP (Carnot)", "-" if summary["cop"] is None
         else f"{summary['cop']:.2f} ({summary['carnot_cop']:.2f})"),
        ("particle centre - surface at outlet", f"{summary['particle_centre_minus_surface_K']:.2f} K"),
        ("product heat / hood loss", f"{summary['product_heat_kW']:.1f} / {summary['loss_kW']:.2f} kW"),
        ("energy closure", f"{summary['energy_closure']:.1e}"),
    ]
    for s in summary["sections"]:
        rows.append((f"{s['section']}: h, f_c h, Bi",
                     f"{s['h_W_m2K']:.0f}, {s['fc_h_W_m2K']:.0f} W/m2K, {s['biot']:.2f}"))
        rows.append((f"{s['section']}: voidage, bed height, bubble (mean)",
                     f"{s['voidage']:.3f}, {s['bed_height_m']:.3f} m, {s['bubble_diameter_m']:.3f} m"))
    for name, value in rows:
        table.add_row(name, value)
    console.print(table)
    if summary.get("notes"):
        err_console.print(summary["notes"])
    err_console.print(f"results in {out}")


def _print_year(rows: list[dict[str, Any]], source_rows: list[dict[str, Any]], out: Path,
                as_json: bool) -> None:
    if as_json:
        console.print_json(json.dumps({"year": rows, "source_table_1": source_rows}, default=float))
        return
    table = Table(title="vibrating fluid-bed cooler over the year", show_header=True)
    for name in ("month", "air (°C)", "product, ambient only (K)", "chill?", "product (K)",
                 "cooled air (°C)", "duty (kJ/kg)", "power (kJ/kg)", "COP", "Carnot"):
        table.add_column(name, justify="right")
    for r in rows:
        table.add_row(r["name"], f"{r['ambient_K'] - 273.15:.1f}",
                      f"{r['product_outlet_ambient_only_K']:.2f}", "yes" if r["cooling_needed"] else "no",
                      f"{r['product_outlet_K']:.2f}",
                      "-" if r["cooled_air_K"] is None else f"{r['cooled_air_K'] - 273.15:.1f}",
                      f"{r['air_cooler_duty_kJ_per_kg']:.2f}", f"{r['compressor_power_kJ_per_kg']:.3f}",
                      "-" if r["cop"] is None else f"{r['cop']:.2f}",
                      "-" if r["carnot_cop"] is None else f"{r['carnot_cop']:.2f}")
    console.print(table)
    src = Table(title="the source's Table 1 (its duty and evaporating temperature) with a "
                "consistent cycle", show_header=True)
    for name in ("month", "duty (kJ/kg)", "T_evap (K)", "T_cond (K)", "source power", "source COP",
                 "Carnot", "consistent power", "COP", "river T_cond (K)", "river power", "river COP",
                 "river Carnot"):
        src.add_column(name, justify="right")
    for r in source_rows:
        river = r["river_condensing_K"] is not None
        src.add_row(r["month"], f"{r['duty_kJ_per_kg']:.3f}", f"{r['evaporating_K']:.2f}",
                    f"{r['condensing_K']:.2f}", f"{r['source_power_kJ_per_kg']:.3f}",
                    f"{r['source_cop']:.2f}" + (" > Carnot" if r["source_exceeds_carnot"] else ""),
                    f"{r['carnot_cop']:.2f}", f"{r['consistent_power_kJ_per_kg']:.3f}",
                    f"{r['consistent_cop']:.2f}",
                    f"{r['river_condensing_K']:.2f}" if river else "-",
                    f"{r['river_power_kJ_per_kg']:.3f}" if river else "-",
                    f"{r['river_cop']:.2f}" if river else "-",
                    f"{r['river_carnot_cop']:.2f}" if river else "-")
    console.print(src)
    err_console.print("powers in kJ per kg of product; the consistent cycles use the case's "
                      "compressor (polytropic efficiency) and refrigerant")
    err_console.print(f"results in {out}")
