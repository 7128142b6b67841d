"""The Pareto front of run time against error, and its picture."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd
from numpy.typing import NDArray

from drumflow._mpl import pyplot


def pareto_front(cost: NDArray[np.float64], error: NDArray[np.float64]) -> NDArray[np.bool_]:
    """Which points no other point beats on both cost and error (ties kept).

    A point is dominated when another is at most as costly and at most as wrong, and strictly
    better in one of the two.
    """
    cost = np.asarray(cost, dtype=float)
    error = np.asarray(error, dtype=float)
    front = np.ones(len(cost), dtype=bool)
    for i in range(len(cost)):
        better_or_equal = (cost <= cost[i]) & (error <= error[i])
        strictly = (cost < cost[i]) | (error < error[i])
        if np.any(better_or_equal & strictly):
            front[i] = False
    return front


def plot_pareto(table: pd.DataFrame, path: Path, tolerances: dict[str, float], title: str) -> None:
    """Wall time of the DEM stage against the worst error over its tolerance, one point per rung."""
    plt = pyplot()

    ok = table[(table["status"] == "ok") & table["dem_wall_time_s"].notna()].copy()
    fig, ax = plt.subplots(figsize=(8.0, 5.5), dpi=120)
    has_errors = "error_over_tolerance" in ok and ok["error_over_tolerance"].notna().any()
    if not has_errors:
        # A speed-only bench (no reference): run times alone, as bars.
        ax.barh(ok["rung"], ok["dem_wall_time_s"].astype(float), color="tab:blue")
        ax.invert_yaxis()
        ax.set_xlabel("DEM wall time (s)")
        ax.set_title(title + " (run time only: no reference rung)", fontsize=10)
        fig.tight_layout()
        path.parent.mkdir(parents=True, exist_ok=True)
        fig.savefig(path)
        plt.close(fig)
        return
    floor = 1e-3  # the reference itself has zero error: draw it on the floor of the log axis
    ok["y"] = ok["error_over_tolerance"].fillna(np.nan).clip(lower=floor)
    groups = list(dict.fromkeys(ok["group"]))
    cmap = plt.get_cmap("tab20")
    for k, group in enumerate(groups):
        g = ok[(ok["group"] == group) & ok["y"].notna()]
        ax.scatter(g["dem_wall_time_s"], g["y"], s=36, color=cmap(k % 20), label=group, zorder=3)
        for _, r in g.iterrows():
            ax.annotate(r["rung"], (r["dem_wall_time_s"], r["y"]), fontsize=7, xytext=(4, 3),
                        textcoords="offset points")
    front = ok[ok["pareto"].astype(bool)].sort_values("dem_wall_time_s")
    if len(front):
        ax.step(front["dem_wall_time_s"], front["y"], where="post", color="0.3", lw=1.2,
                label="Pareto front", zorder=2)
    noise = ok[ok["rung"] == "mpi_2"]["error_over_tolerance"]
    if len(noise) and pd.notna(noise.iloc[0]) and noise.iloc[0] > 0:
        # Same physics, different round-off: below this line differences are chaos, not error.
        ax.axhline(float(noise.iloc[0]), color="0.5", lw=1, ls=":",
                   label="noise floor (mpi_2: round-off only)")
    ax.axhline(1.0, color="tab:red", lw=1, ls="--",
               label=(f"tolerance (T, h {tolerances['temperature']:.0%}; "
                      f"mass flow {tolerances['mass_flow']:.0%})"))
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("DEM wall time (s)")
    ax.set_ylabel("worst error / its tolerance (against the reference)")
    ax.set_title(title, fontsize=10)
    ax.legend(fontsize=7, loc="best")
    ax.grid(True, which="both", alpha=0.3)
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path)
    plt.close(fig)
