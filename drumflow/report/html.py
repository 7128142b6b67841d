"""One self-contained HTML page for a run or a sweep of runs (the paper's Tables 6-8, Figures 4, 6-9).

The page has no external references. Every picture is embedded as a base64 PNG ``data:`` URI,
the style sheet is inline, and there is no script, so the file can be mailed, archived or opened
offline. It holds:

* per run: the case (table), the observables of ``summary.json``, the mean temperature curve
  (Figures 7-8), the per-step ``h``, the crossing scatter (Figure 4, ``post/crossings.png``), an
  off-screen PyVista picture of the last snapshot coloured by temperature (Figure 6), the
  geometry cross-section, and the manifest (pretty JSON in a ``<details>`` block);
* across runs: Table 6 (heat-transfer variables), Table 7 (exchanger model against the plant),
  Table 8 (correlation and ANOVA, when the data allow a fit, otherwise the reason), and
  Nu against Re with the fitted curve (Figure 9).

Nothing stops the page from being written. A run without air (no ``h``), a missing file or a
failed render gives a note in its place. Only a path that is not a run directory (missing, or
without a case file and a manifest) is an error. Every path comes from
:class:`~drumflow.rundir.RunDir`.
"""

from __future__ import annotations

import json
import math
import tempfile
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from drumflow.analysis.correlation import NusseltCorrelation
from drumflow.analysis.methodology import analyse_run, fit_runs
from drumflow.analysis.methodology_result import FallingMassMode, MethodologyResult, NusseltConductivity
from drumflow.case import Case, load_case
from drumflow.errors import (
    AnalysisInputError,
    BadFileError,
    DrumflowError,
    RenderError,
    RunDirectoryError,
)
from drumflow.readers import read_json_object_if_present
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
from drumflow.rundir import RunDir

__all__ = ["write_report"]


@dataclass
class _RunView:
    name: str
    path: str
    anchor: str
    notes: list[str] = field(default_factory=list)
    tables: list[Table] = field(default_factory=list)
    figures: list[Figure] = field(default_factory=list)
    manifest_json: str | None = None


def _anchor(i: int, name: str) -> str:
    safe = "".join(c if c.isalnum() or c in "-_" else "-" for c in name)
    return f"run-{i}-{safe}"


# ---------------------------------------------------------------------------- run parts


def _case_table(case: Case) -> Table:
    rows: list[list[str]] = []
    for section, values in case.model_dump(mode="json").items():
        if isinstance(values, dict):
            for key, val in values.items():
                if isinstance(val, dict):
                    for sub, v in val.items():
                        rows.append([f"{section}.{key}.{sub}", fmt(v)])
                else:
                    rows.append([f"{section}.{key}", fmt(val)])
        else:
            rows.append([section, fmt(values)])
    rows.append(["(derived) particle count", fmt(case.particle_count)])
    rows.append(["(derived) particle mass total, kg", fmt(case.particle_mass_total)])
    rows.append(["(derived) Froude number", fmt(case.drum.froude)])
    return Table("Case", ["field", "value"], rows)


_SUMMARY_LABELS = {
    "particles_initial": "particles at start",
    "particles_final": "particles at end",
    "particles_escaped_through_walls": "escaped through walls",
    "simulated_time_s": "simulated time, s",
    "mean_temperature_initial_C": "mean temperature at start, °C",
    "mean_temperature_C": "mean temperature at end, °C",
    "falling_mass_flow_kg_s": "falling mass flow (Eq. 57), kg/s",
    "curtain_mass_flow_kg_s": "of which curtain, kg/s",
    "airborne_mass_flow_kg_s": "airborne (no particle contact at the crossing), kg/s",
    "bed_mass_flow_kg_s": "the bed (in contact at the crossing), kg/s",
    "falling_crossings": "crossings counted",
    "wall_time_s": "wall time, s",
    "particle_steps_per_s": "particle-steps per second",
}


def _summary_table(summary: dict[str, Any]) -> Table:
    rows = [[label, fmt(summary[key])] for key, label in _SUMMARY_LABELS.items() if key in summary]
    # Any other scalar the run recorded, so nothing in summary.json is hidden.
    for key, val in summary.items():
        if key not in _SUMMARY_LABELS and isinstance(val, (int, float, str, bool)):
            rows.append([key, fmt(val)])
    return Table("Observables (summary.json)", ["quantity", "value"], rows)


