"""The local executor's pool: never more MPI ranks than cores, and resuming without rerunning.

The members here are a small Python program in place of `drumflow run` (the pool is under
test, not the solver; tests/solver/test_sweep_slurm.py runs real members): it records when it
ran, sleeps, and writes the summary a finished `drumflow run` writes (its case hash, status
ok), or fails when its run directory holds a file named ``fail``.
"""

from __future__ import annotations

import json
import sys
import textwrap
from pathlib import Path

import pytest
import tomli_w

from drumflow.sweep.driver import open_sweep, run_sweep, statuses
from drumflow.sweep.local import LocalExecutor
from drumflow.sweep.run_settings import LocalSettings
from drumflow.sweep.spec import Member, SweepError

ROOT = Path(__file__).resolve().parents[2]

_MEMBER = textwrap.dedent("""
    import json, sys, time
    from pathlib import Path
    run_dir, case_hash, ranks = Path(sys.argv[1]), sys.argv[2], int(sys.argv[3])
    start = time.time()
    time.sleep(0.6)
    with open(run_dir.parent.parent / "spans.jsonl", "a") as fh:
        fh.write(json.dumps({"member": run_dir.name, "start": start, "end": time.time(),
                             "ranks": ranks}) + "\\n")
    if (run_dir / "fail").exists():
        sys.exit(1)
    (run_dir / "summary.json").write_text(json.dumps({"case_hash": case_hash, "status": "ok"}))
""")


def _sweep(tmp_path: Path, rpms: list[float], processes: int = 1) -> Path:
    (tmp_path / "smoke.toml").write_bytes((ROOT / "cases" / "smoke.toml").read_bytes())
    path = tmp_path / "sweep.toml"
    path.write_text(tomli_w.dumps({
        "name": "pool", "base": "smoke.toml", "axes": {"drum.rpm": rpms},
        "runs": {"processes": processes}, "executor": {"local": {"poll_interval": 0.05}},
    }))
    (tmp_path / "member.py").write_text(_MEMBER)
    return path


def _executor(tmp_path: Path, sd, cores: int, max_parallel: int | str = "auto") -> LocalExecutor:  # type: ignore[no-untyped-def]
    program = tmp_path / "member.py"

    def command(member: Member, run_dir: Path) -> list[str]:
        return [sys.executable, str(program), str(run_dir), member.hash, str(sd.sweep.runs.processes)]

    settings = LocalSettings(max_parallel=max_parallel, poll_interval=0.05)  # type: ignore[arg-type]
    return LocalExecutor(sd.root, settings, sd.sweep.runs, cores=cores, command=command)


def _peak_ranks(spans_file: Path) -> int:
    spans = [json.loads(line) for line in spans_file.read_text().splitlines()]
    events = sorted([(s["start"], s["ranks"]) for s in spans] + [(s["end"], -s["ranks"]) for s in spans],
                    key=lambda e: (e[0], e[1]))  # an end before a start at the same instant
    peak = level = 0
    for _, change in events:
        level += change
        peak = max(peak, level)
    return peak


@pytest.mark.parametrize(("cores", "processes", "max_parallel", "slots"),
                         [(2, 1, "auto", 2), (2, 2, "auto", 1), (3, 1, 2, 2), (4, 2, 8, 2)])
def test_pool_never_runs_more_ranks_than_cores(tmp_path: Path, cores: int, processes: int,
                                               max_parallel: int | str, slots: int) -> None:
    sd = open_sweep(_sweep(tmp_path, [8.0, 9.0, 10.0, 11.0, 12.0], processes), tmp_path / "out")
    ex = _executor(tmp_path, sd, cores, max_parallel)
    assert ex.slots == slots
    seen = []
    outcome = run_sweep(sd, ex, on_status=lambda rows: seen.append(ex.busy))
    assert outcome.all_done
    peak = _peak_ranks(sd.root / "spans.jsonl")
    assert peak <= cores
    # The pool is used, not serialised: with 5 members of 0.6 s, `slots` run side by side.
    assert peak == slots * processes
    assert max(seen) <= slots


def test_member_needing_more_ranks_than_cores_is_refused_before_running(tmp_path: Path) -> None:
    sd = open_sweep(_sweep(tmp_path, [8.0, 9.0], processes=3), tmp_path / "out")
    with pytest.raises(SweepError, match=r"runs.processes = 3: .* cores \(2\)"):
        run_sweep(sd, _executor(tmp_path, sd, cores=2))
    assert not (sd.root / "spans.jsonl").exists()


