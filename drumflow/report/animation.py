"""Figure 6 in motion: the drum's cross-section, coloured by temperature, snapshot by snapshot.

:func:`render_animation` draws every full snapshot of a run (``dem/dumps/snap.*.txt or .npz``) the way
:func:`drumflow.report.snapshots.render_snapshot_panels` draws four of them: the particles projected
on the section (x-y, seen along the drum axis), one colour scale for the whole run so that the
cooling shows from frame to frame, the shell, and the lifters turned to the drum angle of the
frame (``omega t``, as LIGGGHTS' ``move/mesh rotate`` turns them). Frames go to an animated GIF
(Pillow, which Matplotlib already needs: no ffmpeg on a fresh machine) with the time and the mean
temperature in the title.

A GIF rather than a video because it plays inline in the HTML report and on GitHub; its 256
colours are enough for one colour map. The frame rate is the snapshots' rate scaled to a
watchable length: ``seconds_per_simulated_second`` (default 1: real time when snapshots are dense
enough), capped at :data:`MAX_FPS`; a run with snapshots every 0.5 s plays at 2 frames a second.
A paper-scale run writes one snapshot per ``run.snapshot_interval`` (0.5 s for the paper cases:
15 degrees of drum turn between frames), so its animation shows the cooling and the bed's
development, not the flow of single particles; a denser ``snapshot_interval`` gives smoother
motion at the cost of disk (about 40 MB per 467k-particle text snapshot).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from drumflow._mpl import pyplot
from drumflow.errors import RunDirectoryError
from drumflow.physics.drum_frame import drum_angle

if TYPE_CHECKING:
    from drumflow.case import Case
    from drumflow.rundir import RunDir

__all__ = ["ANIMATION", "MAX_FPS", "AnimationResult", "frame_rate", "render_animation"]

#: The animation's file name in a run's ``post/`` folder.
ANIMATION = "section_temperature.gif"
#: Fastest frame rate written (a GIF's frame delay is stored in hundredths of a second, and
#: browsers slow anything above about 50 fps).
MAX_FPS = 25


@dataclass(frozen=True)
class AnimationResult:
    """What :func:`render_animation` wrote.

    Attributes
    ----------
    path
        The GIF.
    frames
        Frames written (one per readable snapshot, at most ``max_frames``).
    times_s
        The simulated time of each frame.
    fps
        Frames per second of the GIF.
    temperature_range_C
        The colour scale (lowest and highest particle temperature over the frames).
    skipped
        Snapshot files that could not be read (a snapshot cut by an interrupt).
    """

    path: Path
    frames: int
    times_s: list[float]
    fps: int
    temperature_range_C: tuple[float, float]
    skipped: list[str]

    def as_dict(self) -> dict[str, Any]:
        return {"path": str(self.path), "frames": self.frames, "times_s": self.times_s,
                "fps": self.fps, "temperature_range_C": list(self.temperature_range_C),
                "skipped": self.skipped}


def frame_rate(times_s: list[float], seconds_per_simulated_second: float = 1.0) -> int:
    """Frames per second: the snapshots' own rate divided by ``seconds_per_simulated_second``,
    rounded to a whole number (what Matplotlib's GIF writer takes) between 1 and
    :data:`MAX_FPS` (1 for a single frame)."""
    if seconds_per_simulated_second <= 0 or not math.isfinite(seconds_per_simulated_second):
        raise ValueError(f"seconds_per_simulated_second = {seconds_per_simulated_second}: must be > 0")
    if len(times_s) < 2:
        return 1
    gaps = np.diff(np.asarray(times_s, dtype=float))
    gap = float(np.median(gaps[gaps > 0])) if np.any(gaps > 0) else 1.0
    return int(min(MAX_FPS, max(1, round(1.0 / (gap * seconds_per_simulated_second)))))


def _pick(count: int, max_frames: int) -> list[int]:
    if count <= max_frames:
        return list(range(count))
    return sorted({round(i) for i in np.linspace(0, count - 1, max_frames)})


def render_animation(run: RunDir, case: Case, target: Path | None = None, *,
                     seconds_per_simulated_second: float = 1.0, max_frames: int = 400,
                     dpi: int = 80) -> AnimationResult:
    """Write the cross-section animation of a run (module docstring).

    Parameters
    ----------
    run
        The run directory (needs ``dem/dumps/snap.*.txt or .npz``).
    case
        The run's case (drum radius and speed, lifters, particle size).
    target
        The GIF (default ``post/`` :data:`ANIMATION`).
    seconds_per_simulated_second
        Playback seconds per simulated second (1 = real time where the snapshots allow).
    max_frames
        At most this many frames, spread evenly over the snapshots (first and last kept).
    dpi
        Resolution of each frame (80 gives about 480 x 430 pixels).

    Returns
    -------
    AnimationResult

    Raises
    ------
    RunDirectoryError
        When the run has no readable snapshot.
    ValueError
        When ``max_frames`` < 1 or ``seconds_per_simulated_second`` <= 0.
    """
    plt = pyplot()
    from matplotlib.animation import FuncAnimation, PillowWriter
    from matplotlib.patches import Polygon

    from drumflow.case.lifter_shape import all_plates
    from drumflow.dem.dumps import dump_files, read_dump

    if max_frames < 1:
        raise ValueError(f"max_frames = {max_frames}: must be at least 1")
    files = dump_files(run.dem_dumps, "snap")
    if not files:
        raise RunDirectoryError(f"{run.dem_dumps}: no particle snapshot (snap.*.txt or .npz)")
    dt = run.recorded_time_step or case.run.dump_interval
    snaps = []
    skipped: list[str] = []
    for i in _pick(len(files), max_frames):
        try:
            snaps.append(read_dump(files[i]))
        except (RunDirectoryError, ValueError):
            skipped.append(files[i].name)
    if not snaps:
        raise RunDirectoryError(f"{run.dem_dumps}: no readable particle snapshot")
    times = [s.step * dt for s in snaps]
    fps = frame_rate(times, seconds_per_simulated_second)
    t_lo = min(float(np.min(s.columns["T"])) for s in snaps)
    t_hi = max(float(np.max(s.columns["T"])) for s in snaps)
    if not t_hi > t_lo:
        t_hi = t_lo + 0.1
    r = case.drum.radius
    fig, ax = plt.subplots(figsize=(6.0, 5.4))
    ax.set_xlim(-1.05 * r, 1.05 * r)
    ax.set_ylim(-1.05 * r, 1.05 * r)
    ax.set_aspect("equal")
    ax.set_xticks([])
    ax.set_yticks([])
    ax.add_patch(plt.Circle((0.0, 0.0), r, fill=False, lw=1.0, color="0.3"))
    # Marker area from the particle size in points, as in the four-panel figure.
    size = (72.0 * 5.0 * case.particles.diameter / (2.2 * r)) ** 2
    first = snaps[0].columns
    art = ax.scatter(first["x"], first["y"], c=first["T"], s=size, cmap="inferno", vmin=t_lo,
                     vmax=t_hi, linewidths=0)
    fig.colorbar(art, ax=ax, shrink=0.85, label="particle temperature (°C)")
    plates: list[Polygon] = []
    title = ax.set_title("")

    def draw(k: int) -> list[Any]:
        c = snaps[k].columns
        art.set_offsets(np.column_stack([c["x"], c["y"]]))
        art.set_array(np.asarray(c["T"]))
        for patch in plates:
            patch.remove()
        plates.clear()
        if case.lifters.count > 0:
            for plate in all_plates(r, case.lifters, drum_angle(case.drum.omega, times[k])):
                patch = Polygon(plate.corners(), closed=True, color="0.35", lw=0)
                ax.add_patch(patch)
                plates.append(patch)
        title.set_text(f"{case.name}: t = {times[k]:.2f} s, mean {float(np.mean(c['T'])):.2f} °C")
        return [art, title, *plates]

    target = target or run.post / ANIMATION
    target.parent.mkdir(parents=True, exist_ok=True)
    animation = FuncAnimation(fig, draw, frames=len(snaps), blit=False)
    animation.save(str(target), writer=PillowWriter(fps=fps), dpi=dpi)
    plt.close(fig)
    return AnimationResult(path=target, frames=len(snaps), times_s=times, fps=fps,
                           temperature_range_C=(t_lo, t_hi), skipped=skipped)