def _mean_temperature_figure(run: RunDir) -> Figure:
    fig = Figure("Mean particle temperature (Figures 7 and 8)")
    png = file_uri(run.mean_temperature_plot)
    if png is not None:
        fig.uri = png
        return fig
    csv = run.mean_temperature_csv
    try:
        table = pd.read_csv(csv)
        t = table["time_s"].to_numpy(dtype=float)
        temp = table["mean_temperature_C"].to_numpy(dtype=float)
    except (OSError, ValueError, KeyError) as exc:
        fig.note = f"no mean temperature: {csv} could not be read ({exc})"
        return fig

    def draw(ax: Any) -> None:
        ax.plot(t, temp, color="tab:red", lw=1.6)
        ax.set_xlabel("time (s)")
        ax.set_ylabel("mean particle temperature (°C)")
        ax.grid(alpha=0.3)

    fig.uri = figure_uri(draw)
    fig.caption = (f"from {csv.relative_to(run.root)} (no {run.mean_temperature_plot.name} "
                   "in the run)")
    return fig


def _particles_figure(run: RunDir, case: Case, render_3d: bool, timeout_s: float) -> Figure:
    fig = Figure("Particles coloured by temperature, last snapshot (Figure 6)")
    if not render_3d:
        fig.note = "3-D rendering was switched off for this report"
        return fig
    from drumflow.dem.dumps import dump_files, read_dump
    from drumflow.report.render import render_particles_isolated

    files = dump_files(run.dem_dumps, "snap")
    if not files:
        fig.note = f"no particle snapshot in {run.dem_dumps} (snap.*.txt or .npz)"
        return fig
    try:
        snap = read_dump(files[-1])
        cols = snap.columns
        missing = [c for c in ("x", "y", "z", "T") if c not in cols]
        if missing:
            raise RenderError(f"{files[-1]} lacks column(s) {', '.join(missing)}")
        ts = run.recorded_time_step
        when = f"t = {snap.step * ts:.3g} s" if ts else f"step {snap.step}"
        with tempfile.TemporaryDirectory(prefix="drumflow-report-") as tmp:
            png = render_particles_isolated(
                cols["x"], cols["y"], cols["z"], cols["T"], Path(tmp) / "particles.png",
                case.drum.radius, case.drum.length,
                particle_diameter=case.particles.diameter,
                title=f"{case.name}, {when}",
                timeout_s=timeout_s,
            )
            fig.uri = file_uri(png)
        fig.caption = f"{len(snap):,} particles from {files[-1].name}, {when} (PyVista, off-screen)"
        if fig.uri is None:
            fig.note = "the renderer wrote no PNG picture"
    except (DrumflowError, OSError, ValueError) as exc:
        fig.note = f"the 3-D picture could not be rendered: {exc}"
    return fig


def _run_view(i: int, run: RunDir, result: MethodologyResult | None, why_not: str | None,
              render_3d: bool, timeout_s: float) -> _RunView:
    case: Case | None = result.case if result is not None else None
    notes: list[str] = []
    if case is None:
        try:
            case = load_case(run.case_toml)
        except DrumflowError as exc:
            notes.append(f"case not available: {exc}")
    name = case.name if case is not None else run.root.name
    view = _RunView(name=name, path=str(run.root), anchor=_anchor(i, name), notes=notes)
    if why_not:
        view.notes.append(f"heat-transfer methodology not applied: {why_not}")
    if result is not None:
        view.notes.extend(result.warnings)
    if case is not None:
        view.tables.append(_case_table(case))
    summary = read_json_object_if_present(run.summary_path)
    if summary is not None:
        view.tables.append(_summary_table(summary))
    else:
        view.notes.append(f"no summary: {run.summary_path} is missing")
    manifest = read_json_object_if_present(run.manifest_path)
    view.manifest_json = json.dumps(manifest, indent=2, sort_keys=False) if manifest else None

    view.figures.append(_mean_temperature_figure(run))
    if result is not None:
        view.figures.append(h_figure(result))
    crossings = Figure("Particles crossing the axis plane downwards (Figure 4)",
                        uri=file_uri(run.crossings_plot))
    if crossings.uri is None:
        crossings.note = f"no crossing plot: {run.crossings_plot} is missing"
    view.figures.append(crossings)
    if case is not None:
        view.figures.append(_particles_figure(run, case, render_3d, timeout_s))
    section = file_uri(run.particles_plot)
    if section is not None:
        view.figures.append(Figure("Cross-section at the end of the run", uri=section))
    geometry = file_uri(run.geometry_picture)
    if geometry is not None:
        view.figures.append(Figure("Drum and lifter geometry", uri=geometry))
    return view


# --------------------------------------------------------------------------- sweep parts


