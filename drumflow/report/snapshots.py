"""Figure 6 as pictures of a run: its particles coloured by temperature.

:func:`render_last_snapshot` renders the last snapshot in 3-D (PyVista, in a child process);
:func:`render_snapshot_panels` draws the cross-section at several times side by side
(Matplotlib). :mod:`drumflow.report.animation` draws every snapshot as an animation.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from drumflow._mpl import pyplot
from drumflow.case import Case
from drumflow.errors import RunDirectoryError
from drumflow.rundir import RunDir

__all__ = ["render_last_snapshot", "render_snapshot_panels"]


def render_last_snapshot(run: RunDir, case: Case, target: Path, timeout_s: float) -> Path:
    """Figure 6: the last snapshot coloured by temperature (PyVista, in a child process)."""
    from drumflow.dem.dumps import dump_files, read_dump
    from drumflow.report.render import render_particles_isolated

    dt = run.recorded_time_step
    for path in reversed(dump_files(run.dem_dumps, "snap")):
        try:
            snap = read_dump(path)
        except (RunDirectoryError, ValueError):
            continue
        c = snap.columns
        when = f"t = {snap.step * dt:.3g} s" if dt else f"step {snap.step}"
        target.parent.mkdir(parents=True, exist_ok=True)
        return render_particles_isolated(
            c["x"], c["y"], c["z"], c["T"], target, case.drum.radius, case.drum.length,
            particle_diameter=case.particles.diameter, title=f"{case.name}, {when}",
            timeout_s=timeout_s)
    raise RunDirectoryError(f"{run.dem_dumps}: no readable particle snapshot (snap.*.txt or .npz)")


def render_snapshot_panels(run: RunDir, case: Case, target: Path, panels: int = 4) -> Path:
    """Figure 6 at several times: the cross-section (x-y) of up to ``panels`` snapshots.

    The snapshots are spread evenly over those written (first and last always), drawn with one
    colour scale so that the cooling from panel to panel is visible, and the drum shell drawn
    for scale. Matplotlib only (no rendering process): a few seconds for 300k particles.

    Raises
    ------
    RunDirectoryError
        When the run has no readable snapshot.
    """
    from drumflow.dem.dumps import dump_files, read_dump

    plt = pyplot()
    files = dump_files(run.dem_dumps, "snap")
    if not files:
        raise RunDirectoryError(f"{run.dem_dumps}: no particle snapshot (snap.*.txt or .npz)")
    picks = sorted({round(i) for i in np.linspace(0, len(files) - 1, min(panels, len(files)))})
    snaps = []
    for i in picks:
        try:
            snaps.append(read_dump(files[i]))
        except (RunDirectoryError, ValueError):
            continue
    if not snaps:
        raise RunDirectoryError(f"{run.dem_dumps}: no readable particle snapshot")
    dt = run.recorded_time_step
    t_lo = min(float(np.min(s.columns["T"])) for s in snaps)
    t_hi = max(float(np.max(s.columns["T"])) for s in snaps)
    if not t_hi > t_lo:
        t_hi = t_lo + 0.1
    r = case.drum.radius
    fig, axes = plt.subplots(1, len(snaps), figsize=(3.2 * len(snaps) + 0.8, 3.6), squeeze=False)
    art = None
    for ax, snap in zip(axes[0], snaps, strict=True):
        c = snap.columns
        # Marker area from the particle size in points, so the bed looks like a bed at any scale.
        size = (72.0 * 3.2 * case.particles.diameter / (2.2 * r)) ** 2
        art = ax.scatter(c["x"], c["y"], c=c["T"], s=size, cmap="inferno", vmin=t_lo, vmax=t_hi,
                         linewidths=0, rasterized=True)
        ax.add_patch(plt.Circle((0.0, 0.0), r, fill=False, lw=0.8, color="0.3"))
        ax.set_xlim(-1.05 * r, 1.05 * r)
        ax.set_ylim(-1.05 * r, 1.05 * r)
        ax.set_aspect("equal")
        ax.set_xticks([])
        ax.set_yticks([])
        when = f"t = {snap.step * dt:.2f} s" if dt else f"step {snap.step}"
        ax.set_title(f"{when}\nmean {float(np.mean(c['T'])):.2f} °C", fontsize=9)
    assert art is not None
    fig.colorbar(art, ax=list(axes[0]), shrink=0.8, label="particle temperature (°C)")
    fig.suptitle(f"{case.name}: the section seen along the drum axis, coloured by temperature",
                 fontsize=10)
    target.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(target, dpi=110, bbox_inches="tight")
    plt.close(fig)
    return target
