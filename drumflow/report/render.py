"""Off-screen 3-D picture of the particles coloured by temperature (the paper's Figure 6).

:func:`render_particles` draws with PyVista in the calling process.
:func:`render_particles_isolated` does the same in a child Python process with a time limit.
Off-screen OpenGL is the most fragile dependency of a report: a missing or broken driver can
make VTK abort the process or hang while it looks for a display, and neither can be caught by
``try``. In a child process such a failure becomes a :class:`RenderError`, which the report
turns into a note.

Drum frame (as in :mod:`drumflow.geometry`): the axis is ``z`` from 0 to the section length,
the cross-section is ``x``-``y`` centred on the axis, and gravity points along ``-y``.
"""

from __future__ import annotations

import json
import sys
import tempfile
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from drumflow.errors import RenderError, SolverError, SolverTimeoutError
from drumflow.runner import Runner

__all__ = ["RenderError", "render_particles", "render_particles_isolated"]

_DEFAULT_WINDOW = (1000, 800)
# Share of the window height the drum diameter takes in the default view; used to turn the
# particle diameter into a point size in pixels (render_points_as_spheres draws screen-space
# discs of a fixed pixel size).
_DRUM_SHARE_OF_HEIGHT = 0.8


def _as_points(x: ArrayLike, y: ArrayLike, z: ArrayLike, T: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
    arrays = [np.asarray(a, dtype=np.float64).ravel() for a in (x, y, z, T)]
    sizes = {a.size for a in arrays}
    if len(sizes) != 1:
        raise RenderError(f"x, y, z and T differ in length ({[a.size for a in arrays]})")
    pts = np.column_stack(arrays[:3])
    temp = arrays[3]
    # Lost particles are NaN in a snapshot series; they have no place to be drawn.
    keep = np.all(np.isfinite(pts), axis=1) & np.isfinite(temp)
    if not keep.any():
        raise RenderError("no particle with finite position and temperature to draw")
    return pts[keep], temp[keep]


def render_particles(
    x: ArrayLike,
    y: ArrayLike,
    z: ArrayLike,
    T: ArrayLike,
    path: Path | str,
    radius: float,
    length: float,
    *,
    particle_diameter: float | None = None,
    title: str | None = None,
    window_size: tuple[int, int] = _DEFAULT_WINDOW,
) -> Path:
    """Render the particles as spheres coloured by temperature into a PNG (off-screen).

    Parameters
    ----------
    x, y, z
        Particle centres (m), drum frame (axis along ``z``). NaN entries (lost particles) are
        skipped.
    T
        Particle temperatures (deg C), same length.
    path
        PNG file to write.
    radius
        Drum radius (m); the shell is drawn as two rings at ``z = 0`` and ``z = length``.
    length
        Simulated section length (m).
    particle_diameter
        Particle diameter (m), to size the points; default ``radius / 50``.
    title
        Text in the upper left corner.
    window_size
        Picture size in pixels ``(width, height)``.

    Returns
    -------
    pathlib.Path
        ``path``.

    Raises
    ------
    RenderError
        If the inputs hold no drawable particle or have different lengths.
    Exception
        Whatever VTK raises when it cannot render. Use :func:`render_particles_isolated` to
        be safe from crashes.
    """
    import pyvista as pv

    pts, temp = _as_points(x, y, z, T)
    if not (radius > 0 and length > 0):
        raise RenderError(f"radius = {radius!r} and length = {length!r} must be > 0")
    out = Path(path)
    out.parent.mkdir(parents=True, exist_ok=True)
    d_p = particle_diameter if particle_diameter and particle_diameter > 0 else radius / 50.0
    px_per_m = _DRUM_SHARE_OF_HEIGHT * window_size[1] / (2.0 * radius)
    point_size = float(max(2.0, d_p * px_per_m))

    cloud = pv.PolyData(pts)
    cloud["temperature (deg C)"] = temp
    # Any: PyVista's method decorators confuse static checkers (they see unbound wrappers).
    plotter: Any = pv.Plotter(off_screen=True, window_size=list(window_size))
    try:
        plotter.set_background("white")
        lo, hi = float(temp.min()), float(temp.max())
        if hi - lo < 1e-6:
            # A uniform field would give a degenerate colour range; widen it by 1 K.
            lo, hi = lo - 0.5, hi + 0.5
        plotter.add_mesh(
            cloud,
            scalars="temperature (deg C)",
            cmap="coolwarm",
            clim=(lo, hi),
            render_points_as_spheres=True,
            point_size=point_size,
            scalar_bar_args={
                "color": "black", "title": "T (deg C)", "vertical": True,
                "position_x": 0.86, "position_y": 0.1, "width": 0.06, "height": 0.8,
            },
        )
        angle = np.linspace(0.0, 2.0 * np.pi, 181)
        for z_ring in (0.0, length):
            ring = np.column_stack(
                [radius * np.cos(angle), radius * np.sin(angle), np.full(angle.size, z_ring)]
            )
            plotter.add_mesh(pv.lines_from_points(ring), color="gray", line_width=2)
        plotter.view_xy()
        # A slightly oblique view shows the section's depth, like the paper's Figure 6.
        # vtkCamera's rotations (PyVista's lower-case names are absolute-angle properties).
        plotter.camera.Azimuth(-20.0)
        plotter.camera.Elevation(15.0)
        plotter.reset_camera()
        if title:
            plotter.add_text(title, position="upper_left", font_size=10, color="black")
        plotter.screenshot(str(out))
    finally:
        plotter.close()
    return out


def _child_main() -> None:
    """Entry point of the child process started by :func:`render_particles_isolated`."""
    import vtk

    # The child's stderr is captured for the error message; keep VTK's display-probing
    # warnings out of it so that the last line is the real error, if any.
    vtk.vtkLogger.SetStderrVerbosity(vtk.vtkLogger.VERBOSITY_ERROR)
    npz, png, options = sys.argv[1], sys.argv[2], json.loads(sys.argv[3])
    with np.load(npz) as data:
        render_particles(
            data["x"], data["y"], data["z"], data["T"], png,
            options["radius"], options["length"],
            particle_diameter=options.get("particle_diameter"),
            title=options.get("title"),
            window_size=tuple(options.get("window_size", _DEFAULT_WINDOW)),
        )


def render_particles_isolated(
    x: ArrayLike,
    y: ArrayLike,
    z: ArrayLike,
    T: ArrayLike,
    path: Path | str,
    radius: float,
    length: float,
    *,
    particle_diameter: float | None = None,
    title: str | None = None,
    window_size: tuple[int, int] = _DEFAULT_WINDOW,
    timeout_s: float = 180.0,
    runner: Runner | None = None,
) -> Path:
    """:func:`render_particles` in a child Python process with a time limit.

    Parameters
    ----------
    x, y, z, T, path, radius, length, particle_diameter, title, window_size
        As for :func:`render_particles`.
    timeout_s
        Time limit for the child (s); it is killed when exceeded.
    runner
        Starts the child (default a fresh :class:`~drumflow.runner.Runner`).

    Returns
    -------
    pathlib.Path
        ``path``.

    Raises
    ------
    RenderError
        If the child fails, crashes or runs out of time (the message has the reason and the
        last line of its error output), or writes no picture.
    """
    pts, temp = _as_points(x, y, z, T)
    out = Path(path)
    out.parent.mkdir(parents=True, exist_ok=True)
    options = {
        "radius": float(radius),
        "length": float(length),
        "particle_diameter": None if particle_diameter is None else float(particle_diameter),
        "title": title,
        "window_size": list(window_size),
    }
    with tempfile.TemporaryDirectory(prefix="drumflow-render-") as tmp:
        npz = Path(tmp) / "particles.npz"
        np.savez(npz, x=pts[:, 0], y=pts[:, 1], z=pts[:, 2], T=temp)
        # Through the runner like every other program: own process group (a hung VTK is
        # killed whole at the time limit), output kept in a log for the error message.
        log = Path(tmp) / "render.log"
        runner = runner or Runner()
        command = runner.profile.python_module_command("drumflow.report.render", str(npz), str(out),
                                                       json.dumps(options))
        try:
            runner.run("pyvista", command, Path(tmp), log, timeout=timeout_s)
        except SolverTimeoutError:
            raise RenderError(
                f"PyVista render did not finish within {timeout_s:g} s (off-screen OpenGL "
                "unavailable or too slow)"
            ) from None
        except SolverError as exc:
            # The log's first two lines are the runner's header.
            lines = [ln for ln in log.read_text(errors="replace").splitlines()[2:] if ln.strip()]
            last = lines[-1].strip() if lines else "no error output"
            code = exc.returncode
            how = (
                f"killed by signal {-code}" if code is not None and code < 0
                else f"exit status {code}"
            )
            raise RenderError(f"PyVista render failed ({how}): {last}") from None
    if not out.is_file() or out.stat().st_size == 0:
        raise RenderError(f"PyVista render wrote no picture at {out}")
    return out


if __name__ == "__main__":
    _child_main()
