"""Time-step limits against hand-computed values."""

from __future__ import annotations

import math

import pytest

from drumflow.case import case_from_dict
from drumflow.dem.timestep import choose_time_step, hertz_contact_time, rayleigh_time
from drumflow.errors import CaseError


def test_rayleigh_time_paper_particles() -> None:
    # 8 mm NPK, 517 kPa, nu 0.45: G = 517e3 / 2.9 = 178,276 Pa;
    # t_R = pi * 0.004 * sqrt(1050 / 178276) / (0.1631 * 0.45 + 0.8766) = 1.0161e-3 s.
    G = 517e3 / 2.9
    expected = math.pi * 0.004 * math.sqrt(1050 / G) / (0.1631 * 0.45 + 0.8766)
    assert expected == pytest.approx(1.0161e-3, rel=1e-3)
    assert rayleigh_time(0.004, 1050, 517e3, 0.45) == pytest.approx(expected, rel=1e-12)


def test_hertz_time_scales_as_v_to_minus_one_fifth() -> None:
    a = hertz_contact_time(0.004, 1050, 5e6, 0.45, 1.0)
    b = hertz_contact_time(0.004, 1050, 5e6, 0.45, 32.0)
    assert a / b == pytest.approx(2.0, rel=1e-12)


def test_auto_and_fixed(smoke_dict: dict) -> None:
    case = case_from_dict(smoke_dict)
    auto = choose_time_step(case)
    assert auto.mode == "auto"
    assert auto.time_step <= 0.2 * auto.rayleigh_time * (1 + 1e-12)
    assert auto.steps_per_contact >= 10 - 1e-9
    smoke_dict["run"]["time_step"] = 1e-3
    with pytest.raises(CaseError, match=r"run.time_step = 0.001 s: above the stability limit"):
        choose_time_step(case_from_dict(smoke_dict))
    smoke_dict["run"]["time_step"] = 2e-5
    fixed = choose_time_step(case_from_dict(smoke_dict))
    assert fixed.time_step == 2e-5 and fixed.mode == "fixed"
