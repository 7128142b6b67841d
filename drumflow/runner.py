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
import platform
import re
import shutil
import signal
import subprocess
import sys
import threading
import time
from collections import deque
from collections.abc import Callable, Mapping, Sequence
from dataclasses import asdict, dataclass, field
from importlib import metadata
from pathlib import Path
from typing import IO, TYPE_CHECKING, Any

from drumflow.errors import SolverError, SolverNotFoundError, SolverTimeoutError
from drumflow.machine_load import LoadLog

if TYPE_CHECKING:
    from drumflow.case import Case

#: Where the Debian package installs OpenFOAM's ``etc/`` tree; ``WM_PROJECT_DIR`` overrides.
DEFAULT_OPENFOAM_DIR = "/usr/share/openfoam"

#: Python packages whose versions go into every manifest.
_PACKAGES = ("drumflow", "numpy", "scipy", "pandas", "gmsh", "meshio", "pyvista", "pydantic",
             "jinja2", "foamlib", "matplotlib", "typer", "rich")

#: Seconds an interrupted program may take to stop by itself after its stop request is written
#: (``Runner.run(stop_request=...)``): the coupling loop finishes its current update interval
#: and writes a restart (paper model one: about 15 s and 0.3 GB); a second Ctrl-C kills at once.
STOP_GRACE_S = 120.0

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
    """How to launch programs on this machine: binaries, MPI launcher, environment, cores.

    The case says what to compute; the profile says with what on this machine. Everything that
    depends on the machine (the core count, where OpenFOAM lives, which solver versions are
    installed) is read here, never inside the hashed case.

    Parameters
    ----------
    mpirun
        The MPI launcher; ``DRUMFLOW_MPIRUN`` overrides it.
    liggghts
        The LIGGGHTS executable: ``PREFIX/bin/liggghts`` of the build ``DRUMFLOW_LIGGGHTS_PREFIX``
        names (:func:`liggghts_build`), else the Debian package's ``liggghts``.
    python
        The Python interpreter for drumflow's own child processes (coupling loop, renders).
    openfoam_dir
        OpenFOAM's ``WM_PROJECT_DIR`` (the Debian OpenFOAM v1912 binaries in /usr/bin find
        their ``etc/`` files through it); the environment variable overrides the default.
    cores
        Cores available for MPI ranks ('auto' process counts are capped by it).
    env
        Extra environment for every program.
    """

    mpirun: str = field(default_factory=lambda: os.environ.get("DRUMFLOW_MPIRUN", "mpirun"))
    liggghts: str = field(default_factory=lambda: liggghts_build().executable)
    python: str = sys.executable
    openfoam_dir: str = field(
        default_factory=lambda: os.environ.get("WM_PROJECT_DIR", DEFAULT_OPENFOAM_DIR)
    )
    cores: int = field(default_factory=lambda: os.cpu_count() or 1)
    env: dict[str, str] = field(default_factory=dict)

    def __post_init__(self) -> None:
        if os.geteuid() == 0:
            # OpenMPI refuses to run as root without both of these (containers, CI).
            self.env.setdefault("OMPI_ALLOW_RUN_AS_ROOT", "1")
            self.env.setdefault("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1")
        # Single-threaded BLAS and OpenMP inside each rank: MPI ranks already fill the cores.
        self.env.setdefault("OMP_NUM_THREADS", "1")
        build = liggghts_build()
        if build.library is not None:
            # The coupling loop loads LIGGGHTS as a library in its own processes
            # (drumflow.coupling.library reads this variable).
            self.env.setdefault(LIBRARY_VARIABLE, build.library)

    def mpi_command(self, program: Sequence[str], processes: int) -> list[str]:
        """Wrap a program in the MPI launcher.

        Always through ``mpirun``, even for one process: LIGGGHTS started bare can die in
        MPI_Abort before its error message is flushed, leaving an empty log.
        """
        return [self.mpirun, "-np", str(processes), *program]

    def liggghts_command(self, deck: str, log: str, processes: int) -> list[str]:
        """LIGGGHTS on ``deck`` writing its own ``log``, under the MPI launcher."""
        return self.mpi_command([self.liggghts, "-in", deck, "-log", log], processes)

    def python_module_command(self, module: str, *args: str, processes: int | None = None) -> list[str]:
        """``python -m module args``, under the MPI launcher when ``processes`` is given."""
        command = [self.python, "-m", module, *args]
        return command if processes is None else self.mpi_command(command, processes)

    def openfoam_env(self) -> dict[str, str]:
        """Environment every OpenFOAM program needs (``WM_PROJECT_DIR``)."""
        return {"WM_PROJECT_DIR": self.openfoam_dir}

    def processes_for(self, case: Case) -> int:
        """MPI processes for a case on this machine (``run.processes``, or 'auto' capped by
        :attr:`cores`)."""
        return case.processes(self.cores)

    def software_versions(self) -> dict[str, Any]:
        """Versions of drumflow, the solvers, Python and the Python packages it uses."""
        packages: dict[str, str | None] = {}
        for name in _PACKAGES:
            try:
                packages[name] = metadata.version(name)
            except metadata.PackageNotFoundError:
                packages[name] = None
        return {
            "python": sys.version.split()[0],
            "platform": platform.platform(),
            "liggghts": _dpkg_version("liggghts"),
            "liggghts_build": liggghts_build().describe(),
            "openfoam": _dpkg_version("openfoam"),
            "openmpi": _dpkg_version("openmpi-bin"),
            "packages": packages,
        }


