"""The local executor: a bounded pool of ``drumflow run`` processes on this machine.

At most ``cores // runs.processes`` members run at once (and at most
``executor.local.max_parallel``), so members x MPI ranks never exceed the cores: two members
of 2 ranks each on 2 cores would only slow each other down. Each member is its own
``drumflow run`` process (isolation: one member's crash or lost particles cannot take the
others down), writing into its run directory; what it prints goes to
``DIR/logs/<member>.<attempt>.log``.

The pool is driven by :meth:`LocalExecutor.poll` (no threads): every poll reaps the finished
processes and starts queued members while slots are free.
"""

from __future__ import annotations

import os
import signal
import socket
import subprocess
import sys
import time
from collections import deque
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import IO, Any

from drumflow.runner import STOP_GRACE_S
from drumflow.sweep.executor import Attempt, Executor, Ledger
from drumflow.sweep.run_settings import LocalSettings, Runs
from drumflow.sweep.spec import Member, SweepError

__all__ = ["LocalExecutor", "available_cores", "member_command"]

#: Builds the command of one member: (member, its run directory) -> argument list.
CommandFactory = Callable[[Member, Path], list[str]]


def _alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    return True


def available_cores() -> int:
    """Cores this process may run on (the CPU affinity mask, as a container sets it)."""
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:  # not Linux
        return os.cpu_count() or 1


def member_command(runs: Runs) -> CommandFactory:
    """The ``drumflow run`` command of a member, with this Python's drumflow."""

    def command(member: Member, run_dir: Path) -> list[str]:
        cmd = [sys.executable, "-m", "drumflow.cli", "run", str(run_dir / "case.toml"),
               "--out", str(run_dir), "--np", str(runs.processes)]
        if runs.timeout is not None:
            cmd += ["--timeout", f"{runs.timeout:g}"]
        return cmd

    return command


