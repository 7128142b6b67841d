"""The clinker grate cooler (drumflow.coolers.grate): TDMA, energy closure, limits, grid
convergence, trends of the report, case validation and the CLI."""

from __future__ import annotations

import copy
import json
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from typer.testing import CliRunner

from drumflow.cli import app
from drumflow.coolers.grate import grate_case_from_dict, load_grate_case, parse_vary, solve_grate
from drumflow.coolers.grate.properties import ClinkerProperties
from drumflow.coolers.grate.solution import GrateSolution
from drumflow.coolers.grate.tdma import tdma
from drumflow.errors import CaseError
from drumflow.physics.air import (
    air_enthalpy,
    air_enthalpy_scalar,
    air_heat_capacity,
    air_temperature_from_enthalpy,
)

CASE = Path(__file__).resolve().parents[2] / "cases" / "grate_cooler_report.toml"


@pytest.fixture(scope="module")
def report_data() -> dict[str, Any]:
    return load_grate_case(CASE).model_dump()


@pytest.fixture(scope="module")
def report_solution() -> GrateSolution:
    return solve_grate(load_grate_case(CASE))


def _variant(data: dict[str, Any], **changes: Any) -> GrateSolution:
    d = copy.deepcopy(data)
    for key, value in changes.items():
        section, name = key.split("__")
        d[section][name] = value
    return solve_grate(grate_case_from_dict(d))


def _coarse(data: dict[str, Any]) -> dict[str, Any]:
    d = copy.deepcopy(data)
    d["numerics"]["cells_length"] = 40
    d["numerics"]["cells_height"] = 30
    return d


# --- TDMA ---------------------------------------------------------------------------------


@pytest.mark.parametrize("n", [1, 2, 7, 120])
def test_tdma_matches_dense_solve(n: int) -> None:
    rng = np.random.default_rng(n)
    a_w = rng.uniform(0.0, 2.0, n)
    a_e = rng.uniform(0.0, 2.0, n)
    # Not diagonally dominant on purpose in some rows: the banded LU pivots.
    a_p = rng.uniform(-1.0, 5.0, n) + 0.5
    b = rng.normal(size=n)
    dense = np.diag(a_p) - np.diag(a_w[1:], -1) - np.diag(a_e[:-1], 1)
    expected = np.linalg.solve(dense, b)
    # 1e-9: round-off of a well-conditioned small system, far below any physical effect.
    np.testing.assert_allclose(tdma(a_w, a_p, a_e, b), expected, rtol=1e-9, atol=1e-12)


def test_tdma_rejects_mismatched_lengths() -> None:
    with pytest.raises(ValueError, match="one length"):
        tdma(np.ones(3), np.ones(4), np.ones(4), np.ones(4))


# --- properties -----------------------------------------------------------------------------


def test_air_enthalpy_is_integral_of_cp_and_inverts() -> None:
    t = np.linspace(260.0, 1990.0, 97)
    h = air_enthalpy(t)
    # d h / d T = c_p, checked by central differences (0.5 K steps; c_p is piecewise linear,
    # so the difference quotient is exact up to round-off away from table rows).
    dh = (air_enthalpy(t + 0.5) - air_enthalpy(t - 0.5)) / 1.0
    np.testing.assert_allclose(dh, air_heat_capacity(t), rtol=2e-4)
    np.testing.assert_allclose(air_temperature_from_enthalpy(h), t, rtol=1e-12)
    for tk in (300.0, 812.3, 1673.0):
        hs, cps = air_enthalpy_scalar(tk)
        assert hs == pytest.approx(float(air_enthalpy(tk)), rel=1e-14)
        assert cps == pytest.approx(float(air_heat_capacity(tk)), rel=1e-14)


def test_clinker_enthalpy_inverse() -> None:
    props = ClinkerProperties(cp0=710.0, cp1=0.233, k0=1.5, k1=0.0)
    t = np.array([300.0, 905.0, 1673.0])
    np.testing.assert_allclose(props.temperature(props.enthalpy(t)), t, rtol=1e-13)
    # The secant c_p equals the enthalpy difference quotient for a linear c_p.
    assert props.secant(t[2], t[0]) == pytest.approx(
        float((props.enthalpy(t[2]) - props.enthalpy(t[0])) / (t[2] - t[0])), rel=1e-13)


# --- conservation, limits, convergence --------------------------------------------------------


