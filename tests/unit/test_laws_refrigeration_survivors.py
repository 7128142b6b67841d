"""Law tests for the mutation survivors of :mod:`drumflow.coolers.refrigeration` (issue 36;
results/mutation/survivors.md).

The mutmut run (356 of 378 killed) left alive: the condensate's enthalpy in the air-cooling
duty (``cp_w (T_out - 273.16 K)`` divided instead of multiplied, ``cp_w`` dividing, the
reference moved by 1 K: the law test allowed 1 % while the whole term is 1 % of the duty);
the reported cycle states (state 1 set to None, the states' pressure and entropy set to None,
the quality reported outside the dome) and the cycle's reported temperatures and fluid; and
the edges of the argument guards (zero duty refused, an efficiency of 0 or equal saturation
temperatures let through to a ZeroDivisionError, the duty message). Every expected value below
is arithmetic from a published table or an identity written out here; none comes from the
module (the outlet humidity ratio of the duty check is :mod:`drumflow.coolers._fluidization`'s
law, taken from the result and checked beside it against ASHRAE's equation).

References typed here:

* Saturated ammonia, the table on the older ASHRAE datum (h = s = 0 for the saturated
  liquid at -40 C) as tabulated by Engineers Edge, "Saturated Ammonia Properties":
  0 C: p = 429.6 kPa, h_f = 180.36,
  h_fg = 1261.8, h_g = 1442.2 kJ/kg, s_f = 0.7114, s_fg = 4.6195, s_g = 5.3309 kJ/(kg K);
  40 C: p = 1554.9 kPa, h_f = 371.43 kJ/kg, s_f = 1.3574 kJ/(kg K). Only differences of h
  and s are used, so the reference state does not matter. The table is older than CoolProp's
  ammonia (Gao et al. 2020): pressures differ by 0.02-0.08 %, h_f(40) - h_f(0) by 0.3 %.
* Saturated water, IAPWS-95 as tabulated by Cengel and Boles (Table A-4; liquid at the triple
  point the zero): h_g = 2519.2 (10 C), 2555.6 (30 C), 2573.5 (40 C) kJ/kg;
  p_ws(10 C) = 1.2282 kPa (ASHRAE 2017 ch. 1, Table 3).
* Dry air h_da = 1.006 t kJ/kg (ASHRAE 2017 ch. 1, eq. 30).
"""

from __future__ import annotations

import math

import pytest

from drumflow.coolers import refrigeration

T_E, T_C = 273.15, 313.15  # 0 C evaporating, 40 C condensing (rows of the ASHRAE table)


def _close(value: float, reference: float, rtol: float, what: str) -> None:
    assert math.isfinite(value) and abs(value / reference - 1.0) <= rtol, (
        f"{what}: {value:.8g} vs independent {reference:.8g} "
        f"({value / reference - 1.0:+.3%}, allowed {rtol:.1e})")


@pytest.mark.parametrize(("t_in", "w_in", "t_out", "hg_in", "hg_out"), [
    (30.0, 0.020, 10.0, 2555.6, 2519.2),
    (40.0, 0.045, 30.0, 2573.5, 2555.6),
])
def test_condensate_enthalpy_in_the_air_cooling_duty(t_in: float, w_in: float, t_out: float,
                                                     hg_in: float, hg_out: float) -> None:
    """1 kg/s of dry air at 101.325 kPa cooled below its dew point, as an ideal mixture of
    dry air and water vapour (vapour at the steam table's h_g(T), zero at the triple-point
    liquid, as CoolProp's humid air), the condensate leaving at h_w = 4.186 (t_out - 0.01):

    Q = 1.006 (t_in - t_out) + W_in h_g(t_in) - W_out h_g(t_out) - (W_in - W_out) h_w.

    30 -> 10 C at W_in = 0.020 (W_out = 0.0076626 from the result): 20.120 + 51.112 - 19.3037
    - 0.012337 * 41.818 = 51.412 kJ/kg. 40 -> 30 C at W_in = 0.045: 53.798 kJ/kg.
    The ideal mixture differs from CoolProp's real humid air (Herrmann et al. 2009) by 4e-5
    and 1.3e-4 at these two states (measured once); 3e-4 is allowed. Moving the condensate's
    reference by 1 K (a 10 % change of its 10 K enthalpy at 10 C) moves the duty by 1.0e-3
    and 1.4e-3; dividing by cp_w or by (T - 273.16) by 1.0 % and 0.8 %.

    The outlet humidity ratio is the saturation one: ASHRAE eq. 23 with p_ws multiplied by
    the enhancement factor f ~ 1.004 of water vapour in air at 1 atm (Hyland and Wexler
    1983). At f = 1.0044: 0.621945 * 1.0044 * 1.2282 / (101.325 - 1.0044 * 1.2282)
    = 0.0076653; 1e-3 allowed (f to +-0.0005; without f the ratio is 0.4 % lower).
    """
    res = refrigeration.air_cooling_duty(1.0, 273.15 + t_in, w_in, 273.15 + t_out, 101325.0)
    w_out = res.outlet_humidity_ratio
    if t_out == 10.0:
        _close(w_out, 0.621945 * 1.0044 * 1.2282 / (101.325 - 1.0044 * 1.2282), 1e-3,
               "saturation humidity ratio at 10 C")
    _close(res.condensate, w_in - w_out, 1e-12, "condensate = m_da (W_in - W_out)")
    hand = (1.006 * (t_in - t_out) + w_in * hg_in - w_out * hg_out
            - (w_in - w_out) * 4.186 * (t_out - 0.01)) * 1e3
    _close(res.duty, hand, 3e-4, f"air-cooling duty {t_in:g} -> {t_out:g} C")


