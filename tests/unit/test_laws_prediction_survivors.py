"""Law tests for the mutation survivors of :mod:`drumflow.coolers.prediction` (issue 36;
results/mutation/survivors.md).

The mutmut run (tree of d6ddc82, where the module was ``drumflow/analysis/predict.py`` and
``PlantSpec`` lived in it) left alive: the conversion of the paper's Eq. 58 coefficient to
drumflow's Re and Pr (the law test took ``a`` from ``paper_correlation()`` itself), its Re
range and the Table 8 statistics it carries, the Froude number of the centrifuging guard and the
critical speed it advises, the Prandtl range warning, the mean air temperature over the valid
steps only, the air heat capacity of the plant streams, the Nusselt number of a fixed ``h``,
``Prediction`` fields nobody read (``h_source``, velocities, void fraction, reference values)
and the JSON keys of ``to_dict``, Python warnings the module promises not to emit, and the names
in the refusals. Every expected value below is arithmetic written out from the paper's
equations (Burgos-Florez et al., Processes 2019, 7, 673), its Tables 1, 6 and 8, Incropera's
Table A.4 row for air (typed in :mod:`support.law_references`) and the epsilon-NTU outlet of a
counter-current exchanger; none comes from the module.
"""

from __future__ import annotations

import dataclasses
import json
import math
import tomllib
import warnings
from pathlib import Path
from types import SimpleNamespace
from typing import Any

import pandas as pd
import pytest
from support.law_references import counter_current_effectiveness, incropera_air

from drumflow.case import Case, case_from_dict
from drumflow.coolers import prediction
from drumflow.coolers.plant import PlantSpec
from drumflow.errors import AnalysisInputError

CASES = Path(__file__).resolve().parents[2] / "cases"

# Incropera Table A.4 at 303.15 K (30 C, the paper's air inlet), linear between the 300 and
# 350 K rows (w = 0.063): rho = 1.1509168 kg/m3, nu = 16.20689e-6 m2/s, k = 0.0265331 W/(m K),
# Pr = 0.706559.
RHO, _, _, NU, K_AIR, PR = incropera_air(303.15)
AREA_DRUM = math.pi * 3.0**2 / 4.0  # 7.0685835 m2, the 3 m drum's cross-section
A58, B58, C58 = 0.0531283, 0.523707, 1.00824  # Eq. 58 as published
K_PARTICLE = 0.18596  # W/(m K), Table 1
H_TABLE6 = 60.15  # W/(m2 K), Table 6, model one
FALLING = 0.04 / 0.005  # kg/s: Table 6's falling mass per step over model one's 5 ms step
AIR_CP = 1007.0  # J/(kg K): Incropera at 300 K; not the 1005 default, so the case's value shows


def _close(value: float, reference: float, rtol: float, what: str) -> None:
    assert math.isfinite(value) and abs(value / reference - 1.0) <= rtol, (
        f"{what}: {value:.10g} vs independent {reference:.10g} "
        f"({value / reference - 1.0:+.3%}, allowed {rtol:.1e})")


def _case() -> Case:
    """Paper model one (cases/paper_model_one.toml) with the air heat capacity set to 1007."""
    data = tomllib.loads((CASES / "paper_model_one.toml").read_text())
    data["air"]["heat_capacity"] = AIR_CP
    return case_from_dict(data)


CASE = _case()


def _reynolds(air_flow: float, section_m: float, count: float, model_dp: float, dp: float) -> float:
    """Eqs. 51-55: V_ai = m_a / (rho pi D^2 / 4), Vf = (V_d - N pi Dp^3 / 6) / V_d with
    V_d = pi D^2 / 4 l, v_max = V_ai / Vf, Re = v_max Dp / nu (air at 30 C)."""
    v_drum = AREA_DRUM * section_m
    void = (v_drum - count * math.pi * model_dp**3 / 6.0) / v_drum
    return air_flow / (RHO * AREA_DRUM) / void * dp / NU


