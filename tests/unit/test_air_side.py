"""The air side of a snapshot (h per particle, bed vs curtain) and the lumped predictor."""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import pytest

from drumflow.air.field import AirField
from drumflow.analysis.air_side import (
    airborne_mask,
    lumped_h,
    lumped_mean_temperature,
    sample_air_side,
)
from drumflow.case import case_from_dict


@pytest.fixture()
def case(smoke_dict: dict[str, Any]):  # type: ignore[no-untyped-def]
    smoke_dict["air"]["model"] = "uniform"
    return case_from_dict(smoke_dict)


def _columns(case, velocities: np.ndarray, temperatures: np.ndarray) -> dict[str, np.ndarray]:  # type: ignore[no-untyped-def]
    n = len(velocities)
    r = case.particles.radius
    return {
        "x": np.zeros(n), "y": np.full(n, -0.5 * case.drum.radius), "z": np.full(n, 0.5 * case.drum.length),
        "vx": velocities[:, 0], "vy": velocities[:, 1], "vz": velocities[:, 2],
        "radius": np.full(n, r), "T": temperatures,
    }


def test_particles_at_rest_in_plug_flow_see_the_textbook_h(case) -> None:  # type: ignore[no-untyped-def]
    # Independent hand value: 8 mm sphere in air at 30 C, 1 atm, at u = mdot/(rho A_free).
    # Air at 303 K (Incropera Table A.4, interpolated): nu = 16.19e-6 m2/s, k = 0.02652 W/mK,
    # Pr = 0.7066; Re = u D / nu, Nu = 2 + 0.6 Re^0.5 Pr^(1/3) (Ranz and Marshall 1952).
    field = AirField.uniform(case)
    u = field.meta["mean_axial_velocity_m_s"]
    re = u * 0.008 / 16.19e-6
    h_hand = (2.0 + 0.6 * math.sqrt(re) * 0.7066 ** (1.0 / 3.0)) * 0.02652 / 0.008
    cols = _columns(case, np.zeros((4, 3)), np.full(4, 90.0))
    got = sample_air_side(case, field, cols, time_s=0.3)
    assert got.h_mean_w_m2k == pytest.approx(h_hand, rel=0.01)
    assert got.airborne == 0 and math.isnan(got.h_airborne_w_m2k)
    assert got.heat_rate_w == pytest.approx(4 * h_hand * math.pi * 0.008**2 * 60.0, rel=0.01)


def test_falling_particles_are_airborne_and_carry_their_share(case) -> None:  # type: ignore[no-untyped-def]
    field = AirField.uniform(case)
    shell = case.drum.omega * case.drum.radius
    v = np.array([[0.0, -(shell + 0.6), 0.0], [0.0, -(shell + 0.4), 0.0], [0.0, 0.0, 0.0], [0.0, -3.0, 0.0]])
    assert airborne_mask(case, v).tolist() == [True, False, False, True]
    got = sample_air_side(case, field, _columns(case, v, np.full(4, 90.0)), time_s=0.0)
    assert got.airborne == 2
    # Faster slip, larger h: the airborne pair removes more than half the heat.
    assert got.h_airborne_w_m2k > got.h_bed_w_m2k
    assert 0.5 < got.airborne_heat_share < 1.0


def test_lumped_prediction_constant_and_time_varying(case) -> None:  # type: ignore[no-untyped-def]
    p = case.particles
    rate = 6.0 / (p.density * p.heat_capacity * p.diameter)
    times = np.array([0.5, 1.0, 3.5])
    got = lumped_mean_temperature(case, 60.0, times)
    exact = 30.0 + 60.0 * np.exp(-rate * 60.0 * times)
    assert got == pytest.approx(exact, rel=1e-12)
    # h(t) = 40 + 10 t: integral 40 t + 5 t^2, exact for the trapezoidal rule only in the limit.
    fine = np.linspace(0.01, 3.5, 2000)
    varying = lumped_mean_temperature(case, lambda t: 40.0 + 10.0 * t, fine)
    exact_v = 30.0 + 60.0 * np.exp(-rate * (40.0 * fine + 5.0 * fine**2))
    assert varying == pytest.approx(exact_v, rel=1e-6)


def test_lumped_h_inverts_the_lumped_solution(case) -> None:  # type: ignore[no-untyped-def]
    """h back from the temperature the lumped solution gives with it; outside the air's and the
    start's temperatures there is no h."""
    for h in (5.0, 47.4, 300.0):
        temperature = float(lumped_mean_temperature(case, h, np.array([3.5]))[0])
        assert lumped_h(case, temperature, 3.5) == pytest.approx(h, rel=1e-12)
    t_air, t0 = case.air.inlet_temperature_C, case.particles.initial_temperature_C
    assert math.isnan(lumped_h(case, t_air - 1.0, 3.5))
    assert math.isnan(lumped_h(case, t_air, 3.5))  # regression: divided by zero
    assert math.isnan(lumped_h(case, 0.5 * (t_air + t0), 0.0))
    assert math.isnan(lumped_h(case, t0 + 1.0, 3.5))
    assert lumped_h(case, t0, 3.5) == 0.0


def test_the_papers_h_over_its_meshes() -> None:
    """Tables 3-4's T(3.5 s) per mesh through the lumped solution of the paper cases, against
    values computed by hand: h = rho cp D / (6 t) ln(60 / (T - 30)) with rho cp = 1050 x 1465.38
    J/(m3 K), D = 8 and 20 mm (model one mesh 1: 2051.53 / 3.5 x ln(60 / 52.42) = 79.16)."""
    from pathlib import Path

    from drumflow.analysis.published import mesh_h
    from drumflow.case import load_case

    cases = Path(__file__).resolve().parents[2] / "cases"
    one = mesh_h("one", load_case(cases / "paper_model_one.toml"))
    two = mesh_h("two", load_case(cases / "paper_model_two.toml"))
    assert [round(one[m], 1) for m in ("mesh 1", "mesh 2", "mesh 3")] == [79.2, 62.0, 54.6]
    assert [round(two[m], 1) for m in ("mesh 1", "mesh 2", "mesh 3")] == [79.0, 39.4, 23.6]
