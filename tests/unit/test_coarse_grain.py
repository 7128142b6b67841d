"""Coarse-graining (particles.coarse_grain): the parcel view of a case and the air's load on a
parcel, checked against the per-kilogram identity it must keep (no solver; a real run of the
tiny drum with parcels is in tests/solver/test_coarse_grain_run.py)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from drumflow.coupling.driver import air_load
from drumflow.coupling.spec import CouplingSpec
from drumflow.errors import CaseError
from drumflow.physics.particle_air import AirState, convective_heat, drag_force
from drumflow.verify.scenes import tiny_drum


def test_without_coarse_graining_the_dem_moves_the_case_itself() -> None:
    case = tiny_drum()
    assert case.dem_case() is case


def test_parcels_keep_the_total_mass_and_are_an_ordinary_case() -> None:
    case = tiny_drum(particles__coarse_grain=1.45)
    parcels = case.dem_case()
    assert parcels.particles.diameter == pytest.approx(1.45 * 0.008)
    assert parcels.particles.coarse_grain == 1.0  # a case of larger particles, not scaled twice
    assert parcels.particle_count == round(500 / 1.45**3) == 164
    # Same mass up to the rounding of the count (half a parcel at most).
    assert abs(parcels.particle_mass_total - case.particle_mass_total) <= 0.5 * parcels.particles.mass
    assert parcels.hash() != case.hash()


def test_parcels_too_large_for_the_section_are_refused_naming_the_field() -> None:
    with pytest.raises(CaseError) as err:
        from drumflow.case import case_from_dict
        from drumflow.verify.scenes import tiny_drum_dict

        case_from_dict(tiny_drum_dict(particles__coarse_grain=2.0))  # 16 mm in a 48 mm section
    text = str(err.value)
    assert "particles.coarse_grain = 2.0" in text and "up to 1.5" in text


@pytest.mark.parametrize("k", [1.0, 1.45, 2.0, 3.0])
def test_a_parcel_feels_the_air_per_kilogram_as_its_particles(k: float) -> None:
    rng = np.random.default_rng(3)
    n = 50
    air = AirState.at(30.0)
    u = rng.normal(0.0, 3.0, (n, 3))
    v = rng.normal(0.0, 1.0, (n, 3))
    T = rng.uniform(40.0, 90.0, n)
    d0 = 0.008
    force, heat, d = air_load(u, v, T, np.full(n, k * d0), k, air)
    assert np.allclose(d, d0)
    m0 = 1050.0 * math.pi / 6.0 * d0**3
    m_parcel = k**3 * m0
    # Acceleration and heating rate of a parcel: those of one particle (independent route:
    # the correlations called at the particle diameter directly).
    np.testing.assert_allclose(force / m_parcel, drag_force(u, v, d0, air) / m0, rtol=1e-12)
    np.testing.assert_allclose(heat / m_parcel, convective_heat(u, v, T, np.full(n, d0), air) / m0,
                               rtol=1e-12)
    if k > 1.0:
        # Plain size scaling (the sphere's own diameter in the correlations) heats more slowly
        # per kilogram: surface per kilogram falls as 1/k and h falls with diameter too.
        plain = convective_heat(u, v, T, np.full(n, k * d0), air) / m_parcel
        assert np.all(np.abs(plain) < np.abs(heat / m_parcel) / k)


def test_the_coupling_key_and_driver_file_carry_the_parcels() -> None:
    base = CouplingSpec(field={"kind": "uniform", "velocity": [0, 0, -1]}, field_key="f", interval=10,
                        temperature_C=30.0, pressure_kPa=101.3, omega=0.0)
    parcels = CouplingSpec(**{**base.__dict__, "coarse_grain": 1.45})
    assert base.key == ":air=f:every=10"  # runs without parcels keep their stage keys
    assert parcels.key != base.key and "parcels=1.45" in parcels.key
    assert parcels.driver_file("d", "l", 10, 1e-5, [])["coarse_grain"] == 1.45
