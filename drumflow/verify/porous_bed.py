"""Two-way momentum through a local solids fraction: air through and past a LIGGGHTS-packed
bed, solved by OpenFOAM v1912 ``porousSimpleFoam``, against independent references.

The bed
-------
:func:`pour_bed` pours 1856 spheres of 4 mm into a square section 10 d wide, periodic
on its four sides (x and y), onto a floor, and lets them settle under gravity (LIGGGHTS,
Hertz contacts, friction 0.5): a random loose packing of voidage about 0.41 away from the
floor. The section is periodic, not walled, because walls pack a layer of voidage ~0.5 that
carries more than its share of air (wall channelling); Ergun's constants were fitted to data
corrected for it, so a walled bed would test the wall effect, not the law.

The air model
-------------
The spheres are deposited on the air grid (cells of 2 d, :mod:`drumflow.air.solids_fraction`,
one 1-2-1 smoothing pass), the cells are binned into porosity zones (``topoSet``
``cellZoneSet`` from cell lists) whose Darcy-Forchheimer coefficients come from Ergun's law at
the cell's voidage, and ``porousSimpleFoam`` (laminar, SIMPLE) solves the superficial velocity.

The checks (all ``kind="reference"``)
-------------------------------------
a. :func:`bed_pressure_drop_check`: air blown up through the bed; the pressure gradient over
   an interior window (8 d, away from the floor and the free surface) against Ergun's at the
   window's mean voidage, computed exactly from the sphere positions (spherical caps, no grid);
   at Re_p = 20 (mostly viscous) and 120 (mostly inertial).
b. :func:`bed_flow_split_check`: a duct whose lower half is the bed and whose upper half is
   open, split by a thin baffle along its length and periodic along it, driven by a uniform
   pressure gradient G: the bed's share of the flow against the parallel-resistance solution
   at the same G (the open half's exact laminar rectangular-duct flow, White 2006 Eq. 3-48,
   and the bed's Ergun flow). The baffle makes the parallel-resistance model exact. Without
   it the open half's shear drags the top of the bed along: in Brinkman's continuum model
   that layer adds h / (2 H) of the bed's Darcy flow (50 % for a half-blocked duct) whatever
   the permeability, and the porous surface lets the open half slip. Measured on this grid
   (``baffle=False``): bed flow +23 %, open flow +22 % against the parallel model at the same
   G, so the *share* still agrees (0.9 %) while neither flow does. The coupling is then a
   question of grid and interface model, not of Ergun's law, and is left out of the check.
c. :func:`bed_momentum_check` (same run as a): the drag of Ergun's law at each bed cell's
   voidage and solved velocity, summed over the bed, against the pressure loss times the duct
   area. The solver balances its own (binned) coefficients against the pressure by
   construction; this sum uses the exact per-cell law, so it fails when the coefficients the
   solver was given are not Ergun's.

Each check fails when the law on the simulated side is changed by 10 % (``law=...``) while
the reference keeps the published constants (tests/solver/test_porous_bed.py).
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray
from scipy.optimize import brentq

from drumflow.air.solids_fraction import (
    ERGUN,
    ErgunLaw,
    PorosityZones,
    RectilinearGrid,
    bin_coefficients,
    deposit_solids_fraction,
    slab_sphere_volume,
    smooth_deposition,
)
from drumflow.errors import AirNotConvergedError, SolverError
from drumflow.runner import Runner
from drumflow.verify.checks import Check, relative_error

#: Particle diameter (m), density (kg/m^3) and the section's width in diameters.
DIAMETER = 0.004
PARTICLE_DENSITY = 1050.0
WIDTH_DIAMETERS = 10
#: Rows of 8 x 8 spheres dropped from a loose lattice: 29 rows settle to a bed ~16.8 d deep.
LATTICE_ROWS = 29
LATTICE_SIDE = 8
#: Settling: Hertz with a softened modulus (as drumflow's drum decks soften theirs) for a
#: 5e-5 s step; KE falls to ~1e-6 of its peak by 6000 steps (0.3 s).
YOUNGS_MODULUS = 1.0e6
SETTLE_STEPS = 6000
#: RMS particle speed (m/s) below which the poured bed counts as settled (see pour_bed).
SETTLED_SPEED = 0.05
TIME_STEP = 5.0e-5
#: Air cell size in particle diameters: 2 d cells hold ~9 spheres, so the deposited fraction
#: scatters by 0.027 from cell to cell (measured), 0.008 after the smoothing pass.
CELL_DIAMETERS = 2
#: Porosity zones: bins of equal width in ln d; each zone gets the volume-mean of its
#: cells' coefficients (:func:`~drumflow.air.solids_fraction.bin_coefficients`).
BINS = 16
#: Air at 30 C and 1 atm (drumflow's air table).
AIR_TEMPERATURE_C = 30.0
#: Particle Reynolds numbers rho U d / mu of the flow up through the bed. At 20 (checks a and
#: c) the viscous term is 72 % of Ergun's gradient, at 120 (check a at the inertial end) the
#: inertial one is 66 %: a 10 % change of either constant then moves one of the two gradients
#: by more than the tolerance (a change of B alone moves the first by only 2.8 %).
BED_REYNOLDS = 20.0
INERTIAL_REYNOLDS = 120.0
#: Residual target of the SIMPLE iterations (p and U).
RESIDUAL_TARGET = 1e-7
MAX_ITERATIONS = 4000

#: Check a: Ergun's correlation itself scatters by about +-15 % about packed-bed data
#: (Macdonald et al. 1979), but here the reference and the solver use the same constants; what
#: separates them is (i) the binning (16 zones against one zone per cell: 0.04-0.12 % in the
#: gradient, measured on two pours), (ii) the scatter of the smoothed cell voidage (standard
#: deviation 0.008 between cells, 0.007 between layers, measured; by second-order estimates
#: well under 1 % on the mean resistance), (iii) the grid's window voidage against the exact
#: one (0.0001, 0.1 % in resistance) and (iv) the collocated grid's cell velocities at
#: resistance jumps (the rest of the measured +1.4 % at Re_p 20, +1.0 % at 120). 5 %, not the
#: brief's 10 %: a 10 % change of the law moves the gradient by 10 %, which a 10 % tolerance
#: could let pass.
PRESSURE_DROP_TOLERANCE = 0.05
#: Check b: the bed's share of the flow, ~5e-4 (the bed is ~4000 times less permeable than the
#: open half). Errors: the open duct's discretisation with 20 x 16 cells (+1.2 % of its flow,
#: measured), the bed's voidage scatter and the binning (the bed's flow came within 0.2 % of
#: Ergun's). Measured -1.4 %. 5 %, as the brief asks; Ergun's 150 10 % high moves the share by
#: 10 % (measured). The bed's Re_p is ~0.001 there, so B does not enter this check.
FLOW_SPLIT_TOLERANCE = 0.05
#: Check c: momentum over the duct closes to the SIMPLE residual (1e-7) and to the momentum-flux
#: change between the uniform inlet and the outlet (< 0.1 % of the pressure force at Re_p 20);
#: the rest is the binning: the zone's mean coefficient against each cell's own, weighted by
#: the cell's velocity (measured: 0.0 % with a zone per cell, 0.38 % with 16 zones, 1.5 % with
#: 8, 2.4 % with 4). 1 %, as the brief asks; it needs >= 16 zones.
MOMENTUM_TOLERANCE = 0.01


@dataclass(frozen=True)
class PackedBed:
    """Spheres settled by LIGGGHTS in a section periodic along x and y, on a floor at z = 0."""

    positions: NDArray[np.float64]  # (n, 3), m, inside [0, width)^2 x [0, height]
    radii: NDArray[np.float64]  # (n,), m
    width: float  # the section's period along x and y, m
    diameter: float
    wall_time_s: float

    @property
    def top(self) -> float:
        """Height of the highest sphere's top, m."""
        return float(np.max(self.positions[:, 2] + self.radii))

    def voidage(self, lower: float, upper: float) -> float:
        """Exact mean voidage between two horizontal planes (spherical caps, no grid)."""
        solid = slab_sphere_volume(self.positions, self.radii, lower, upper)
        return 1.0 - solid / (self.width**2 * (upper - lower))


