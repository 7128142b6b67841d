"""The run directories of the cooler models: run a model on a case file, write its result,
tables and pictures, and return what the command line prints.

One function per command of ``drumflow cooler`` (the drum's is
:mod:`drumflow.coolers.plant_from_slice`): :func:`run_curtain`, :func:`run_grate`,
:func:`run_fluid_bed`, :func:`run_fluid_bed_fit`. Each checks and runs the model before it
makes the run directory, so a refused case leaves nothing behind. Library code: it raises and
writes files, it never prints.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from drumflow.coolers.curtain import CurtainCase, CurtainResult

__all__ = ["CurtainRun", "FluidBedFitRun", "FluidBedRun", "GrateRun", "celsius_text",
           "plot_curtain", "run_curtain", "run_fluid_bed", "run_fluid_bed_fit", "run_grate"]


def celsius_text(kelvin: float | None) -> str:
    """A temperature in K written in °C with two decimals ("-" when not known)."""
    return "-" if kelvin is None else f"{kelvin - 273.15:.2f} °C"


@dataclass(frozen=True)
class CurtainRun:
    """A curtain-model run: the case, its result, what ``result.json`` holds, where it went."""

    case: CurtainCase
    result: CurtainResult
    payload: dict[str, Any]
    root: Path
    plot: Path


def run_curtain(case_file: Path, out: Path | None, force: bool = False) -> CurtainRun:
    """Solve a particle-curtain case into its run directory (default
    ``runs/cooler/curtain/<case>``): ``result.json``, ``profile.csv`` and ``profile.png``."""
    from drumflow.case import read_toml, validate_model
    from drumflow.coolers._rundir import open_cooler_run, write_result
    from drumflow.coolers.curtain import CurtainCase, solve_curtain

    data = read_toml(case_file)
    case = validate_model(CurtainCase, data, case_file)
    start = time.perf_counter()
    result = solve_curtain(case)
    wall = time.perf_counter() - start
    target = out or Path("runs/cooler/curtain") / case.name
    rundir = open_cooler_run(target, "curtain", case, Path(case_file).read_text(), force=force)
    payload = {"case": case.name, "source": case.source, **result.to_dict()}
    write_result(rundir, payload, wall)
    with (rundir.root / "profile.csv").open("w") as fh:
        fh.write("depth_m,solids_C,gas_C\n")
        for z, s, g in zip(result.depth_m, result.solids_profile_C, result.gas_profile_C,
                           strict=True):
            fh.write(f"{z:.6g},{s:.6g},{g:.6g}\n")
    plot = plot_curtain(case, result, rundir.root / "profile.png")
    return CurtainRun(case, result, payload, rundir.root, plot)


@dataclass(frozen=True)
class GrateRun:
    """A grate-cooler run: one case (``summary``) or a study of one field (``vary``, ``rows``,
    ``maxima``), and its run directory."""

    root: Path
    summary: dict[str, Any] | None = None
    vary: str | None = None
    rows: list[dict[str, float]] = field(default_factory=list)
    maxima: dict[str, dict[str, Any]] = field(default_factory=dict)


def run_grate(case_file: Path, out: Path | None, vary: str | None = None,
              force: bool = False) -> GrateRun:
    """Solve a grate-cooler case, or a study of one field (``FIELD=START:STOP:COUNT`` or
    ``FIELD=V1,V2,...``), into its run directory (default ``runs/cooler/grate/<case>``, with
    ``-<field>`` for a study): ``result.json`` with the profiles or the study's table and
    their pictures."""
    from drumflow.coolers._rundir import open_cooler_run, write_result
    from drumflow.coolers.grate import plots
    from drumflow.coolers.grate.case import load_grate_case
    from drumflow.coolers.grate.model import solve_grate
    from drumflow.coolers.grate.studies import parse_vary, run_sweep, vary_cases

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
        return GrateRun(root, summary=summary)
    name, values = sweep_spec
    short = name.split(".")[-1]
    run_out = out or Path("runs/cooler/grate") / f"{case.name}-{short}"
    rundir = open_cooler_run(run_out, "grate", case, case_file.read_text(), force)
    rundir.record("vary", {"field": name, "values": values})
    sweep = run_sweep(case, name, values)
    root = rundir.root
    rows = sweep.rows()
    plots.write_csv(rows, root / "sweep.csv")
    plots.plot_sweep(sweep, root / "sweep_profiles.png")
    plots.plot_sweep_outlets(sweep, root / "sweep_outlets.png")
    plots.plot_sweep_recovered(sweep, root / "sweep_recovered.png")
    peaks = {column: dict(zip(("at", "value", "interior"), sweep.peak(column), strict=True))
             for column in ("heat_recovered_MW", "secondary_air_K")}
    write_result(rundir, {"model": "grate", "case": case.name, "vary": name,
                          "air_supply": case.air.supply, "rows": rows, "maxima": peaks},
                 time.perf_counter() - start)
    return GrateRun(root, vary=name, rows=rows, maxima=peaks)


@dataclass(frozen=True)
class FluidBedRun:
    """A fluid-bed run: one operating point (``summary``) or the year (``year``, with the
    source's Table 1 beside consistent cycles), and its run directory."""

    root: Path
    summary: dict[str, Any] | None = None
    year: list[dict[str, Any]] = field(default_factory=list)
    source_table_1: list[dict[str, Any]] = field(default_factory=list)


def run_fluid_bed(case_file: Path, out: Path | None, month: int | None = None,
                  year: bool = False, force: bool = False) -> FluidBedRun:
    """Run the fluid-bed cooler with its refrigeration cycle at the case's conditions, one
    month of its weather table, or every month, into its run directory (default
    ``runs/cooler/fluid-bed/<case>[-monthMM|-year]``).

    Raises
    ------
    CaseError
        Both ``month`` and ``year``, or a case the model refuses (nothing is written then).
    """
    from drumflow.coolers import _fluid_bed_plots as plots
    from drumflow.coolers._rundir import open_cooler_run, write_result
    from drumflow.coolers.fluid_bed import operate, operate_year, source_cycle_checks
    from drumflow.coolers.fluid_bed_case import (
        case_conditions,
        load_fluid_bed_case,
        load_weather,
        month_conditions,
    )
    from drumflow.errors import CaseError

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
        return FluidBedRun(root, year=rows, source_table_1=source_rows)
    _unit_outputs(plots, op, root, target, label)
    summary = {**_flat(op.summary()), **_sections(op)}
    write_result(rundir, {"model": "fluid-bed", "case": case.name, "month": month, **summary},
                 time.perf_counter() - start)
    return FluidBedRun(root, summary=summary)


@dataclass(frozen=True)
class FluidBedFitRun:
    """A fit of the fluid-bed cooler's two parameters: its summary, the number of operating
    points, and the run directory."""

    root: Path
    summary: dict[str, Any]
    points: int


def run_fluid_bed_fit(case_file: Path, data: Path, out: Path | None,
                      force: bool = False) -> FluidBedFitRun:
    """Fit the convective efficiency f_c and hood losses hLosses*A to the measured operating
    points of ``data`` into a run directory (default ``runs/cooler/fluid-bed/<case>-fit``):
    ``result.json``, ``fit.png`` and ``fit_residuals.csv``."""
    from drumflow.coolers import _fluid_bed_plots as plots
    from drumflow.coolers._rundir import open_cooler_run, write_result
    from drumflow.coolers.fit import fit_parameters, read_points
    from drumflow.coolers.fluid_bed_case import load_fluid_bed_case

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
    return FluidBedFitRun(root, summary, len(points))


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
                       f"{label}ambient {amb:.1f} °C; product out "
                       f"{celsius_text(unit.product_outlet_temperature)}, "
                       f"air out (measured) {celsius_text(unit.air_measured_temperature)}")
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


