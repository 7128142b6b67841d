"""The pieces both HTML pages are built from: the run and sweep report
(:mod:`drumflow.report.html`) and the paper comparison (:mod:`drumflow.report.paper_page`).

A page is a Jinja template filled with :class:`Table` and :class:`Figure` values; every picture is
a base64 PNG (or GIF) ``data:`` URI, so the page has no outside reference. The parts drawn on
both pages are here once: number formatting, Table 8 (the correlation and its analysis of
variance), the per-step h (Eqs. 34-41) and Figure 9 (Nu against Re with the fitted curve).
"""

from __future__ import annotations

import base64
import io
import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from drumflow._mpl import pyplot
from drumflow.analysis.correlation import NusseltCorrelation
from drumflow.analysis.methodology_result import MethodologyResult

__all__ = [
    "Figure",
    "Table",
    "figure_uri",
    "file_uri",
    "fmt",
    "h_figure",
    "nusselt_reynolds_figure",
    "render_page",
    "table8",
]


@dataclass
class Table:
    """A table of a page: caption, header, rows of formatted cells, and a note under it."""

    caption: str
    header: list[str]
    rows: list[list[str]]
    note: str = ""


@dataclass
class Figure:
    """A picture of a page (``uri``), or the ``note`` saying why it is missing."""

    title: str
    caption: str = ""
    uri: str | None = None
    note: str | None = None


def fmt(value: Any, digits: int = 5) -> str:
    """A value as a table cell: ``digits`` significant digits, thousands separated, "–" for none."""
    if value is None:
        return "–"
    if isinstance(value, (bool, np.bool_)):
        return "yes" if value else "no"
    if isinstance(value, (int, np.integer)):
        return f"{int(value):,}"
    if isinstance(value, (float, np.floating)):
        v = float(value)
        if not math.isfinite(v):
            return "–"
        return f"{v:.{digits}g}"
    if isinstance(value, (list, tuple)):
        return ", ".join(fmt(v, digits) for v in value)
    return str(value)


def _png_uri(data: bytes) -> str:
    return "data:image/png;base64," + base64.b64encode(data).decode("ascii")


def file_uri(path: Path) -> str | None:
    """A PNG picture or GIF animation on disk as a ``data:`` URI; None if missing or neither."""
    try:
        data = path.read_bytes()
    except OSError:
        return None
    # Only PNG pictures and GIF animations are embedded, each under its own type.
    if data.startswith(b"\x89PNG\r\n\x1a\n"):
        return _png_uri(data)
    if data.startswith((b"GIF87a", b"GIF89a")):
        return "data:image/gif;base64," + base64.b64encode(data).decode("ascii")
    return None


def figure_uri(draw: Callable[[Any], None], size: tuple[float, float] = (6.4, 3.8)) -> str:
    """Call ``draw(ax)`` on a new figure of ``size`` inches and return the PNG as a URI."""
    plt = pyplot()
    fig, ax = plt.subplots(figsize=size, dpi=110)
    try:
        draw(ax)
        fig.tight_layout()
        buf = io.BytesIO()
        # No "Software" text chunk: the page should carry no outside references, even encoded.
        fig.savefig(buf, format="png", metadata={"Software": None})
    finally:
        plt.close(fig)
    return _png_uri(buf.getvalue())


def render_page(template: str, **values: Any) -> str:
    """Fill a template shipped in ``drumflow/report/templates/`` (undefined names are errors)."""
    from jinja2 import Environment, PackageLoader, StrictUndefined

    env = Environment(loader=PackageLoader("drumflow.report", "templates"), autoescape=True,
                      undefined=StrictUndefined, trim_blocks=True, lstrip_blocks=True)
    return env.get_template(template).render(**values)


# ------------------------------------------------------------------ drawn on both pages


