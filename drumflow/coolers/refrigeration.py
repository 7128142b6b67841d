"""The vapour-compression cycle that chills the air of the fluid-bed cooler's cooled section.

The source's Figure 5: ammonia condensed against river water, expanded in a valve
(isenthalpic), evaporated in the chiller CH-101 that cools the water loop of the air cooler
IC-101, and compressed (polytropic) by CP-101. Refrigerant properties are CoolProp's
reference equations of state (ammonia: Gao et al. 2020 as shipped with CoolProp 6.6+).

States (the usual numbering)::

    1  saturated vapour at the evaporating temperature (compressor suction)
    2  compressor discharge at the condensing pressure (polytropic path)
    3  saturated liquid at the condensing temperature (condenser outlet)
    4  two-phase mixture after the valve, h4 = h3, at the evaporating pressure

Polytropic compression with efficiency eta_p follows dh = v dP / eta_p along the path
(the small-stage definition of the polytropic efficiency, e.g. Dixon and Hall 2014,
sec. 2.10); it is integrated with a fixed-step midpoint rule on ln P with real-gas
properties. With eta_p = 1 the path is isentropic, which the tests check against CoolProp's
isentropic discharge enthalpy.

The air side: humid air cooled from ambient to the cooled-air temperature; below its dew
point water condenses and leaves at that temperature, so the duty includes the latent load.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import CoolProp.CoolProp as CP

from drumflow.coolers._fluidization import humidity_ratio, saturation_humidity_ratio

#: Liquid water specific heat for the condensate's enthalpy, J/(kg K) (IAPWS-95 at 10-30 degC
#: is 4182-4192; the condensate term is < 1 % of the duty).
WATER_HEAT_CAPACITY = 4186.0


@dataclass(frozen=True)
class CycleState:
    """One state of the cycle."""

    temperature: float  # K
    pressure: float  # Pa
    enthalpy: float  # J/kg
    entropy: float  # J/(kg K)
    quality: float | None  # vapour mass fraction, None outside the dome


@dataclass(frozen=True)
class CycleResult:
    """A solved cycle for one refrigeration duty.

    Attributes
    ----------
    duty
        Heat taken from the chilled side, W.
    power
        Compressor shaft power, W.
    condenser_heat
        Heat given to the river water, W (duty + power).
    refrigerant_flow
        kg/s.
    cop
        duty / power.
    carnot_cop
        T_evap / (T_cond - T_evap), the upper bound.
    states
        States 1 to 4.
    """

    refrigerant: str
    duty: float
    power: float
    condenser_heat: float
    refrigerant_flow: float
    cop: float
    carnot_cop: float
    evaporating_temperature: float
    condensing_temperature: float
    discharge_temperature: float
    states: tuple[CycleState, CycleState, CycleState, CycleState]


def _state(refrigerant: str, pressure: float, enthalpy: float) -> CycleState:
    t = CP.PropsSI("T", "P", pressure, "H", enthalpy, refrigerant)
    s = CP.PropsSI("S", "P", pressure, "H", enthalpy, refrigerant)
    q = CP.PropsSI("Q", "P", pressure, "H", enthalpy, refrigerant)
    return CycleState(float(t), pressure, enthalpy, float(s), float(q) if 0.0 <= q <= 1.0 else None)


def polytropic_discharge_enthalpy(refrigerant: str, suction_pressure: float, suction_enthalpy: float,
                                  discharge_pressure: float, efficiency: float,
                                  steps: int = 200) -> float:
    """Integrate dh = v dP / eta_p from suction to discharge pressure, J/kg.

    Midpoint rule on x = ln P (dh/dx = v P / eta_p): second order; 200 steps put the
    isentropic (eta_p = 1) discharge enthalpy within 1e-6 relative of CoolProp's isentrope
    for ammonia between -10 and 60 degC.
    """
    if not 0.0 < efficiency <= 1.0:
        raise ValueError(f"polytropic efficiency = {efficiency!r}: must be > 0 and <= 1")
    x0, x1 = math.log(suction_pressure), math.log(discharge_pressure)
    dx = (x1 - x0) / steps
    h = suction_enthalpy

    def slope(x: float, hh: float) -> float:
        p = math.exp(x)
        rho = CP.PropsSI("D", "P", p, "H", hh, refrigerant)
        return p / rho / efficiency

    x = x0
    for _ in range(steps):
        k1 = slope(x, h)
        h = h + dx * slope(x + 0.5 * dx, h + 0.5 * dx * k1)
        x += dx
    return h


def solve_cycle(duty: float, evaporating_temperature: float, condensing_temperature: float,
                polytropic_efficiency: float, refrigerant: str = "Ammonia") -> CycleResult:
    """The cycle that removes ``duty`` watts at the evaporator.

    Parameters
    ----------
    duty
        W (>= 0).
    evaporating_temperature, condensing_temperature
        Saturation temperatures, K (evaporating < condensing, both inside the dome).
    polytropic_efficiency
        Of the compressor, 0 < eta_p <= 1.
    refrigerant
        A CoolProp fluid name.
    """
    if duty < 0:
        raise ValueError(f"duty = {duty!r}: must be >= 0")
    if not evaporating_temperature < condensing_temperature:
        raise ValueError(f"evaporating temperature {evaporating_temperature:.2f} K must be below "
                         f"the condensing temperature {condensing_temperature:.2f} K")
    p_evap = float(CP.PropsSI("P", "T", evaporating_temperature, "Q", 1, refrigerant))
    p_cond = float(CP.PropsSI("P", "T", condensing_temperature, "Q", 0, refrigerant))
    h1 = float(CP.PropsSI("H", "T", evaporating_temperature, "Q", 1, refrigerant))
    h3 = float(CP.PropsSI("H", "T", condensing_temperature, "Q", 0, refrigerant))
    h2 = polytropic_discharge_enthalpy(refrigerant, p_evap, h1, p_cond, polytropic_efficiency)
    s1 = _state(refrigerant, p_evap, h1)
    s2 = _state(refrigerant, p_cond, h2)
    s3 = _state(refrigerant, p_cond, h3)
    s4 = _state(refrigerant, p_evap, h3)
    q_evap = h1 - h3  # J per kg refrigerant; h4 = h3 (isenthalpic valve)
    w = h2 - h1
    flow = duty / q_evap
    return CycleResult(
        refrigerant=refrigerant,
        duty=duty,
        power=flow * w,
        condenser_heat=flow * (h2 - h3),
        refrigerant_flow=flow,
        cop=q_evap / w,
        carnot_cop=evaporating_temperature / (condensing_temperature - evaporating_temperature),
        evaporating_temperature=evaporating_temperature,
        condensing_temperature=condensing_temperature,
        discharge_temperature=s2.temperature,
        states=(s1, s2, s3, s4),
    )


@dataclass(frozen=True)
class AirCooling:
    """Humid air cooled at constant pressure, per second.

    Attributes
    ----------
    duty
        Heat removed, W.
    outlet_humidity_ratio
        kg/kg dry air after condensation (if any).
    condensate
        kg/s of water condensed.
    """

    duty: float
    outlet_humidity_ratio: float
    condensate: float


def air_cooling_duty(dry_air_flow: float, inlet_temperature: float, inlet_humidity_ratio: float,
                     outlet_temperature: float, pressure: float) -> AirCooling:
    """Heat to remove from humid air to bring it to ``outlet_temperature``, W.

    Sensible only while the outlet stays above the dew point; below it the air leaves
    saturated and the condensate leaves at the outlet temperature:
    Q = m_da (h_in - h_out) - m_da (W_in - W_out) cp_w (T_out - 273.16 K)
    (CoolProp's humid-air enthalpy takes liquid water at the triple point as zero).
    """
    w_sat = saturation_humidity_ratio(outlet_temperature, pressure)
    w_out = min(inlet_humidity_ratio, w_sat)
    h_in = CP.HAPropsSI("H", "T", inlet_temperature, "P", pressure, "W", inlet_humidity_ratio)
    h_out = CP.HAPropsSI("H", "T", outlet_temperature, "P", pressure, "W", w_out)
    condensate = dry_air_flow * (inlet_humidity_ratio - w_out)
    duty = (dry_air_flow * (h_in - h_out)
            - condensate * WATER_HEAT_CAPACITY * (outlet_temperature - 273.16))
    return AirCooling(float(duty), float(w_out), float(condensate))


__all__ = ["AirCooling", "CycleResult", "CycleState", "air_cooling_duty", "humidity_ratio",
           "polytropic_discharge_enthalpy", "solve_cycle"]