def _table6(names: list[str], results: list[MethodologyResult | None]) -> Table:
    rows_def: list[tuple[str, Callable[[MethodologyResult], Any]]] = [
        ("Particle diameter Dp (mm)", lambda r: r.case.particles.diameter * 1e3),
        ("Time step dt (s)", lambda r: r.dt_s),
        ("Air mass m_a (kg)", lambda r: r.air_mass_per_step_kg),
        ("Material falling mass m_mf (kg)", lambda r: r.falling_mass_per_step_kg),
        ("Falling mass flow (kg/s)", lambda r: r.falling_mass_flow_kg_s),
        ("Area of heat exchange A_fp (m²)", lambda r: r.falling_area_m2),
        ("Average heat transfer coefficient h (W/(m² K))", lambda r: r.h_mean_w_m2k),
        ("Valid steps / steps", lambda r: f"{r.n_valid:,} / {r.n_steps:,}"),
    ]
    rows = [[label] + [fmt(get(r)) if r is not None else "–" for r in results]
            for label, get in rows_def]
    return Table("Table 6. Heat transfer variables during one time step", ["Model"] + names, rows)


def _table7(names: list[str], results: list[MethodologyResult | None]) -> Table:
    columns: list[tuple[str, Any, Any]] = []  # (header, exchanger result, methodology result)
    for name, r in zip(names, results, strict=True):
        if r is None:
            continue
        columns.append((name, r.exchanger, r))
        if r.plant_exchanger is not None:
            columns.append((f"{name}: plant at its T_mo", r.plant_exchanger, r))
    spec: list[tuple[str, Callable[[Any], Any]]] = [
        ("Particle diameter Dp (mm)", lambda c: c[2].case.particles.diameter * 1e3),
        ("Thermodynamic model", lambda c: ""),
        ("Material outlet temperature T_mo (°C)", lambda c: c[1].material_outlet_temperature_c),
        ("Thermal power Q_m (kW)", lambda c: c[1].heat_removed_w / 1e3),
        ("Air outlet temperature T_ao (°C)", lambda c: c[1].air_outlet_temperature_c),
        ("Counter-current heat exchanger model", lambda c: ""),
        ("Material inlet temperature T_mi (°C)", lambda c: c[1].material_inlet_temperature_c),
        ("Air inlet temperature T_ai (°C)", lambda c: c[1].air_inlet_temperature_c),
        ("LMTD_he (°C)", lambda c: c[1].lmtd_c),
        ("Heat transfer coefficient h (W/(m² K))", lambda c: c[1].h_w_m2k),
        ("Exchanged heat Q_he (kW)", lambda c: c[1].heat_exchanged_w / 1e3),
        ("Total area of heat exchange A_he (m²)", lambda c: c[1].area_m2),
    ]
    rows = [[label] + [fmt(get(c)) for c in columns] for label, get in spec]
    note = (
        "Model columns: A_he from the simulated section (Eq. 46 with L/l), T_mo solved from "
        "Q_he = Q_m (Eq. 48). Plant columns (when the case gives plant.material_outlet_temperature_C): "
        "the area the plant needs to reach that outlet temperature with the run's h."
    )
    return Table("Table 7. Thermodynamic and counter-current exchanger models",
                  ["Property"] + [c[0] for c in columns], rows, note)




def _figure9(names: list[str], results: list[MethodologyResult | None],
             corr: NusseltCorrelation | None) -> Figure:
    pairs = [(n, r) for n, r in zip(names, results, strict=True) if r is not None]
    if not pairs:
        return Figure("Nusselt against Reynolds (Figure 9)", note="no run could be analysed, so "
                      "there are no Nusselt and Reynolds numbers")
    pr_all = np.concatenate([r.prandtl[np.isfinite(r.prandtl)] for _, r in pairs])
    pr_mean = float(pr_all.mean()) if pr_all.size else math.nan
    fig = nusselt_reynolds_figure("Nusselt against Reynolds (Figure 9)", pairs, corr, pr_mean,
                                  xlabel="Re (Eq. 51)", ylabel="Nu (Eq. 49)",
                                  axes_title=f"Pr = {pr_mean:.4g}")
    k = {r.nusselt_conductivity for _, r in pairs}
    fig.caption = (
        "per-step values of the valid steps; Nu with the "
        + " / ".join(sorted(k)) + " conductivity"
        + ("" if corr is not None else "; no fitted curve (see Table 8)")
    )
    return fig


def _comparison(names: list[str], results: list[MethodologyResult | None],
                why_not: list[str | None]) -> Table:
    rows = []
    for name, r, why in zip(names, results, why_not, strict=True):
        if r is None:
            rows.append([name, "–", "–", "–", "–", "–", "–", "–",
                         "not analysed, see its section" if why else ""])
            continue
        rows.append([
            name,
            fmt(r.case.particles.diameter * 1e3),
            fmt(r.case.drum.rpm),
            fmt(r.case.air.mass_flow),
            fmt(r.h_mean_w_m2k),
            fmt(float(np.nanmean(r.reynolds))),
            fmt(float(np.nanmean(r.nusselt))),
            fmt(r.exchanger.material_outlet_temperature_c),
            "; ".join(r.warnings),
        ])
    return Table(
        "Runs",
        ["run", "Dp (mm)", "rpm", "air (kg/s)", "h (W/(m² K))", "mean Re", "mean Nu",
         "T_mo (°C)", "note"],
        rows,
    )


