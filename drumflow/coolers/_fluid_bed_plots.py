"""Plots and CSV tables of the fluid-bed cooler (matplotlib, Agg backend)."""

from __future__ import annotations

import csv
from pathlib import Path
from typing import Any

import numpy as np

from drumflow._mpl import pyplot
from drumflow.coolers.fit import FitResult
from drumflow.coolers.fluid_bed import Operation, UnitResult
from drumflow.coolers.fluid_bed_case import KELVIN, MonthWeather

plt = pyplot()


def write_profile_csv(unit: UnitResult, path: Path) -> None:
    with path.open("w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(["position_m", "product_mean_K", "product_centre_K", "product_surface_K",
                    "air_leaving_slice_K"])
        for row in zip(unit.position, unit.product_mean, unit.product_centre, unit.product_surface,
                       unit.air_outlet_local):
            w.writerow([f"{v:.6g}" for v in row])


def write_radial_csv(unit: UnitResult, path: Path) -> None:
    with path.open("w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(["radius_m", "temperature_K"])
        for r, t in zip(unit.radius, unit.radial_temperature):
            w.writerow([f"{r:.6g}", f"{t:.6f}"])


def write_rows_csv(rows: list[dict[str, Any]], path: Path) -> None:
    if not rows:
        return
    with path.open("w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=list(rows[0]))
        w.writeheader()
        for r in rows:
            w.writerow({k: ("" if v is None else v) for k, v in r.items()})


def plot_profile(unit: UnitResult, path: Path, target_K: float, title: str) -> None:
    """Product (mean, centre, surface) and the air leaving each slice along the deck."""
    fig, ax = plt.subplots(figsize=(8, 4.8))
    x = unit.position
    c = lambda t: np.asarray(t) - KELVIN  # noqa: E731
    b_end = unit.sections[0].length
    ax.axvspan(0, b_end, color="tab:green", alpha=0.07)
    ax.axvspan(b_end, x[-1], color="tab:blue", alpha=0.10)
    ax.text(0.5 * b_end, 0.97, "B: ambient air", transform=ax.get_xaxis_transform(), ha="center", va="top")
    label_c = "C: chilled air" if unit.cooled_air_temperature is not None else "C: ambient air"
    ax.text(0.5 * (b_end + x[-1]), 0.97, label_c, transform=ax.get_xaxis_transform(), ha="center", va="top")
    ax.plot(x, c(unit.product_mean), color="tab:red", lw=2.2, label="product, caloric mean")
    ax.plot(x, c(unit.product_centre), color="tab:red", lw=1, ls="--", label="particle centre")
    ax.plot(x, c(unit.product_surface), color="tab:orange", lw=1, ls=":", label="particle surface")
    ax.plot(x[1:], c(unit.air_outlet_local[1:]), color="tab:blue", lw=1.5, label="air leaving the bed")
    for i, s in enumerate(unit.sections):
        x_lo, x_hi = (0.0, b_end) if i == 0 else (b_end, float(x[-1]))
        ax.hlines(s.air_inlet_temperature - KELVIN, x_lo, x_hi, colors="tab:blue",
                  linestyles="--", lw=1, label="air entering the bed" if i == 0 else "_nolegend_")
    ax.axhline(target_K - KELVIN, color="k", lw=0.8, ls="-.", label=f"target {target_K:.0f} K")
    ax.set_xlabel("position along the deck (m)")
    ax.set_ylabel("temperature (°C)")
    ax.set_title(title, fontsize=10)
    ax.legend(loc="upper right", bbox_to_anchor=(1.0, 0.9), fontsize=8)
    ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def plot_radial(unit: UnitResult, path: Path) -> None:
    """The particle's temperature across its radius at the outlet (the source's Fig. 9)."""
    fig, ax = plt.subplots(figsize=(6, 4.2))
    r_over_r = unit.radius / (unit.radius[-1] + 0.5 * (unit.radius[1] - unit.radius[0]))
    t = unit.radial_temperature - KELVIN
    ax.plot(r_over_r, t, "o-", color="tab:red")
    mean = unit.product_outlet_temperature - KELVIN
    ax.axhline(mean, color="k", lw=0.8, ls="--", label=f"caloric mean {mean:.2f} °C")
    span = max(float(t.max() - t.min()), 1e-3)
    mid = 0.5 * (t.max() + t.min())
    # A +-5 K window makes "nearly flat" visible at a glance, as in the source's figure.
    half = max(5.0, span)
    ax.set_ylim(mid - half, mid + half)
    ax.set_xlabel("r / R")
    ax.set_ylabel("temperature (°C)")
    ax.set_title(f"particle at the outlet: centre - surface shell = {t[0] - t[-1]:.2f} K", fontsize=10)
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def plot_year(months: list[tuple[MonthWeather, Operation]], path: Path, target_K: float) -> None:
    """Product outlet per month with and without chilled air, and the refrigeration energy
    per kg of product (the source's Fig. 10 and Table 1)."""
    labels = [m.name[:3] for m, _ in months]
    x = np.arange(len(months))
    amb = [op.unit.conditions.ambient_temperature - KELVIN for _, op in months]
    only = [op.ambient_only.product_outlet_temperature - KELVIN for _, op in months]
    run = [op.unit.product_outlet_temperature - KELVIN for _, op in months]
    duty = [op.summary()["air_cooler_duty_kJ_per_kg"] for _, op in months]
    power = [op.summary()["compressor_power_kJ_per_kg"] for _, op in months]
    fig, (ax1, ax2) = plt.subplots(2, 1, figsize=(8, 6.5), sharex=True,
                                   gridspec_kw={"height_ratios": [3, 2]})
    ax1.plot(x, amb, "s--", color="tab:blue", label="ambient air (mean of daily maxima)")
    ax1.plot(x, only, "o-", color="tab:red", label="product outlet, ambient air only")
    ax1.plot(x, run, "^-", color="tab:green", label="product outlet, as operated")
    ax1.axhline(target_K - KELVIN, color="k", lw=0.8, ls="-.", label=f"storage limit {target_K:.0f} K")
    for i, (_, op) in enumerate(months):
        if op.cooling_needed:
            ax1.axvspan(i - 0.4, i + 0.4, color="tab:cyan", alpha=0.15, lw=0)
    ax1.set_ylabel("temperature (°C)")
    ax1.legend(fontsize=8, loc="upper left")
    ax1.grid(alpha=0.3)
    # Say so when no month needs chilling (an empty shading legend would read as a bug).
    chilled = any(op.cooling_needed for _, op in months)
    ax1.set_title("shaded: months that need chilled air in section C" if chilled
                  else "no month needs chilled air in section C", fontsize=10)
    w = 0.38
    ax2.bar(x - w / 2, duty, w, color="tab:cyan", label="air-cooler duty")
    ax2.bar(x + w / 2, power, w, color="tab:purple", label="compressor power")
    ax2.set_ylabel("kJ per kg of product")
    ax2.set_ylim(bottom=0.0, top=max([*duty, *power, 1.0]) * 1.1)
    ax2.set_xticks(x, labels)
    ax2.legend(fontsize=8, loc="upper left")
    ax2.grid(alpha=0.3, axis="y")
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def plot_fit(fit: FitResult, path: Path) -> None:
    """Measured against fitted temperatures and relative residuals (the source's Fig. 8)."""
    fig, axes = plt.subplots(2, 2, figsize=(9, 7.5))
    pairs = (("product", fit.measured_product, fit.model_product, "tab:red"),
             ("air (mixed, after hood)", fit.measured_air, fit.model_air, "tab:blue"))
    for col, (name, meas, model, color) in enumerate(pairs):
        ax = axes[0, col]
        m, p = meas - KELVIN, model - KELVIN
        lo, hi = min(m.min(), p.min()) - 1, max(m.max(), p.max()) + 1
        ax.plot([lo, hi], [lo, hi], "k-", lw=0.8)
        ax.fill_between([lo, hi], [lo * 0.9, hi * 0.9], [lo * 1.1, hi * 1.1], color="0.9",
                        label="±10 % (source's error bars)")
        ax.plot(m, p, "o", color=color, ms=4)
        ax.set_xlabel(f"measured {name} (°C)")
        ax.set_ylabel(f"model {name} (°C)")
        ax.legend(fontsize=8)
        ax.grid(alpha=0.3)
        ax = axes[1, col]
        rel = 100.0 * (model - meas) / meas  # relative to the kelvin reading, as the source
        ax.plot(m, rel, "o", color=color, ms=4)
        ax.axhline(0, color="k", lw=0.8)
        ax.set_xlabel(f"measured {name} (°C)")
        ax.set_ylabel("relative residual (% of K)")
        ax.grid(alpha=0.3)
    fig.suptitle(f"fit: f_c = {fit.convective_efficiency:.3f}, hLosses A = "
                 f"{fit.losses_conductance / 1e3:.2f} kW/K, s = {fit.residual_std:.2f} K", fontsize=11)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
