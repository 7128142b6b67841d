"""How much of the bed's and the curtains' heat the drum's air really takes: the contact
efficiency of a solved bed-air case (:mod:`drumflow.air.bed_air`), on its frozen snapshot.

The air's steady temperature is solved with the particles' heat as its source,
rho c_p (div(U T) - div(D grad T)) = h a_v (T_p - T) in every cell with solids, and measured:
``heat_W`` = sum of h a_v V (T_p - T_air) (what the air takes); ``heat_bulk_W``, the same with
T_air = ``air.inlet_temperature_C`` (every particle in fresh air); ``contact_efficiency`` =
their ratio; ``saturated_flow_m3_s_m`` = heat_W / (rho c_p (T_p,mean - T_in) L), the air per
metre of drum that would leave at the particles' mean temperature with the same heat; the split
by cell category (:func:`~drumflow.air.bed_air.categorize`); the outlet's flux-weighted
temperature; and the enthalpy balance rho c_p Q (T_out - T_in) + what else leaves the ends
(diffusion through the outlet's backflow faces) against heat_W: bookkeeping, no physics.

The law: h from Gunn's Nusselt number for fixed and fluidised beds (D.J. Gunn, Int. J. Heat
Mass Transfer 21 (1978) 467-476; :func:`drumflow.physics.particle_air.gunn_h`) at the cell's
voidage eps = 1 - phi (held in Gunn's 0.35..1) and the superficial slip, Re = rho |U - eps v_p|
d / mu: simpleFoam's U with an explicit porosity source is the superficial velocity, so U -
eps v_p = eps (U_interstitial - v_p). a_v = 6 phi / d with d the *granule* diameter
(``particles.diameter``: a coarse-grained parcel carries k^3 granules' volume and surface). Air
properties at the inlet temperature, as the flow was solved
(:func:`~drumflow.air.foam_case.air_properties_for`, :mod:`drumflow.physics.air`). Per cell,
v_p and T_p are the particles' volume-weighted means on the deposition grid of
:func:`~drumflow.air.bed_air.solve_bed_air` (:func:`particle_means`), positions and velocities
turned into the mesh's drum frame.

How, and why: stock ``scalarTransportFoam`` (v1912, nothing to compile) in a copy of the bed
case, ``<work>/heat``. It transports T with the solved face flux ``phi`` itself (no second
interpolation of U) and takes ``system/fvOptions``. ``phi`` of an MRF solution is the flux
relative to the drum, the frozen-rotor convention stock MRF solvers transport scalars with: the
bed, frozen on the cells, is swept by the air at its velocity relative to the drum. The unknown
is theta = T - T_in (round-off scales with the heating). The source is ``semiImplicitSource``
per cellZone, S = k (theta_p - theta), k = h a_v / (rho c_p) (1/s): stock fvOptions take one
value per zone, so the cells are binned (:func:`bin_heat_sources`: equal-count bins of log k,
each split by T_p; 144 zones, the binning moves the smoke bed's heat by 0.2 %), keeping sum k V
and sum k theta_p V exactly; the zones are written by
:func:`~drumflow.air.foam_case.write_zone_sets`. v1912 puts ``fvm::SuSp(Sp, T)`` on the
right-hand side, making our negative Sp explicit: T is under-relaxed (:func:`_relaxation`). Steady,
``bounded Gauss linearUpwind`` with a cell-limited gradient: second order (the 0.03 m smoke mesh
has three or four cells along the slice; upwind would be 8 % off the plug-flow check) and inside
the sources' range (unlimited it overshot by 13 %).

Ends: a periodic flow's temperature is not periodic; the copy's cyclicAMI pair becomes plain
patches carrying phi's cyclic values, fresh air at ``inlet`` (z = l) by a Danckwerts condition
(``mixed``, value fraction u / (u + D / delta); a fixed T_in let 9 % of the smoke bed's heat
diffuse out upstream), ``inletOutlet`` at ``outlet``, walls adiabatic.

D is one constant (v1912's scalarTransportFoam takes no field): by default the volume mean of
nu_t / 0.85 of the solved ``nut`` plus nu / Pr (:func:`turbulent_diffusivity`), which lets heat
leave the bed's cells as if they were free air (an upper bound there); ``mixing="molecular"``
keeps nu / Pr alone (the lower bound: heat leaves the bed only with the air through it).
"""