def _bed_deck(width: float, seed: int) -> str:
    """A minimal LIGGGHTS deck: spheres on a jittered loose lattice fall onto a floor."""
    rng = np.random.default_rng(seed)
    spacing = width / LATTICE_SIDE
    lines = []
    for k in range(LATTICE_ROWS):
        for j in range(LATTICE_SIDE):
            for i in range(LATTICE_SIDE):
                # The jitter breaks the lattice so that the spheres settle into a random packing.
                x, y = (np.array([i, j]) + 0.5) * spacing + rng.uniform(-0.1, 0.1, 2) * DIAMETER
                z = (0.55 + 1.1 * k) * DIAMETER
                lines.append(f"create_atoms 1 single {x:.9g} {y:.9g} {z:.9g} units box")
    height = (0.6 + 1.1 * LATTICE_ROWS + 1.0) * DIAMETER
    atoms = "\n".join(lines)
    return f"""# Packed bed for drumflow's porous-bed verification (drumflow.verify.porous_bed).
atom_style      granular
atom_modify     map array
boundary        p p f
newton          off
communicate     single vel yes
units           si
# A 1 MPa modulus (below LIGGGHTS' 5 MPa limit) keeps the time step at 5e-5 s.
soft_particles  yes
region          box block 0 {width:.9g} 0 {width:.9g} 0 {height:.9g} units box
create_box      1 box
{atoms}
set             atom * diameter {DIAMETER} density {PARTICLE_DENSITY}
fix m1 all property/global youngsModulus peratomtype {YOUNGS_MODULUS:g}
fix m2 all property/global poissonsRatio peratomtype 0.45
fix m3 all property/global coefficientRestitution peratomtypepair 1 0.2
fix m4 all property/global coefficientFriction peratomtypepair 1 0.5
pair_style      gran model hertz tangential history
pair_coeff      * *
neighbor        {0.25 * DIAMETER:g} bin
neigh_modify    delay 0
timestep        {TIME_STEP:g}
fix floor all wall/gran model hertz tangential history primitive type 1 zplane 0.0
fix grav all gravity 9.81 vector 0 0 -1
fix integrate all nve/sphere
compute ke all ke
thermo_style    custom step atoms c_ke
thermo          1000
thermo_modify   norm no flush yes
run             {SETTLE_STEPS}
dump bed all custom 1 bed.dump id x y z radius
dump_modify bed format "%d %.10g %.10g %.10g %.10g"
run 0
"""


