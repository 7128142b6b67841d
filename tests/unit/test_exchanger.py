"""Counter-current exchanger model of the whole cooler (Eqs. 42-48) against Table 7.

Tolerances for Table 7: 0.1 deg C on temperatures and 0.5 % on powers, LMTD and area. The paper
prints two decimals and found T_mo "by trial and error" (its own Q_m and Q_he differ by 0.01 %).
More importantly, its thermal powers imply mdot_m cp_m = Q_m / (T_mi - T_mo) = 20334 W/K in all
three columns, 0.09 % below the stated 13.88889 kg/s x 1465.38 J/(kg K) = 20352.5 W/K (see
``test_paper_powers_imply_a_slightly_lower_capacity_rate``). From the stated inputs the model
therefore cannot match to the last digit; the tolerances are about five times the largest
resulting difference (0.03 deg C, 0.17 % on the plant area) and still far below what would
distinguish a wrong equation (e.g. co-current LMTD: several deg C).

cp of air: the paper does not state it. 1005 J/(kg K) reproduces its air outlet temperatures
(1007, the table value at 30-70 deg C, puts the plant T_ao 0.07 deg C off when the paper's own
Q_m is used; see ``test_paper_used_cp_air_1005``).
"""

from __future__ import annotations

import math

import pytest

from drumflow.analysis.heat_transfer import falling_particle_area
from drumflow.errors import AnalysisInputError
from drumflow.physics.exchanger import (
    ExchangerResult,
    InfeasibleExchangerError,
    area_for_outlet_temperature,
    counter_current_exchanger,
    exchanger_area_from_section,
    solve_outlet_temperature,
)

PLANT = dict(
    material_mass_flow_kg_s=13.88889,
    material_cp_j_kgk=1465.38,
    material_inlet_temperature_c=90.0,
    air_mass_flow_kg_s=25.0,
    air_cp_j_kgk=1005.0,
    air_inlet_temperature_c=30.0,
)

TEMP_TOL = 0.1  # deg C, see module docstring
REL_TOL = 0.005  # 0.5 %, see module docstring


def _check_column(
    r: ExchangerResult, t_mo: float, q_kw: float, t_ao: float, lmtd: float, area: float
) -> None:
    assert abs(r.material_outlet_temperature_c - t_mo) < TEMP_TOL
    assert r.heat_removed_w / 1e3 == pytest.approx(q_kw, rel=REL_TOL)
    assert abs(r.air_outlet_temperature_c - t_ao) < TEMP_TOL
    assert r.lmtd_c == pytest.approx(lmtd, rel=REL_TOL)
    assert r.area_m2 == pytest.approx(area, rel=REL_TOL)
    # Eq. 48 holds at the solution to solver precision (brentq xtol 1e-12 K on ~1 MW): 1e-6 rel.
    assert r.heat_exchanged_w == pytest.approx(r.heat_removed_w, rel=1e-6)


# ------------------------------------------------------------------------------ Table 7


def test_table7_model_one_forward() -> None:
    r = solve_outlet_temperature(h_w_m2k=60.15, area_m2=1099.28, **PLANT)
    _check_column(r, t_mo=40.90, q_kw=998.40, t_ao=69.73, lmtd=15.10, area=1099.28)
    # The paper's Q_he for this column is 998.48 kW.
    assert r.heat_exchanged_w / 1e3 == pytest.approx(998.48, rel=REL_TOL)


def test_table7_model_two_forward() -> None:
    # Table 7 uses h = 38.92 for model two (Table 6 prints 38.93).
    r = solve_outlet_temperature(h_w_m2k=38.92, area_m2=443.13, **PLANT)
    _check_column(r, t_mo=61.23, q_kw=584.87, t_ao=53.27, lmtd=33.90, area=443.13)
    assert r.heat_exchanged_w / 1e3 == pytest.approx(584.88, rel=REL_TOL)


def test_table7_industry_cooler_inverse() -> None:
    r = area_for_outlet_temperature(h_w_m2k=60.15, material_outlet_temperature_c=45.0, **PLANT)
    _check_column(r, t_mo=45.0, q_kw=915.04, t_ao=66.42, lmtd=18.97, area=802.01)


