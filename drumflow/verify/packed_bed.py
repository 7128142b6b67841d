"""The packed bed of the porous-bed verification (:mod:`drumflow.verify.porous_bed`).

:func:`pour_bed` pours 1856 spheres of 4 mm into a square section 10 d wide, periodic on its
four sides (x and y), onto a floor, and lets them settle under gravity (LIGGGHTS, Hertz
contacts, friction 0.5): a random loose packing of voidage about 0.41 away from the floor.
:class:`PackedBed` gives the exact voidage between two planes from the sphere positions.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from drumflow.air.solids_fraction import slab_sphere_volume
from drumflow.errors import SolverError
from drumflow.runner import Runner

__all__ = ["DIAMETER", "PARTICLE_DENSITY", "WIDTH_DIAMETERS", "PackedBed", "pour_bed"]

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
