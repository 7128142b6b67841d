"""The vibrating fluidised-bed cooler with its refrigeration cycle (the fluid-bed source in
``/work/shared/reference/vibrating-fluid-bed-cooler.md``).

The product moves along the deck in plug flow at the forward velocity v (the source's eq. 4),
first through section B fed with ambient air, then through section C fed with ambient air or,
when ambient air cannot bring the product below the storage limit (311 K), with air chilled by
an ammonia cycle (:mod:`drumflow.coolers.refrigeration`). Each particle is followed along the
unit with the project's spherical-shell conduction solver
(:class:`~drumflow.physics.particle_interior.SphereConduction`, the source's concentric
shells, eqs. 1-7 and 26-28); its surface exchanges heat with the air by convection at
f_c h, h from the bed Nusselt number (:mod:`drumflow.coolers._fluidization`).

Air and particles in one slice of the deck: the air crosses the bed upwards once; the slice's
particles are well mixed vertically (bubbling), so the air heats along its path towards the
particles' surface temperature with NTU = N_p g_s / (m_air cp) (g_s the conductance from the
particle's outer shell to the gas), and the particles see the air's mean temperature over the
path. The heat each step removes from the particle is put in that slice's air exactly, so the
energy balance closes to round-off.

The plant measures the mixed air leaving both sections after the hood, which loses heat to
the surroundings: hLosses A (T_air - T_amb) (the source's eqs. 23-25), solved implicitly for
the measured temperature. f_c and hLosses A are the model's two fitted parameters
(:mod:`drumflow.coolers.fit`); the source's values are 0.30 and 1.17 kW/K. The source's f_c
multiplies another Nusselt correlation (Pakowski et al. 1984, not retrievable) than the one
used here (Gunn 1978), so it does not carry over; the source's plant data are not published,
so it cannot be refitted here either (issue 34): the case keeps 0.30 and says so.

The bed (issue 34): dense phase at minimum fluidisation, bubble fraction of Johnsson et al.
(1991); see :mod:`drumflow.coolers._fluidization` for why not the source's Richardson-Zaki
dense phase, and where a vibrated, shallow Geldart D bed stands.

Units: SI and kelvin inside; case fields in degC say so in their names.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray
from scipy.optimize import brentq

from drumflow.coolers import _fluidization as fl
from drumflow.coolers.fluid_bed_case import (
    KELVIN,
    Conditions,
    FluidBedCase,
    MonthWeather,
    load_weather,
    month_conditions,
)
from drumflow.coolers.refrigeration import (
    AirCooling,
    CycleResult,
    SourceCycleCheck,
    air_cooling_duty,
    solve_cycle,
    source_table_cycles,
)
from drumflow.physics.particle_interior import Sphere, SphereConduction

FloatArray = NDArray[np.float64]


# == the unit ===================================================================================
@dataclass
class SectionResult:
    """One air section of the deck."""

    name: str
    length: float
    residence_time: float
    air_inlet_temperature: float
    air_humidity_ratio: float
    air_mass_flow: float  # kg humid air / s
    air_heat_capacity: float  # J/(kg K)
    air_outlet_temperature: float  # mixing cup over the section
    bed: fl.BedState
    reynolds: float
    vibration_reynolds: float
    vibration_intensity: float
    nusselt: float
    h_correlation: float  # W/(m^2 K)
    h_effective: float  # f_c h
    biot: float
    ntu: float
    heat: float  # W given by the product to the air
    product_outlet_temperature: float


@dataclass
class UnitResult:
    """The cooler at one operating point.

    Profiles run along the deck (``position``, m); ``radius`` and ``radial_temperature`` are
    the particle's shells at the outlet (the source's Figure 9).
    """

    conditions: Conditions
    convective_efficiency: float
    losses_conductance: float  # W/K
    cooled_air_temperature: float | None  # K, None = ambient air in section C
    sections: list[SectionResult]
    position: FloatArray
    product_mean: FloatArray
    product_centre: FloatArray
    product_surface: FloatArray
    air_outlet_local: FloatArray
    radius: FloatArray
    radial_temperature: FloatArray
    product_outlet_temperature: float  # caloric mean, K
    air_mixed_temperature: float  # before the hood losses, K
    air_measured_temperature: float  # after the hood losses (what the plant measures), K
    product_heat: float  # W, product enthalpy drop
    air_heat: float  # W, air enthalpy gain up to the measuring point
    loss_heat: float  # W
    closure: float  # |product - air - losses| / product

    def summary(self) -> dict[str, Any]:
        return {
            "product_outlet_K": self.product_outlet_temperature,
            "air_outlet_measured_K": self.air_measured_temperature,
            "air_outlet_mixed_K": self.air_mixed_temperature,
            "cooled_air_K": self.cooled_air_temperature,
            "product_heat_kW": self.product_heat / 1e3,
            "loss_kW": self.loss_heat / 1e3,
            "energy_closure": self.closure,
            "particle_centre_minus_surface_K": float(self.radial_temperature[0]
                                                     - self.radial_temperature[-1]),
        }


def run_unit(case: FluidBedCase, conditions: Conditions, *, convective_efficiency: float | None = None,
             losses_conductance: float | None = None,
             cooled_air_temperature: float | None = None) -> UnitResult:
    """Follow the product through both sections at one operating point.

    Parameters
    ----------
    case
        The validated case.
    conditions
        Ambient air, product inlet and river water.
    convective_efficiency
        f_c; default the case's.
    losses_conductance
        hLosses A, W/K; default the case's.
    cooled_air_temperature
        Supply temperature of section C's chilled air, K; ``None`` for ambient air.
    """
    fc = case.losses.convective_efficiency if convective_efficiency is None else convective_efficiency
    ha = case.losses.h_losses_A_kW_per_K * 1e3 if losses_conductance is None else losses_conductance
    prod, unit = case.product, case.unit
    p = case.air.pressure_kPa * 1e3
    sphere = Sphere(prod.diameter, prod.conductivity, prod.density, prod.heat_capacity)
    solver = SphereConduction(sphere, shells=case.numerics.shells)
    particle_rate = prod.mass_flow / sphere.mass  # particles per second
    orifice_area = unit.area / unit.orifices
    gamma = fl.vibration_intensity(unit.vibration_amplitude, unit.vibration_frequency)

    temps = solver.uniform(conditions.product_inlet_temperature)
    enthalpy_in = solver.enthalpy(temps)
    positions = [0.0]
    means = [solver.mean_temperature(temps)]
    centres = [float(temps[0])]
    surfaces = [float(temps[-1])]
    air_local = [math.nan]
    sections: list[SectionResult] = []
    x0 = 0.0
    specs = (("B (ambient)", unit.ambient_fraction * unit.length, case.air.ambient.velocity, None),
             ("C (cooled)", (1.0 - unit.ambient_fraction) * unit.length, case.air.cooled.velocity,
              cooled_air_temperature))
    for name, length, velocity, chilled in specs:
        if chilled is None:
            t_air, w_air = conditions.ambient_temperature, conditions.humidity_ratio
        else:
            t_air = chilled
            w_air = min(conditions.humidity_ratio, fl.saturation_humidity_ratio(chilled, p))
        gas = fl.humid_air(t_air, p, w_air)
        bed = fl.bed_state(velocity, gas, prod.diameter, prod.density, prod.mass_flow,
                           unit.solids_velocity, unit.width, orifice_area,
                           prod.min_fluidization_voidage)
        re = fl.particle_reynolds(velocity, prod.diameter, gas)
        nu = fl.gunn_nusselt(re, gas.prandtl, bed.voidage)
        h = nu * gas.conductivity / prod.diameter
        h_eff = fc * h
        air_flow = gas.density * velocity * unit.width * length
        capacity = air_flow * gas.heat_capacity  # W/K
        tau = length / unit.solids_velocity
        ntu = particle_rate * solver.surface_conductance(h_eff) * tau / capacity
        mean_fraction = -math.expm1(-ntu) / ntu if ntu > 0 else 1.0
        steps = case.numerics.steps_per_section
        dt = tau / steps
        heat = 0.0
        for i in range(steps):
            t_outer = float(temps[-1])
            t_gas = t_outer - (t_outer - t_air) * mean_fraction
            temps, q = solver.step(temps, h_eff, t_gas, dt)
            heat += q
            positions.append(x0 + (i + 1) * dt * unit.solids_velocity)
            means.append(solver.mean_temperature(temps))
            centres.append(float(temps[0]))
            surfaces.append(solver.surface_temperature(temps, h_eff, t_gas))
            # Air leaving this slice: the slice's particles' heat in the slice's air.
            air_local.append(t_air + particle_rate * q * tau / (capacity * dt))
        section_heat = particle_rate * heat
        sections.append(SectionResult(
            name=name, length=length, residence_time=tau, air_inlet_temperature=t_air,
            air_humidity_ratio=w_air, air_mass_flow=air_flow, air_heat_capacity=gas.heat_capacity,
            air_outlet_temperature=t_air + section_heat / capacity, bed=bed, reynolds=re,
            vibration_reynolds=fl.vibration_reynolds(unit.vibration_amplitude,
                                                     unit.vibration_frequency, prod.diameter, gas),
            vibration_intensity=gamma, nusselt=nu, h_correlation=h, h_effective=h_eff,
            biot=sphere.biot(h_eff), ntu=ntu, heat=section_heat,
            product_outlet_temperature=solver.mean_temperature(temps)))
        x0 += length

    capacities = [s.air_mass_flow * s.air_heat_capacity for s in sections]
    total_capacity = sum(capacities)
    t_in_mix = sum(c * s.air_inlet_temperature for c, s in zip(capacities, sections)) / total_capacity
    t_mix = sum(c * s.air_outlet_temperature for c, s in zip(capacities, sections)) / total_capacity
    t_amb = conditions.ambient_temperature
    # Hood losses at the measured (outlet) air temperature, solved implicitly:
    # C (T_mix - T_meas) = hA (T_meas - T_amb).
    t_meas = (total_capacity * t_mix + ha * t_amb) / (total_capacity + ha)
    loss = ha * (t_meas - t_amb)
    product_heat = particle_rate * (enthalpy_in - solver.enthalpy(temps))
    air_heat = total_capacity * (t_meas - t_in_mix)
    closure = abs(product_heat - air_heat - loss) / max(abs(product_heat), 1e-300)
    return UnitResult(
        conditions=conditions, convective_efficiency=fc, losses_conductance=ha,
        cooled_air_temperature=cooled_air_temperature, sections=sections,
        position=np.asarray(positions), product_mean=np.asarray(means),
        product_centre=np.asarray(centres), product_surface=np.asarray(surfaces),
        air_outlet_local=np.asarray(air_local), radius=solver.r_centres.copy(),
        radial_temperature=temps.copy(), product_outlet_temperature=solver.mean_temperature(temps),
        air_mixed_temperature=t_mix, air_measured_temperature=t_meas, product_heat=product_heat,
        air_heat=air_heat, loss_heat=loss, closure=closure)


# == operation with the refrigeration cycle =====================================================
@dataclass
class Operation:
    """The cooler at one operating point with the cooled section controlled.

    Attributes
    ----------
    ambient_only
        The unit with ambient air in both sections.
    unit
        The unit as operated (chilled section C when needed).
    cooling_needed
        Ambient air alone leaves the product above the target.
    target_met
        The product leaves at or below the target.
    air_cooling
        The air cooler IC-101 (None when section C runs on ambient air).
    cycle
        The refrigeration cycle (None when river water alone chills the air, or no cooling).
    """

    ambient_only: UnitResult
    unit: UnitResult
    cooling_needed: bool
    target_met: bool
    air_cooling: AirCooling | None = None
    cycle: CycleResult | None = None
    chilled_water_temperature: float | None = None
    notes: list[str] = field(default_factory=list)

    def per_kg(self, watts: float) -> float:
        """kJ per kg of product."""
        return watts / self.unit_mass_flow / 1e3

    unit_mass_flow: float = 1.0

    def summary(self) -> dict[str, Any]:
        c = self.cycle
        return {
            "ambient_K": self.unit.conditions.ambient_temperature,
            "product_outlet_ambient_only_K": self.ambient_only.product_outlet_temperature,
            "cooling_needed": self.cooling_needed,
            "target_met": self.target_met,
            "product_outlet_K": self.unit.product_outlet_temperature,
            "air_outlet_measured_K": self.unit.air_measured_temperature,
            "cooled_air_K": self.unit.cooled_air_temperature,
            "chilled_water_K": self.chilled_water_temperature,
            "air_cooler_duty_kJ_per_kg": self.per_kg(self.air_cooling.duty) if self.air_cooling else 0.0,
            "compressor_power_kJ_per_kg": self.per_kg(c.power) if c else 0.0,
            "condenser_heat_kJ_per_kg": self.per_kg(c.condenser_heat) if c else 0.0,
            "refrigerant_kg_per_kg": c.refrigerant_flow / self.unit_mass_flow if c else 0.0,
            "evaporating_K": c.evaporating_temperature if c else None,
            "condensing_K": c.condensing_temperature if c else None,
            "discharge_K": c.discharge_temperature if c else None,
            "cop": c.cop if c else None,
            "carnot_cop": c.carnot_cop if c else None,
            "energy_closure": self.unit.closure,
            "notes": self.notes,
        }


def operate(case: FluidBedCase, conditions: Conditions, *, convective_efficiency: float | None = None,
            losses_conductance: float | None = None) -> Operation:
    """Run the cooler; chill section C's air only as much as the product target needs.

    With ``air.cooled.temperature_C = 'auto'`` the supply temperature of section C is the
    one that puts the product exactly at the target (brentq on a monotone function), bounded
    below by the lowest chilled-water temperature plus the air-cooler approach. The chilled
    water comes straight from the river when the river is cold enough, otherwise from the
    refrigeration cycle (evaporating at chilled water minus the chiller approach, condensing
    at river water plus the condenser approach). A number fixes the supply temperature;
    'off' never chills.
    """
    kwargs: dict[str, Any] = {"convective_efficiency": convective_efficiency,
                              "losses_conductance": losses_conductance}
    ref = case.refrigeration
    target = ref.target_product_temperature_K
    ambient = run_unit(case, conditions, **kwargs)
    needed = ambient.product_outlet_temperature > target
    setting = case.air.cooled.temperature_C
    notes: list[str] = []
    if setting == "off" or (setting == "auto" and not needed):
        op = Operation(ambient, ambient, needed, not needed)
        op.unit_mass_flow = case.product.mass_flow
        return op
    lowest = ref.min_chilled_water_C + KELVIN + ref.air_cooler_approach_K
    if isinstance(setting, float | int):
        t_cool = float(setting) + KELVIN
        if t_cool > conditions.ambient_temperature:
            # An air cooler cannot warm the air: above ambient it is off and the air enters
            # as it is (not a negative duty that nothing would deliver).
            notes.append(f"cooled-air setting {float(setting):.2f} C is above the ambient "
                         f"{conditions.ambient_temperature - KELVIN:.2f} C: the air cooler is off "
                         "and the air enters at ambient")
            t_cool = conditions.ambient_temperature
    else:
        def excess(t: float) -> float:
            unit = run_unit(case, conditions, cooled_air_temperature=t, **kwargs)
            return unit.product_outlet_temperature - target

        if conditions.ambient_temperature <= lowest or excess(lowest) > 0:
            t_cool = min(lowest, conditions.ambient_temperature)
            notes.append(f"target {target:.2f} K not reachable with the lowest cooled-air "
                         f"temperature {t_cool:.2f} K")
        else:
            t_cool = float(brentq(excess, lowest, conditions.ambient_temperature, xtol=1e-4))
    unit = run_unit(case, conditions, cooled_air_temperature=t_cool, **kwargs)
    section_c = unit.sections[1]
    dry_air = section_c.air_mass_flow / (1.0 + conditions.humidity_ratio)
    cooling = air_cooling_duty(dry_air, conditions.ambient_temperature, conditions.humidity_ratio,
                               t_cool, case.air.pressure_kPa * 1e3)
    chilled_water = t_cool - ref.air_cooler_approach_K
    cycle = None
    if conditions.river_water_temperature > chilled_water and cooling.duty > 0:
        cycle = solve_cycle(cooling.duty, chilled_water - ref.chiller_approach_K,
                            conditions.river_water_temperature + ref.condenser_approach_K,
                            ref.polytropic_efficiency, ref.refrigerant)
    elif cooling.duty > 0:
        notes.append("river water is cold enough: no compressor")
    op = Operation(ambient, unit, needed, unit.product_outlet_temperature <= target + 1e-3,
                   cooling, cycle, chilled_water, notes)
    op.unit_mass_flow = case.product.mass_flow
    return op


def operate_year(case: FluidBedCase, weather: list[MonthWeather] | None = None,
                 ) -> list[tuple[MonthWeather, Operation]]:
    """:func:`operate` for each month of the weather table (the source's Figure 10, Table 1)."""
    table = weather if weather is not None else load_weather(case.weather.table)
    return [(m, operate(case, month_conditions(case, m))) for m in table]


def source_cycle_checks(case: FluidBedCase, weather: list[MonthWeather] | None = None,
                        ) -> list[SourceCycleCheck]:
    """The source's Table 1 re-solved with a consistent cycle (the case's compressor and
    refrigerant), at the source's saturation temperatures and with condensing against the
    month's river water plus the case's condenser approach (issue 34)."""
    table = weather if weather is not None else load_weather(case.weather.table)
    ref = case.refrigeration
    river = {m.name: (ref.river_water_temperature_C if ref.river_water_temperature_C is not None
                      else m.t_mean_C) + KELVIN + ref.condenser_approach_K for m in table}
    return source_table_cycles(ref.polytropic_efficiency, ref.refrigerant, river)


__all__ = ["Operation", "SectionResult", "UnitResult", "operate", "operate_year", "run_unit",
           "source_cycle_checks"]
