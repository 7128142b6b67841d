"""A sweep of tiny drums on a real one-node SLURM cluster, against the local executor.

The cluster is this machine (scripts/slurm_localhost.sh: munged, slurmctld, slurmd), started for
the session and the daemons it started stopped at its end (support/slurm.py). Four
members run as one job array; one member's array task is cancelled mid-run (scancel, after
it wrote a restart file); the sweep reports it failed with its log tail; ``--requeue-failed``
resubmits only that member, which resumes from its restart. Every member must end done with
the same results as the same sweep run by the local executor.
"""

from __future__ import annotations

import json
import subprocess
import sys
import time
from collections.abc import Iterator
from pathlib import Path

import pytest
import tomli_w
from support.requirements import missing
from support.slurm import localhost_cluster
from support.solvers import LIGGGHTS, requires_solver

from drumflow.sweep.driver import simulated_time

pytestmark = [pytest.mark.solver, requires_solver(*LIGGGHTS)]


@pytest.fixture(scope="session")
def slurm_cluster() -> Iterator[None]:
    """The localhost SLURM cluster, for the session: started (or found) before the first test;
    the daemons it started stopped after the last (support/slurm.py). Where SLURM cannot run:
    skipped on a workstation, failed under CI (support/requirements.py)."""
    with localhost_cluster() as problem:
        if problem is not None:
            missing(*problem)
        yield


def _sweep_file(tmp_path: Path, kind: str) -> Path:
    from drumflow.verify.scenes import tiny_drum_dict

    # 500 particles, 0.6 s simulated with plug-flow air: each member takes under a minute, and
    # writes a restart file every 0.1 s so a killed one has something to resume from. 30 and
    # 36 rpm: at 25 rpm this drum lifts no particle over the axis plane before 0.5 s, and then
    # has no falling mass (no h) to analyse.
    base = tiny_drum_dict(air__model="uniform", air__mass_flow=0.1, run__time=0.6,
                          run__mass_flow_start=0.2, run__restart_interval=0.1)
    (tmp_path / "tiny.toml").write_text(tomli_w.dumps(base))
    path = tmp_path / f"sweep_{kind}.toml"
    path.write_text(tomli_w.dumps({
        "name": "tiny_slurm",
        "base": "tiny.toml",
        "axes": {"drum.rpm": [30.0, 36.0], "air.mass_flow": [0.08, 0.12]},
        "runs": {"processes": 1, "timeout": 600},
        "executor": {"kind": kind, "local": {"poll_interval": 0.5},
                     "slurm": {"max_parallel": 2, "poll_interval": 1.0}},
    }))
    return path


def _sweep(*args: str, timeout: float = 900) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-m", "drumflow.cli", "sweep", *args],
                          capture_output=True, text=True, timeout=timeout)


def _results(root: Path) -> dict[str, dict]:
    out = {}
    for d in sorted((root / "members").iterdir()):
        s = json.loads((d / "summary.json").read_text())
        out[d.name] = s
    return out


@pytest.mark.timeout(1500)
def test_slurm_sweep_survives_a_killed_member_and_matches_local(tmp_path: Path, slurm_cluster: None) -> None:
    slurm_dir = tmp_path / "slurm_run"
    sweep_file = _sweep_file(tmp_path, "slurm")
    proc = subprocess.Popen(
        [sys.executable, "-m", "drumflow.cli", "sweep", str(sweep_file), "--out", str(slurm_dir)],
        stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
    )
    # Wait until member m001 runs under SLURM and has written a restart file, then cancel
    # its array task.
    victim = slurm_dir / "members" / "m001"
    job = None
    deadline = time.time() + 600
    while time.time() < deadline and proc.poll() is None:
        restarts = list((victim / "dem" / "restart").glob("drum.*.restart")) if victim.exists() else []
        t = simulated_time(victim) if victim.exists() else None
        if restarts and t is not None and t < 0.5:
            attempts = json.loads((slurm_dir / "executor" / "attempts.json").read_text())
            job = next(a["job_id"] for a in attempts if a["member"] == "m001")
            subprocess.run(["scancel", job], check=True)
            break
        time.sleep(0.3)
    assert job is not None, "member m001 never ran long enough under SLURM to be killed"
    stdout, stderr = proc.communicate(timeout=900)
    # The sweep finishes the others and reports the cancelled member, with its log tail.
    assert proc.returncode == 1, stderr[-3000:]
    assert "m001" in stderr and "CANCELLED" in stderr, stderr[-3000:]
    assert "--requeue-failed" in stderr

    second = _sweep(str(slurm_dir), "--requeue-failed", "--json")
    assert second.returncode == 0, second.stderr[-3000:]
    states = {r["member"]: r["state"] for r in json.loads(second.stdout)}
    assert states == {"m000": "done", "m001": "done", "m002": "done", "m003": "done"}

    # The killed member resumed from its restart file; the others ran once.
    dem = json.loads((victim / "stages" / "dem.json").read_text())["result"]
    assert dem["resumed_from_step"], "m001 did not resume from a restart file"
    attempts = json.loads((slurm_dir / "executor" / "attempts.json").read_text())
    per_member = {m: [a for a in attempts if a["member"] == m] for m in states}
    assert len(per_member["m001"]) == 2 and per_member["m001"][0]["state"] == "failed"
    assert all(len(per_member[m]) == 1 for m in ("m000", "m002", "m003"))
    assert all(a["node"] and "_" in a["job_id"] for a in attempts)  # array task ids, nodes
    assert (slurm_dir / "slurm" / "submissions.json").is_file()

    # A third run changes nothing: done members are never rerun.
    third = _sweep(str(slurm_dir))
    assert third.returncode == 0, third.stderr[-2000:]
    assert len(json.loads((slurm_dir / "executor" / "attempts.json").read_text())) == len(attempts)

    # The same sweep on the local executor gives the same results.
    local_dir = tmp_path / "local_run"
    local = _sweep(str(_sweep_file(tmp_path, "local")), "--out", str(local_dir))
    assert local.returncode == 0, local.stderr[-3000:]
    slurm_results, local_results = _results(slurm_dir), _results(local_dir)
    for member, ours in slurm_results.items():
        theirs = local_results[member]
        assert ours["case_hash"] == theirs["case_hash"]
        if member == "m001":
            # Resumed from a restart: LIGGGHTS rebuilds its neighbour lists at the restart
            # step, which changes the order of force summation, so the trajectory is equal
            # only to round-off amplified by the chaotic granular flow. The mean temperature
            # is an average over 500 particles cooled by the same air: 0.05 K of a 60 K
            # particle-air difference (< 0.1 %) is far above round-off growth over 0.5 s and far
            # below any physical effect of the sweep's axes (0.08 vs 0.12 kg/s air).
            assert abs(ours["mean_temperature_C"] - theirs["mean_temperature_C"]) < 0.05
            assert ours["particles_final"] == theirs["particles_final"] == 500
        else:
            # Same case, same seed, same single rank: the runs are identical.
            for key in ("mean_temperature_C", "falling_mass_flow_kg_s", "particles_final",
                        "heat_removed_by_air_J"):
                assert ours[key] == theirs[key], (member, key)

    # The analysis runs over the SLURM directory and writes its page and fit.
    analysed = _sweep(str(slurm_dir), "--analyse")
    assert analysed.returncode == 0, analysed.stderr[-3000:]
    page = (slurm_dir / "analysis" / "report.html").read_text()
    assert "data:image/png;base64," in page and "Member fit" in page
    fit = json.loads((slurm_dir / "analysis" / "fit.json").read_text())
    assert [m["analysed"] for m in fit["members"]] == [True] * 4


