"""The single-particle air checks on the real coupling loop, and each shown to fail when the
coupling runs a deliberately broken implementation.

The break is put into the coupling driver's own process (it runs under mpirun, out of reach
of monkeypatch): a ``sitecustomize`` module on PYTHONPATH replaces the physics function before
the driver imports it. About a minute in all.
"""

from __future__ import annotations

import textwrap
from pathlib import Path

import pytest
from support.solvers import LIGGGHTS, requires_solver

from drumflow.runner import Runner
from drumflow.verify.single_particle import SETTLING_DIAMETERS, convective_h_check, settling_check

pytestmark = [pytest.mark.solver, pytest.mark.timeout(300), requires_solver(*LIGGGHTS)]

_BROKEN_EXPONENT = """
    import math
    import numpy as np
    import drumflow.physics.particle_air as physics

    def drag_force(air_velocity, particle_velocity, diameter, air):
        # Schiller-Naumann with the exponent 0.6 instead of 0.687.
        slip = np.asarray(air_velocity, float) - np.asarray(particle_velocity, float)
        speed = np.linalg.norm(slip, axis=1)
        d = np.broadcast_to(np.asarray(diameter, float), speed.shape)
        re = air.density * speed * d / air.viscosity
        return (3.0 * math.pi * air.viscosity * d * (1.0 + 0.15 * re**0.6))[:, None] * slip

    physics.drag_force = drag_force
"""

_CONDUCTIVITY_OFF = """
    import dataclasses
    import drumflow.physics.particle_air as physics

    _at = physics.AirState.at.__func__

    def at(cls, temperature_C, pressure_kPa=101.325):
        air = _at(cls, temperature_C, pressure_kPa)
        return dataclasses.replace(air, conductivity=1.1 * air.conductivity)

    physics.AirState.at = classmethod(at)
"""


def _break_the_driver(monkeypatch: pytest.MonkeyPatch, tmp_path: Path, source: str) -> None:
    site = tmp_path / "broken_site"
    site.mkdir()
    (site / "sitecustomize.py").write_text(textwrap.dedent(source))
    monkeypatch.setenv("PYTHONPATH", str(site))


@pytest.mark.parametrize("diameter", SETTLING_DIAMETERS)
def test_settling_in_the_schiller_naumann_range(tmp_path: Path, diameter: float) -> None:
    check = settling_check(tmp_path, Runner(), diameter)
    assert check.passed, check.as_dict()
    assert 50 < check.details["reynolds"] < 500
    # Settled: the speed one output interval earlier agrees to 1e-4.
    assert check.details["speed_one_output_earlier_m_s"] == pytest.approx(
        check.details["terminal_speed_m_s"], rel=1e-4
    )


def test_settling_fails_with_a_wrong_exponent(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    _break_the_driver(monkeypatch, tmp_path, _BROKEN_EXPONENT)
    check = settling_check(tmp_path / "run", Runner(), SETTLING_DIAMETERS[1])
    assert not check.passed, check.as_dict()


@pytest.mark.parametrize("speed", [1.0, 3.0])
def test_convective_h_against_ranz_marshall_formed_anew(tmp_path: Path, speed: float) -> None:
    check = convective_h_check(tmp_path, Runner(), speed=speed)
    assert check.passed, check.as_dict()


def test_convective_h_fails_with_air_conductivity_off_by_10_percent(
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    _break_the_driver(monkeypatch, tmp_path, _CONDUCTIVITY_OFF)
    check = convective_h_check(tmp_path / "run", Runner(), speed=3.0)
    assert not check.passed, check.as_dict()
    assert check.measured == pytest.approx(1.1 * check.expected, rel=0.02)
