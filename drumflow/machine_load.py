"""What else the machine did while a run ran: a load log beside every long solver run.

A wall time measures the run only when the run had the machine to itself. The load average
cannot tell (a run's own ranks keep it at their count), so the CPU other programs took is
measured: the machine's busy CPU time (``/proc/stat``) less the CPU time of the run's own
session (:class:`drumflow.runner.Runner` starts a program in a session of its own, which its MPI
ranks inherit). :class:`LoadLog` samples both every ``period`` seconds into a CSV
(one row per sample; a resumed run appends its attempt), and :func:`contended_stretches` gives
the stretches where others took more than :data:`BUSY_OTHER_CORES` of a core, which a
time-to-answer table marks. On a machine without ``/proc`` the columns are NaN.
"""

from __future__ import annotations

import math
import os
import threading
import time
from pathlib import Path

import numpy as np
import pandas as pd
from numpy.typing import NDArray

#: Other programs' mean CPU, in cores, above which a run or a stretch of one is contended: an
#: idle VM's daemons and a shell stay at 0.01-0.03, a test suite or a second solver far above.
BUSY_OTHER_CORES = 0.1
#: Seconds between samples: long enough to cost nothing, short enough to place a contended
#: stretch within a minute of a run's hours.
LOAD_PERIOD_S = 30.0
#: Seconds to the first sample.
FIRST_SAMPLE_S = 3.0
COLUMNS = ("time_unix", "load_1min", "busy_cores", "run_cores", "other_cores")


def machine_busy_cpu_s() -> float:
    """CPU seconds the whole machine has been busy since boot (``/proc/stat``; NaN elsewhere)."""
    try:
        fields = Path("/proc/stat").read_text().split("\n", 1)[0].split()
    except OSError:
        return math.nan
    user, nice, system, _idle, _iowait, irq, softirq, steal = (int(v) for v in fields[1:9])
    return (user + nice + system + irq + softirq + steal) / os.sysconf("SC_CLK_TCK")


def session_cpu_s(session: int) -> float:
    """CPU seconds (user + system) of the live processes in session ``session``.

    A process that ended between two samples takes its last stretch with it (counted as
    another program's); the ranks of a run live as long as the run.
    """
    total = 0
    try:
        entries = os.listdir("/proc")
    except OSError:
        return math.nan
    for entry in entries:
        if not entry.isdigit():
            continue
        try:
            stat = Path("/proc", entry, "stat").read_text()
        except OSError:
            continue  # ended meanwhile
        # The command name is in parentheses and may hold spaces: split after its last ')'.
        fields = stat[stat.rfind(")") + 2:].split()
        # The session, not the process group: Open MPI gives each rank a group of its own.
        if int(fields[3]) == session:  # fields[11:13] are utime, stime
            total += int(fields[11]) + int(fields[12])
    return total / os.sysconf("SC_CLK_TCK")


class LoadLog:
    """Sample the machine's load while session ``session`` runs, into ``path``.

    Parameters
    ----------
    path
        The CSV (:data:`COLUMNS`); created with its header, else appended to.
    session
        The run's session (the launcher's pid when it was started with ``setsid``).
    period
        Seconds between samples.
    """

    def __init__(self, path: Path, session: int, period: float = LOAD_PERIOD_S) -> None:
        if not period > 0:
            raise ValueError(f"load log period = {period!r} s: must be positive")
        self.path = path
        self.session = session
        self.period = period
        self._stop = threading.Event()
        path.parent.mkdir(parents=True, exist_ok=True)
        if not path.exists() or path.stat().st_size == 0:
            path.write_text(",".join(COLUMNS) + "\n")
        self._last = (time.time(), machine_busy_cpu_s(), session_cpu_s(session))
        self._thread = threading.Thread(target=self._loop, daemon=True)
        self._thread.start()

    def sample(self) -> None:
        """Append one row: the means since the previous sample."""
        now, busy, own = time.time(), machine_busy_cpu_s(), session_cpu_s(self.session)
        then, busy0, own0 = self._last
        self._last = (now, busy, own)
        span = max(now - then, 1e-9)
        busy_cores = (busy - busy0) / span
        # A rank that ended within the span lowers the session's sum: never a negative share.
        run_cores = max(own - own0, 0.0) / span
        other = max(busy_cores - run_cores, 0.0)
        try:
            load = os.getloadavg()[0]
        except OSError:
            load = math.nan
        with self.path.open("a") as fh:
            fh.write(f"{now:.1f},{load:.2f},{busy_cores:.3f},{run_cores:.3f},{other:.3f}\n")

    def _loop(self) -> None:
        # The first row early, so that a run of seconds (a test, a start-up check) has one.
        wait = min(self.period, FIRST_SAMPLE_S)
        while not self._stop.wait(wait):
            wait = self.period
            try:
                self.sample()
            except OSError:
                return  # the run directory went away: nothing left to log into

    def close(self) -> None:
        """Stop sampling. No last row: the run's processes have ended by now, and their last
        stretch of CPU would be counted as other programs'."""
        self._stop.set()
        self._thread.join(5)


