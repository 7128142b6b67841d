"""A particle curtain falling through a horizontal gas stream: the element-array model of
Wardjiman and Rhodes (2009, Powder Technology 191, 247-253), with the shared particle-interior
solver.

The curtain (fall height ``H``, thickness ``delta`` in the gas direction, width ``W`` across
the duct) is split into ``M`` horizontal rows and ``N`` vertical columns. Gas crosses the
columns one after another in each row; particles fall through the rows one after another in
each column and carry their interior temperature profile to the element below (paper,
Section 3). In each element:

* the particles are exposed for their residence time ``dz / v_s`` (constant fall velocity
  ``v_s``, the paper's assumption) to gas at one temperature, with the film coefficient of
  Ranz and Marshall (paper Eq. 5, the same correlation as the slice coupling,
  :func:`drumflow.physics.particle_air.ranz_marshall_h`) at the superficial gas velocity;
* the particle interior is the Crank-Nicolson shell model
  :class:`~drumflow.physics.particle_interior.SphereConduction` with a convective surface
  (paper Eqs. 3-4);
* the gas leaving the element follows from the energy balance (paper Eqs. 7-10), with the gas
  mass flow of the row ``rho_g v_g eps W dz`` (Eq. 9; the area normal to the gas is the row's
  ``W dz``) and the curtain voidage ``eps = 1 - mdot_s / (rho_s v_s W delta)``.

Grid (paper Eqs. 1-2): ``t_c = delta / (v_g N)`` is the gas contact time of a column, and
``M = H / (v_s t_c)``, rounded to an integer, makes the particles' time per row equal to it.

One choice differs from the paper, and is written down here: the gas temperature the
particles of an element see is the mean of the element's gas inlet and outlet temperatures,
solved implicitly (the paper uses the inlet temperature). Both converge to the same curtain
as ``N`` grows; the mean is second order in the element size, and it keeps the model sound
in the limits: with no gas flow no heat is exchanged (the gas in the element takes the
particles' temperature), and with an infinite film coefficient particles and gas leave an
element at their common mixing temperature. Because the shell model is linear at a fixed
``h``, both are exact, not iterated (:mod:`drumflow.coolers._propagator`).

Energy closes to round-off: the heat each element passes to the gas is, by construction, the
particles' enthalpy change in it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any, Literal

import numpy as np
from numpy.typing import NDArray
from pydantic import BaseModel, Field, model_validator

from drumflow.case import INPUT_MODEL_CONFIG
from drumflow.coolers._propagator import exposure_matrix
from drumflow.physics import air as air_properties
from drumflow.physics.particle_air import AirState, ranz_marshall_h
from drumflow.physics.particle_interior import Sphere, SphereConduction

FloatArray = NDArray[np.float64]

__all__ = [
    "PAPER_GAS_TABLE",
    "CurtainCase",
    "CurtainResult",
    "GasProperties",
    "element_exchange",
    "gas_properties",
    "solve_curtain",
]

#: Wardjiman and Rhodes (2009), Table 1: air at 20 and 100 deg C (viscosity Pa s,
#: conductivity W/(m K), heat capacity J/(kg K), density kg/m^3). The paper interpolates
#: linearly between the two at the gas inlet temperature.
PAPER_GAS_TABLE: dict[str, tuple[float, float]] = {
    "temperature_C": (20.0, 100.0),
    "viscosity": (18.16e-6, 21.9e-6),
    "conductivity": (25.9e-3, 32.1e-3),
    "heat_capacity": (1005.0, 1009.0),
    "density": (1.205, 0.946),
}


#: Most elements (rows x columns, automatic rows included) a curtain may have. Measured here
#: (2 shared cores): 8.4 s for 1000 x 1000 elements at 20 shells and 35 s at the most shells
#: (400), so the largest allowed curtain finishes in well under a minute; the old maxima
#: (100,000 rows x 1,000 columns, automatic rows unbounded) meant hours. The paper's
#: curtains have about 100 x 10.
MAX_ELEMENTS = 1_000_000


class _Section(BaseModel):
    # The one input-model config (strict types, finite numbers): drumflow.case.
    model_config = INPUT_MODEL_CONFIG


class CurtainSolids(_Section):
    """The falling particles."""

    diameter: float = Field(gt=0, le=0.05, description="particle (Sauter) diameter, m")
    density: float = Field(gt=0, le=20000, description="particle density, kg/m^3")
    conductivity: float = Field(gt=0, le=1e4, description="particle conductivity, W/(m K)")
    heat_capacity: float = Field(gt=0, le=1e5, description="particle heat capacity, J/(kg K)")
    mass_flow: float = Field(ge=0, le=100, description="solids mass flow of the curtain, kg/s")
    fall_velocity: float = Field(gt=0, le=50, description="constant fall velocity v_s, m/s")
    inlet_temperature_C: float = Field(gt=-100, lt=1500, description="solids inlet temperature")


class CurtainGas(_Section):
    """The gas crossing the curtain."""

    velocity: float = Field(ge=0, le=50, description="superficial gas velocity v_g, m/s")
    inlet_temperature_C: float = Field(gt=-100, lt=1000, description="gas inlet temperature")
    properties: Literal["paper", "incropera"] = Field(
        "paper",
        description="'paper': Table 1 of Wardjiman and Rhodes interpolated at the inlet "
        "temperature; 'incropera': drumflow's air table (Incropera Table A.4), ideal-gas density",
    )
    pressure_kPa: float = Field(101.325, gt=10, le=1e4, description="gas pressure, kPa")


class CurtainGeometry(_Section):
    """The curtain in the duct."""

    width: float = Field(gt=0, le=100, description="curtain width across the duct W, m")
    thickness: float = Field(gt=0, le=10, description="curtain thickness in the gas direction, m")
    height: float = Field(gt=0, le=100, description="fall height H, m")


class CurtainNumerics(_Section):
    """Discretisation."""

    columns: int = Field(10, ge=1, le=1000, description="vertical sections N across the thickness")
    rows: int | Literal["auto"] = Field(
        "auto", description="horizontal sections M, or 'auto' for M = H / (v_s t_c) (Eq. 2)"
    )
    shells: int = Field(20, ge=2, le=400, description="shells of the particle-interior solver")

    @model_validator(mode="after")
    def _rows_range(self) -> CurtainNumerics:
        if isinstance(self.rows, int) and not 1 <= self.rows <= 100_000:
            raise ValueError(f"rows = {self.rows}: allowed 1 to 100000 or 'auto'")
        return self


class CurtainCase(_Section):
    """A curtain experiment or design: ``drumflow cooler curtain CASE``."""

    name: str = Field(min_length=1, max_length=80, pattern=r"^[A-Za-z0-9_.-]+$")
    description: str = ""
    source: str = Field("", description="where the inputs come from (paper, figure)")
    solids: CurtainSolids
    gas: CurtainGas
    geometry: CurtainGeometry
    numerics: CurtainNumerics = CurtainNumerics()

    @model_validator(mode="after")
    def _fits(self) -> CurtainCase:
        s, g, n = self.solids, self.geometry, self.numerics
        packed = s.mass_flow / (s.density * s.fall_velocity * g.width * g.thickness)
        if packed >= 1.0:
            raise ValueError(
                f"solids.mass_flow = {s.mass_flow} kg/s: the curtain's solids fraction would be "
                f"{packed:.3g} (voidage < 0); allowed below "
                f"{s.density * s.fall_velocity * g.width * g.thickness:.4g} kg/s"
            )
        if n.rows == "auto" and self.gas.velocity == 0:
            raise ValueError(
                "numerics.rows = 'auto': needs gas.velocity > 0 (Eq. 2 divides by the gas "
                "contact time); give an integer number of rows for a still gas"
            )
        rows = self.rows()
        if rows * n.columns > MAX_ELEMENTS:
            which = (f"numerics.rows = 'auto' ({rows:,} rows by Eq. 2 from geometry.height, "
                     "gas.velocity, solids.fall_velocity and geometry.thickness)"
                     if n.rows == "auto" else f"numerics.rows = {rows:,}")
            raise ValueError(
                f"{which} x numerics.columns = {n.columns:,}: {rows * n.columns:,} elements; "
                f"allowed up to {MAX_ELEMENTS:,} (fewer rows or columns)"
            )
        return self

    def rows(self) -> int:
        """The number of rows M: ``numerics.rows``, or Eq. 2's for 'auto'."""
        if self.numerics.rows != "auto":
            return self.numerics.rows
        contact = self.geometry.thickness / (self.gas.velocity * self.numerics.columns)  # Eq. 1
        # Capped before rounding: a huge M is refused by its size, not by an overflow.
        return max(1, round(min(self.geometry.height / (self.solids.fall_velocity * contact),
                                1e15)))  # Eq. 2


