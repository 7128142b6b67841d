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

The source's Table 1 (issue 34). Its column headers were lost with the equations; the
columns are read by their numbers: the condenser heat (col. 3) is minus the sum of the duty
(col. 1) and the compressor work (col. 6) to 0.002 kJ/kg in each month, cols. 2 and 4 are
kelvin (evaporating, then condensing: 275.80 K and 320.15 K in June), col. 5 is kg of
ammonia per kg of product. Read so, its COP (duty / work) is above the Carnot COP
T_e / (T_c - T_e) in all three months (June 6.23 against 6.22, July 5.44 against 5.35,
August 5.50 against 5.41), which no cycle can reach: its compressor work is too small.
Its numbers are reproduced by a cycle that (a) sizes the ammonia flow on the latent heat at
the evaporating temperature, duty / h_fg(T_e) (0.0024028 kg/kg in June against the table's
0.0024027), ignoring the vapour that flashes in the valve (h1 - h4 = h1 - h3 is 17-19 %
smaller), and (b) compresses isentropically (work per kg of ammonia 201.0 kJ/kg in June,
the isentrope's 201.0; July and August 1.2 % under it), not along the polytropic path with
an efficiency the source's text describes. (a) alone puts the COP above Carnot.
:func:`source_table_cycles` re-solves each month with this module's consistent cycle at the
source's own duty and saturation temperatures (July: 2.88 kJ/kg of work at eta_p = 0.75,
not 1.61), and, for comparison, with condensing against river water.
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


def carnot_cop(evaporating_temperature: float, condensing_temperature: float) -> float:
    """T_e / (T_c - T_e): the COP of a reversible cycle between the two temperatures (K)."""
    if not 0.0 < evaporating_temperature < condensing_temperature:
        raise ValueError(f"evaporating temperature {evaporating_temperature!r} K must be > 0 and "
                         f"below the condensing temperature {condensing_temperature!r} K")
    return evaporating_temperature / (condensing_temperature - evaporating_temperature)


#: How far outside [0, 1] a flashed quality may fall by round-off and still be on the dome.
QUALITY_ROUND_OFF = 1e-9


def _state(refrigerant: str, pressure: float, enthalpy: float) -> CycleState:
    t = CP.PropsSI("T", "P", pressure, "H", enthalpy, refrigerant)
    s = CP.PropsSI("S", "P", pressure, "H", enthalpy, refrigerant)
    q = float(CP.PropsSI("Q", "P", pressure, "H", enthalpy, refrigerant))
    # A state put on the dew or bubble line (the evaporator's outlet, the condenser's) flashes
    # to a quality a few ulps outside [0, 1] (1.0000000000000004): it is on the dome.
    # Snapped to the line, so that a saturated state reads as one (6.8e-16 is liquid).
    for line in (0.0, 1.0):
        if abs(q - line) <= QUALITY_ROUND_OFF:
            q = line
    quality = q if 0.0 <= q <= 1.0 else None
    return CycleState(float(t), pressure, enthalpy, float(s), quality)


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
        carnot_cop=carnot_cop(evaporating_temperature, condensing_temperature),
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


# == the source's Table 1 ======================================================================
@dataclass(frozen=True)
class SourceCycleRow:
    """One month of the source's Table 1, per kg of fertiliser (columns read as in the module
    docstring).

    Attributes
    ----------
    month
        June, July or August.
    duty
        Heat taken from the chilled side, kJ/kg (col. 1).
    evaporating_temperature
        K (col. 2).
    condenser_heat
        kJ/kg, negative: given to the river water (col. 3).
    condensing_temperature
        K (col. 4).
    refrigerant_flow
        kg ammonia / kg product (col. 5).
    power
        Compressor work, kJ/kg (col. 6).
    """

    month: str
    duty: float
    evaporating_temperature: float
    condenser_heat: float
    condensing_temperature: float
    refrigerant_flow: float
    power: float

    @property
    def cop(self) -> float:
        return self.duty / self.power

    @property
    def carnot_cop(self) -> float:
        return carnot_cop(self.evaporating_temperature, self.condensing_temperature)

    @property
    def exceeds_carnot(self) -> bool:
        """True when the row's COP is above the reversible limit (the second law is broken)."""
        return self.cop > self.carnot_cop


#: The source's Table 1, transcribed (``/work/shared/reference/vibrating-fluid-bed-cooler.md``).
SOURCE_TABLE_1: tuple[SourceCycleRow, ...] = (
    SourceCycleRow("June", 3.009, 275.80, -3.494, 320.15, 0.00240273, 0.483),
    SourceCycleRow("July", 8.768, 272.06, -10.380, 322.95, 0.00691682, 1.613),
    SourceCycleRow("August", 8.339, 272.43, -9.856, 322.75, 0.00658318, 1.517),
)


@dataclass(frozen=True)
class SourceCycleCheck:
    """One month of the source's Table 1 beside consistent cycles at the same duty.

    Attributes
    ----------
    row
        The source's numbers.
    at_source_temperatures
        This module's cycle at the source's evaporating and condensing temperatures,
        per kg of product (its ``duty``, ``power``, ``condenser_heat`` in J/kg and
        ``refrigerant_flow`` in kg/kg).
    with_river_condensing
        The same at the source's evaporating temperature with condensing against river water
        (None when no river temperature was given for the month).
    """

    row: SourceCycleRow
    at_source_temperatures: CycleResult
    with_river_condensing: CycleResult | None


def source_table_cycles(polytropic_efficiency: float, refrigerant: str = "Ammonia",
                        river_condensing: dict[str, float] | None = None,
                        ) -> list[SourceCycleCheck]:
    """Re-solve the source's Table 1 with a consistent cycle.

    Parameters
    ----------
    polytropic_efficiency
        Of the compressor (the source gives none; the case's).
    refrigerant
        A CoolProp fluid name (the source: ammonia).
    river_condensing
        Condensing temperature (K) against river water per month name, for the second
        cycle; months missing from it get none.
    """
    out = []
    for row in SOURCE_TABLE_1:
        duty = row.duty * 1e3  # J per kg of product: the cycle's "per second" read per kg
        at_source = solve_cycle(duty, row.evaporating_temperature, row.condensing_temperature,
                                polytropic_efficiency, refrigerant)
        t_river = (river_condensing or {}).get(row.month)
        river = None
        if t_river is not None:
            river = solve_cycle(duty, row.evaporating_temperature, t_river,
                                polytropic_efficiency, refrigerant)
        out.append(SourceCycleCheck(row, at_source, river))
    return out


__all__ = ["SOURCE_TABLE_1", "AirCooling", "CycleResult", "CycleState", "SourceCycleCheck",
           "SourceCycleRow", "air_cooling_duty", "carnot_cop", "humidity_ratio",
           "polytropic_discharge_enthalpy", "solve_cycle", "source_table_cycles"]
