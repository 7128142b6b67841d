"""The paper comparison's page and files: ``paper.json``, ``comparison.csv`` and one HTML page.

The page sets drumflow's runs of the paper's two cases (:mod:`drumflow.report.paper_results`)
beside Burgos-Florez et al. (2019): Tables 3-8 as paper | drumflow | difference, Figures 4 and
6-9, built from the pieces of :mod:`drumflow.report.page_parts`. It is self-contained (every
picture embedded) and only reads what the results hold.
"""

from __future__ import annotations

import csv
import json
import math
import time
from collections.abc import Sequence
from dataclasses import asdict
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from drumflow._json import json_safe
from drumflow.analysis.air_side import lumped_mean_temperature
from drumflow.analysis.correlation import NusseltCorrelation
from drumflow.analysis.methodology import fit_runs
from drumflow.analysis.published import (
    EQ58,
    PAPER_MODELS,
    PAPER_PARTICLE_CONDUCTIVITY,
    reynolds_conversion,
)
from drumflow.errors import AnalysisInputError, RunDirectoryError
from drumflow.physics.particle_air import AirState, ranz_marshall_slip
from drumflow.report.animation import ANIMATION
from drumflow.report.page_parts import (
    Figure,
    Table,
    figure_uri,
    file_uri,
    fmt,
    h_figure,
    nusselt_reynolds_figure,
    render_page,
    table8,
)
from drumflow.report.paper_results import AT_S, PARTICLES_3D, PARTICLES_TIMES, PaperRun

__all__ = ["build_page", "write_paper"]


# ------------------------------------------------------------------------------ the page


def _anchor(model: str) -> str:
    return f"model-{model}"


def _comparison_table(run: PaperRun) -> Table:
    rows = [[r.quantity, r.source, fmt(r.paper), fmt(r.drumflow), fmt(r.difference),
             f"{r.relative:+.1%}" if math.isfinite(r.relative) else "–", r.unit] for r in run.rows]
    return Table(f"Model {run.model}: the paper's Tables 4, 6 and 7 beside drumflow",
                  ["quantity", "paper's source", "paper", "drumflow", "difference", "relative",
                   "unit"], rows,
                  "difference = drumflow - paper. Re: the paper's value converted to drumflow's "
                  "definition (see the top of the page).")


def _duration(seconds: Any) -> str:
    if not isinstance(seconds, (int, float)) or not math.isfinite(seconds):
        return "–"
    return f"{seconds:,.0f} s ({seconds / 3600:.2f} h)"


def _record_table(run: PaperRun) -> Table:
    r = run.record
    m = r.get("machine") or {}
    target = r.get("target_time_s")
    sim = r.get("simulated_time_s")
    reached = (f"{fmt(sim)} of {fmt(target)} s"
               + (f" ({sim / target:.0%})" if isinstance(sim, (int, float)) and target else ""))
    rows = [
        ["simulated time reached", reached + ("" if r.get("finished") else ", not finished")],
        ["wall time of the last `drumflow run` call", _duration(r.get("wall_time_s"))],
        [f"DEM wall time ({r.get('dem_wall_time_source', '')})", _duration(r.get("dem_wall_time_s"))],
        ["air stage wall time (OpenFOAM)" + (", field from the cache" if r.get("air_field_cache_hit")
                                             else ""), _duration(r.get("air_wall_time_s"))],
        ["air cells (paper's mesh 2: "
         f"{PAPER_MODELS[run.model].air_cells:,})", fmt(r.get("air_cells"))],
        ["particle-steps per second", fmt(r.get("particle_steps_per_s"))],
        ["machine", f"{m.get('cpu', '?')}, {m.get('cpus', '?')} cpus; {m.get('platform', '?')}"],
        ["MPI processes", fmt(m.get("processes"))],
    ]
    if run.case is not None:
        rows.insert(0, ["case", f"{run.case.name}: {run.case.particle_count:,} particles of "
                        f"{run.case.particles.diameter * 1e3:g} mm, section {run.case.drum.length:g} m"])
        moved = run.case.dem_case()
        if moved is not run.case:
            # A coarse-grained run answers a sweep's question, not the paper's at 1 %: say so.
            rows.insert(1, ["coarse-grained (particles.coarse_grain)",
                            f"the DEM moved {moved.particle_count:,} parcels of "
                            f"{moved.particles.diameter * 1e3:g} mm ({run.case.particles.coarse_grain:g} "
                            "particle diameters), drag and heat per kg kept; on model two parcels of 2 "
                            "diameters kept the heat answer to 0.3 % and the falling mass flow to about 3 %"])
    return Table(f"Model {run.model}: the run", ["quantity", "value"], rows)