@dataclass(frozen=True)
class GasProperties:
    """Gas properties at one temperature, for Ranz-Marshall and the energy balance."""

    temperature_C: float
    density: float
    viscosity: float
    conductivity: float
    heat_capacity: float

    @property
    def prandtl(self) -> float:
        return self.heat_capacity * self.viscosity / self.conductivity

    def air_state(self) -> AirState:
        """The coupling's :class:`~drumflow.physics.particle_air.AirState` with these values."""
        return AirState(self.temperature_C, self.density, self.viscosity, self.conductivity,
                        self.prandtl)


def gas_properties(temperature_C: float, source: Literal["paper", "incropera"] = "paper",
                   pressure_kPa: float = 101.325) -> GasProperties:
    """Air properties at ``temperature_C`` from the paper's Table 1 or drumflow's air table."""
    if source == "paper":
        t0, t1 = PAPER_GAS_TABLE["temperature_C"]
        w = (temperature_C - t0) / (t1 - t0)

        def lerp(key: str) -> float:
            a, b = PAPER_GAS_TABLE[key]
            return a + w * (b - a)

        return GasProperties(temperature_C, lerp("density"), lerp("viscosity"),
                             lerp("conductivity"), lerp("heat_capacity"))
    props = air_properties.air_properties(temperature_C, name="gas temperature")
    return GasProperties(
        temperature_C,
        air_properties.ideal_gas_density(temperature_C, pressure_kPa),
        float(props.dynamic_viscosity),
        float(props.thermal_conductivity),
        float(props.specific_heat),
    )


