"""The SLURM executor's batch script and sbatch options, and how it settles a task that was
stopped before its time limit (tests/solver/test_sweep_slurm.py runs them on a real cluster)."""

from __future__ import annotations

import json
import subprocess
from pathlib import Path

import pytest
from support.requirements import requires_program

from drumflow.sweep.executor import Attempt
from drumflow.sweep.run_settings import Runs, SlurmSettings
from drumflow.sweep.slurm import SlurmExecutor


def _executor(root: Path, **settings: object) -> SlurmExecutor:
    return SlurmExecutor(root, SlurmSettings(**settings), Runs(processes=2), "demo", 3)  # type: ignore[arg-type]


@requires_program("bash")  # skipped without bash on a workstation, failed under CI
def test_the_batch_script_is_valid_bash_and_traps_the_time_limit_warning(tmp_path: Path) -> None:
    script = _executor(tmp_path).script()
    check = subprocess.run(["bash", "-n"], input=script, text=True, capture_output=True, check=False)
    assert check.returncode == 0, check.stderr
    assert "trap stop_member USR1" in script and " stop \"$member_dir\" --no-wait" in script
    # The run goes to the background so that the shell can take the signal while it runs.
    assert "--np 2 &" in script and 'wait "$run_pid"' in script


def test_the_warning_is_asked_for_unless_switched_off(tmp_path: Path) -> None:
    args = _executor(tmp_path, time_limit="02:00:00")._sbatch_args([0, 1, 2])
    assert "--time=02:00:00" in args and "--signal=B:USR1@300" in args
    args = _executor(tmp_path, stop_before_limit=900)._sbatch_args([0])
    assert "--signal=B:USR1@900" in args
    off = _executor(tmp_path, stop_before_limit=0)._sbatch_args([0])
    assert not any(a.startswith("--signal") for a in off)


@pytest.mark.parametrize(("exit_code", "state"), [(130, "interrupted"), (0, "completed"), (1, "failed")])
def test_a_task_that_stopped_after_its_restart_is_interrupted_not_failed(
        tmp_path: Path, exit_code: int, state: str) -> None:
    ex = _executor(tmp_path)
    attempt = Attempt(member="m001", executor="slurm", state="running", job_id="12_1")
    record = tmp_path / "members" / "m001" / "slurm-12_1.json"
    record.parent.mkdir(parents=True)
    record.write_text(json.dumps({"job_id": "12_1", "node": "n1", "started": 1, "ended": 2,
                                  "exit_code": exit_code}))
    ex._settle(attempt, None)  # SLURM has forgotten the task; its own record is what is left
    assert attempt.state == state and attempt.exit_code == str(exit_code)
    # SLURM's own view of an exit 130 is FAILED; the member's record outranks it.
    attempt = Attempt(member="m001", executor="slurm", state="running", job_id="12_1")
    ex._settle(attempt, {"state": "FAILED" if exit_code else "COMPLETED", "exit_code": f"{exit_code}:0"})
    assert attempt.state == state