def h_figure(result: MethodologyResult) -> Figure:
    """The heat-transfer coefficient of every step and its time average (Eqs. 34-41)."""
    s = result.steps

    def draw(ax: Any) -> None:
        ok = s["valid"].to_numpy(dtype=bool)
        ax.plot(s["time_s"][ok], s["h_W_m2K"][ok], ".", ms=3, color="tab:blue", label="per step")
        ax.axhline(result.h_mean_w_m2k, color="tab:red", lw=1.4,
                   label=f"time average {result.h_mean_w_m2k:.4g} W/(m² K)")
        ax.set_xlabel("time (s)")
        ax.set_ylabel("h (W/(m² K))")
        # Plain tick labels: an offset such as "1e-5+6e1" hides the value being read off.
        ax.ticklabel_format(axis="y", useOffset=False, style="plain")
        h_ok = s["h_W_m2K"].to_numpy(dtype=float)[ok]
        if h_ok.size and np.ptp(h_ok) < 0.01 * abs(result.h_mean_w_m2k):
            # A nearly constant h would be drawn as noise magnified to the full axis height.
            pad = 0.05 * abs(result.h_mean_w_m2k)
            ax.set_ylim(result.h_mean_w_m2k - pad, result.h_mean_w_m2k + pad)
        ax.legend(fontsize=8)
        ax.grid(alpha=0.3)

    masked = result.masked
    caption = f"{result.n_valid} valid of {result.n_steps} steps"
    if masked:
        caption += "; masked: " + ", ".join(f"{v} {k.replace('_', ' ')}" for k, v in masked.items())
    return Figure("Heat-transfer coefficient per step (Eqs. 34-41)", caption, figure_uri(draw))


def table8(corr: NusseltCorrelation) -> list[Table]:
    """Table 8: the fitted correlation, its analysis of variance, and (when the residuals are
    serially correlated) the same fit with the errors that correlation implies."""
    coef = Table(
        "Table 8a. Correlation Nu = a Re^b Pr^c (Eq. 56, Levenberg-Marquardt)",
        ["Parameter", "Estimate", "Std. error", "95 % confidence interval"],
        [
            ["a", fmt(corr.a, 6), fmt(corr.se_a, 3), fmt(corr.ci_a, 5)],
            ["b", fmt(corr.b, 6), fmt(corr.se_b, 3), fmt(corr.ci_b, 5)],
            ["c" + ("" if corr.prandtl_exponent_fitted else " (fixed)"), fmt(corr.c, 6),
             fmt(corr.se_c, 3), fmt(corr.ci_c, 5)],
        ],
        note=corr.note,
    )
    t = corr.anova
    anova = Table(
        "Table 8. Analysis of variance of the non-linear correlation",
        ["Source of variance", "Sum of squares", "Degrees of freedom", "Mean square",
         "F observed", "P-value"],
        [
            ["Model", fmt(t.ss_model, 6), fmt(t.df_model), fmt(t.ms_model, 6),
             fmt(t.f_value, 6), f"{t.p_value:.4f}"],
            ["Error", fmt(t.ss_error, 6), fmt(t.df_error), fmt(t.ms_error, 6), "", ""],
            ["Total", fmt(t.ss_total, 6), fmt(t.df_total), "", "", ""],
            ["Adjusted R-squared (%)", fmt(100 * corr.adjusted_r_squared, 6), "", "", "", ""],
        ],
        note=(
            f"{corr.n:,} steps used, {corr.n_dropped:,} dropped (masked or non-positive); valid "
            f"for {corr.reynolds_range[0]:.5g} < Re < {corr.reynolds_range[1]:.5g}. Uncorrected "
            "sums of squares as in Statgraphics; R-squared against the corrected total."
        ),
    )
    serial = corr.serial
    if serial is None:
        return [coef, anova]
    honest = Table(
        "Table 8b. The same fit with serially correlated time steps",
        ["Parameter", "Estimate", "Std. error (independent steps)",
         "Std. error (serial correlation)", "95 % confidence interval"],
        [
            [name, fmt(value, 6), fmt(naive, 3), fmt(wide, 3), fmt(ci, 5)]
            for name, value, naive, wide, ci in (
                ("a", corr.a, corr.se_a, serial.se_a, serial.ci_a),
                ("b", corr.b, corr.se_b, serial.se_b, serial.ci_b),
                ("c" + ("" if corr.prandtl_exponent_fitted else " (fixed)"), corr.c, corr.se_c,
                 serial.se_c, serial.ci_c),
            )
        ],
        note=(
            f"Consecutive steps are not independent: lag-1 autocorrelation of the residuals "
            f"{serial.lag1:.3f} (within each run), so the {corr.n:,} steps carry the information "
            f"of about {serial.n_effective:.4g} independent ones (n (1 - rho) / (1 + rho)); the "
            f"errors are {serial.inflation:.3g} times the table's, and the interval uses "
            f"{serial.df_effective:.4g} degrees of freedom."
        ),
    )
    return [coef, anova, honest]


