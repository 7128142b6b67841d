"""The air's steady temperature in a solved drum case, with the particles' heat as its source:
rho c_p (div(U T) - div(D grad T)) = h a_v (T_p - T), on the case's mesh and face flux
(:mod:`drumflow.air.bed_heat` builds the sources and measures the heat).

How, and why: stock OpenFOAM v1912, nothing to compile, in a copy of the bed case (``heat/``).
``scalarTransportFoam`` hosts the run and reads the solved face flux ``phi`` (T is transported
with it, no second interpolation of U); its own ``T`` is a dummy that stays zero. The unknown,
theta = T - T_in (round-off scales with the heating), is solved by the ``scalarTransport``
function object, because that one takes the diffusivity as a *cell field* (its ``nut`` entry
names a field, read in by ``readFields``), where the solver's ``DT`` is one constant: the
mixing of a packed bed and of free turbulent air differ by orders of magnitude
(:func:`drumflow.air.bed_heat.cell_diffusivity`). With one uniform D both give the same theta to
the last digit (the smoke bed's periodic case: 748 iterations each, 2026-11-28). D is carried to
the faces harmonically (``Gauss harmonic``), the conductance of two cells in series (Patankar,
Numerical Heat Transfer and Fluid Flow, 1980, Sec. 4.2-3): a face between the bed and free air
passes what the bed's side lets through, not the mean of the two. A ``runTimeControl`` stops the
iterations when theta's initial residual is below the target.

``phi`` of an MRF solution is the flux relative to the drum, the frozen-rotor convention stock
MRF solvers transport scalars with: the bed, frozen on the cells, is swept by the air at its
velocity relative to the drum. The source is ``semiImplicitSource`` per cellZone,
S = k (theta_p - theta), k = h a_v / (rho c_p) (1/s): stock fvOptions take one value per zone,
so the cells are binned (:func:`drumflow.air.bed_heat.bin_heat_sources`); the zones are written
by :func:`~drumflow.air.foam_case.write_zone_sets`. v1912 puts ``fvm::SuSp(Sp, T)`` on the
right-hand side, making our negative Sp explicit: theta is under-relaxed (:func:`_relaxation`).
Steady, ``bounded Gauss linearUpwind`` with a cell-limited gradient: second order (the 0.03 m
smoke mesh has three or four cells along the slice; upwind would be 8 % off the plug-flow
check) and inside the sources' range (unlimited it overshot by 13 %).

Ends: a periodic flow's temperature is not periodic; the copy's cyclicAMI pair becomes plain
patches carrying phi's cyclic values, fresh air at ``inlet`` (z = l) by a Danckwerts condition
(``mixed``, value fraction u / (u + D / delta) with the owner cell's D; a fixed T_in let 9 % of
the smoke bed's heat diffuse out upstream), ``inletOutlet`` at ``outlet``, walls adiabatic.
"""

from __future__ import annotations

import math
import re
import shutil
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any, ClassVar, cast

import numpy as np
from numpy.typing import NDArray

from drumflow.air.solids_fraction import CellZones
from drumflow.errors import AnalysisInputError

if TYPE_CHECKING:
    from drumflow.runner import Runner

__all__ = ["MAX_ITERATIONS", "AirTemperature", "HeatZones", "solve_air_temperature"]

#: Outer iterations allowed before theta counts as not converged: the explicit sink needs
#: strong under-relaxation where D is small (model one's periodic bed under the local
#: diffusivity: the residual fell from 1.3e-5 to 7.9e-6 between iterations 1,390 and 1,983).
MAX_ITERATIONS = 10_000


@dataclass(frozen=True)
class HeatZones(CellZones):
    """Source cells binned: ``cells`` per zone, its ``k`` (1/s) and ``theta_p`` (K over the
    inlet); ``cell_k``, ``cell_theta_p``: the exact per-cell values."""

    cells: list[NDArray[np.int64]]
    k: NDArray[np.float64]
    theta_p: NDArray[np.float64]
    cell_k: NDArray[np.float64] = field(repr=False)
    cell_theta_p: NDArray[np.float64] = field(repr=False)

    stem: ClassVar[str] = "heat"

    def binned(self) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Each cell's zone k and theta_p (0 outside every zone)."""
        k, t = self.spread(self.cell_k, self.k, self.theta_p)
        return k, t


