"""The whole flighted rotary cooler from a slice: axial cells, counter-current air, a curtain
and a bed in every cell.

The drum (length ``L``) is ``N`` axial cells. The solids enter at ``z = 0`` and advance in plug
flow; the air enters at ``z = L`` in plug flow (counter-current). In every cell the solids
hold-up is split between the air (the curtain of particles falling from the flights) and the
bed/flights, and one representative particle, whose interior is the shared shell model
(:class:`~drumflow.physics.particle_interior.SphereConduction`), goes through the cell's
cascade cycles: half a bed stay, a fall, half a bed stay, repeated. The heat it gives off
goes to the cell's air.

Closures, all from a slice run (:class:`~drumflow.analysis.closures.SliceClosures`), scaled to
the plant by the laws below (:func:`scale_closures`; each is reported with the result):

* hold-up per metre ``W = mdot_s tau / L`` with ``tau`` from the Friedman-Marshall law
  (:mod:`drumflow.coolers._transport`), its one constant calibrated to the plant's measured
  residence time;
* falling mass flow per metre ``G_f = n_c W rpm / 60`` with ``n_c`` the slice's falls per
  particle per revolution (a flight empties its load once a turn);
* fall height ``H_f`` proportional to the drum diameter (geometric similarity of flights);
* fall time and the slip along the fall from a drag-ballistic fall through ``H_f``
  (:mod:`drumflow.coolers._fall`), checked against the slice's measured fall time;
* airborne fraction ``phi = G_f t_f / W`` (Little's law), compared with the slice's;
* bed exposed surface: the slice's, scaled with the chord of the bed segment at each drum's
  bed volume.

Heat transfer. Falling particles: the curtain model (:mod:`drumflow.coolers.curtain`) in the
limit where the curtain's gas is the cell's air (it crosses the curtain along the drum, and
one cell's curtain warms it by ``O(1/N)``): particles exposed for ``t_f`` at the Ranz-Marshall
``h`` of their slip. Bed: only its exposed surface exchanges, at the Ranz-Marshall ``h`` of
the axial air speed, shared by all bed particles (a particle reaches the surface many times
per cell). Optional wall loss ``U_w pi D dz (T_solids - T_ambient)`` from the solids (off by
default). Air temperature seen in a cell: the mean of its inlet and outlet (second order in
the cell length). Air properties at the cell's air temperature.

Solution: the shell model is linear at a fixed ``h``, so a whole cell is one matrix
(:mod:`drumflow.coolers._propagator`), and the air outlet temperature that makes the air enter
at its inlet temperature is found exactly (the march is affine in it). The air properties
(hence ``h``) are updated from the air profile until it moves less than 1e-6 K. Energy closes
to round-off: every cell's heat is the particles' enthalpy change.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

from drumflow.analysis.closures import SliceClosures
from drumflow.coolers._curtain_pass import curtain_pass
from drumflow.coolers._propagator import exposure_matrix
from drumflow.coolers._transport import TransportLaw
from drumflow.coolers.drum_closures import PRESSURE_KPA, PlantClosures, scale_closures
from drumflow.coolers.plant import PlantSpec
from drumflow.errors import DrumModelError
from drumflow.physics.exchanger import ExchangerResult, solve_outlet_temperature
from drumflow.physics.particle_air import AirState, ranz_marshall_h
from drumflow.physics.particle_interior import Sphere, SphereConduction

FloatArray = NDArray[np.float64]

__all__ = [
    "DrumOptions",
    "DrumResult",
    "DrumModelError",
    "paper_exchanger",
    "solve_drum",
    "volumetric_coefficient_estimate",
]

#: Conductivity standing for a lumped particle (Bi -> 0), W/(m K).
LUMPED_CONDUCTIVITY = 1.0e4
#: Largest through-curtain flow accepted, m^3/s per metre of drum: far beyond where the result
#: has reached the all-air limit (the plant's drum carries ~1 m^3/s per metre axially).
MAX_CURTAIN_AIR_M3_S_M = 1.0e4


@dataclass(frozen=True)
class DrumOptions:
    """Model choices.

    Attributes
    ----------
    cells
        Axial cells ``N``.
    shells
        Shells of the particle-interior solver.
    wall_loss_w_m2k
        Overall wall-loss coefficient from the solids to ambient over the shell area; 0 (off)
        by default.
    ambient_temperature_c
        Ambient temperature of the wall loss.
    lumped_particles
        Replace the particle conductivity by a very large one (Bi -> 0), to measure what the
        interior conduction changes.
    bed_exchange
        Include the bed-surface term.
    curtain_air_m3_s_m
        Air that passes through the curtains, m^3/s per metre of drum (volume at the air
        inlet temperature). ``None`` (the default): all the air meets every falling granule,
        the curtain model in the limit where the curtain's gas is the cell's air (an unbounded
        through-curtain flow; the model before issue 34, kept as this setting). A number: that
        stream runs through the curtain model and mixes back, the rest bypasses the curtains
        (module notes, "Air through the curtains").
    curtain_rows
        Rows of the curtain's element array with a through-curtain flow.
    """

    cells: int = 40
    shells: int = 10
    wall_loss_w_m2k: float = 0.0
    ambient_temperature_c: float = 30.0
    lumped_particles: bool = False
    bed_exchange: bool = True
    curtain_air_m3_s_m: float | None = None
    curtain_rows: int = 5

    def __post_init__(self) -> None:
        if not 1 <= self.cells <= 5000:
            raise DrumModelError(f"cells = {self.cells}: allowed 1 to 5000")
        if not 2 <= self.shells <= 200:
            raise DrumModelError(f"shells = {self.shells}: allowed 2 to 200")
        if not (self.wall_loss_w_m2k >= 0 and math.isfinite(self.wall_loss_w_m2k)):
            raise DrumModelError(f"wall_loss_w_m2k = {self.wall_loss_w_m2k}: allowed >= 0")
        q = self.curtain_air_m3_s_m
        if q is not None and not (math.isfinite(q) and 0.0 <= q <= MAX_CURTAIN_AIR_M3_S_M):
            raise DrumModelError(
                f"curtain_air_m3_s_m = {q}: allowed 0 to {MAX_CURTAIN_AIR_M3_S_M:g} m3/s per "
                "metre of drum, or None (all the air meets every falling granule)"
            )
        if not 1 <= self.curtain_rows <= 50:
            raise DrumModelError(f"curtain_rows = {self.curtain_rows}: allowed 1 to 50")

    @property
    def all_air_meets_curtain(self) -> bool:
        """True for the limit where the curtain's gas is the cell's air (no through-curtain
        flow given)."""
        return self.curtain_air_m3_s_m is None


@dataclass(frozen=True)
class DrumResult:
    """The whole-cooler prediction (temperatures deg C, heats W, lengths m).

    Attributes
    ----------
    material_outlet_c, air_outlet_c
        Solids and air outlet temperatures.
    heat_to_air_w, heat_curtain_w, heat_bed_w, wall_loss_w
        Heat the air takes (curtain + bed) and the wall loss to ambient.
    curtain_share
        Share of the heat to air removed by the curtain.
    z_m, solids_c, air_c
        Axial cell faces (0 = solids inlet), the solids mean temperature and the air
        temperature there.
    cell_curtain_w, cell_bed_w, cell_wall_w
        Per-cell heats.
    energy_residual
        ``(solids enthalpy loss - air gain - wall loss) / solids enthalpy loss``.
    curtain_air_kg_s_m
        Through-curtain air per metre of drum, kg/(s m) (``inf``: all the air meets the
        curtain).
    cell_curtain_air_out_c
        Temperature of the through-curtain air leaving each cell's curtain (the cell's air
        when all the air meets the curtain).
    curtain_saturation
        Heat-weighted mean over the cells of how close the through-curtain air comes to the
        particles: ``(T_out - T_air) / (T_solids - T_air)``, 1 for a saturated curtain (NaN
        when all the air meets the curtain).
    """

    plant: PlantSpec
    options: DrumOptions
    law: TransportLaw
    scaled: PlantClosures
    material_outlet_c: float
    air_outlet_c: float
    heat_to_air_w: float
    heat_curtain_w: float
    heat_bed_w: float
    wall_loss_w: float
    curtain_share: float
    z_m: FloatArray
    solids_c: FloatArray
    air_c: FloatArray
    cell_curtain_w: FloatArray
    cell_bed_w: FloatArray
    cell_wall_w: FloatArray
    h_fall_w_m2k: float
    h_bed_surface_w_m2k: float
    biot_fall: float
    energy_residual: float
    property_iterations: int
    curtain_air_kg_s_m: float
    cell_curtain_air_out_c: FloatArray
    curtain_saturation: float
    warnings: list[str] = field(default_factory=list)

    @property
    def duty_w(self) -> float:
        """Heat removed from the solids (to air and through the wall)."""
        return self.heat_to_air_w + self.wall_loss_w

    def air_streams(self) -> dict[str, Any]:
        """The axial air split into the stream through the curtains and the bypass.

        Per cell, ``through_share_per_cell`` of the axial air crosses the cell's curtains and
        mixes back; the rest bypasses them. ``curtain_passes`` is the through-curtain mass over
        the drum divided by the axial air: how many curtains the air meets on its way (below 1,
        the share of the air that meets any).
        """
        plant = self.plant
        q = self.options.curtain_air_m3_s_m
        if q is None:
            return {
                "setting": "all",
                "note": "all the air meets every falling granule: the curtain's gas is the "
                        "cell's air (the limit of an unbounded through-curtain flow)",
                "through_curtain_m3_s_per_m": None,
                "through_curtain_kg_s_total": None,
                "through_share_per_cell": 1.0,
                "bypass_share_per_cell": 0.0,
                "curtain_passes": None,
                "curtain_saturation": None,
            }
        dz = plant.length_m / self.options.cells
        total = self.curtain_air_kg_s_m * plant.length_m
        share = self.curtain_air_kg_s_m * dz / plant.air_mass_flow_kg_s
        return {
            "setting": "through-curtain flow",
            "note": "the through-curtain stream runs through the curtain model (a dense curtain "
                    "saturates it) and mixes back; the rest of the air bypasses the curtains",
            "through_curtain_m3_s_per_m": q,
            "through_curtain_kg_s_total": total,
            "through_share_per_cell": share,
            "bypass_share_per_cell": max(0.0, 1.0 - share),
            "curtain_passes": total / plant.air_mass_flow_kg_s,
            "curtain_saturation": self.curtain_saturation,
            "axial_air_kg_s": plant.air_mass_flow_kg_s,
        }

    def to_dict(self) -> dict[str, Any]:
        return {
            "material_outlet_temperature_C": self.material_outlet_c,
            "air_outlet_temperature_C": self.air_outlet_c,
            "heat_duty_W": self.duty_w,
            "heat_to_air_W": self.heat_to_air_w,
            "heat_curtain_W": self.heat_curtain_w,
            "heat_bed_W": self.heat_bed_w,
            "wall_loss_W": self.wall_loss_w,
            "curtain_share": self.curtain_share,
            "h_fall_W_m2K": self.h_fall_w_m2k,
            "h_bed_surface_W_m2K": self.h_bed_surface_w_m2k,
            "biot_fall": self.biot_fall,
            "energy_residual": self.energy_residual,
            "property_iterations": self.property_iterations,
            "air_streams": self.air_streams(),
            "plant": asdict(self.plant),
            "options": asdict(self.options),
            "transport_law": asdict(self.law),
            "plant_closures": asdict(self.scaled),
            "profile": {
                "z_m": self.z_m.tolist(),
                "solids_C": self.solids_c.tolist(),
                "air_C": self.air_c.tolist(),
                "cell_curtain_W": self.cell_curtain_w.tolist(),
                "cell_bed_W": self.cell_bed_w.tolist(),
                "cell_wall_W": self.cell_wall_w.tolist(),
                "cell_curtain_air_out_C": self.cell_curtain_air_out_c.tolist(),
            },
            "warnings": list(self.warnings),
        }


def _phase(exposure: FloatArray, capacities: FloatArray, accumulator: int) -> FloatArray:
    """Exposure matrix on the state [T, T_air, Q_fall, Q_bed], adding the heat given off."""
    n = len(capacities)
    mat = np.eye(n + 3)
    mat[: n + 1, : n + 1] = exposure
    mat[accumulator, :n] = capacities - capacities @ exposure[:n, :n]
    mat[accumulator, n] = -(capacities @ exposure[:n, n])
    return mat


@dataclass(frozen=True)
class _CurtainStream:
    """The curtain of one cell and the air that crosses it (module notes)."""

    particle_rate: float  #: particles falling through the cell's curtain per second
    gas_capacity_rate_w_k: float  #: through-curtain air of the cell, mass flow x c_p
    rows: int


def _cell_matrix(model: SphereConduction, h_fall: float, h_bed: float, fall_time: float,
                 bed_time: float, cycles: float,
                 curtain: _CurtainStream | None = None) -> FloatArray:
    """Map of a particle's state over one cell: ``cycles`` of (bed/2, fall, bed/2).

    Without ``curtain`` a fall exposes the particle to the cell's air itself (all the air meets
    the curtain); with it, a fall is one pass through the curtain model crossed by the
    through-curtain stream entering at the cell's air temperature.
    """
    n = model.shells
    caps = model.capacities

    def fall_exposure(fraction: float) -> FloatArray:
        if curtain is None:
            return exposure_matrix(model, h_fall, fraction * fall_time)
        # A part-cycle is a shorter fall through a proportionally smaller share of the air:
        # the air per particle-second of exposure, hence the curtain's saturation, is kept.
        return curtain_pass(model, h_fall, fraction * fall_time, curtain.particle_rate,
                            fraction * curtain.gas_capacity_rate_w_k, curtain.rows).matrix

    def cycle(fraction: float) -> FloatArray:
        fall = _phase(fall_exposure(fraction), caps, n + 1)
        bed = _phase(exposure_matrix(model, h_bed, 0.5 * fraction * bed_time), caps, n + 2)
        return bed @ fall @ bed

    whole = int(math.floor(cycles))
    rest = cycles - whole
    mat = np.linalg.matrix_power(cycle(1.0), whole) if whole else np.eye(n + 3)
    if rest > 1e-12:
        mat = cycle(rest) @ mat
    return mat


@dataclass(frozen=True)
class _CellMarch:
    """One pass of the solids through the cells, inlet to outlet, against counter-current air.

    Each cell's exchange is affine in the air temperature it sees (its matrices, built for the
    air properties of the last pass), so a pass from a guessed air outlet temperature is exact
    for that guess: :func:`solve_drum` finds the outlet from two passes.
    """

    plant: PlantSpec
    opt: DrumOptions
    model: SphereConduction
    sphere: Sphere
    rate: float  #: particles per second
    c_air: float  #: air heat-capacity rate, W/K
    wall_area: float  #: shell area of one cell, m2

    def march(self, mats: list[FloatArray], unit: list[FloatArray],
              t_air_out: float) -> tuple[FloatArray, ...]:
        """Solids and air temperatures at the cell faces, each cell's curtain, bed and wall
        heat (W), the air temperature each cell saw, and the solids' state at the outlet."""
        plant, opt, model, sphere = self.plant, self.opt, self.model, self.sphere
        rate, c_air, wall_area = self.rate, self.c_air, self.wall_area
        n = model.shells
        cells = len(mats)
        state = model.uniform(plant.material_inlet_temperature_c)
        t_out = t_air_out
        solids = [model.mean_temperature(state)]
        air_faces = [t_out]
        q_f = np.empty(cells)
        q_b = np.empty(cells)
        q_w = np.empty(cells)
        seen = np.empty(cells)
        for i in range(cells):
            base = mats[i] @ np.concatenate([state, [0.0, 0.0, 0.0]])
            a_f, a_b = rate * base[n + 1], rate * base[n + 2]
            b_f, b_b = rate * unit[i][n + 1], rate * unit[i][n + 2]
            b = b_f + b_b
            denominator = 1.0 + 0.5 * b / c_air
            if denominator <= 0.1:
                raise DrumModelError(
                    f"cells = {cells}: a cell exchanges more than the air can carry at "
                    f"{plant.air_mass_flow_kg_s:g} kg/s; use more cells"
                )
            heat = (a_f + a_b + b * t_out) / denominator
            t_mean = t_out - 0.5 * heat / c_air
            seen[i] = t_mean
            new = base[:n] + unit[i][:n] * t_mean
            q_f[i] = a_f + b_f * t_mean
            q_b[i] = a_b + b_b * t_mean
            t_in_air = t_out - (q_f[i] + q_b[i]) / c_air
            if opt.wall_loss_w_m2k > 0:
                t_solid = 0.5 * (model.mean_temperature(state) + model.mean_temperature(new))
                q_w[i] = opt.wall_loss_w_m2k * wall_area * (t_solid - opt.ambient_temperature_c)
                new = new - q_w[i] / (rate * sphere.mass * sphere.heat_capacity)
            else:
                q_w[i] = 0.0
            state = new
            t_out = t_in_air
            solids.append(model.mean_temperature(state))
            air_faces.append(t_out)
        return (np.array(solids), np.array(air_faces), q_f, q_b, q_w, seen, state)