from __future__ import annotations

import math
import re
import shutil
import time
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any, Protocol, cast

import numpy as np
from numpy.typing import NDArray

from drumflow.air.bed_air import (
    CATEGORIES,
    POROUS_FRACTION,
    SMOOTHING_PASSES,
    BedSnapshot,
    categorize,
)
from drumflow.errors import AnalysisInputError

if TYPE_CHECKING:
    from drumflow.air.bed_air import BedAirResult
    from drumflow.case import Case
    from drumflow.physics.particle_air import AirState
    from drumflow.runner import Runner

__all__ = ["MIXING", "TURBULENT_PRANDTL", "AirTemperature", "BedHeatResult", "HeatSnapshot", "HeatZones",
           "bin_heat_sources", "exchange_rate", "measure_heat", "particle_means",
           "solve_air_temperature", "solve_bed_heat", "turbulent_diffusivity"]

#: Turbulent Prandtl number of air for the diffusivity.
TURBULENT_PRANDTL = 0.85
#: Bins of log k, and of T_p inside each (:func:`bin_heat_sources`).
K_BINS, T_BINS = 24, 6
#: The diffusivity's choices (module notes): turbulent (default) or molecular.
MIXING = ("turbulent", "molecular")


def _finite(name: str, values: NDArray[np.float64], allowed: str = "finite numbers") -> None:
    bad = ~np.isfinite(values)
    if np.any(bad):
        raise AnalysisInputError(name, np.asarray(values)[bad].ravel()[0], allowed)


def particle_means(centres: NDArray[np.float64], positions: NDArray[np.float64],
                   radii: NDArray[np.float64], values: NDArray[np.float64],
                   lower: NDArray[np.float64], upper: NDArray[np.float64], spacing: float,
                   periodic_z: bool = False, passes: int = SMOOTHING_PASSES,
                   ) -> NDArray[np.float64]:
    """Volume-weighted means of the particles' ``values`` ((n,) or (n, m)) per mesh cell
    (``centres``) on the grid of :func:`~drumflow.air.bed_air.deposit_on_cells` (spacing, box,
    ``passes``); a cell whose grid cell got no weight takes the mean over all particles."""
    from drumflow.air.bed_air import deposition_grid
    from drumflow.air.solids_fraction import Deposition, smooth_deposition

    grid = deposition_grid(lower, upper, spacing, periodic_z)
    v = np.asarray(values, float)
    flat = v.reshape(len(v), -1)
    volume = 4.0 / 3.0 * math.pi * np.asarray(radii, float) ** 3
    where = grid.locate(positions)
    inside = where >= 0
    n = int(np.prod(grid.shape))
    nx, ny, nz = grid.shape

    def smoothed(weights: NDArray[np.float64]) -> NDArray[np.float64]:
        raw = np.asarray(np.bincount(where[inside], weights=weights[inside], minlength=n), float)
        dep = Deposition(grid, raw.reshape(nz, ny, nx).transpose(2, 1, 0), 0.0, 0.0, 1)
        return np.asarray(grid.flatten(smooth_deposition(dep, passes).volume), float)

    w = smoothed(volume)
    held = w > 1e-9 * max(float(w.max()), 1e-300)
    at = grid.locate(centres)
    if np.any(at < 0):
        raise AnalysisInputError("mesh cell centres", int(np.sum(at < 0)),
                                 "all inside the deposition grid's box")
    out = np.empty((len(at), flat.shape[1]))
    for j in range(flat.shape[1]):
        mean = np.average(flat[:, j], weights=volume)
        grid_mean = np.divide(smoothed(volume * flat[:, j]), w, out=np.full(n, mean), where=held)
        out[:, j] = grid_mean[at]
    return out.reshape((len(at),) + v.shape[1:])