# Model one (Dp 8 mm, l = 0.1 m, 467,443 spheres): V_ai = 25 / 8.1353515 = 3.0730080 m/s,
# Vf = 1 - 0.12531332 / 0.70685835 = 0.82271791, Re = 1843.7543. Model two (20 mm, 1 m,
# 299,164): Vf = 0.82271763, Re = 4609.3872. The paper's Re at the ends of Eq. 58's range
# (3073, 7686) over these: 1.6667080 and 1.6674668, mean f_Re = 1.6670874.
RE_ONE = _reynolds(25.0, 0.1, 467443, 0.008, 0.008)
RE_TWO = _reynolds(25.0, 1.0, 299164, 0.020, 0.020)
F_RE = (3073.0 / RE_ONE + 7686.0 / RE_TWO) / 2.0
F_PR = 0.7282 / PR  # the paper's Pr at 30 C over Table A.4's: 1.0306287
A_DRUMFLOW = A58 * F_RE**B58 * F_PR**C58  # 0.0531283 x 1.3065 x 1.0309 = 0.07157762


def _exchanger(ua: float, c_material: float, c_air: float) -> tuple[float, float]:
    """Counter-current (T_mo, T_ao) from epsilon-NTU, material in at 90 C, air at 30 C."""
    c_min, c_max = min(c_material, c_air), max(c_material, c_air)
    duty = counter_current_effectiveness(ua / c_min, c_min / c_max) * c_min * (90.0 - 30.0)
    return 90.0 - duty / c_material, 30.0 + duty / c_air


def check_paper_correlation() -> None:
    """Eq. 58 in drumflow's Re and Pr: a' = a f_Re^b f_Pr^c = 0.07157762 (module notes),
    b and c as published, the Re range 3073 / f_Re to 7686 / f_Re = 1843.3347 to 4610.4362,
    the Pr range Table A.4's 0.706559 at 30 C. At model one's drumflow Re and Pr it gives the
    paper's Nu = 0.0531283 x 3073^0.523707 x 0.7282^1.00824 = 2.587632 to the 0.012 % that the
    single factor f_Re leaves (model one's own ratio is 0.023 % from the mean).
    Both sides are closed form with the same table row: 1e-9.
    """
    corr = prediction.paper_correlation()
    _close(corr.a, A_DRUMFLOW, 1e-9, "Eq. 58 coefficient in drumflow's Re and Pr")
    assert (corr.b, corr.c) == (B58, C58)
    _close(corr.reynolds_range[0], 3073.0 / F_RE, 1e-9, "lower end of the Re range")
    _close(corr.reynolds_range[1], 7686.0 / F_RE, 1e-9, "upper end of the Re range")
    _close(corr.prandtl_range[0], PR, 1e-9, "Pr range")
    _close(corr.prandtl_range[1], PR, 1e-9, "Pr range")
    published = A58 * 3073.0**B58 * 0.7282**C58
    _close(float(corr.predict(RE_ONE, PR, warn=False)), published, 2e-4,
           "converted Eq. 58 at model one's Re gives the paper's Nu")


