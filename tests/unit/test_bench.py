"""The benchmark ladder, its errors and the Pareto front (drumflow.bench), without a solver."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from drumflow.bench.ladder import (
    CONSERVATIVE,
    REFERENCE,
    apply_rung,
    ladder,
    select,
)
from drumflow.bench.pareto import pareto_front, plot_pareto
from drumflow.bench.stage import TOLERANCES, _add_errors
from drumflow.case import load_case
from drumflow.dem.timestep import choose_time_step, rayleigh_time
from drumflow.physics.validation import relative_error


@pytest.fixture(scope="module")
def smoke():
    return load_case(Path(__file__).resolve().parents[2] / "cases" / "smoke.toml")


def test_ladder_covers_every_knob_of_the_issue(smoke) -> None:
    groups = {r.group for r in ladder(smoke)}
    assert groups >= {"reference", "conservative", "default", "time_step", "walls", "modulus", "size",
                      "coupling", "mpi", "skin", "output", "conduction", "air", "overhead"}
    names = [r.name for r in ladder(smoke)]
    assert names[0] == REFERENCE and len(names) == len(set(names))


def test_time_step_rungs_are_fractions_of_the_rayleigh_time(smoke) -> None:
    rung = next(r for r in ladder(smoke) if r.name == "dt_40pct")
    case = apply_rung(smoke, rung)
    p = smoke.particles
    t_r = rayleigh_time(p.radius, p.density, p.youngs_modulus, p.poisson_ratio)
    choice = choose_time_step(case)
    assert choice.time_step == pytest.approx(0.4 * t_r)
    assert choice.mode == "forced"  # 40% is past drumflow's limit: the ladder measures beyond it


def test_the_contact_step_and_the_fast_profile_have_rungs(smoke) -> None:
    """The old "auto" (the contact rule) and the two ways back to its step without the spin
    limit: the default's step is the spin-limited one, the three others take the contact step,
    and the fast rung keeps the case's fixed time (its errors are the settings')."""
    rungs = {r.name: r for r in ladder(smoke)}
    steps = {n: choose_time_step(apply_rung(smoke, rungs[n]).dem_case()).time_step
             for n in ("default", "contact", "no_tangential_damping", "fast")}
    assert steps["default"] < 0.9 * steps["contact"]
    assert steps["no_tangential_damping"] == pytest.approx(steps["contact"])
    assert steps["fast"] == pytest.approx(steps["contact"])
    fast = apply_rung(smoke, rungs["fast"])
    assert not fast.contacts.tangential_damping and not fast.run.conduction
    assert fast.run.stop == smoke.run.stop


def test_reference_is_finest_and_conservative_is_the_issues(smoke) -> None:
    rungs = {r.name: r for r in ladder(smoke)}
    ref, cons = apply_rung(smoke, rungs[REFERENCE]), apply_rung(smoke, rungs[CONSERVATIVE])
    assert ref.run.wall_motion == cons.run.wall_motion == "moving_mesh"
    assert choose_time_step(ref).fraction_of_rayleigh == pytest.approx(0.05)
    assert choose_time_step(cons).fraction_of_rayleigh == pytest.approx(0.10)


def test_size_scaling_keeps_the_mass(smoke) -> None:
    rung = next(r for r in ladder(smoke) if r.name == "size_x1.5")
    case = apply_rung(smoke, rung)
    assert case.particle_mass_total == pytest.approx(smoke.particle_mass_total, rel=2e-3)
    assert case.particles.diameter == pytest.approx(1.5 * smoke.particles.diameter)


def test_softening_keeps_the_conduction_reference(smoke) -> None:
    case = apply_rung(smoke, next(r for r in ladder(smoke) if r.name == "E_x0.2"))
    assert case.particles.youngs_modulus == pytest.approx(0.2 * smoke.particles.youngs_modulus)
    assert case.particles.youngs_modulus_reference == smoke.particles.youngs_modulus


def test_select_adds_the_reference_and_refuses_unknown_names(smoke) -> None:
    chosen = [r.name for r in select(ladder(smoke), ["no_air_by_hand"])]
    assert chosen == [REFERENCE, "no_air", "no_air_by_hand"]
    with pytest.raises(ValueError, match="unknown rung"):
        select(ladder(smoke), ["dt_99pct"])


def test_pareto_front() -> None:
    cost = np.array([1.0, 2.0, 3.0, 2.0, 4.0])
    error = np.array([5.0, 2.0, 1.0, 3.0, 1.0])
    assert pareto_front(cost, error).tolist() == [True, True, True, False, False]


def test_relative_error_handles_missing_values() -> None:
    assert relative_error(1.1, 1.0) == pytest.approx(0.1)
    assert math.isnan(relative_error(1.0, 0.0))
    assert math.isnan(relative_error(math.nan, 1.0))


def test_errors_scores_and_plot(tmp_path: Path) -> None:
    table = pd.DataFrame([
        {"rung": REFERENCE, "group": "reference", "status": "ok", "dem_wall_time_s": 100.0,
         "cooling_K": 6.0, "falling_mass_flow_kg_s": 0.3, "h_W_m2K": 50.0},
        {"rung": CONSERVATIVE, "group": "conservative", "status": "ok", "dem_wall_time_s": 60.0,
         "cooling_K": 6.03, "falling_mass_flow_kg_s": 0.31, "h_W_m2K": 50.1},
        {"rung": "default", "group": "default", "status": "ok", "dem_wall_time_s": 20.0,
         "cooling_K": 6.06, "falling_mass_flow_kg_s": 0.285, "h_W_m2K": 50.0},
        {"rung": "no_air", "group": "overhead", "status": "ok", "dem_wall_time_s": 19.0,
         "cooling_K": 0.0, "falling_mass_flow_kg_s": 0.2, "h_W_m2K": math.nan},
    ])
    _add_errors(table)
    d = table.set_index("rung")
    assert d.loc["default", "err_temperature"] == pytest.approx(0.01)
    assert d.loc["default", "err_mass_flow"] == pytest.approx(0.05)
    # Worst error over its tolerance: 1% of 1% and 5% of 5% are both exactly at it.
    assert d.loc["default", "error_over_tolerance"] == pytest.approx(1.0)
    assert d.loc["default", "speedup_vs_conservative"] == pytest.approx(3.0)
    assert math.isnan(d.loc["no_air", "err_temperature"])  # timing-only rung
    assert d.loc[REFERENCE, "pareto"] and d.loc["default", "pareto"]
    plot_pareto(table, tmp_path / "p.png", TOLERANCES, "test")
    assert (tmp_path / "p.png").stat().st_size > 10_000


def test_speed_only_table_plots_run_times(tmp_path: Path) -> None:
    """Regression: a --speed-only bench has no errors, and the log-scaled error axis raised
    'Data cannot be log-scaled' after every rung had run."""
    table = pd.DataFrame([
        {"rung": CONSERVATIVE, "group": "conservative", "status": "ok", "dem_wall_time_s": 52.3,
         "cooling_K": 0.0, "falling_mass_flow_kg_s": math.nan, "h_W_m2K": math.nan},
        {"rung": "default", "group": "default", "status": "ok", "dem_wall_time_s": 41.2,
         "cooling_K": 0.0, "falling_mass_flow_kg_s": math.nan, "h_W_m2K": math.nan},
    ])
    _add_errors(table)
    assert table["error_over_tolerance"].isna().all()
    assert table.set_index("rung").loc["default", "speedup_vs_conservative"] == pytest.approx(52.3 / 41.2)
    plot_pareto(table, tmp_path / "p.png", TOLERANCES, "speed only")
    assert (tmp_path / "p.png").stat().st_size > 5_000