def exchange_rate(fraction: NDArray[np.float64], air_velocity: NDArray[np.float64],
                  particle_velocity: NDArray[np.float64], diameter: float, air: AirState,
                  heat_capacity: float) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Per cell h (W/(m^2 K), Gunn) and k = h a_v / (rho c_p) (1/s), a_v = 6 phi / d; zero in
    cells with less than :data:`~drumflow.air.bed_air.POROUS_FRACTION` solids. ``air_velocity``
    is the superficial (solved) one; see the module docstring for the slip."""
    from drumflow.physics.particle_air import GUNN_VOIDAGE, gunn_h

    if not (diameter > 0.0 and math.isfinite(diameter)):
        raise AnalysisInputError("diameter", diameter, "a finite length > 0 (m)")
    phi = np.asarray(fraction, float)
    _finite("fraction", phi)
    if np.any((phi < 0.0) | (phi >= 1.0)):
        raise AnalysisInputError("fraction", float(phi[(phi < 0) | (phi >= 1)][0]),
                                 "solids fractions in 0..1 (exclusive)")
    U, vp = np.asarray(air_velocity, float), np.asarray(particle_velocity, float)
    for name, a in (("air_velocity", U), ("particle_velocity", vp)):
        _finite(name, a)
    eps = 1.0 - phi
    slip = np.linalg.norm(U - eps[:, None] * vp, axis=1)
    h = gunn_h(slip, np.clip(eps, *GUNN_VOIDAGE), diameter, air)
    return h, np.where(phi >= POROUS_FRACTION,
                       h * 6.0 * phi / diameter / (air.density * heat_capacity), 0.0)


@dataclass(frozen=True)
class HeatZones:
    """Source cells binned: ``cells`` per zone, its ``k`` (1/s) and ``theta_p`` (K over the
    inlet); ``cell_k``, ``cell_theta_p``: the exact per-cell values."""

    cells: list[NDArray[np.int64]]
    k: NDArray[np.float64]
    theta_p: NDArray[np.float64]
    cell_k: NDArray[np.float64] = field(repr=False)
    cell_theta_p: NDArray[np.float64] = field(repr=False)

    @property
    def names(self) -> list[str]:
        return [f"heat{i}" for i in range(len(self.cells))]

    def binned(self) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Each cell's zone k and theta_p (0 outside every zone)."""
        k, t = np.zeros_like(self.cell_k), np.zeros_like(self.cell_k)
        for i, c in enumerate(self.cells):
            k[c], t[c] = self.k[i], self.theta_p[i]
        return k, t


def bin_heat_sources(k: NDArray[np.float64], theta_p: NDArray[np.float64],
                     volumes: NDArray[np.float64], k_bins: int = K_BINS,
                     t_bins: int = T_BINS) -> HeatZones:
    """Bin the cells with k > 0 into zones: ``k_bins`` equal-count bins of log k, each split
    into ``t_bins`` equal-count bins of theta_p. A zone's k is its cells' volume mean and its
    theta_p their k V-weighted mean: sum k V and sum k theta_p V are kept."""
    k, t, V = (np.asarray(a, float) for a in (k, theta_p, volumes))
    for name, a in (("k", k), ("theta_p", t), ("volumes", V)):
        _finite(name, a)
    if np.any(k < 0.0):
        raise AnalysisInputError("k", float(k[k < 0][0]), "rates >= 0 (1/s)")
    src = np.flatnonzero(k > 0.0)
    cells: list[NDArray[np.int64]] = []
    zk, zt = [], []  # type: list[float], list[float]
    if len(src):
        by_k = src[np.argsort(np.log(k[src]), kind="stable")]
        for part in np.array_split(by_k, min(k_bins, len(by_k))):
            by_t = part[np.argsort(t[part], kind="stable")]
            for zone in np.array_split(by_t, min(t_bins, len(by_t))):
                kv = k[zone] * V[zone]
                cells.append(zone.astype(np.int64))
                zk.append(float(kv.sum() / V[zone].sum()))
                zt.append(float(np.sum(kv * t[zone]) / kv.sum()))
    return HeatZones(cells, np.array(zk), np.array(zt), k, t)


