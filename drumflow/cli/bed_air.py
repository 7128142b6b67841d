"""`drumflow bed-air CASE --state STATE.npz --out DIR [--heat | --heat-only]`: the drum's air solved once with
a bed state's particles as Ergun porosity, beside the empty drum's, and what the bed and the
curtains do to it (:mod:`drumflow.air.bed_air`); with ``--heat`` also the air's temperature
with the particles' heat, and the contact efficiency (:mod:`drumflow.air.bed_heat`).

Exit codes (:func:`drumflow.errors.exit_code`): 0 written, 1 OpenFOAM failed or did not
converge, 2 bad input (case file, a state of another scene, a grid spacing out of range, an
unknown ``--axial``, ``--mixing``, ``--flux`` or ``--film``, ``--heat-only`` without a matching
earlier run), 130 interrupted. Bad input is refused before any solver starts.
"""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Optional

import typer
from rich.table import Table

from drumflow.cli._common import load_case_file
from drumflow.cli._guard import console, err_console

if TYPE_CHECKING:
    from drumflow.air.bed_air import BedAirResult, BedSnapshot
    from drumflow.case import Case

__all__ = ["bed_air"]

#: Where the two OpenFOAM cases go unless ``--work`` says otherwise.
DEFAULT_WORK = Path("/var/tmp/drumflow-runs/bed_air")


def bed_air(
    case_file: Annotated[Path, typer.Argument(help="case file (TOML) the state belongs to")],
    state_file: Annotated[Path, typer.Option("--state", help="bed state (.npz, `drumflow export "
                                             "RUN --state`)")],
    out: Annotated[Path, typer.Option("--out", help="folder for split.json, split.csv and the "
                                      "cross-section picture")],
    grid_spacing: Annotated[Optional[float], typer.Option(
        "--grid-spacing", help="deposition grid size, m (default: the larger of two parcel "
        "diameters and the air mesh size)")] = None,
    processes: Annotated[int, typer.Option("--processes", help="MPI ranks for simpleFoam")] = 1,
    axial: Annotated[str, typer.Option("--axial", help="periodic: the slice as a piece of a long "
                                       "drum at the case's mean air velocity (the plant's "
                                       "question); inlet-outlet: the case's own ends")
                     ] = "periodic",
    heat: Annotated[bool, typer.Option("--heat", help="also solve the air's temperature with "
                                       "the particles' heat (Gunn) and write heat.json: the "
                                       "contact efficiency")] = False,
    mixing: Annotated[str, typer.Option("--mixing", help="the heat's diffusivity: local (each "
                                        "cell's own: the solved turbulence in free air and "
                                        "curtains, a packed bed's dispersion in the bed), "
                                        "turbulent (the mean nu_t everywhere, an upper bound for "
                                        "the bed's heat) or molecular (the lower bound)")
                      ] = "local",
    flux: Annotated[str, typer.Option("--flux", help="the flux the heat is carried with: "
                                      "relative (MRF's, to the drum), absolute (the lab's, as "
                                      "the coupled loop) or carried (absolute plus the air the "
                                      "bed's particles carry)")] = "relative",
    film: Annotated[str, typer.Option("--film", help="the particles' film law: gunn (at the "
                                      "cell's voidage) or ranz_marshall (the coupled loop's)")
                    ] = "gunn",
    heat_only: Annotated[bool, typer.Option("--heat-only", help="only the air's temperature "
                                            "(implies --heat), on the flow an earlier run solved "
                                            "in the work folder for this state; its split.json in "
                                            "--out must match")] = False,
    work: Annotated[Optional[Path], typer.Option(
        "--work", help="where the OpenFOAM cases go (default /var/tmp/drumflow-runs/bed_air/"
        "<out folder name>)")] = None,
) -> None:
    """Solve the drum's air with a bed state's particles as porosity (Ergun), once, and
    measure the through-flow of bed, curtains and free air against the empty drum."""
    from drumflow.air.bed_air import solve_bed_air, write_bed_air
    from drumflow.dem.state import check_state, read_state
    from drumflow.runner import Runner

    case = load_case_file(case_file)
    state = read_state(state_file)
    check_state(state, case, state_file)
    _check_options(case, case_file, grid_spacing, processes, axial, mixing, flux, film)
    workdir = work or DEFAULT_WORK / out.resolve().name
    result: BedAirResult | None = None
    paths: list[Path] = []
    if heat_only:
        _check_reuse(out / "split.json", case.name, state, axial)
    else:
        err_console.print(f"solving the empty drum and the bed in {workdir} ...", highlight=False)
        result = solve_bed_air(case, state, workdir, Runner(), spacing=grid_spacing,
                               processes=processes, axial=axial)  # type: ignore[arg-type]
        paths = list(write_bed_air(result, out))
        _print_split(result, case.name, axial)
    if heat or heat_only:
        from drumflow.air.bed_heat import heat_file_name, solve_bed_heat

        err_console.print("solving the air's temperature with the particles' heat ...",
                          highlight=False)
        warm = solve_bed_heat(result, state, case, Runner(), workdir, spacing=grid_spacing,
                              mixing=mixing, flux=flux, film=film)
        # One file per choice, so the bounds and the loop's choices sit beside the default.
        paths.append(out / heat_file_name(mixing, flux, film))
        paths[-1].write_text(json.dumps(warm.as_dict(), indent=2, default=float) + "\n")
        console.print(
            f"heat taken by the air {warm.heat_W / 1e3:.4g} kW of {warm.heat_bulk_W / 1e3:.4g} kW "
            f"with fresh air everywhere: contact efficiency {warm.contact_efficiency:.3f}; air "
            f"{warm.air_inlet_temperature_C:.1f} -> {warm.air_outlet_temperature_C:.2f} C; as "
            f"saturated air {warm.saturated_flow_m3_s_m:.3g} m3/s per metre", highlight=False)
    console.print("written: " + ", ".join(str(p) for p in paths), highlight=False)