def _h_table(run: PaperRun) -> Table:
    paper = PAPER_MODELS[run.model]
    rows: list[list[str]] = [["paper, Table 6 (Eq. 39)", fmt(paper.h_w_m2k), ""]]
    if run.methodology is not None:
        rows.append(["drumflow, Eq. 39 from the mean temperature (Table 6)",
                     fmt(run.methodology.h_mean_w_m2k),
                     f"time average over {run.methodology.n_valid:,} steps"])
    if run.coupling is not None:
        rows.append(["drumflow, coupling log: heat / (all particle surface × (T_p − T_air))",
                     fmt(run.coupling.h_run_w_m2k),
                     f"{run.coupling.updates:,} updates over {run.coupling.time_s:.3g} s"])
    a = run.air_side
    if a is not None:
        share = a.get("airborne_heat_share")
        rows += [
            ["last snapshot: all particles (surface mean, Ranz-Marshall)", fmt(a.get("h_mean_w_m2k")),
             f"{a.get('snapshot')}, t = {fmt(a.get('time_s'), 4)} s"],
            ["last snapshot: bed", fmt(a.get("h_bed_w_m2k")),
             f"slip {fmt(a.get('slip_bed_m_s'), 3)} m/s"],
            ["last snapshot: airborne (falling)", fmt(a.get("h_airborne_w_m2k")),
             f"{fmt(a.get('airborne'))} particles, slip {fmt(a.get('slip_airborne_m_s'), 3)} m/s, "
             + (f"{share:.1%} of the heat" if isinstance(share, (int, float)) else "")],
        ]
    if run.case is not None:
        # What air speed the paper's h needs in the correlation drumflow applies (Eq. 23), to
        # set beside the slip the particles see: the measured source of the h difference.
        air = AirState.at(run.case.air.inlet_temperature_C, run.case.air.pressure_kPa)
        slip = ranz_marshall_slip(paper.h_w_m2k, run.case.particles.diameter, air)
        seen = a.get("slip_mean_m_s") if a is not None else None
        rows.append(["slip speed the paper's h needs in Ranz-Marshall (Eq. 23), m/s", fmt(slip, 3),
                     f"the particles see {fmt(seen, 3)} m/s (last snapshot, mean)"
                     if isinstance(seen, (int, float)) else ""])
    if run.case is not None and run.methodology is not None:
        surface = run.case.particle_count * math.pi * run.case.particles.diameter**2
        rows += [
            ["surface h acts on in the slice: every particle, N π Dp² (m²)", fmt(surface), ""],
            ["surface Eq. 46 gives h per second: A_fp / dt (m²/s)",
             fmt(run.methodology.falling_area_m2 / run.methodology.dt_s), "the falling particles"],
        ]
    return Table(f"Model {run.model}: what h is (W/(m² K))", ["h", "value", ""], rows,
                  "Eq. 39 with Eqs. 35 and 41 is rho Dp cp (−dT/dt) / (6 LMTD): the falling mass "
                  "cancels, so the paper's h is the lumped coefficient over the surface of every "
                  "particle of the slice, the same number the coupling log gives. Eq. 46 then "
                  "applies it only to the surface falling per second.")