def turbulent_diffusivity(case_dir: Path, time_dir: str, volumes: NDArray[np.float64],
                          nu: float, prandtl: float) -> float:
    """D, m^2/s: volume mean of nut / :data:`TURBULENT_PRANDTL` (laminar: 0) plus nu / Pr."""
    from foamlib import FoamFieldFile

    path = case_dir / time_dir / "nut"
    nut = (np.broadcast_to(np.asarray(FoamFieldFile(path).internal_field, float), volumes.shape)
           if path.exists() else np.zeros_like(volumes))
    return float(np.average(nut, weights=volumes)) / TURBULENT_PRANDTL + nu / prandtl


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
                          diffusivity: float, runner: Runner, timeout: float | None = 600.0,
                          residual: float = 1e-6) -> AirTemperature:
    """Copy the solved case ``bed_dir``/``time_dir`` to ``heat_dir``, write and run the
    temperature case (module docstring), and read theta, the outlet and the bookkeeping.

    Raises
    ------
    drumflow.errors.SolverError
        topoSet or scalarTransportFoam failed, or theta did not converge to ``residual``
        within 3000 iterations or left the range of the sources.
    """
    from foamlib import FoamFieldFile

    from drumflow.air.foam_results import latest_time, read_cell_fields
    from drumflow.air.mesh import run_foam
    from drumflow.air.poly_mesh import read_poly_mesh
    from drumflow.errors import SolverError

    if not (diffusivity >= 0.0 and math.isfinite(diffusivity)):
        raise AnalysisInputError("diffusivity", diffusivity, "a finite number >= 0 (m^2/s)")
    t0 = time.perf_counter()
    heat_dir = Path(heat_dir)
    _copy_case(bed_dir, time_dir, heat_dir)
    mesh = read_poly_mesh(heat_dir)
    cells = read_cell_fields(bed_dir, time_dir)
    phi = FoamFieldFile(heat_dir / "0" / "phi")
    flux = np.asarray(phi.internal_field, float)
    pb = cast(dict[str, Any], phi.boundary_field)
    alpha = _relaxation(mesh, flux, cells["C"], cells["V"], zones, diffusivity)
    ends = {p: _end_faces(mesh, p, cells["C"], pb) for p in ("inlet", "outlet")}
    q_in, area_in, g_in = ends["inlet"]
    u_in = np.maximum(-q_in, 0.0) / area_in
    _write_heat_case(heat_dir, zones, diffusivity, alpha, residual,
                     u_in / np.maximum(u_in + diffusivity * g_in, 1e-300))
    run_foam(runner, "topoSet", [], heat_dir, timeout=timeout)
    log = run_foam(runner, "scalarTransportFoam", [], heat_dir, timeout=timeout)
    found = _RESIDUAL_RE.findall(log.read_text(errors="replace"))
    T = FoamFieldFile(heat_dir / latest_time(heat_dir) / "T")
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
        leaving += float(np.sum(q * tf + diffusivity * area * g * (theta[mesh.owner[s]] - tf)))
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


_RESIDUAL_RE = re.compile(r"Solving for T, Initial residual = ([^,]+),")


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
                volumes: NDArray[np.float64], zones: HeatZones, diffusivity: float) -> float:
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
    g = diffusivity * np.linalg.norm(mesh.face_areas[:ni], axis=1) / np.linalg.norm(
        centres[nb] - centres[o], axis=1)
    d = inflow + np.bincount(o, weights=g, minlength=n) + np.bincount(nb, weights=g, minlength=n)
    k, _ = zones.binned()
    r = np.divide(k * volumes, d, out=np.full(n, np.inf), where=d > 0)
    worst = float(r[k > 0].max()) if np.any(k > 0) else 0.0
    return float(np.clip(1.0 / (1.0 + worst), 0.01, 0.6))