@pytest.mark.parametrize(("h", "area"), [(60.15, 1099.28), (38.92, 443.13)])
def test_table7_models_inverse_gives_back_the_area(h: float, area: float) -> None:
    forward = solve_outlet_temperature(h_w_m2k=h, area_m2=area, **PLANT)
    back = area_for_outlet_temperature(
        h_w_m2k=h, material_outlet_temperature_c=forward.material_outlet_temperature_c, **PLANT
    )
    # Round trip limited by brentq's xtol (1e-12 K) through an LMTD of ~15-34 K: 1e-8 rel.
    assert back.area_m2 == pytest.approx(area, rel=1e-8)


def test_industry_cooler_forward_gives_back_45_c() -> None:
    inv = area_for_outlet_temperature(h_w_m2k=60.15, material_outlet_temperature_c=45.0, **PLANT)
    fwd = solve_outlet_temperature(h_w_m2k=60.15, area_m2=inv.area_m2, **PLANT)
    # brentq xtol is 1e-12 K: 1e-9 K is a comfortable bound.
    assert fwd.material_outlet_temperature_c == pytest.approx(45.0, abs=1e-9)


def test_paper_powers_imply_a_slightly_lower_capacity_rate() -> None:
    # mdot_m cp_m implied by each Table 7 column: Q_m / (T_mi - T_mo).
    implied = [998.40e3 / (90 - 40.90), 584.87e3 / (90 - 61.23), 915.04e3 / (90 - 45.0)]
    stated = 13.88889 * 1465.38
    for c in implied:
        # All three agree with 20334 W/K to within the rounding of T_mo (0.005 K in 29-49 K)...
        assert c == pytest.approx(20334.0, rel=4e-4)
        # ...and are 0.09 % below the stated product, beyond that rounding.
        assert c / stated < 0.9995
    # With the implied capacity rate (mdot_m = 20334.2 / 1465.38 = 13.8764 kg/s) and
    # cp_a = 1005 the model reproduces the plant column to the paper's last digit.
    plant = {**PLANT, "material_mass_flow_kg_s": 20334.2 / 1465.38}
    r = area_for_outlet_temperature(h_w_m2k=60.15, material_outlet_temperature_c=45.0, **plant)
    # Half a unit of the last printed digit (0.005 deg C, 0.005 kW, 0.005 K, 0.005 m2 + the
    # rounding of h = 60.15 which alone moves the area by 0.008 %, i.e. 0.07 m2).
    assert r.heat_removed_w / 1e3 == pytest.approx(915.04, abs=0.005)
    assert r.air_outlet_temperature_c == pytest.approx(66.42, abs=0.005)
    assert r.lmtd_c == pytest.approx(18.97, abs=0.005)
    assert r.area_m2 == pytest.approx(802.01, abs=0.08)


def test_paper_used_cp_air_1005() -> None:
    # Use the paper's own Q_m (through the implied mdot_m) and vary only cp_a.
    plant = {**PLANT, "material_mass_flow_kg_s": 20334.2 / 1465.38}
    t_ao = {}
    for cp_a in (1005.0, 1007.0):
        r = area_for_outlet_temperature(
            h_w_m2k=60.15, material_outlet_temperature_c=45.0, **{**plant, "air_cp_j_kgk": cp_a}
        )
        t_ao[cp_a] = r.air_outlet_temperature_c
    # 1005 lands within the printed rounding (0.005 deg C) of 66.42; 1007 is 0.07 deg C off.
    assert abs(t_ao[1005.0] - 66.42) < 0.005
    assert abs(t_ao[1007.0] - 66.42) > 0.05


# ------------------------------------------------------------------- A_he from Table 6


def test_section_area_model_one_from_table6() -> None:
    a_fp = falling_particle_area(0.04, 0.008, 1050.0)  # 0.028571 m2, unrounded
    a_he = exchanger_area_from_section(a_fp, cooler_length_m=19.0, section_length_m=0.1, dt_s=0.005)
    # 0.028571 * 190 / 0.005 = 1085.7 m2, 1.2 % below Table 7's 1099.28. Table 6 prints
    # A_fp = 0.029 +/- 0.0005 m2 (+/- 1.7 %) and m_mf = 0.04 kg to one significant digit, so the
    # printed inputs pin A_he only to +/- 1.7 %; Table 7's area implies m_mf = 0.0405 kg.
    assert a_he == pytest.approx(1099.28, rel=0.0005 / 0.029)
    # With Table 6's rounded A_fp itself: 1102.0 m2, inside the same +/- 1.7 %.
    a_he_rounded = exchanger_area_from_section(
        0.029, cooler_length_m=19.0, section_length_m=0.1, dt_s=0.005
    )
    assert a_he_rounded == pytest.approx(1099.28, rel=0.0005 / 0.029)