def nusselt_reynolds_figure(
    title: str,
    runs: Sequence[tuple[str, MethodologyResult]],
    corr: NusseltCorrelation | None,
    prandtl: float,
    *,
    xlabel: str,
    ylabel: str,
    reference: Callable[[Any], None] | None = None,
    axes_title: str | None = None,
    size: tuple[float, float] = (6.4, 3.8),
) -> Figure:
    """Figure 9: the per-step Nu and Re of the valid steps of each run, and the fitted curve.

    Parameters
    ----------
    title
        The figure's title on the page.
    runs
        (legend label, methodology result) of each analysed run.
    corr
        The correlation fitted to the runs (drawn over their Re range at ``prandtl``), or None.
    prandtl
        The Prandtl number the fitted curve is drawn at.
    xlabel, ylabel
        The axis labels (the pages say which Re and which conductivity in Nu).
    reference
        Draws what the runs are compared with (the paper's Eq. 58 and points) before them; the
        fitted curve is then red, to stand apart from the reference's black.
    axes_title
        A line above the axes, or None.
    size
        Inches.
    """

    def draw(ax: Any) -> None:
        if reference is not None:
            reference(ax)
        re_points = []
        for label, r in runs:
            ok = np.isfinite(r.nusselt) & (r.nusselt > 0)
            ax.plot(r.reynolds[ok], r.nusselt[ok], ".", ms=3, alpha=0.6, label=label)
            re_points.append(r.reynolds[ok])
        re_cat = np.concatenate(re_points) if re_points else np.array([])
        re_cat = re_cat[np.isfinite(re_cat) & (re_cat > 0)]
        if corr is not None and re_cat.size:
            grid = np.geomspace(re_cat.min(), re_cat.max(), 200)
            ax.plot(grid, corr.a * grid**corr.b * prandtl**corr.c,
                    color="black" if reference is None else "tab:red",
                    lw=1.4 if reference is None else 1.2,
                    label=f"drumflow fit: Nu = {corr.a:.4g} Re^{corr.b:.4g} Pr^{corr.c:.4g}")
        lines = [np.asarray(ln.get_xdata(), float) for ln in ax.get_lines()]
        xs = np.concatenate(lines) if lines else np.array([])
        if xs.size and xs.max() > 10 * xs.min() > 0:
            from matplotlib.ticker import FuncFormatter

            ax.set_xscale("log")
            ax.set_yscale("log")
            # Nu spans less than a decade: plain labels on the minor ticks too, not "3 x 10^0".
            plain = FuncFormatter(lambda v, _: f"{v:g}")
            ax.yaxis.set_major_formatter(plain)
            ax.yaxis.set_minor_formatter(plain)
        else:
            # Plain tick labels: one run spans a tiny Re range, and an offset label such as
            # "+9.27e4" hides the values (a log axis would have no labelled tick).
            ax.ticklabel_format(useOffset=False, style="plain")
        ax.set_xlabel(xlabel)
        ax.set_ylabel(ylabel)
        if axes_title is not None:
            ax.set_title(axes_title, fontsize=9)
        ax.legend(fontsize=8 if reference is None else 7)
        ax.grid(alpha=0.3, which="both")

    return Figure(title, uri=figure_uri(draw, size=size))