def _write_heat_case(heat_dir: Path, zones: HeatZones, diffusivity: float, alpha: float,
                     residual: float, inlet_fraction: NDArray[np.float64]) -> None:
    from foamlib import FoamFile

    from drumflow.air.foam_case import write_field, write_zone_sets
    from drumflow.air.solids_fraction import PorosityZones

    names = [n for n, _ in cast(list[tuple[str, Any]],
                                FoamFile(heat_dir / "constant/polyMesh/boundary")[None])]
    bc: dict[str, dict[str, Any]] = {n: {"type": "zeroGradient"} for n in names}
    # Danckwerts at the inlet: advected plus conducted, the air brings exactly T_in.
    bc["inlet"] = {"type": "mixed", "refValue": 0.0, "refGradient": 0.0, "valueFraction": 1.0,
                   "value": 0.0}
    bc["outlet"] = {"type": "inletOutlet", "inletValue": 0.0, "value": 0.0}
    write_field(heat_dir, "T", {"temperature": 1}, 0.0, bc)
    # foamlib writes a list under a key it does not know as a field without its header.
    path = heat_dir / "0" / "T"
    values = " ".join(repr(float(v)) for v in inlet_fraction)
    path.write_text(re.sub(r"valueFraction\s+[^;]*;", f"valueFraction nonuniform List<scalar> "
                           f"{len(inlet_fraction)}({values});", path.read_text(), count=1))
    _write(heat_dir / "system" / "controlDict", {
        "application": "scalarTransportFoam", "startFrom": "startTime", "startTime": 0,
        "stopAt": "endTime", "endTime": 3000, "deltaT": 1, "writeControl": "timeStep",
        "writeInterval": 3000, "purgeWrite": 0, "writeFormat": "ascii", "writePrecision": 12,
        "timeFormat": "general", "runTimeModifiable": False})
    _write(heat_dir / "system" / "fvSchemes", {
        "ddtSchemes": {"default": "steadyState"},
        # Limited: linearUpwind with the plain gradient overshot the sources' range by 13 %
        # on the smoke bed's tetrahedra; cell-limited it stays inside.
        "gradSchemes": {"default": ("Gauss", "linear"),
                        "grad(T)": ("cellLimited", "Gauss", "linear", 1)},
        "divSchemes": {"default": "none",
                       "div(phi,T)": ("bounded", "Gauss", "linearUpwind", "grad(T)")},
        "laplacianSchemes": {"default": ("Gauss", "linear", "limited", "corrected", 0.5)},
        "interpolationSchemes": {"default": "linear"},
        "snGradSchemes": {"default": ("limited", "corrected", 0.5)}})
    _write(heat_dir / "system" / "fvSolution", {
        "solvers": {"T": {"solver": "PBiCGStab", "preconditioner": "DILU", "tolerance": 1e-12,
                          "relTol": 0.0}},
        "SIMPLE": {"nNonOrthogonalCorrectors": 0, "residualControl": {"T": residual}},
        "relaxationFactors": {"equations": {"T": alpha}}})
    with FoamFile(heat_dir / "constant" / "transportProperties") as f:
        f["DT"] = FoamFile.Dimensioned(float(diffusivity),
                                       FoamFile.DimensionSet(length=2, time=-1), "DT")
    with FoamFile(heat_dir / "system" / "fvOptions") as f:
        for name, k, tp in zip(zones.names, zones.k, zones.theta_p, strict=True):
            # S = Su + Sp theta per m^3 of the zone (K/s): k theta_p - k theta.
            f[name] = {"type": "scalarSemiImplicitSource", "active": True,
                       "selectionMode": "cellZone", "cellZone": name, "volumeMode": "specific",
                       "injectionRateSuSp": {"T": [float(k * tp), -float(k)]}}
    # write_zone_sets takes the cell lists of a PorosityZones; its d and f are not written.
    write_zone_sets(heat_dir, PorosityZones(zones.cells, zones.k, zones.theta_p, zones.cell_k,
                                            zones.cell_theta_p))
    with FoamFile(heat_dir / "system" / "topoSetDict") as f:
        actions = cast(list[dict[str, Any]], f["actions"])
        f["actions"] = [{**a, "name": n} for a, n in zip(actions, zones.names, strict=True)]


def _write(path: Path, entries: dict[str, Any]) -> None:
    from foamlib import FoamFile

    with FoamFile(path) as f:
        for key, value in entries.items():
            f[key] = value