def pour_bed(work: Path, runner: Runner, seed: int = 1, processes: int = 2,
             timeout: float = 900.0) -> PackedBed:
    """Pour and settle the bed with LIGGGHTS; return the settled spheres.

    Raises
    ------
    drumflow.errors.SolverError
        LIGGGHTS failed, or the bed has not settled (the RMS speed from the last thermo
        line's kinetic energy above :data:`SETTLED_SPEED`).
    """
    t0 = time.perf_counter()
    work.mkdir(parents=True, exist_ok=True)
    width = WIDTH_DIAMETERS * DIAMETER
    (work / "in.bed").write_text(_bed_deck(width, seed))
    processes = max(1, min(processes, runner.profile.cores))
    command = runner.profile.liggghts_command("in.bed", "log.liggghts", processes)
    runner.run("liggghts", command, work, work / "liggghts.out", timeout=timeout)
    table = np.loadtxt(work / "bed.dump", skiprows=9, ndmin=2)
    positions, radii = table[:, 1:4], table[:, 4]
    ke = _last_kinetic_energy(work / "log.liggghts")
    mass = float(np.sum(PARTICLE_DENSITY * 4.0 / 3.0 * math.pi * radii**3))
    # Settled: the RMS speed sqrt(2 KE / m) below 5 cm/s. A settled bed of soft spheres keeps
    # ringing in its contacts (about 1 cm/s at 6000 steps, measured), but with a contact time
    # near 1 ms that is an amplitude of a few micrometres, 0.1 % of a diameter; a bed still
    # flowing moves at tenths of a metre per second.
    if not ke < 0.5 * mass * SETTLED_SPEED**2:
        raise SolverError("liggghts", command, 0, work / "log.liggghts",
                          None, reason=f"the bed has not settled: KE = {ke:g} J")
    return PackedBed(positions, radii, width, DIAMETER, time.perf_counter() - t0)


