"""The methodology over every member of a sweep: the Nu-Re-Pr fit and the plant predictions.

For each done member, :func:`drumflow.analysis.methodology.analyse_run` gives its mean ``h``,
its per-step Nu, Re and Pr, its falling mass flow and the plant's outlet temperatures at its
operating point (the exchanger model with the member's ``h``). Over all members two fits of
``Nu = a Re^b Pr^c`` are made:

* the **step fit** (:func:`~drumflow.analysis.methodology.fit_runs`, the paper's method, Eq. 56
  and Table 8): every valid output step is a point. Its standard errors treat thousands of
  steps as independent observations, which they are not: the steps of one member share its
  operating point and follow each other in time, so the scatter within a member is
  measurement noise of that member, not new information about the exponent. Its confidence
  intervals are therefore far too narrow and are shown only for comparison with the paper.
* the **member fit**: one point per member (its mean Re, Nu and Pr), fitted by the same
  Levenberg-Marquardt routine. Its degrees of freedom are members minus parameters, so its
  confidence intervals (Student t) are the honest uncertainty of the correlation from this
  sweep. With 4 members and 2 parameters that is 2 degrees of freedom, t = 4.30: wide, and
  rightly so.

``DIR/analysis/`` receives ``report.html`` (self-contained, PNGs embedded), ``members.csv``
(one row per member) and ``fit.json`` (both fits).
"""

from __future__ import annotations

import json
import math
import time
import warnings
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from drumflow.analysis.correlation import NusseltCorrelation, fit_nusselt_correlation
from drumflow.analysis.methodology import analyse_run, fit_runs
from drumflow.analysis.methodology_result import MethodologyResult
from drumflow.errors import DrumflowError
from drumflow.physics.validation import AnalysisInputError
from drumflow.sweep.driver import SweepDir, statuses
from drumflow.sweep.spec import Member, format_value, short_axis

__all__ = ["MemberAnalysis", "SweepAnalysis", "analyse_sweep", "correlation_to_dict",
           "write_sweep_report"]


@dataclass
class MemberAnalysis:
    """One member's methodology result (None with the reason when it has none)."""

    member: Member
    state: str
    result: MethodologyResult | None
    why_not: str | None


@dataclass
class SweepAnalysis:
    """The methodology over a sweep.

    Attributes
    ----------
    members
        Every member, analysed or with the reason it was not.
    step_fit, member_fit
        The two fits (see the module notes); None with the reason in ``*_error``.
    table
        One row per analysed member: axis values, h, Re, Pr, Nu, falling mass flow, plant
        outlets from the member's own h and from the member fit.
    """

    sd: SweepDir
    members: list[MemberAnalysis]
    step_fit: NusseltCorrelation | None
    step_fit_error: str
    member_fit: NusseltCorrelation | None
    member_fit_error: str
    table: pd.DataFrame

    @property
    def analysed(self) -> list[MemberAnalysis]:
        return [m for m in self.members if m.result is not None]


def correlation_to_dict(corr: NusseltCorrelation | None) -> dict[str, Any] | None:
    """A fit as JSON-ready numbers."""
    if corr is None:
        return None
    return {
        "a": corr.a, "b": corr.b, "c": corr.c, "se_a": corr.se_a, "se_b": corr.se_b,
        "se_c": corr.se_c, "ci95_a": list(corr.ci_a), "ci95_b": list(corr.ci_b),
        "ci95_c": list(corr.ci_c), "prandtl_exponent_fitted": corr.prandtl_exponent_fitted,
        "note": corr.note, "n": corr.n, "n_params": corr.n_params, "n_dropped": corr.n_dropped,
        "r_squared": corr.r_squared, "adjusted_r_squared": corr.adjusted_r_squared,
        "residual_std": corr.residual_std, "reynolds_range": list(corr.reynolds_range),
        "prandtl_range": list(corr.prandtl_range),
    }


def _valid_mean(result: MethodologyResult, column: str) -> float:
    steps = result.steps
    values = steps.loc[steps["valid"], column].to_numpy(dtype=np.float64)
    values = values[np.isfinite(values)]
    return float(values.mean()) if values.size else math.nan


