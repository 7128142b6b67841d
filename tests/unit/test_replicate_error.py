"""studies/replicate_error.py on model one's first full-particle run (to 3.515 s, shipped in
results/paper/model_one_replicate/first_run): a copy of it is its own replicate (every
difference 0), a copy with its temperatures shifted shows the shift, and a run of another case
is refused."""

from __future__ import annotations

import json
import shutil
from pathlib import Path
from types import ModuleType

import pandas as pd
import pytest
from support.scripts import load_script

ROOT = Path(__file__).resolve().parents[2]
SHIPPED = ROOT / "results" / "paper" / "model_one_replicate" / "first_run"
PARCELS = ROOT / "results" / "paper_parcels" / "model_one"


def _script() -> ModuleType:
    return load_script("replicate_error")


def test_a_run_against_itself_and_against_a_shifted_copy(tmp_path: Path) -> None:
    script = _script()
    table, summary = script.compare(SHIPPED, SHIPPED, until=2.0, window=0.5)
    assert summary["max_abs_temperature_difference_K"] == 0.0
    assert summary["last_common_time_s"] == pytest.approx(2.0, abs=0.006)
    assert list(table["window_end_s"]) == pytest.approx([0.5, 1.0, 1.5, 2.0], abs=0.006)
    assert (table["falling_mass_flow_first_kg_s"] == table["falling_mass_flow_second_kg_s"]).all()
    # The shipped run's first crossings were at 1.5 s: nothing falls before.
    assert table["falling_mass_flow_first_kg_s"].iloc[:3].sum() == 0.0
    assert table["falling_mass_flow_first_kg_s"].iloc[3] > 0.0

    shifted = tmp_path / "shifted"
    shutil.copytree(SHIPPED, shifted)
    series = pd.read_csv(shifted / "post" / "mean_temperature.csv")
    series["mean_temperature_C"] -= 0.25 * series["time_s"]  # cools 0.25 K/s faster
    series.to_csv(shifted / "post" / "mean_temperature.csv", index=False)
    out = tmp_path / "out"
    assert script.main([str(SHIPPED), str(shifted), str(out), "--until", "2.0"]) == 0
    summary = json.loads((out / "replicate.json").read_text())
    end = summary["last_common_time_s"]
    assert summary["temperature_difference_at_end_K"] == pytest.approx(-0.25 * end)
    assert summary["cooling_second_K"] - summary["cooling_first_K"] == pytest.approx(0.25 * end)
    assert len(pd.read_csv(out / "replicate.csv")) == 4


def test_runs_of_different_cases_are_refused(tmp_path: Path) -> None:
    # The parcel run differs in particles.coarse_grain: not a replicate.
    assert _script().main([str(SHIPPED), str(PARCELS), str(tmp_path / "out")]) == 2
    assert not (tmp_path / "out").exists()


def test_progress_of_one_run_over_all_it_reached(tmp_path: Path) -> None:
    script = _script()
    ahead = script.progress(SHIPPED, 0.5)
    series = pd.read_csv(SHIPPED / "post" / "mean_temperature.csv")
    crossings = pd.read_csv(SHIPPED / "post" / "crossings.csv")
    # Windows to the run's last output (3.515 s), the last one short.
    assert ahead["window_end_s"].iloc[-1] == pytest.approx(series["time_s"].iloc[-1])
    assert len(ahead) == 8
    # Every crossing counted once, and the flow is the count's mass per window length.
    assert ahead["crossings"].sum() == (crossings["time"] < series["time_s"].iloc[-1]).sum()
    mass = ahead["falling_mass_flow_kg_s"] * (ahead["window_end_s"] - ahead["window_start_s"])
    per_crossing = mass[ahead["crossings"] > 0] / ahead["crossings"][ahead["crossings"] > 0]
    assert per_crossing.max() == pytest.approx(per_crossing.min())
    assert ahead["temperature_C"].iloc[-1] == pytest.approx(series["mean_temperature_C"].iloc[-1])
    out = tmp_path / "out"
    assert script.main([str(SHIPPED), str(SHIPPED), str(out), "--until", "2.0", "--progress"]) == 0
    assert len(pd.read_csv(out / "progress.csv")) == 8 and len(pd.read_csv(out / "replicate.csv")) == 4


@pytest.mark.parametrize("window", ["0", "-0.5", "nan"])
def test_a_window_that_is_not_positive_is_refused_by_name(tmp_path: Path, window: str) -> None:
    script = _script()
    with pytest.raises(ValueError, match=r"--window = .* s: must be positive"):
        script.progress(SHIPPED, float(window))
    out = tmp_path / "out"
    assert script.main([str(SHIPPED), str(SHIPPED), str(out), "--window", window]) == 2
    assert not out.exists()


def test_two_settings_compare_only_in_the_fields_named(tmp_path: Path) -> None:
    """--differ names the fields two runs may differ in (the spin study: the time step)."""
    spin = ROOT / "results" / "bench" / "paper_model_two_spin"
    half, default = spin / "half_step", spin / "default_step"
    script = _script()
    with pytest.raises(ValueError, match=r"differ in name, run\.time_step"):
        script.compare(half, default, 2.0, 1.0)
    with pytest.raises(ValueError, match=r"differ in run\.time_step"):
        script.compare(half, default, 2.0, 1.0, ("name",))
    table, summary = script.compare(half, default, 2.0, 1.0, ("name", "run.time_step"))
    assert summary["differ_in"] == ["name", "run.time_step"] and len(table) == 2
