"""The one-node SLURM cluster of the sweep tests (scripts/slurm_localhost.sh: munged, slurmctld,
slurmd on this machine), started for a test session and stopped at its end.

Only the daemons the session started are stopped: a daemon that was running before (a
developer's cluster, another session's) is left running, even if the script restarted it to
read a changed slurm.conf. Processes are found by their name (``/proc/PID/comm``) and the pid
files the script's slurm.conf names; zombies do not count as running.
"""

from __future__ import annotations

import os
import shutil
import signal
import subprocess
import time
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
SCRIPT = ROOT / "scripts" / "slurm_localhost.sh"
#: The daemons scripts/slurm_localhost.sh starts, with their pid files, in the order to stop them.
DAEMONS: tuple[tuple[str, Path], ...] = (
    ("slurmd", Path("/run/slurmd.pid")),
    ("slurmctld", Path("/run/slurmctld.pid")),
    ("munged", Path("/run/munge/munged.pid")),
)
PROC = Path("/proc")


def _alive(pid: int, proc: Path = PROC) -> bool:
    """A process with this pid exists and is not a zombie."""
    try:
        stat = (proc / str(pid) / "stat").read_text()
    except OSError:
        return False
    # "pid (comm) state ...": the state follows the last ')' (comm may hold spaces or ')').
    return stat.rsplit(")", 1)[-1].split()[:1] != ["Z"]


def running(name: str, pidfile: Path | None = None, proc: Path = PROC) -> set[int]:
    """Pids of the live processes named ``name``, and the live pid in ``pidfile`` if any."""
    pids = set()
    for entry in proc.iterdir():
        if not entry.name.isdigit():
            continue
        try:
            comm = (entry / "comm").read_text().strip()
        except OSError:
            continue
        if comm == name and _alive(int(entry.name), proc):
            pids.add(int(entry.name))
    if pidfile is not None:
        try:
            pid = int(pidfile.read_text().split()[0])
        except (OSError, ValueError, IndexError):
            pid = 0
        if pid > 0 and _alive(pid, proc):
            pids.add(pid)
    return pids


def to_stop(before: dict[str, set[int]], now: dict[str, set[int]]) -> list[tuple[str, int]]:
    """What to stop at the end: every live pid of a daemon that had none running before.

    ``before`` and ``now`` map a daemon's name to its live pids before the session's start and
    at its end. A daemon that ran before is left alone, whatever its pid is now."""
    return [(name, pid) for name, _ in DAEMONS if not before.get(name)
            for pid in sorted(now.get(name, set()))]


def _signal(pid: int, sig: signal.Signals) -> None:
    if os.geteuid() == 0:
        try:
            os.kill(pid, sig)
        except ProcessLookupError:
            pass
    else:
        subprocess.run(["sudo", "kill", f"-{sig.name.removeprefix('SIG')}", str(pid)],
                       capture_output=True, check=False, timeout=30)


def stop(daemons: list[tuple[str, int]], grace: float = 30.0) -> None:
    """SIGTERM each daemon in turn (slurmd, slurmctld, munged) and wait for it to end; SIGKILL
    the ones still alive after ``grace`` seconds."""
    for _, pid in daemons:
        _signal(pid, signal.SIGTERM)
        deadline = time.monotonic() + grace
        while _alive(pid) and time.monotonic() < deadline:
            time.sleep(0.2)
        if _alive(pid):
            _signal(pid, signal.SIGKILL)


def _snapshot() -> dict[str, set[int]]:
    return {name: running(name, pidfile) for name, pidfile in DAEMONS}


@contextmanager
def localhost_cluster() -> Iterator[tuple[str, str] | None]:
    """Start (or find) the localhost cluster; yield None when it runs, or ``(what, why)`` when
    SLURM cannot run here (for :func:`support.requirements.missing`). On exit, stop the daemons
    started here (:func:`to_stop`)."""
    if shutil.which("sbatch") is None or not Path("/usr/sbin/slurmctld").exists():
        yield ("SLURM (scripts/install.sh installs slurmctld slurmd munge slurm-client)",
               "not installed")
        return
    if os.geteuid() != 0 and shutil.which("sudo") is None:
        yield ("root or sudo, to start slurmctld and slurmd", "cannot start SLURM")
        return
    before = _snapshot()
    try:
        proc = subprocess.run([str(SCRIPT)], capture_output=True, text=True, timeout=180,
                              check=False)
        if proc.returncode == 4:
            yield (f"a SLURM cluster of drumflow's own ({proc.stderr.strip()})",
                   "a slurm.conf not written by drumflow is in place")
        elif proc.returncode != 0:
            pytest.fail(f"scripts/slurm_localhost.sh failed ({proc.returncode}): {proc.stderr[-2000:]}")
        else:
            yield None
    finally:
        stop(to_stop(before, _snapshot()))