def check_prediction_fixed_h() -> None:
    """predict_plant with Table 6's h = 60.15 W/(m2 K) held fixed, from the falling mass flow
    F_ref = 0.04 kg / 0.005 s = 8 kg/s, at rpm 6, 1.1 x the feed, Dp = 10 mm and 30 kg/s of air.

    Assumptions 1-2: ratio = 1.1 x 6 / 5 = 1.32, F = 10.56 kg/s; A_ref = 6 F_ref / (rho_p Dp)
    x L / l = 6 x 8 / (1050 x 0.008) x 19 / 0.1 = 1085.7143 m2; A = 1085.7143 x 1.32 x 0.8 =
    1146.5143 m2. Assumptions 3-4: Vf_ref = 0.82271791, Vf = 1 - 1.1 x 0.12531332 / 0.70685835
    = 0.80498971; V_ai = 30 / 8.1353515 = 3.6876096 m/s, v_max = 4.5809400 m/s,
    Re = 4.5809400 x 0.01 / 16.20689e-6 = 2826.5386 (reference 1843.7543). Nu = h Dp / k_air
    = 60.15 x 0.01 / 0.0265331 = 22.669797. Streams (Eqs. 42-48) with the case's air c_p =
    1007: C_m = 1.1 x 13.88889 x 1465.38, C_a = 30 x 1007; epsilon-NTU gives T_mo = 40.5033 C,
    T_ao = 66.6806 C (reference: 41.0452 C, 69.5770 C).
    Closed form except the package's brentq (xtol 1e-12 K): 1e-9 relative, 1e-6 on the
    temperature changes.
    """
    p = prediction.predict_plant(H_TABLE6, CASE, rpm=6.0, feed_rate=1.1 * 13.88889,
                                 particle_diameter=0.01, air_mass_flow=30.0,
                                 falling_mass_flow_kg_s=FALLING)
    assert p.h_source == "fixed"
    assert p.h_w_m2k == p.reference_h_w_m2k == H_TABLE6
    assert p.measured_h_w_m2k is None
    assert p.air_property_temperature_c == 30.0  # no reference run: T_ai
    _close(p.conductivity_w_mk, K_AIR, 1e-9, "air conductivity at 30 C")
    _close(p.prandtl, PR, 1e-9, "Pr at 30 C")
    area_ref = 6.0 * FALLING / (1050.0 * 0.008) * 19.0 / 0.1
    area = area_ref * 1.32 * 0.8
    _close(p.reference_falling_mass_flow_kg_s, FALLING, 1e-12, "reference falling mass flow")
    _close(p.falling_mass_flow_kg_s, FALLING * 1.32, 1e-12, "falling mass flow")
    _close(p.reference_exchanger_area_m2, area_ref, 1e-12, "reference exchange area")
    _close(p.exchanger_area_m2, area, 1e-12, "exchange area")
    v_drum = AREA_DRUM * 0.1
    v_solids = 467443 * math.pi * 0.008**3 / 6.0
    _close(p.reference_void_fraction, (v_drum - v_solids) / v_drum, 1e-12, "reference Vf")
    _close(p.void_fraction, (v_drum - 1.1 * v_solids) / v_drum, 1e-12, "Vf")
    v_ai = 30.0 / (RHO * AREA_DRUM)
    _close(p.air_inlet_velocity_m_s, v_ai, 1e-9, "V_ai")
    _close(p.max_air_velocity_m_s, v_ai / ((v_drum - 1.1 * v_solids) / v_drum), 1e-9, "v_max")
    _close(p.reynolds, _reynolds(30.0, 0.1, 1.1 * 467443, 0.008, 0.01), 1e-9, "Re")
    _close(p.reference_reynolds, RE_ONE, 1e-9, "reference Re")
    _close(p.nusselt, H_TABLE6 * 0.01 / K_AIR, 1e-9, "Nu = h Dp / k of the fixed h")
    c_m, c_m_ref = 1.1 * 13.88889 * 1465.38, 13.88889 * 1465.38
    t_mo, t_ao = _exchanger(H_TABLE6 * area, c_m, 30.0 * AIR_CP)
    _close(90.0 - p.material_outlet_temperature_c, 90.0 - t_mo, 1e-6, "T_mi - T_mo")
    _close(p.air_outlet_temperature_c - 30.0, t_ao - 30.0, 1e-6, "T_ao - T_ai")
    t_mo, t_ao = _exchanger(H_TABLE6 * area_ref, c_m_ref, 25.0 * AIR_CP)
    _close(90.0 - p.reference_exchanger.material_outlet_temperature_c, 90.0 - t_mo, 1e-6,
           "reference T_mi - T_mo")
    _close(p.reference_exchanger.air_outlet_temperature_c - 30.0, t_ao - 30.0, 1e-6,
           "reference T_ao - T_ai")
    assert len(p.warnings) == 1 and p.warnings[0].startswith("h held at 60.15 W/(m2 K)")


def check_prediction_paper_correlation() -> None:
    """The same change with the converted Eq. 58 (particle conductivity in Nu):
    h = a' Re^b Pr^c k_p / Dp = 0.07157762 x 2826.5386^0.523707 x 0.706559^1.00824 x 0.18596
    / 0.01 = 60.19336 W/(m2 K), reference (Re 1843.7543, Dp 8 mm) 60.15667 W/(m2 K) (Table 6:
    60.15). Both Re lie in [1843.3347, 4610.4362]: no warning. epsilon-NTU: T_mo = 40.4942 C.
    1e-9 on h, 1e-6 on the temperature change.
    """
    p = prediction.predict_plant(prediction.paper_correlation(), CASE, rpm=6.0,
                                 feed_rate=1.1 * 13.88889, particle_diameter=0.01,
                                 air_mass_flow=30.0, falling_mass_flow_kg_s=FALLING,
                                 nusselt_conductivity="particle")
    assert p.h_source == "correlation"
    assert p.conductivity_w_mk == K_PARTICLE
    re_new = _reynolds(30.0, 0.1, 1.1 * 467443, 0.008, 0.01)
    nu_new = A_DRUMFLOW * re_new**B58 * PR**C58
    _close(p.nusselt, nu_new, 1e-9, "Nu from the converted Eq. 58")
    _close(p.h_w_m2k, nu_new * K_PARTICLE / 0.01, 1e-9, "h = Nu k_p / Dp")
    h_ref = A_DRUMFLOW * RE_ONE**B58 * PR**C58 * K_PARTICLE / 0.008
    _close(p.reference_h_w_m2k, h_ref, 1e-9, "reference h")
    assert p.warnings == [] and p.range_warnings == []
    area = 6.0 * FALLING / (1050.0 * 0.008) * 19.0 / 0.1 * 1.32 * 0.8
    t_mo, _ = _exchanger(p.h_w_m2k * area, 1.1 * 13.88889 * 1465.38, 30.0 * AIR_CP)
    _close(90.0 - p.material_outlet_temperature_c, 90.0 - t_mo, 1e-6, "T_mi - T_mo")


