"""The grate-cooler case file: a validated TOML with one section per part of the model.

Every value outside its allowed range is reported at once, each naming the field, the value
and the range (:class:`drumflow.errors.CaseError`), before the solver starts. Units are SI,
temperatures in kelvin (the report's unit).

Layout::

    name = "grate_cooler_report"
    [cooler]    length, width, grate_speed
    [clinker]   mass_flow, inlet_temperature, particle_diameter, sphericity, bed_porosity,
                density, heat_capacity, heat_capacity_slope, conductivity,
                conductivity_slope, emissivity
    [air]       mass_flow, inlet_temperature, distribution, supply
    [fan]       shutoff_pressure, free_delivery        (only with air.supply = "fan")
    [model]     radiation, interior_resistance
    [numerics]  cells_length, cells_height, exchange, under_relaxation,
                residual_tolerance, energy_tolerance, max_sweeps
"""

from __future__ import annotations

from pathlib import Path
from typing import Any, Literal

from pydantic import BaseModel, Field, model_validator

from drumflow.case import INPUT_MODEL_CONFIG, read_toml, validate_model
from drumflow.physics.air import AIR_T_MAX, AIR_T_MIN

__all__ = [
    "Air", "Clinker", "Cooler", "Fan", "GrateCase", "Model", "Numerics", "grate_case_from_dict",
    "load_grate_case",
]


#: Most balance cells (cells_length x cells_height) of one grid. Measured here (2 shared
#: cores): a sweep costs about 0.65 us per cell on large grids, so one sweep of 1,000,000
#: cells takes about 0.7 s and a converged solve (9 sweeps at under_relaxation = 1) about
#: 10 s; the old maxima (4000 x 2000 = 8,000,000 cells) needed gigabytes and minutes per
#: sweep. The report's grid is 120 x 90.
MAX_CELLS = 1_000_000

#: A line solve (one TDMA call and its set-up) costs about as much as this many cells:
#: measured 90 us per line against 0.65 us per cell (4000 x 2 cells: 0.36 s per sweep).
LINE_COST_CELLS = 140

#: Most work a solve may do before it gives up: numerics.max_sweeps x (cells +
#: LINE_COST_CELLS x lines), in cell-sweeps. 1e8 is about 65 s here (0.65 us each), the
#: report's case at its 2000 sweeps (8.0e7) included; a solve that converges stops long
#: before (9 sweeps at under_relaxation = 1, 90 at 0.5, 1,238 at 0.05 on the report's grid).
MAX_SWEEP_WORK = 100_000_000


class _Section(BaseModel):
    # Unknown keys are errors: a misspelt field must not fall back to a default silently.
    # The one input-model config (strict types, finite numbers): drumflow.case.
    model_config = INPUT_MODEL_CONFIG


class Cooler(_Section):
    """The grate: a rectangle of length x width carrying the clinker bed at the grate speed."""

    length: float = Field(gt=0, le=100, description="grate length L along the clinker path, m")
    width: float = Field(gt=0, le=20, description="grate width W, m")
    grate_speed: float = Field(gt=0, le=2, description="grate (and clinker plug-flow) speed, m/s")


class Clinker(_Section):
    """The clinker bed: plug flow of uniform particles at constant porosity.

    c_p(T) = heat_capacity + heat_capacity_slope * T and k(T) = conductivity +
    conductivity_slope * T, with T in K; both must stay positive between the air and clinker
    inlet temperatures.
    """

    mass_flow: float = Field(gt=0, le=500, description="clinker mass flow, kg/s")
    inlet_temperature: float = Field(gt=AIR_T_MIN, le=AIR_T_MAX,
                                     description="clinker temperature at the kiln outlet, K")
    particle_diameter: float = Field(gt=0, le=0.2, description="clinker nodule diameter d_p, m")
    sphericity: float = Field(1.0, gt=0, le=1, description="particle sphericity psi (1 = sphere)")
    bed_porosity: float = Field(gt=0.2, lt=0.8, description="bed void fraction eps")
    density: float = Field(gt=500, le=6000, description="clinker (particle) density, kg/m3")
    heat_capacity: float = Field(gt=0, le=5000,
                                 description="c_p at T = 0 K of the linear c_p(T), J/(kg K)")
    heat_capacity_slope: float = Field(0.0, ge=-2, le=2, description="d c_p / dT, J/(kg K2)")
    conductivity: float = Field(gt=0, le=50, description="k at T = 0 K of the linear k(T), W/(m K)")
    conductivity_slope: float = Field(0.0, ge=-0.02, le=0.02, description="d k / dT, W/(m K2)")
    emissivity: float = Field(ge=0, le=1, description="emissivity of the bed top surface")


