"""The physics floor holds each law once: the air table's two views agree row by row, the
lumped solution is one formula, the drum's frame one rotation."""

from __future__ import annotations

import math

import numpy as np
import pytest

from drumflow.physics import air
from drumflow.physics.drum_frame import (
    drum_angle,
    rotate_about_axis,
    rotate_to_drum_frame,
    rotate_to_lab_frame,
)
from drumflow.physics.particle_air import lumped_cooling, lumped_temperature
from drumflow.physics.particle_interior import Sphere, lumped_mean_temperature


@pytest.mark.parametrize("t_k", [250.0, 300.0, 350.0, 400.0, 450.0, 500.0, 550.0, 600.0, 275.0, 333.3])
def test_the_kelvin_and_celsius_views_read_one_table(t_k: float) -> None:
    t_c = t_k - air.KELVIN_OFFSET
    assert float(air.air_heat_capacity(t_k)) == pytest.approx(air.specific_heat(t_c), rel=1e-12)
    assert float(air.air_viscosity(t_k)) == pytest.approx(air.dynamic_viscosity(t_c), rel=1e-12)
    assert float(air.air_conductivity(t_k)) == pytest.approx(air.thermal_conductivity(t_c), rel=1e-12)
    assert float(air.air_prandtl(t_k)) == pytest.approx(air.prandtl(t_c), rel=1e-12)


def test_the_views_keep_their_ranges() -> None:
    # deg C: 200-600 K, refused outside; kelvin: 250-2000 K, clipped (the grate's first iterates).
    assert (air.T_MIN_C, air.T_MAX_C) == pytest.approx((200.0 - 273.15, 600.0 - 273.15))
    assert (air.AIR_T_MIN, air.AIR_T_MAX) == (250.0, 2000.0)
    assert float(air.air_enthalpy(250.0)) == 0.0
    assert float(air.air_heat_capacity(100.0)) == float(air.air_heat_capacity(250.0))


def test_one_lumped_solution() -> None:
    t = np.array([0.0, 1.0, 10.0])
    h, mass, cp, area = 50.0, 1e-3, 1000.0, 1e-4
    expected = 30.0 + 60.0 * np.exp(-t * h * area / (mass * cp))
    np.testing.assert_allclose(lumped_temperature(t, 90.0, 30.0, h, mass, cp, area), expected, rtol=1e-14)
    np.testing.assert_allclose(lumped_cooling(90.0, 30.0, t * h * area / (mass * cp)), expected, rtol=1e-14)
    sphere = Sphere(diameter=2.7e-3, density=1050.0, heat_capacity=1465.38, conductivity=0.18596)
    rate = h * sphere.surface / (sphere.mass * sphere.heat_capacity)
    np.testing.assert_allclose(lumped_mean_temperature(sphere, h, 90.0, 30.0, t),
                               30.0 + 60.0 * np.exp(-rate * t), rtol=1e-14)


def test_the_drum_frame_turns_with_the_drum() -> None:
    omega = 2.0 * math.pi * 5.0 / 60.0
    assert drum_angle(omega, 3.0) == omega * 3.0
    quarter = 0.5 * math.pi
    np.testing.assert_allclose(rotate_about_axis(np.array([[1.0, 0.0, 0.2]]), quarter), [[0.0, 1.0, 0.2]],
                               atol=1e-15)
    np.testing.assert_allclose(rotate_to_drum_frame(np.array([1.0, 0.0, 0.2]), quarter), [0.0, -1.0, 0.2],
                               atol=1e-15)
    pts = np.random.default_rng(1).normal(size=(5, 3))
    np.testing.assert_allclose(rotate_to_lab_frame(rotate_to_drum_frame(pts, 0.7), 0.7), pts, atol=1e-14)