def test_paper_correlation_written_out() -> None:
    check_paper_correlation()


def test_paper_correlation_carries_table8() -> None:
    """The statistics of the paper's Table 8 as printed: 4,802 observations, three fitted
    parameters (c fitted), none dropped, total SS 58470.6 and error SS 4.05118 (4,799 error
    degrees of freedom), MS_error 0.000844 (residual std sqrt(0.000844) = 0.02905168),
    adjusted R^2 99.8634 %. The paper gives no R^2, standard errors or intervals: NaN."""
    corr = prediction.paper_correlation()
    assert (corr.n, corr.n_params, corr.n_dropped) == (4802, 3, 0)
    assert corr.prandtl_exponent_fitted is True
    assert (corr.anova.ss_total, corr.anova.ss_error) == (58470.6, 4.05118)
    assert (corr.anova.df_model, corr.anova.df_error) == (3, 4799)
    _close(corr.residual_std, math.sqrt(0.000844), 1e-12, "residual std of Table 8")
    assert corr.adjusted_r_squared == 0.998634
    not_given = [corr.r_squared, corr.se_a, corr.se_b, corr.se_c, *corr.ci_a, *corr.ci_b,
                 *corr.ci_c]
    assert all(math.isnan(x) for x in not_given)
    assert "Re range 3073-7686 / 1.6671" in corr.note


def test_prediction_with_fixed_h_written_out() -> None:
    check_prediction_fixed_h()


def test_prediction_with_paper_correlation_written_out() -> None:
    check_prediction_paper_correlation()


def test_plant_of_the_case() -> None:
    """PlantSpec.from_case against cases/paper_model_one.toml, typed (air c_p set to 1007)."""
    plant = PlantSpec.from_case(CASE)
    assert dataclasses.asdict(plant) == {
        "diameter_m": 3.0, "length_m": 19.0, "rpm": 5.0, "tilt_deg": 1.5,
        "feed_rate_kg_s": 13.88889, "material_inlet_temperature_c": 90.0,
        "air_mass_flow_kg_s": 25.0, "air_inlet_temperature_c": 30.0,
        "particle_diameter_m": 0.008, "particle_density_kg_m3": 1050.0,
        "particle_heat_capacity_j_kgk": 1465.38, "particle_conductivity_w_mk": 0.18596,
        "air_heat_capacity_j_kgk": AIR_CP, "residence_time_s": None,
        "measured_material_outlet_c": 45.0, "measured_air_outlet_c": None,
    }


def test_centrifuging_speed() -> None:
    """Froude = omega^2 R / g with omega = 2 pi N / 60, R = 1.5 m: the critical speed is
    60 / (2 pi) sqrt(9.81 / 1.5) = 9.549297 x 2.557342 = 24.42082 rpm. At 24.3 rpm,
    Fr = (24.3 / 24.42082)^2 = 0.9901 (accepted); at 24.55 rpm, 1.0106 (refused, the message
    advises 24.4 rpm)."""
    prediction.predict_plant(H_TABLE6, CASE, rpm=24.3, falling_mass_flow_kg_s=FALLING)
    with pytest.raises(AnalysisInputError, match=r"a speed below 24\.4 rpm \(Froude 1\.01 >= 1") as err:
        prediction.predict_plant(H_TABLE6, CASE, rpm=24.55, falling_mass_flow_kg_s=FALLING)
    assert (err.value.name, err.value.value) == ("rpm", 24.55)