@pytest.mark.timeout(1200)
def test_a_member_warned_of_its_time_limit_stops_at_a_restart_and_resumes(
        tmp_path: Path, slurm_cluster: None) -> None:
    """SLURM's warning before a time limit (``--signal=B:USR1@300``, here sent at once with
    ``scancel --batch --signal=USR1``, which reaches the batch shell only, as B: does): the
    member is asked to stop, writes a restart at its next air update, exits 130 and is
    'interrupted', not failed; the next `drumflow sweep` resumes it from that restart."""
    from drumflow.dem.stage import restart_files
    from drumflow.verify.scenes import tiny_drum_dict

    # No periodic restart before the end (interval 1 s): the one restart left is the loop's.
    base = tiny_drum_dict(air__model="uniform", air__mass_flow=0.1, run__time=1.0,
                          run__mass_flow_start=0.2, run__restart_interval=1.0)
    (tmp_path / "tiny.toml").write_text(tomli_w.dumps(base))
    sweep_file = tmp_path / "sweep_limit.toml"
    sweep_file.write_text(tomli_w.dumps({
        "name": "tiny_limit", "base": "tiny.toml", "axes": {"drum.rpm": [30.0]},
        "runs": {"processes": 1, "timeout": 900},
        "executor": {"kind": "slurm", "slurm": {"time_limit": "00:30:00", "poll_interval": 1.0}},
    }))
    out = tmp_path / "limit_run"
    proc = subprocess.Popen(
        [sys.executable, "-m", "drumflow.cli", "sweep", str(sweep_file), "--out", str(out)],
        stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
    )
    job, warned_at = None, None
    deadline = time.time() + 600
    while time.time() < deadline and proc.poll() is None:
        members = sorted((out / "members").glob("m*")) if (out / "members").exists() else []
        t = simulated_time(members[0]) if members else None
        if t is not None and t >= 0.3:
            attempts = json.loads((out / "executor" / "attempts.json").read_text())
            job, warned_at = attempts[-1]["job_id"], t
            subprocess.run(["scancel", "--batch", "--signal=USR1", job], check=True)
            break
        time.sleep(0.3)
    assert job is not None, "the member never ran long enough under SLURM to be warned"
    _, stderr = proc.communicate(timeout=600)
    member = sorted((out / "members").glob("m*"))[0]
    attempts = json.loads((out / "executor" / "attempts.json").read_text())
    assert [(a["state"], a["exit_code"]) for a in attempts] == [("interrupted", "130")], stderr[-3000:]
    # The batch script asked for the warning, and the loop wrote its restart after it.
    sub = json.loads((out / "slurm" / "submissions.json").read_text())
    assert "--signal=B:USR1@300" in json.dumps(sub)
    stopped = json.loads((member / "dem" / "stopped.json").read_text())
    assert [s for s, _ in restart_files(member / "dem" / "restart")] == [stopped["step"]]
    assert warned_at <= stopped["time_s"] < 1.0
    log = next((out / "slurm" / "logs").glob("*.out")).read_text()
    assert "time limit near" in log

    second = _sweep(str(out), "--json")
    assert second.returncode == 0, second.stderr[-3000:]
    assert [r["state"] for r in json.loads(second.stdout)] == ["done"]
    dem = json.loads((member / "stages" / "dem.json").read_text())["result"]
    assert dem["resumed_from_step"] == stopped["step"]
    summary = json.loads((member / "summary.json").read_text())
    assert summary["particles_final"] == 500 and summary["energy_balance_error"] < 1e-6