def test_section_area_model_two_from_table6() -> None:
    a_fp = falling_particle_area(0.82, 0.020, 1050.0)  # 0.23429 m2, unrounded
    a_he = exchanger_area_from_section(a_fp, cooler_length_m=19.0, section_length_m=1.0, dt_s=0.01)
    # 445.1 m2, 0.45 % above 443.13: m_mf = 0.82 kg is printed to +/- 0.005 kg (+/- 0.61 %).
    assert a_he == pytest.approx(443.13, rel=0.005 / 0.82)
    a_he_rounded = exchanger_area_from_section(
        0.233, cooler_length_m=19.0, section_length_m=1.0, dt_s=0.01
    )
    # 442.7 m2 from the printed A_fp = 0.233 +/- 0.0005 (+/- 0.21 %).
    assert a_he_rounded == pytest.approx(443.13, rel=0.0005 / 0.233)


def test_section_area_scales_with_l_not_just_l_cap() -> None:
    # Eq. 46 as printed lacks the section length; the corrected form divides by it.
    a1 = exchanger_area_from_section(0.1, cooler_length_m=19.0, section_length_m=0.1, dt_s=0.01)
    a2 = exchanger_area_from_section(0.1, cooler_length_m=19.0, section_length_m=1.0, dt_s=0.01)
    assert a1 == pytest.approx(10.0 * a2, rel=1e-12)  # exact arithmetic
    assert a2 == pytest.approx(0.1 * 19.0 / 0.01, rel=1e-12)


# --------------------------------------------------------------- independent cross-checks


def _epsilon_ntu_outlet(
    h: float, area: float, c_m: float, c_a: float, t_mi: float, t_ai: float
) -> float:
    c_min, c_max = min(c_m, c_a), max(c_m, c_a)
    ntu, cr = h * area / c_min, c_min / c_max
    if math.isclose(cr, 1.0):
        eps = ntu / (1 + ntu)
    else:
        e = math.exp(-ntu * (1 - cr))
        eps = (1 - e) / (1 - cr * e)
    return t_mi - eps * c_min * (t_mi - t_ai) / c_m


@pytest.mark.parametrize(
    "air_flow",
    [25.0, 13.88889 * 1465.38 / 1005.0, 10.0],
    ids=["c_air>c_mat", "equal", "c_air<c_mat"],
)
def test_forward_matches_epsilon_ntu(air_flow: float) -> None:
    plant = {**PLANT, "air_mass_flow_kg_s": air_flow}
    r = solve_outlet_temperature(h_w_m2k=60.15, area_m2=1099.28, **plant)
    expected = _epsilon_ntu_outlet(
        60.15, 1099.28, 13.88889 * 1465.38, air_flow * 1005.0, 90.0, 30.0
    )
    # Closed form vs root finding with xtol 1e-12 K: 1e-8 K.
    assert r.material_outlet_temperature_c == pytest.approx(expected, abs=1e-8)


def test_equal_capacity_rates_have_equal_end_differences() -> None:
    plant = {**PLANT, "air_mass_flow_kg_s": 13.88889 * 1465.38 / 1005.0}
    r = solve_outlet_temperature(h_w_m2k=60.15, area_m2=800.0, **plant)
    end_a = r.material_inlet_temperature_c - r.air_outlet_temperature_c
    end_b = r.material_outlet_temperature_c - r.air_inlet_temperature_c
    # Equal capacity rates make the two end differences equal (to float rounding, 1e-9 K), and
    # the LMTD is their common value (the 0/0 limit of Eq. 47).
    assert end_a == pytest.approx(end_b, abs=1e-9)
    assert r.lmtd_c == pytest.approx(end_a, abs=1e-9)


