"""The shipped paper runs stay readable, two independent runs of model one agree, and model
one's shipped time-to-answer ladder is what its spec replays today.

`results/paper/model_one` is the full-particle run (467,443 particles), `results/paper_parcels/
model_one` the same case in parcels of 2 diameters (58,430 bodies, another trajectory). With
one-way air every particle sees the air, so their mean temperatures at 3.5 s must agree to well
within the 0.01 K the parcels kept on model two (0.006 K); the full run's own energy balance
must close to 1e-6 (docs/paper.md, issue 10).
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from drumflow.bench.time_to_answer import answer_ladder, load_ladder_spec
from drumflow.report.paper_results import collect_paper_run

RESULTS = Path(__file__).resolve().parents[2] / "results"


def test_shipped_model_one_agrees_with_its_parcel_run() -> None:
    full = collect_paper_run(RESULTS / "paper" / "model_one", "one", render_3d=False)
    parcels = collect_paper_run(RESULTS / "paper_parcels" / "model_one", "one", render_3d=False)
    assert full.temperature_at_s is not None and parcels.temperature_at_s is not None
    assert full.temperature_at_s == pytest.approx(parcels.temperature_at_s, abs=0.01)
    summary = json.loads((RESULTS / "paper" / "model_one" / "summary.json").read_text())
    assert summary["particles_final"] == summary["particles_initial"] == 467_443
    assert summary["energy_balance_error"] < 1e-6


def test_shipped_model_one_ladder_is_what_its_spec_replays_over_one_window() -> None:
    """The model-one ladder in docs/benchmarks.md is the replay of its spec today, and every rung answers
    over the full-particle run's window (the parcel run to 17.5 s cut at its end): a rung over a
    longer window than the reference would be scored against another answer."""
    folder = RESULTS / "bench" / "paper_model_one_ladder_12s"
    ladder = answer_ladder(load_ladder_spec(folder / "ladder.toml"))
    table = ladder.table.set_index("rung")
    # ladder.json keeps every digit (ladder.csv rounds to 6).
    shipped = pd.DataFrame(json.loads((folder / "ladder.json").read_text())["rungs"]).set_index("rung")
    assert list(table.index) == list(shipped.index)
    end = float(table.loc["reference", "run_end_s"])
    assert end == pytest.approx(12.1165, abs=1e-3)
    assert np.allclose(table["run_end_s"].to_numpy(float), end, atol=1e-3)
    for column in ("stop_time_s", "wall_s", "max_error", "error_steady_mass_flow", "error_h"):
        assert np.allclose(table[column].to_numpy(float), shipped[column].to_numpy(float),
                           rtol=1e-12, atol=1e-12, equal_nan=True), column
    assert list(table["within_tolerance"]) == list(shipped["within_tolerance"])