# ------------------------------------------------------------------------------ template

#: The page template, shipped as package data (``drumflow/report/templates/``).
TEMPLATE = "report.html.j2"



def write_report(
    run_dirs: Sequence[Path | str],
    out: Path | str,
    *,
    nusselt_conductivity: NusseltConductivity = "air",
    falling_mass: FallingMassMode = "mean",
    render_3d: bool = True,
    render_timeout_s: float = 180.0,
    on_note: Callable[[str], None] | None = None,
) -> Path:
    """Write one self-contained HTML page for one run or a sweep of runs.

    Parameters
    ----------
    run_dirs
        Run directories written by ``drumflow run`` (at least one).
    out
        HTML file to write (its folder is created if needed).
    nusselt_conductivity, falling_mass
        Passed to :func:`~drumflow.analysis.methodology.analyse_run`.
    render_3d
        Render the last snapshot with PyVista (Figure 6). Off makes the page faster.
    render_timeout_s
        Time limit of each PyVista render (it runs in a child process).
    on_note
        Called with every note the page carries (what was not applied or not drawn, and why),
        each prefixed with its run's name: a caller that prints them keeps them from being
        seen only by whoever opens the page.

    Returns
    -------
    pathlib.Path
        The HTML file (absolute).

    Raises
    ------
    RunDirectoryError
        If no run directory is given or one of them is not a directory.
    BadFileError
        If a file of a run is damaged (cut short, not UTF-8, a series that ends before the
        run): refused, not turned into a note.
    """
    import drumflow

    if not run_dirs:
        raise RunDirectoryError("no run directory given for the report")
    runs = [RunDir.existing(p) for p in run_dirs]
    roots = [run.root for run in runs]

    results: list[MethodologyResult | None] = []
    why_not: list[str | None] = []
    for root in roots:
        try:
            results.append(analyse_run(root, nusselt_conductivity=nusselt_conductivity,
                                       falling_mass=falling_mass))
            why_not.append(None)
        except BadFileError:
            # A damaged file is refused: a note would let a cut-short series pass as a run.
            raise
        except DrumflowError as exc:
            # A run without air or without its CSV still gets its page, with the reason.
            results.append(None)
            why_not.append(str(exc))

    views = [
        _run_view(i, run, res, why, render_3d, render_timeout_s)
        for i, (run, res, why) in enumerate(zip(runs, results, why_not, strict=True))
    ]
    names = [v.name for v in views]
    ok = [r for r in results if r is not None]
    corr: NusseltCorrelation | None = None
    no_fit = ""
    if not ok:
        no_fit = "no run could be analysed (see the notes of each run)."
    else:
        try:
            corr = fit_runs(ok)
        except AnalysisInputError as exc:
            hint = (
                " A single run cannot identify the exponent b, because Re then changes only "
                "through the air viscosity. Combine runs with different particle diameters or "
                "air flows."
                if len(ok) == 1
                else ""
            )
            no_fit = f"the correlation could not be fitted: {exc}.{hint}"

    page_notes: list[str] = []
    if len(ok) < len(results):
        page_notes.append(
            f"{len(results) - len(ok)} of {len(results)} run(s) could not be analysed for heat "
            "transfer; their observables are shown below with the reason."
        )
    if on_note is not None:
        for note in page_notes:
            on_note(note)
        for view in views:
            for note in view.notes:
                on_note(f"{view.name}: {note}")
            for fig in view.figures:
                if fig.note:
                    on_note(f"{view.name}: {fig.title}: {fig.note}")
        if no_fit:
            on_note(f"Table 8 (correlation): {no_fit}")
    title = (
        f"drumflow report: {names[0]}" if len(names) == 1
        else f"drumflow report: sweep of {len(names)} runs"
    )
    html = render_page(
        TEMPLATE,
        title=title,
        version=drumflow.__version__,
        generated=time.strftime("%Y-%m-%d %H:%M:%S %z"),
        conductivity=nusselt_conductivity,
        falling_mass=falling_mass,
        notes=page_notes,
        runs=views,
        comparison=_comparison(names, results, why_not) if len(roots) > 1 else None,
        table6=_table6(names, results),
        table7=_table7(names, results),
        table8=table8(corr) if corr is not None else None,
        equation=(
            f"Nu = {corr.a:.6g} Re^{corr.b:.6g} Pr^{corr.c:.6g}, "
            f"{corr.reynolds_range[0]:.5g} < Re < {corr.reynolds_range[1]:.5g}"
            if corr is not None else ""
        ),
        no_fit=no_fit,
        figure9=_figure9(names, results, corr),
    )
    target = Path(out).resolve()
    target.parent.mkdir(parents=True, exist_ok=True)
    target.write_text(html, encoding="utf-8")
    return target
