"""PNG plots of a run's observables (matplotlib, no display needed)."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
import pandas as pd
from numpy.typing import NDArray

from drumflow._mpl import pyplot
from drumflow.physics.drum_frame import drum_angle

if TYPE_CHECKING:
    from drumflow.analysis.observables import FallingMassFlow
    from drumflow.case import Case


def plot_mean_temperature(times: NDArray, T_mean: NDArray, path: Path, title: str) -> None:
    """Mean particle temperature against time (the paper's Figures 7 and 8)."""
    plt = pyplot()
    fig, ax = plt.subplots(figsize=(6, 3.6), dpi=120)
    ax.plot(times, T_mean, color="tab:red", lw=1.6)
    ax.set_xlabel("time (s)")
    ax.set_ylabel("mean particle temperature (°C)")
    ax.set_title(title, fontsize=9)
    ax.grid(alpha=0.3)
    span = float(np.nanmax(T_mean) - np.nanmin(T_mean)) if len(T_mean) else 0.0
    if span < 1e-3:
        # A flat curve (no air, adiabatic walls) would otherwise be drawn as noise at 1e-6 K.
        mid = float(np.nanmean(T_mean))
        ax.set_ylim(mid - 1.0, mid + 1.0)
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)


def plot_crossings(
    crossings: pd.DataFrame,
    flow: FallingMassFlow,
    length: float,
    path: Path,
    title: str,
) -> None:
    """Crossing time against axial position (the paper's Figure 4), and the cumulative count."""
    plt = pyplot()
    fig, (ax, ax2) = plt.subplots(1, 2, figsize=(9, 3.6), dpi=120, gridspec_kw={"width_ratios": [3, 2]})
    inwin = crossings["time"] >= flow.window_start_s
    ax.scatter(crossings["time"][~inwin], crossings["z"][~inwin], s=6, color="0.7", lw=0,
               label="before window")
    ax.scatter(crossings["time"][inwin], crossings["z"][inwin], s=6, color="tab:blue", lw=0, label="counted")
    ax.set_xlabel("crossing time (s)")
    ax.set_ylabel("axial position z (m)")
    ax.set_ylim(0, length)
    ax.legend(loc="upper left", fontsize=7, markerscale=2)
    ax.set_title(title, fontsize=9)
    t = crossings["time"].to_numpy()
    ax2.step(t, np.arange(1, len(t) + 1) * flow.particle_mass_kg, where="post", color="tab:blue")
    ax2.set_xlabel("time (s)")
    ax2.set_ylabel("cumulative falling mass (kg)")
    ax2.set_title(f"falling mass flow {flow.mass_flow_kg_s:.4g} kg/s", fontsize=9)
    ax2.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)


#: Largest number of particles one cross-section picture draws (a seeded sample above it): at
#: 624 x 552 pixels more markers only cover each other.
MAX_DRAWN_PARTICLES = 100_000


def plot_particles(x: NDArray, y: NDArray, T: NDArray, case: Case, path: Path, title: str,
                   time_s: float | None = None) -> None:
    """Cross-section view of the particles coloured by temperature, lifters where they are."""
    plt = pyplot()
    from matplotlib.patches import Circle, Polygon

    from drumflow.case.lifter_shape import all_plates

    radius = case.drum.radius
    fig, ax = plt.subplots(figsize=(5.2, 4.6), dpi=120)
    ax.add_patch(Circle((0, 0), radius, fill=False, lw=1.5, color="0.3"))
    if time_s is not None:
        for plate in all_plates(radius, case.lifters, offset=drum_angle(case.drum.omega, time_s)):
            c = plate.corners()
            r = np.hypot(c[:, 0], c[:, 1])
            ax.add_patch(Polygon(c * np.minimum(1.0, radius / r)[:, None], color="0.45"))
    drawn = np.flatnonzero(~np.isnan(x))
    if len(drawn) > MAX_DRAWN_PARTICLES:
        # A seeded sample: the picture at this size shows no more, and drawing every marker of a
        # paper-scale bed was 4 s of `drumflow post`.
        drawn = np.sort(np.random.default_rng(0).choice(drawn, MAX_DRAWN_PARTICLES, replace=False))
        title = f"{title} ({MAX_DRAWN_PARTICLES:,} of {int(np.count_nonzero(~np.isnan(x))):,} drawn)"
    sc = ax.scatter(x[drawn], y[drawn], c=T[drawn], s=4, cmap="coolwarm", lw=0)
    fig.colorbar(sc, ax=ax, label="temperature (°C)")
    ax.set_aspect("equal")
    ax.set_xlim(-1.05 * radius, 1.05 * radius)
    ax.set_ylim(-1.05 * radius, 1.05 * radius)
    ax.set_title(title, fontsize=9)
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)


def plot_air_heat(coupling: pd.DataFrame, path: Path, title: str) -> None:
    """Heat removed by the air: rate (W) and cumulative (J) against time."""
    plt = pyplot()
    fig, ax = plt.subplots(figsize=(6, 3.6), dpi=120)
    t = coupling["time_s"].to_numpy()
    ax.plot(t, -coupling["heat_to_particles_W"].to_numpy(), color="tab:blue", lw=1.2)
    ax.set_xlabel("time (s)")
    ax.set_ylabel("heat removal rate (W)", color="tab:blue")
    ax2 = ax.twinx()
    ax2.plot(t, coupling["heat_removed_J"].to_numpy(), color="tab:red", lw=1.6)
    ax2.set_ylabel("heat removed (J)", color="tab:red")
    ax.set_title(title, fontsize=9)
    ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)