@dataclass(frozen=True)
class AirTemperature:
    """A solved air temperature.

    Attributes
    ----------
    theta
        Per cell, T - T_in, K.
    outlet_theta, outflow_m3_s
        Flux-weighted theta over the outlet's outflow faces, K; their flow, m^3/s.
    other_out_m3K_s
        What else leaves the ends (phi theta_f plus diffusion, less the outlet's outflow), m^3 K/s.
    iterations, relaxation, wall_time_s
        Outer iterations, the T equation's under-relaxation, the time taken (s).
    """

    theta: NDArray[np.float64] = field(repr=False)
    outlet_theta: float
    outflow_m3_s: float
    other_out_m3K_s: float
    iterations: int
    relaxation: float
    wall_time_s: float


def _decouple(heat_dir: Path) -> None:
    """The cyclicAMI pair back to plain patches (mesh, phi, U) in a copied case."""
    from foamlib import FoamFieldFile, FoamFile

    boundary = FoamFile(heat_dir / "constant" / "polyMesh" / "boundary")
    patches = cast(list[tuple[str, dict[str, Any]]], boundary[None])
    cyclic = [name for name, e in patches if e.get("type") == "cyclicAMI"]
    if not cyclic:
        return
    boundary[None] = [(name, {"type": "patch", "nFaces": e["nFaces"], "startFace": e["startFace"]}
                       if name in cyclic else e) for name, e in patches]
    for name in ("phi", "U"):
        with FoamFieldFile(heat_dir / "0" / name) as f:
            bf = cast(dict[str, Any], f.boundary_field)
            for patch in cyclic:
                value = bf[patch].get("value", 0.0 if name == "phi" else [0.0, 0.0, 0.0])
                f[("boundaryField", patch)] = {"type": "calculated", "value": value}


