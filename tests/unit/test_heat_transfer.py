"""Per-step heat-transfer model (Eqs. 34-41): Table 6, an analytic case, masking, errors."""

from __future__ import annotations

import math

import numpy as np
import pytest

from drumflow.analysis.heat_transfer import (
    falling_particle_area,
    particle_mass,
    per_step_heat_transfer,
)
from drumflow.errors import AnalysisInputError
from drumflow.physics.exchanger import log_mean_temperature_difference

NDArrayLike = float | np.ndarray

RHO = 1050.0  # NPK density, Table 1
CP_M = 1465.38  # NPK specific heat, Table 1
CP_A = 1005.0  # air specific heat (the value the paper's Table 7 implies, see test_exchanger)
MDOT_A = 25.0  # air mass flow, Table 1
T_AI = 30.0  # air inlet temperature, Table 1

COMMON = dict(
    particle_density_kg_m3=RHO,
    material_cp_j_kgk=CP_M,
    air_mass_flow_kg_s=MDOT_A,
    air_cp_j_kgk=CP_A,
    air_inlet_temperature_c=T_AI,
)


# --------------------------------------------------------------------------- Table 6


@pytest.mark.parametrize(
    ("m_mf", "dp", "paper_area"),
    [(0.04, 0.008, 0.029), (0.82, 0.020, 0.233)],
    ids=["model-one", "model-two"],
)
def test_table6_falling_area(m_mf: float, dp: float, paper_area: float) -> None:
    area = falling_particle_area(m_mf, dp, RHO)
    # Independent closed form: number of particles m_mf / (rho pi Dp^3 / 6) times pi Dp^2.
    assert area == pytest.approx(6.0 * m_mf / (RHO * dp), rel=1e-12)
    # Table 6 prints m_mf to 0.01 kg and A_fp to 0.001 m2, so the two can disagree by the sum of
    # both rounding half-widths (model two: 0.82 kg gives 0.2343 m2, printed 0.233).
    rounding = falling_particle_area(0.005, dp, RHO) + 0.0005
    assert abs(area - paper_area) <= rounding


def test_table6_model_one_area_rounds_to_printed_value() -> None:
    # Model one is tighter: 0.04 kg of 8 mm spheres is 0.02857 m2, which prints as 0.029.
    assert round(falling_particle_area(0.04, 0.008, RHO), 3) == 0.029


@pytest.mark.parametrize(("dt", "paper_air_mass"), [(0.005, 0.125), (0.01, 0.25)])
def test_table6_air_mass_per_step(dt: float, paper_air_mass: float) -> None:
    times = np.arange(4) * dt
    steps = per_step_heat_transfer(
        times,
        [90.0, 89.99, 89.98, 89.97],
        particle_diameter_m=0.008,
        falling_mass_kg=0.04,
        **COMMON,
    )
    # m_a = 25 kg/s * dt is exact up to the float rounding of arange * dt: 1e-12.
    np.testing.assert_allclose(steps.air_mass_kg, paper_air_mass, rtol=1e-12)


def test_particle_mass() -> None:
    # 8 mm NPK sphere: 1050 * pi/6 * 0.008^3 = 2.8149e-4 kg (hand value, 5 figures).
    assert particle_mass(0.008, RHO) == pytest.approx(2.8149e-4, rel=1e-4)


# ------------------------------------------------------------- analytic (epsilon-NTU) case


def _series_from_h(
    h: NDArrayLike,
    times: np.ndarray,
    t0: float,
    m_mf: NDArrayLike,
    dp: float,
) -> np.ndarray:
    """Mean particle temperatures produced by a known h, step by step.

    Each step is a counter-current exchanger between the falling particles (capacity
    m_mf cp_m / dt) and the air of the step (m_a cp_a / dt) with UA = h A_fp. The heat of the
    step is given by the closed-form effectiveness-NTU relation, which does not use the LMTD,
    so recovering h through Eqs. 34-39 is an independent check.
    """
    h_arr = np.broadcast_to(np.asarray(h, dtype=float), (times.size - 1,))
    m_arr = np.broadcast_to(np.asarray(m_mf, dtype=float), (times.size - 1,))
    temps = [t0]
    for k, dt in enumerate(np.diff(times)):
        area = 6.0 * m_arr[k] / (RHO * dp)
        c_m = m_arr[k] * CP_M / dt
        c_a = MDOT_A * dt * CP_A / dt
        c_min, c_max = min(c_m, c_a), max(c_m, c_a)
        ntu = h_arr[k] * area / c_min
        cr = c_min / c_max
        if math.isclose(cr, 1.0, rel_tol=1e-12):
            eps = ntu / (1.0 + ntu)
        else:
            e = math.exp(-ntu * (1.0 - cr))
            eps = (1.0 - e) / (1.0 - cr * e)
        q = eps * c_min * (temps[-1] - T_AI) * dt  # J given to the air
        temps.append(temps[-1] - q / (m_arr[k] * CP_M))
    return np.array(temps)


