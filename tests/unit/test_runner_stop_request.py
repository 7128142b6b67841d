"""The runner's clean stop on an interrupt (``Runner.run(stop_request=...)``), with real child
processes: a program that watches for the request and ends by itself (as the coupling loop does
after writing its restart), and one that never looks (killed after the grace)."""

from __future__ import annotations

import _thread
import signal
import sys
import threading
from collections.abc import Iterator
from pathlib import Path

import pytest

from drumflow.runner import Runner

#: A stand-in for the coupling loop's side of the protocol: it says it is ready (a marker file:
#: the runner's log is not flushed line by line), polls for the request as the loop does at every
#: air update, then "writes its restart" and exits 0.
_WATCHER = """
import pathlib, sys, time
request, done = pathlib.Path(sys.argv[1]), pathlib.Path(sys.argv[2])
pathlib.Path(sys.argv[3]).write_text("ready")
deadline = time.time() + 60  # never hang a test run
while not request.exists() and time.time() < deadline:
    time.sleep(0.05)
if request.exists():
    done.write_text("restart written")
"""

_DEAF = """
import pathlib, sys, time
pathlib.Path(sys.argv[1]).write_text("ready")
time.sleep(60)
"""


@pytest.fixture(autouse=True)
def _ctrl_c_raises() -> Iterator[None]:
    """Ctrl-C raises KeyboardInterrupt in these tests, whatever the test process inherited: a
    background job (`cmd &` from a script, as CI may be) starts with SIGINT ignored, and then
    `_thread.interrupt_main` does nothing and the runner would wait for ever."""
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, previous)


def _interrupt_when_ready(ready: Path) -> threading.Thread:
    """Ctrl-C in the main thread once the child has written its ``ready`` marker (at most 20 s).

    Regression: this used to look for 'ready' in the runner's log, whose header repeats the
    command and so the stand-in's source; the interrupt could then come before the program had
    started, and no stop was requested (CI of stop 24 failed that way)."""

    def fire() -> None:
        for _ in range(400):
            if ready.exists():
                break
            threading.Event().wait(0.05)
        _thread.interrupt_main()

    thread = threading.Thread(target=fire, daemon=True)
    thread.start()
    return thread


def test_an_interrupt_asks_the_program_to_stop_and_waits_for_it(tmp_path: Path) -> None:
    request, done, log = tmp_path / "stop.request", tmp_path / "restart", tmp_path / "out.log"
    runner = Runner()
    _interrupt_when_ready(tmp_path / "ready")
    with pytest.raises(KeyboardInterrupt):
        runner.run("watcher", [sys.executable, "-c", _WATCHER, str(request), str(done),
                               str(tmp_path / "ready")], tmp_path,
                   log, stop_request=request, stop_grace=30.0)
    # The request was written on the interrupt and the program ended by itself after doing its
    # part: the interrupt is still raised, the record says so.
    assert done.read_text() == "restart written"
    assert "stop requested" in request.read_text()
    assert runner.records[-1].status == "interrupted"


def test_a_request_made_before_the_start_is_left_for_the_program(tmp_path: Path) -> None:
    """`drumflow stop` while the geometry or air stage ran: the request is already there when
    the loop starts, and the loop stops at once by itself (the caller removes stale requests)."""
    request, done = tmp_path / "stop.request", tmp_path / "restart"
    request.write_text("stop requested while the air stage ran")
    record = Runner().run("watcher", [sys.executable, "-c", _WATCHER, str(request), str(done),
                                      str(tmp_path / "ready")], tmp_path, tmp_path / "out.log",
                          stop_request=request)
    assert record.status == "ok" and done.read_text() == "restart written"


def test_without_a_request_file_the_program_is_killed_at_once(tmp_path: Path) -> None:
    request, done, log = tmp_path / "stop.request", tmp_path / "restart", tmp_path / "out.log"
    runner = Runner()
    _interrupt_when_ready(tmp_path / "ready")
    with pytest.raises(KeyboardInterrupt):
        runner.run("watcher", [sys.executable, "-c", _WATCHER, str(request), str(done),
                               str(tmp_path / "ready")], tmp_path, log)
    assert not request.exists() and not done.exists()


def test_a_program_that_does_not_stop_is_killed_after_the_grace(tmp_path: Path) -> None:
    request, log = tmp_path / "stop.request", tmp_path / "out.log"
    runner = Runner()
    _interrupt_when_ready(tmp_path / "ready")
    with pytest.raises(KeyboardInterrupt):
        runner.run("deaf", [sys.executable, "-c", _DEAF, str(tmp_path / "ready")], tmp_path, log,
                   stop_request=request,
                   stop_grace=0.5)
    record = runner.records[-1]
    assert request.exists() and record.status == "interrupted"
    # Killed after the 0.5 s grace plus the group's SIGTERM, not after the program's 60 s.
    assert record.wall_time_s < 30.0


def test_an_interrupt_while_the_output_threads_start_kills_the_program(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """Regression: Ctrl-C between the program's start and the runner's try left it running (the
    full unit suite on a loaded machine once found the exit-code test's launcher alive after
    `drumflow run` had exited 130)."""
    import os

    from drumflow import runner as runner_module

    pid_file = tmp_path / "pid"

    def interrupted(proc: object, *args: object) -> None:
        for _ in range(200):  # the child has started and written its pid
            if pid_file.exists() and pid_file.read_text().strip():
                break
            threading.Event().wait(0.05)
        raise KeyboardInterrupt

    monkeypatch.setattr(runner_module, "_Watch", interrupted)
    runner = Runner()
    program = f"import os, time; open({str(pid_file)!r}, 'w').write(str(os.getpid())); time.sleep(60)"
    with pytest.raises(KeyboardInterrupt):
        runner.run("sleeper", [sys.executable, "-c", program], tmp_path, tmp_path / "out.log")
    pid = int(pid_file.read_text())
    with pytest.raises(ProcessLookupError):
        os.kill(pid, 0)
    assert runner.records[-1].status == "interrupted"
