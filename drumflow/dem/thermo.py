"""LIGGGHTS thermo output: live progress while running, and the time series afterwards.

The deck's thermo style is ``step v_sim_time atoms ke c_ke_rot v_T_mean v_overlap cpu``; ``v_T_mean`` is
the mass-weighted mean particle temperature computed inside LIGGGHTS over all particles, at
every output step. ``v_overlap`` is the largest particle-particle overlap, or
:data:`OVERLAP_NOT_EVALUATED` on the rows where the coupling loop left it out
(``overlap_every``); :func:`read_thermo` gives those rows NaN. The series is rebuilt from
LIGGGHTS' own log files (the first attempt and every resume), so an interrupted run loses
nothing and ``drumflow post`` needs no solver.
"""

from __future__ import annotations

import re
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pandas as pd

from drumflow.coupling.spec import OVERLAP_NOT_EVALUATED

COLUMNS = ("step", "time", "atoms", "ke", "ke_rot", "T_mean", "overlap_max", "cpu")
#: Runs made before the overlap column existed (their logs stay readable by `drumflow post`).
LEGACY_COLUMNS = ("step", "time", "atoms", "ke", "ke_rot", "T_mean", "cpu")
#: LIGGGHTS' line after every ``run``: loop seconds, processes, steps, atoms. The one pattern
#: for it (the profile and the run record both read it).
LOOP_TIME = re.compile(r"^Loop time of (\S+) on (\d+) procs.*? for (\d+) steps with (\d+) atoms",
                       flags=re.M)


def loop_time_s(text: str) -> float | None:
    """Sum of LIGGGHTS' loop times in a log's text (None when it has none)."""
    times = [float(m.group(1)) for m in LOOP_TIME.finditer(text)]
    return sum(times) if times else None


class ThermoParser:
    """Collects thermo rows from lines as they come; optionally reports simulated time."""

    def __init__(
        self,
        on_time: Callable[[float, int], None] | None = None,
        columns: tuple[str, ...] = COLUMNS,
    ) -> None:
        self.rows: list[tuple[float, ...]] = []
        self.on_time = on_time
        self.columns = columns

    def __call__(self, line: str) -> None:
        parts = line.split()
        if len(parts) != len(self.columns) or not parts[0].isdigit():
            return
        try:
            row = tuple(float(p) for p in parts)
        except ValueError:
            return
        self.rows.append(row)
        if self.on_time is not None:
            self.on_time(row[1], int(row[2]))


def log_files(dem_dir: Path) -> list[Path]:
    """LIGGGHTS logs of a DEM stage in the order they were written."""
    logs = []
    first = dem_dir / "log.liggghts"
    if first.exists():
        logs.append(first)

    def resume_step(p: Path) -> int:
        m = re.search(r"resume-(\d+)", p.name)
        return int(m.group(1)) if m else -1

    logs += sorted(dem_dir.glob("log.resume-*.liggghts"), key=resume_step)
    return logs


def read_thermo(dem_dir: Path, every: int | None = None) -> pd.DataFrame:
    """The thermo series of a DEM stage, one row per output step, later attempts winning.

    ``every``: keep only steps that are multiples of it (and the last step). The coupling loop
    runs LIGGGHTS in short runs, each printing thermo at its first and last step; the output
    grid is the multiples of the output step.

    Returns
    -------
    pandas.DataFrame
        Columns :data:`COLUMNS`, sorted by step, without duplicate steps.
    """
    frames = []
    for order, path in enumerate(log_files(dem_dir)):
        parser = ThermoParser()
        legacy = ThermoParser(columns=LEGACY_COLUMNS)
        with path.open("r", errors="replace") as fh:
            for line in fh:
                parser(line)
                legacy(line)
        if not parser.rows and legacy.rows:
            frame = pd.DataFrame(np.array(legacy.rows), columns=list(LEGACY_COLUMNS))
            frame.insert(6, "overlap_max", np.nan)
            frame["attempt"] = order
            frames.append(frame)
        elif parser.rows:
            frame = pd.DataFrame(np.array(parser.rows), columns=list(COLUMNS))
            frame["attempt"] = order
            frames.append(frame)
    if not frames:
        return pd.DataFrame(columns=list(COLUMNS))
    # A resumed attempt supersedes everything earlier attempts wrote from its restart step on,
    # including the off-grid line an interrupted LIGGGHTS prints when it stops.
    kept = []
    for k, frame in enumerate(frames):
        later_starts = [f["step"].iloc[0] for f in frames[k + 1 :]]
        cut = min(later_starts) if later_starts else np.inf
        kept.append(frame[frame["step"] < cut])
    table = pd.concat(kept, ignore_index=True)
    # Within an attempt a step can appear twice: at the end of one coupled run and at the start
    # of the next (or in the final `run 0`). The first is the state at that step; the second
    # comes after the loop's update, which, when the loop integrates the temperatures itself
    # (run.conduction = false), has already added the next interval's heat.
    table = table.drop_duplicates(["attempt", "step"], keep="first")
    table = table.sort_values(["step", "attempt"], kind="stable").drop_duplicates("step", keep="last")
    table["step"] = table["step"].astype(np.int64)
    if every:
        last = table["step"].max()
        table = table[(table["step"] % every == 0) | (table["step"] == last)]
    table["atoms"] = table["atoms"].astype(np.int64)
    table.loc[table["overlap_max"] == OVERLAP_NOT_EVALUATED, "overlap_max"] = np.nan
    return table.drop(columns="attempt").reset_index(drop=True)
