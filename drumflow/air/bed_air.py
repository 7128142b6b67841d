"""The drum's air with a bed state's particles as Ergun porosity, solved once on a frozen
snapshot, and what the bed and the curtains do to it (a measurement tool; re-solving inside the
coupling loop is not built). The page ``docs/air-around-the-bed.md`` tells the whole story.

Solved: the air stage's drum case (:func:`drumflow.air.foam.solve_air`: gmsh mesh, simpleFoam,
MRF about +z) twice on one mesh, empty and with the bed as Darcy-Forchheimer cellZones
(``explicitPorositySource`` in ``system/fvOptions``), the latter from the empty solution with
plain SIMPLE (SIMPLEC's residuals stall with porosity in this build).

Particles to cells: positions turned into the mesh's drum frame by the state's drum angle
(:func:`drumflow.physics.drum_frame.rotate_to_drum_frame`); the spheres (a coarse-grained
case's parcels: k^3 granules' volume each) deposited conservatively on a
:class:`~drumflow.air.solids_fraction.RectilinearGrid` of spacing h, smoothed by one 1-2-1 pass
per axis (smoothing length, a standard deviation, of h sqrt(1/2)), divided by the air volume of
each grid cell (the cross-section sampled for shell and lifters, smoothed alike); each mesh
cell takes the fraction of the grid cell holding its centre. Ergun's law at each cell's
voidage with the *granule* diameter (``particles.diameter``) gives its d and f; cells below
:data:`POROUS_FRACTION` get none; the rest are binned into zones (:func:`porosity_zones`).

Stated limitation: stock ``explicitPorositySource`` adds ``-(mu d + rho |U| f / 2) U`` with U
the *absolute* air velocity; it cannot take U - v_particle. The bed is treated as solids at
rest in the lab: its motion with the wall is left out of its drag. The axial drag is
unaffected (the particles move little along the axis).

Measured, empty and bed, with cells sorted into bed (solids fraction >= :data:`BED_FRACTION`),
curtain (>= :data:`CURTAIN_FRACTION`) and free air: (a) the axial flow each carries through the
mid section (:func:`section_flow`); (b) the air crossing into the curtain cells from free air
and into the bed cells from the rest, per metre of drum (:func:`inflow_into`, absolute and
drum-frame face fluxes); (c) the volume-weighted mean |U|; (d) the inlet-outlet pressure drop
(face-area means of the static pressure; the inlet's zeroGradient faces take their cells').
"""

from __future__ import annotations

import csv
import json
import math
import shutil
import time
from collections.abc import Callable
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any, Literal, Protocol

import numpy as np
from numpy.typing import NDArray

from drumflow.air.poly_mesh import PolyMesh, read_poly_mesh
from drumflow.air.solids_fraction import (
    ERGUN,
    ErgunLaw,
    PorosityZones,
    RectilinearGrid,
    bin_coefficients,
    deposit_solids_fraction,
    smooth_deposition,
)
from drumflow.errors import AnalysisInputError, MeshCheckError

if TYPE_CHECKING:
    from drumflow.air.foam_results import AirSolution
    from drumflow.case import Case
    from drumflow.runner import Runner

__all__ = ["BED_FRACTION", "CURTAIN_FRACTION", "POROUS_FRACTION", "AirMeasure", "BedAirResult",
           "BedSnapshot", "CellDeposit", "PolyMesh", "categorize", "deposit_on_cells", "deposit_state",
           "inflow_into", "measure_air", "porosity_zones", "read_poly_mesh", "section_flow", "solve_bed_air",
           "write_bed_air"]

#: Cells with at least this solids fraction are bed cells.
BED_FRACTION = 0.3
#: Cells with at least this (and less than :data:`BED_FRACTION`) are curtain cells.
CURTAIN_FRACTION = 0.003
#: Cells with less solids than this get no porosity.
POROUS_FRACTION = 1e-3
#: Solids fractions binned apart (:func:`porosity_zones`).
ZONE_DECADES = (POROUS_FRACTION, 0.01, 0.1, BED_FRACTION, 1.0)
#: 1-2-1 smoothing passes per axis of the deposition.
SMOOTHING_PASSES = 1
CATEGORIES = ("bed", "curtain", "free")
#: How the air meets the slice's ends: a piece of a long drum (:mod:`drumflow.air.periodic`,
#: the plant's question) or the case's inlet and outlet (the paper's set-up).
Axial = Literal["periodic", "inlet-outlet"]
AXIAL_MODES: tuple[str, ...] = ("periodic", "inlet-outlet")
#: SIMPLE iteration limit of the periodic solves when the case allows fewer: periodic air
#: converges slowly (the smoke drum's bed case took 1,672 iterations to 1e-4, the inlet-outlet
#: one 538; docs/air-around-the-bed.md), and stopping early is not an option.
PERIODIC_MAX_ITERATIONS = 6000
_FIELDS = ("U", "p", "k", "epsilon", "nut")