def element_exchange(exposure: FloatArray, capacities: FloatArray, temperatures: FloatArray,
                     particle_rate: float, gas_inlet_C: float,
                     gas_capacity_rate: float) -> tuple[FloatArray, float, float]:
    """One element: particles in at ``temperatures``, gas in at ``gas_inlet_C``.

    The particles see the mean of the gas inlet and outlet temperatures (module notes);
    the shell model is affine in that temperature, so the balance is solved exactly.

    Parameters
    ----------
    exposure
        Augmented exposure matrix of the particles' stay in the element
        (:func:`drumflow.coolers._propagator.exposure_matrix`).
    capacities
        Heat capacity of each shell, J/K.
    temperatures
        Shell temperatures of the particles entering.
    particle_rate
        Particles passing through the element per second.
    gas_inlet_C
        Gas inlet temperature.
    gas_capacity_rate
        Gas mass flow times heat capacity through the element, W/K (>= 0).

    Returns
    -------
    (temperatures, heat_to_gas_w, gas_outlet_C)
        The particles' shell temperatures leaving, the heat they gave the gas (W, negative
        when heated) and the gas outlet temperature.
    """
    n = len(temperatures)
    free = exposure[:n, :n] @ temperatures  # at zero gas temperature
    unit = exposure[:n, n]  # response to a unit gas temperature
    a = particle_rate * float(capacities @ (temperatures - free))
    b = particle_rate * float(capacities @ unit)
    if gas_capacity_rate <= 0.0:
        # No gas throughput: the gas in the element takes the temperature at which the
        # particles give it nothing.
        gas_seen = a / b if b > 0 else gas_inlet_C
        return free + unit * gas_seen, 0.0, gas_seen
    heat = (a - b * gas_inlet_C) / (1.0 + 0.5 * b / gas_capacity_rate)
    gas_out = gas_inlet_C + heat / gas_capacity_rate
    gas_seen = 0.5 * (gas_inlet_C + gas_out)
    out = free + unit * gas_seen
    # The heat is the particles' enthalpy drop: recompute it from the state so that the energy
    # balance closes to round-off whatever the conditioning of the formula above.
    heat = particle_rate * float(capacities @ (temperatures - out))
    return out, heat, gas_inlet_C + heat / gas_capacity_rate