def solve_air_temperature(bed_dir: Path, time_dir: str, heat_dir: Path, zones: HeatZones,
                          diffusivity: float | NDArray[np.float64], runner: Runner,
                          timeout: float | None = 3600.0, residual: float = 1e-6,
                          internal_flux: NDArray[np.float64] | None = None) -> AirTemperature:
    """Copy the solved case ``bed_dir``/``time_dir`` to ``heat_dir``, write and run the
    temperature case (module docstring), and read theta, the outlet and the bookkeeping.
    ``diffusivity``: D, m^2/s, one value or one per cell. ``internal_flux``: the internal
    faces' flux to carry theta with instead of the solved ``phi``'s
    (:func:`drumflow.air.transport_flux.transport_flux`; the boundary's are kept).

    Raises
    ------
    drumflow.errors.AnalysisInputError
        A negative or non-finite D, or one per cell of another length than the mesh's cells.
    drumflow.errors.SolverError
        topoSet or scalarTransportFoam failed, or theta did not converge to ``residual``
        within :data:`MAX_ITERATIONS` iterations or left the range of the sources.
    """
    from foamlib import FoamFieldFile

    from drumflow.air.foam_results import latest_time, read_cell_fields
    from drumflow.air.mesh import run_foam
    from drumflow.air.poly_mesh import read_poly_mesh
    from drumflow.errors import SolverError

    given = np.asarray(diffusivity, float)
    bad = ~(np.isfinite(given) & (given >= 0.0))
    if np.any(bad):
        raise AnalysisInputError("diffusivity", float(given[bad].ravel()[0]),
                                 "finite numbers >= 0 (m^2/s)")
    n = len(zones.cell_k)
    if given.ndim > 1 or (given.ndim == 1 and len(given) != n):
        raise AnalysisInputError("diffusivity", f"{given.shape} values",
                                 f"one value or one per cell ({n})")
    d_cell = np.broadcast_to(given, (n,)).astype(float)
    t0 = time.perf_counter()
    heat_dir = Path(heat_dir)
    _copy_case(bed_dir, time_dir, heat_dir)
    mesh = read_poly_mesh(heat_dir)
    cells = read_cell_fields(bed_dir, time_dir)
    phi = FoamFieldFile(heat_dir / "0" / "phi")
    flux = np.asarray(phi.internal_field, float)
    if internal_flux is not None:
        given_flux = np.asarray(internal_flux, float)
        if given_flux.shape != flux.shape or not np.all(np.isfinite(given_flux)):
            raise AnalysisInputError("internal_flux", f"{given_flux.shape} values",
                                     f"{flux.shape[0]} finite internal-face fluxes")
        phi.internal_field = given_flux
        flux = given_flux
    pb = cast(dict[str, Any], phi.boundary_field)
    alpha = _relaxation(mesh, flux, cells["C"], cells["V"], zones, d_cell)
    ends = {p: _end_faces(mesh, p, cells["C"], pb) for p in ("inlet", "outlet")}
    q_in, area_in, g_in = ends["inlet"]
    u_in = np.maximum(-q_in, 0.0) / area_in
    d_in = d_cell[mesh.owner[mesh.patch_faces("inlet")]]
    _write_heat_case(heat_dir, zones, d_cell, mesh, alpha, residual,
                     u_in / np.maximum(u_in + d_in * g_in, 1e-300))
    run_foam(runner, "topoSet", [], heat_dir, timeout=timeout)
    log = run_foam(runner, "scalarTransportFoam", [], heat_dir, timeout=timeout)
    found = _RESIDUAL_RE.findall(log.read_text(errors="replace"))
    T = FoamFieldFile(heat_dir / latest_time(heat_dir) / "theta")
    theta = np.broadcast_to(np.asarray(T.internal_field, float), zones.cell_k.shape).copy()
    top = float(max(zones.theta_p.max(initial=0.0), 0.0))
    low = float(min(zones.theta_p.min(initial=0.0), 0.0))
    slack = 1e-3 * max(top - low, 1e-12)
    if (not found or float(found[-1]) > residual or theta.min() < low - slack
            or theta.max() > top + slack):
        raise SolverError("scalarTransportFoam", [], None, log,
                          reason=f"theta not converged (last residual {found[-1:]}, target "
                          f"{residual}; range {theta.min():.4g}..{theta.max():.4g} K against "
                          f"sources {low:.4g}..{top:.4g} K; relaxation {alpha:.3g})")
    tb = cast(dict[str, Any], T.boundary_field)
    leaving, out_q, out_qt = 0.0, 0.0, 0.0
    for patch, (q, area, g) in ends.items():
        s = mesh.patch_faces(patch)
        tf = np.broadcast_to(np.asarray(tb[patch].get("value", 0.0), float), q.shape)
        # Advected and conducted out (OpenFOAM's boundary delta coefficient g).
        owner = mesh.owner[s]
        leaving += float(np.sum(q * tf + d_cell[owner] * area * g * (theta[owner] - tf)))
        if patch == "outlet":
            out_q, out_qt = float(q[q > 0].sum()), float(np.sum((q * tf)[q > 0]))
    return AirTemperature(theta, out_qt / out_q if out_q > 0 else math.nan, out_q,
                          leaving - out_qt, len(found), alpha, time.perf_counter() - t0)


def _end_faces(mesh: Any, patch: str, centres: NDArray[np.float64], phi: dict[str, Any],
               ) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """Per face of ``patch``: flux (m^3/s, out > 0), area (m^2) and delta coefficient
    1 / max(n . d, 0.05 |d|) (1/m, d from the owner's centre to the face's, as OpenFOAM)."""
    s = mesh.patch_faces(patch)
    q = np.broadcast_to(np.asarray(phi[patch]["value"], float), (s.stop - s.start,))
    area = np.linalg.norm(mesh.face_areas[s], axis=1)
    d = mesh.face_centres[s] - centres[mesh.owner[s]]
    normal = np.einsum("ij,ij->i", d, mesh.face_areas[s]) / area
    return q, area, 1.0 / np.maximum(normal, 0.05 * np.linalg.norm(d, axis=1))