@pytest.mark.parametrize(
    ("h", "m_mf", "dp", "dt", "n"),
    [
        (60.15, 0.04, 0.008, 0.005, 1000),  # model one of the paper (NTU ~ 1.5e-4)
        (38.92, 0.82, 0.020, 0.010, 1000),  # model two: air capacity below particle capacity
        # Large NTU (~0.05) exercises the nonlinearity; fewer steps, or the particles reach the
        # air temperature and the steps stop carrying information.
        (2.0e4, 0.04, 0.008, 0.005, 100),
    ],
    ids=["model-one", "model-two", "large-ntu"],
)
def test_known_h_is_recovered(h: float, m_mf: float, dp: float, dt: float, n: int) -> None:
    times = np.arange(n + 1) * dt
    temps = _series_from_h(h, times, 90.0, m_mf, dp)
    steps = per_step_heat_transfer(
        times, temps, particle_diameter_m=dp, falling_mass_kg=m_mf, **COMMON
    )
    assert steps.n_valid == steps.n_steps == n
    # The series is built in double precision from temperature drops of ~1e-2 K on ~90 K, so
    # about 12-13 digits of each drop survive; 1e-8 leaves ample margin.
    np.testing.assert_allclose(steps.h_w_m2k, h, rtol=1e-8)
    assert steps.h_mean_w_m2k == pytest.approx(h, rel=1e-8)
    assert np.all(steps.heat_j > 0) and np.all(steps.air_dT_c > 0)


def test_equal_capacities_use_the_lmtd_limit() -> None:
    # m_mf cp_m == m_a cp_a: both end differences are equal and Eq. 38 is 0/0; the limit applies.
    dt = 0.005
    m_mf = MDOT_A * dt * CP_A / CP_M
    times = np.arange(201) * dt
    temps = _series_from_h(500.0, times, 90.0, m_mf, 0.008)
    steps = per_step_heat_transfer(
        times, temps, particle_diameter_m=0.008, falling_mass_kg=m_mf, **COMMON
    )
    assert steps.n_valid == 200
    # Same double-precision argument as above: 1e-8.
    np.testing.assert_allclose(steps.h_w_m2k, 500.0, rtol=1e-8)


def test_falling_mass_flow_equals_mass_per_step() -> None:
    dt = 0.005
    times = np.arange(51) * dt
    temps = _series_from_h(60.15, times, 90.0, 0.04, 0.008)
    by_mass = per_step_heat_transfer(
        times, temps, particle_diameter_m=0.008, falling_mass_kg=0.04, **COMMON
    )
    by_flow = per_step_heat_transfer(
        times, temps, particle_diameter_m=0.008, falling_mass_flow_kg_s=8.0, **COMMON
    )
    # 8 kg/s * 0.005 s = 0.04 kg up to float rounding of dt: 1e-10.
    np.testing.assert_allclose(by_flow.h_w_m2k, by_mass.h_w_m2k, rtol=1e-10)
    np.testing.assert_allclose(by_flow.area_m2, by_mass.area_m2, rtol=1e-10)


def test_mean_is_time_weighted_for_uneven_steps() -> None:
    times = np.array([0.0, 0.01, 0.04])  # steps of 0.01 s and 0.03 s
    # A falling mass flow of 8 kg/s gives 0.08 kg and 0.24 kg in the two steps.
    temps = _series_from_h(np.array([40.0, 80.0]), times, 90.0, 8.0 * np.diff(times), 0.008)
    steps = per_step_heat_transfer(
        times, temps, particle_diameter_m=0.008, falling_mass_flow_kg_s=8.0, **COMMON
    )
    np.testing.assert_allclose(steps.h_w_m2k, [40.0, 80.0], rtol=1e-8)
    # Time average (40 * 0.01 + 80 * 0.03) / 0.04 = 70, not the plain mean 60; 1e-8 as above.
    assert steps.h_mean_w_m2k == pytest.approx(70.0, rel=1e-8)


# ------------------------------------------------------------------------------- masking


def test_zero_change_and_cross_steps_are_masked() -> None:
    dt = 0.005
    times = np.arange(5) * dt
    # step 0: cooling (valid); step 1: no change (masked); step 2: particles end below the air
    # inlet temperature, log argument negative (masked); step 3: back above (valid, heating).
    temps = [90.0, 89.99, 89.99, 29.0, 35.0]
    steps = per_step_heat_transfer(
        times, temps, particle_diameter_m=0.008, falling_mass_kg=0.04, **COMMON
    )
    assert steps.valid.tolist() == [True, False, False, True]
    assert steps.masked_no_change == 1 and steps.masked_cross == 1
    assert steps.n_valid == 2 and steps.n_steps == 4
    assert np.isnan(steps.h_w_m2k[1]) and np.isnan(steps.h_w_m2k[2]) and np.isnan(steps.lmtd_c[2])
    assert steps.h_w_m2k[0] > 0  # cooling gives a positive h
    assert steps.h_w_m2k[3] < 0  # a heating step is kept, with a negative h
    # The mean covers the valid steps only (equal dt): exact arithmetic, 1e-12.
    assert steps.h_mean_w_m2k == pytest.approx(np.mean(steps.h_w_m2k[[0, 3]]), rel=1e-12)


