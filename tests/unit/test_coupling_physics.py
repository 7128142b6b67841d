"""Drag and convection laws, rotation of the air field, and the coupling log, without a solver."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from drumflow.coupling.driver import UniformAir, air_velocity_at
from drumflow.coupling.log import read_coupling
from drumflow.physics.particle_air import (
    AirState,
    auto_coupling_interval,
    convective_heat,
    drag_force,
    lumped_temperature,
    ranz_marshall_h,
    schiller_naumann_cd,
    terminal_velocity,
)

AIR = AirState.at(30.0)


def test_air_state_ideal_gas() -> None:
    # 101.325 kPa / (287.05 J/kg K * 303.15 K) = 1.1644 kg/m3
    assert AIR.density == pytest.approx(101325 / (287.05 * 303.15), rel=1e-12)
    assert 1.8e-5 < AIR.viscosity < 1.9e-5 and 0.70 < AIR.prandtl < 0.71


def test_schiller_naumann_limits() -> None:
    assert schiller_naumann_cd(0.1) == pytest.approx(240 * (1 + 0.15 * 0.1**0.687))
    assert schiller_naumann_cd(5000.0) == 0.44
    # The two branches meet within 0.5% at Re = 1000 (0.4385 against 0.44).
    assert schiller_naumann_cd(999.999) == pytest.approx(0.44, rel=5e-3)


def test_drag_force_equals_half_cd_rho_a_v2() -> None:
    d = 0.008
    for speed in (0.01, 1.0, 3.0, 20.0):
        f = drag_force(np.array([[0.0, 0.0, speed]]), np.zeros((1, 3)), d, AIR)[0]
        re = AIR.density * speed * d / AIR.viscosity
        expected = 0.5 * schiller_naumann_cd(re) * AIR.density * math.pi / 4 * d**2 * speed**2
        assert f[2] == pytest.approx(expected, rel=1e-12)
        assert f[0] == f[1] == 0.0
    # Zero slip: zero force, no division by zero.
    assert np.all(drag_force(np.zeros((1, 3)), np.zeros((1, 3)), d, AIR) == 0.0)


def test_ranz_marshall() -> None:
    # Still air: Nu = 2 exactly, h = 2 k / d.
    assert ranz_marshall_h(0.0, 0.008, AIR) == pytest.approx(2 * AIR.conductivity / 0.008)
    re = AIR.density * 1.0 * 0.008 / AIR.viscosity
    nu = 2 * (1 + 0.3 * math.sqrt(re) * AIR.prandtl ** (1 / 3))
    assert ranz_marshall_h(1.0, 0.008, AIR) == pytest.approx(nu * AIR.conductivity / 0.008)


def test_convective_heat_sign() -> None:
    q = convective_heat(np.zeros((2, 3)), np.zeros((2, 3)), np.array([90.0, 30.0]), 0.008, AIR)
    assert q[0] < 0 and q[1] == 0.0  # hot particle loses heat; one at air temperature none


def test_lumped_and_terminal() -> None:
    assert lumped_temperature(0.0, 90, 30, 50, 1e-3, 1000, 1e-4) == 90.0
    tau = 1e-3 * 1000 / (50 * 1e-4)
    assert lumped_temperature(tau, 90, 30, 50, 1e-3, 1000, 1e-4) == pytest.approx(30 + 60 / math.e)
    v = terminal_velocity(0.008, 1050.0, AIR)
    weight = 1050 * math.pi / 6 * 0.008**3 * 9.81
    drag = drag_force(np.zeros((1, 3)), np.array([[0.0, 0.0, -v]]), 0.008, AIR)[0, 2]
    assert drag == pytest.approx(weight, rel=1e-9)


def test_auto_interval_keeps_hold_error_small() -> None:
    dt = 1e-4
    n = auto_coupling_interval(dt, 0.008, 1050.0, 1465.38, AIR, max_slip=6.0, cap=10_000)
    h = float(ranz_marshall_h(6.0, 0.008, AIR))
    tau = 1050 * math.pi / 6 * 0.008**3 * 1465.38 / (h * math.pi * 0.008**2)
    assert n * dt <= 0.002 * tau + dt and n >= 1
    assert auto_coupling_interval(dt, 0.008, 1050.0, 1465.38, AIR, 6.0, cap=5) == 5


def test_uniform_field_ignores_rotation() -> None:
    x = np.random.default_rng(1).normal(size=(10, 3))
    field = UniformAir((0.0, 0.0, -3.0))
    assert np.allclose(air_velocity_at(field, x, 1.3, 0.5), [0.0, 0.0, -3.0])


class _DrumFixedField:
    """A field fixed to the drum and not symmetric about its axis: in drum-frame coordinates
    u = (1, 0, x) (a cross-flow along the drum's own x axis, and an axial velocity growing
    with drum-frame x)."""

    def sample(self, points: np.ndarray) -> np.ndarray:
        return np.column_stack([np.ones(len(points)), np.zeros(len(points)), points[:, 0]])


@pytest.mark.parametrize(("turn", "expected"), [
    # Fraction of a turn at the sampling time, and by hand the lab velocity at the lab point
    # (0.3, 0.1, 0). The drum turns counter-clockwise about +z, so after a quarter turn the
    # drum's +x axis points along lab +y, and the lab point sits at drum-frame (0.1, -0.3).
    (0.0, (1.0, 0.0, 0.3)),
    (0.25, (0.0, 1.0, 0.1)),
    (0.5, (-1.0, 0.0, -0.3)),
    (0.75, (0.0, -1.0, -0.1)),
])
def test_rotating_field_is_sampled_at_the_drum_angle(
    turn: float, expected: tuple[float, float, float],
) -> None:
    omega = 2.0 * math.pi * 0.5  # 30 rpm, the tiny drum's
    t = turn / 0.5  # the time at which the drum has made ``turn`` of a revolution
    u = air_velocity_at(_DrumFixedField(), np.array([[0.3, 0.1, 0.0]]), time_s=t, omega=omega)
    assert u[0] == pytest.approx(expected, abs=1e-12)


def test_sampling_angle_off_by_one_coupling_step_is_seen() -> None:
    """An angle late by one coupling interval (10 steps of 5e-5 s at 30 rpm: 0.18 degrees)
    moves the sampled axial velocity at the lab point (0.1, 0, 0) by 1e-4 m/s in 0.1: well
    above round-off, so the frame test above pins the angle, not just the direction."""
    omega, dt = math.pi, 5e-5
    x = np.array([[0.1, 0.0, 0.0]])
    on_time = air_velocity_at(_DrumFixedField(), x, time_s=0.25, omega=omega)
    late = air_velocity_at(_DrumFixedField(), x, time_s=0.25 - 10 * dt, omega=omega)
    assert abs(on_time[0, 2] - late[0, 2]) > 1e-5


def test_coupling_log_sums_ranks_and_supersedes_attempts(tmp_path: Path) -> None:
    head = "step,time_s,steps,heat_to_particles_W,drag_x_N,drag_y_N,drag_z_N,particles,mean_slip_m_s\n"
    for rank, q in ((0, -1), (1, -2)):
        rows = "".join(f"{s},{s / 100:g},10,{q},0,0,0,5,1\n" for s in (0, 10, 20))
        (tmp_path / f"rank{rank}.0.csv").write_text(head + rows)
    (tmp_path / "rank0.20.csv").write_text(head + "20,0.2,10,-4,0,0,0,10,1\n")
    table = read_coupling(tmp_path, time_step=0.01)
    assert table["step"].tolist() == [0, 10, 20]
    assert table["heat_to_particles_W"].tolist() == [-3.0, -3.0, -4.0]
    # Each row's heat is applied for 10 steps of 0.01 s: 0.3 + 0.3 + 0.4 J.
    assert table["heat_removed_J"].iloc[-1] == pytest.approx(1.0)
    assert read_coupling(tmp_path / "none", 0.01).empty


def test_ranz_marshall_slip_inverts_the_correlation() -> None:
    """The slip a published h needs: Eq. 23 solved for Re gives back h, and below the
    still-air limit 2 k / d no slip gives it (NaN, not a negative speed)."""
    from drumflow.physics.particle_air import ranz_marshall_slip

    air = AirState.at(30.0, 101.3)
    for h, d in ((60.15, 0.008), (38.93, 0.02), (500.0, 0.001)):
        v = ranz_marshall_slip(h, d, air)
        assert v > 0.0
        assert float(ranz_marshall_h(v, d, air)) == pytest.approx(h, rel=1e-12)
    assert math.isnan(ranz_marshall_slip(0.99 * 2.0 * air.conductivity / 0.008, 0.008, air))


def test_overlap_is_wanted_on_runs_reaching_a_multiple_and_the_last() -> None:
    """The loop's overlap switch: a run of n steps from `step` evaluates the overlap column when
    it ends on or passes a multiple of `every`, and on the run's last interval."""
    from drumflow.coupling.driver import overlap_wanted

    every, total = 420, 10_000
    ends = [s + 42 for s in range(0, 2100, 42) if overlap_wanted(s, 42, every, total)]
    assert ends == [420, 840, 1260, 1680, 2100]
    assert overlap_wanted(9_990, 10, every, total)  # the last run
    assert overlap_wanted(400, 100, every, total)  # passes 420 inside the run
    assert not overlap_wanted(420, 42, every, total)  # starts on a multiple, ends off it
