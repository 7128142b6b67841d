"""The shipped spin studies (results/bench/paper_model_one_settings, paper_model_one_spin,
paper_model_two_spin) still say what the tables of docs/benchmarks.md say.

Shipped files only: these tests open the shipped CSV and JSON files and compare their numbers;
no drumflow code runs, so they test no code (marker ``shipped``; tests/shipped holds them
apart from the tests of code). The spin limit's code: tests/unit/test_spin_limit.py.
"""

from __future__ import annotations

import json
from pathlib import Path

import pandas as pd
import pytest

ROOT = Path(__file__).resolve().parents[2]

pytestmark = pytest.mark.shipped


def test_the_shipped_study_shows_the_numerical_spin_and_its_cause() -> None:
    """The table in docs/benchmarks.md (model one from its 5.5 s restart, 100 steps of the default step's
    time): the default step's rotational energy is ten times a resolved step's; half and a
    quarter of the step agree (converged), and so does the default step without the tangential
    dashpot (the cause). The long run at the default step keeps about 2 J from 0.25 s on."""
    study = pd.read_csv(ROOT / "results" / "bench" / "paper_model_one_settings" / "spin_5.5s.csv")
    row = study.set_index("variant")
    spin, ke = row["rotational_kinetic_energy_J"], row["kinetic_energy_J"]
    assert spin["baseline"] > 5.0 * spin["half_step"]
    assert spin["half_step"] == pytest.approx(spin["quarter_step"], rel=0.02)
    assert spin["no_tangential_damping"] == pytest.approx(spin["quarter_step"], rel=0.02)
    assert ke["half_step"] == pytest.approx(ke["quarter_step"], rel=0.002)
    assert ke["baseline"] > 1.015 * ke["quarter_step"]
    energy = pd.read_csv(ROOT / "results" / "bench" / "paper_model_one_spin" / "long_run" / "energy.csv")
    formed = energy[energy["time_s"] >= 0.25]
    assert formed["rotational_kinetic_energy_J"].between(1.8, 2.7).all()


def test_the_whole_run_study_shows_the_old_steps_bias_on_the_flow() -> None:
    """results/bench/paper_model_two_spin (the table in docs/benchmarks.md): over 17.5 s of model two's
    parcels, the cascading bed's flow at the old step (1.61 x the spin limit) is above the half
    step's by more than twice the half step's noise floor, in both runs at the old step, which
    agree with each other within 1 %; the heat answers agree within 0.1 %."""
    spin = ROOT / "results" / "bench" / "paper_model_two_spin"
    ladder = json.loads((spin / "ladder.json").read_text())
    assert ladder["reference"] == "half_step"
    rungs = {r["rung"]: r for r in ladder["rungs"]}
    floor = ladder["noise_floor"]["steady_mass_flow"]
    for name in ("default_step", "default_step_replicate"):
        assert rungs[name]["error_steady_mass_flow"] > max(2.0 * floor, 0.04)
        assert abs(rungs[name]["error_h"]) < 1e-3 and abs(rungs[name]["error_temperature"]) < 1e-3
    old, replicate = (rungs[n]["value_steady_mass_flow"] for n in ("default_step", "default_step_replicate"))
    assert abs(replicate / old - 1.0) < 0.01
    steps = {n: json.loads((spin / n / "manifest.json").read_text())["time_step"]["time_step"]
             for n in ("half_step", "default_step")}
    assert steps["half_step"] == pytest.approx(0.5 * steps["default_step"], rel=1e-9)


def test_the_fast_profile_run_lands_on_the_resolved_spins_answers() -> None:
    """results/bench/paper_model_two_spin/fast (docs/benchmarks.md, 'The fast profile'): without the
    tangential dashpot, at the old (contact) step, the three answers over 17.5 s are within the
    half step's noise floor and 1 % of it (the old step with the dashpot: +5.5 %), and the run
    took the old step, the dashpot off and no conduction, as its manifest records."""
    spin = ROOT / "results" / "bench" / "paper_model_two_spin"
    ladder = json.loads((spin / "ladder.json").read_text())
    rungs = {r["rung"]: r for r in ladder["rungs"]}
    floor = ladder["noise_floor"]["steady_mass_flow"]
    fast = rungs["fast"]
    assert abs(fast["error_steady_mass_flow"]) < min(floor, 0.01)
    assert abs(fast["error_h"]) < 1e-3 and abs(fast["error_temperature"]) < 1e-3
    assert fast["speedup"] > 1.3
    manifest = json.loads((spin / "fast" / "manifest.json").read_text())
    old = json.loads((spin / "default_step" / "manifest.json").read_text())
    assert manifest["case"]["contacts"]["tangential_damping"] is False
    assert manifest["case"]["run"]["conduction"] is False
    assert manifest["time_step"]["time_step"] == pytest.approx(old["time_step"]["time_step"], rel=1e-9)
    assert manifest["time_step"]["bound"] == "contact"