def test_prandtl_range_warning() -> None:
    """A correlation fitted at Pr 0.72-0.75 is more than 1 % above the air's 0.706559
    (0.72 x 0.99 = 0.7128); one at Pr 0.60-0.69 more than 1 % below it (0.69 x 1.01 = 0.6969);
    one at exactly 0.70 is within 1 % (0.707). The function emits no Python warning (module
    notes): the range warnings are returned, so a batch can be reported."""
    corr = prediction.paper_correlation()
    for pr_range, flagged in (((0.72, 0.75), True), ((0.60, 0.69), True), ((0.70, 0.70), False)):
        shifted = dataclasses.replace(corr, prandtl_range=pr_range)
        with warnings.catch_warnings():
            warnings.simplefilter("error")
            p = prediction.predict_plant(shifted, CASE, falling_mass_flow_kg_s=FALLING,
                                         nusselt_conductivity="particle")
        texts = [str(w) for w in p.range_warnings]
        if flagged:
            assert len(p.range_warnings) == 1
            assert isinstance(p.range_warnings[0], prediction.CorrelationRangeWarning)
            assert texts[0].startswith("Pr = 0.7066 is more than 1% outside")
            assert p.warnings == texts
        else:
            assert p.range_warnings == [] and p.warnings == []


def test_reynolds_range_warning_and_its_ends() -> None:
    """At 80 kg/s of air drumflow's Re is 1843.7543 x 80 / 25 = 5900.01, above the converted
    range's 4610.4362: one warning, no Python warning. A range that ends exactly at the
    prediction's Re is inside (both ends are included)."""
    corr = prediction.paper_correlation()
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        p = prediction.predict_plant(corr, CASE, air_mass_flow=80.0,
                                     falling_mass_flow_kg_s=FALLING,
                                     nusselt_conductivity="particle")
    _close(p.reynolds, RE_ONE * 80.0 / 25.0, 1e-9, "Re at 80 kg/s")
    assert len(p.range_warnings) == 1
    assert str(p.range_warnings[0]).endswith(
        "outside the correlation's range [1843.3, 4610.4]: the predicted h is an extrapolation")
    for ends in ((p.reynolds, 1e5), (1.0, p.reynolds)):
        p_edge = prediction.predict_plant(dataclasses.replace(corr, reynolds_range=ends), CASE,
                                          air_mass_flow=80.0, falling_mass_flow_kg_s=FALLING,
                                          nusselt_conductivity="particle")
        assert p_edge.range_warnings == []


def test_air_properties_at_the_mean_of_valid_steps() -> None:
    """With a reference run, the air properties are taken at the mean T_ma of its valid steps
    (assumption 5): steps at 45, 30.2, 30.4 and 45 C with only the middle two valid give
    30.3 C (all four would give 37.65 C). predict_plant reads from the run only ``case``,
    ``steps``, ``falling_mass_flow_kg_s``, ``exchanger_area_m2`` and ``h_mean_w_m2k``."""
    steps = pd.DataFrame({"valid": [False, True, True, False],
                          "mean_air_temperature_C": [45.0, 30.2, 30.4, 45.0]})
    run: Any = SimpleNamespace(case=CASE, steps=steps, falling_mass_flow_kg_s=FALLING,
                               exchanger_area_m2=1085.7142857142858, h_mean_w_m2k=H_TABLE6)
    p = prediction.predict_plant(H_TABLE6, CASE, reference=run)
    _close(p.air_property_temperature_c, 30.3, 1e-12, "air property temperature")
    assert p.measured_h_w_m2k == H_TABLE6 and p.warnings == []


