"""Dimensionless numbers (Eqs. 49-55): void factor, velocities, Nu/Re/Pr per step."""

from __future__ import annotations

import math

import numpy as np
import pytest

from drumflow.analysis.dimensionless import (
    dimensionless_numbers,
    drum_volume,
    mean_air_inlet_velocity,
    particle_volume,
    void_fraction,
)
from drumflow.errors import AnalysisInputError

T_300K = 300.0 - 273.15  # a node of the air table: properties known exactly
T_325K = 325.0 - 273.15
# Table 1 of the paper.
MODEL_ONE = dict(
    drum_diameter_m=3.0, section_length_m=0.1, particle_count=467443, particle_diameter_m=0.008
)
MODEL_TWO = dict(
    drum_diameter_m=3.0, section_length_m=1.0, particle_count=299164, particle_diameter_m=0.020
)
PLANT_AIR = dict(air_mass_flow_kg_s=25.0, drum_diameter_m=3.0, air_inlet_temperature_c=30.0)


@pytest.mark.parametrize("model", [MODEL_ONE, MODEL_TWO], ids=["model-one", "model-two"])
def test_void_fraction_of_the_paper_models(model: dict[str, float]) -> None:
    # Independent closed form: Vf = 1 - (2/3) N Dp^3 / (D^2 l).
    n, dp, d, length = (model["particle_count"], model["particle_diameter_m"],
                        model["drum_diameter_m"], model["section_length_m"])
    expected = 1.0 - 2.0 / 3.0 * n * dp**3 / (d**2 * length)
    vf = void_fraction(**model)  # type: ignore[arg-type]
    assert vf == pytest.approx(expected, rel=1e-12)  # same arithmetic, different order
    # Both paper models have the same solid fraction (17.7 %), Vf = 0.8227 to 4 decimals.
    assert round(vf, 4) == 0.8227


def test_volumes() -> None:
    # pi * 1.5^2 * 0.1 = 0.706858 m3 and 467443 * pi/6 * 0.008^3 = 0.125313 m3 (hand values).
    assert drum_volume(3.0, 0.1) == pytest.approx(0.706858, rel=1e-6)
    assert particle_volume(467443, 0.008) == pytest.approx(0.125313, rel=1e-5)


def test_mean_air_inlet_velocity_uses_air_density_at_inlet() -> None:
    # rho(30 C) = 1.1614 + 3.15/50 (0.9950 - 1.1614) = 1.150917 kg/m3 (Incropera, interpolated).
    rho = 1.1614 + 3.15 / 50.0 * (0.9950 - 1.1614)
    expected = 25.0 / (rho * math.pi * 3.0**2 / 4.0)
    v = mean_air_inlet_velocity(**PLANT_AIR)
    assert v == pytest.approx(expected, rel=1e-12)  # same closed form
    assert v == pytest.approx(3.073, rel=1e-3)  # hand value to 4 figures


def test_numbers_at_a_table_node() -> None:
    # Air inlet and outlet both at 300 K: T_ma is a table node, so nu = 15.89e-6 m2/s,
    # k = 0.0263 W/(m K) and Pr = 0.707 exactly.
    h = np.array([60.0, 30.0, np.nan])
    steps = dimensionless_numbers(
        h,
        np.full(3, T_300K),
        air_inlet_temperature_c=T_300K,
        air_inlet_velocity_m_s=3.0,
        **MODEL_ONE,
    )
    vf = void_fraction(**MODEL_ONE)  # type: ignore[arg-type]
    # Closed forms on exact table values: 1e-12.
    np.testing.assert_allclose(steps.nusselt[:2], h[:2] * 0.008 / 0.0263, rtol=1e-12)
    np.testing.assert_allclose(steps.reynolds, 3.0 / vf * 0.008 / 15.89e-6, rtol=1e-12)
    np.testing.assert_allclose(steps.prandtl, 0.707, rtol=1e-12)
    assert steps.max_air_velocity_m_s == pytest.approx(3.0 / vf, rel=1e-12)
    # A masked step (NaN h) stays masked.
    assert steps.valid.tolist() == [True, True, False] and np.isnan(steps.nusselt[2])


def test_mean_air_temperature_is_eq50() -> None:
    # T_ai at 300 K and Ta at 350 K: T_ma at 325 K, midway between two table rows.
    steps = dimensionless_numbers(
        [50.0],
        [350.0 - 273.15],
        air_inlet_temperature_c=T_300K,
        air_inlet_velocity_m_s=3.0,
        **MODEL_ONE,
    )
    assert steps.mean_air_temperature_c[0] == pytest.approx(T_325K, rel=1e-12)
    # Midpoint interpolation is exact arithmetic on table values: 1e-12.
    assert steps.prandtl[0] == pytest.approx((0.707 + 0.700) / 2, rel=1e-12)
    assert steps.kinematic_viscosity_m2_s[0] == pytest.approx((15.89 + 20.92) / 2 * 1e-6, rel=1e-12)
    assert steps.conductivity_w_mk[0] == pytest.approx((26.3 + 30.0) / 2 * 1e-3, rel=1e-12)


