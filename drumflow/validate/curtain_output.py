"""What ``drumflow validate particle_curtain`` writes: a CSV of the experiments (the DEM's answer
beside the reduced-order model's) and a plot of the solids' temperature over the fall height."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

from drumflow._mpl import pyplot

__all__ = ["ENERGY_TOLERANCE", "bookkeeping_closes", "plot_curtain", "write_curtain_csv"]

#: The grains' enthalpy gain against the heat the loop gave them, relative: the logs carry 12
#: significant digits over a few thousand updates, so round-off stays far below it.
ENERGY_TOLERANCE = 1e-8
#: The air's enthalpy gain against the heat it received, relative (the transport's projection
#: conserves to the linear solver's tolerance).
AIR_TOLERANCE = 1e-6

#: The CSV's columns: per experiment, each quantity from the DEM and the reduced-order model.
QUANTITIES = ("heat_duty_W", "solids_outlet_C", "gas_outlet_C", "outlet_speed_m_s", "outlet_drift_m")


def bookkeeping_closes(book: dict[str, float]) -> bool:
    """Fed = out + in flight exactly, the grains' enthalpy gain = the heat given (within
    :data:`ENERGY_TOLERANCE`), the air's gain = the heat it received (:data:`AIR_TOLERANCE`)."""
    return (book["count_residual"] == 0 and book["fed"] > 0
            and abs(book["energy_residual"]) <= ENERGY_TOLERANCE
            and book["air_heat_balance"] <= AIR_TOLERANCE)


def _text(value: Any) -> str:
    return "" if value is None or (isinstance(value, float) and not math.isfinite(value)) else f"{value:.6g}"


def write_curtain_csv(path: Path, records: list[dict[str, Any]]) -> None:
    """One row per experiment: each quantity by the DEM and by the reduced-order model, the
    gas-side duty, the parcels in flight and the run's wall time."""
    header = ["experiment", "coarse_grain"]
    for q in QUANTITIES:
        header += [f"dem_{q}", f"reduced_order_{q}"]
    header += ["dem_gas_side_duty_W", "dem_parcels_in_flight", "energy_residual", "wall_time_s"]
    rows = [",".join(header)]
    for r in records:
        cells = [r["experiment"], _text(r["coarse_grain"])]
        for q in QUANTITIES:
            cells += [_text(r["dem"][q]), _text(r["reduced_order"][q])]
        cells += [_text(r["dem"]["gas_side_duty_W"]), _text(r["dem"]["parcels_in_flight"]),
                  _text(r["dem"]["bookkeeping"]["energy_residual"]), _text(r["wall_time_s"])]
        rows.append(",".join(cells))
    path.write_text("\n".join(rows) + "\n")


def plot_curtain(path: Path, records: list[dict[str, Any]], scale: str) -> None:
    """The solids' mean temperature against the depth below the slit, the DEM's (points, from
    the snapshots of the averaging window) over the reduced-order model's (line), one panel per
    experiment."""
    plt = pyplot()
    n = len(records)
    cols = min(3, n)
    rows = math.ceil(n / cols)
    fig, axes = plt.subplots(rows, cols, figsize=(4.0 * cols, 3.4 * rows), dpi=110, squeeze=False)
    for ax, r in zip(axes.ravel(), records, strict=False):
        rom = r["reduced_order"]["profile"]
        ax.plot(rom["solids_C"], rom["depth_m"], "-", color="0.4", label="reduced-order model")
        prof = [p for p in r["dem"]["profile"] if p["parcels"] > 0]
        ax.plot([p["solids_C"] for p in prof], [p["depth_m"] for p in prof], "o", color="tab:red",
                label=f"CFD-DEM (k = {r['coarse_grain']:g})")
        ax.invert_yaxis()
        ax.set_title(r["experiment"].replace("curtain_", "Figure ").replace("fig", ""), fontsize=9)
        ax.set_xlabel("solids temperature (°C)")
        ax.set_ylabel("depth below the slit (m)")
        ax.legend(fontsize=7)
    for ax in axes.ravel()[n:]:
        ax.set_visible(False)
    fig.suptitle(f"particle curtain ({scale}): Wardjiman and Rhodes 2009", fontsize=10)
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)
