"""Verification of the air set-up against an exact solution: circular Couette flow.

Laminar flow between two concentric cylinders, the inner one (radius r1) turning at omega1
and the outer one (r2) at rest, has the exact steady azimuthal velocity

    u_theta(r) = A r + B / r,   A = -omega1 r1^2 / (r2^2 - r1^2),
                                B =  omega1 r1^2 r2^2 / (r2^2 - r1^2).

The check runs the same machinery as the drum (gmsh -> gmshToFoam -> patch types -> checkMesh
-> simpleFoam, dictionaries from :mod:`drumflow.air.foam`) on a 2D annulus: a structured
quadrilateral mesh extruded one cell in z, its front and back faces ``empty`` (OpenFOAM
v1912's way of saying 2D; cyclic ends would need matching face pairs from gmsh, which
gmshToFoam cannot declare). Two ways to turn the inner wall are offered:

- ``"mrf"`` (default, as the drum): the whole fluid is an MRF zone turning at omega1, the outer
  wall is a non-rotating patch (``noSlip`` at rest); the inner ``noSlip`` wall turns with the
  zone. This checks the MRF source terms, the absolute-velocity output and the handling of
  walls that the drum relies on.
- ``"wall"``: no MRF; the inner wall has ``rotatingWallVelocity``.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Literal

import numpy as np
from numpy.typing import NDArray

from drumflow.air.foam import (
    ResidualParser,
    latest_time,
    read_cell_fields,
    write_cell_centres,
    write_control_dict,
    write_fv_schemes,
    write_mrf,
    write_transport,
)
from drumflow.air.mesh import check_mesh, import_gmsh_mesh, run_foam
from drumflow.runner import Runner


@dataclass
class CouetteResult:
    """Measured and exact u_theta, and the run's numbers.

    ``r``, ``measured`` and ``exact`` are along one radius (the column of cells nearest the
    +x axis), sorted by r. ``max_relative_error`` is the largest |u - u_exact| over **every**
    cell, divided by the inner wall speed omega1 r1 (relative to the local u_theta it would be
    undefined at the outer wall, where u_theta = 0).
    """

    case_dir: Path
    method: str
    r: NDArray[np.float64]
    measured: NDArray[np.float64]
    exact: NDArray[np.float64]
    max_relative_error: float
    max_radial_velocity: float
    iterations: int
    converged: bool
    cells: int
    wall_time_s: float

    def summary(self) -> dict[str, Any]:
        """Plain-JSON numbers."""
        return {
            "case_dir": str(self.case_dir),
            "method": self.method,
            "max_relative_error": self.max_relative_error,
            "max_radial_velocity_over_wall_speed": self.max_radial_velocity,
            "iterations": self.iterations,
            "converged": self.converged,
            "cells": self.cells,
            "wall_time_s": self.wall_time_s,
        }


def couette_exact(r: NDArray[np.float64], r1: float, r2: float, omega1: float) -> NDArray[np.float64]:
    """Exact u_theta(r) between an inner cylinder turning at omega1 and a fixed outer one."""
    r = np.asarray(r, dtype=float)
    A = -omega1 * r1**2 / (r2**2 - r1**2)
    B = omega1 * r1**2 * r2**2 / (r2**2 - r1**2)
    return A * r + B / r


def write_annulus_mesh(
    path: Path, r1: float, r2: float, n_radial: int, n_theta: int, thickness: float
) -> int:
    """Structured annulus of hexahedra, one cell thick in z, as ASCII msh 2.2; return cells.

    Four quarter sectors, each a transfinite quadrilateral patch, so the mesh is
    orthogonal and the error is the scheme's, not the mesh's.
    """
    import gmsh

    from drumflow.geometry.drum import _Gmsh

    if n_theta % 4:
        raise ValueError(f"n_theta must be a multiple of 4, got {n_theta}")
    geo = gmsh.model.geo
    with _Gmsh():
        gmsh.model.add("annulus")
        centre = geo.addPoint(0.0, 0.0, 0.0)
        inner = [geo.addPoint(r1 * math.cos(a), r1 * math.sin(a), 0.0)
                 for a in (0.5 * math.pi * k for k in range(4))]
        outer = [geo.addPoint(r2 * math.cos(a), r2 * math.sin(a), 0.0)
                 for a in (0.5 * math.pi * k for k in range(4))]
        radial = [geo.addLine(inner[k], outer[k]) for k in range(4)]
        arcs_in = [geo.addCircleArc(inner[k], centre, inner[(k + 1) % 4]) for k in range(4)]
        arcs_out = [geo.addCircleArc(outer[k], centre, outer[(k + 1) % 4]) for k in range(4)]
        surfaces = []
        for k in range(4):
            loop = geo.addCurveLoop([radial[k], arcs_out[k], -radial[(k + 1) % 4], -arcs_in[k]])
            surfaces.append(geo.addPlaneSurface([loop]))
        # Constraints through the geo kernel itself: set on gmsh.model.mesh they would be
        # lost when the extrusion below synchronises the model again.
        for c in radial:
            geo.mesh.setTransfiniteCurve(c, n_radial + 1)
        for c in arcs_in + arcs_out:
            geo.mesh.setTransfiniteCurve(c, n_theta // 4 + 1)
        for s in surfaces:
            geo.mesh.setTransfiniteSurface(s)
            geo.mesh.setRecombine(2, s)
        out = geo.extrude([(2, s) for s in surfaces], 0.0, 0.0, thickness, [1], recombine=True)
        geo.synchronize()
        volumes = [t for d, t in out if d == 3]
        # Bounding boxes (gmsh pads them a little, hence the loose tolerance): a quarter arc
        # spans [0, r] on both axes; the interior radial faces between sectors are flat in
        # one of them, and are not boundaries.
        tol = 1e-3 * r2
        groups: dict[str, list[int]] = {"inner": [], "outer": [], "frontAndBack": []}
        for _, tag in gmsh.model.getEntities(2):
            x0, y0, z0, x1, y1, z1 = gmsh.model.getBoundingBox(2, tag)
            reach_x, reach_y = max(abs(x0), abs(x1)), max(abs(y0), abs(y1))
            if z1 < tol or z0 > thickness - tol:
                groups["frontAndBack"].append(tag)
            elif max(reach_x, reach_y) < r1 + tol:
                groups["inner"].append(tag)
            elif min(reach_x, reach_y) > r1 + tol:
                groups["outer"].append(tag)
        for name, tags in groups.items():
            gmsh.model.addPhysicalGroup(2, tags, name=name)
        gmsh.model.addPhysicalGroup(3, volumes, name="fluid")
        gmsh.option.setNumber("Mesh.MshFileVersion", 2.2)
        gmsh.option.setNumber("Mesh.Binary", 0)
        gmsh.model.mesh.generate(3)
        cells = sum(
            len(t) for v in volumes for t in gmsh.model.mesh.getElements(3, v)[1]
        )
        path.parent.mkdir(parents=True, exist_ok=True)
        gmsh.write(str(path))
    return int(cells)


def _write_fields(case_dir: Path, method: str, omega1: float) -> None:
    from drumflow.air.foam_case import write_field

    zero = [0.0, 0.0, 0.0]
    if method == "mrf":
        inner: dict[str, Any] = {"type": "noSlip"}
    else:
        inner = {
            "type": "rotatingWallVelocity",
            "origin": zero,
            "axis": [0.0, 0.0, 1.0],
            "omega": float(omega1),
            "value": zero,
        }
    write_field(case_dir, "U", {"length": 1, "time": -1}, zero, {
        "inner": inner,
        "outer": {"type": "noSlip"},
        "frontAndBack": {"type": "empty"},
    })
    write_field(case_dir, "p", {"length": 2, "time": -2}, 0.0, {
        "inner": {"type": "zeroGradient"},
        "outer": {"type": "zeroGradient"},
        "frontAndBack": {"type": "empty"},
    })


def _write_solution(case_dir: Path, tolerance: float) -> None:
    from foamlib import FoamFile

    path = case_dir / "system" / "fvSolution"
    path.unlink(missing_ok=True)
    with FoamFile(path) as f:
        f["solvers"] = {
            "p": {"solver": "GAMG", "smoother": "GaussSeidel", "tolerance": 1e-10, "relTol": 0.01},
            "U": {"solver": "smoothSolver", "smoother": "symGaussSeidel", "tolerance": 1e-10,
                  "relTol": 0.01},
        }
        f["SIMPLE"] = {
            "nNonOrthogonalCorrectors": 0,
            "consistent": True,
            # A closed domain: the pressure level is fixed in one cell.
            "pRefCell": 0,
            "pRefValue": 0.0,
            "residualControl": {"p": tolerance, "U": tolerance},
        }
        f["relaxationFactors"] = {"fields": {"p": 1.0}, "equations": {"U": 0.9}}


def verify_couette(
    workdir: Path,
    runner: Runner | None = None,
    *,
    method: Literal["mrf", "wall"] = "mrf",
    r1: float = 0.1,
    r2: float = 0.2,
    omega1: float = 1.0,
    nu: float = 1e-3,
    n_radial: int = 16,
    n_theta: int = 96,
    tolerance: float = 1e-6,
    max_iterations: int = 3000,
    timeout: float | None = 300.0,
) -> CouetteResult:
    """Run circular Couette flow with simpleFoam and compare u_theta with the exact profile.

    Parameters
    ----------
    workdir
        The OpenFOAM case directory (created; old results inside are overwritten).
    runner
        Starts the OpenFOAM programs; default a fresh :class:`Runner`.
    method
        ``"mrf"`` (the drum's way) or ``"wall"`` (rotating wall condition), see the module
        docstring.
    r1, r2, omega1
        Inner and outer radius (m) and the inner wall's angular speed (rad/s).
    nu
        Kinematic viscosity, m^2/s. The default gives Re = omega1 r1 (r2 - r1) / nu = 10,
        far below the Taylor-vortex onset, so the steady laminar answer is the physical one.
    n_radial, n_theta
        Cells across the gap and around the circumference (a multiple of 4).
    tolerance
        SIMPLE residual target.

    Returns
    -------
    CouetteResult
    """
    import shutil

    runner = runner or Runner()
    started = time.time()
    workdir = Path(workdir)
    workdir.mkdir(parents=True, exist_ok=True)
    for p in list(workdir.iterdir()):
        if p.is_dir() and p.name not in ("0", "constant", "system"):
            try:
                float(p.name)
            except ValueError:
                if p.name != "postProcessing":
                    continue
            shutil.rmtree(p)
    thickness = 2.0 * math.pi * r1 / n_theta  # cells about as deep as they are wide
    msh = workdir / "annulus.msh"
    cells = write_annulus_mesh(msh, r1, r2, n_radial, n_theta, thickness)
    import_gmsh_mesh(
        msh, workdir, runner, {"inner": "wall", "outer": "wall", "frontAndBack": "empty"},
        timeout=timeout,
    )
    check_mesh(workdir, runner, timeout=timeout)
    write_control_dict(workdir, max_iterations)
    write_fv_schemes(workdir)
    _write_solution(workdir, tolerance)
    write_transport(workdir, nu, "laminar")
    mrf = workdir / "constant" / "MRFProperties"
    mrf.unlink(missing_ok=True)
    if method == "mrf":
        write_mrf(workdir, omega1, ["outer"])
    _write_fields(workdir, method, omega1)
    parser = ResidualParser()
    run_foam(runner, "simpleFoam", [], workdir, timeout=timeout, on_line=parser)
    history = parser.finish()
    time_dir = latest_time(workdir)
    write_cell_centres(runner, workdir, timeout)
    data = read_cell_fields(workdir, time_dir)
    C, U = data["C"], data["U"]
    r = np.hypot(C[:, 0], C[:, 1])
    e_theta = np.column_stack([-C[:, 1] / r, C[:, 0] / r])
    u_theta = (U[:, :2] * e_theta).sum(axis=1)
    u_r = (U[:, :2] * np.column_stack([C[:, 0] / r, C[:, 1] / r])).sum(axis=1)
    exact = couette_exact(r, r1, r2, omega1)
    wall_speed = omega1 * r1
    angle = np.arctan2(C[:, 1], C[:, 0])
    first = np.abs(angle - angle[np.argmin(np.abs(angle))]) < 0.5 * (2.0 * math.pi / n_theta)
    order = np.argsort(r[first])
    return CouetteResult(
        case_dir=workdir,
        method=method,
        r=r[first][order],
        measured=u_theta[first][order],
        exact=exact[first][order],
        max_relative_error=float(np.max(np.abs(u_theta - exact)) / wall_speed),
        max_radial_velocity=float(np.max(np.abs(u_r)) / wall_speed),
        iterations=int(history["iteration"].iloc[-1]) if len(history) else 0,
        converged=parser.converged,
        cells=cells,
        wall_time_s=time.time() - started,
    )