def test_air_mass_flow_gives_the_inlet_velocity() -> None:
    by_flow = dimensionless_numbers(
        [60.0], [30.05], air_inlet_temperature_c=30.0, air_mass_flow_kg_s=25.0, **MODEL_ONE
    )
    v = mean_air_inlet_velocity(**PLANT_AIR)
    assert by_flow.air_inlet_velocity_m_s == pytest.approx(v, rel=1e-12)  # same formula
    # With the full drum section as inlet, model one has Re ~ 1844 (the paper reports Re from
    # 3073; it does not give the inlet area it used). 1e-3: hand value to 4 figures.
    assert by_flow.reynolds[0] == pytest.approx(1844.0, rel=1e-3)


@pytest.mark.parametrize(
    ("h", "model", "re_paper"),
    [(60.15, MODEL_ONE, 3073.0), (38.92, MODEL_TWO, 7686.0)],
    ids=["model-one", "model-two"],
)
def test_paper_nusselt_needs_the_particle_conductivity(
    h: float, model: dict[str, float], re_paper: float
) -> None:
    # The paper's correlation (Eq. 58) at the ends of its Re range and Pr = 0.7282 (Figure 9)
    # equals h Dp / k only with the NPK conductivity k_m = 0.18596 W/(m K) of Table 1.
    eq58 = 0.0531283 * re_paper**0.523707 * 0.7282**1.00824
    with_km = dimensionless_numbers(
        [h], [30.05], air_inlet_temperature_c=30.0, air_inlet_velocity_m_s=3.0,
        conductivity_w_mk=0.18596, **model,  # type: ignore[arg-type]
    )
    # 0.2 %: h is printed to 4 figures (0.013 %) and each run's own Pr is not given; the model-two
    # residual (0.09 %) corresponds to a Pr difference of only 0.0006 between the runs.
    assert with_km.nusselt[0] == pytest.approx(eq58, rel=0.002)
    with_air = dimensionless_numbers(
        [h], [30.05], air_inlet_temperature_c=30.0, air_inlet_velocity_m_s=3.0,
        **model,  # type: ignore[arg-type]
    )
    # With the air conductivity (default) Nu is about 7 times larger (k_m / k_air = 7.0).
    assert with_air.nusselt[0] / with_km.nusselt[0] == pytest.approx(0.18596 / 0.02654, rel=0.01)


# ------------------------------------------------------------------------------- errors


def test_too_many_particles() -> None:
    with pytest.raises(AnalysisInputError, match="particle_count = 10000000"):
        void_fraction(**{**MODEL_ONE, "particle_count": 10_000_000})  # type: ignore[arg-type]


def test_velocity_or_flow_exactly_one() -> None:
    with pytest.raises(AnalysisInputError, match="exactly one"):
        dimensionless_numbers([60.0], [30.05], air_inlet_temperature_c=30.0, **MODEL_ONE)
    with pytest.raises(AnalysisInputError, match="both given"):
        dimensionless_numbers(
            [60.0], [30.05], air_inlet_temperature_c=30.0, air_mass_flow_kg_s=25.0,
            air_inlet_velocity_m_s=3.0, **MODEL_ONE,
        )


def test_mean_air_temperature_outside_table_names_t_ma() -> None:
    with pytest.raises(AnalysisInputError, match=r"T_ma \(Eq\. 50\) = 400"):
        dimensionless_numbers(
            [60.0], [770.0], air_inlet_temperature_c=30.0, air_inlet_velocity_m_s=3.0, **MODEL_ONE
        )


@pytest.mark.parametrize(
    ("kwargs", "needle"),
    [
        ({"particle_diameter_m": 0.0}, "particle_diameter_m = 0"),
        ({"particle_count": 1.5}, "particle_count = 1.5"),
        ({"conductivity_w_mk": -0.1}, "conductivity_w_mk = -0.1"),
        ({"drum_diameter_m": float("nan")}, "drum_diameter_m = nan"),
    ],
)
def test_bad_arguments_name_the_field(kwargs: dict[str, float], needle: str) -> None:
    args = {**MODEL_ONE, "air_inlet_velocity_m_s": 3.0, **kwargs}
    with pytest.raises(AnalysisInputError) as info:
        dimensionless_numbers([60.0], [30.05], air_inlet_temperature_c=30.0, **args)  # type: ignore
    assert needle in str(info.value)


def test_length_mismatch() -> None:
    with pytest.raises(AnalysisInputError, match="air_temperature_c = 1 value"):
        dimensionless_numbers(
            [60.0, 61.0],
            [30.05],
            air_inlet_temperature_c=30.0,
            air_inlet_velocity_m_s=3.0,
            **MODEL_ONE,
        )
