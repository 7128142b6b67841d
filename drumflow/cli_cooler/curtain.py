"""`drumflow cooler curtain CASE`: the particle-curtain model (Wardjiman and Rhodes 2009)."""

from __future__ import annotations

import json
import time
from pathlib import Path
from typing import TYPE_CHECKING, Annotated

import typer
from rich.table import Table

from drumflow.case import read_toml, validate_model
from drumflow.cli_cooler._app import app, console, guard

if TYPE_CHECKING:
    from drumflow.coolers.curtain import CurtainCase, CurtainResult


def plot_curtain(case: CurtainCase, result: CurtainResult, path: Path) -> Path:
    """Solids and gas-outlet temperatures down the curtain, like the paper's Figures 3-8."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

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


@app.command("curtain")
def curtain(
    case_file: Annotated[Path, typer.Argument(help="curtain case file (TOML)")],
    out: Annotated[Path | None, typer.Option("--out", "-o", help="run directory")] = None,
    as_json: Annotated[bool, typer.Option("--json", help="print the result as JSON")] = False,
    force: Annotated[bool, typer.Option("--force", help="reuse a directory of another case")] = False,
) -> None:
    """Heat transfer in a particle curtain crossed by a gas stream (element-array model)."""
    # Imported here so that other commands do not load the model (and scipy) at start-up.
    from drumflow.coolers._rundir import open_cooler_run, write_result
    from drumflow.coolers.curtain import CurtainCase, solve_curtain

    with guard():
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
    table.add_row("written", f"{rundir.root / 'result.json'}, {plot}")
    console.print(table)