@dataclass(frozen=True)
class BedHeatResult:
    """The heat the air takes from one bed state's particles (module docstring).

    Attributes
    ----------
    heat_W, heat_bulk_W, contact_efficiency, saturated_flow_m3_s_m
        What the air takes; what fresh air would; their ratio; the flow of air per metre of
        drum that would leave at the particles' mean temperature with heat_W.
    air_flow_m3_s, air_inlet_temperature_C, air_outlet_temperature_C
        The outlet's outflow; the case's inlet temperature; the outlet's flux-weighted one.
    particle_mean_temperature_C
        The particles' volume-weighted mean.
    enthalpy_balance, other_out_W
        (rho c_p Q (T_out - T_in) + other_out_W) / heat_W - 1 (bookkeeping); what leaves the
        ends besides the outlet's air (diffusion at its backflow faces).
    by_category
        heat_W, heat_bulk_W and contact_efficiency of the bed, curtain and free-air cells.
    mixing, diffusivity_m2_s, zones, binning_error, voidage_clipped_cells
        One of :data:`MIXING`; D; source zones; heat with each cell's own k and T_p at the
        solved T over heat_W, less 1; source cells whose voidage was raised to Gunn's 0.35.
    iterations, wall_time_s, fields
        scalarTransportFoam's outer iterations; s taken; per cell T, k (1/s) and T_p (degC).
    """

    case_name: str
    heat_W: float
    heat_bulk_W: float
    contact_efficiency: float
    saturated_flow_m3_s_m: float
    air_flow_m3_s: float
    air_inlet_temperature_C: float
    air_outlet_temperature_C: float
    particle_mean_temperature_C: float
    enthalpy_balance: float
    other_out_W: float
    by_category: dict[str, dict[str, float]]
    mixing: str
    diffusivity_m2_s: float
    zones: int
    binning_error: float
    voidage_clipped_cells: int
    iterations: int
    wall_time_s: float
    fields: dict[str, NDArray[np.float64]] = field(repr=False, default_factory=dict)

    def as_dict(self) -> dict[str, Any]:
        return {k: v for k, v in asdict(self).items() if k != "fields"}


def measure_heat(zones: HeatZones, air: AirTemperature, volumes: NDArray[np.float64],
                 fraction: NDArray[np.float64], rho_cp: float,
                 ) -> tuple[float, float, dict[str, dict[str, float]], float]:
    """heat_W, heat_bulk_W (W), their split by category, and the binning error (the heat with
    each cell's own k and theta_p at the solved theta, relative to heat_W)."""
    k, tp = zones.binned()
    cell = rho_cp * k * volumes * (tp - air.theta)
    bulk = rho_cp * k * volumes * tp
    exact = float(np.sum(rho_cp * zones.cell_k * volumes * (zones.cell_theta_p - air.theta)))
    category = categorize(fraction)
    split: dict[str, dict[str, float]] = {}
    for i, name in enumerate(CATEGORIES):
        m = category == i
        h, b = float(cell[m].sum()), float(bulk[m].sum())
        split[name] = {"heat_W": h, "heat_bulk_W": b,
                       "contact_efficiency": h / b if b > 0 else math.nan}
    total = float(cell.sum())
    return total, float(bulk.sum()), split, exact / total - 1.0 if total else math.nan


class HeatSnapshot(BedSnapshot, Protocol):
    """A bed state with what the heat needs besides the places (a
    :class:`drumflow.dem.state.StartState` is one; a Protocol, as the air stage does not import
    the DEM's)."""

    @property
    def velocities(self) -> NDArray[np.floating[Any]]: ...  # (n, 3), m/s, lab frame
    @property
    def temperatures_C(self) -> NDArray[np.floating[Any]]: ...  # (n,), degC


