"""The air coupling on the real LIGGGHTS library: `drumflow verify --quick` end to end."""

from __future__ import annotations

import json
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

pytestmark = [
    pytest.mark.solver,
    pytest.mark.skipif(shutil.which("liggghts") is None, reason="LIGGGHTS not installed (scripts/install.sh)"),
]


@pytest.mark.timeout(900)
def test_verify_quick_passes_and_writes_json(tmp_path: Path) -> None:
    out = tmp_path / "verify"
    proc = subprocess.run(
        [sys.executable, "-m", "drumflow.cli", "verify", "--quick", "--out", str(out)],
        capture_output=True, text=True, timeout=850,
    )
    assert proc.returncode == 0, proc.stderr[-3000:]
    checks = json.loads((out / "verification.json").read_text())
    names = {c["name"] for c in checks}
    assert {"lumped_cooling_one_time_constant", "terminal_velocity_schiller_naumann",
            "conduction_conserves_mean_temperature", "energy_balance_air_heat",
            "air_mass_flow_in_equals_out", "air_mean_axial_velocity",
            "couette_rotating_cylinders"} <= names
    for c in checks:
        assert set(c) >= {"name", "measured", "expected", "error", "tolerance", "passed"}
        assert c["passed"], c


@pytest.mark.timeout(600)
def test_smoke_drum_with_uniform_air_cools_and_closes_energy(tmp_path: Path) -> None:
    from drumflow.pipeline import run_case
    from drumflow.verify.scenes import tiny_drum

    case = tiny_drum(air__model="uniform", air__mass_flow=0.1, run__processes=2)
    summary = run_case(case, tmp_path / "run", timeout=500)
    # Cooling happened, through the air, on 2 MPI ranks (each rank logs its own particles).
    assert summary["mean_temperature_C"] < 90.0 - 0.1
    assert summary["energy_balance_error"] < 0.005
    ranks = list((tmp_path / "run" / "dem" / "coupling").glob("rank1.*.csv"))
    assert ranks, "rank 1 wrote no coupling log: the run did not use 2 ranks"
    assert summary["particles_final"] == 500


@pytest.mark.timeout(600)
def test_interrupted_coupled_run_resumes_with_its_heat_log(tmp_path: Path) -> None:
    from drumflow.errors import SolverTimeoutError
    from drumflow.pipeline import run_case
    from drumflow.verify.scenes import tiny_drum

    case = tiny_drum(air__model="uniform", air__mass_flow=0.1, run__time=2.0, run__restart_interval=0.1)
    out = tmp_path / "run"
    with pytest.raises(SolverTimeoutError):
        run_case(case, out, timeout=7)
    summary = run_case(case, out, timeout=300)
    dem = json.loads((out / "stages" / "dem.json").read_text())["result"]
    assert dem["resumed_from_step"]
    # Two attempts logged heat; stitched, the energy still closes.
    assert len(list((out / "dem" / "coupling").glob("rank0.*.csv"))) == 2
    assert summary["energy_balance_error"] < 0.005
    assert summary["particles_final"] == 500