def read_load_log(path: Path) -> pd.DataFrame:
    """A load log as a table (:data:`COLUMNS`); a row cut by a killed run is dropped."""
    table = pd.read_csv(path)
    missing = [c for c in COLUMNS if c not in table.columns]
    if missing:
        raise ValueError(f"{path}: not a load log (columns {', '.join(missing)} missing)")
    return table.dropna(subset=["time_unix", "other_cores"]).reset_index(drop=True)


def sample_spans(times: NDArray[np.float64], period: float = LOAD_PERIOD_S) -> NDArray[np.float64]:
    """Wall seconds each sample's means cover: the gap to the previous sample, or
    :data:`FIRST_SAMPLE_S` for an attempt's first (a gap much longer than the period is a new
    attempt: the run was not going in between)."""
    spans = np.full(len(times), FIRST_SAMPLE_S)
    if len(times) > 1:
        gaps = np.diff(times)
        spans[1:] = np.where(gaps < 4 * period, gaps, FIRST_SAMPLE_S)
    return spans


def contended_stretches(table: pd.DataFrame, threshold: float = BUSY_OTHER_CORES
                        ) -> list[tuple[float, float, float]]:
    """The stretches where other programs took more than ``threshold`` cores.

    Each is ``(start, end, mean other cores)`` in the log's unix times, the start being where
    its first sample's span begins (:func:`sample_spans`); a stretch never spans two attempts.
    """
    times = table["time_unix"].to_numpy(float)
    other = table["other_cores"].to_numpy(float)
    spans = sample_spans(times)
    stretches: list[tuple[float, float, float]] = []
    current: list[int] = []
    for i, value in enumerate(other):
        # A sample that starts an attempt (its span is not the gap) closes the stretch before.
        joined = bool(current) and spans[i] == times[i] - times[current[-1]]
        if current and not (value > threshold and joined):
            stretches.append(_stretch(current, times, other, spans))
            current = []
        if value > threshold:
            current.append(i)
    if current:
        stretches.append(_stretch(current, times, other, spans))
    return stretches


def _stretch(rows: list[int], times: NDArray[np.float64], other: NDArray[np.float64],
             spans: NDArray[np.float64]) -> tuple[float, float, float]:
    weights = spans[rows]
    return (float(times[rows[0]] - spans[rows[0]]), float(times[rows[-1]]),
            float((other[rows] * weights).sum() / weights.sum()))


def contended_share(run: Path) -> float:
    """The share of a run's logged wall time that other programs contended.

    ``run`` is a run directory (its log in ``dem/``) or a shipped results folder (the log at
    its top). NaN where the run has no load log (runs older than the log) or an empty one: not
    known, which a table must not print as zero.
    """
    for path in (run / "dem" / "machine_load.csv", run / "machine_load.csv"):
        if path.is_file():
            table = read_load_log(path)
            if table.empty:
                return math.nan
            logged = float(sample_spans(table["time_unix"].to_numpy(float)).sum())
            contended = sum(end - start for start, end, _ in contended_stretches(table))
            return contended / logged
    return math.nan