#: Names a LIGGGHTS built from source (``PREFIX/bin/liggghts``, ``PREFIX/lib/libliggghts.so.3``,
#: ``PREFIX/build-flags.txt``; ``scripts/install.sh --liggghts-native``); unset: the Debian package.
PREFIX_VARIABLE = "DRUMFLOW_LIGGGHTS_PREFIX"
#: The library the coupling loop loads (drumflow.coupling.library).
LIBRARY_VARIABLE = "DRUMFLOW_LIGGGHTS_LIBRARY"
#: The Debian package's library, by its soname (the dynamic loader finds it).
SYSTEM_LIBRARY = "libliggghts.so.3"
#: The file of a build's prefix that records its compiler and flags.
BUILD_FLAGS_FILE = "build-flags.txt"


@dataclass(frozen=True)
class LiggghtsBuild:
    """Which LIGGGHTS runs: the Debian package (``prefix`` None) or a build from source.

    Attributes
    ----------
    prefix
        Install prefix of a build from source, or ``None`` for the Debian package.
    executable
        The ``liggghts`` program to launch.
    library
        The shared library for the coupling loop, or ``None`` for the system's
        ``libliggghts.so.3``.
    flags
        The build's compiler and flags as its ``build-flags.txt`` records them (``None`` for the
        Debian package: -O2, Debian's hardening, no -march).
    """

    prefix: str | None
    executable: str
    library: str | None
    flags: str | None

    def describe(self) -> dict[str, str | None]:
        """For the manifest and the benchmarks' results files."""
        if self.prefix is None:
            return {"source": "debian package", "prefix": None, "flags": None}
        return {"source": "built from source", "prefix": self.prefix, "flags": self.flags}


#: The Debian package's LIGGGHTS, the default.
DEBIAN_LIGGGHTS = LiggghtsBuild(None, "liggghts", None, None)