def analyse_sweep(sd: SweepDir) -> SweepAnalysis:
    """Analyse every done member and fit the correlation over them.

    Members that are not done, or whose run cannot give ``h`` (no air), are listed with the
    reason; a fit that the data cannot support (e.g. Re does not vary) gives its reason
    instead of a result. Nothing here runs a solver.
    """
    settings = sd.sweep.analysis
    members: list[MemberAnalysis] = []
    for status in statuses(sd):
        m = status.member
        if status.state != "done":
            members.append(MemberAnalysis(m, status.state, None, f"member is {status.state}"))
            continue
        try:
            result = analyse_run(sd.member_dir(m), nusselt_conductivity=settings.conductivity,
                                 falling_mass=settings.falling_mass)
            members.append(MemberAnalysis(m, status.state, result, None))
        except DrumflowError as exc:
            members.append(MemberAnalysis(m, status.state, None, str(exc)))
    ok = [m for m in members if m.result is not None]

    step_fit, step_error = None, ""
    member_fit, member_error = None, ""
    if not ok:
        step_error = member_error = "no member could be analysed"
    else:
        try:
            step_fit = fit_runs([m.result for m in ok if m.result is not None])
        except AnalysisInputError as exc:
            step_error = str(exc)
        nu = np.array([_valid_mean(m.result, "nusselt") for m in ok if m.result is not None])
        re = np.array([_valid_mean(m.result, "reynolds") for m in ok if m.result is not None])
        pr = np.array([_valid_mean(m.result, "prandtl") for m in ok if m.result is not None])
        try:
            member_fit = fit_nusselt_correlation(nu, re, pr, drop_nonpositive=True)
        except AnalysisInputError as exc:
            member_error = str(exc)
    table = _member_table(sd, ok, member_fit)
    return SweepAnalysis(sd, members, step_fit, step_error, member_fit, member_error, table)


def _member_table(sd: SweepDir, ok: list[MemberAnalysis],
                  fit: NusseltCorrelation | None) -> pd.DataFrame:
    from drumflow.coolers.prediction import predict_plant

    rows = []
    for m in ok:
        r = m.result
        assert r is not None
        nu, re, pr = (_valid_mean(r, c) for c in ("nusselt", "reynolds", "prandtl"))
        row: dict[str, Any] = {"member": m.member.id}
        row.update({axis: format_value(v) if isinstance(v, dict) else v
                    for axis, v in m.member.values.items()})
        row.update({
            "h_mean_W_m2K": r.h_mean_w_m2k,
            "h_std_W_m2K": float(r.steps.loc[r.steps["valid"], "h_W_m2K"].std()),
            "reynolds_mean": re, "prandtl_mean": pr, "nusselt_mean": nu,
            "valid_steps": r.n_valid,
            "falling_mass_flow_kg_s": r.falling_mass_flow_kg_s,
            "plant_area_m2": r.exchanger_area_m2,
            "plant_material_outlet_C": r.exchanger.material_outlet_temperature_c,
            "plant_air_outlet_C": r.exchanger.air_outlet_temperature_c,
            "plant_heat_removed_kW": r.exchanger.heat_removed_w / 1e3,
        })
        if fit is not None and math.isfinite(re) and re > 0 and pr > 0:
            nu_fit = float(fit.predict(re, pr, warn=False))
            row["nusselt_fit"] = nu_fit
            row["h_fit_W_m2K"] = r.h_mean_w_m2k * nu_fit / nu if nu > 0 else math.nan
            row["residual_percent"] = 100.0 * (nu - nu_fit) / nu_fit
            try:
                with warnings.catch_warnings():
                    warnings.simplefilter("ignore")
                    pred = predict_plant(fit, r.case, reference=r,
                                         nusselt_conductivity=sd.sweep.analysis.conductivity)
                row["fit_material_outlet_C"] = pred.exchanger.material_outlet_temperature_c
                row["fit_air_outlet_C"] = pred.exchanger.air_outlet_temperature_c
            except DrumflowError:
                row["fit_material_outlet_C"] = row["fit_air_outlet_C"] = math.nan
        rows.append(row)
    return pd.DataFrame(rows)


# ------------------------------------------------------------------------------- the page


def _numeric(values: list[Any]) -> bool:
    return all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in values)