def test_cycle_states_against_the_ammonia_table() -> None:
    """The ammonia cycle at 0 C / 40 C, eta_p = 0.75, 100 kW.

    Pressures: states 1 and 4 at p_sat(0 C) = 429.6 kPa, 2 and 3 at p_sat(40 C) = 1554.9 kPa
    (0.2 % allowed; the table and CoolProp differ by 0.08 %).
    Valve: x4 = (h_f(40) - h_f(0)) / h_fg(0) = 191.07 / 1261.8 = 0.151427 (1 %: the table's
    liquid enthalpies differ by 0.3 %).
    Entropy: s1 - s4 = s_g(0) - s_f(0) - x4 s_fg(0) = 5.3309 - 0.7114 - 0.151427 * 4.6195
    = 3.91998 kJ/(kg K) (0.3 %; the identity (h_g(0) - h_f(40)) / 273.15 = 3.92008 checks the
    arithmetic); the valve's entropy generation s4 - s3 = 0.7114 + 0.69952 - 1.3574
    = 0.05352 kJ/(kg K) (1 %); the compression s2 > s1 at eta_p < 1.
    The discharge is superheated (no quality) and state 4 inside the dome. States 1 and 3 are
    on the dome: quality 1 and 0 exactly (CoolProp's flash returns 1 +- 4e-16 and 0 +- 1e-15
    there, which the module reported as None before; regression).
    The reported fluid and saturation temperatures are the inputs.
    """
    cyc = refrigeration.solve_cycle(100e3, T_E, T_C, 0.75)
    s1, s2, s3, s4 = cyc.states
    assert cyc.refrigerant == "Ammonia"
    assert cyc.evaporating_temperature == T_E and cyc.condensing_temperature == T_C
    _close(s1.temperature, T_E, 1e-9, "state 1 temperature")
    _close(s3.temperature, T_C, 1e-9, "state 3 temperature")
    for state, p_kpa, name in ((s1, 429.6, "1"), (s4, 429.6, "4"), (s2, 1554.9, "2"),
                               (s3, 1554.9, "3")):
        _close(state.pressure / 1e3, p_kpa, 2e-3, f"state {name} pressure")
    x4 = (371.43 - 180.36) / 1261.8
    assert s4.quality is not None
    _close(s4.quality, x4, 1e-2, "state 4 quality after the valve")
    assert s2.quality is None, "the discharge is superheated"
    assert s1.quality == 1.0 and s3.quality == 0.0, (s1.quality, s3.quality)
    assert s2.temperature > T_C
    _close((s1.entropy - s4.entropy) / 1e3, 5.3309 - 0.7114 - x4 * 4.6195, 3e-3,
           "s1 - s4 (evaporation at 0 C)")
    _close((s4.entropy - s3.entropy) / 1e3, 0.7114 + x4 * 4.6195 - 1.3574, 1e-2,
           "s4 - s3 (valve)")
    assert s2.entropy > s1.entropy
    _close(s1.enthalpy - s4.enthalpy, (1442.2 - 371.43) * 1e3, 3e-3, "h1 - h4")


def test_isentropic_compression_keeps_the_entropy() -> None:
    """eta_p = 1: dh = v dP is ds = 0 (T ds = dh - v dP), so s2 = s1 to the integrator's
    error (1e-6 of the work, ~1e-7 of s). A reported entropy of None or a state 1 of None
    fails here too."""
    cyc = refrigeration.solve_cycle(100e3, T_E, T_C, 1.0)
    s1, s2 = cyc.states[0], cyc.states[1]
    _close(s2.entropy, s1.entropy, 1e-6, "s2 = s1 on the isentrope")


def test_zero_and_small_duties_are_accepted() -> None:
    """duty >= 0 is the documented range: zero duty is zero refrigerant flow, power and
    condenser heat (the COP stays the cycle's); 0.5 W gives a flow of 0.5 / (h1 - h3)
    = 0.5 / 1070.77e3 = 4.6696e-7 kg/s from the table (0.3 %)."""
    zero = refrigeration.solve_cycle(0.0, T_E, T_C, 0.75)
    assert zero.refrigerant_flow == 0.0 and zero.power == 0.0 and zero.condenser_heat == 0.0
    small = refrigeration.solve_cycle(0.5, T_E, T_C, 0.75)
    _close(small.refrigerant_flow, 0.5 / ((1442.2 - 371.43) * 1e3), 3e-3, "flow at 0.5 W")
    _close(small.cop, zero.cop, 1e-12, "COP independent of the duty")


def test_guards_refuse_with_their_messages() -> None:
    """Negative duty, equal saturation temperatures and eta_p = 0 are refused with a
    ValueError naming the argument (not a ZeroDivisionError from the integration)."""
    with pytest.raises(ValueError, match="duty"):
        refrigeration.solve_cycle(-1.0, T_E, T_C, 0.75)
    with pytest.raises(ValueError, match="evaporating"):
        refrigeration.solve_cycle(1.0, T_E, T_E, 0.75)
    with pytest.raises(ValueError, match="polytropic efficiency"):
        refrigeration.solve_cycle(1.0, T_E, T_C, 0.0)
    with pytest.raises(ValueError, match="polytropic efficiency"):
        refrigeration.polytropic_discharge_enthalpy("Ammonia", 4e5, 1.6e6, 1.5e6, 0.0)