def _last_kinetic_energy(log: Path) -> float:
    ke = math.nan
    for line in log.read_text(errors="replace").splitlines():
        parts = line.split()
        if len(parts) == 3 and parts[0].isdigit():
            try:
                ke = float(parts[2])
            except ValueError:
                continue
    return ke


# -- the OpenFOAM cases ---------------------------------------------------------------------


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
    from drumflow.air_properties import dynamic_viscosity, ideal_gas_density

    return ideal_gas_density(temperature_C), float(dynamic_viscosity(temperature_C))


def _block_mesh(case_dir: Path, blocks: list[dict[str, Any]]) -> None:
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


def _write_porosity(case_dir: Path, zones: PorosityZones) -> None:
    """``system/topoSetDict`` (one cellZoneSet per zone, from its cell list) and
    ``constant/porosityProperties`` (one DarcyForchheimer model per zone)."""
    from foamlib import FoamFile

    topo = case_dir / "system" / "topoSetDict"
    topo.unlink(missing_ok=True)
    with FoamFile(topo) as f:
        f["actions"] = [
            {"name": name, "type": "cellZoneSet", "action": "new", "source": "labelToCell",
             "value": [int(c) for c in cells]}
            for name, cells in zip(zones.names, zones.cells, strict=True)
        ]
    props = case_dir / "constant" / "porosityProperties"
    props.unlink(missing_ok=True)
    with FoamFile(props) as f:
        for name, d, fc in zip(zones.names, zones.d, zones.f, strict=True):
            f[name] = {
                "type": "DarcyForchheimer",
                "active": True,
                "cellZone": name,
                "DarcyForchheimerCoeffs": {
                    "d": [float(d)] * 3,
                    "f": [float(fc)] * 3,
                    "coordinateSystem": {
                        "type": "cartesian",
                        "origin": [0.0, 0.0, 0.0],
                        "coordinateRotation": {"type": "axesRotation", "e1": [1.0, 0.0, 0.0],
                                               "e2": [0.0, 1.0, 0.0]},
                    },
                },
            }


def _write_field(case_dir: Path, name: str, dims: dict[str, int], internal: Any,
                 boundary: dict[str, dict[str, Any]]) -> None:
    from foamlib import FoamFieldFile, FoamFile

    path = case_dir / "0" / name
    path.parent.mkdir(parents=True, exist_ok=True)
    path.unlink(missing_ok=True)
    with FoamFieldFile(path) as f:
        f.dimensions = FoamFile.DimensionSet(**dims)
        f.internal_field = internal
        f.boundary_field = boundary