def _effect_figure(analysis: SweepAnalysis, axis: str) -> str:
    """h, falling mass flow and plant T_mo against one axis, a line per setting of the others."""
    from drumflow.report.page_parts import figure_uri

    table = analysis.table
    others = [a for a in analysis.sd.sweep.axes if a != axis and a in table.columns]
    quantities = [("h_mean_W_m2K", "h (W/(m² K))"),
                  ("falling_mass_flow_kg_s", "falling mass flow (kg/s)"),
                  ("plant_material_outlet_C", "plant T_mo (°C)")]
    xs = list(table[axis])
    numeric = _numeric(xs)
    cats = sorted({str(x) for x in xs})

    def xpos(v: Any) -> float:
        return float(v) if numeric else float(cats.index(str(v)))

    groups = table.groupby(others, sort=True) if others else [((), table)]

    def draw(ax_unused: Any) -> None:
        fig = ax_unused.figure
        ax_unused.remove()
        axes = fig.subplots(1, 3)
        for ax, (col, label) in zip(axes, quantities, strict=True):
            for key, group in groups:
                key = key if isinstance(key, tuple) else (key,)
                g = group.assign(_x=[xpos(v) for v in group[axis]]).sort_values("_x")
                name = ", ".join(f"{short_axis(o)}={format_value(k)}"
                                 for o, k in zip(others, key, strict=True)) or "members"
                ax.plot(g["_x"], g[col], "o-", ms=5, label=name)
            ax.set_xlabel(axis)
            ax.set_ylabel(label)
            ax.grid(alpha=0.3)
            if not numeric:
                ax.set_xticks(range(len(cats)), cats, rotation=20, fontsize=7)
        axes[0].legend(fontsize=7)

    return figure_uri(draw, size=(11.0, 3.4))


def _fit_figure(analysis: SweepAnalysis) -> str:
    from drumflow.report.page_parts import figure_uri

    ok = [m for m in analysis.analysed if m.result is not None]
    pr_mean = float(np.nanmean(analysis.table["prandtl_mean"])) if len(analysis.table) else math.nan

    def draw(ax: Any) -> None:
        res_all = []
        for m in ok:
            r = m.result
            assert r is not None
            good = np.isfinite(r.nusselt) & (r.nusselt > 0)
            ax.plot(r.reynolds[good], r.nusselt[good], ".", ms=2, alpha=0.25)
            res_all.append(r.reynolds[good])
        t = analysis.table
        ax.plot(t["reynolds_mean"], t["nusselt_mean"], "ks", ms=7, label="member means")
        for _, row in t.iterrows():
            ax.annotate(row["member"], (row["reynolds_mean"], row["nusselt_mean"]),
                        textcoords="offset points", xytext=(4, 4), fontsize=7)
        re_cat = np.concatenate(res_all) if res_all else np.array([])
        if re_cat.size:
            grid = np.linspace(re_cat.min(), re_cat.max(), 200)
            for fit, style, what in ((analysis.member_fit, "-", "member fit"),
                                     (analysis.step_fit, "--", "step fit")):
                if fit is not None:
                    ax.plot(grid, fit.a * grid**fit.b * pr_mean**fit.c, style, color="black",
                            lw=1.3, label=f"{what}: Nu = {fit.a:.3g} Re^{fit.b:.3g} Pr^{fit.c:.3g}")
        ax.set_xlabel("Re (Eq. 51)")
        ax.set_ylabel("Nu (Eq. 49)")
        ax.set_title("dots: valid output steps of each member", fontsize=9)
        ax.legend(fontsize=7)
        ax.grid(alpha=0.3)

    return figure_uri(draw, size=(7.0, 4.2))


def _residual_figure(analysis: SweepAnalysis) -> str:
    from drumflow.report.page_parts import figure_uri

    t = analysis.table

    def draw(ax: Any) -> None:
        ax.bar(t["member"], t["residual_percent"], color="tab:blue")
        ax.axhline(0, color="black", lw=0.8)
        ax.set_ylabel("(Nu − Nu_fit) / Nu_fit (%)")
        ax.set_title("member fit: residual of each member's mean Nu", fontsize=9)
        ax.grid(alpha=0.3, axis="y")

    return figure_uri(draw, size=(6.0, 3.2))


