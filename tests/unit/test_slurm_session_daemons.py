"""The SLURM test session stops only the daemons it started (support/slurm.py), found by name
and pid file in a /proc of its own here; no daemon is started or signalled."""

from __future__ import annotations

from pathlib import Path

from support.slurm import running, to_stop


def _process(proc: Path, pid: int, comm: str, state: str = "S") -> None:
    (proc / str(pid)).mkdir(parents=True)
    (proc / str(pid) / "comm").write_text(comm + "\n")
    (proc / str(pid) / "stat").write_text(f"{pid} ({comm}) {state} 1 {pid} {pid} 0 -1\n")


def test_daemons_are_found_by_name_and_pid_file_and_zombies_do_not_count(tmp_path: Path) -> None:
    proc = tmp_path / "proc"
    _process(proc, 101, "slurmctld")
    _process(proc, 102, "slurmctld", state="Z")  # killed, not yet reaped
    _process(proc, 103, "slurmctld-wlm")  # another name; its pid file names it
    _process(proc, 104, "munged")
    (proc / "self").mkdir()
    pidfile = tmp_path / "slurmctld.pid"
    pidfile.write_text("103\n")
    assert running("slurmctld", proc=proc) == {101}
    assert running("slurmctld", pidfile, proc=proc) == {101, 103}
    pidfile.write_text("102\n")  # a zombie's pid file
    assert running("slurmctld", pidfile, proc=proc) == {101}
    assert running("slurmd", tmp_path / "no.pid", proc=proc) == set()


def test_only_daemons_that_were_not_running_before_are_stopped() -> None:
    before: dict[str, set[int]] = {"munged": {7}, "slurmctld": set(), "slurmd": set()}
    # munged ran before (a developer's); slurmctld and slurmd were started by the session.
    now = {"munged": {7}, "slurmctld": {20}, "slurmd": {21, 22}}
    assert to_stop(before, now) == [("slurmd", 21), ("slurmd", 22), ("slurmctld", 20)]
    # A daemon that ran before and was restarted (a changed slurm.conf) is still not ours.
    assert to_stop({**before, "slurmctld": {5}}, now) == [("slurmd", 21), ("slurmd", 22)]
    # Nothing running before, all three started: stopped slurmd first, munged last.
    empty: dict[str, set[int]] = {"munged": set(), "slurmctld": set(), "slurmd": set()}
    assert [n for n, _ in to_stop(empty, now)] == ["slurmd", "slurmd", "slurmctld", "munged"]
    assert to_stop(now, now) == []
