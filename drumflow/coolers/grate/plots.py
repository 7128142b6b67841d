"""PNG plots of the grate-cooler model in the style of the report's Figures 7-15
(matplotlib, Agg backend) and CSV tables beside them."""

from __future__ import annotations

import csv
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from drumflow._mpl import pyplot
from drumflow.coolers.grate.solution import GrateSolution
from drumflow.coolers.grate.studies import Sweep

__all__ = [
    "plot_air_height",
    "plot_fields",
    "plot_layers",
    "plot_sweep",
    "plot_sweep_outlets",
    "write_csv",
    "write_profiles",
]

_LAYER_FRACTIONS = (0.0, 0.25, 0.5, 0.75, 1.0)



def write_csv(rows: Sequence[Mapping[str, Any]], path: Path) -> Path:
    """Write dictionaries of one layout as a CSV table (floats with 6 significant digits)."""
    path.parent.mkdir(parents=True, exist_ok=True)
    with path.open("w", newline="") as fh:
        writer = csv.DictWriter(fh, fieldnames=list(rows[0]))
        writer.writeheader()
        for row in rows:
            writer.writerow({k: (f"{v:.6g}" if isinstance(v, float) else v) for k, v in row.items()})
    return path


def write_profiles(sol: GrateSolution, path: Path) -> Path:
    """Profiles along the grate: caloric clinker, bottom/top layer clinker, freeboard air."""
    rows = [{
        "x_m": float(sol.x[i]),
        "clinker_caloric_K": float(sol.caloric_temperature[i]),
        "clinker_bottom_K": float(sol.clinker_temperature[0, i]),
        "clinker_top_K": float(sol.clinker_temperature[-1, i]),
        "air_top_layer_K": float(sol.air_temperature[-1, i]),
        "freeboard_air_K": float(sol.freeboard_temperature[i]),
        "h_mean_W_m2K": float(sol.heat_transfer_coefficient[:, i].mean()),
    } for i in range(sol.x.size)]
    return write_csv(rows, path)


def _layers(m: int) -> list[int]:
    return sorted({min(m - 1, int(round(f * (m - 1)))) for f in _LAYER_FRACTIONS})


def plot_layers(sol: GrateSolution, path: Path, *, air: bool = False, title: str = "") -> Path:
    """Clinker (or air) temperature against length at several heights (Figures 7-9); the air
    plot adds the freeboard air."""
    plt = pyplot()
    field = sol.air_temperature if air else sol.clinker_temperature
    fig, ax = plt.subplots(figsize=(6.4, 4.0), dpi=120)
    cmap = plt.get_cmap("viridis")
    layers = _layers(sol.y.size)
    for k, j in enumerate(layers):
        ax.plot(sol.x, field[j], color=cmap(k / max(1, len(layers) - 1)), lw=1.5,
                label=f"y = {sol.y[j]:.3f} m")
    if air:
        ax.plot(sol.x, sol.freeboard_temperature, color="tab:red", lw=2.0, ls="--",
                label="freeboard (to kiln)")
    else:
        ax.plot(sol.x, sol.caloric_temperature, color="k", lw=2.0, ls="--", label="caloric mean")
    ax.set_xlabel("length along the grate x (m)")
    ax.set_ylabel(("air" if air else "clinker") + " temperature (K)")
    ax.set_title(title or ("air" if air else "clinker") + " temperature at several heights",
                 fontsize=9)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7, ncol=2)
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)
    return path


def plot_air_height(sol: GrateSolution, path: Path) -> Path:
    """Air temperature against height at several positions along the grate (Figure 10)."""
    plt = pyplot()
    fig, ax = plt.subplots(figsize=(6.4, 4.0), dpi=120)
    cmap = plt.get_cmap("plasma")
    n = sol.x.size
    columns = sorted({min(n - 1, int(round(f * (n - 1)))) for f in (0.0, 0.1, 0.25, 0.5, 0.75, 1.0)})
    top = sol.bed_height
    for k, i in enumerate(columns):
        color = cmap(0.85 * k / max(1, len(columns) - 1))
        ax.plot(np.append(sol.y, top * 1.08), np.append(sol.air_temperature[:, i],
                sol.freeboard_temperature[i]), color=color, lw=1.5, label=f"x = {sol.x[i]:.2f} m")
    ax.axvline(top, color="0.5", lw=0.8, ls=":")
    ax.text(top, ax.get_ylim()[0], " bed top", fontsize=7, color="0.4", va="bottom")
    ax.set_xlabel("height above the grate y (m); last point: freeboard")
    ax.set_ylabel("air temperature (K)")
    ax.set_title("air temperature over the bed height", fontsize=9)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7, ncol=2)
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)
    return path


