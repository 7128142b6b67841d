"""The ammonia refrigeration cycle and the air cooler, checked against CoolProp's own
isentrope, the first and second laws, and the sensible-heat limit."""

from __future__ import annotations

import CoolProp.CoolProp as CP
import pytest

from drumflow.coolers._fluidization import humid_air, humidity_ratio
from drumflow.coolers.refrigeration import (
    air_cooling_duty,
    polytropic_discharge_enthalpy,
    solve_cycle,
)


def test_polytropic_path_at_efficiency_one_is_the_isentrope() -> None:
    # eta_p = 1: dh = v dP is ds = 0; CoolProp's (s, P) flash is an independent route.
    te, tc = 268.15, 313.15
    p1 = CP.PropsSI("P", "T", te, "Q", 1, "Ammonia")
    p2 = CP.PropsSI("P", "T", tc, "Q", 0, "Ammonia")
    h1 = CP.PropsSI("H", "T", te, "Q", 1, "Ammonia")
    s1 = CP.PropsSI("S", "T", te, "Q", 1, "Ammonia")
    h2s = CP.PropsSI("H", "S", s1, "P", p2, "Ammonia")
    h2 = polytropic_discharge_enthalpy("Ammonia", p1, h1, p2, 1.0)
    # Midpoint rule with 200 steps: error ~1e-7 of the compression work.
    assert (h2 - h1) == pytest.approx(h2s - h1, rel=1e-5)


def test_cycle_first_and_second_law() -> None:
    cyc = solve_cycle(100e3, 275.0, 313.0, 0.75)
    assert cyc.condenser_heat == pytest.approx(cyc.duty + cyc.power, rel=1e-12)
    assert 1.0 < cyc.cop < cyc.carnot_cop
    # Isenthalpic valve: state 4 has state 3's enthalpy, inside the dome.
    assert cyc.states[3].enthalpy == cyc.states[2].enthalpy
    assert cyc.states[3].quality is not None and 0 < cyc.states[3].quality < 1
    # A worse compressor costs more power and discharges hotter.
    worse = solve_cycle(100e3, 275.0, 313.0, 0.6)
    assert worse.power > cyc.power and worse.discharge_temperature > cyc.discharge_temperature


def test_cycle_refuses_bad_arguments() -> None:
    with pytest.raises(ValueError, match="evaporating"):
        solve_cycle(1.0, 300.0, 290.0, 0.75)
    with pytest.raises(ValueError, match="polytropic efficiency"):
        solve_cycle(1.0, 270.0, 300.0, 1.5)


def test_air_cooling_sensible_above_the_dew_point() -> None:
    p = 101325.0
    w = humidity_ratio(303.15, p, 0.3)  # dew point ~11 degC
    res = air_cooling_duty(1.0, 303.15, w, 293.15, p)
    assert res.condensate == 0.0
    # Sensible only: m_da (1 + W) cp_ha dT with cp at the mean temperature, to 0.2 %.
    cp = humid_air(298.15, p, w).heat_capacity
    assert res.duty == pytest.approx((1 + w) * cp * 10.0, rel=2e-3)


def test_air_cooling_below_the_dew_point_condenses() -> None:
    p = 101325.0
    w = humidity_ratio(303.15, p, 0.8)
    res = air_cooling_duty(1.0, 303.15, w, 288.15, p)
    assert res.condensate > 0 and res.outlet_humidity_ratio < w
    cp = humid_air(295.65, p, w).heat_capacity
    assert res.duty > 1.5 * (1 + w) * cp * 15.0  # the latent load exceeds half the sensible one