_RESIDUAL_RE = re.compile(r"Solving for theta, Initial residual = ([^,]+),")


def _copy_case(bed_dir: Path, time_dir: str, heat_dir: Path) -> None:
    """The mesh (without the porosity zones) and the solved U and phi into a fresh case."""
    if heat_dir.exists():
        shutil.rmtree(heat_dir)
    (heat_dir / "0").mkdir(parents=True)
    shutil.copytree(bed_dir / "constant", heat_dir / "constant",
                    ignore=shutil.ignore_patterns("cellZones", "sets", "MRFProperties"))
    (heat_dir / "system").mkdir()
    for name in ("phi", "U"):
        shutil.copyfile(bed_dir / time_dir / name, heat_dir / "0" / name)
    _decouple(heat_dir)


def _relaxation(mesh: Any, flux: NDArray[np.float64], centres: NDArray[np.float64],
                volumes: NDArray[np.float64], zones: HeatZones,
                diffusivity: NDArray[np.float64]) -> float:
    """Under-relaxation of the T equation that keeps the outer iterations stable.

    The sink is explicit in v1912: a cell whose k V exceeds its matrix coefficient D (inflow
    plus diffusion) diverges (the smoke bed: unrelaxed and at 0.9; 0.6 converged). Relaxed by
    alpha, an error is multiplied by about 1 - alpha (1 + k V / D) per iteration: alpha =
    1 / (1 + max k V / D), clipped to 0.01..0.6, keeps every factor in 0..1.
    """
    n, ni = len(volumes), len(mesh.neighbour)
    o, nb = mesh.owner[:ni], mesh.neighbour
    q = flux[:ni]
    inflow = (np.bincount(nb, weights=np.maximum(q, 0.0), minlength=n)
              + np.bincount(o, weights=np.maximum(-q, 0.0), minlength=n))
    do, dn = diffusivity[o], diffusivity[nb]
    harmonic = np.divide(2.0 * do * dn, do + dn, out=np.zeros(ni), where=do + dn > 0)
    g = harmonic * np.linalg.norm(mesh.face_areas[:ni], axis=1) / np.linalg.norm(
        centres[nb] - centres[o], axis=1)
    d = inflow + np.bincount(o, weights=g, minlength=n) + np.bincount(nb, weights=g, minlength=n)
    k, _ = zones.binned()
    r = np.divide(k * volumes, d, out=np.full(n, np.inf), where=d > 0)
    worst = float(r[k > 0].max()) if np.any(k > 0) else 0.0
    return float(np.clip(1.0 / (1.0 + worst), 0.01, 0.6))


