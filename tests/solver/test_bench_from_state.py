"""`drumflow bench` from a shipped start state (issue 35): a case whose run.start_state is the
smoke case's bed at 1 s (results/states/smoke_1.0s.npz) benches from that bed, not from an empty
drum, on any machine."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest
import tomli_w
from support.solvers import CASES, LIGGGHTS, ROOT, requires_solver

pytestmark = [pytest.mark.solver, requires_solver(*LIGGGHTS)]

STATE = ROOT / "results" / "states" / "smoke_1.0s.npz"


@pytest.mark.timeout(600)
def test_bench_rungs_start_from_the_shipped_state(tmp_path: Path) -> None:
    from drumflow.case import read_toml
    from drumflow.dem.state import read_state

    data = read_toml(CASES / "smoke.toml")
    data["air"]["model"] = "uniform"  # cheap; the scene is the smoke case's, whose bed it is
    data["run"]["processes"] = 1
    data["run"]["start_state"] = str(STATE)
    case = tmp_path / "smoke_from_state.toml"
    case.write_text(tomli_w.dumps(data))
    state = read_state(STATE)
    end = state.time_s + 0.04
    out = tmp_path / "bench"
    proc = subprocess.run([sys.executable, "-m", "drumflow.cli", "bench", str(case), "--rungs",
                           "default,dt_20pct", "--time", f"{end:.4f}", "--speed-only", "--out", str(out)],
                          capture_output=True, text=True, timeout=550, check=False)
    assert proc.returncode == 0, proc.stdout + proc.stderr
    rows = json.loads((out / "results.json").read_text())["rows"]
    assert [r["status"] for r in rows] == ["ok", "ok"]
    for rung in ("default", "dt_20pct"):
        manifest = json.loads((out / "rungs" / rung / "manifest.json").read_text())
        assert manifest["start_state"]["time_s"] == pytest.approx(state.time_s, abs=1e-3)
        summary = json.loads((out / "rungs" / rung / "summary.json").read_text())
        # From the state's time to the end asked for: 0.04 s simulated, not 1.04 s.
        assert summary["simulated_time_s"] == pytest.approx(end, abs=0.02)
        assert summary["particles_initial"] == len(state)
