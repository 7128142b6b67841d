"""Pure helpers of the two-particle contact checks: Hertz contact radius, Eq. 24, LIGGGHTS'
conduction area and the conductivity factor that maps one onto the other."""

from __future__ import annotations

import math

import pytest

from drumflow.dem.conduction import GEOMETRIC_AREA_FACTOR, liggghts_conductivity
from drumflow.dem.timestep import (
    MIN_STEPS_PER_CONTACT,
    hertz_contact_time,
    rayleigh_time,
)
from drumflow.verify.contacts import (
    decay_conductance,
    default_time_step,
    eq24_heat_flow,
    geometric_overlap_area,
    harmonic_conductivity,
    hertz_contact_radius,
    liggghts_heat_flow,
    reference_overlap,
)

R = 0.004
K = 0.18596


def test_hertz_contact_radius_equal_spheres() -> None:
    # R* = R/2 for equal spheres.
    assert hertz_contact_radius(R, R, 4e-6) == pytest.approx(math.sqrt(0.002 * 4e-6))
    # Sphere on a much larger sphere: R* -> R.
    assert hertz_contact_radius(R, 1e6, 4e-6) == pytest.approx(math.sqrt(R * 4e-6), rel=1e-6)


def test_eq24_series_conductivity_and_sign() -> None:
    assert harmonic_conductivity(K, K) == pytest.approx(K / 2)
    assert harmonic_conductivity(1.0, 3.0) == pytest.approx(0.75)  # 1/k = 1/1 + 1/3
    q = eq24_heat_flow(1e-4, K, K, 80.0, 100.0)
    assert q == pytest.approx(4 * 1e-4 * K / 2 * 20.0)
    assert eq24_heat_flow(1e-4, K, K, 100.0, 80.0) == pytest.approx(-q)  # heat flows downhill


def test_geometric_area_is_intersection_circle() -> None:
    delta = 1e-5
    a2 = R * delta - delta**2 / 4  # equal spheres: a^2 = R^2 - (R - delta/2)^2
    assert geometric_overlap_area(R, R, 2 * R - delta) == pytest.approx(math.pi * a2, rel=1e-9)


@pytest.mark.parametrize("fraction", [1e-4, 1e-3, 1e-2])
def test_liggghts_over_eq24_is_sqrt_2pi(fraction: float) -> None:
    """The ratio is the geometric constant sqrt(2 pi), up to sqrt(1 - delta / 4R)."""
    delta = fraction * R
    ratio = liggghts_heat_flow(R, delta, K, K, 80.0, 100.0) / eq24_heat_flow(
        hertz_contact_radius(R, R, delta), K, K, 80.0, 100.0)
    assert ratio == pytest.approx(GEOMETRIC_AREA_FACTOR * math.sqrt(1 - fraction / 4), rel=1e-9)
    assert ratio == pytest.approx(2.5066, rel=3e-3)


@pytest.mark.parametrize("E", [1e5, 517e3, 5e6])
def test_scaled_conductivity_with_area_correction_matches_eq24(E: float) -> None:
    """k / sqrt(2 pi) and the overlap scaled to the reference modulus give Eq. 24 within 0.1%."""
    delta, E_ref = 1e-3 * R, 517e3
    q = liggghts_heat_flow(R, delta, liggghts_conductivity(K), liggghts_conductivity(K), 80.0, 100.0,
                           youngs_modulus=E, reference_modulus=E_ref)
    r_c = hertz_contact_radius(R, R, reference_overlap(delta, E, E_ref))
    assert q == pytest.approx(eq24_heat_flow(r_c, K, K, 80.0, 100.0), rel=1e-3)


def test_reference_overlap_hertz_scaling() -> None:
    # Same force, 8x stiffer: overlap 4x smaller (delta ~ E^-2/3).
    assert reference_overlap(4e-6, 1e5, 8e5) == pytest.approx(1e-6)
    assert reference_overlap(4e-6, 1e5, None) == 4e-6


def test_decay_conductance_inverts_explicit_update() -> None:
    h, dt, mcp = 3e-4, 1e-4, 0.4
    dT = 20.0
    for _ in range(500):
        dT -= h * dt * (2 / mcp) * dT
    assert decay_conductance(20.0, dT, 500, dt, mcp, mcp) == pytest.approx(h, rel=1e-9)


def test_default_time_step_is_drumflows_rule() -> None:
    t_r = rayleigh_time(R, 1050.0, 5e6, 0.45)
    t_h = hertz_contact_time(R, 1050.0, 5e6, 0.45, 2.0)
    assert default_time_step(R, 1050.0, 5e6, 0.45, 2.0) == pytest.approx(
        min(0.2 * t_r, t_h / MIN_STEPS_PER_CONTACT))
