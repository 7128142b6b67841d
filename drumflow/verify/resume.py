"""Rotation and frame after a restart: the lifters' angle against the air-sampling angle.

The air field is steady in the drum frame and the coupling loop samples it at the angle
omega t (:func:`drumflow.coupling.driver.air_velocity_at`), with t = step * dt from LIGGGHTS'
step counter. The lifters are a LIGGGHTS mesh turned by ``fix move/mesh``. After a resume both
must continue from where the interrupted attempt stopped: if the step counter restarted from 0
the air would be sampled at the wrong angle, and if the mesh were re-read from its STL file the
lifters would jump back to their initial angle. Either shows as a difference between the two
angles below.

:func:`lifter_angle_at_resume` measures the lifters' angle the way LIGGGHTS holds it: it re-runs
the run's own resume deck (in a scratch copy, so the run directory is not touched) up to its
set-up (``run 0``), dumps the lifter mesh, and finds the rotation that maps the geometry stage's
STL onto it. The air angle is omega times the time of the first row of the resumed attempt's
coupling log: the time the loop sampled the air at.
"""

from __future__ import annotations

import json
import math
import re
import shutil
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from drumflow.runner import Runner

#: The resumed attempt's deck (drumflow.dem.stage) and the dump this module adds to a copy.
RESUME_DECK = "in.drum.resume"
#: LIGGGHTS asks for a "*" (one file per step); the step number replaces it.
MESH_DUMP = "lifters_at_resume.*.stl"


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


def lifter_angle_at_resume(run_dir: Path, work: Path, runner: Runner | None = None) -> dict[str, Any]:
    """The lifters' angle and the air-sampling angle at the start of a resumed attempt.

    Parameters
    ----------
    run_dir
        A run directory whose DEM stage was resumed (it holds ``dem/in.drum.resume``) with air.
    work
        Scratch folder for the copy of the run's DEM and geometry folders (replaced).
    runner
        Runs LIGGGHTS (serial).

    Returns
    -------
    dict
        ``resume_step``, ``time_s`` (of the first coupling row after the resume), ``omega``,
        ``pitch_rad`` (2 pi / lifter count), ``lifter_angle_rad`` (measured from the mesh),
        ``air_angle_rad`` (omega t), both wrapped into one pitch, and ``mismatch_rad`` (their
        difference, wrapped the same way).
    """
    from drumflow.case import load_case

    runner = runner or Runner()
    case = load_case(run_dir / "case.toml")
    deck = (run_dir / "dem" / RESUME_DECK).read_text()
    m = re.search(r"^read_restart\s+restart/drum\.(\d+)\.restart", deck, flags=re.M)
    if m is None:
        raise ValueError(f"{run_dir}: {RESUME_DECK} does not read a numbered restart file")
    resume_step = int(m.group(1))
    mesh = "lifters" if re.search(r"^fix lifters ", deck, flags=re.M) else "shell"
    reference = "lifters.stl" if mesh == "lifters" else "walls.stl"

    if work.exists():
        shutil.rmtree(work)
    shutil.copytree(run_dir / "geometry", work / "geometry")
    shutil.copytree(run_dir / "dem", work / "dem",
                    ignore=shutil.ignore_patterns("*.txt", "*.npz", "*.csv", "log*"))
    # The resume deck with air ends at its set-up (`run 0`): the loop runs the steps. Dump the
    # lifter mesh as LIGGGHTS holds it there (a dump writes at the set-up of a run).
    if not re.fullmatch(r"run\s+0", deck.rstrip().splitlines()[-1].strip()):
        raise ValueError(f"{run_dir}: {RESUME_DECK} is not a coupled deck ending at its set-up")
    probe = deck + f"\ndump lifter_mesh all mesh/stl 1 {MESH_DUMP} {mesh}\nrun 0\n"
    (work / "dem" / "in.angle").write_text(probe)
    runner.run("liggghts", runner.profile.liggghts_command("in.angle", "log.angle", 1),
               work / "dem", work / "dem" / "angle.out", timeout=300)
    moved = read_stl_triangles(work / "dem" / MESH_DUMP.replace("*", str(resume_step)))
    original = read_stl_triangles(run_dir / "geometry" / reference)
    n = max(case.lifters.count, 1)
    pitch = 2.0 * math.pi / n

    log = run_dir / "dem" / "coupling" / f"rank0.{resume_step}.csv"
    first = pd.read_csv(log).iloc[0]
    omega = float(json.loads((run_dir / "dem" / "coupling.json").read_text())["omega"])
    lifter = wrap_angle(rotation_about_axis(original, moved, n), pitch)
    air = wrap_angle(omega * float(first["time_s"]), pitch)
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