def liggghts_build(prefix: str | None = None) -> LiggghtsBuild:
    """The LIGGGHTS build at ``prefix``, or the one ``DRUMFLOW_LIGGGHTS_PREFIX`` names, or the
    Debian package.

    Raises
    ------
    SolverNotFoundError
        ``prefix`` (or the variable) names a folder without ``bin/liggghts`` and
        ``lib/libliggghts.so.3``: refused by name rather than silently running Debian's.
    """
    prefix = prefix if prefix is not None else (os.environ.get(PREFIX_VARIABLE) or None)
    if prefix is None:
        return DEBIAN_LIGGGHTS
    root = Path(prefix)
    executable, library = root / "bin" / "liggghts", root / "lib" / "libliggghts.so.3"
    missing = [str(p) for p in (executable, library) if not p.is_file()]
    if missing:
        raise SolverNotFoundError(
            "liggghts", missing, None, None,
            reason=f"{PREFIX_VARIABLE}={prefix}: not a LIGGGHTS build ({', '.join(missing)} missing); "
            "build one with `bash scripts/install.sh --liggghts-native`, or unset "
            f"{PREFIX_VARIABLE} for the Debian package")
    flags_file = root / BUILD_FLAGS_FILE
    flags = flags_file.read_text(errors="replace").strip() if flags_file.is_file() else None
    return LiggghtsBuild(str(root), str(executable), str(library), flags)


def _dpkg_version(package: str) -> str | None:
    """The installed Debian package version, or ``None`` (no dpkg, not installed)."""
    out = capture_output(["dpkg-query", "-W", "-f=${Version}", package], timeout=10)
    return out.strip() or None if out is not None else None


def capture_output(command: Sequence[str], timeout: float = 10.0) -> str | None:
    """Standard output of a short query program (a version lookup), or ``None`` if it is
    missing, fails or runs out of time.

    Like :meth:`Runner.run` it starts the program in its own process group, which a timeout
    kills whole; unlike it there is no log file, because nothing here is worth keeping.
    """
    if shutil.which(command[0]) is None:
        return None
    try:
        proc = subprocess.Popen(
            list(command), stdout=subprocess.PIPE, stderr=subprocess.DEVNULL,
            stdin=subprocess.DEVNULL, text=True, start_new_session=True,
        )
    except OSError:
        return None
    try:
        out, _ = proc.communicate(timeout=timeout)
    except subprocess.TimeoutExpired:
        _kill_group(proc)
        return None
    return out if proc.returncode == 0 else None


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
        stop_request: Path | None = None,
        stop_grace: float = STOP_GRACE_S,
        load_log: Path | None = None,
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
        stop_request
            A file the program looks for to stop cleanly (the coupling loop writes a restart,
            then exits). On an interrupt the runner writes it and gives the program
            ``stop_grace`` seconds to end before killing its process group; the interrupt is
            raised either way. A request already there when the program starts is left for
            it (``drumflow stop`` while earlier stages ran): the caller removes stale ones at
            the start of its attempt.
        stop_grace
            Seconds allowed for that clean stop.
        load_log
            A CSV that receives the machine's load while the program runs
            (:class:`drumflow.machine_load.LoadLog`: other programs' CPU, every 30 s; appended
            to by a resumed attempt), so that a wall time says whether it had the machine.

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
        _require_executable(program, command)
        cwd.mkdir(parents=True, exist_ok=True)
        log.parent.mkdir(parents=True, exist_ok=True)
        full_env = {**os.environ, **self.profile.env, **(env or {})}
        record = RunRecord(program, command, str(cwd), str(log), None, 0.0, time.time())
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
            try:
                # Inside the try: an interrupt while the output threads start (a loaded machine
                # can take a while to schedule them) must not leave the program running.
                watch = _Watch(proc, fh, on_line, follow)
            except BaseException:
                _kill_group(proc)
                record.status = "interrupted"
                record.wall_time_s = time.time() - record.started
                raise
            # The program's own session (start_new_session): the launcher and its MPI ranks,
            # whose CPU the log tells apart from everything else's.
            sampler = LoadLog(load_log, proc.pid) if load_log is not None else None
            try:
                _wait(proc, watch, record.started, timeout)
            except subprocess.TimeoutExpired:
                watch.halt(record, "timeout")
                raise SolverTimeoutError(
                    program,
                    command,
                    None,
                    log,
                    last_error_line(list(watch.tail)),
                    reason=f"{program} ran longer than {timeout:g} s and was stopped",
                ) from None
            except BaseException:
                # Ctrl-C (KeyboardInterrupt) or anything else: never leave solvers behind, but
                # let a program that can stop cleanly do so first.
                try:
                    if stop_request is not None:
                        _request_stop(proc, stop_request, stop_grace)
                finally:
                    watch.halt(record, "interrupted")
                raise
            finally:
                if sampler is not None:
                    sampler.close()
            watch.finish()
            if watch.stops:
                # The monitor's verdict (also on the last lines) outranks how the program ended.
                record.returncode = proc.returncode
                record.status = "stopped"
                record.wall_time_s = time.time() - record.started
                raise watch.stops[0].error
        record.returncode = proc.returncode
        record.wall_time_s = time.time() - record.started
        lines = list(watch.tail)
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