@dataclass(frozen=True)
class CurtainResult:
    """The curtain model's answer (all temperatures in deg C, heats in W).

    Attributes
    ----------
    heat_to_solids_w
        Heat duty: heat the gas gives the solids (negative when the solids are the hot side).
    solids_outlet_C, gas_outlet_C
        Mixed-mean outlet temperatures (solids at the bottom, gas leaving the curtain).
    h_w_m2k, biot
        Ranz-Marshall film coefficient and the particle Biot number h R / k.
    voidage
        Curtain voidage ``1 - mdot_s / (rho_s v_s W delta)``.
    rows, columns, contact_time_s
        The grid ``M x N`` and the particles' time per row.
    depth_m
        Distance from the top of the curtain to the bottom of each row.
    solids_profile_C
        Mean solids temperature leaving each row (paper Eq. 11).
    gas_profile_C
        Gas temperature leaving the curtain at each row (downstream face).
    element_heat_w
        Heat given to the solids in each element, shape ``(M, N)``.
    energy_residual
        ``(solids enthalpy gain - gas enthalpy loss) / max(|duty|, tiny)``.
    gas, notes
        Gas properties used, and remarks.
    """

    heat_to_solids_w: float
    solids_outlet_C: float
    gas_outlet_C: float
    h_w_m2k: float
    biot: float
    voidage: float
    rows: int
    columns: int
    contact_time_s: float
    fall_time_s: float
    depth_m: FloatArray
    solids_profile_C: FloatArray
    gas_profile_C: FloatArray
    element_heat_w: FloatArray
    solids_capacity_rate_w_k: float
    gas_capacity_rate_w_k: float
    energy_residual: float
    gas: GasProperties
    notes: list[str] = field(default_factory=list)

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready summary with the profiles."""
        return {
            "heat_duty_W": self.heat_to_solids_w,
            "solids_outlet_temperature_C": self.solids_outlet_C,
            "gas_outlet_temperature_C": self.gas_outlet_C,
            "h_W_m2K": self.h_w_m2k,
            "biot": self.biot,
            "voidage": self.voidage,
            "rows": self.rows,
            "columns": self.columns,
            "contact_time_s": self.contact_time_s,
            "fall_time_s": self.fall_time_s,
            "solids_capacity_rate_W_K": self.solids_capacity_rate_w_k,
            "gas_capacity_rate_W_K": self.gas_capacity_rate_w_k,
            "energy_residual": self.energy_residual,
            "gas_properties": {
                "temperature_C": self.gas.temperature_C,
                "density_kg_m3": self.gas.density,
                "viscosity_Pa_s": self.gas.viscosity,
                "conductivity_W_mK": self.gas.conductivity,
                "heat_capacity_J_kgK": self.gas.heat_capacity,
            },
            "profile": {
                "depth_m": self.depth_m.tolist(),
                "solids_C": self.solids_profile_C.tolist(),
                "gas_C": self.gas_profile_C.tolist(),
            },
            "notes": list(self.notes),
        }


def solve_curtain(case: CurtainCase, *, h_w_m2k: float | None = None) -> CurtainResult:
    """Run the element-array curtain model.

    Parameters
    ----------
    case
        The validated curtain case.
    h_w_m2k
        Film coefficient to use instead of Ranz-Marshall (limits and sensitivity studies);
        ``math.inf`` holds the particle surface at the gas temperature.

    Returns
    -------
    CurtainResult
    """
    s, g, geo, num = case.solids, case.gas, case.geometry, case.numerics
    gas = gas_properties(g.inlet_temperature_C, g.properties, g.pressure_kPa)
    sphere = Sphere(s.diameter, s.conductivity, s.density, s.heat_capacity)
    model = SphereConduction(sphere, shells=num.shells)
    h = float(ranz_marshall_h(g.velocity, s.diameter, gas.air_state())) if h_w_m2k is None \
        else float(h_w_m2k)
    columns = num.columns
    rows = case.rows()
    dz = geo.height / rows
    exposure_time = dz / s.fall_velocity
    voidage = 1.0 - s.mass_flow / (s.density * s.fall_velocity * geo.width * geo.thickness)
    gas_rate_row = gas.density * g.velocity * voidage * geo.width * dz * gas.heat_capacity
    particle_rate = s.mass_flow / columns / sphere.mass
    exposure = exposure_matrix(model, h, exposure_time)
    caps = model.capacities

    state = np.tile(model.uniform(s.inlet_temperature_C), (columns, 1))
    heat = np.zeros((rows, columns))
    solids_profile = np.empty(rows)
    gas_profile = np.empty(rows)
    for m in range(rows):
        gas_t = g.inlet_temperature_C
        for n in range(columns):
            state[n], q, gas_t = element_exchange(exposure, caps, state[n], particle_rate,
                                                  gas_t, gas_rate_row)
            heat[m, n] = -q
        gas_profile[m] = gas_t
        solids_profile[m] = float(np.mean([model.mean_temperature(t) for t in state]))
    duty = float(heat.sum())
    solids_rate = s.mass_flow * s.heat_capacity
    gain = solids_rate * (solids_profile[-1] - s.inlet_temperature_C)
    loss = gas_rate_row * float(np.sum(g.inlet_temperature_C - gas_profile))
    scale = max(abs(duty), abs(gain), 1e-300)
    notes = []
    if g.velocity == 0:
        notes.append("no gas flow: the gas in the curtain takes the solids' temperature, no heat")
    return CurtainResult(
        heat_to_solids_w=duty,
        solids_outlet_C=float(solids_profile[-1]),
        gas_outlet_C=float(np.mean(gas_profile)),
        h_w_m2k=h,
        biot=sphere.biot(h) if math.isfinite(h) else math.inf,
        voidage=voidage,
        rows=rows,
        columns=columns,
        contact_time_s=exposure_time,
        fall_time_s=geo.height / s.fall_velocity,
        depth_m=np.asarray(dz * np.arange(1, rows + 1), dtype=np.float64),
        solids_profile_C=solids_profile,
        gas_profile_C=gas_profile,
        element_heat_w=heat,
        solids_capacity_rate_w_k=solids_rate,
        gas_capacity_rate_w_k=gas_rate_row * rows,
        energy_residual=(gain - loss) / scale,
        gas=gas,
        notes=notes,
    )