class BedSnapshot(Protocol):
    """What a bed state gives (:class:`drumflow.dem.state.StartState` is one)."""

    @property
    def positions(self) -> NDArray[np.float64]: ...  # (n, 3), m, lab frame
    @property
    def radii(self) -> NDArray[np.float64]: ...  # (n,), m
    @property
    def time_s(self) -> float: ...
    @property
    def drum_angle_rad(self) -> float: ...
    @property
    def source(self) -> str: ...
    def __len__(self) -> int: ...


@dataclass(frozen=True)
class CellDeposit:
    """A bed's solids on the mesh cells.

    Attributes
    ----------
    fraction
        Solids volume fraction per mesh cell.
    spacing_m, smoothing_length_m
        The grid's cell size and the smoothing kernel's standard deviation along x, y, z, m.
    particles_volume_m3, grid_volume_m3, outside_m3, cells_volume_m3, unmapped_m3
        The particles' (parcels') total volume; deposited on the grid; fallen outside it; on
        the mesh cells (sum of fraction x volume); in grid cells holding no mesh-cell centre.
    """

    fraction: NDArray[np.float64] = field(repr=False)
    spacing_m: tuple[float, float, float]
    smoothing_length_m: tuple[float, float, float]
    particles_volume_m3: float
    grid_volume_m3: float
    outside_m3: float
    cells_volume_m3: float
    unmapped_m3: float

    def summary(self) -> dict[str, Any]:
        out = {k: v for k, v in asdict(self).items() if k != "fraction"}
        out["cells_over_particles"] = self.cells_volume_m3 / self.particles_volume_m3
        out["max_fraction"] = float(self.fraction.max()) if len(self.fraction) else 0.0
        return out


def deposit_on_cells(
    centres: NDArray[np.float64],
    volumes: NDArray[np.float64],
    positions: NDArray[np.float64],
    radii: NDArray[np.float64],
    lower: NDArray[np.float64],
    upper: NDArray[np.float64],
    spacing: float,
    fluid_xy: Callable[[NDArray[np.float64], NDArray[np.float64]], NDArray[np.bool_]] | None = None,
    periodic_z: bool = False,
    passes: int = SMOOTHING_PASSES,
) -> CellDeposit:
    """Deposit spheres on a grid of about ``spacing`` (m) over the box ``lower``..``upper`` and
    give each mesh cell (``centres``, ``volumes``) its grid cell's solids fraction (see the
    module docstring). ``fluid_xy(x, y)`` tells air from metal in the cross-section (the
    section is a prism along z); ``None``: the whole box is air.
    """
    grid = deposition_grid(lower, upper, spacing, periodic_z)
    cells = grid.shape
    raw = deposit_solids_fraction(grid, positions, radii)
    solids = smooth_deposition(raw, passes)
    where = grid.locate(centres)
    if np.any(where < 0):
        raise AnalysisInputError("mesh cell centres", int(np.sum(where < 0)),
                                 "all inside the deposition grid's box")
    n = int(np.prod(grid.shape))
    air = grid.cell_volumes * _air_share(grid, fluid_xy)[:, :, None]
    fluid = smooth_deposition(type(raw)(grid, air, 0.0, 0.0, raw.resolution), passes)
    solid_flat = grid.flatten(solids.volume)
    fluid_flat = grid.flatten(fluid.volume)
    grid_fraction = np.divide(solid_flat, fluid_flat, out=np.zeros(n), where=fluid_flat > 0)
    fraction = grid_fraction[where]
    held = np.bincount(where, minlength=n) > 0
    h = tuple(float(grid.edges[a][-1] - grid.edges[a][0]) / cells[a] for a in range(3))
    return CellDeposit(
        fraction=fraction,
        spacing_m=(h[0], h[1], h[2]),
        smoothing_length_m=tuple(x * math.sqrt(passes / 2.0) for x in h),  # type: ignore[arg-type]
        particles_volume_m3=raw.spheres_volume,
        grid_volume_m3=float(raw.volume.sum()),
        outside_m3=raw.outside,
        cells_volume_m3=float(np.sum(fraction * volumes)),
        unmapped_m3=float(solid_flat[~held].sum()),
    )