def test_converged_field_closes_the_energy_balance(report_solution: GrateSolution) -> None:
    sol = report_solution
    case = sol.case
    props = ClinkerProperties.of(case)
    # Recomputed here from the fields, independently of the solver's own bookkeeping.
    q_clinker = case.clinker.mass_flow * float(
        props.enthalpy(case.clinker.inlet_temperature)
        - props.enthalpy(sol.clinker_temperature[:, -1]).mean())
    q_air = case.air.mass_flow * float(
        air_enthalpy(sol.freeboard_temperature[0]) - air_enthalpy(case.air.inlet_temperature))
    # 1e-6: the closure requirement; the solver stops at 1e-9 of the duty.
    assert abs(q_clinker - q_air) / q_clinker < 1e-6
    assert sol.residual < case.numerics.residual_tolerance


def test_report_case_headline_numbers_are_physical(report_solution: GrateSolution) -> None:
    sol = report_solution
    # Second law: neither stream crosses the other's inlet temperature.
    assert 300.0 < sol.clinker_outlet_temperature < 1673.0
    assert 300.0 < sol.secondary_air_temperature < 1673.0
    assert np.all(sol.clinker_temperature <= 1673.0 + 1e-9)
    assert np.all(sol.air_temperature >= 300.0 - 1e-9)
    assert 0.0 < sol.efficiency < 1.0
    # The bed height follows from plug flow: 33 / (3150 * 0.5 * 0.1 * 1) m.
    assert sol.bed_height == pytest.approx(33.0 / (3150 * 0.5 * 0.1), rel=1e-12)


@pytest.mark.parametrize("radiation", [True, False])
def test_without_air_the_clinker_leaves_hot(report_data: dict[str, Any], radiation: bool) -> None:
    sol = _variant(_coarse(report_data), air__mass_flow=1e-4, model__radiation=radiation)
    # The air can take at most m_a [h_a(1673) - h_a(300)] ~ 150 W from 33 kg/s of clinker
    # (~0.005 K); radiation only heats the freeboard air, which has no capacity either.
    assert sol.clinker_outlet_temperature > 1673.0 - 0.01


def test_with_unlimited_air_the_clinker_leaves_at_the_air_temperature(
        report_data: dict[str, Any]) -> None:
    sol = _variant(_coarse(report_data), air__mass_flow=5000.0)
    # 200 times the report's air: the air warms by Q / (m_a c_p) < 9 K and the bed's NTU is
    # ~100, so the clinker must leave within 1 K of the air inlet.
    assert sol.clinker_outlet_temperature - 300.0 < 1.0
    assert sol.secondary_air_temperature - 300.0 < 9.0


def test_outlet_temperatures_converge_with_cell_count(report_data: dict[str, Any]) -> None:
    base = load_grate_case(CASE)
    fine = copy.deepcopy(report_data)
    fine["numerics"]["cells_length"] = 2 * base.numerics.cells_length
    fine["numerics"]["cells_height"] = 2 * base.numerics.cells_height
    # A finer grid takes fewer sweeps at most (MAX_SWEEP_WORK); it converges in about 9.
    fine["numerics"]["max_sweeps"] = 200
    a = solve_grate(base)
    b = solve_grate(grate_case_from_dict(fine))
    # The criterion: less than 1 K from the report's 120 x 90 grid to 240 x 180.
    assert abs(a.clinker_outlet_temperature - b.clinker_outlet_temperature) < 1.0
    assert abs(a.secondary_air_temperature - b.secondary_air_temperature) < 1.0


def test_outlet_exchange_is_first_order(report_data: dict[str, Any]) -> None:
    # The report's own form (exchange at the cell outlet temperatures) converges to the same
    # answer, with an error that halves when the cells halve (first order).
    results = []
    for f in (1, 2, 4):
        d = _coarse(report_data)
        d["numerics"]["exchange"] = "outlet"
        d["numerics"]["cells_length"] *= f
        d["numerics"]["cells_height"] *= f
        d["numerics"]["max_sweeps"] = 200  # within MAX_SWEEP_WORK on the finest grid
        results.append(solve_grate(grate_case_from_dict(d)).clinker_outlet_temperature)
    ratio = (results[0] - results[1]) / (results[1] - results[2])
    assert 1.7 < ratio < 2.3  # 2 for a first-order scheme


# --- trends of the report ---------------------------------------------------------------------


def test_radiation_cools_the_top_layer(report_data: dict[str, Any]) -> None:
    base = _coarse(report_data)
    with_rad = _variant(base, model__radiation=True)
    without = _variant(base, model__radiation=False)
    column = 3  # near the kiln end (report Figures 7 and 8)
    # Without radiation the top layer is the hottest; with it the top is cooled below the
    # layers just beneath.
    assert np.argmax(without.clinker_temperature[:, column]) == without.y.size - 1
    assert np.argmax(with_rad.clinker_temperature[:, column]) < with_rad.y.size - 1