def _fit_rows(fit: NusseltCorrelation) -> list[list[str]]:
    from drumflow.report.page_parts import fmt

    rows = [["a", fmt(fit.a, 5), fmt(fit.se_a, 3), fmt(fit.ci_a, 4)],
            ["b", fmt(fit.b, 5), fmt(fit.se_b, 3), fmt(fit.ci_b, 4)]]
    rows.append(["c" + ("" if fit.prandtl_exponent_fitted else " (held)"), fmt(fit.c, 5),
                 fmt(fit.se_c, 3), fmt(fit.ci_c, 4)])
    return rows


_PAGE = """<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8"><title>{{ title }}</title>
<style>
body { font-family: sans-serif; max-width: 1150px; margin: 2em auto; color: #222; }
table { border-collapse: collapse; margin: 0.6em 0 1.2em; font-size: 0.88em; }
th, td { border: 1px solid #bbb; padding: 3px 8px; text-align: right; }
th { background: #eee; } td:first-child, th:first-child { text-align: left; }
.note { color: #555; font-size: 0.9em; max-width: 60em; } img { max-width: 100%; }
.bad { color: #a00; } pre { background: #f6f6f6; padding: 0.6em; font-size: 0.8em; overflow-x: auto; }
</style></head><body>
<h1>{{ title }}</h1>
<p class="note">{{ description }} Generated {{ generated }} by drumflow {{ version }}; sweep
directory {{ root }}; Nu with the {{ conductivity }} conductivity.</p>
<h2>Members</h2>
<p>{{ n_done }} of {{ n_members }} members done, {{ n_analysed }} analysed.</p>
{% if not_analysed %}<ul class="bad">{% for m in not_analysed %}<li>{{ m }}</li>{% endfor %}</ul>{% endif %}
<h2>Correlation Nu = a Re<sup>b</sup> Pr<sup>c</sup></h2>
{% if member_fit %}
<p><b>Member fit</b> (one point per member, {{ member_fit.n }} points, {{ member_fit.n_params }}
parameters, {{ member_fit.n - member_fit.n_params }} degrees of freedom): <b>{{ member_eq }}</b>.
These confidence intervals are the honest uncertainty of the fit from this sweep.</p>
<table><tr><th>parameter</th><th>estimate</th><th>std. error</th><th>95 % interval (t)</th></tr>
{% for r in member_rows %}<tr>{% for c in r %}<td>{{ c }}</td>{% endfor %}</tr>{% endfor %}</table>
<p class="note">Adjusted R² {{ member_r2 }}; residual standard deviation of Nu {{ member_sd }};
valid for {{ member_range }}. {{ member_fit.note }}</p>
{% else %}<p class="bad">member fit not possible: {{ member_error }}</p>{% endif %}
{% if step_fit %}
<p><b>Step fit</b> (the paper's method: every valid output step a point, {{ step_fit.n }}
points): {{ step_eq }}. Its intervals treat autocorrelated steps of the same member as
independent observations and are far too narrow; for comparison with the paper's Table 8 only.</p>
<table><tr><th>parameter</th><th>estimate</th><th>std. error</th><th>95 % interval (nominal)</th></tr>
{% for r in step_rows %}<tr>{% for c in r %}<td>{{ c }}</td>{% endfor %}</tr>{% endfor %}</table>
{% else %}<p class="bad">step fit not possible: {{ step_error }}</p>{% endif %}
<img src="{{ fit_png }}" alt="Nu against Re">
{% if residual_png %}<h3>Residuals</h3><img src="{{ residual_png }}" alt="residuals">{% endif %}
<h2>Each axis's effect</h2>
<p class="note">h (the member's time-averaged heat-transfer coefficient, Eq. 39), the falling
mass flow of the simulated section, and the plant's material outlet temperature predicted by the
exchanger model with the member's h (Eqs. 42-48); one line per setting of the other axes.</p>
{% for name, png in effects %}<h3>{{ name }}</h3><img src="{{ png }}" alt="effect of {{ name }}">{% endfor %}
<h2>Member table and plant predictions</h2>
<table><tr>{% for h in table_header %}<th>{{ h }}</th>{% endfor %}</tr>
{% for r in table_rows %}<tr>{% for c in r %}<td>{{ c }}</td>{% endfor %}</tr>{% endfor %}</table>
<p class="note">T_mo, T_ao: plant outlets from the member's own h; "fit" columns: the same with
h from the member fit at the member's Re. Full per-member pages: drumflow report
{{ root }}/members/*.</p>
<details><summary>sweep file</summary><pre>{{ sweep_text }}</pre></details>
<details><summary>attempts (executor records)</summary><pre>{{ attempts }}</pre></details>
</body></html>
"""