class LocalExecutor(Executor):
    """Run members as a bounded pool of processes on this machine.

    Parameters
    ----------
    root
        The sweep directory (members in ``root/members/<id>``, logs in ``root/logs``).
    settings
        ``executor.local`` of the sweep file.
    runs
        ``runs`` of the sweep file (MPI ranks per member, time limit).
    cores
        Cores to fill (default: :func:`available_cores`).
    command
        Builds each member's command (default: :func:`member_command`); tests give their own
        program to watch the pool.
    """

    kind = "local"

    def __init__(
        self,
        root: Path,
        settings: LocalSettings,
        runs: Runs,
        cores: int | None = None,
        command: CommandFactory | None = None,
    ) -> None:
        self.root = Path(root)
        self.settings = settings
        self.runs = runs
        self.cores = cores if cores is not None else available_cores()
        self.poll_interval = settings.poll_interval
        self._command = command or member_command(runs)
        self._queue: deque[tuple[Member, Attempt]] = deque()
        self._running: dict[str, tuple[subprocess.Popen[bytes], Attempt, IO[bytes]]] = {}

    @property
    def slots(self) -> int:
        """Members at once: never more ranks than cores."""
        by_cores = self.cores // self.runs.processes
        cap = self.settings.max_parallel
        return max(0, by_cores if cap == "auto" else min(cap, by_cores))

    def check(self, members: Sequence[Member]) -> None:
        if self.runs.processes > self.cores:
            raise SweepError([
                f"runs.processes = {self.runs.processes}: each member needs more MPI ranks than "
                f"this machine has cores ({self.cores}); allowed: 1 to {self.cores} with the "
                "local executor (or use the slurm executor)"
            ])

    def submit(self, members: Sequence[Member], ledger: Ledger) -> None:
        for member in members:
            attempt = ledger.add(Attempt(member=member.id, executor=self.kind))
            self._queue.append((member, attempt))
        self.poll(ledger)

    def _adopt_stale(self, ledger: Ledger) -> None:
        """Attempts a previous session left 'pending' or 'running' (its process was killed)."""
        mine = {id(a) for _, a in self._queue} | {id(r[1]) for r in self._running.values()}
        for attempt in ledger.active(self.kind):
            if id(attempt) in mine:
                continue
            pid = int(attempt.job_id.split()[-1]) if attempt.job_id else None
            if pid is not None and _alive(pid):
                raise SweepError([
                    f"member {attempt.member}: still being run by process {pid} of an earlier "
                    "sweep session; wait for it to end (or stop it) and run the sweep again"
                ])
            attempt.state = "interrupted"
            attempt.reason = "the sweep session that ran it ended before it did"
            attempt.ended = attempt.ended or time.time()

    def poll(self, ledger: Ledger) -> None:
        self._adopt_stale(ledger)
        for mid, (proc, attempt, log) in list(self._running.items()):
            code = proc.poll()
            if code is None:
                continue
            log.close()
            del self._running[mid]
            attempt.ended = time.time()
            attempt.exit_code = str(code)
            if code == 0:
                attempt.state = "completed"
            elif code in (130, -signal.SIGINT, -signal.SIGTERM):
                attempt.state = "interrupted"
                attempt.reason = "stopped by a signal; resumed from its restart on rerun"
            else:
                attempt.state = "failed"
                attempt.reason = f"killed by signal {-code}" if code < 0 else "drumflow run failed"
        while self._queue and len(self._running) < self.slots:
            member, attempt = self._queue.popleft()
            self._start(member, attempt, ledger)
        ledger.save()

    def _start(self, member: Member, attempt: Attempt, ledger: Ledger) -> None:
        run_dir = self.root / "members" / member.id
        logs = self.root / "logs"
        logs.mkdir(parents=True, exist_ok=True)
        log_path = logs / f"{member.id}.{ledger.count(member.id)}.log"
        log = log_path.open("wb")
        command = self._command(member, run_dir)
        log.write(f"# drumflow sweep (local): {' '.join(command)}\n".encode())
        log.flush()
        # Its own session: the sweep decides how a member is stopped (`interrupt`), so that a
        # Ctrl-C in the terminal does not reach it twice.
        proc = subprocess.Popen(command, stdout=log, stderr=subprocess.STDOUT, stdin=subprocess.DEVNULL,
                                start_new_session=True)
        attempt.state = "running"
        attempt.started = time.time()
        attempt.job_id = f"pid {proc.pid}"
        attempt.node = socket.gethostname()
        attempt.log = str(log_path)
        self._running[member.id] = (proc, attempt, log)

    @property
    def busy(self) -> int:
        """Members running now."""
        return len(self._running)

    def interrupt(self, ledger: Ledger) -> str:
        # One SIGTERM per member (they run in their own sessions, so a Ctrl-C in the terminal
        # reached only the sweep): `drumflow run` then stops its solver, a run with air after
        # writing a restart at its next air update, within the runner's grace; a second signal
        # would cut that short. SIGTERM, not SIGINT: a member may have inherited an ignored
        # SIGINT (a background job), never an ignored SIGTERM from drumflow.
        for proc, _, _ in self._running.values():
            if proc.poll() is None:
                proc.send_signal(signal.SIGTERM)
        deadline = time.time() + STOP_GRACE_S + 10.0
        for proc, _, _ in self._running.values():
            try:
                proc.wait(timeout=max(0.1, deadline - time.time()))
            except subprocess.TimeoutExpired:
                proc.kill()
                proc.wait()
        self.poll(ledger)
        for mid, (_, attempt, log) in list(self._running.items()):
            log.close()
            attempt.state = "interrupted"
            del self._running[mid]
        while self._queue:
            _, attempt = self._queue.popleft()
            attempt.state = "interrupted"
            attempt.reason = "the sweep was interrupted before this member started"
        ledger.save()
        return "members stopped; run the same command again to resume them from their restarts"

    def describe(self) -> dict[str, Any]:
        return {"kind": self.kind, "cores": self.cores, "slots": self.slots,
                "processes_per_member": self.runs.processes, "host": socket.gethostname(),
                "max_parallel": self.settings.max_parallel}
