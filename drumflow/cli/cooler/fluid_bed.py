"""`drumflow cooler fluid-bed CASE` and `drumflow cooler fit CASE DATA.csv`: the vibrating
fluid-bed cooler with its refrigeration cycle, and the fit of its two parameters."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Annotated, Any, Optional

import typer
from rich.table import Table

from drumflow.cli.cooler._app import app, console, err_console, guard


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
    from drumflow.coolers.model_runs import run_fluid_bed

    with guard():
        run = run_fluid_bed(case_file, out, month, year, force)
        if run.summary is None:
            _print_year(run.year, run.source_table_1, run.root, as_json)
        else:
            _print_single(run.summary, run.root, as_json)


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
    from drumflow.coolers.model_runs import run_fluid_bed_fit

    with guard():
        run = run_fluid_bed_fit(case_file, data, out, force)
        summary, root = run.summary, run.root
        if as_json:
            console.print_json(json.dumps(summary, default=float))
            return
        table = Table(title=f"fluid-bed fit: {run.points} operating points", show_header=True)
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


def _print_single(summary: dict[str, Any], out: Path, as_json: bool) -> None:
    from drumflow.coolers.model_runs import celsius_text

    if as_json:
        console.print_json(json.dumps(summary, default=float))
        return
    table = Table(title="vibrating fluid-bed cooler", show_header=True)
    table.add_column("quantity")
    table.add_column("value", justify="right")
    rows = [
        ("ambient air", celsius_text(summary["ambient_K"])),
        ("product out, ambient air only", celsius_text(summary["product_outlet_ambient_only_K"])),
        ("chilled air needed", "yes" if summary["cooling_needed"] else "no"),
        ("product out, as operated", celsius_text(summary["product_outlet_K"])),
        ("air out, measured (after hood)", celsius_text(summary["air_outlet_measured_K"])),
        ("section C supply air", celsius_text(summary["cooled_air_K"])),
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