class Air(_Section):
    """The cooling air, blown up through the grate and collected in the freeboard."""

    mass_flow: float = Field(gt=0, le=5000, description="total cooling-air mass flow, kg/s")
    inlet_temperature: float = Field(ge=AIR_T_MIN, le=1000, description="air temperature below the grate, K")
    distribution: list[float] = Field(
        default_factory=lambda: [1.0], min_length=1, max_length=100,
        description="relative air flux of equal-length grate compartments, kiln end first "
        "(normalised; [1.0] = uniform, the report's Eq. 16)",
    )

    supply: Literal["fixed", "fan"] = Field(
        "fixed", description="'fixed': mass_flow is blown whatever the bed's resistance (the "
        "report); 'fan': the [fan] curve against the bed's Ergun pressure drop sets the flow, "
        "and mass_flow is only the first guess of the operating point")

    @model_validator(mode="after")
    def _positive_weights(self) -> Air:
        bad = [f"air.distribution[{i}] = {w}: must be > 0 (a compartment without air leaves "
               "its clinker uncooled and its cells undefined)"
               for i, w in enumerate(self.distribution) if not w > 0]
        if bad:
            raise ValueError("\n".join(bad))
        return self


class Fan(_Section):
    """The cooling-air fan(s) as one pressure-flow curve (used with ``air.supply = "fan"``).

    Delta p_fan(Q) = shutoff_pressure [1 - (Q / free_delivery)^2], Q the volume flow at the
    air inlet temperature and 1 atm (a fan moves a volume at its speed); without
    free_delivery the curve is flat, a fixed fan pressure. The air shares of the compartments
    stay air.distribution (dampers hold them); the fan's pressure rise is the flow-weighted
    mean of the columns' bed pressure drops (see :mod:`drumflow.coolers.grate.fans`).
    """

    shutoff_pressure: float = Field(gt=0, le=50_000,
                                    description="fan pressure rise at zero flow, Pa")
    free_delivery: float | None = Field(
        None, gt=0, le=10_000, description="volume flow at zero pressure rise, m3/s at the air "
        "inlet temperature and 1 atm (omitted: a flat curve, the fixed fan pressure)")


class Model(_Section):
    """Physics switches."""

    radiation: bool = Field(True, description="radiation from the bed top to the freeboard air "
                            "(off reproduces the report's Figure 8)")
    interior_resistance: Literal["none", "jeschar"] = Field(
        "none", description="'none': cells are bed volumes at one temperature (the report); "
        "'jeschar': add the particle's internal resistance d_p/(10 k) to 1/h")


class Numerics(_Section):
    """Grid and solver controls."""

    cells_length: int = Field(120, ge=2, le=4000, description="balance cells along the grate, n")
    cells_height: int = Field(90, ge=1, le=2000, description="balance cells over the bed height, m")
    exchange: Literal["mean", "outlet"] = Field(
        "mean", description="temperatures a cell's convection acts on: 'outlet' = the cell's "
        "outlet temperatures (the report's Eqs. 8 and 21, first order in the cell size), "
        "'mean' = the means of what enters and leaves the cell (second order)")
    under_relaxation: float = Field(1.0, gt=0, le=1, description="under-relaxation factor alpha_T")
    residual_tolerance: float = Field(1e-9, gt=0, le=1e-2, description=
                                      "summed absolute cell imbalance / clinker heat duty at convergence")
    energy_tolerance: float = Field(1e-9, gt=0, le=1e-2, description=
                                    "|clinker heat lost - air heat gained| / clinker heat lost")
    max_sweeps: int = Field(2000, ge=1, le=100_000, description="sweep limit before giving up")


