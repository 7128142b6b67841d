"""The physics-level table in ``results/paper/levels/`` is what the study's measurement gives on
the runs it ships (``studies/interior_levels.py``): the numbers cannot drift from their files."""

from __future__ import annotations

import importlib.util
import json
from pathlib import Path

import pandas as pd
import pytest

ROOT = Path(__file__).resolve().parents[2]
LEVELS = ROOT / "results" / "paper" / "levels"


def _study():  # type: ignore[no-untyped-def]
    spec = importlib.util.spec_from_file_location("interior_levels", ROOT / "studies" / "interior_levels.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


@pytest.mark.parametrize("table", sorted(LEVELS.glob("levels_model_*.csv")), ids=lambda p: p.stem)
def test_shipped_level_table_is_measured_from_its_shipped_runs(table: Path) -> None:
    study = _study()
    rows = pd.read_csv(table)
    for _, row in rows.iterrows():
        until = json.loads(row["window_s"])[1]
        again = study.measure(ROOT / row["run"], 3.5, until)
        for key in ("mean_temperature_3.5s_C", "h_eq39_W_m2K", "h_coupling_log_W_m2K",
                    "centre_minus_surface_3.5s_K", "interior_share_of_loop_wall",
                    "volumetric_coefficient_W_m3K", "volumetric_coefficient_lmtd_W_m3K",
                    "air_outlet_if_warmed_C", "dem_wall_time_s"):
            assert again[key] == pytest.approx(float(row[key]), rel=1e-5, abs=1e-9), key



def test_the_dem_wall_time_counts_every_attempt_of_a_resumed_run() -> None:
    """Regression: model one's shells run was resumed at step 31,605 (3.65 s) and the table took
    its summary's last call, 604 s, for a run whose updates took 3,995 s in all."""
    run = LEVELS / "runs" / "paper_model_one_shells_cg2"
    assert len(list((run / "dem" / "coupling").glob("rank0.*.csv"))) == 2  # two attempts
    summary = json.loads((run / "summary.json").read_text())
    wall = _study().dem_wall_s(run, summary)
    logs = [pd.read_csv(p) for p in (run / "dem" / "coupling").glob("rank*.csv") if "interior" not in p.name]
    by_rank = pd.concat(logs).groupby("step")[["python_wall_s", "liggghts_wall_s"]].max().sum().sum()
    assert wall == pytest.approx(by_rank, rel=1e-9)
    assert wall > 6 * summary["dem_wall_time_s"]
