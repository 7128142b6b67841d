"""The load log beside a solver run (drumflow.machine_load): the run's CPU told apart from other
programs', and the stretches where others took the machine."""

from __future__ import annotations

import math
import subprocess
import sys
import time
from pathlib import Path

import pandas as pd
import pytest

from drumflow.machine_load import (
    COLUMNS,
    LoadLog,
    contended_share,
    contended_stretches,
    read_load_log,
    session_cpu_s,
)

BURN = "import time\nt = time.time()\nwhile time.time() - t < {s}: pass"


def test_the_run_group_and_another_program_are_told_apart(tmp_path: Path) -> None:
    # One busy process in the "run" (its own session, as the runner starts solvers), one outside.
    run = subprocess.Popen([sys.executable, "-c", BURN.format(s=3.0)], start_new_session=True)
    other = subprocess.Popen([sys.executable, "-c", BURN.format(s=3.0)], start_new_session=True)
    try:
        log = LoadLog(tmp_path / "load.csv", run.pid, period=1.0)
        time.sleep(2.6)
        log.close()
    finally:
        run.wait()
        other.wait()
    table = read_load_log(tmp_path / "load.csv")
    assert list(table.columns) == list(COLUMNS)
    assert len(table) >= 2
    # A spinning process takes at most one core; on this 2-core machine a background job may
    # share the cores, so the run's share is at least a third of one (three busy processes).
    assert table["run_cores"].between(0.3, 1.1).all(), table
    assert (table["other_cores"] >= 0.3).all(), table  # the second spinner at least
    assert (table["busy_cores"] >= table["run_cores"] - 0.05).all()


def test_session_cpu_counts_only_the_session() -> None:
    proc = subprocess.Popen([sys.executable, "-c", BURN.format(s=0.5)], start_new_session=True)
    time.sleep(0.4)
    inside = session_cpu_s(proc.pid)
    proc.wait()
    assert 0.05 < inside < 0.6
    assert session_cpu_s(2**22 + 12345) == 0.0  # no such session


def test_contended_stretches_join_neighbours_and_split_attempts() -> None:
    t0 = 1.0e9
    times = [t0 + 30 * i for i in range(10)] + [t0 + 3600 + 30 * i for i in range(3)]
    other = [0.0, 0.5, 0.9, 0.0, 0.0, 0.3, 0.0, 0.0, 0.0, 0.1] + [0.4, 0.6, 0.0]
    table = pd.DataFrame({"time_unix": times, "load_1min": 2.0, "busy_cores": 2.0,
                          "run_cores": 2.0, "other_cores": other})
    stretches = contended_stretches(table)
    assert [(round(a - t0), round(b - t0)) for a, b, _ in stretches] == [(0, 60), (120, 150), (3597, 3630)]
    assert stretches[0][2] == pytest.approx(0.7)
    # Means weighted by the samples' spans: the attempt's first sample covers its first 3 s.
    assert stretches[2][2] == pytest.approx((0.4 * 3 + 0.6 * 30) / 33)
    assert contended_stretches(table, threshold=1.0) == []


def test_a_file_that_is_not_a_load_log_is_refused(tmp_path: Path) -> None:
    path = tmp_path / "machine_load.csv"
    path.write_text("time,load\n1,2\n")
    with pytest.raises(ValueError, match=r"machine_load.csv: not a load log \(columns time_unix"):
        read_load_log(path)
    with pytest.raises(ValueError, match="period = 0"):
        LoadLog(tmp_path / "x.csv", 1, period=0.0)


def test_contended_share_of_a_run_or_a_shipped_folder(tmp_path: Path) -> None:
    t0 = 1.0e9
    # First sample covers 3 s, then nine of 30 s: 273 s logged; samples 3-4 contended (60 s).
    other = [0.0, 0.0, 0.0, 0.5, 0.9, 0.0, 0.0, 0.0, 0.0, 0.0]
    table = pd.DataFrame({"time_unix": [t0 + 30 * i for i in range(10)], "load_1min": 2.0,
                          "busy_cores": 2.0, "run_cores": 2.0, "other_cores": other})
    run = tmp_path / "run"
    (run / "dem").mkdir(parents=True)
    table.to_csv(run / "dem" / "machine_load.csv", index=False)
    assert contended_share(run) == pytest.approx(60 / 273)
    shipped = tmp_path / "shipped"
    shipped.mkdir()
    table.assign(other_cores=0.0).to_csv(shipped / "machine_load.csv", index=False)
    assert contended_share(shipped) == 0.0
    # No log: not known, never zero.
    assert math.isnan(contended_share(tmp_path))