def deposition_grid(lower: NDArray[np.float64], upper: NDArray[np.float64], spacing: float,
                    periodic_z: bool = False) -> RectilinearGrid:
    """The deposition grid over the box ``lower``..``upper``: cells of about ``spacing`` (m),
    at least one per axis, periodic along z if asked (what the particles are put on)."""
    if not spacing > 0.0 or not math.isfinite(spacing):
        raise AnalysisInputError("spacing", spacing, "a finite length > 0 (m)")
    lo, hi = np.asarray(lower, float), np.asarray(upper, float)
    cells = tuple(max(1, int((hi[a] - lo[a]) // spacing)) for a in range(3))
    return RectilinearGrid.uniform(lo, hi, (cells[0], cells[1], cells[2]),
                                   periodic=(False, False, periodic_z))


def _air_share(grid: RectilinearGrid, fluid_xy: Callable[..., NDArray[np.bool_]] | None,
               samples: int = 8) -> NDArray[np.float64]:
    """Share of each (x, y) column of grid cells that is air, from ``samples``^2 points each."""
    nx, ny, _ = grid.shape
    if fluid_xy is None:
        return np.ones((nx, ny))
    ex, ey = grid.edges[0], grid.edges[1]
    u = (np.arange(samples) + 0.5) / samples
    x = (ex[:-1, None] + np.diff(ex)[:, None] * u[None, :]).ravel()
    y = (ey[:-1, None] + np.diff(ey)[:, None] * u[None, :]).ravel()
    X, Y = np.meshgrid(x, y, indexing="ij")
    inside = np.asarray(fluid_xy(X, Y), float).reshape(nx, samples, ny, samples)
    return np.asarray(inside.mean(axis=(1, 3)), float)


def categorize(fraction: NDArray[np.float64]) -> NDArray[np.int64]:
    """0 bed, 1 curtain, 2 free air (the order of :data:`CATEGORIES`)."""
    phi = np.asarray(fraction, float)
    return np.where(phi >= BED_FRACTION, 0, np.where(phi >= CURTAIN_FRACTION, 1, 2))


def inflow_into(
    owner: NDArray[np.int64],
    neighbour: NDArray[np.int64],
    flux: NDArray[np.float64],
    target: NDArray[np.bool_],
    source: NDArray[np.bool_],
) -> float:
    """Sum over internal faces between a ``target`` and a ``source`` cell of the flux into the
    target cell, m^3/s (``flux`` per internal face, positive from owner to neighbour)."""
    o, n = owner[: len(neighbour)], neighbour
    q = np.asarray(flux, float)[: len(neighbour)]
    into_n = target[n] & source[o]
    into_o = target[o] & source[n]
    return float(np.sum(np.maximum(q[into_n], 0.0)) + np.sum(np.maximum(-q[into_o], 0.0)))


def section_flow(
    owner: NDArray[np.int64],
    neighbour: NDArray[np.int64],
    flux: NDArray[np.float64],
    centres_z: NDArray[np.float64],
    z: float,
    category: NDArray[np.int64],
) -> dict[str, float]:
    """Volume flow along -z (the air's direction) through the cross-section at ``z``, m^3/s,
    split by cell category (module docstring, (a)).

    The section is the surface of internal faces between cells whose centres lie above ``z``
    and cells whose centres lie below: it spans the whole cross-section, so by continuity it
    carries exactly the inlet's flow. A face's flux counts half to each of its two cells'
    categories.
    """
    o, n = owner[: len(neighbour)], neighbour
    below = np.asarray(centres_z) < z
    q = np.asarray(flux, float)[: len(neighbour)]
    down = below[n] & ~below[o]
    up = below[o] & ~below[n]
    faces = np.flatnonzero(down | up)
    # Flux from the upper cell to the lower one: phi runs from owner to neighbour.
    q_down = np.where(down[faces], q[faces], -q[faces])
    out = {name: 0.0 for name in CATEGORIES}
    for cells in (o[faces], n[faces]):
        for i, name in enumerate(CATEGORIES):
            out[name] += 0.5 * float(np.sum(q_down[category[cells] == i]))
    out["total"] = float(np.sum(q_down))
    return out


@dataclass(frozen=True)
class AirMeasure:
    """What one air solution does at the bed and the curtains (module docstring (a)-(d))."""

    axial_flow_m3_s: dict[str, float]
    inflow_m3_s_m: dict[str, float]
    inflow_drum_frame_m3_s_m: dict[str, float]
    mean_speed_m_s: dict[str, float]
    pressure_drop_Pa: float
    pressure_gradient_Pa_m: float
    inlet_flow_m3_s: float
    iterations: int
    wall_time_s: float


def _patch_mean(mesh: PolyMesh, values: NDArray[np.float64], cells: NDArray[np.float64],
                name: str) -> float:
    s = mesh.patch_faces(name)
    area = np.linalg.norm(mesh.face_areas[s], axis=1)
    face = values if len(values) == len(area) else cells[mesh.owner[s]]
    return float(np.sum(face * area) / np.sum(area))


def measure_air(case_dir: Path, time_dir: str, mesh: PolyMesh, category: NDArray[np.int64],
                omega: float, density: float, iterations: int, wall_time_s: float,
                periodic: bool = False) -> AirMeasure:
    """Read one solution (U, p, phi, cell volumes) and measure it (module docstring). The
    pressure drop over the slice: the inlet-outlet difference, or periodic the gradient that
    ``meanVelocityForce`` applied times the slice's length."""
    from foamlib import FoamFieldFile

    from drumflow.air.foam_results import patch_flux, read_cell_fields

    cells = read_cell_fields(case_dir, time_dir)
    length = float(mesh.bounds[1][2] - mesh.bounds[0][2])
    phi = np.asarray(FoamFieldFile(case_dir / time_dir / "phi").internal_field, float).ravel()
    ni = len(mesh.neighbour)
    xf = mesh.face_centres[:ni]
    swirl = np.column_stack([-omega * xf[:, 1], omega * xf[:, 0], np.zeros(ni)])
    absolute = phi + np.einsum("ij,ij->i", swirl, mesh.face_areas[:ni])
    masks = {name: category == i for i, name in enumerate(CATEGORIES)}
    flows = section_flow(mesh.owner, mesh.neighbour, phi, cells["C"][:, 2],
                         0.5 * float(mesh.bounds[0][2] + mesh.bounds[1][2]), category)
    inflows: dict[str, dict[str, float]] = {}
    for label, flux in (("absolute", absolute), ("drum", phi)):
        inflows[label] = {
            "curtain_from_free": inflow_into(mesh.owner, mesh.neighbour, flux, masks["curtain"],
                                             masks["free"]) / length,
            "bed_from_other": inflow_into(mesh.owner, mesh.neighbour, flux, masks["bed"],
                                          ~masks["bed"]) / length,
        }
    speed = np.linalg.norm(cells["U"], axis=1)
    mean = {name: float(np.average(speed[m], weights=cells["V"][m])) if m.any() else float("nan")
            for name, m in masks.items()}
    if periodic:
        from drumflow.air.periodic import read_pressure_gradient

        drop = density * read_pressure_gradient(case_dir, time_dir) * length
    else:
        boundary: Any = FoamFieldFile(case_dir / time_dir / "p").boundary_field
        p_face = {name: np.asarray(boundary[name].get("value", []), float).ravel()
                  for name in ("inlet", "outlet")}
        drop = density * (_patch_mean(mesh, p_face["inlet"], cells["p"], "inlet")
                          - _patch_mean(mesh, p_face["outlet"], cells["p"], "outlet"))
    return AirMeasure(flows, inflows["absolute"], inflows["drum"], mean, drop, drop / length,
                      -patch_flux(case_dir, time_dir, "inlet"), iterations, wall_time_s)


@dataclass(frozen=True)
class BedAirResult:
    """Empty and bed air of one state on the same mesh, and how the bed was made."""

    case_name: str
    axial: str
    state: dict[str, Any]
    cells: int
    category_cells: dict[str, int]
    category_volume_m3: dict[str, float]
    deposit: dict[str, Any]
    zones: dict[str, float]
    granule_diameter_m: float
    empty: AirMeasure
    bed: AirMeasure
    wall_time_s: float
    fields: dict[str, NDArray[np.float64]] = field(repr=False, default_factory=dict)
    # The two OpenFOAM solutions (their case folders), for a caller that resamples the bed's
    # field (drumflow.air.bed_phases) or solves another state from the same empty drum.
    empty_solution: AirSolution | None = field(repr=False, default=None, compare=False)
    bed_solution: AirSolution | None = field(repr=False, default=None, compare=False)

    def as_dict(self) -> dict[str, Any]:
        out = asdict(self)
        for name in ("fields", "empty_solution", "bed_solution"):
            out.pop(name)
        out["thresholds"] = {"bed_fraction": BED_FRACTION, "curtain_fraction": CURTAIN_FRACTION,
                             "porous_fraction": POROUS_FRACTION}
        return out

    def rows(self) -> list[dict[str, Any]]:
        """One row per (solution, quantity, category): the table of ``split.csv``."""
        rows: list[dict[str, Any]] = []
        for label, m in (("empty", self.empty), ("bed", self.bed)):
            for quantity, unit, values in (
                    ("axial_flow", "m3/s", m.axial_flow_m3_s),
                    ("inflow", "m3/s/m", m.inflow_m3_s_m),
                    ("inflow_drum_frame", "m3/s/m", m.inflow_drum_frame_m3_s_m),
                    ("mean_speed", "m/s", m.mean_speed_m_s),
                    ("pressure_drop", "Pa", {"over_slice": m.pressure_drop_Pa}),
                    ("pressure_gradient", "Pa/m", {"axial": m.pressure_gradient_Pa_m})):
                rows += [{"solution": label, "quantity": quantity, "part": k, "value": v,
                          "unit": unit} for k, v in values.items()]
        return rows


def porosity_zones(fraction: NDArray[np.float64], volumes: NDArray[np.float64], diameter: float,
                   law: ErgunLaw = ERGUN, bins: int = 16) -> PorosityZones:
    """Ergun porosity zones of the cells with at least :data:`POROUS_FRACTION` solids, granule
    ``diameter`` in m: :func:`~drumflow.air.solids_fraction.bin_coefficients` with ``bins``
    zones in each decade of solids fraction (:data:`ZONE_DECADES`). One call over the whole
    drum would put every cell resisting less than 1 % of the densest one (the curtains and the
    bed's fringe, some 10^5 times apart in d) into one zone whose mean is its densest cells'.
    """
    phi = np.where(fraction >= POROUS_FRACTION, fraction, 0.0)
    if np.any(phi >= 1.0):
        raise AnalysisInputError("grid spacing (a mesh cell's solids fraction)",
                                 float(phi.max()), "a fraction < 1: use a coarser grid")
    cell_d, cell_f = np.zeros_like(phi), np.zeros_like(phi)
    cells: list[NDArray[np.int64]] = []
    d: list[float] = []
    f: list[float] = []
    for lo, hi in zip(ZONE_DECADES[:-1], ZONE_DECADES[1:], strict=True):
        part = np.where((phi >= lo) & (phi < hi), phi, 0.0)
        if not part.any():
            continue
        z = bin_coefficients(part, volumes, diameter, bins=bins, law=law)
        cells += z.cells
        d += list(z.d)
        f += list(z.f)
        cell_d += z.cell_d
        cell_f += z.cell_f
    return PorosityZones(cells, np.array(d), np.array(f), cell_d, cell_f)


def deposit_state(case: Case, state: BedSnapshot, mesh: PolyMesh,
                  cells: dict[str, NDArray[np.float64]], spacing: float | None = None,
                  ) -> CellDeposit:
    """``state``'s solids on the air mesh's cells (``cells``: centres ``C``, volumes ``V``),
    in the drum's frame, at ``spacing`` (default: the larger of two parcel diameters and the
    air mesh size), periodic along the axis when the drum's ends are."""
    from drumflow.air.field_grid import fluid_mask_xy
    from drumflow.geometry.fluid import fluid_mesh_size
    from drumflow.physics.drum_frame import rotate_to_drum_frame

    h = spacing if spacing is not None else max(4.0 * float(state.radii.max()),
                                                fluid_mesh_size(case))
    positions = rotate_to_drum_frame(state.positions, state.drum_angle_rad)
    return deposit_on_cells(cells["C"], cells["V"], positions, state.radii, mesh.bounds[0],
                            mesh.bounds[1], h, lambda x, y: fluid_mask_xy(case, x, y),
                            periodic_z=case.drum.ends == "periodic")


def solve_bed_air(
    case: Case,
    state: BedSnapshot,
    workdir: Path,
    runner: Runner,
    *,
    spacing: float | None = None,
    processes: int = 1,
    timeout: float | None = 7200.0,
    law: ErgunLaw = ERGUN,
    axial: Axial = "periodic",
    empty: AirSolution | None = None,
) -> BedAirResult:
    """Solve the drum's air empty and with ``state``'s particles as porosity; measure both.

    Parameters
    ----------
    case, state
        The case and a bed state of its scene (checked by the caller:
        :func:`drumflow.dem.state.check_state`).
    workdir, runner
        Where the two OpenFOAM cases go (``empty/``, ``bed/``); what starts every program.
    spacing, law
        Deposition grid size, m (default: the larger of two parcel diameters and the air
        mesh size); the Ergun constants.
    processes, timeout
        MPI ranks for simpleFoam; limit per OpenFOAM program, s.
    axial
        ``"periodic"`` (default): the slice as a piece of a long drum at the case's mean air
        velocity (:mod:`drumflow.air.periodic`; at least :data:`PERIODIC_MAX_ITERATIONS`
        SIMPLE iterations allowed); ``"inlet-outlet"``: the case's own ends.
    empty
        The empty drum's solution of an earlier call with the same case and ``axial`` (its
        ``empty_solution``): not solved again.

    Raises
    ------
    drumflow.errors.SolverError
        An OpenFOAM program failed, or simpleFoam did not converge.
    drumflow.errors.AnalysisInputError
        A grid spacing that fills a cell with solids.
    """
    from drumflow.air.foam import solve_air
    from drumflow.air.foam_case import air_properties_for, write_fv_solution, write_porosity
    from drumflow.air.foam_results import read_cell_fields
    from drumflow.air.mesh import run_foam

    if axial not in AXIAL_MODES:
        raise AnalysisInputError("axial", axial, f"one of {', '.join(AXIAL_MODES)}")
    periodic = axial == "periodic"
    if periodic and case.air.max_iterations < PERIODIC_MAX_ITERATIONS:
        case = case.model_copy(update={"air": case.air.model_copy(
            update={"max_iterations": PERIODIC_MAX_ITERATIONS})})
    t0 = time.perf_counter()
    workdir = Path(workdir)
    if empty is None:
        empty = solve_air(case, workdir / "empty", runner, processes=processes, timeout=timeout,
                          periodic=periodic)
    mesh = read_poly_mesh(empty.case_dir)
    cells = read_cell_fields(empty.case_dir, empty.time_dir)
    deposit = deposit_state(case, state, mesh, cells, spacing)
    rho, nu = air_properties_for(case)
    diameter = case.particles.diameter
    zones = porosity_zones(deposit.fraction, cells["V"], diameter, law)
    points = empty.case_dir / "constant" / "polyMesh" / "points"
    fields = ["p", "U"] + ([] if case.air.turbulence == "laminar" else ["k", "epsilon"])

    def prepare(bed_dir: Path) -> None:
        if (bed_dir / "constant" / "polyMesh" / "points").read_bytes() != points.read_bytes():
            raise MeshCheckError("gmsh", ["gmshToFoam"], 0, bed_dir / "log.gmshToFoam",
                                 reason=f"the bed case's mesh ({bed_dir}) differs from the empty "
                                 f"drum's ({empty.case_dir}); the cells cannot be matched")
        for name in _FIELDS:
            source = empty.case_dir / empty.time_dir / name
            if source.exists():
                shutil.copyfile(source, bed_dir / "0" / name)
        write_porosity(bed_dir, zones, "fvOptions")
        # Plain SIMPLE: with porosity SIMPLEC's residuals stall in this build (a drum full of
        # porosity: p at 8e-3 for 2000 iterations; SIMPLE converged in 133, same gradient).
        write_fv_solution(bed_dir, case.air.residual_target, fields, consistent=False)
        run_foam(runner, "topoSet", [], bed_dir, timeout=timeout)

    bed = solve_air(case, workdir / "bed", runner, processes=processes, timeout=timeout,
                    prepare=prepare, periodic=periodic)
    category = categorize(deposit.fraction)
    measures = [measure_air(s.case_dir, s.time_dir, mesh, category, case.drum.omega, rho,
                            s.iterations, s.wall_time_s, periodic) for s in (empty, bed)]
    bed_cells = read_cell_fields(bed.case_dir, bed.time_dir)
    return BedAirResult(
        case_name=case.name,
        axial=axial,
        state={"time_s": state.time_s, "drum_angle_rad": state.drum_angle_rad,
               "particles": len(state), "parcel_diameter_m": 2.0 * float(state.radii.max()),
               "source": state.source},
        cells=len(category),
        category_cells={c: int(np.sum(category == i)) for i, c in enumerate(CATEGORIES)},
        category_volume_m3={c: float(cells["V"][category == i].sum())
                            for i, c in enumerate(CATEGORIES)},
        deposit=deposit.summary(),
        zones={**zones.binning_error(cells["V"]), "dynamic_viscosity_Pa_s": rho * nu},
        granule_diameter_m=diameter,
        empty=measures[0],
        bed=measures[1],
        wall_time_s=time.perf_counter() - t0,
        fields={"C": cells["C"], "fraction": deposit.fraction, "U_empty": cells["U"],
                "U_bed": bed_cells["U"]},
        empty_solution=empty,
        bed_solution=bed,
    )


def write_bed_air(result: BedAirResult, out: Path, slab: float | None = None) -> list[Path]:
    """``split.json``, ``split.csv`` and ``cross_section.png`` in ``out``; return the paths.

    The picture shows the cells whose centres lie within ``slab`` / 2 of the mid plane (default
    a tenth of the slice length or more, so that a layer of cells shows): solids fraction,
    and the axial air speed (-U_z) empty and with the bed.
    """
    from drumflow._mpl import pyplot

    out.mkdir(parents=True, exist_ok=True)
    paths = [out / "split.json", out / "split.csv", out / "cross_section.png"]
    paths[0].write_text(json.dumps(result.as_dict(), indent=2, default=float) + "\n")
    with paths[1].open("w", newline="") as fh:
        writer = csv.DictWriter(fh, fieldnames=["solution", "quantity", "part", "value", "unit"])
        writer.writeheader()
        writer.writerows(result.rows())
    C = result.fields["C"]
    z0, z1 = float(C[:, 2].min()), float(C[:, 2].max())
    width = slab if slab is not None else max(0.1 * (z1 - z0), 1.5 * result.deposit["spacing_m"][2])
    near = np.abs(C[:, 2] - 0.5 * (z0 + z1)) <= 0.5 * width
    plt = pyplot()
    fig, axes = plt.subplots(1, 3, figsize=(13.5, 4.6), constrained_layout=True)
    uz = [-result.fields["U_empty"][near, 2], -result.fields["U_bed"][near, 2]]
    vmax = float(max(np.abs(u).max() for u in uz)) if near.any() else 1.0
    size = max(2.0, 6e4 / max(int(near.sum()), 1))
    panels = [(result.fields["fraction"][near], "solids fraction", "Greys", 0.0, 0.65),
              (uz[0], "axial air speed -U_z, empty drum (m/s)", "RdBu_r", -vmax, vmax),
              (uz[1], "axial air speed -U_z, with the bed (m/s)", "RdBu_r", -vmax, vmax)]
    for ax, (values, title, cmap, lo, hi) in zip(axes, panels, strict=True):
        sc = ax.scatter(C[near, 0], C[near, 1], c=values, s=size, cmap=cmap, vmin=lo, vmax=hi,
                        marker="s", linewidths=0)
        ax.set_aspect("equal")
        ax.set_title(title, fontsize=10)
        ax.set_xlabel("x (m, drum frame)")
        fig.colorbar(sc, ax=ax, shrink=0.8)
    axes[0].set_ylabel("y (m)")
    fig.suptitle(f"{result.case_name}: state at t = {result.state['time_s']:.3f} s, cells within "
                 f"{0.5 * width:.3g} m of the mid plane", fontsize=11)
    fig.savefig(paths[2], dpi=110)
    plt.close(fig)
    return paths
