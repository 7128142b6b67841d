"""The subprocess runner, on real programs (sh), not mocks."""

from __future__ import annotations

import time
from pathlib import Path

import pytest

from drumflow.errors import SolverError, SolverNotFoundError, SolverTimeoutError
from drumflow.runner import LaunchProfile, Runner, last_error_line


def test_log_and_lines(tmp_path: Path) -> None:
    seen: list[str] = []
    r = Runner()
    rec = r.run("sh", ["sh", "-c", "echo one; echo two"], tmp_path, tmp_path / "log.txt", on_line=seen.append)
    assert rec.returncode == 0 and rec.status == "ok"
    assert [s.strip() for s in seen] == ["one", "two"]
    assert "two" in (tmp_path / "log.txt").read_text()
    assert r.records == [rec]


def test_failure_carries_code_command_and_error_line(tmp_path: Path) -> None:
    with pytest.raises(SolverError) as info:
        Runner().run("sh", ["sh", "-c", "echo 'ERROR: Lost atoms: original 10 current 9'; echo bye; exit 3"],
                     tmp_path, tmp_path / "log.txt")
    err = info.value
    assert err.returncode == 3
    assert err.command[0] == "sh"
    assert err.last_error == "ERROR: Lost atoms: original 10 current 9"
    assert isinstance(err, RuntimeError)


def test_timeout_kills_the_process_group(tmp_path: Path) -> None:
    marker = tmp_path / "child_alive"
    # The child outlives its parent shell unless the whole group is killed.
    script = f"(sleep 3; touch {marker}) & sleep 30"
    t0 = time.time()
    with pytest.raises(SolverTimeoutError):
        Runner().run("sh", ["sh", "-c", script], tmp_path, tmp_path / "log.txt", timeout=1)
    assert time.time() - t0 < 10
    time.sleep(3.5)
    assert not marker.exists(), "a child of the timed-out program survived"


def test_missing_program(tmp_path: Path) -> None:
    with pytest.raises(SolverNotFoundError, match="not found"):
        Runner().run("x", ["no-such-program-drumflow"], tmp_path, tmp_path / "log.txt")


def test_check_hook_turns_exit_zero_into_failure(tmp_path: Path) -> None:
    with pytest.raises(SolverError, match="no result"):
        Runner().run("sh", ["sh", "-c", "true"], tmp_path, tmp_path / "log.txt",
                     check=lambda code, lines: "no result")


def test_profile_mpi_command_and_root_env() -> None:
    p = LaunchProfile(mpirun="mpirun")
    assert p.mpi_command(["liggghts", "-in", "x"], 2) == ["mpirun", "-np", "2", "liggghts", "-in", "x"]
    assert p.env["OMP_NUM_THREADS"] == "1"


def test_last_error_line() -> None:
    lines = ["ok", "ERROR: a", "fine", "assertion failed (x.h:1)"]
    assert last_error_line(lines) == "assertion failed (x.h:1)"
    assert last_error_line(["ok"]) is None


def test_follow_reads_the_programs_own_log_while_it_runs(tmp_path: Path) -> None:
    """Progress comes from a file the program flushes (LIGGGHTS' log), not its buffered stdout."""
    seen: list[tuple[float, str]] = []
    t0 = time.time()
    script = (
        "for i in 1 2 3; do echo step $i >> own.log; sleep 0.6; done; echo stdout-only"
    )
    Runner().run("sh", ["sh", "-c", script], tmp_path, tmp_path / "out.txt",
                 on_line=lambda line: seen.append((time.time() - t0, line.strip())),
                 follow=tmp_path / "own.log")
    assert [line for _, line in seen] == ["step 1", "step 2", "step 3"]
    # The first line arrived while the program was still running (it runs ~1.8 s).
    assert seen[0][0] < 1.2
    assert "stdout-only" in (tmp_path / "out.txt").read_text()


def test_monitor_stop_kills_the_program_and_raises_its_error(tmp_path: Path) -> None:
    """An on_line callback raising StopRun ends a 10 s program within seconds, with its error."""
    from drumflow.runner import StopRun

    def monitor(line: str) -> None:
        if line.strip() == "row 3":
            raise StopRun(ArithmeticError("diverged at row 3"))

    runner = Runner()
    t0 = time.time()
    with pytest.raises(ArithmeticError, match="row 3"):
        runner.run("sh", ["sh", "-c", "for i in $(seq 1 100); do echo row $i; sleep 0.1; done"],
                   tmp_path, tmp_path / "log.txt", on_line=monitor)
    assert time.time() - t0 < 6
    assert runner.records[-1].status == "stopped"


def test_other_callback_errors_never_stop_the_program(tmp_path: Path) -> None:
    def broken(line: str) -> None:
        raise ValueError("a progress bar bug")

    rec = Runner().run("sh", ["sh", "-c", "echo a; echo b"], tmp_path, tmp_path / "log.txt", on_line=broken)
    assert rec.status == "ok"
