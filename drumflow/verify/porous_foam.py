"""The OpenFOAM side of the porous-bed verification (:mod:`drumflow.verify.porous_bed`):
``porousSimpleFoam`` cases of air through a bed's porosity zones.

Each case is written from scratch: a ``blockMesh`` of axis-aligned boxes (:func:`write_block_mesh`),
one ``DarcyForchheimer`` porosity model per zone (``drumflow.air.foam_case.write_porosity``),
plain SIMPLE numerics
(:func:`write_numerics`) and the initial fields (:func:`drumflow.air.foam_case.write_field`);
:func:`solve_bed_air` runs ``topoSet`` and ``porousSimpleFoam`` and reads the cells back.
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from drumflow.air.solids_fraction import PorosityZones
from drumflow.errors import AirNotConvergedError
from drumflow.runner import Runner

__all__ = [
    "AirOfBed",
    "air_at",
    "cell_order",
    "fresh_case",
    "solve_bed_air",
    "write_block_mesh",
    "write_numerics",
]

#: Air at 30 C and 1 atm (drumflow's air table).
AIR_TEMPERATURE_C = 30.0
#: Residual target of the SIMPLE iterations (p and U).
RESIDUAL_TARGET = 1e-7
MAX_ITERATIONS = 4000


@dataclass
class AirOfBed:
    """The air's properties and the solved fields of one porous-bed run."""

    density: float
    viscosity: float  # dynamic, Pa s
    cells: dict[str, NDArray[np.float64]]  # C, V, U, p (kinematic) from read_cell_fields
    zones: PorosityZones
    fraction: NDArray[np.float64]  # per OpenFOAM cell
    iterations: int
    wall_time_s: float

    @property
    def kinematic_viscosity(self) -> float:
        return self.viscosity / self.density


def air_at(temperature_C: float = AIR_TEMPERATURE_C) -> tuple[float, float]:
    """Air density (ideal gas, 1 atm) and dynamic viscosity (drumflow's air table), SI."""
    from drumflow.physics.air import dynamic_viscosity, ideal_gas_density

    return ideal_gas_density(temperature_C), float(dynamic_viscosity(temperature_C))


def write_block_mesh(case_dir: Path, blocks: list[dict[str, Any]]) -> None:
    """Write ``system/blockMeshDict`` for axis-aligned boxes, each with its own vertices (so
    blocks touching one another are *not* joined: the shared face becomes two wall patches,
    a baffle). Each block: ``lower``, ``upper``, ``cells``, ``prefix``; x faces are cyclic
    when ``cyclic_x``, y faces when ``cyclic_y``; the rest are walls, except the z faces
    named in ``z_patches`` (``(low_name, high_name)``)."""
    vertices: list[str] = []
    hexes: list[str] = []
    patches: list[str] = []
    for b in blocks:
        lo, hi = b["lower"], b["upper"]
        o = len(vertices)
        for z in (lo[2], hi[2]):
            for x, y in ((lo[0], lo[1]), (hi[0], lo[1]), (hi[0], hi[1]), (lo[0], hi[1])):
                vertices.append(f"({x:.12g} {y:.12g} {z:.12g})")
        n = b["cells"]
        grading = b.get("grading", "simpleGrading (1 1 1)")
        hexes.append(f"hex ({' '.join(str(o + i) for i in range(8))}) ({n[0]} {n[1]} {n[2]}) {grading}")
        faces = {
            "xlo": f"({o} {o + 4} {o + 7} {o + 3})", "xhi": f"({o + 1} {o + 2} {o + 6} {o + 5})",
            "ylo": f"({o} {o + 1} {o + 5} {o + 4})", "yhi": f"({o + 3} {o + 7} {o + 6} {o + 2})",
            "zlo": f"({o} {o + 3} {o + 2} {o + 1})", "zhi": f"({o + 4} {o + 5} {o + 6} {o + 7})",
        }
        p = b["prefix"]
        walls: list[str] = []
        for axis in ("x", "y"):
            if b.get(f"cyclic_{axis}"):
                for side, other in (("lo", "hi"), ("hi", "lo")):
                    patches.append(f"{p}{axis}{side} {{ type cyclic; neighbourPatch {p}{axis}{other}; "
                                   f"faces ({faces[axis + side]}); }}")
            else:
                walls += [faces[axis + "lo"], faces[axis + "hi"]]
        z_names = b.get("z_patches", (None, None))
        for side, name in zip(("lo", "hi"), z_names, strict=True):
            if name is None:
                walls.append(faces["z" + side])
            else:
                patches.append(f"{name} {{ type patch; faces ({faces['z' + side]}); }}")
        if walls:
            patches.append(f"{p}walls {{ type wall; faces ({' '.join(walls)}); }}")
    text = (
        "FoamFile { version 2.0; format ascii; class dictionary; object blockMeshDict; }\n"
        "convertToMeters 1;\n"
        f"vertices ({' '.join(vertices)});\n"
        f"blocks ({' '.join(hexes)});\n"
        "edges ();\n"
        f"boundary ({' '.join(patches)});\n"
        "mergePatchPairs ();\n"
    )
    (case_dir / "system").mkdir(parents=True, exist_ok=True)
    (case_dir / "system" / "blockMeshDict").write_text(text)


