"""The picture of an air field: the air speed in a cross-section of the drum."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from drumflow._mpl import pyplot
from drumflow.air.field import AirField
from drumflow.air.field_grid import fluid_mask_xy

if TYPE_CHECKING:
    from drumflow.case import Case

__all__ = ["plot_air_cross_section"]


def plot_air_cross_section(
    air: AirField, case: Case, path: Path, z: float | None = None, resolution: int = 240
) -> None:
    """PNG of the air speed in a drum cross-section (default: mid length, z = l/2).

    Left: the speed |U| (absolute, all three components). Right: the in-plane (swirl) speed
    with arrows of the in-plane velocity, which the axial throughflow would otherwise hide.
    Lifters and points outside the shell are blank.
    """
    plt = pyplot()
    import matplotlib
    from matplotlib.patches import Circle, Polygon

    from drumflow.case.lifter_shape import all_plates

    R, L = case.drum.radius, case.drum.length
    z = 0.5 * L if z is None else float(z)
    xs = np.linspace(-R, R, resolution)
    X, Y = np.meshgrid(xs, xs, indexing="xy")
    pts = np.column_stack([X.ravel(), Y.ravel(), np.full(X.size, z)])
    U = air.sample(pts)
    mask = ~fluid_mask_xy(case, X, Y)
    speed = np.ma.array(np.linalg.norm(U, axis=1).reshape(X.shape), mask=mask)
    swirl = np.ma.array(np.hypot(U[:, 0], U[:, 1]).reshape(X.shape), mask=mask)

    fig, axes = plt.subplots(1, 2, figsize=(11, 5), dpi=120)
    panels = ((speed, "|U| (m/s)"), (swirl, "in-plane speed (m/s)"))
    for ax, (data, label) in zip(axes, panels, strict=True):
        # Masked pixels (lifters) in the lifters' grey, and the image clipped to the shell:
        # otherwise a pixel row of white shows beside each plate wherever its edge falls
        # inside a pixel.
        cmap = matplotlib.colormaps["viridis"].with_extremes(bad="0.35")
        im = ax.imshow(
            data, origin="lower", extent=(-R, R, -R, R), cmap=cmap, interpolation="nearest"
        )
        shell = Circle((0, 0), R, fill=False, lw=1.5, color="0.2")
        ax.add_patch(shell)
        im.set_clip_path(shell)
        fig.colorbar(im, ax=ax, shrink=0.85, label=label)
        for plate in all_plates(R, case.lifters):
            corners = plate.corners()
            r = np.hypot(corners[:, 0], corners[:, 1])
            scale = np.minimum(1.0, R / np.maximum(r, 1e-300))
            ax.add_patch(Polygon(corners * scale[:, None], closed=True, color="0.35"))
        ax.set_xlim(-1.05 * R, 1.05 * R)
        ax.set_ylim(-1.05 * R, 1.05 * R)
        ax.set_aspect("equal")
        ax.set_xlabel("x (m)")
        ax.set_ylabel("y (m)")
    step = max(1, resolution // 24)
    sl = (slice(None, None, step), slice(None, None, step))
    Ux = np.ma.array(U[:, 0].reshape(X.shape), mask=mask)[sl]
    Uy = np.ma.array(U[:, 1].reshape(X.shape), mask=mask)[sl]
    axes[1].quiver(X[sl], Y[sl], Ux, Uy, color="white", scale_units="xy", angles="xy",
                   scale=float(max(np.ma.max(swirl), 1e-12)) / (0.08 * R), width=0.003)
    model = air.meta.get("model", "?")
    fig.suptitle(
        f"{case.name}: air ({model}) at z = {z:.3g} m, drum frame, absolute velocity; "
        f"{case.drum.rpm:g} rpm, mean axial {air.mean_axial_velocity():.3g} m/s towards -z",
        fontsize=9,
    )
    fig.tight_layout()
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path)
    plt.close(fig)