def solve_drum(plant: PlantSpec, closures: SliceClosures, law: TransportLaw,
               options: DrumOptions | None = None) -> DrumResult:
    """Predict the plant's outlets from slice closures (module notes).

    Parameters
    ----------
    plant
        The cooler and its streams.
    closures
        Closures of a slice run (:func:`drumflow.analysis.closures.extract_closures`, or
        hand-made for tests).
    law
        The residence-time law (calibrated with :func:`drumflow.coolers._transport.calibrate`).
    options
        Model choices.

    Raises
    ------
    DrumModelError
        When the conditions leave what the model can represent (message names the quantity).
    """
    opt = options or DrumOptions()
    if plant.material_inlet_temperature_c <= plant.air_inlet_temperature_c:
        raise DrumModelError(
            f"material_inlet_temperature_c = {plant.material_inlet_temperature_c}: must be above "
            f"the air inlet ({plant.air_inlet_temperature_c} C) for a cooler"
        )
    scaled = scale_closures(plant, closures, law)
    k = LUMPED_CONDUCTIVITY if opt.lumped_particles else plant.particle_conductivity_w_mk
    sphere = Sphere(plant.particle_diameter_m, k, plant.particle_density_kg_m3,
                    plant.particle_heat_capacity_j_kgk)
    model = SphereConduction(sphere, shells=opt.shells)
    n = model.shells
    cells = opt.cells
    dz = plant.length_m / cells
    rate = plant.feed_rate_kg_s / sphere.mass  # particles per second
    c_air = plant.air_mass_flow_kg_s * plant.air_heat_capacity_j_kgk
    cell_time = scaled.residence_time_s / cells
    cycles = cell_time / scaled.cycle_time_s
    bed_time = scaled.cycle_time_s - scaled.fall_time_s
    bed_particles_per_m = (1.0 - scaled.airborne_fraction) * scaled.holdup_kg_per_m / sphere.mass
    # Bed surface shared by every bed particle: the film coefficient each sees on average.
    bed_share = scaled.bed_surface_m2_per_m / (bed_particles_per_m * sphere.surface)
    if not opt.bed_exchange:
        bed_share = 0.0
    marcher = _CellMarch(plant, opt, model, sphere, rate, c_air, math.pi * plant.diameter_m * dz)
    # The through-curtain stream of one cell (module notes, "Air through the curtains"): its
    # volume is given at the air inlet temperature, so its mass flow is the same in every cell.
    rho_in = AirState.at(plant.air_inlet_temperature_c, PRESSURE_KPA).density
    curtain_stream: _CurtainStream | None = None
    curtain_air_kg_s_m = math.inf
    if opt.curtain_air_m3_s_m is not None:
        curtain_air_kg_s_m = rho_in * opt.curtain_air_m3_s_m
        curtain_stream = _CurtainStream(
            particle_rate=scaled.falling_mass_flow_kg_s_m * dz / sphere.mass,
            gas_capacity_rate_w_k=curtain_air_kg_s_m * dz * plant.air_heat_capacity_j_kgk,
            rows=opt.curtain_rows,
        )

    def film(t_air: float) -> tuple[float, float]:
        air = AirState.at(t_air, PRESSURE_KPA)
        h_fall = float(ranz_marshall_h(scaled.fall_effective_slip_m_s, sphere.diameter, air))
        h_surface = float(ranz_marshall_h(scaled.axial_air_velocity_m_s, sphere.diameter, air))
        return h_fall, h_surface

    # First guess of the air profile: a linear profile with the air taking 70 % of the heat
    # the solids could give (only sets the first air properties).
    c_solids = plant.feed_rate_kg_s * plant.particle_heat_capacity_j_kgk
    guess_out = plant.air_inlet_temperature_c + 0.7 * c_solids * (
        plant.material_inlet_temperature_c - plant.air_inlet_temperature_c) / c_air
    seen = np.linspace(guess_out, plant.air_inlet_temperature_c, cells)
    iterations = 0
    h_fall = h_surface = math.nan
    for iterations in range(1, 31):  # noqa: B007  (the count is reported)
        mats: list[FloatArray] = []
        units: list[FloatArray] = []
        for i in range(cells):
            h_fall, h_surface = film(float(seen[i]))
            mat = _cell_matrix(model, h_fall, h_surface * bed_share, scaled.fall_time_s,
                               bed_time, cycles, curtain_stream)
            mats.append(mat)
            unit_state = np.zeros(n + 3)
            unit_state[n] = 1.0
            units.append(mat @ unit_state)
        # The march is affine in the air outlet temperature: two marches find it exactly.
        lo, hi = plant.air_inlet_temperature_c, plant.material_inlet_temperature_c
        r_lo = marcher.march(mats, units, lo)[1][-1] - plant.air_inlet_temperature_c
        r_hi = marcher.march(mats, units, hi)[1][-1] - plant.air_inlet_temperature_c
        t_ao = lo - r_lo * (hi - lo) / (r_hi - r_lo)
        solids, air_faces, q_f, q_b, q_w, new_seen, final = marcher.march(mats, units, t_ao)
        change = float(np.max(np.abs(new_seen - seen)))
        seen = new_seen
        if change < 1e-6:
            break
    h_fall, h_surface = film(float(np.mean(seen)))
    heat_air = float(q_f.sum() + q_b.sum())
    wall = float(q_w.sum())
    t_mo = float(model.mean_temperature(final))
    solids_loss = c_solids * (plant.material_inlet_temperature_c - t_mo)
    air_gain = c_air * (air_faces[0] - plant.air_inlet_temperature_c)
    residual = (solids_loss - air_gain - wall) / solids_loss
    # The through-curtain air leaving each cell's curtain: it carries the curtain's heat.
    if curtain_stream is None or curtain_stream.gas_capacity_rate_w_k == 0.0:
        curtain_out = seen.copy()
    else:
        curtain_out = seen + q_f / curtain_stream.gas_capacity_rate_w_k
    solids_cell = 0.5 * (solids[1:] + solids[:-1])
    with np.errstate(divide="ignore", invalid="ignore"):
        approach = np.where(solids_cell > seen,
                            (curtain_out - seen) / (solids_cell - seen), np.nan)
    weights = np.abs(q_f)
    saturation = (float(np.sum(weights * np.nan_to_num(approach)) / weights.sum())
                  if curtain_stream is not None and weights.sum() > 0 else math.nan)
    warnings: list[str] = []
    if change >= 1e-6:
        warnings.append(f"air properties did not settle: last change {change:.2g} K")
    return DrumResult(
        plant=plant,
        options=opt,
        law=law,
        scaled=scaled,
        material_outlet_c=t_mo,
        air_outlet_c=float(air_faces[0]),
        heat_to_air_w=heat_air,
        heat_curtain_w=float(q_f.sum()),
        heat_bed_w=float(q_b.sum()),
        wall_loss_w=wall,
        curtain_share=float(q_f.sum()) / heat_air if heat_air else math.nan,
        z_m=np.linspace(0.0, plant.length_m, cells + 1),
        solids_c=solids,
        air_c=air_faces,
        cell_curtain_w=q_f,
        cell_bed_w=q_b,
        cell_wall_w=q_w,
        h_fall_w_m2k=h_fall,
        h_bed_surface_w_m2k=h_surface,
        biot_fall=sphere.biot(h_fall),
        energy_residual=residual,
        property_iterations=iterations,
        curtain_air_kg_s_m=curtain_air_kg_s_m,
        cell_curtain_air_out_c=curtain_out,
        curtain_saturation=saturation,
        warnings=warnings,
    )


