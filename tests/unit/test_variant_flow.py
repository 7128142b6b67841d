"""studies/variant_flow.py on a hand-built settings study: known crossing times give known
flows per window and in all, the run itself is cut to the study's interval, and a run that
stopped before the interval's end is refused."""

from __future__ import annotations

import json
from pathlib import Path
from types import ModuleType

import numpy as np
import pytest
from support.scripts import load_script

from drumflow.case import case_to_toml, load_case

ROOT = Path(__file__).resolve().parents[2]
DT = 1e-3


def _script() -> ModuleType:
    return load_script("variant_flow")


def _crossings(path: Path, times: np.ndarray) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text("time,id,x,z\n" + "".join(f"{t:.9f},{i},0,0\n" for i, t in enumerate(times)))


def _study(tmp_path: Path) -> tuple[Path, Path, float]:
    run = tmp_path / "run"
    run.mkdir()
    case = load_case(ROOT / "cases" / "smoke.toml")
    (run / "case.toml").write_text(case_to_toml(case))
    study = tmp_path / "study"
    # From step 1000 (1.0 s) over 300 steps: 0.3 s, windows of 0.1 s.
    (study / "variants" / "baseline" / "dem").mkdir(parents=True)
    (study / "settings.json").write_text(json.dumps({"run_dir": str(run), "restart_step": 1000,
                                                     "steps": 300}))
    (study / "variants" / "baseline" / "dem" / "coupling.json").write_text(json.dumps({"time_step": DT}))
    _crossings(study / "variants" / "baseline" / "dem" / "coupling" / "crossings.csv",
               np.concatenate([np.full(10, 1.05), np.full(20, 1.15), np.full(30, 1.25)]))
    _crossings(study / "variants" / "half_step" / "dem" / "coupling" / "crossings.csv",
               np.concatenate([np.full(11, 1.05), np.full(20, 1.15), np.full(30, 1.25)]))
    # The run went on before and after the interval: only 1.0-1.3 s counts.
    _crossings(run / "dem" / "coupling" / "crossings.csv",
               np.concatenate([np.full(7, 0.95), np.full(10, 1.05), np.full(20, 1.15),
                               np.full(30, 1.25), np.full(5, 1.35)]))
    return study, run, case.dem_case().particles.mass


def test_known_crossings_give_known_flows(tmp_path: Path) -> None:
    study, run, mass = _study(tmp_path)
    table, summary = _script().flows(study, run, 0.1)
    base = table[table["source"] == "baseline"]
    assert list(base["crossings"]) == [10, 20, 30]
    assert list(base["falling_mass_flow_kg_s"]) == pytest.approx([100 * mass, 200 * mass, 300 * mass])
    sources = summary["sources"]
    assert sources["run"]["crossings"] == 60 and sources["run"]["relative_to_baseline"] == 0.0
    assert sources["half_step"]["relative_to_baseline"] == pytest.approx(1 / 60)
    assert summary["start_s"] == pytest.approx(1.0) and summary["end_s"] == pytest.approx(1.3)


def test_a_run_that_stopped_inside_the_interval_is_refused(tmp_path: Path) -> None:
    study, run, _ = _study(tmp_path)
    _crossings(run / "dem" / "coupling" / "crossings.csv", np.full(3, 1.05))
    with pytest.raises(ValueError, match="before"):
        _script().flows(study, run, 0.1)


@pytest.mark.parametrize("window", [0.0, -0.05, float("nan")])
def test_a_window_that_is_not_positive_is_refused_by_name(tmp_path: Path, window: float) -> None:
    study, run, _ = _study(tmp_path)
    with pytest.raises(ValueError, match=r"--window = .* s: must be positive"):
        _script().flows(study, run, window)
    # From the command line: one line on stderr, exit code 2, nothing written.
    out = tmp_path / "out"
    assert _script().main([str(study), str(out), "--window", str(window)]) == 2
    assert not out.exists()