def solve_bed_heat(result: BedAirResult, state: HeatSnapshot, case: Case, runner: Runner,
                   workdir: Path, *, spacing: float | None = None,
                   timeout: float | None = 600.0, k_bins: int = K_BINS, t_bins: int = T_BINS,
                   residual: float = 1e-6, mixing: str = "turbulent") -> BedHeatResult:
    """The heat the air takes from ``state``'s particles in the bed case that
    :func:`~drumflow.air.bed_air.solve_bed_air` solved (``result``) in ``workdir``
    (``workdir/bed``); the temperature case goes to ``workdir/heat``. ``spacing``: the
    deposition grid's, as given to :func:`~drumflow.air.bed_air.solve_bed_air` (default
    alike); ``k_bins``, ``t_bins``: :func:`bin_heat_sources`; ``residual``: the outer
    iterations' target (:func:`solve_air_temperature`); ``mixing``: one of :data:`MIXING`.

    Raises
    ------
    drumflow.errors.AnalysisInputError
        A NaN particle temperature or velocity, a bad diameter or solids fraction, or mixing.
    drumflow.errors.SolverError
        topoSet or scalarTransportFoam failed.
    """
    from drumflow.air.foam_case import air_properties_for
    from drumflow.air.foam_results import latest_time, read_cell_fields
    from drumflow.air.poly_mesh import read_poly_mesh
    from drumflow.geometry.fluid import fluid_mesh_size
    from drumflow.physics.air import specific_heat
    from drumflow.physics.drum_frame import rotate_to_drum_frame
    from drumflow.physics.particle_air import GUNN_VOIDAGE, AirState

    if mixing not in MIXING:
        raise AnalysisInputError("mixing", mixing, " or ".join(MIXING))
    t0 = time.perf_counter()
    temps = np.asarray(state.temperatures_C, float)
    _finite("temperatures_C", temps)
    _finite("velocities", np.asarray(state.velocities, float))
    bed_dir = Path(workdir) / "bed"
    time_dir = latest_time(bed_dir)
    cells = read_cell_fields(bed_dir, time_dir)
    mesh = read_poly_mesh(bed_dir)
    t_in = case.air.inlet_temperature_C
    rho, nu = air_properties_for(case)
    cp = float(specific_heat(t_in))
    air = AirState.at(t_in, case.air.pressure_kPa)
    h = spacing if spacing is not None else max(4.0 * float(state.radii.max()),
                                                fluid_mesh_size(case))
    positions = rotate_to_drum_frame(state.positions, state.drum_angle_rad)
    velocities = rotate_to_drum_frame(state.velocities, state.drum_angle_rad)
    means = particle_means(cells["C"], positions, state.radii,
                           np.column_stack([velocities, temps]), mesh.bounds[0], mesh.bounds[1],
                           h, periodic_z=case.drum.ends == "periodic")
    fraction = result.fields["fraction"]
    _, k = exchange_rate(fraction, cells["U"], means[:, :3], case.particles.diameter, air, cp)
    zones = bin_heat_sources(k, means[:, 3] - t_in, cells["V"], k_bins, t_bins)
    diffusivity = (turbulent_diffusivity(bed_dir, time_dir, cells["V"], nu, air.prandtl)
                   if mixing == "turbulent" else nu / air.prandtl)
    solved = solve_air_temperature(bed_dir, time_dir, Path(workdir) / "heat", zones,
                                   diffusivity, runner, timeout, residual)
    heat, bulk, split, binning = measure_heat(zones, solved, cells["V"], fraction, rho * cp)
    volume = 4.0 / 3.0 * math.pi * np.asarray(state.radii, float) ** 3
    tp_mean = float(np.average(temps, weights=volume))
    advected = rho * cp * (solved.outflow_m3_s * solved.outlet_theta + solved.other_out_m3K_s)
    eps = 1.0 - fraction
    return BedHeatResult(
        case_name=case.name, heat_W=heat, heat_bulk_W=bulk,
        contact_efficiency=heat / bulk if bulk > 0 else math.nan,
        saturated_flow_m3_s_m=heat / (rho * cp * (tp_mean - t_in) * case.drum.length),
        air_flow_m3_s=solved.outflow_m3_s, air_inlet_temperature_C=t_in,
        air_outlet_temperature_C=t_in + solved.outlet_theta,
        particle_mean_temperature_C=tp_mean,
        enthalpy_balance=advected / heat - 1.0 if heat else math.nan,
        other_out_W=rho * cp * solved.other_out_m3K_s,
        by_category=split, mixing=mixing, diffusivity_m2_s=diffusivity, zones=len(zones.cells),
        binning_error=binning,
        voidage_clipped_cells=int(np.sum((k > 0) & (eps < GUNN_VOIDAGE[0]))),
        iterations=solved.iterations, wall_time_s=time.perf_counter() - t0,
        fields={"T": t_in + solved.theta, "k": k, "T_p": means[:, 3]})