# ------------------------------------------------------------------------ dispatch, errors


def test_dispatcher_selects_the_direction() -> None:
    fwd = counter_current_exchanger(h_w_m2k=60.15, area_m2=1099.28, **PLANT)
    inv = counter_current_exchanger(h_w_m2k=60.15, material_outlet_temperature_c=45.0, **PLANT)
    assert fwd.area_m2 == 1099.28 and inv.material_outlet_temperature_c == 45.0
    with pytest.raises(AnalysisInputError, match="exactly one"):
        counter_current_exchanger(h_w_m2k=60.15, **PLANT)
    with pytest.raises(AnalysisInputError, match="exactly one"):
        counter_current_exchanger(
            h_w_m2k=60.15, area_m2=1.0, material_outlet_temperature_c=45.0, **PLANT
        )


@pytest.mark.parametrize(
    ("t_mo", "needle"),
    [
        (30.0, "cannot leave colder than the inlet air"),
        (25.0, "cannot leave colder than the inlet air"),
        (90.0, "must be cooled"),
    ],
)
def test_infeasible_outlet_temperature(t_mo: float, needle: str) -> None:
    with pytest.raises(InfeasibleExchangerError) as info:
        area_for_outlet_temperature(h_w_m2k=60.15, material_outlet_temperature_c=t_mo, **PLANT)
    msg = str(info.value)
    assert "material_outlet_temperature_c" in msg and needle in msg
    assert isinstance(info.value, ValueError)


def test_temperature_cross_is_reported_with_feasible_range() -> None:
    # With 5 kg/s of air, cooling the material to 35 deg C would heat the air to 253 deg C.
    plant = {**PLANT, "air_mass_flow_kg_s": 5.0}
    with pytest.raises(InfeasibleExchangerError, match="temperature cross") as info:
        area_for_outlet_temperature(h_w_m2k=60.15, material_outlet_temperature_c=35.0, **plant)
    # Lowest feasible outlet: 90 - (5 * 1005 / 20352.5) * 60 = 75.19 deg C.
    assert "(75.186" in str(info.value)


@pytest.mark.parametrize(
    ("override", "needle"),
    [
        ({"h_w_m2k": 0.0}, "h_w_m2k = 0"),
        ({"area_m2": -5.0}, "area_m2 = -5"),
        ({"material_inlet_temperature_c": 30.0}, "material_inlet_temperature_c = 30"),
        ({"air_cp_j_kgk": float("nan")}, "air_cp_j_kgk = nan"),
    ],
)
def test_bad_arguments_name_the_field(override: dict[str, float], needle: str) -> None:
    args = {"h_w_m2k": 60.15, "area_m2": 1000.0, **PLANT, **override}
    with pytest.raises(AnalysisInputError) as info:
        solve_outlet_temperature(**args)
    assert needle in str(info.value)


def test_section_area_rejects_bad_lengths() -> None:
    with pytest.raises(AnalysisInputError, match="section_length_m = 0"):
        exchanger_area_from_section(0.03, cooler_length_m=19.0, section_length_m=0.0, dt_s=0.005)


def test_pinched_exchanger_returns_the_air_limited_outlet() -> None:
    """Regression: a huge area for little air made brentq fail ('f(a) and f(b) must have
    different signs') and `drumflow report` crash on a real sweep of small drums."""
    from drumflow.physics.exchanger import solve_outlet_temperature

    r = solve_outlet_temperature(
        h_w_m2k=80.0, area_m2=50.0, material_mass_flow_kg_s=13.88889, material_cp_j_kgk=1465.38,
        material_inlet_temperature_c=90.0, air_mass_flow_kg_s=0.05, air_cp_j_kgk=1005.0,
        air_inlet_temperature_c=30.0,
    )
    # Air-limited: the air leaves at the material inlet temperature, and the material cools by
    # exactly the air's capacity rate times 60 K.
    c_a, c_m = 0.05 * 1005.0, 13.88889 * 1465.38
    assert r.air_outlet_temperature_c == pytest.approx(90.0, abs=1e-6)
    assert r.material_outlet_temperature_c == pytest.approx(90.0 - c_a / c_m * 60.0, abs=1e-6)
