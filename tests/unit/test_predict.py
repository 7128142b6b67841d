"""Plant predictions: identity at the case's own conditions, the scaling laws, range warnings."""

from __future__ import annotations

import dataclasses
import json
import math
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from support.synthetic_run import AIR_FLOW

from drumflow.analysis.correlation import (
    CorrelationRangeWarning,
    NusseltCorrelation,
    fit_nusselt_correlation,
)
from drumflow.analysis.methodology import analyse_run
from drumflow.analysis.methodology_result import MethodologyResult, plant_streams
from drumflow.coolers.prediction import ASSUMPTIONS, PAPER_REYNOLDS_RANGE, predict_plant
from drumflow.errors import AnalysisInputError
from drumflow.physics.exchanger import solve_outlet_temperature


@pytest.fixture(scope="module")
def reference(
    tmp_path_factory: pytest.TempPathFactory,
    write_synthetic_run: Callable[..., Any],
) -> MethodologyResult:
    root = write_synthetic_run(tmp_path_factory.mktemp("pred") / "run", extras=False)
    return analyse_run(root, nusselt_conductivity="particle")


def _correlation(b: float, reynolds_range: tuple[float, float], c: float = 1 / 3) -> NusseltCorrelation:
    """A correlation Nu = 0.05 Re^b Pr^c valid on ``reynolds_range`` (fitted to exact data)."""
    re = np.linspace(*reynolds_range, 20)
    pr = np.full(re.size, 0.7)
    nu = 0.05 * re**b * pr**c
    # Exact power-law data: the fit returns a, b to ~1e-10; range = the data's range.
    return fit_nusselt_correlation(nu, re, pr, fit_prandtl_exponent=False, fixed_prandtl_exponent=c)


def test_identity_with_fixed_h(reference: MethodologyResult) -> None:
    pred = predict_plant(reference.h_mean_w_m2k, reference.case, reference=reference)
    # Same h, same A_he (ratios exactly 1), same streams, same solver: identical results.
    assert pred.material_outlet_temperature_c == reference.exchanger.material_outlet_temperature_c
    assert pred.air_outlet_temperature_c == reference.exchanger.air_outlet_temperature_c
    assert pred.exchanger_area_m2 == reference.exchanger_area_m2
    assert pred.exchanger == pred.reference_exchanger
    assert pred.warnings == [] and pred.range_warnings == []
    assert pred.measured_h_w_m2k == reference.h_mean_w_m2k
    assert pred.assumptions == ASSUMPTIONS


def test_identity_from_the_falling_mass_flow(reference: MethodologyResult) -> None:
    # Without the result object, A_he comes from the falling mass flow alone (Eq. 46 at
    # dt = 1 s); it equals the run's A_he up to float rounding of dt: 1e-12 relative, which
    # moves T_mo by far less than 1e-9 K.
    pred = predict_plant(
        reference.h_mean_w_m2k,
        reference.case,
        falling_mass_flow_kg_s=reference.falling_mass_flow_kg_s,
    )
    assert pred.exchanger_area_m2 == pytest.approx(reference.exchanger_area_m2, rel=1e-12)
    assert pred.material_outlet_temperature_c == pytest.approx(
        reference.exchanger.material_outlet_temperature_c, abs=1e-9
    )


def test_correlation_at_own_conditions(reference: MethodologyResult) -> None:
    corr = _correlation(0.5, (0.5 * reference.reynolds.min(), 2.0 * reference.reynolds.max()))
    pred = predict_plant(corr, reference.case, reference=reference, nusselt_conductivity="particle")
    # h from the correlation at the case's Re and Pr, with k = particle conductivity (Eq. 49).
    h = corr.predict(pred.reynolds, pred.prandtl, warn=False) * 0.18596 / 0.008
    assert pred.h_w_m2k == pytest.approx(h, rel=1e-12)
    direct = solve_outlet_temperature(
        h_w_m2k=h, area_m2=reference.exchanger_area_m2, **plant_streams(reference.case)
    )
    # Same solver and inputs equal to 1e-12: T_mo to 1e-9 K.
    assert pred.material_outlet_temperature_c == pytest.approx(
        direct.material_outlet_temperature_c, abs=1e-9
    )
    assert pred.reynolds == pred.reference_reynolds
    # The property temperature is the run's mean T_ma, so the case's own Re lies inside the
    # per-step Re range of the run (no spurious range warning at the reference point).
    assert reference.reynolds.min() <= pred.reynolds <= reference.reynolds.max()


def test_air_flow_scales_re_and_h(reference: MethodologyResult) -> None:
    b = 0.5
    corr = _correlation(b, (0.5 * reference.reynolds.min(), 4.0 * reference.reynolds.max()))
    pred = predict_plant(corr, reference.case, reference=reference,
                         nusselt_conductivity="particle", air_mass_flow=2 * AIR_FLOW)
    # Assumption 4: Re is proportional to the air flow; h to Re^b (same Dp, Pr, k). The fit
    # of exact data returns b to ~1e-10, hence 1e-9.
    assert pred.reynolds / pred.reference_reynolds == pytest.approx(2.0, rel=1e-12)
    assert pred.h_w_m2k / pred.reference_h_w_m2k == pytest.approx(2.0**b, rel=1e-9)
    # More air (and more h) cools the material more; the area does not change.
    assert pred.exchanger_area_m2 == reference.exchanger_area_m2
    assert pred.material_outlet_temperature_c < pred.reference_exchanger.material_outlet_temperature_c
    assert pred.warnings == []