def _check_options(case: Case, case_file: Path, grid_spacing: float | None, processes: int,
                   axial: str, mixing: str, flux: str = "relative", film: str = "gunn"
                   ) -> None:
    """Refuse, by name, what no solver should start with."""
    from drumflow.air.bed_air import AXIAL_MODES
    from drumflow.air.bed_heat import check_choices
    from drumflow.errors import AnalysisInputError
    from drumflow.geometry.fluid import fluid_mesh_size

    if case.air.model != "cfd":
        raise AnalysisInputError(f"{case_file}: air.model", case.air.model, "'cfd'")
    if grid_spacing is not None:
        top = 0.5 * min(case.drum.diameter, case.drum.length)
        low = fluid_mesh_size(case) / 4.0
        if not (math.isfinite(grid_spacing) and low <= grid_spacing <= top):
            raise AnalysisInputError("--grid-spacing", grid_spacing,
                                     f"a length from {low:.4g} m (a quarter of the mesh size) to "
                                     f"{top:.4g} m (half the drum's smaller extent)")
    if not 1 <= processes <= 256:
        raise AnalysisInputError("--processes", processes, "an integer from 1 to 256")
    if axial not in AXIAL_MODES:
        raise AnalysisInputError("--axial", axial, " or ".join(AXIAL_MODES))
    check_choices(mixing, flux, film, prefix="--")


def _check_reuse(split_file: Path, case_name: str, state: BedSnapshot, axial: str) -> None:
    """Refuse --heat-only unless ``split_file`` records this case, state and --axial."""
    from drumflow.errors import AnalysisInputError

    if not split_file.is_file():
        raise AnalysisInputError(f"{split_file}", "missing", "the split.json of an earlier "
                                 "drumflow bed-air run with the same --out")
    try:
        split = json.loads(split_file.read_text())
        was = (split["case_name"], split["axial"], float(split["state"]["time_s"]),
               int(split["state"]["particles"]))
    except (ValueError, KeyError, TypeError) as exc:
        raise AnalysisInputError(f"{split_file}", f"unreadable ({exc})",
                                 "a split.json written by drumflow bed-air") from exc
    now = (case_name, axial, float(state.time_s), len(state))
    if was[:2] != now[:2] or not math.isclose(was[2], now[2], abs_tol=1e-9) or was[3] != now[3]:
        raise AnalysisInputError(f"{split_file}", f"case, --axial, state time, particles {was}",
                                 f"those of this run {now}")


def _print_split(result: BedAirResult, case_name: str, axial: str) -> None:
    from drumflow.air.bed_air import CATEGORIES

    table = Table(title=f"{case_name}: air around the bed (state t = {result.state['time_s']:.3f} "
                  f"s, {axial} air)")
    for col in ("", "cells", "axial flow empty", "axial flow bed", "|U| empty", "|U| bed"):
        table.add_column(col, justify="left" if col == "" else "right")
    e, b = result.empty, result.bed
    for name in CATEGORIES:
        table.add_row(name, f"{result.category_cells[name]:,}",
                      f"{e.axial_flow_m3_s[name]:.4g} m3/s", f"{b.axial_flow_m3_s[name]:.4g} m3/s",
                      f"{e.mean_speed_m_s[name]:.3g} m/s", f"{b.mean_speed_m_s[name]:.3g} m/s")
    table.add_row("total", f"{result.cells:,}", f"{e.axial_flow_m3_s['total']:.4g} m3/s",
                  f"{b.axial_flow_m3_s['total']:.4g} m3/s", "", "")
    console.print(table)
    console.print(
        f"into the curtains from free air: {e.inflow_m3_s_m['curtain_from_free']:.4g} (empty) -> "
        f"{b.inflow_m3_s_m['curtain_from_free']:.4g} m3/s/m (bed); into the bed: "
        f"{e.inflow_m3_s_m['bed_from_other']:.4g} -> {b.inflow_m3_s_m['bed_from_other']:.4g} "
        f"m3/s/m\npressure drop {e.pressure_drop_Pa:.4g} Pa (empty) -> {b.pressure_drop_Pa:.4g} "
        f"Pa (bed); solids on the cells {100 * result.deposit['cells_over_particles']:.2f} % of "
        f"the particles'; wall time {result.wall_time_s:.0f} s", highlight=False)