def paper_exchanger(plant: PlantSpec) -> ExchangerResult:
    """The paper's exchanger prediction (Table 7, model one: h = 60.15, A_he = 1099.28 m2)
    with this plant's streams (Eqs. 42-48)."""
    return solve_outlet_temperature(h_w_m2k=60.15, area_m2=1099.28, **plant.streams())


#: Handbook volumetric coefficient of flighted rotary dryers: Ua = K G^0.67 / D in
#: Btu/(h ft^3 F), G in lb/(h ft^2), D in ft, K = 0.5; attributed to McCormick (1962) through
#: Perry's Chemical Engineers' Handbook (rotary dryers). In SI it is 237 G^0.67 / D, W/(m^3 K),
#: G in kg/(s m^2), D in m. Issue 34 checked it against a source it could read: Coulson and
#: Richardson's Chemical Engineering Vol. 2, chapter 16 (Drying), Example 16.5, sizes a rotary
#: dryer with L = Q / (0.0625 pi D G^0.67 dT_m) (as transcribed in FOSSEE's Scilab textbook
#: companion, FOSSEE/Scilab-TBC-Uploads 542/CH16/EX16.5), i.e. Ua = 0.25 G^0.67 / D kW/(m^3 K):
#: 250 against 237, 5 % apart, the same law. The Perry's page itself was not found to quote.
VOLUMETRIC_K = 0.5
_BTU_H_FT3_F = 18.6259  # W/(m^3 K)


def volumetric_coefficient_estimate(plant: PlantSpec) -> tuple[float, ExchangerResult]:
    """The textbook estimate: ``Ua`` (W/(m^3 K)) and the counter-current exchanger with
    ``U A = Ua V`` (V the drum volume) and this plant's streams."""
    ft = 0.3048
    area = math.pi * plant.diameter_m**2 / 4
    gas_lb = plant.air_mass_flow_kg_s / area / (0.45359237 / 3600 / ft**2)
    ua_imperial = VOLUMETRIC_K * gas_lb**0.67 / (plant.diameter_m / ft)
    ua = ua_imperial * _BTU_H_FT3_F
    volume = area * plant.length_m
    return ua, solve_outlet_temperature(h_w_m2k=ua, area_m2=volume, **plant.streams())
