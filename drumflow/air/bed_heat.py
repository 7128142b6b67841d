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

The air's temperature: :func:`drumflow.air.air_temperature.solve_air_temperature` (stock
OpenFOAM on the solved case's face flux, the sources binned into zones by
:func:`bin_heat_sources`: equal-count bins of log k, each split by T_p; 144 zones, keeping sum
k V and sum k theta_p V exactly; the binning moves the smoke bed's heat by 0.2 %).

D, the air's diffusivity for heat, per cell (``mixing``, :data:`MIXING`; the choice was fixed
before any comparison with the plant):

- ``"local"`` (default, :func:`cell_diffusivity`): in free air and curtain cells nu / Pr plus
  the cell's own solved nu_t / 0.85; in the bed's cells (solids fraction at least
  :data:`~drumflow.air.bed_air.BED_FRACTION`) a packed bed's: the air's conduction through its
  voids, eps nu / Pr, plus the dispersion of the air through the packing,
  :data:`BED_DISPERSION` |u_s| d (Yagi & Kunii, AIChE J. 3 (1957) 373-381: k_e = k_e0 + 0.1 Pr
  Re_p k_f for spheres, transverse, which is the direction heat leaves the bed to the air
  above it; the axial value is larger but the air carries heat along the bed anyway), with u_s
  the superficial slip of Gunn's Re. The k-epsilon model's nu_t in a porosity zone is not a
  bed's mixing (the model has no term for the packing), so it is not used there.
- ``"turbulent"``: one D everywhere, the volume mean of nu_t / 0.85 plus nu / Pr
  (:func:`turbulent_diffusivity`): heat leaves the bed's cells as if they were free air, the
  upper bound.
- ``"molecular"``: nu / Pr everywhere, the lower bound (heat leaves the bed only with the air
  through it, and the curtains mix only by the mean flow).

Not in any of them: the bed's own particle mixing (the DEM moves the particles; the snapshot is
frozen). The air the rolling bed carries in its voids (eps v_p, not in phi) is the ``flux``
choice ``"carried"``.

