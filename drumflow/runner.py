"""The one way drumflow starts external programs (LIGGGHTS, mpirun, OpenFOAM utilities).

Every program gets an argument list (never a shell string), a working directory, a log file
holding all it printed, a time limit, and its own process group, so that a timeout or Ctrl-C
kills it and every child it started (mpirun's ranks included). A failure raises a typed
:class:`~drumflow.errors.SolverError` carrying the return code, the command and the last
error line of the log.

A *profile* (:class:`LaunchProfile`) knows how to launch a code on this machine (which binary,
MPI launcher, environment); the code-specific stages know what to ask it for. This is the
split ASE makes between a calculator's template and its profile.
"""

from __future__ import annotations

import os
import re
import shutil
import signal
import subprocess
import threading
import time
from collections import deque
from collections.abc import Callable, Mapping, Sequence
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

from drumflow.errors import SolverError, SolverNotFoundError, SolverTimeoutError

#: Patterns of lines that carry a program's own error message.
ERROR_PATTERNS = (
    re.compile(r"\bERROR\b"),
    re.compile(r"assertion failed", re.IGNORECASE),
    re.compile(r"FOAM FATAL"),
    re.compile(r"Segmentation fault|signal 11|SIGSEGV"),
    re.compile(r"MPI_ABORT"),
)


class StopRun(Exception):
    """Raised by an ``on_line`` callback to stop the program: the runner kills its process
    group and raises ``error`` instead (a monitor that found the run going wrong)."""

    def __init__(self, error: BaseException) -> None:
        super().__init__(str(error))
        self.error = error


@dataclass
class RunRecord:
    """What happened when a program ran (goes into the manifest)."""

    program: str
    command: list[str]
    cwd: str
    log: str
    returncode: int | None
    wall_time_s: float
    started: float
    status: str = "ok"

    def as_dict(self) -> dict[str, Any]:
        return asdict(self)


def last_error_line(lines: Sequence[str]) -> str | None:
    """The last line matching one of :data:`ERROR_PATTERNS`, stripped."""
    for line in reversed(lines):
        if any(p.search(line) for p in ERROR_PATTERNS):
            return line.strip()
    return None


@dataclass
class LaunchProfile:
    """How to launch programs on this machine.

    Parameters
    ----------
    mpirun
        The MPI launcher; ``DRUMFLOW_MPIRUN`` overrides it.
    env
        Extra environment for every program.
    """

    mpirun: str = field(default_factory=lambda: os.environ.get("DRUMFLOW_MPIRUN", "mpirun"))
    env: dict[str, str] = field(default_factory=dict)

    def __post_init__(self) -> None:
        if os.geteuid() == 0:
            # OpenMPI refuses to run as root without both of these (containers, CI).
            self.env.setdefault("OMPI_ALLOW_RUN_AS_ROOT", "1")
            self.env.setdefault("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1")
        # Single-threaded BLAS and OpenMP inside each rank: MPI ranks already fill the cores.
        self.env.setdefault("OMP_NUM_THREADS", "1")

    def mpi_command(self, program: Sequence[str], processes: int) -> list[str]:
        """Wrap a program in the MPI launcher.

        Always through ``mpirun``, even for one process: LIGGGHTS started bare can die in
        MPI_Abort before its error message is flushed, leaving an empty log.
        """
        return [self.mpirun, "-np", str(processes), *program]