def _write_numerics(case_dir: Path, nu: float, reference_cell: bool,
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


def _solve(case_dir: Path, runner: Runner, zones: PorosityZones, fraction: NDArray[np.float64],
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


def _cell_order(case_dir: Path, runner: Runner, timeout: float) -> NDArray[np.float64]:
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


def _fresh(case_dir: Path) -> None:
    import shutil

    if case_dir.exists():
        shutil.rmtree(case_dir)
    (case_dir / "system").mkdir(parents=True)
    (case_dir / "constant").mkdir()


# -- check a and c: air blown up through the bed -----------------------------------------------


@dataclass
class ColumnRun:
    """The flow up through the bed: fields, grid and what the checks need."""

    air: AirOfBed
    bed: PackedBed
    grid: RectilinearGrid
    velocity: float  # superficial, m/s
    window: tuple[float, float]  # the interior planes of check a, m
    inlet_z: float
    reynolds: float  # rho U d / mu

    def layer_pressure(self, z: float) -> float:
        """Area-mean kinematic pressure of the cell layer centred at ``z``."""
        c = self.air.cells["C"][:, 2]
        layer = np.isclose(c, z, atol=1e-9)
        return float(np.average(self.air.cells["p"][layer], weights=self.air.cells["V"][layer]))


def run_bed_column(work: Path, runner: Runner, bed: PackedBed, law: ErgunLaw = ERGUN,
                   bins: int | None = BINS, smoothing_passes: int = 1,
                   reynolds: float = BED_REYNOLDS, timeout: float = 600.0) -> ColumnRun:
    """Air blown up (+z) through the bed at particle Reynolds number ``reynolds``.

    The duct runs from 4 d below the floor (inlet, uniform velocity) to 4 d above the bed's top
    (outlet, p = 0), periodic across; cells of :data:`CELL_DIAMETERS` d. ``law`` is what the
    solver is given (the references always use :data:`ERGUN`).
    """
    d = bed.diameter
    cell = CELL_DIAMETERS * d
    bottom = -4.0 * d
    n_z = math.ceil((bed.top + 4.0 * d - bottom) / cell)
    n_xy = round(bed.width / cell)
    grid = RectilinearGrid.uniform([0.0, 0.0, bottom], [bed.width, bed.width, bottom + n_z * cell],
                                   (n_xy, n_xy, n_z), periodic=(True, True, False))
    deposition = smooth_deposition(deposit_solids_fraction(grid, bed.positions, bed.radii),
                                   smoothing_passes)
    rho, mu = air_at()
    velocity = reynolds * mu / (rho * d)
    case_dir = work / f"column_re{reynolds:g}"
    _fresh(case_dir)
    _block_mesh(case_dir, [{"lower": [0.0, 0.0, bottom],
                            "upper": [bed.width, bed.width, float(grid.edges[2][-1])],
                            "cells": grid.shape, "prefix": "", "cyclic_x": True, "cyclic_y": True,
                            "z_patches": ("inlet", "outlet")}])
    from drumflow.air.mesh import run_foam

    _write_numerics(case_dir, mu / rho, reference_cell=False)
    run_foam(runner, "blockMesh", [], case_dir, timeout=timeout)
    centres = _cell_order(case_dir, runner, timeout)
    fraction = grid.flatten(deposition.fraction)[grid.locate(centres)]
    volumes = grid.flatten(grid.cell_volumes)[grid.locate(centres)]
    zones = bin_coefficients(fraction, volumes, d, bins=bins, law=law)
    _write_porosity(case_dir, zones)
    cyclic = {"type": "cyclic"}
    _write_field(case_dir, "U", {"length": 1, "time": -1}, [0.0, 0.0, velocity], {
        "inlet": {"type": "fixedValue", "value": [0.0, 0.0, velocity]},
        "outlet": {"type": "zeroGradient"},
        '"(x|y)(lo|hi)"': cyclic,
    })
    _write_field(case_dir, "p", {"length": 2, "time": -2}, 0.0, {
        "inlet": {"type": "zeroGradient"},
        "outlet": {"type": "fixedValue", "value": 0.0},
        '"(x|y)(lo|hi)"': cyclic,
    })
    air = _solve(case_dir, runner, zones, fraction, rho, mu, timeout)
    # The window: cell-layer centres 5 d and 13 d above the floor, clear of the floor's loose
    # layer and of the free surface (~16.8 d) after one smoothing pass.
    window = (bottom + cell * (math.floor((5.0 * d - bottom) / cell) + 0.5),
              bottom + cell * (math.floor((13.0 * d - bottom) / cell) + 0.5))
    return ColumnRun(air, bed, grid, velocity, window, bottom, reynolds)


def bed_pressure_drop_check(run: ColumnRun) -> Check:
    """Check a: the CFD's pressure gradient over the bed's interior against Ergun's at the
    window's exact mean voidage."""
    lo, hi = run.window
    rho = run.air.density
    measured = (run.layer_pressure(lo) - run.layer_pressure(hi)) * rho / (hi - lo)
    eps = run.bed.voidage(lo, hi)
    expected = ERGUN.pressure_gradient(eps, run.bed.diameter, run.velocity, rho, run.air.viscosity)
    viscous = ErgunLaw(ERGUN.viscous, 0.0).pressure_gradient(
        eps, run.bed.diameter, run.velocity, rho, run.air.viscosity)
    suffix = "" if run.reynolds == BED_REYNOLDS else f"_re{run.reynolds:g}"
    return Check(
        name="porous_bed_pressure_drop" + suffix,
        measured=measured,
        expected=expected,
        error=relative_error(measured, expected),
        tolerance=PRESSURE_DROP_TOLERANCE,
        unit="Pa/m",
        note=f"{len(run.bed.radii)} spheres of {run.bed.diameter * 1e3:g} mm settled by LIGGGHTS "
        f"(periodic {WIDTH_DIAMETERS} d section); air up through it at Re_p = {run.reynolds:g} "
        f"(U = {run.velocity:.4g} m/s superficial), porousSimpleFoam on "
        f"{len(run.air.cells['V'])} cells, {len(run.air.zones.cells)} porosity zones; "
        f"-dp/dz over z = {lo * 1e3:.0f}-{hi * 1e3:.0f} mm",
        reference="Ergun (1952) Chem. Eng. Prog. 48:89 at the window's voidage from the sphere "
        "positions (exact spherical caps)",
        wall_time_s=run.air.wall_time_s,
        details={
            "voidage_window": eps,
            "reynolds_particle": run.reynolds,
            "viscous_share": viscous / expected,
            "iterations": run.air.iterations,
            "binning": run.air.zones.binning_error(),
            "spheres": len(run.bed.radii),
            "bed_top_m": run.bed.top,
        },
    )


def bed_momentum_check(run: ColumnRun) -> Check:
    """Check c: Ergun's drag at each cell's voidage and velocity, summed, against the pressure
    loss times the duct area."""
    cells = run.air.cells
    rho, mu = run.air.density, run.air.viscosity
    bed = run.air.fraction > 0
    d_cell, f_cell = ERGUN.darcy_forchheimer(1.0 - run.air.fraction[bed], run.bed.diameter)
    u = cells["U"][bed]
    speed = np.linalg.norm(u, axis=1)
    drag = float(np.sum((mu * d_cell + 0.5 * rho * f_cell * speed) * u[:, 2] * cells["V"][bed]))
    area = run.bed.width**2
    # zeroGradient at the inlet: its face pressure is the first layer's cell pressure.
    p_in = run.layer_pressure(float(run.grid.centres[0, 2]))
    force = p_in * rho * area
    return Check(
        name="porous_bed_momentum",
        measured=drag,
        expected=force,
        error=relative_error(drag, force),
        tolerance=MOMENTUM_TOLERANCE,
        unit="N",
        note="sum over the bed cells of (mu d + rho |U| f / 2) U_z V with Ergun's d, f at each "
        "cell's deposited voidage, against (p_inlet - p_outlet) times the duct area",
        reference="momentum balance of the duct (no walls: periodic sides) with Ergun's law "
        "per cell",
        wall_time_s=run.air.wall_time_s,
        details={"pressure_loss_Pa": p_in * rho, "bed_cells": int(bed.sum())},
    )


# -- check b: the flow split in a duct half blocked by the bed ---------------------------------


def rectangular_duct_flow(gradient: float, viscosity: float, width: float, height: float,
                          terms: int = 50) -> float:
    """Volume flow, m^3/s, of fully developed laminar flow in a rectangular duct.

    Q = G a^3 b / (12 mu) [1 - 192 a / (pi^5 b) sum_{n odd} tanh(n pi b / (2 a)) / n^5] with
    a <= b the sides (White 2006, Viscous Fluid Flow, 3rd ed., Eq. 3-48).
    """
    a, b = sorted((width, height))
    n = np.arange(1, 2 * terms, 2, dtype=float)
    series = np.sum(np.tanh(n * math.pi * b / (2.0 * a)) / n**5)
    return gradient * a**3 * b / (12.0 * viscosity) * (1.0 - 192.0 * a / (math.pi**5 * b) * series)


def ergun_velocity(gradient: float, voidage: float, diameter: float, density: float,
                   viscosity: float, law: ErgunLaw = ERGUN) -> float:
    """Superficial velocity at which ``law`` gives the pressure gradient ``gradient``, m/s."""
    top = 1.0
    while law.pressure_gradient(voidage, diameter, top, density, viscosity) < gradient:
        top *= 2.0
    return float(brentq(lambda u: law.pressure_gradient(voidage, diameter, u, density, viscosity)
                        - gradient, 0.0, top, xtol=1e-16, rtol=1e-13))


@dataclass
class SplitRun:
    air: AirOfBed
    gradient: float  # driving pressure gradient, Pa/m
    bed_flow: float  # m^3/s through the bed half
    open_flow: float  # m^3/s through the open half
    voidage: float  # the bed slab's exact mean voidage
    slab: tuple[float, float]  # the slab of the poured bed used, m
    duct: tuple[float, float, float]  # length (periodic), width, half height, m


#: Open-half mean velocity aimed at (m/s): Re_Dh ~ 200, laminar.
OPEN_VELOCITY = 0.3


def run_flow_split(work: Path, runner: Runner, bed: PackedBed, law: ErgunLaw = ERGUN,
                   bins: int | None = BINS, baffle: bool = True, timeout: float = 600.0) -> SplitRun:
    """The baffled duct: lower half the bed (the slab 2-10 d above the poured bed's floor),
    upper half open, periodic along x, driven by a uniform pressure gradient.

    ``baffle=False`` leaves the halves open to each other (one block, the bed's cells as
    narrow across the duct as the open half's): the open half's shear then drags the bed's
    top along, which the parallel-resistance reference leaves out (for the report, not a check).
    """
    d = bed.diameter
    cell = CELL_DIAMETERS * d
    length = width = bed.width
    half = 8.0 * d
    slab = (2.0 * d, 2.0 * d + half)
    n = round(width / cell)
    n_across = n if baffle else round(width / (0.5 * d))
    grid = RectilinearGrid.uniform([0.0, 0.0, 0.0], [length, width, half],
                                   (n, n_across, round(half / cell)), periodic=(True, True, False))
    shifted = bed.positions - np.array([0.0, 0.0, slab[0]])
    deposition = smooth_deposition(deposit_solids_fraction(grid, shifted, bed.radii), 1)
    rho, mu = air_at()
    # Open half: 2d cells along the flow (it is uniform there), d/2 across.
    open_cells = (n, round(width / (0.5 * d)), round(half / (0.5 * d)))
    gradient = OPEN_VELOCITY * width * half / rectangular_duct_flow(1.0, mu, width, half)
    case_dir = work / "split"
    _fresh(case_dir)
    if baffle:
        _block_mesh(case_dir, [
            {"lower": [0.0, 0.0, 0.0], "upper": [length, width, half], "cells": grid.shape,
             "prefix": "bed_", "cyclic_x": True},
            {"lower": [0.0, 0.0, half], "upper": [length, width, 2.0 * half], "cells": open_cells,
             "prefix": "open_", "cyclic_x": True},
        ])
    else:
        nz_bed, nz = grid.shape[2], grid.shape[2] + open_cells[2]
        _block_mesh(case_dir, [
            {"lower": [0.0, 0.0, 0.0], "upper": [length, width, 2.0 * half],
             "cells": (n, n_across, nz), "prefix": "bed_", "cyclic_x": True,
             "grading": f"simpleGrading (1 1 ((0.5 {nz_bed / nz:.12g} 1) (0.5 {1 - nz_bed / nz:.12g} 1)))"},
        ])
    from drumflow.air.mesh import run_foam

    _write_numerics(case_dir, mu / rho, reference_cell=True, source=gradient / rho)
    run_foam(runner, "blockMesh", [], case_dir, timeout=timeout)
    centres = _cell_order(case_dir, runner, timeout)
    in_bed = centres[:, 2] < half
    index = grid.locate(centres)
    fraction = np.where(in_bed, grid.flatten(deposition.fraction)[np.clip(index, 0, None)], 0.0)
    cell_volumes = np.full(len(centres), 0.0)
    cell_volumes[in_bed] = grid.flatten(grid.cell_volumes)[index[in_bed]]
    cell_volumes[~in_bed] = length * width * half / np.prod(open_cells)
    zones = bin_coefficients(fraction, cell_volumes, d, bins=bins, law=law)
    _write_porosity(case_dir, zones)
    cyclic = {"type": "cyclic"}
    _write_field(case_dir, "U", {"length": 1, "time": -1}, [0.0, 0.0, 0.0], {
        '"(bed|open)_walls"': {"type": "noSlip"}, '"(bed|open)_x(lo|hi)"': cyclic})
    _write_field(case_dir, "p", {"length": 2, "time": -2}, 0.0, {
        '"(bed|open)_walls"': {"type": "zeroGradient"}, '"(bed|open)_x(lo|hi)"': cyclic})
    air = _solve(case_dir, runner, zones, fraction, rho, mu, timeout)
    c, v, u = air.cells["C"], air.cells["V"], air.cells["U"][:, 0]
    bed_cells = c[:, 2] < half
    bed_flow = float(np.sum(u[bed_cells] * v[bed_cells]) / length)
    open_flow = float(np.sum(u[~bed_cells] * v[~bed_cells]) / length)
    return SplitRun(air, gradient, bed_flow, open_flow, bed.voidage(*slab), slab,
                    (length, width, half))


def bed_flow_split_check(run: SplitRun) -> Check:
    """Check b: the bed half's share of the flow against the parallel-resistance solution."""
    rho, mu = run.air.density, run.air.viscosity
    length, width, half = run.duct
    q_open = rectangular_duct_flow(run.gradient, mu, width, half)
    u_bed = ergun_velocity(run.gradient, run.voidage, DIAMETER, rho, mu)
    q_bed = u_bed * width * half
    expected = q_bed / (q_bed + q_open)
    measured = run.bed_flow / (run.bed_flow + run.open_flow)
    return Check(
        name="porous_bed_flow_split",
        measured=measured,
        expected=expected,
        error=relative_error(measured, expected),
        tolerance=FLOW_SPLIT_TOLERANCE,
        unit="of the flow",
        note=f"periodic duct {width * 1e3:g} mm wide, lower {half * 1e3:g} mm the LIGGGHTS bed "
        f"(voidage {run.voidage:.4f}), upper half open, split by a baffle; driven by "
        f"G = {run.gradient:.4g} Pa/m; {len(run.air.cells['V'])} cells, {len(run.air.zones.cells)} "
        "porosity zones",
        reference="parallel resistance at the same G: White (2006) Eq. 3-48 laminar rectangular "
        "duct for the open half, Ergun (1952) for the bed at its exact mean voidage",
        wall_time_s=run.air.wall_time_s,
        details={
            "open_flow_cfd_m3_s": run.open_flow,
            "open_flow_reference_m3_s": q_open,
            "open_flow_error": relative_error(run.open_flow, q_open),
            "bed_flow_cfd_m3_s": run.bed_flow,
            "bed_flow_reference_m3_s": q_bed,
            "iterations": run.air.iterations,
            "binning": run.air.zones.binning_error(),
        },
    )


def porous_bed_checks(work: Path, runner: Runner) -> list[Check]:
    """Pour the bed once, then checks a and c (one run), a at Re_p 120, and b."""
    t0 = time.perf_counter()
    bed = pour_bed(work / "bed", runner)
    column = run_bed_column(work, runner, bed)
    inertial = run_bed_column(work, runner, bed, reynolds=INERTIAL_REYNOLDS)
    split = run_flow_split(work, runner, bed)
    checks = [bed_pressure_drop_check(column), bed_pressure_drop_check(inertial),
              bed_flow_split_check(split), bed_momentum_check(column)]
    for check in checks:
        check.details["bed_pour_wall_time_s"] = bed.wall_time_s
    checks[0].details["total_wall_time_s"] = time.perf_counter() - t0
    return checks