def write_numerics(case_dir: Path, nu: float, reference_cell: bool,
                    source: float | None = None) -> None:
    """controlDict, fvSchemes, fvSolution (plain SIMPLE: SIMPLEC with a porosity diagonal hit a
    floating-point exception in this build), laminar transport, optional driving source."""
    from foamlib import FoamFile

    from drumflow.air.foam_case import (
        write_control_dict,
        write_fv_schemes,
        write_fv_solution,
        write_transport,
    )

    write_control_dict(case_dir, MAX_ITERATIONS)
    write_fv_schemes(case_dir)
    write_fv_solution(case_dir, RESIDUAL_TARGET, ["p", "U"], consistent=False)
    with FoamFile(case_dir / "system" / "fvSolution") as f:
        # Conjugate gradients: the baffled duct is two unconnected regions, and only one can
        # hold the reference cell; CG converges on the other's consistent singular system.
        f["solvers"] = {
            "p": {"solver": "PCG", "preconditioner": "DIC", "tolerance": 1e-12, "relTol": 0.01},
            "U": {"solver": "smoothSolver", "smoother": "symGaussSeidel", "tolerance": 1e-14,
                  "relTol": 0.1},
        }
        if reference_cell:
            f["SIMPLE", "pRefCell"] = 0
            f["SIMPLE", "pRefValue"] = 0.0
    write_transport(case_dir, nu, "laminar")
    options = case_dir / "constant" / "fvOptions"
    options.unlink(missing_ok=True)
    if source is not None:
        # Written as text: foamlib drops the parentheses around the (Su Sp) pair.
        options.write_text(
            "FoamFile { version 2.0; format ascii; class dictionary; object fvOptions; }\n"
            "drivingPressureGradient\n{\n    type vectorSemiImplicitSource;\n    active yes;\n"
            "    selectionMode all;\n    volumeMode specific;\n"
            f"    injectionRateSuSp {{ U (({source:.12g} 0 0) 0); }}\n}}\n"
        )


def solve_bed_air(case_dir: Path, runner: Runner, zones: PorosityZones, fraction: NDArray[np.float64],
           density: float, viscosity: float, timeout: float) -> AirOfBed:
    """blockMesh, topoSet, porousSimpleFoam, cell centres; return the fields."""
    from drumflow.air.foam import latest_time, read_cell_fields, write_cell_centres
    from drumflow.air.foam_results import ResidualParser
    from drumflow.air.mesh import run_foam

    t0 = time.perf_counter()
    run_foam(runner, "topoSet", [], case_dir, timeout=timeout)
    parser = ResidualParser()
    log = run_foam(runner, "porousSimpleFoam", [], case_dir, timeout=timeout, on_line=parser)
    history = parser.finish()
    iterations = int(history["iteration"].iloc[-1]) if len(history) else 0
    if not parser.converged:
        final = {k: float(v) for k, v in history.iloc[-1].items() if k != "iteration"} if len(history) else {}
        raise AirNotConvergedError(iterations, final, RESIDUAL_TARGET, log)
    write_cell_centres(runner, case_dir, timeout)
    cells = read_cell_fields(case_dir, latest_time(case_dir))
    return AirOfBed(density, viscosity, cells, zones, fraction, iterations,
                    time.perf_counter() - t0)


def cell_order(case_dir: Path, runner: Runner, timeout: float) -> NDArray[np.float64]:
    """Cell centres of the mesh as blockMesh numbered them (before any solve)."""
    from foamlib import FoamFieldFile

    from drumflow.air.mesh import run_foam

    (case_dir / "0").mkdir(exist_ok=True)
    run_foam(runner, "postProcess", ["-funcs", "(writeCellCentres)", "-time", "0"], case_dir,
             timeout=timeout, log_name="log.postProcess.centres")
    centres = np.asarray(FoamFieldFile(case_dir / "0" / "C").internal_field, dtype=float).reshape(-1, 3)
    for name in ("C", "Cx", "Cy", "Cz"):
        # Left in 0/, they would be read back as initial fields by the later postProcess.
        (case_dir / "0" / name).unlink(missing_ok=True)
    return centres


def fresh_case(case_dir: Path) -> None:
    import shutil

    if case_dir.exists():
        shutil.rmtree(case_dir)
    (case_dir / "system").mkdir(parents=True)
    (case_dir / "constant").mkdir()