def plot_fields(sol: GrateSolution, path: Path) -> Path:
    """Clinker and air temperature fields over the bed (x along the grate, y up)."""
    plt = pyplot()
    fig, axes = plt.subplots(2, 1, figsize=(7.0, 5.2), dpi=120, sharex=True)
    lo = sol.case.air.inlet_temperature
    hi = sol.case.clinker.inlet_temperature
    extent = (0.0, sol.case.cooler.length, 0.0, sol.bed_height)
    for ax, data, name in ((axes[0], sol.clinker_temperature, "clinker"),
                           (axes[1], sol.air_temperature, "air")):
        im = ax.imshow(data, origin="lower", aspect="auto", extent=extent, cmap="inferno",
                       vmin=lo, vmax=hi)
        ax.set_ylabel("height y (m)")
        ax.set_title(f"{name} temperature (K)", fontsize=9)
        fig.colorbar(im, ax=ax, pad=0.01)
    axes[1].set_xlabel("length along the grate x (m); clinker enters at x = 0")
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)
    return path


def _label(field: str) -> str:
    return {"cooler.grate_speed": "grate speed (m/s)", "clinker.mass_flow": "clinker flow (kg/s)",
            "air.mass_flow": "air flow (kg/s)"}.get(field, field)


def plot_sweep(sweep: Sweep, path: Path, title: str = "") -> Path:
    """Caloric clinker temperature and freeboard air along the grate for each value of the
    varied field (Figures 11-15)."""
    plt = pyplot()
    fig, axes = plt.subplots(1, 2, figsize=(10.0, 4.0), dpi=120)
    cmap = plt.get_cmap("viridis")
    k_max = max(1, len(sweep.values) - 1)
    for k, (value, sol) in enumerate(zip(sweep.values, sweep.solutions, strict=True)):
        color = cmap(k / k_max)
        axes[0].plot(sol.x, sol.caloric_temperature, color=color, lw=1.4, label=f"{value:g}")
        axes[1].plot(sol.x, sol.freeboard_temperature, color=color, lw=1.4, label=f"{value:g}")
    axes[0].set_ylabel("clinker caloric temperature (K)")
    axes[1].set_ylabel("freeboard air temperature (K)")
    for ax in axes:
        ax.set_xlabel("length along the grate x (m)")
        ax.grid(alpha=0.3)
    ncol = 2 if len(sweep.values) > 8 else 1
    axes[1].legend(title=_label(sweep.field), fontsize=6, title_fontsize=7, ncol=ncol)
    fig.suptitle(title or f"varying {_label(sweep.field)}", fontsize=10)
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)
    return path


def plot_sweep_outlets(sweep: Sweep, path: Path, title: str = "") -> Path:
    """Clinker outlet and secondary-air temperatures, and the cooler efficiency, against the
    varied field."""
    plt = pyplot()
    rows = sweep.rows()
    x = [r[sweep.field] for r in rows]
    fig, ax = plt.subplots(figsize=(6.4, 4.0), dpi=120)
    ax.plot(x, [r["secondary_air_K"] for r in rows], "o-", color="tab:red", ms=3,
            label="secondary air (freeboard, kiln end)")
    ax.plot(x, [r["clinker_outlet_K"] for r in rows], "s-", color="tab:blue", ms=3,
            label="clinker outlet (caloric)")
    ax.set_xlabel(_label(sweep.field))
    ax.set_ylabel("temperature (K)")
    ax.grid(alpha=0.3)
    ax2 = ax.twinx()
    ax2.plot(x, [100 * r["efficiency"] for r in rows], "^--", color="tab:green", ms=3,
             label="cooler efficiency")
    ax2.set_ylabel("cooler efficiency (%)", color="tab:green")
    lines = ax.get_legend_handles_labels()
    lines2 = ax2.get_legend_handles_labels()
    ax.legend(lines[0] + lines2[0], lines[1] + lines2[1], fontsize=7, loc="best")
    ax.set_title(title or f"outlets against {_label(sweep.field)}", fontsize=9)
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)
    return path


def plot_sweep_recovered(sweep: Sweep, path: Path, title: str = "") -> Path:
    """Heat recovered by the air (its largest value marked) and the air flow against the
    varied field: with fan-limited air (``air.supply = "fan"``) the flow varies too."""
    plt = pyplot()
    rows = sweep.rows()
    x = [r[sweep.field] for r in rows]
    fig, ax = plt.subplots(figsize=(6.4, 4.0), dpi=120)
    ax.plot(x, [r["heat_recovered_MW"] for r in rows], "o-", color="tab:red", ms=3,
            label="heat recovered by the air")
    at, value, interior = sweep.peak("heat_recovered_MW")
    ax.plot([at], [value], "*", color="black", ms=10,
            label=f"largest: {value:.2f} MW at {at:g}" + ("" if interior else " (range end)"))
    ax.set_xlabel(_label(sweep.field))
    ax.set_ylabel("heat recovered (MW)")
    ax.grid(alpha=0.3)
    ax2 = ax.twinx()
    ax2.plot(x, [r["air_flow_kg_s"] for r in rows], "s--", color="tab:blue", ms=3,
             label="air flow")
    ax2.set_ylabel("air flow (kg/s)", color="tab:blue")
    lines = ax.get_legend_handles_labels()
    lines2 = ax2.get_legend_handles_labels()
    ax.legend(lines[0] + lines2[0], lines[1] + lines2[1], fontsize=7, loc="best")
    supply = sweep.solutions[0].case.air.supply
    ax.set_title(title or f"recovered heat against {_label(sweep.field)} (air: {supply})",
                 fontsize=9)
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)
    return path