Two switches measure the frozen analysis against the coupled loop's choices on the same flow
(added 2026-11-29; the defaults stay the analysis' own, so the shipped files are unchanged):

- ``flux`` (:data:`~drumflow.air.transport_flux.FLUX`): ``"relative"`` (default) carries theta
  with MRF's ``phi``, relative to the drum; ``"absolute"`` with the lab frame's flux, as the loop
  does; ``"carried"`` adds the bed's air moving with its particles
  (:mod:`drumflow.air.transport_flux` has the reasons).
- ``film`` (:data:`FILM`): ``"gunn"`` (default) as above; ``"ranz_marshall"``, the loop's law:
  Nu = 2 + 0.6 Re^0.5 Pr^(1/3) at Re of |U - v_p| (the solved superficial U less the cell's
  particle mean, as the loop samples U at each particle) and the granule's diameter
  (:func:`drumflow.physics.particle_air.ranz_marshall_h`).
"""

from __future__ import annotations

import math
import time
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any, Protocol

import numpy as np
from numpy.typing import NDArray

from drumflow.air.air_temperature import AirTemperature, HeatZones, solve_air_temperature
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

__all__ = ["BED_DISPERSION", "FILM", "MIXING", "TURBULENT_PRANDTL", "AirTemperature", "BedHeatResult",
           "HeatSnapshot", "HeatZones", "bin_heat_sources", "cell_diffusivity", "exchange_rate",
           "measure_heat", "particle_means", "solve_air_temperature", "solve_bed_heat",
           "check_choices", "heat_file_name", "superficial_slip", "turbulent_diffusivity"]

#: Turbulent Prandtl number of air for the diffusivity.
TURBULENT_PRANDTL = 0.85
#: Bins of log k, and of T_p inside each (:func:`bin_heat_sources`).
K_BINS, T_BINS = 24, 6
#: The diffusivity's choices (module notes): local (default), turbulent, molecular.
MIXING = ("local", "turbulent", "molecular")
#: The film law's choices (module notes): Gunn at the voidage (default), the loop's Ranz-Marshall.
FILM = ("gunn", "ranz_marshall")
#: A packed bed's transverse dispersion, D = 0.1 |u_s| d (Yagi & Kunii 1957; module notes).
BED_DISPERSION = 0.1


def _finite(name: str, values: NDArray[np.float64], allowed: str = "finite numbers") -> None:
    bad = ~np.isfinite(values)
    if np.any(bad):
        raise AnalysisInputError(name, np.asarray(values)[bad].ravel()[0], allowed)


def heat_file_name(mixing: str = "local", flux: str = "relative", film: str = "gunn") -> str:
    """``heat.json`` for the defaults; else ``heat_`` and the choices that differ from them,
    e.g. ``heat_molecular.json``, ``heat_molecular_absolute_ranz_marshall.json``."""
    parts = [c for c, default in ((mixing, "local"), (flux, "relative"), (film, "gunn"))
             if c != default]
    return "heat.json" if not parts else "heat_" + "_".join(parts) + ".json"


def check_choices(mixing: str, flux: str, film: str, prefix: str = "") -> None:
    """Refuse, by name (``prefix`` + mixing, flux or film), a choice not in :data:`MIXING`,
    :data:`~drumflow.air.transport_flux.FLUX` or :data:`FILM`."""
    from drumflow.air.transport_flux import FLUX

    for name, choice, allowed in (("mixing", mixing, MIXING), ("flux", flux, FLUX),
                                  ("film", film, FILM)):
        if choice not in allowed:
            raise AnalysisInputError(prefix + name, choice, " or ".join(allowed))


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


def superficial_slip(fraction: NDArray[np.float64], air_velocity: NDArray[np.float64],
                     particle_velocity: NDArray[np.float64]) -> NDArray[np.float64]:
    """|U - eps v_p| per cell, m/s: the superficial velocity of the air relative to the
    particles (U is superficial; module docstring)."""
    eps = 1.0 - np.asarray(fraction, float)
    return np.asarray(np.linalg.norm(np.asarray(air_velocity, float)
                                     - eps[:, None] * np.asarray(particle_velocity, float),
                                     axis=1), float)


def exchange_rate(fraction: NDArray[np.float64], air_velocity: NDArray[np.float64],
                  particle_velocity: NDArray[np.float64], diameter: float, air: AirState,
                  heat_capacity: float, film: str = "gunn",
                  ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Per cell h (W/(m^2 K), Gunn, or Ranz-Marshall with ``film="ranz_marshall"``) and k = h
    a_v / (rho c_p) (1/s), a_v = 6 phi / d; zero in cells with less than
    :data:`~drumflow.air.bed_air.POROUS_FRACTION` solids. ``air_velocity`` is the superficial
    (solved) one; see the module docstring for the slip."""
    from drumflow.physics.particle_air import GUNN_VOIDAGE, gunn_h, ranz_marshall_h

    if film not in FILM:
        raise AnalysisInputError("film", film, " or ".join(FILM))

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
    if film == "gunn":
        h = gunn_h(superficial_slip(phi, U, vp), np.clip(eps, *GUNN_VOIDAGE), diameter, air)
    else:
        h = ranz_marshall_h(np.linalg.norm(U - vp, axis=1), diameter, air)
    return h, np.where(phi >= POROUS_FRACTION,
                       h * 6.0 * phi / diameter / (air.density * heat_capacity), 0.0)


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
    nut = _read_nut(case_dir, time_dir, len(volumes))
    return float(np.average(nut, weights=volumes)) / TURBULENT_PRANDTL + nu / prandtl


def cell_diffusivity(nut: NDArray[np.float64], fraction: NDArray[np.float64],
                     slip: NDArray[np.float64], diameter: float, nu: float,
                     prandtl: float) -> NDArray[np.float64]:
    """D per cell, m^2/s, for ``mixing="local"`` (module docstring): nu / Pr + nu_t / 0.85
    outside the bed; eps nu / Pr + :data:`BED_DISPERSION` |u_s| d in the bed's cells."""
    phi = np.asarray(fraction, float)
    for name, a in (("nut", nut), ("fraction", phi), ("slip", slip)):
        _finite(name, np.asarray(a, float))
    if np.any(np.asarray(nut) < 0.0):
        raise AnalysisInputError("nut", float(np.min(nut)), "viscosities >= 0 (m^2/s)")
    free = nu / prandtl + np.asarray(nut, float) / TURBULENT_PRANDTL
    packed = (1.0 - phi) * nu / prandtl + BED_DISPERSION * np.asarray(slip, float) * diameter
    return np.asarray(np.where(categorize(phi) == 0, packed, free), float)


def _read_nut(case_dir: Path, time_dir: str, n: int) -> NDArray[np.float64]:
    from foamlib import FoamFieldFile

    path = case_dir / time_dir / "nut"
    if not path.exists():  # laminar
        return np.zeros(n)
    return np.broadcast_to(np.asarray(FoamFieldFile(path).internal_field, float), (n,)).copy()


def _check_converged(bed_dir: Path) -> None:
    """Refuse a bed case whose simpleFoam log does not say converged (a heat-only rerun)."""
    from drumflow.air.foam_results import ResidualParser

    log = bed_dir / "log.simpleFoam"
    parser = ResidualParser()
    for line in log.read_text(errors="replace").splitlines() if log.is_file() else []:
        parser(line)
    if not parser.converged:
        raise AnalysisInputError(f"{bed_dir}", "no converged bed-air solution",
                                 "a bed case solved by drumflow bed-air in this work folder")


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
    mixing, diffusivity_m2_s, diffusivity_by_category_m2_s
        One of :data:`MIXING`; D's volume mean, and over the bed, curtain and free-air cells.
    flux, film
        The transport flux (:data:`~drumflow.air.transport_flux.FLUX`) and the film law
        (:data:`FILM`) the heat was solved with.
    zones, binning_error, voidage_clipped_cells
        Source zones; heat with each cell's own k and T_p at the
        solved T over heat_W, less 1; source cells whose voidage was raised to Gunn's 0.35.
    iterations, wall_time_s, fields
        The temperature solve's outer iterations; s taken; per cell T, k (1/s) and T_p (degC).
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
    diffusivity_by_category_m2_s: dict[str, float]
    zones: int
    binning_error: float
    voidage_clipped_cells: int
    iterations: int
    wall_time_s: float
    fields: dict[str, NDArray[np.float64]] = field(repr=False, default_factory=dict)
    flux: str = "relative"
    film: str = "gunn"

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


def solve_bed_heat(result: BedAirResult | None, state: HeatSnapshot, case: Case, runner: Runner,
                   workdir: Path, *, spacing: float | None = None,
                   timeout: float | None = 3600.0, k_bins: int = K_BINS, t_bins: int = T_BINS,
                   residual: float = 1e-6, mixing: str = "local", flux: str = "relative",
                   film: str = "gunn") -> BedHeatResult:
    """The heat the air takes from ``state``'s particles in the bed case that
    :func:`~drumflow.air.bed_air.solve_bed_air` solved (``result``) in ``workdir``
    (``workdir/bed``); the temperature case goes to ``workdir/heat``. ``result=None`` reuses
    a bed case solved earlier in ``workdir`` (its simpleFoam log must say converged): the
    state is deposited again on its cells, as :func:`~drumflow.air.bed_air.solve_bed_air`
    did (the caller makes sure the case was solved for this state: the CLI checks the
    ``split.json`` it wrote). ``spacing``: the
    deposition grid's, as given to :func:`~drumflow.air.bed_air.solve_bed_air` (default
    alike); ``k_bins``, ``t_bins``: :func:`bin_heat_sources`; ``residual``: the outer
    iterations' target (:func:`solve_air_temperature`); ``mixing``: one of :data:`MIXING`;
    ``flux``: one of :data:`~drumflow.air.transport_flux.FLUX`; ``film``: one of :data:`FILM`.

    Raises
    ------
    drumflow.errors.AnalysisInputError
        A NaN particle temperature or velocity, a bad diameter or solids fraction, mixing,
        flux or film, or (``result=None``) no converged bed case in ``workdir``.
    drumflow.errors.SolverError
        topoSet or scalarTransportFoam failed.
    """
    from drumflow.air.foam_case import air_properties_for
    from drumflow.air.foam_results import latest_time, read_cell_fields
    from drumflow.air.poly_mesh import read_poly_mesh
    from drumflow.air.transport_flux import transport_flux
    from drumflow.geometry.fluid import fluid_mesh_size
    from drumflow.physics.air import specific_heat
    from drumflow.physics.drum_frame import rotate_to_drum_frame
    from drumflow.physics.particle_air import GUNN_VOIDAGE, AirState

    check_choices(mixing, flux, film)
    t0 = time.perf_counter()
    temps = np.asarray(state.temperatures_C, float)
    _finite("temperatures_C", temps)
    _finite("velocities", np.asarray(state.velocities, float))
    bed_dir = Path(workdir) / "bed"
    if result is None:
        _check_converged(bed_dir)
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
    if result is None:
        from drumflow.air.bed_air import deposit_state

        fraction = deposit_state(case, state, mesh, cells, spacing).fraction
    else:
        fraction = result.fields["fraction"]
    diameter = case.particles.diameter
    _, k = exchange_rate(fraction, cells["U"], means[:, :3], diameter, air, cp, film)
    zones = bin_heat_sources(k, means[:, 3] - t_in, cells["V"], k_bins, t_bins)
    n = len(cells["V"])
    if mixing == "local":
        slip = superficial_slip(fraction, cells["U"], means[:, :3])
        diffusivity = cell_diffusivity(_read_nut(bed_dir, time_dir, n), fraction, slip,
                                       diameter, nu, air.prandtl)
    else:
        diffusivity = np.full(n, turbulent_diffusivity(bed_dir, time_dir, cells["V"], nu,
                                                       air.prandtl)
                              if mixing == "turbulent" else nu / air.prandtl)
    category = categorize(fraction)
    d_split = {c: float(np.average(diffusivity[category == i], weights=cells["V"][category == i]))
               for i, c in enumerate(CATEGORIES) if np.any(category == i)}
    internal = None
    if flux != "relative":
        from foamlib import FoamFieldFile

        solved_phi = np.asarray(FoamFieldFile(bed_dir / time_dir / "phi").internal_field, float)
        carried = np.where((category == 0)[:, None], (1.0 - fraction)[:, None] * means[:, :3],
                           0.0)
        internal = transport_flux(mesh, solved_phi, case.drum.omega, flux, carried)
    solved = solve_air_temperature(bed_dir, time_dir, Path(workdir) / "heat", zones,
                                   diffusivity, runner, timeout, residual, internal)
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
        by_category=split, mixing=mixing, flux=flux, film=film,
        diffusivity_m2_s=float(np.average(diffusivity, weights=cells["V"])),
        diffusivity_by_category_m2_s=d_split, zones=len(zones.cells),
        binning_error=binning,
        voidage_clipped_cells=int(np.sum((k > 0) & (eps < GUNN_VOIDAGE[0]))),
        iterations=solved.iterations, wall_time_s=time.perf_counter() - t0,
        fields={"T": t_in + solved.theta, "k": k, "T_p": means[:, 3]})
