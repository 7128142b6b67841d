"""Two-way momentum through a local solids fraction: air through and past a LIGGGHTS-packed
bed, solved by OpenFOAM v1912 ``porousSimpleFoam``, against independent references.

The bed
-------
:func:`~drumflow.verify.packed_bed.pour_bed` pours 1856 spheres of 4 mm into a square section
10 d wide, periodic on its four sides (x and y), onto a floor, and lets them settle under
gravity (LIGGGHTS, Hertz contacts, friction 0.5): a random loose packing of voidage about 0.41
away from the floor. The section is periodic, not walled, because walls pack a layer of voidage ~0.5 that
carries more than its share of air (wall channelling); Ergun's constants were fitted to data
corrected for it, so a walled bed would test the wall effect, not the law.

The air model
-------------
The spheres are deposited on the air grid (cells of 2 d, :mod:`drumflow.air.solids_fraction`,
one 1-2-1 smoothing pass), the cells are binned into porosity zones (``topoSet``
``cellZoneSet`` from cell lists) whose Darcy-Forchheimer coefficients come from Ergun's law at
the cell's voidage, and ``porousSimpleFoam`` (laminar, SIMPLE) solves the superficial velocity
(the cases are written by :mod:`drumflow.verify.porous_foam`).

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

import numpy as np
from scipy.optimize import brentq

from drumflow.air.foam_case import write_field, write_porosity
from drumflow.air.solids_fraction import (
    ERGUN,
    ErgunLaw,
    RectilinearGrid,
    bin_coefficients,
    deposit_solids_fraction,
    smooth_deposition,
)
from drumflow.physics.validation import relative_error
from drumflow.runner import Runner
from drumflow.verify.checks import Check
from drumflow.verify.packed_bed import DIAMETER, WIDTH_DIAMETERS, PackedBed, pour_bed
from drumflow.verify.porous_foam import (
    AirOfBed,
    air_at,
    cell_order,
    fresh_case,
    solve_bed_air,
    write_block_mesh,
    write_numerics,
)

#: Air cell size in particle diameters: 2 d cells hold ~9 spheres, so the deposited fraction
#: scatters by 0.027 from cell to cell (measured), 0.008 after the smoothing pass.
CELL_DIAMETERS = 2
#: Porosity zones: bins of equal width in ln d; each zone gets the volume-mean of its
#: cells' coefficients (:func:`~drumflow.air.solids_fraction.bin_coefficients`).
BINS = 16
#: Particle Reynolds numbers rho U d / mu of the flow up through the bed. At 20 (checks a and
#: c) the viscous term is 72 % of Ergun's gradient, at 120 (check a at the inertial end) the
#: inertial one is 66 %: a 10 % change of either constant then moves one of the two gradients
#: by more than the tolerance (a change of B alone moves the first by only 2.8 %).
BED_REYNOLDS = 20.0
INERTIAL_REYNOLDS = 120.0

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
    fresh_case(case_dir)
    write_block_mesh(case_dir, [{"lower": [0.0, 0.0, bottom],
                            "upper": [bed.width, bed.width, float(grid.edges[2][-1])],
                            "cells": grid.shape, "prefix": "", "cyclic_x": True, "cyclic_y": True,
                            "z_patches": ("inlet", "outlet")}])
    from drumflow.air.mesh import run_foam

    write_numerics(case_dir, mu / rho, reference_cell=False)
    run_foam(runner, "blockMesh", [], case_dir, timeout=timeout)
    centres = cell_order(case_dir, runner, timeout)
    fraction = grid.flatten(deposition.fraction)[grid.locate(centres)]
    volumes = grid.flatten(grid.cell_volumes)[grid.locate(centres)]
    zones = bin_coefficients(fraction, volumes, d, bins=bins, law=law)
    write_porosity(case_dir, zones, "porosityProperties")
    cyclic = {"type": "cyclic"}
    write_field(case_dir, "U", {"length": 1, "time": -1}, [0.0, 0.0, velocity], {
        "inlet": {"type": "fixedValue", "value": [0.0, 0.0, velocity]},
        "outlet": {"type": "zeroGradient"},
        '"(x|y)(lo|hi)"': cyclic,
    })
    write_field(case_dir, "p", {"length": 2, "time": -2}, 0.0, {
        "inlet": {"type": "zeroGradient"},
        "outlet": {"type": "fixedValue", "value": 0.0},
        '"(x|y)(lo|hi)"': cyclic,
    })
    air = solve_bed_air(case_dir, runner, zones, fraction, rho, mu, timeout)
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
    fresh_case(case_dir)
    if baffle:
        write_block_mesh(case_dir, [
            {"lower": [0.0, 0.0, 0.0], "upper": [length, width, half], "cells": grid.shape,
             "prefix": "bed_", "cyclic_x": True},
            {"lower": [0.0, 0.0, half], "upper": [length, width, 2.0 * half], "cells": open_cells,
             "prefix": "open_", "cyclic_x": True},
        ])
    else:
        nz_bed, nz = grid.shape[2], grid.shape[2] + open_cells[2]
        write_block_mesh(case_dir, [
            {"lower": [0.0, 0.0, 0.0], "upper": [length, width, 2.0 * half],
             "cells": (n, n_across, nz), "prefix": "bed_", "cyclic_x": True,
             "grading": f"simpleGrading (1 1 ((0.5 {nz_bed / nz:.12g} 1) (0.5 {1 - nz_bed / nz:.12g} 1)))"},
        ])
    from drumflow.air.mesh import run_foam

    write_numerics(case_dir, mu / rho, reference_cell=True, source=gradient / rho)
    run_foam(runner, "blockMesh", [], case_dir, timeout=timeout)
    centres = cell_order(case_dir, runner, timeout)
    in_bed = centres[:, 2] < half
    index = grid.locate(centres)
    fraction = np.where(in_bed, grid.flatten(deposition.fraction)[np.clip(index, 0, None)], 0.0)
    cell_volumes = np.full(len(centres), 0.0)
    cell_volumes[in_bed] = grid.flatten(grid.cell_volumes)[index[in_bed]]
    cell_volumes[~in_bed] = length * width * half / np.prod(open_cells)
    zones = bin_coefficients(fraction, cell_volumes, d, bins=bins, law=law)
    write_porosity(case_dir, zones, "porosityProperties")
    cyclic = {"type": "cyclic"}
    write_field(case_dir, "U", {"length": 1, "time": -1}, [0.0, 0.0, 0.0], {
        '"(bed|open)_walls"': {"type": "noSlip"}, '"(bed|open)_x(lo|hi)"': cyclic})
    write_field(case_dir, "p", {"length": 2, "time": -2}, 0.0, {
        '"(bed|open)_walls"': {"type": "zeroGradient"}, '"(bed|open)_x(lo|hi)"': cyclic})
    air = solve_bed_air(case_dir, runner, zones, fraction, rho, mu, timeout)
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