def _require_executable(program: str, command: list[str]) -> None:
    exe = command[0]
    if shutil.which(exe) is None and not Path(exe).exists():
        raise SolverNotFoundError(
            program, command, None, None, reason=f"{exe} not found; run scripts/install.sh"
        )


def _wait(proc: subprocess.Popen[str], watch: _Watch, started: float, timeout: float | None) -> None:
    """Wait for the program to end or a monitor to stop it; raise ``TimeoutExpired`` at the
    deadline."""
    deadline = None if timeout is None else started + timeout
    while True:
        try:
            proc.wait(timeout=0.2)
            return
        except subprocess.TimeoutExpired:
            if watch.stops:
                return
            if deadline is not None and time.time() > deadline:
                raise


class _Watch:
    """The threads that copy a program's output to its log and pass lines to ``on_line``.

    Standard output always goes to the log (and the last 400 lines to :attr:`tail`); the lines
    for ``on_line`` come from standard output, or from ``follow`` when the program writes its
    own log. A :class:`StopRun` raised by ``on_line`` is kept in :attr:`stops`.
    """

    def __init__(self, proc: subprocess.Popen[str], fh: IO[str],
                 on_line: Callable[[str], None] | None, follow: Path | None) -> None:
        self.proc = proc
        self.fh = fh
        self.on_line = on_line
        self.follow = follow
        self.tail: deque[str] = deque(maxlen=400)
        self.stops: list[StopRun] = []
        self.stop_follow = threading.Event()
        self.reader = threading.Thread(target=self._pump, daemon=True)
        self.reader.start()
        self.follower: threading.Thread | None = None
        if follow is not None:
            self.follower = threading.Thread(
                target=_follow_file, args=(follow, self._notify, self.stop_follow), daemon=True
            )
            self.follower.start()

    def _notify(self, line: str) -> None:
        if self.on_line is not None and not self.stops:
            try:
                self.on_line(line)
            except StopRun as stop:
                self.stops.append(stop)
            except Exception:  # a progress display must never kill a solver run
                pass

    def _pump(self) -> None:
        assert self.proc.stdout is not None
        for line in self.proc.stdout:
            self.fh.write(line)
            self.tail.append(line.rstrip("\n"))
            if self.follow is None:
                self._notify(line)
        self.fh.flush()

    def halt(self, record: RunRecord, status: str) -> None:
        """Kill the process group (timeout, interrupt) and record how the run ended."""
        self.stop_follow.set()
        _kill_group(self.proc)
        self.reader.join(5)
        record.status = status
        record.wall_time_s = time.time() - record.started

    def finish(self) -> None:
        """After the program ended (or a monitor stopped it): drain the output threads."""
        if self.stops:
            # A monitor (on_line) found the run going wrong: stop it; its error is raised by
            # the caller, once the output threads have finished.
            _kill_group(self.proc)
        self.reader.join()
        self.stop_follow.set()
        if self.follower is not None:
            self.follower.join(5)


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


def _request_stop(proc: subprocess.Popen[str], request: Path, grace: float) -> None:
    """Write ``request`` and wait up to ``grace`` seconds for the program to end by itself. A
    second interrupt during the wait ends the wait (the caller then kills the group)."""
    if proc.poll() is not None:
        return
    try:
        request.write_text(f"stop requested at {time.strftime('%Y-%m-%d %H:%M:%S')}\n")
        proc.wait(timeout=grace)
    except (subprocess.TimeoutExpired, KeyboardInterrupt, OSError):
        pass


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
