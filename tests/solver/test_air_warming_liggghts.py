"""Air that warms (``air.warming``) through the real coupling loop: the epsilon-NTU check of
``drumflow verify`` and its failure when the heat law is 10 % off, and the tiny drum with warming
air against the same drum with one-way air."""

from __future__ import annotations

from pathlib import Path

import pytest
from support.solvers import LIGGGHTS, requires_solver

from drumflow.runner import Runner
from drumflow.verify.air_heat import TOLERANCE, air_heat_check

pytestmark = [pytest.mark.solver, requires_solver(*LIGGGHTS)]


@pytest.mark.timeout(300)
def test_plug_flow_column_warms_as_epsilon_ntu_and_a_wrong_law_fails(tmp_path: Path) -> None:
    check = air_heat_check(tmp_path / "true", Runner())
    assert check.passed, check
    # Bookkeeping beside it: the air carried out what the particles gave, to round-off.
    assert check.details["air_enthalpy_gain_W"] == pytest.approx(check.details["heat_to_air_W"], rel=1e-9)
    # The contact efficiency the loop logs is epsilon / NTU (1 %, as the rise).
    assert check.details["contact_efficiency"] == pytest.approx(
        check.details["contact_efficiency_exact"], rel=TOLERANCE)
    for factor in (0.9, 1.1):
        wrong = air_heat_check(tmp_path / f"h{factor}", Runner(), h_factor=factor)
        assert not wrong.passed and wrong.error > 3 * TOLERANCE, wrong
        # Against the wrong law's epsilon / NTU the logged efficiency misses by 4-5 %.
        off = wrong.details["contact_efficiency"] / wrong.details["contact_efficiency_exact"] - 1.0
        assert abs(off) > 3 * TOLERANCE, off


@pytest.mark.timeout(900)
def test_tiny_drum_air_that_warms_cools_the_bed_less_and_closes_energy(tmp_path: Path) -> None:
    from drumflow.pipeline import run_case
    from drumflow.verify.scenes import tiny_drum

    common = {"air__model": "uniform", "air__mass_flow": 0.1, "run__time": 0.6,
              "run__mass_flow_start": 0.2, "run__processes": 2}
    one_way = run_case(tiny_drum(**common), tmp_path / "one_way", timeout=600)
    warming = run_case(tiny_drum(air__warming=True, **common), tmp_path / "warming", timeout=600)
    for summary in (one_way, warming):
        assert summary["energy_balance_error"] < 1e-6
        assert summary["particles_final"] == 500
    # The air the bed heats is what the next particles see: less cooling than at 30 C.
    cooled = {k: 90.0 - s["mean_temperature_C"] for k, s in (("one_way", one_way), ("warming", warming))}
    assert cooled["warming"] < 0.97 * cooled["one_way"], cooled
    assert warming["air_energy_balance_error"] < 1e-6
    # Air that warms leaves the bed less of the film's drive than fresh air would.
    assert 0.0 < warming["contact_efficiency"] < 1.0
    # 0.1 kg/s of air taking the bed's heat leaves warmer by about Q / (m_dot c_p).
    rise = warming["air_outlet_temperature_C"] - 30.0
    assert rise == pytest.approx(warming["mean_heat_removal_W"] / (0.1 * 1005.0), rel=0.3)