def test_rerun_never_reruns_done_members_and_failed_ones_only_on_request(tmp_path: Path) -> None:
    path = _sweep(tmp_path, [8.0, 9.0, 10.0])
    sd = open_sweep(path, tmp_path / "out")
    (sd.root / "members" / "m001" / "fail").write_text("")
    outcome = run_sweep(sd, _executor(tmp_path, sd, cores=2))
    assert [s.state for s in outcome.statuses] == ["done", "failed", "done"]
    assert outcome.failed[0].attempt is not None and outcome.failed[0].attempt.exit_code == "1"

    # Rerun: nothing runs (the failed member waits for --requeue-failed).
    sd = open_sweep(path, tmp_path / "out")
    run_sweep(sd, _executor(tmp_path, sd, cores=2))
    assert len((sd.root / "spans.jsonl").read_text().splitlines()) == 3

    (sd.root / "members" / "m001" / "fail").unlink()
    sd = open_sweep(path, tmp_path / "out")
    outcome = run_sweep(sd, _executor(tmp_path, sd, cores=2), requeue_failed=True)
    assert outcome.all_done
    runs = [json.loads(line)["member"] for line in (sd.root / "spans.jsonl").read_text().splitlines()]
    assert sorted(runs) == ["m000", "m001", "m001", "m002"]
    attempts = json.loads((sd.root / "executor" / "attempts.json").read_text())
    assert [a["member"] for a in attempts] == ["m000", "m001", "m002", "m001"]
    assert all(a["node"] and a["job_id"].startswith("pid ") for a in attempts)


def test_edited_sweep_is_refused_in_the_old_directory(tmp_path: Path) -> None:
    sd = open_sweep(_sweep(tmp_path, [8.0, 9.0]), tmp_path / "out")
    # A run directory bound to member m000's case (what `drumflow run` writes first).
    (sd.root / "members" / "m000" / "manifest.json").write_text(
        json.dumps({"case_hash": sd.members[0].hash}))
    with pytest.raises(SweepError, match="member m000 .* holds a run of another case"):
        open_sweep(_sweep(tmp_path, [7.0, 9.0]), tmp_path / "out")


def test_status_of_untouched_members_is_pending(tmp_path: Path) -> None:
    sd = open_sweep(_sweep(tmp_path, [8.0, 9.0]), tmp_path / "out")
    assert [s.state for s in statuses(sd)] == ["pending", "pending"]
    assert (sd.root / "sweep.toml").is_file() and (sd.root / "base.toml").is_file()
    assert (sd.root / "members" / "m001" / "case.toml").is_file()


_CHECKPOINTING_MEMBER = textwrap.dedent("""
    import signal, sys, time
    from pathlib import Path
    run_dir = Path(sys.argv[1])
    run_dir.mkdir(parents=True, exist_ok=True)
    def note(signum, frame):
        with open(run_dir / "signals", "a") as fh:
            fh.write(signal.Signals(signum).name + "\\n")
        if signum == signal.SIGTERM:
            time.sleep(1.0)  # `drumflow run` writing its restart at the next air update
            (run_dir / "checkpoint").write_text("written")
            sys.exit(130)
    signal.signal(signal.SIGTERM, note)
    signal.signal(signal.SIGINT, note)
    (run_dir / "ready").write_text("")
    time.sleep(60)
""")


def test_an_interrupted_sweep_signals_each_member_once_and_waits_for_its_restart(
        tmp_path: Path) -> None:
    """Regression: the sweep sent a second SIGINT 10 s after the terminal's Ctrl-C, which cuts
    short the restart a run with air writes when interrupted. Members now run in their own
    sessions and get exactly one SIGTERM, and the sweep waits for them to end by themselves."""
    sd = open_sweep(_sweep(tmp_path, [8.0, 9.0]), tmp_path / "out")
    (tmp_path / "member.py").write_text(_CHECKPOINTING_MEMBER)
    members = [sd.root / "members" / m for m in ("m000", "m001")]

    def interrupt_once_running(rows: object) -> None:
        if all((m / "ready").exists() for m in members):
            raise KeyboardInterrupt

    outcome = run_sweep(sd, _executor(tmp_path, sd, cores=2), on_status=interrupt_once_running)
    assert outcome.interrupted
    for m in members:
        assert (m / "signals").read_text().split() == ["SIGTERM"]
        assert (m / "checkpoint").read_text() == "written"
    assert [s.state for s in outcome.statuses] == ["interrupted", "interrupted"]
