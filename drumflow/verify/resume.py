"""Rotation and frame after a restart: the lifters' angle against the air-sampling angle.

The air field is steady in the drum frame and the coupling loop samples it at the angle
omega t (:func:`drumflow.coupling.driver.air_velocity_at`), with t = step * dt from LIGGGHTS'
step counter. The lifters are a LIGGGHTS mesh turned by ``fix move/mesh``. After a resume both
must continue from where the interrupted attempt stopped: if the step counter restarted from 0
the air would be sampled at the wrong angle, and if the mesh were re-read from its STL file the
lifters would jump back to their initial angle. Either shows as a difference between the two
angles below.

:func:`lifter_angle_at_resume` measures the lifters' angle the way LIGGGHTS holds it: a resumed
deck writes the turning mesh once at its set-up, as read from the restart
(:data:`~drumflow.dem.deck.RESUME_MESH_PATTERN`), and the rotation that maps the geometry
stage's STL onto it is the lifters' angle. The air angle is omega times the time of the first
row of the resumed attempt's coupling log: the time the loop sampled the air at. (The check
once re-ran the resume deck from the restart in a scratch copy; reading what the run itself
wrote lets the run drop that restart, 0.27 GB for paper model one.)
"""

from __future__ import annotations

import json
import math
import re
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from drumflow.dem.deck import RESUME_MESH_PATTERN
from drumflow.physics.drum_frame import drum_angle

#: The resumed attempt's deck (drumflow.dem.stage).
RESUME_DECK = "in.drum.resume"


def read_stl_triangles(path: Path) -> np.ndarray:
    """The triangles of an ASCII STL file, shape (n, 3, 3), m."""
    numbers = re.findall(r"^\s*vertex\s+(\S+)\s+(\S+)\s+(\S+)", path.read_text(), flags=re.M)
    if not numbers or len(numbers) % 3:
        raise ValueError(f"{path}: not an ASCII STL file with whole triangles")
    return np.asarray(numbers, dtype=float).reshape(-1, 3, 3)


def rotation_about_axis(reference: np.ndarray, moved: np.ndarray, symmetry: int) -> float:
    """Angle (rad) by which ``moved`` is ``reference`` turned counter-clockwise about +z.

    The triangles need not correspond one to one (LIGGGHTS writes its own order): the angle
    comes from the ``symmetry``-th complex moment sum_i A_i (x_i + i y_i)^n of the triangles'
    area-weighted centroids, which turns by n theta. A drum with n equal lifters is the same
    after a turn of 2 pi / n, so the angle is returned in (-pi/n, pi/n].
    """

    def moment(tris: np.ndarray) -> complex:
        centroid = tris.mean(axis=1)
        area = 0.5 * np.linalg.norm(np.cross(tris[:, 1] - tris[:, 0], tris[:, 2] - tris[:, 0]), axis=1)
        z = centroid[:, 0] + 1j * centroid[:, 1]
        return complex(np.sum(area * z**symmetry))

    ref = moment(reference)
    if abs(ref) == 0.0:
        raise ValueError("the reference mesh has no moment of that order: its angle is undefined")
    return float(np.angle(moment(moved) / ref)) / symmetry


def wrap_angle(angle: float, period: float) -> float:
    """``angle`` wrapped into (-period/2, period/2]."""
    return -((-angle + 0.5 * period) % period - 0.5 * period)


def lifter_angle_at_resume(run_dir: Path) -> dict[str, Any]:
    """The lifters' angle and the air-sampling angle at the start of a resumed attempt.

    Parameters
    ----------
    run_dir
        A run directory whose DEM stage was resumed with air: it holds ``dem/in.drum.resume``
        and the turning mesh that deck wrote at its set-up.

    Returns
    -------
    dict
        ``resume_step``, ``time_s`` (of the first coupling row after the resume), ``omega``,
        ``pitch_rad`` (2 pi / lifter count), ``lifter_angle_rad`` (measured from the mesh),
        ``air_angle_rad`` (omega t), both wrapped into one pitch, and ``mismatch_rad`` (their
        difference, wrapped the same way).

    Raises
    ------
    ValueError
        The deck does not resume from a numbered restart, or did not write the turning mesh
        (a static shell without lifters, or a run resumed by an older drumflow).
    """
    from drumflow.case import load_case

    case = load_case(run_dir / "case.toml")
    deck = (run_dir / "dem" / RESUME_DECK).read_text()
    m = re.search(r"^read_restart\s+restart/drum\.(\d+)\.restart", deck, flags=re.M)
    if m is None:
        raise ValueError(f"{run_dir}: {RESUME_DECK} does not read a numbered restart file")
    resume_step = int(m.group(1))
    written = re.search(r"^dump\s+resume_mesh\s+all\s+mesh/stl\s+\d+\s+\S+\s+(\w+)", deck, flags=re.M)
    if written is None:
        raise ValueError(f"{run_dir}: {RESUME_DECK} writes no turning mesh to check")
    reference = "lifters.stl" if written.group(1) == "lifters" else "walls.stl"
    moved = read_stl_triangles(run_dir / "dem" / RESUME_MESH_PATTERN.replace("*", str(resume_step)))
    original = read_stl_triangles(run_dir / "geometry" / reference)
    n = max(case.lifters.count, 1)
    pitch = 2.0 * math.pi / n

    log = run_dir / "dem" / "coupling" / f"rank0.{resume_step}.csv"
    first = pd.read_csv(log).iloc[0]
    omega = float(json.loads((run_dir / "dem" / "coupling.json").read_text())["omega"])
    lifter = wrap_angle(rotation_about_axis(original, moved, n), pitch)
    air = wrap_angle(drum_angle(omega, float(first["time_s"])), pitch)
    return {
        "resume_step": resume_step,
        "coupling_first_step": int(first["step"]),
        "time_s": float(first["time_s"]),
        "omega": omega,
        "pitch_rad": pitch,
        "lifter_angle_rad": lifter,
        "air_angle_rad": air,
        "mismatch_rad": wrap_angle(lifter - air, pitch),
    }