def _write_heat_case(heat_dir: Path, zones: HeatZones, diffusivity: NDArray[np.float64],
                     mesh: Any, alpha: float, residual: float,
                     inlet_fraction: NDArray[np.float64]) -> None:
    from foamlib import FoamFieldFile, FoamFile

    from drumflow.air.foam_case import write_field, write_zone_sets
    names = [n for n, _ in cast(list[tuple[str, Any]],
                                FoamFile(heat_dir / "constant/polyMesh/boundary")[None])]
    bc: dict[str, dict[str, Any]] = {n: {"type": "zeroGradient"} for n in names}
    # The host's own T: zero everywhere, so every one of its solves is a no-op.
    write_field(heat_dir, "T", {"temperature": 1}, 0.0, bc)
    # Danckwerts at the inlet: advected plus conducted, the air brings exactly T_in.
    bc["inlet"] = {"type": "mixed", "refValue": 0.0, "refGradient": 0.0, "valueFraction": 1.0,
                   "value": 0.0}
    bc["outlet"] = {"type": "inletOutlet", "inletValue": 0.0, "value": 0.0}
    write_field(heat_dir, "theta", {"temperature": 1}, 0.0, bc)
    # foamlib writes a list under a key it does not know as a field without its header.
    path = heat_dir / "0" / "theta"
    values = " ".join(repr(float(v)) for v in inlet_fraction)
    path.write_text(re.sub(r"valueFraction\s+[^;]*;", f"valueFraction nonuniform List<scalar> "
                           f"{len(inlet_fraction)}({values});", path.read_text(), count=1))
    # D per cell; on a boundary face its owner's (what the Danckwerts fraction assumed).
    with FoamFieldFile(heat_dir / "0" / "D") as f:
        f.dimensions = FoamFile.DimensionSet(length=2, time=-1)
        f.internal_field = diffusivity
        f.boundary_field = {n: {"type": "calculated",
                                "value": diffusivity[mesh.owner[mesh.patch_faces(n)]]}
                            for n in names}
    sources = {name: {"type": "scalarSemiImplicitSource", "active": True,
                      "selectionMode": "cellZone", "cellZone": name, "volumeMode": "specific",
                      # S = Su + Sp theta per m^3 of the zone (K/s): k theta_p - k theta.
                      "injectionRateSuSp": {"theta": [float(k * tp), -float(k)]}}
               for name, k, tp in zip(zones.names, zones.k, zones.theta_p, strict=True)}
    _write(heat_dir / "system" / "controlDict", {
        "application": "scalarTransportFoam", "startFrom": "startTime", "startTime": 0,
        "stopAt": "endTime", "endTime": MAX_ITERATIONS, "deltaT": 1,
        "writeControl": "timeStep", "writeInterval": MAX_ITERATIONS, "purgeWrite": 0,
        "writeFormat": "ascii", "writePrecision": 12, "timeFormat": "general",
        "runTimeModifiable": False,
        "functions": {
            "readD": {"type": "readFields", "libs": ["libfieldFunctionObjects.so"],
                      "fields": ["D"]},
            "theta": {"type": "scalarTransport", "libs": ["libsolverFunctionObjects.so"],
                      "field": "theta", "phi": "phi", "nut": "D", "nCorr": 0,
                      "resetOnStartUp": False, "fvOptions": sources},
            "converged": {"type": "runTimeControl", "libs": ["libutilityFunctionObjects.so"],
                          "conditions": {"theta": {
                              "type": "equationInitialResidual", "fields": ["theta"],
                              "value": residual, "mode": "minimum"}}}}})
    _write(heat_dir / "system" / "fvSchemes", {
        "ddtSchemes": {"default": "steadyState"},
        # Limited: linearUpwind with the plain gradient overshot the sources' range by 13 %
        # on the smoke bed's tetrahedra; cell-limited it stays inside.
        "gradSchemes": {"default": ("Gauss", "linear"),
                        "grad(theta)": ("cellLimited", "Gauss", "linear", 1)},
        "divSchemes": {"default": "none", "div(phi,T)": ("bounded", "Gauss", "upwind"),
                       "div(phi,theta)": ("bounded", "Gauss", "linearUpwind", "grad(theta)")},
        # Harmonic: two cells' conductances in series (module docstring).
        "laplacianSchemes": {"default": ("Gauss", "harmonic", "limited", "corrected", 0.5)},
        "interpolationSchemes": {"default": "linear"},
        "snGradSchemes": {"default": ("limited", "corrected", 0.5)}})
    solver = {"solver": "PBiCGStab", "preconditioner": "DILU", "tolerance": 1e-12, "relTol": 0.0}
    _write(heat_dir / "system" / "fvSolution", {
        "solvers": {"T": solver, "theta": solver},
        "SIMPLE": {"nNonOrthogonalCorrectors": 0},
        "relaxationFactors": {"equations": {"theta": alpha}}})
    with FoamFile(heat_dir / "constant" / "transportProperties") as f:
        f["DT"] = FoamFile.Dimensioned(0.0, FoamFile.DimensionSet(length=2, time=-1), "DT")
    # No system/fvOptions: the sources act on theta, inside its function object.
    # Named at once: parsing the written dictionary again took minutes on 150k cells.
    write_zone_sets(heat_dir, zones, zones.names)


def _write(path: Path, entries: dict[str, Any]) -> None:
    from foamlib import FoamFile

    with FoamFile(path) as f:
        for key, value in entries.items():
            f[key] = value
