"""`drumflow bench` end to end on the tiny drum: a short ladder on the real solver.

No timing is asserted (speed lives in the results file); the test checks that every rung ran
or says why, that errors are measured against the reference, and that the overhead pair
(drumflow against the same deck by hand) was measured.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import pandas as pd
import pytest
from support.solvers import LIGGGHTS, requires_solver, tiny_case_dict

from drumflow.bench import run_bench
from drumflow.case import case_from_dict

pytestmark = [
    pytest.mark.solver,
    pytest.mark.timeout(600),
    requires_solver(*LIGGGHTS),
]


def test_short_ladder_on_the_tiny_drum(tmp_path: Path) -> None:
    case = case_from_dict(tiny_case_dict(air__model="uniform", air__mass_flow=0.1, run__time=0.4,
                                         run__mass_flow_start=0.2))
    result = run_bench(case, tmp_path / "bench", ["default", "dt_40pct", "no_air_by_hand"])
    table = pd.read_csv(result.csv)
    assert list(table["rung"]) == ["reference", "default", "dt_40pct", "no_air", "no_air_by_hand"]
    assert (table["status"] == "ok").all(), table[["rung", "status"]]
    ref = table.set_index("rung").loc["reference"]
    assert ref["err_temperature"] == 0.0 and ref["fraction_of_rayleigh"] == pytest.approx(0.05)
    default = table.set_index("rung").loc["default"]
    # The air cools the bed: the default's cooling is measured against the reference's.
    assert default["cooling_K"] > 0 and math.isfinite(default["err_temperature"])
    assert default["particle_steps_per_s"] > 0
    overhead = json.loads(result.json.read_text())["summary"]["overhead"]
    assert overhead["liggghts_loop_time_by_hand_s"] > 0
    assert result.plot.stat().st_size > 10_000
    # A second call reuses every finished rung (the bench resumes).
    again = run_bench(case, tmp_path / "bench", ["default"])
    assert pd.read_csv(again.csv).set_index("rung").loc["default", "dem_wall_time_s"] == pytest.approx(
        default["dem_wall_time_s"])