def test_more_air_lowers_both_outlets(report_data: dict[str, Any]) -> None:
    base = _coarse(report_data)
    low = _variant(base, air__mass_flow=20.0)
    high = _variant(base, air__mass_flow=30.0)
    assert high.clinker_outlet_temperature < low.clinker_outlet_temperature
    assert high.secondary_air_temperature < low.secondary_air_temperature


def test_more_clinker_raises_its_outlet(report_data: dict[str, Any]) -> None:
    base = _coarse(report_data)
    low = _variant(base, clinker__mass_flow=25.0)
    high = _variant(base, clinker__mass_flow=41.0)
    assert high.clinker_outlet_temperature > low.clinker_outlet_temperature


def test_air_distribution_conserves_the_total(report_data: dict[str, Any]) -> None:
    d = _coarse(report_data)
    d["air"]["distribution"] = [3.0, 2.0, 1.0, 1.0]
    sol = solve_grate(grate_case_from_dict(d))
    assert sol.air_column_flow.sum() == pytest.approx(25.0, rel=1e-12)
    assert sol.air_column_flow[0] == pytest.approx(3.0 * sol.air_column_flow[-1], rel=1e-12)


# --- validation and CLI ---------------------------------------------------------------------------


def test_bad_values_name_field_and_range(report_data: dict[str, Any]) -> None:
    d = copy.deepcopy(report_data)
    d["cooler"]["grate_speed"] = -0.1
    d["clinker"]["bed_porosity"] = 0.95
    d["air"]["distribution"] = [1.0, 0.0]
    with pytest.raises(CaseError) as info:
        grate_case_from_dict(d)
    text = str(info.value)
    assert "cooler.grate_speed = -0.1" in text and "> 0" in text
    assert "clinker.bed_porosity = 0.95" in text and "< 0.8" in text
    assert "air.distribution[1] = 0.0" in text


def test_clinker_colder_than_air_is_refused(report_data: dict[str, Any]) -> None:
    d = copy.deepcopy(report_data)
    d["air"]["inlet_temperature"] = 900.0
    d["clinker"]["inlet_temperature"] = 800.0
    with pytest.raises(CaseError, match="clinker.inlet_temperature = 800.0"):
        grate_case_from_dict(d)


def test_parse_vary_forms_and_errors() -> None:
    assert parse_vary("grate_speed=0.05:0.2:4") == ("cooler.grate_speed", [0.05, 0.1, 0.15, 0.2])
    assert parse_vary("air.mass_flow=20,25") == ("air.mass_flow", [20.0, 25.0])
    with pytest.raises(CaseError, match="unknown field"):
        parse_vary("speed=1:2:3")
    with pytest.raises(CaseError, match="COUNT = 1"):
        parse_vary("grate_speed=0.1:0.2:1")
    with pytest.raises(CaseError, match="expected"):
        parse_vary("grate_speed")


def _small_case(tmp_path: Path) -> Path:
    text = CASE.read_text().replace("cells_length = 120", "cells_length = 24").replace(
        "cells_height = 90", "cells_height = 12")
    path = tmp_path / "small.toml"
    path.write_text(text)
    return path


def test_cli_single_run_writes_results(tmp_path: Path) -> None:
    out = tmp_path / "run"
    res = CliRunner().invoke(app, ["cooler", "grate", str(_small_case(tmp_path)), "--out",
                                   str(out), "--json"])
    assert res.exit_code == 0, res.output
    result = json.loads((out / "result.json").read_text())
    assert result["cells"] == [24, 12]
    for name in ("profiles.csv", "fields.png", "clinker_layers.png", "air_layers.png",
                 "air_height.png", "manifest.json"):
        assert (out / name).is_file(), name


def test_cli_sweep_and_bad_input(tmp_path: Path) -> None:
    case = _small_case(tmp_path)
    out = tmp_path / "sweep"
    res = CliRunner().invoke(app, ["cooler", "grate", str(case), "--out", str(out),
                                   "--vary", "grate_speed=0.08:0.12:3"])
    assert res.exit_code == 0, res.output
    rows = (out / "sweep.csv").read_text().splitlines()
    assert len(rows) == 4 and rows[0].startswith("cooler.grate_speed,")
    bad = CliRunner().invoke(app, ["cooler", "grate", str(case), "--out", str(tmp_path / "b"),
                                   "--vary", "grate_speed=0:0.2:3"])
    assert bad.exit_code == 2
    assert "cooler.grate_speed" in bad.output