def test_json_keys() -> None:
    """The keys of ``drumflow predict --json`` (Prediction.to_dict), typed, with their values."""
    p = prediction.predict_plant(H_TABLE6, CASE, air_mass_flow=30.0,
                                 falling_mass_flow_kg_s=FALLING)
    d = json.loads(json.dumps(p.to_dict(), allow_nan=False))
    fields = {
        "h_source": p.h_source, "air_property_temperature_C": p.air_property_temperature_c,
        "conductivity_W_mK": p.conductivity_w_mk, "void_fraction": p.void_fraction,
        "reference_void_fraction": p.reference_void_fraction,
        "air_inlet_velocity_m_s": p.air_inlet_velocity_m_s,
        "max_air_velocity_m_s": p.max_air_velocity_m_s, "reynolds": p.reynolds,
        "reference_reynolds": p.reference_reynolds, "prandtl": p.prandtl,
        "nusselt": p.nusselt, "h_W_m2K": p.h_w_m2k, "reference_h_W_m2K": p.reference_h_w_m2k,
        "measured_h_W_m2K": None, "falling_mass_flow_kg_s": p.falling_mass_flow_kg_s,
        "reference_falling_mass_flow_kg_s": p.reference_falling_mass_flow_kg_s,
        "area_he_m2": p.exchanger_area_m2, "reference_area_he_m2": p.reference_exchanger_area_m2,
    }
    assert set(d) == {*fields, "reference", "conditions", "exchanger", "reference_exchanger",
                      "warnings", "assumptions"}
    for key, value in fields.items():
        assert d[key] == value, key
    assert d["reference"]["air_mass_flow_kg_s"] == 25.0
    assert d["conditions"]["air_mass_flow_kg_s"] == 30.0
    assert d["exchanger"]["material_outlet_temperature_c"] == p.material_outlet_temperature_c
    assert (d["reference_exchanger"]["material_outlet_temperature_c"]
            == p.reference_exchanger.material_outlet_temperature_c)
    assert d["warnings"] == p.warnings and len(d["warnings"]) == 1


@pytest.mark.parametrize(("kwargs", "name", "value", "allowed"), [
    ({"nusselt_conductivity": "gas"}, "nusselt_conductivity", "gas", "'air' or 'particle'"),
    ({"falling_mass_flow_kg_s": None}, "reference or falling_mass_flow_kg_s", "none given",
     "exactly one: the reference run's methodology result or its falling mass flow"),
    ({"reference": "run"}, "reference or falling_mass_flow_kg_s", "both given", None),
    ({"correlation_or_h": "60"}, "correlation_or_h", "str",
     "a NusseltCorrelation or a heat-transfer coefficient in W/(m2 K)"),
    ({"correlation_or_h": -1.0}, "correlation_or_h", -1.0, None),
    ({"rpm": -5.0}, "rpm", -5.0, None),
    ({"air_mass_flow": 0.0}, "air_mass_flow", 0.0, None),
    ({"feed_rate": -1.0}, "feed_rate", -1.0, None),
    ({"feed_rate": 100.0}, "feed_rate", 100.0, None),  # hold-up 0.90 m3 > the 0.71 m3 section
    ({"particle_diameter": 0.0}, "particle_diameter", 0.0, None),
    ({"falling_mass_flow_kg_s": -8.0}, "falling_mass_flow_kg_s", -8.0, None),
])
def test_refusals_name_the_argument(kwargs: dict[str, Any], name: str, value: object,
                                    allowed: str | None) -> None:
    args: dict[str, Any] = {"correlation_or_h": H_TABLE6, "case": CASE,
                            "falling_mass_flow_kg_s": FALLING, **kwargs}
    with pytest.raises(AnalysisInputError) as err:
        prediction.predict_plant(**args)
    assert (err.value.name, err.value.value) == (name, value)
    if allowed is not None:
        assert err.value.allowed == allowed
    if name == "feed_rate" and value == 100.0:
        assert err.value.allowed.startswith("a feed rate whose hold-up fits the drum section")


def test_air_property_temperature_out_of_the_table() -> None:
    """A reference run whose mean T_ma is outside the air table is refused under that name."""
    steps = pd.DataFrame({"valid": [True], "mean_air_temperature_C": [5000.0]})
    run: Any = SimpleNamespace(case=CASE, steps=steps, falling_mass_flow_kg_s=FALLING,
                               exchanger_area_m2=1085.7142857142858, h_mean_w_m2k=H_TABLE6)
    with pytest.raises(AnalysisInputError) as err:
        prediction.predict_plant(H_TABLE6, CASE, reference=run)
    assert err.value.name == "air property temperature"


def test_case_without_air_flow_is_refused() -> None:
    """A case may have no air (``air.mass_flow = 0`` is valid for a DEM-only run); it has no
    Re to scale from, and the refusal names the case's air flow."""
    data = tomllib.loads((CASES / "paper_model_one.toml").read_text())
    data["air"]["mass_flow"] = 0.0
    with pytest.raises(AnalysisInputError) as err:
        prediction.predict_plant(H_TABLE6, case_from_dict(data), falling_mass_flow_kg_s=FALLING)
    assert (err.value.name, err.value.value) == ("air.mass_flow of the case", 0.0)