def _temperature_figure(run: PaperRun) -> Figure:
    paper = PAPER_MODELS[run.model]
    number = {"one": "7", "two": "8"}[run.model]
    fig = Figure(f"Mean particle temperature (Figure {number}; Tables 3-4 at {AT_S:g} s)")
    csv_path = run.root / "post" / "mean_temperature.csv"
    try:
        table = pd.read_csv(csv_path)
        t = table["time_s"].to_numpy(float)
        temp = table["mean_temperature_C"].to_numpy(float)
    except (OSError, ValueError, KeyError) as exc:
        fig.note = f"no mean temperature: {csv_path} could not be read ({exc})"
        return fig
    case = run.case
    t_end = max(float(t[-1]), AT_S)
    grid = np.linspace(0.0, t_end, 200)

    def draw(ax: Any) -> None:
        ax.plot(t, temp, color="tab:red", lw=1.8, label="drumflow")
        if case is not None:
            lumped = lumped_mean_temperature(case, paper.h_w_m2k, grid[1:])
            ax.plot(grid[1:], lumped, color="0.4", lw=1.2, ls="--",
                    label=f"every particle at the paper's h = {paper.h_w_m2k:g} W/(m² K)")
        for value, label, marker in (
            (paper.mean_temperature_3p5s_mesh1_C, "paper, mesh 1", "v"),
            (paper.mean_temperature_3p5s_C, "paper, mesh 2 (chosen)", "o"),
            (paper.mean_temperature_3p5s_mesh3_C, "paper, mesh 3", "^"),
        ):
            ax.plot([AT_S], [value], marker, color="black", ms=6, mfc="none" if "chosen" not in label
                    else "black", label=f"{label}: {value:g} °C")
        ax.set_xlabel("time (s)")
        ax.set_ylabel("mean particle temperature (°C)")
        ax.legend(fontsize=8)
        ax.grid(alpha=0.3)

    fig.uri = figure_uri(draw)
    fig.caption = (f"from {csv_path.name}; the dashed curve is the lumped cooling of every particle "
                   "at the paper's h (what its Eq. 39 means), the markers Table 4's three meshes")
    return fig


def _run_tables_and_figures(run: PaperRun) -> tuple[list[Table], list[Figure]]:
    tables = [_record_table(run), _comparison_table(run), _h_table(run)]
    figures = [_temperature_figure(run)]
    if run.methodology is not None:
        figures.append(h_figure(run.methodology))
    crossings = Figure("Particles crossing the axis plane downwards (Figure 4)",
                        uri=file_uri(run.root / "post" / "crossings.png"))
    if crossings.uri is None:
        crossings.note = "no post/crossings.png"
    figures.append(crossings)
    particles = Figure("Particles coloured by temperature, last snapshot (Figure 6)",
                        uri=file_uri(run.root / "post" / PARTICLES_3D))
    if particles.uri is None:
        particles.note = f"no post/{PARTICLES_3D} (3-D rendering off, failed, or not shipped)"
    figures.append(particles)
    over_time = Figure("The section at several times, coloured by temperature (Figure 6)",
                        uri=file_uri(run.root / "post" / PARTICLES_TIMES))
    if over_time.uri is None:
        over_time.note = f"no post/{PARTICLES_TIMES} (no snapshot, or not shipped)"
    figures.append(over_time)
    motion = Figure("Figure 6 in motion: the section at every snapshot, coloured by temperature",
                     uri=file_uri(run.root / "post" / ANIMATION))
    if motion.uri is None:
        motion.note = f"no post/{ANIMATION} (no snapshot, or not shipped)"
    figures.append(motion)
    air = file_uri(run.root / "air" / "air_cross_section.png")
    if air is not None:
        figures.append(Figure("Air field, cross-section", uri=air))
    return tables, figures


def _reynolds_table() -> Table:
    conv = reynolds_conversion()
    rows = []
    for model, v in conv.per_model.items():
        rows.append([f"model {model}", fmt(v["re_paper"]), fmt(v["re_drumflow"]),
                     f"{v['ratio']:.4f}", fmt(v["v_ai_m_s"], 4), fmt(v["void_fraction"], 4),
                     fmt(v["v_max_drumflow_m_s"], 4), fmt(v["v_max_paper_implied_m_s"], 4)])
    return Table(
        "Reynolds number: the paper's and drumflow's definitions (Eqs. 51-54)",
        ["", "Re, paper", "Re, drumflow", "ratio", "V_ai (m/s)", "Vf", "v_max drumflow (m/s)",
         "v_max implied by the paper (m/s)"], rows,
        f"One factor {conv.factor:.4f} fits both models to {conv.factor_spread:.2%}: a definition, "
        "not physics. drumflow compares in its own definition; the paper's Re range and Eq. 58 are "
        f"converted (range / {conv.factor:.4f}; a × {conv.factor:.4f}^b × {conv.prandtl_factor:.4f}^c, "
        "the last factor for the paper's Pr table, 0.7282 against drumflow's 0.7066 at 30 °C).")