def write_sweep_report(analysis: SweepAnalysis, out_dir: Path | None = None) -> Path:
    """Write ``report.html``, ``members.csv`` and ``fit.json`` into ``DIR/analysis``.

    Returns
    -------
    pathlib.Path
        The HTML page.
    """
    from jinja2 import Environment, StrictUndefined

    import drumflow
    from drumflow.report.page_parts import fmt

    sd = analysis.sd
    out = (out_dir or sd.root / "analysis").resolve()
    out.mkdir(parents=True, exist_ok=True)
    analysis.table.to_csv(out / "members.csv", index=False, float_format="%.6g")
    fit = {
        "member_fit": correlation_to_dict(analysis.member_fit),
        "member_fit_error": analysis.member_fit_error or None,
        "step_fit": correlation_to_dict(analysis.step_fit),
        "step_fit_error": analysis.step_fit_error or None,
        "members": [{"id": m.member.id, "state": m.state, "analysed": m.result is not None,
                     "why_not": m.why_not} for m in analysis.members],
        "conductivity": sd.sweep.analysis.conductivity,
    }
    (out / "fit.json").write_text(json.dumps(fit, indent=2, default=float))

    t = analysis.table
    header = list(t.columns)
    rows = [[fmt(v, 5) for v in row] for row in t.itertuples(index=False)]

    def eq(f: NusseltCorrelation) -> str:
        return f"Nu = {f.a:.4g} Re^{f.b:.4g} Pr^{f.c:.4g}"

    mf, sf = analysis.member_fit, analysis.step_fit
    effects = []
    if len(t) > 1:
        for axis in sd.sweep.axes:
            if axis in t.columns and t[axis].nunique() > 1:
                effects.append((axis, _effect_figure(analysis, axis)))
    env = Environment(autoescape=True, undefined=StrictUndefined, trim_blocks=True,
                      lstrip_blocks=True)
    html = env.from_string(_PAGE).render(
        title=f"drumflow sweep {sd.sweep.name}",
        description=sd.sweep.description,
        generated=time.strftime("%Y-%m-%d %H:%M:%S %z"),
        version=drumflow.__version__,
        root=str(sd.root),
        conductivity=sd.sweep.analysis.conductivity,
        n_members=len(analysis.members),
        n_done=sum(1 for m in analysis.members if m.state == "done"),
        n_analysed=len(analysis.analysed),
        not_analysed=[f"{m.member.id} ({m.member.label()}): {m.why_not}"
                      for m in analysis.members if m.result is None],
        member_fit=mf, member_error=analysis.member_fit_error,
        member_eq=eq(mf) if mf else "", member_rows=_fit_rows(mf) if mf else [],
        member_r2=fmt(mf.adjusted_r_squared, 4) if mf else "",
        member_sd=fmt(mf.residual_std, 3) if mf else "",
        member_range=(f"{mf.reynolds_range[0]:.5g} < Re < {mf.reynolds_range[1]:.5g}" if mf else ""),
        step_fit=sf, step_error=analysis.step_fit_error,
        step_eq=eq(sf) if sf else "", step_rows=_fit_rows(sf) if sf else [],
        fit_png=_fit_figure(analysis) if len(t) else "",
        residual_png=_residual_figure(analysis) if mf is not None and "residual_percent" in t else "",
        effects=effects,
        table_header=header, table_rows=rows,
        sweep_text=(sd.root / "sweep.toml").read_text() if (sd.root / "sweep.toml").exists() else "",
        attempts=json.dumps([a.__dict__ for a in sd.ledger.attempts], indent=1, default=str),
    )
    page = out / "report.html"
    page.write_text(html, encoding="utf-8")
    return page