def test_air_leaving_hotter_than_particles_is_masked() -> None:
    # A tiny air flow makes the air of the step leave above the particle temperature at the
    # start of the step: end difference A is negative, the counter-current model does not apply.
    times = [0.0, 0.005]
    temps = [90.0, 80.0]
    steps = per_step_heat_transfer(
        times, temps, particle_diameter_m=0.008, falling_mass_kg=0.04,
        **{**COMMON, "air_mass_flow_kg_s": 0.01},
    )
    assert steps.air_temperature_c[0] > 90.0
    assert steps.n_valid == 0 and math.isnan(steps.h_mean_w_m2k)


def test_results_are_read_only() -> None:
    steps = per_step_heat_transfer(
        [0.0, 0.005], [90.0, 89.99], particle_diameter_m=0.008, falling_mass_kg=0.04, **COMMON
    )
    with pytest.raises(ValueError):
        steps.h_w_m2k[0] = 1.0


# ---------------------------------------------------------------------------------- LMTD


def test_lmtd_known_values_and_limits() -> None:
    # (30 - 10) / ln 3 = 18.2048 (hand value): rel 1e-12 for a closed form.
    expected = 20.0 / math.log(3.0)
    assert log_mean_temperature_difference(30.0, 10.0) == pytest.approx(expected, rel=1e-12)
    assert log_mean_temperature_difference(10.0, 30.0) == pytest.approx(expected, rel=1e-12)
    assert log_mean_temperature_difference(7.5, 7.5) == 7.5
    # Nearly equal ends: the LMTD tends to the arithmetic mean; 1e-12 shows no cancellation.
    near = log_mean_temperature_difference(10.0 + 1e-9, 10.0)
    assert near == pytest.approx(10.0 + 5e-10, rel=1e-12)
    out = log_mean_temperature_difference(np.array([5.0, -1.0, 0.0]), np.array([5.0, 2.0, 3.0]))
    assert out[0] == 5.0 and np.isnan(out[1]) and np.isnan(out[2])


# ------------------------------------------------------------------------------- errors


@pytest.mark.parametrize(
    ("kwargs", "needle"),
    [
        ({"particle_diameter_m": -0.008}, "particle_diameter_m = -0.008"),
        ({"material_cp_j_kgk": 0.0}, "material_cp_j_kgk = 0"),
        ({"air_mass_flow_kg_s": float("inf")}, "air_mass_flow_kg_s = inf"),
        ({"falling_mass_kg": -0.04}, "falling_mass_kg[0] = -0.04"),
        ({"falling_mass_kg": None}, "falling_mass_kg or falling_mass_flow_kg_s"),
        ({"falling_mass_flow_kg_s": 8.0}, "exactly one"),
        ({"falling_mass_kg": [0.04, 0.04]}, "one per step"),
    ],
)
def test_bad_arguments_name_the_field(kwargs: dict[str, object], needle: str) -> None:
    args: dict[str, object] = {"particle_diameter_m": 0.008, "falling_mass_kg": 0.04, **COMMON}
    args.update(kwargs)
    with pytest.raises(AnalysisInputError) as info:
        per_step_heat_transfer(
            [0.0, 0.005, 0.01, 0.015], [90.0, 89.9, 89.8, 89.7], **args  # type: ignore[arg-type]
        )
    assert needle in str(info.value)
    assert isinstance(info.value, ValueError)


def test_bad_series_name_the_index() -> None:
    kw = {"particle_diameter_m": 0.008, "falling_mass_kg": 0.04, **COMMON}
    with pytest.raises(AnalysisInputError, match=r"times_s\[2\] = 0\.005"):
        per_step_heat_transfer([0.0, 0.005, 0.005], [90.0, 89.9, 89.8], **kw)  # type: ignore
    with pytest.raises(AnalysisInputError, match=r"mean_particle_temperature_c\[1\] = nan"):
        per_step_heat_transfer([0.0, 0.005, 0.01], [90.0, math.nan, 89.8], **kw)  # type: ignore
    with pytest.raises(AnalysisInputError, match=r"mean_particle_temperature_c = 2 value"):
        per_step_heat_transfer([0.0, 0.005, 0.01], [90.0, 89.9], **kw)  # type: ignore[arg-type]
    with pytest.raises(AnalysisInputError, match=r"times_s = 1 value"):
        per_step_heat_transfer([0.0], [90.0], **kw)  # type: ignore[arg-type]