def test_feed_rate_rpm_and_diameter_scale_the_area(reference: MethodologyResult) -> None:
    case = reference.case
    pred = predict_plant(reference.h_mean_w_m2k, case, reference=reference,
                         rpm=1.5 * case.drum.rpm, feed_rate=2.0 * case.plant.material_mass_flow,
                         particle_diameter=0.5 * case.particles.diameter)
    # Assumptions 1-2: F x (2 x 1.5), A_he x (2 x 1.5) x (Dp_ref / Dp = 2). Exact ratios: 1e-12.
    assert pred.falling_mass_flow_kg_s == pytest.approx(3.0 * reference.falling_mass_flow_kg_s, rel=1e-12)
    assert pred.exchanger_area_m2 == pytest.approx(6.0 * reference.exchanger_area_m2, rel=1e-12)
    # Assumption 3: twice the solids volume, so a smaller void fraction.
    v_d = math.pi * 0.2**2 * 0.08
    v_m = 2 * 3000 * math.pi / 6 * 0.008**3
    assert pred.void_fraction == pytest.approx((v_d - v_m) / v_d, rel=1e-12)
    # Fixed h with changed conditions is flagged.
    assert any("h held at" in w for w in pred.warnings)
    assert pred.range_warnings == []
    # The plant streams use the new feed rate.
    assert pred.exchanger.heat_removed_w == pytest.approx(
        2.0 * 13.88889 * 1465.38
        * (90.0 - pred.material_outlet_temperature_c), rel=1e-12
    )


def test_range_warning_outside_reynolds_range(reference: MethodologyResult) -> None:
    # A correlation fitted on the paper's range; the smoke section at 25 kg/s of air has Re of
    # order 1e5, far above 7686.
    corr = _correlation(0.523707, PAPER_REYNOLDS_RANGE)
    pred = predict_plant(corr, reference.case, reference=reference)
    assert pred.reynolds > PAPER_REYNOLDS_RANGE[1]
    assert len(pred.range_warnings) == 1
    assert isinstance(pred.range_warnings[0], CorrelationRangeWarning)
    assert "outside the correlation's range" in pred.warnings[0]
    assert "Re = " in str(pred.range_warnings[0])


def test_no_range_warning_inside(reference: MethodologyResult) -> None:
    lo, hi = 0.9 * reference.reynolds.min(), 1.1 * reference.reynolds.max()
    pred = predict_plant(_correlation(0.5, (lo, hi)), reference.case, reference=reference)
    assert pred.range_warnings == [] and pred.warnings == []
    # Leaving it by air flow triggers the warning.
    pred = predict_plant(_correlation(0.5, (lo, hi)), reference.case, reference=reference,
                         air_mass_flow=3 * AIR_FLOW)
    assert len(pred.range_warnings) == 1


def test_to_dict_is_json(reference: MethodologyResult) -> None:
    corr = _correlation(0.5, PAPER_REYNOLDS_RANGE)
    d = predict_plant(corr, reference.case, reference=reference, rpm=20.0).to_dict()
    text = json.dumps(d, allow_nan=False)
    assert "assumptions" in d and d["conditions"]["rpm"] == 20.0 and "warnings" in text


def test_errors(reference: MethodologyResult) -> None:
    case = reference.case
    with pytest.raises(AnalysisInputError, match="exactly one"):
        predict_plant(50.0, case)
    with pytest.raises(AnalysisInputError, match="exactly one"):
        predict_plant(50.0, case, reference=reference, falling_mass_flow_kg_s=0.05)
    with pytest.raises(AnalysisInputError, match="correlation_or_h"):
        predict_plant(-1.0, case, reference=reference)
    with pytest.raises(AnalysisInputError, match="rpm.*centrifuging"):
        predict_plant(50.0, case, reference=reference, rpm=200.0)
    with pytest.raises(AnalysisInputError, match="feed_rate"):
        predict_plant(50.0, case, reference=reference, feed_rate=1e3 * case.plant.material_mass_flow)
    with pytest.raises(AnalysisInputError, match="air_mass_flow"):
        predict_plant(50.0, case, reference=reference, air_mass_flow=0.0)


def test_reference_of_another_case_is_flagged(
    reference: MethodologyResult,
    tmp_path: Path,
    synthetic_case_dict: Callable[..., Any],
) -> None:
    from drumflow.case import case_from_dict

    other = case_from_dict(synthetic_case_dict(drum={"rpm": 12.0}))
    pred = predict_plant(50.0, other, reference=reference)
    assert any("differs from the case given" in w for w in pred.warnings)
    assert dataclasses.is_dataclass(pred)