class GrateCase(_Section):
    """A grate-cooler case."""

    name: str = Field("grate", min_length=1, max_length=100, pattern=r"^[A-Za-z0-9_.-]+$",
                      description="case name (default run directory runs/cooler/grate/<name>)")
    cooler: Cooler
    clinker: Clinker
    air: Air
    fan: Fan | None = None
    model: Model = Field(default_factory=Model)
    numerics: Numerics = Field(default_factory=Numerics)

    @model_validator(mode="after")
    def _consistent(self) -> GrateCase:
        problems: list[str] = []
        c, a = self.clinker, self.air
        if c.inlet_temperature <= a.inlet_temperature:
            problems.append(
                f"clinker.inlet_temperature = {c.inlet_temperature} K: must be above "
                f"air.inlet_temperature ({a.inlet_temperature} K) for a cooler")
        lo, hi = a.inlet_temperature, c.inlet_temperature
        for field, base, slope in (("heat_capacity", c.heat_capacity, c.heat_capacity_slope),
                                   ("conductivity", c.conductivity, c.conductivity_slope)):
            low_end = min(base + slope * lo, base + slope * hi)
            if low_end <= 0:
                problems.append(
                    f"clinker.{field}_slope = {slope}: makes clinker.{field} {low_end:.4g} <= 0 "
                    f"between {lo:g} K and {hi:g} K; allowed: positive over that range")
        if a.supply == "fan" and self.fan is None:
            problems.append("air.supply = 'fan': needs a [fan] section (shutoff_pressure, "
                            "optional free_delivery)")
        if a.supply == "fixed" and self.fan is not None:
            problems.append("[fan] given with air.supply = 'fixed', which would ignore it; "
                            "allowed: air.supply = 'fan' with [fan], or no [fan]")
        problems += _size_problems(self.numerics)
        if problems:
            raise ValueError("\n".join(problems))
        return self

    @property
    def bed_height(self) -> float:
        """Bed height from plug flow: H = m_s / (rho_s (1 - eps) v_g W), m."""
        c = self.clinker
        return c.mass_flow / (c.density * (1.0 - c.bed_porosity) * self.cooler.grate_speed
                              * self.cooler.width)


def _size_problems(num: Numerics) -> list[str]:
    """The grid and the sweep limit against what finishes here (MAX_CELLS, MAX_SWEEP_WORK)."""
    n, m = num.cells_length, num.cells_height
    cells = n * m
    if cells > MAX_CELLS:
        return [f"numerics.cells_length = {n:,} x numerics.cells_height = {m:,}: {cells:,} cells; "
                f"allowed up to {MAX_CELLS:,} (fewer cells along or across the bed)"]
    per_sweep = cells + LINE_COST_CELLS * (n + m)
    work = num.max_sweeps * per_sweep
    if work > MAX_SWEEP_WORK:
        return [f"numerics.max_sweeps = {num.max_sweeps:,} x ({cells:,} cells + "
                f"{LINE_COST_CELLS} x {n + m:,} lines) = {work:,} cell-sweeps; allowed up to "
                f"{MAX_SWEEP_WORK:,} (numerics.max_sweeps up to "
                f"{MAX_SWEEP_WORK // per_sweep:,} on this grid, or fewer cells)"]
    return []


def grate_case_from_dict(data: dict[str, Any], source: Path | str | None = None) -> GrateCase:
    """Validate a grate case given as nested dictionaries (raises ``CaseError``)."""
    return validate_model(GrateCase, data, source)


def load_grate_case(path: Path | str) -> GrateCase:
    """Read and validate a grate-cooler TOML case file.

    Raises
    ------
    CaseError
        When the file is missing, is not TOML, or holds values outside their ranges.
    """
    return grate_case_from_dict(read_toml(path), path)