def _reading() -> list[str]:
    return [
        "Eq. 39 with Eqs. 35 and 41 put in is h = ρ Dp cp (−dT/dt) / (6 LMTD): the falling mass "
        "cancels. The paper's h is therefore the lumped coefficient over the surface of every "
        "particle of the slice, bed and curtain, because its one-way air acts on all of them; "
        "Eq. 46 then applies that h only to the surface falling per second. The coupling log "
        "gives the same coefficient directly (each model's 'what h is' table).",
        "drumflow's Re (Eqs. 51-54 with the whole cross-section and the void factor) is 1.667 "
        "times smaller than the paper's for both models (table below). Every Re on this page is "
        "drumflow's; the paper's are converted.",
        "Table 8's ANOVA counts every time step as an independent observation. Consecutive steps "
        "are not independent: the residuals' lag-1 autocorrelation gives an effective sample "
        "size and wider errors, shown beside the paper-style table.",
    ]


def _figure9(runs: Sequence[PaperRun], corr: NusseltCorrelation | None) -> Figure:
    from drumflow.coolers.prediction import paper_correlation

    eq58 = paper_correlation()
    conv = reynolds_conversion()
    analysed = [(f"drumflow, model {r.model} (per step)", r.methodology) for r in runs
                if r.methodology is not None]
    pr = eq58.prandtl_range[0]

    def paper(ax: Any) -> None:
        lo, hi = eq58.reynolds_range
        grid = np.geomspace(lo, hi, 100)
        ax.plot(grid, eq58.predict(grid, pr, warn=False), color="black", lw=1.4,
                label=f"paper's Eq. 58, converted (Re {lo:.0f}-{hi:.0f})")
        for (model, v), marker in zip(conv.per_model.items(), ("s", "D"), strict=True):
            table6 = PAPER_MODELS[model]  # type: ignore[index]
            ax.plot([v["re_drumflow"]], [table6.h_w_m2k * table6.particle_diameter_m
                                         / PAPER_PARTICLE_CONDUCTIVITY], marker, color="black",
                    mfc="none", ms=8, label=f"paper, model {model} (Table 6 h)")

    fig = nusselt_reynolds_figure(
        "Nusselt against Reynolds, drumflow's definition (Figure 9)", analysed, corr, pr,
        xlabel="Re (drumflow's Eqs. 51-54)",
        ylabel="Nu = h Dp / k_m (particle conductivity, as the paper)",
        reference=paper, size=(6.4, 4.2))
    fig.caption = ("per-step values of the valid steps; the paper's curve is drawn at drumflow's "
                   "Pr of air at 30 °C, which is its Pr = 0.7282 in the paper's property table")
    if not analysed:
        fig.caption += "; no drumflow run could be analysed yet"
    return fig


def _table8_beside_paper(corr: NusseltCorrelation) -> Table:
    from drumflow.coolers.prediction import paper_correlation

    t = corr.anova
    rows = [
        ["a", f"{EQ58['a']:.6g} (in drumflow's Re and Pr: {paper_correlation().a:.6g})",
         fmt(corr.a, 6)],
        ["b", fmt(EQ58["b"], 6), fmt(corr.b, 6)],
        ["c" + ("" if corr.prandtl_exponent_fitted else " (fixed in drumflow's fit)"),
         fmt(EQ58["c"], 6), fmt(corr.c, 6)],
        ["observations (time steps)", fmt(int(EQ58["observations"])), fmt(corr.n)],
        ["error degrees of freedom", "4,799", fmt(t.df_error)],
        ["error sum of squares", "4.05118", fmt(t.ss_error, 6)],
        ["adjusted R² (%)", fmt(100 * EQ58["adjusted_r2"], 6), fmt(100 * corr.adjusted_r_squared, 6)],
    ]
    if corr.serial is not None:
        rows.append(["effective observations (serial correlation)", "–",
                     fmt(corr.serial.n_effective, 4)])
    return Table("Table 8 beside the paper", ["", "paper", "drumflow"], rows,
                  "The paper's a is for its own Re and Pr; the value in brackets is the same "
                  "correlation in drumflow's definitions, the one comparable with drumflow's a.")


