"""Fan-limited cooling air of the grate cooler (issue 34): the case choice, its defaults,
the coupled solve, the grate-speed study with the recovered heat's maximum, and the CLI.

The laws (Ergun by hand, the operating point by hand, and 10 % mutants of both) are in
``test_laws_grate.py``.
"""

from __future__ import annotations

import copy
import json
from pathlib import Path
from typing import Any

import pytest
from typer.testing import CliRunner

from drumflow.cli import app
from drumflow.coolers.grate import grate_case_from_dict, load_grate_case, run_sweep, solve_grate
from drumflow.errors import CaseError, GrateConvergenceError

CASES = Path(__file__).resolve().parents[2] / "cases"
REPORT = CASES / "grate_cooler_report.toml"
FANS = CASES / "grate_cooler_fans.toml"


@pytest.fixture(scope="module")
def fan_data() -> dict[str, Any]:
    return load_grate_case(FANS).model_dump(exclude_none=True)


def _coarse(data: dict[str, Any], **numerics: Any) -> dict[str, Any]:
    d = copy.deepcopy(data)
    d["numerics"] |= {"cells_length": 40, "cells_height": 30, **numerics}
    return d


def test_report_case_is_unchanged_by_the_new_fields() -> None:
    """The defaults (air.supply = "fixed", no [fan]) give the numbers the model gave before
    the fan choice existed (measured on the report case before the change)."""
    case = load_grate_case(REPORT)
    assert case.air.supply == "fixed" and case.fan is None
    sol = solve_grate(case)
    assert sol.clinker_outlet_temperature == pytest.approx(904.9340507548085, rel=1e-9)
    assert sol.secondary_air_temperature == pytest.approx(1239.3709748041442, rel=1e-9)
    assert sol.heat_recovered == pytest.approx(25.607985013771533e6, rel=1e-9)
    assert sol.sweeps == 9
    assert sol.air_flow == 25.0 and sol.fan_pressure is None
    summary = sol.summary()
    assert summary["air_supply"] == "fixed" and "fan_pressure_Pa" not in summary
    # The hot kiln end resists most (thin, viscous air), the discharge end least.
    drops = sol.column_pressure_drop
    assert drops[0] > drops[-1] > 0.0
    assert summary["bed_pressure_drop_Pa"] == pytest.approx(934.66, rel=1e-4)  # the fans' design


def test_fan_choice_is_validated_by_name(fan_data: dict[str, Any]) -> None:
    no_fan = copy.deepcopy(fan_data)
    del no_fan["fan"]
    with pytest.raises(CaseError, match=r"air.supply = 'fan': needs a \[fan\] section"):
        grate_case_from_dict(no_fan)
    unused = copy.deepcopy(fan_data)
    unused["air"]["supply"] = "fixed"
    with pytest.raises(CaseError, match=r"\[fan\] given with air.supply = 'fixed'"):
        grate_case_from_dict(unused)
    bad = copy.deepcopy(fan_data)
    bad["fan"] = {"shutoff_pressure": -5.0, "free_delivery": 0.0}
    with pytest.raises(CaseError) as info:
        grate_case_from_dict(bad)
    text = str(info.value)
    assert "fan.shutoff_pressure = -5.0" in text and "> 0" in text
    assert "fan.free_delivery = 0.0" in text
    wrong = copy.deepcopy(fan_data)
    wrong["air"]["supply"] = "fans"
    with pytest.raises(CaseError, match="air.supply"):
        grate_case_from_dict(wrong)


def test_fan_case_meets_its_design_point(fan_data: dict[str, Any]) -> None:
    """The fan values were derived from the report's design point (25 kg/s at 0.1 m/s) and
    rounded to 3-4 digits: the solved flow there is 25 kg/s within their rounding."""
    sol = solve_grate(grate_case_from_dict(fan_data))
    assert sol.air_flow == pytest.approx(25.0, rel=2e-3)
    assert sol.fan_pressure == pytest.approx(sol.bed_pressure_drop, rel=1e-6)
    assert sol.bed_pressure_drop == pytest.approx(934.7, rel=5e-3)
    assert sol.energy_imbalance < 1e-9