class Runner:
    """Start programs, log them, time them out, and record what happened.

    Parameters
    ----------
    profile
        The launch profile (MPI launcher, environment).
    records
        A list that receives a :class:`RunRecord` for every program run; the run directory's
        manifest takes it.
    """

    def __init__(self, profile: LaunchProfile | None = None, records: list[RunRecord] | None = None):
        self.profile = profile or LaunchProfile()
        self.records: list[RunRecord] = records if records is not None else []

    def run(
        self,
        program: str,
        command: Sequence[str],
        cwd: Path,
        log: Path,
        timeout: float | None = None,
        on_line: Callable[[str], None] | None = None,
        env: Mapping[str, str] | None = None,
        check: Callable[[int, list[str]], str | None] | None = None,
        follow: Path | None = None,
    ) -> RunRecord:
        """Run ``command`` in ``cwd``, writing all it prints to ``log``.

        Parameters
        ----------
        program
            Short name for messages and the manifest (``"liggghts"``).
        command
            The argument list.
        cwd, log
            Working directory and log file (created as needed).
        timeout
            Seconds before the process group is killed; ``None`` = no limit.
        on_line
            Called with every line the program prints (progress parsing). It must be quick.
        env
            Extra environment variables.
        check
            Called with the return code and the last lines; returns an error message when the
            run failed although the return code is 0 (some solvers exit 0 on fatal errors).
        follow
            A file the program writes and flushes as it goes (its own log); ``on_line`` then
            gets that file's lines instead of standard output. LIGGGHTS 3.8 flushes its log
            file at every thermo line but leaves standard output buffered until it exits.

        Raises
        ------
        SolverNotFoundError
            The executable is not installed.
        SolverTimeoutError
            The time limit passed; the process group was killed.
        SolverError
            Non-zero return code, or ``check`` found an error.
        """
        command = [str(c) for c in command]
        exe = command[0]
        if shutil.which(exe) is None and not Path(exe).exists():
            raise SolverNotFoundError(
                program, command, None, None, reason=f"{exe} not found; run scripts/install.sh"
            )
        cwd.mkdir(parents=True, exist_ok=True)
        log.parent.mkdir(parents=True, exist_ok=True)
        full_env = dict(os.environ)
        full_env.update(self.profile.env)
        if env:
            full_env.update(env)
        tail: deque[str] = deque(maxlen=400)
        started = time.time()
        record = RunRecord(program, command, str(cwd), str(log), None, 0.0, started)
        self.records.append(record)
        with log.open("w", encoding="utf-8", errors="replace") as fh:
            fh.write(f"# drumflow runner: {' '.join(command)}\n# cwd: {cwd}\n")
            fh.flush()
            proc = subprocess.Popen(
                command,
                cwd=cwd,
                stdout=subprocess.PIPE,
                stderr=subprocess.STDOUT,
                stdin=subprocess.DEVNULL,
                env=full_env,
                text=True,
                errors="replace",
                bufsize=1,
                start_new_session=True,  # own process group: killpg reaches mpirun's ranks
            )

            stops: list[StopRun] = []

            def notify(line: str) -> None:
                if on_line is not None and not stops:
                    try:
                        on_line(line)
                    except StopRun as stop:
                        stops.append(stop)
                    except Exception:  # a progress display must never kill a solver run
                        pass

            def pump() -> None:
                assert proc.stdout is not None
                for line in proc.stdout:
                    fh.write(line)
                    tail.append(line.rstrip("\n"))
                    if follow is None:
                        notify(line)
                fh.flush()

            reader = threading.Thread(target=pump, daemon=True)
            reader.start()
            stop_follow = threading.Event()
            follower = None
            if follow is not None:
                follower = threading.Thread(
                    target=_follow_file, args=(follow, notify, stop_follow), daemon=True
                )
                follower.start()
            def halt(status: str) -> None:
                stop_follow.set()
                _kill_group(proc)
                reader.join(5)
                record.status = status
                record.wall_time_s = time.time() - started

            try:
                deadline = None if timeout is None else started + timeout
                while True:
                    try:
                        proc.wait(timeout=0.2)
                        break
                    except subprocess.TimeoutExpired:
                        if stops:
                            break
                        if deadline is not None and time.time() > deadline:
                            raise
            except subprocess.TimeoutExpired:
                halt("timeout")
                raise SolverTimeoutError(
                    program,
                    command,
                    None,
                    log,
                    last_error_line(list(tail)),
                    reason=f"{program} ran longer than {timeout:g} s and was stopped",
                ) from None
            except BaseException:
                # Ctrl-C (KeyboardInterrupt) or anything else: never leave solvers behind.
                halt("interrupted")
                raise
            if stops:
                # A monitor (on_line) found the run going wrong: stop it; its error is raised
                # below, once the output threads have finished.
                _kill_group(proc)
            reader.join()
            stop_follow.set()
            if follower is not None:
                follower.join(5)
            if stops:
                # The monitor's verdict (also on the last lines) outranks how the program ended.
                record.returncode = proc.returncode
                record.status = "stopped"
                record.wall_time_s = time.time() - started
                raise stops[0].error
        record.returncode = proc.returncode
        record.wall_time_s = time.time() - started
        lines = list(tail)
        problem = check(proc.returncode, lines) if check else None
        if proc.returncode != 0 or problem:
            record.status = "failed"
            raise SolverError(
                program,
                command,
                proc.returncode,
                log,
                last_error_line(lines),
                reason=problem,
            )
        return record


def _follow_file(path: Path, notify: Callable[[str], None], stop: threading.Event) -> None:
    """Pass each complete line appended to ``path`` to ``notify`` until ``stop`` is set."""
    fh = None
    buffer = ""
    try:
        while True:
            finished = stop.is_set()
            if fh is None and path.exists():
                fh = path.open("r", errors="replace")
            if fh is not None:
                buffer += fh.read()
                *lines, buffer = buffer.split("\n")
                for line in lines:
                    notify(line + "\n")
            if finished:
                return
            stop.wait(0.25)
    finally:
        if fh is not None:
            fh.close()


def _kill_group(proc: subprocess.Popen[str], grace: float = 5.0) -> None:
    """SIGTERM the process group, then SIGKILL what is left after ``grace`` seconds."""
    try:
        pgid = os.getpgid(proc.pid)
    except ProcessLookupError:
        return
    for sig, wait in ((signal.SIGTERM, grace), (signal.SIGKILL, grace)):
        try:
            os.killpg(pgid, sig)
        except ProcessLookupError:
            return
        try:
            proc.wait(timeout=wait)
            return
        except subprocess.TimeoutExpired:
            continue
