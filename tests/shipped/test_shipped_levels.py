"""The physics levels' shipped results against the prediction written before them
(``results/paper/levels/prediction.json``). Reads shipped files only; tests no code."""

from __future__ import annotations

import json
from pathlib import Path

import pandas as pd
import pytest

pytestmark = pytest.mark.shipped

LEVELS = Path(__file__).resolve().parents[2] / "results" / "paper" / "levels"


def test_the_prediction_was_written_before_the_runs() -> None:
    """The pre-registered prediction names what it predicts; the shells runs' T(3.5 s) of model
    two lands within 0.05 K of it (the level is the Biot number's doing, as predicted)."""
    prediction = json.loads((LEVELS / "prediction.json").read_text())
    assert "before any run" in prediction["written"]
    rows = pd.read_csv(LEVELS / "levels_model_two_cg2.csv").set_index("level")
    predicted = prediction["this_prediction"]["model_two"]["T_3.5s_C"]
    assert abs(float(rows.loc["shells", "mean_temperature_3.5s_C"]) - predicted) < 0.05
    low, high = prediction["this_prediction"]["model_two"]["h_eq39_W_m2K_range"]
    assert low <= float(rows.loc["shells", "h_eq39_W_m2K"]) <= high