def test_operating_point_does_not_depend_on_the_first_guess(fan_data: dict[str, Any]) -> None:
    flows = []
    for guess in (10.0, 40.0):
        d = _coarse(fan_data)
        d["air"]["mass_flow"] = guess
        flows.append(solve_grate(grate_case_from_dict(d)).air_flow)
    assert flows[0] == pytest.approx(flows[1], rel=1e-7)


def test_flat_curve_is_a_fixed_fan_pressure(fan_data: dict[str, Any]) -> None:
    d = _coarse(fan_data)
    d["fan"] = {"shutoff_pressure": 935.0}
    sol = solve_grate(grate_case_from_dict(d))
    assert sol.fan_pressure == 935.0
    assert sol.bed_pressure_drop == pytest.approx(935.0, rel=1e-6)


def test_thicker_bed_gets_less_air_and_stronger_fan_more(fan_data: dict[str, Any]) -> None:
    case = grate_case_from_dict(_coarse(fan_data))
    by_speed = run_sweep(case, "cooler.grate_speed", [0.06, 0.15]).solutions
    assert by_speed[0].air_flow < by_speed[1].air_flow
    by_fan = run_sweep(case, "fan.shutoff_pressure", [1000.0, 2000.0]).solutions
    assert by_fan[0].air_flow < by_fan[1].air_flow


def test_max_sweeps_bounds_the_coupled_solve(fan_data: dict[str, Any]) -> None:
    d = _coarse(fan_data, max_sweeps=2)
    with pytest.raises(GrateConvergenceError, match="air-flow change"):
        solve_grate(grate_case_from_dict(d))


def _coarse_file(tmp_path: Path) -> Path:
    text = FANS.read_text().replace("cells_length = 120", "cells_length = 40").replace(
        "cells_height = 90", "cells_height = 30")
    path = tmp_path / "fans.toml"
    path.write_text(text)
    return path


def test_cli_grate_speed_study_shows_the_recovered_heat_maximum(tmp_path: Path) -> None:
    """The issue's check: the grate-speed study with the fan-limited air has its largest
    recovered heat inside 0.05-0.19 m/s, the secondary air none (it falls throughout)."""
    out = tmp_path / "study"
    res = CliRunner().invoke(app, ["cooler", "grate", str(_coarse_file(tmp_path)), "--out",
                                   str(out), "--vary", "grate_speed=0.05:0.19:8"])
    assert res.exit_code == 0, res.output
    assert "largest recovered heat" in res.output and "inside the range" in res.output
    result = json.loads((out / "result.json").read_text())
    assert result["air_supply"] == "fan"
    peak = result["maxima"]["heat_recovered_MW"]
    assert peak["interior"] and 0.05 < peak["at"] < 0.19
    assert result["maxima"]["secondary_air_K"] == {
        "at": 0.05, "value": result["rows"][0]["secondary_air_K"], "interior": False}
    air = [r["air_flow_kg_s"] for r in result["rows"]]
    assert air == sorted(air)  # thinner bed, more air
    for name in ("sweep.csv", "sweep_outlets.png", "sweep_recovered.png"):
        assert (out / name).is_file(), name


def test_cli_refuses_to_vary_a_solved_air_flow(tmp_path: Path) -> None:
    out = tmp_path / "bad"
    res = CliRunner().invoke(app, ["cooler", "grate", str(_coarse_file(tmp_path)), "--out",
                                   str(out), "--vary", "air_flow=20,30"])
    assert res.exit_code == 2
    assert "air.supply = 'fan'" in res.output
    assert not out.exists()


def test_cli_single_fan_run_prints_the_operating_point(tmp_path: Path) -> None:
    out = tmp_path / "one"
    res = CliRunner().invoke(app, ["cooler", "grate", str(_coarse_file(tmp_path)), "--out",
                                   str(out), "--json"])
    assert res.exit_code == 0, res.output
    result = json.loads((out / "result.json").read_text())
    assert result["air_supply"] == "fan"
    assert result["fan_pressure_Pa"] == pytest.approx(result["bed_pressure_drop_Pa"], rel=1e-6)