def plot_curtain(case: CurtainCase, result: CurtainResult, path: Path) -> Path:
    """Solids and gas-outlet temperatures down the curtain, like the paper's Figures 3-8."""
    from drumflow._mpl import pyplot

    plt = pyplot()
    fig, ax = plt.subplots(figsize=(6.4, 4.4), dpi=120)
    depth_cm = 100 * result.depth_m
    ax.plot(depth_cm, result.solids_profile_C, "-", color="tab:blue", lw=2,
            label="solids (mean leaving each row)")
    ax.plot(depth_cm, result.gas_profile_C, ":", color="tab:red", lw=2,
            label="gas (leaving the curtain)")
    ax.axhline(case.gas.inlet_temperature_C, color="tab:red", lw=0.8, alpha=0.5)
    ax.axhline(case.solids.inlet_temperature_C, color="tab:blue", lw=0.8, alpha=0.5)
    ax.set_xlabel("distance from the top of the curtain (cm)")
    ax.set_ylabel("temperature (°C)")
    ax.set_xlim(0, 100 * case.geometry.height)
    ax.set_title(f"{case.name}: v_g {case.gas.velocity:g} m/s, {100 * case.geometry.thickness:g} cm, "
                 f"{case.solids.mass_flow:g} kg/s\nduty {result.heat_to_solids_w:.0f} W, "
                 f"h {result.h_w_m2k:.0f} W/m²K, Bi {result.biot:.2f}", fontsize=10)
    ax.grid(alpha=0.3)
    ax.legend(loc="center right", fontsize=9)
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)
    return path
