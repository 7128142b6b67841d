"""The replayed LIGGGHTS contact and the restitution correction (drumflow.dem.restitution)."""

from __future__ import annotations

import math

import pytest

from drumflow.dem.restitution import (
    calibrate_case,
    calibrate_restitution,
    mean_realised_restitution,
    realised_restitution,
)
from drumflow.dem.timestep import choose_time_step, hertz_contact_time
from drumflow.verify.scenes import tiny_drum

MASS = 1050.0 * math.pi / 6.0 * 0.008**3
PAIR = (0.5 * MASS, 0.002, 5e6 / (2.0 * (1.0 - 0.45**2)))
T_HERTZ = hertz_contact_time(0.004, 1050.0, 5e6, 0.45, 2.0)


@pytest.mark.parametrize(("steps", "liggghts"), [(10, 0.0847), (20, 0.0929), (50, 0.0963),
                                                 (100, 0.0982), (200, 0.0991)])
def test_replay_reproduces_liggghts_measurements(steps: int, liggghts: float) -> None:
    """Values LIGGGHTS 3.8 realised for e = 0.1 at 2 m/s, two 8 mm spheres, 5 MPa (measured
    with the verification deck, first touch at phase 0; printed to 3 digits)."""
    e = realised_restitution(0.1, T_HERTZ / steps, *PAIR, 2.0)
    assert e == pytest.approx(liggghts, abs=1.5e-4)


def test_error_is_first_order_in_the_time_step() -> None:
    """Halving dt halves the shortfall (phase-averaged, 50 to 100 to 200 steps per contact)."""
    short = [0.1 - mean_realised_restitution(0.1, T_HERTZ / n, *PAIR, 2.0) for n in (50, 100, 200)]
    assert short[0] / short[1] == pytest.approx(2.0, rel=0.15)
    assert short[1] / short[2] == pytest.approx(2.0, rel=0.15)


def test_elastic_contact_stays_elastic() -> None:
    """e = 1 has no damping: the Verlet contact returns the speed to within 1% at 10 steps."""
    assert mean_realised_restitution(1.0, T_HERTZ / 10, *PAIR, 2.0) == pytest.approx(1.0, rel=0.01)


@pytest.mark.parametrize("target", [0.1, 0.3, 0.6])
def test_calibration_realises_the_target(target: float) -> None:
    c = calibrate_restitution(target, T_HERTZ / 10, *PAIR, 2.0)
    assert c.realised_corrected == pytest.approx(target, rel=1e-5)
    assert c.realised_uncorrected < target < c.liggghts_value <= 1.0


def test_calibration_holds_off_its_speed_within_two_percent() -> None:
    """Made at 1.4 m/s, the correction stays within 2% from 1 to 2 m/s: steps per contact
    change only as v^(-1/5)."""
    dt = T_HERTZ / 10
    c = calibrate_restitution(0.1, dt, *PAIR, 1.4)
    for v in (1.0, 2.0):
        assert mean_realised_restitution(c.liggghts_value, dt, *PAIR, v) == pytest.approx(0.1, rel=0.02)


def test_case_calibration_is_recorded_per_pair_and_can_be_switched_off() -> None:
    case = tiny_drum()
    dt = choose_time_step(case).time_step
    on = calibrate_case(case, dt)
    assert set(on) == {"particle_particle", "particle_wall"}
    assert on["particle_particle"].liggghts_value > 0.1
    off = calibrate_case(tiny_drum(run__restitution_correction=False), dt)
    assert off["particle_particle"].liggghts_value == 0.1
    assert off["particle_particle"].realised_corrected < 0.095