def build_page(runs: Sequence[PaperRun], source: str) -> tuple[str, dict[str, Any]]:
    """The HTML page and the ``paper.json`` content for some model results."""
    import drumflow

    analysed = [r.methodology for r in runs if r.methodology is not None]
    corr: NusseltCorrelation | None = None
    no_fit = ""
    if len(analysed) < 2:
        no_fit = ("it needs both models analysed (within one run Re changes only through the air "
                  f"viscosity); {len(analysed)} of 2 are")
    else:
        try:
            corr = fit_runs(analysed, nusselt_conductivity="particle")
        except AnalysisInputError as exc:
            no_fit = f"the correlation could not be fitted: {exc}"
    views = []
    for run in runs:
        tables, figures = _run_tables_and_figures(run)
        views.append({"model": run.model, "anchor": _anchor(run.model), "path": str(run.root),
                      "kind": "a drumflow run directory" if run.kind == "run"
                      else "shipped results, no dumps",
                      "name": run.case.name if run.case is not None else run.root.name,
                      "notes": run.notes, "tables": tables, "figures": figures})
    html = render_page(
        "paper.html.j2",
        title="drumflow: the paper's two cases",
        version=drumflow.__version__,
        generated=time.strftime("%Y-%m-%d %H:%M:%S %z"),
        source=source,
        notes=[],
        runs=views,
        reading=_reading(),
        reynolds=_reynolds_table(),
        table8=([_table8_beside_paper(corr), *table8(corr)] if corr is not None else None),
        no_fit=no_fit,
        figure9=_figure9(runs, corr),
    )
    data = json_safe({
        "generated": time.strftime("%Y-%m-%dT%H:%M:%S%z"),
        "drumflow_version": drumflow.__version__,
        "source": source,
        "reynolds_conversion": reynolds_conversion().to_dict(),
        "models": {r.model: r.to_dict() for r in runs},
        "table8": _correlation_dict(corr) if corr is not None else {"not_fitted": no_fit},
    })
    return html, data


def _correlation_dict(corr: NusseltCorrelation) -> dict[str, Any]:
    return asdict(corr)


def write_paper(runs: Sequence[PaperRun], out_dir: Path | str, html_path: Path | str | None = None,
                *, source: str = "") -> dict[str, Path]:
    """Write ``paper.json``, ``comparison.csv`` and the HTML page.

    Parameters
    ----------
    runs
        The model results (:func:`collect_paper_run`), at least one.
    out_dir
        Folder of ``paper.json`` and ``comparison.csv`` (created if missing).
    html_path
        The page (default ``out_dir/paper.html``).
    source
        Where the results came from, printed on the page.

    Returns
    -------
    dict
        ``{"json": ..., "csv": ..., "html": ...}`` (absolute paths).

    Raises
    ------
    RunDirectoryError
        If ``runs`` is empty.
    """
    if not runs:
        raise RunDirectoryError("no model directory to compare with the paper")
    out = Path(out_dir).resolve()
    out.mkdir(parents=True, exist_ok=True)
    page = Path(html_path).resolve() if html_path is not None else out / "paper.html"
    html, data = build_page(runs, source)
    json_path = out / "paper.json"
    json_path.write_text(json.dumps(data, indent=2, allow_nan=False) + "\n")
    csv_path = out / "comparison.csv"
    with csv_path.open("w", newline="") as fh:
        writer = csv.writer(fh)
        writer.writerow(["model", "quantity", "source", "paper", "drumflow", "difference",
                         "relative", "unit"])
        for run in runs:
            for r in run.rows:
                writer.writerow([run.model, r.quantity, r.source, f"{r.paper:.10g}",
                                 f"{r.drumflow:.10g}", f"{r.difference:.10g}",
                                 f"{r.relative:.10g}", r.unit])
    page.parent.mkdir(parents=True, exist_ok=True)
    page.write_text(html, encoding="utf-8")
    return {"json": json_path, "csv": csv_path, "html": page}
