"""The stop rule (``run.stop = "converged"``) replayed on a finished run.

:func:`rule_monitor` feeds the online monitor (:class:`drumflow.coupling.stop.StopMonitor`) the
run's logged series instead of live particles; :func:`rule_verdict` is its verdict after the
first updates, and :func:`rule_first_fire` the first check at which it fires on the coupling
loop's own schedule. :mod:`drumflow.bench.answer` sets them beside what the run reports.
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pandas as pd
from numpy.typing import NDArray

from drumflow.bench.answer_result import TIME_EPS_S
from drumflow.case import Case
from drumflow.convergence import ConvergenceState, MeanInterval, batch_means, decide
from drumflow.coupling.stop import StopMonitor, rule_inputs
from drumflow.rundir import RunDir

__all__ = ["rule_check_every", "rule_first_fire", "rule_monitor", "rule_verdict"]


def rule_monitor(case: Case, run: RunDir, updates: pd.DataFrame, crossings: pd.DataFrame,
             dt: float) -> StopMonitor:
    """The online monitor, fed the replayed series instead of live particles.

    It is made as a rank other than 0, which writes nothing, so the replay reads the run
    directory only; :meth:`StopMonitor.windowed` then builds the rule's two series exactly as
    the coupling loop does.
    """
    # The DEM's case: with coarse-graining, what crossed were parcels.
    rule = rule_inputs(case.dem_case(), case.run.time, check_every=1)
    monitor = StopMonitor(rule, run.dem, rank=1, time_step=dt, start_step=0)
    t_upd = updates["time_s"].to_numpy(float)
    # Crossing sample k counts the crossings in (t_{k-1}, t_k], as the loop's tracker does.
    at = np.searchsorted(t_upd, crossings["time"].to_numpy(float), side="left")
    inside = (at > 0) & (at < t_upd.size)
    counts = np.bincount(at[inside], minlength=t_upd.size).astype(float)
    counts[0] = math.nan  # the first update has no previous sample
    s = monitor.series
    s.step = [int(v) for v in updates["step"]]
    s.time_s = [float(v) for v in t_upd]
    s.steps = [int(v) for v in updates["steps"]]
    s.h = [float(v) for v in updates["h_W_m2K"]]
    s.crossings = [float(v) for v in counts]
    return monitor


def rule_verdict(monitor: StopMonitor, n: int, time_s: float, tolerance: float,
             min_time: float) -> tuple[ConvergenceState, bool, MeanInterval]:
    """The rule at ``time_s`` on the first ``n`` updates, whether its intervals alone pass, and
    the whole-surface h over the window so far (batch means of every sample, whole cycles or
    not: the temperature's extrapolation needs it before the first cycle ends)."""
    full = monitor.series
    monitor.series = replace(full, step=full.step[:n], time_s=full.time_s[:n],
                             steps=full.steps[:n], h=full.h[:n], crossings=full.crossings[:n])
    try:
        intervals = monitor.intervals()
        h_window = batch_means(*monitor.windowed()["h_W_m2K"])
    finally:
        monitor.series = full
    state = decide(intervals, time_s, tolerance, min_time)
    narrow = decide(intervals, time_s, tolerance, -math.inf).converged
    return state, narrow, h_window


def rule_check_every(run: RunDir, out_t: NDArray[np.float64], dt: float) -> int:
    """DEM steps between the rule's checks: the output step (``drumflow.dem.stage``)."""
    recorded = run.manifest.get("output_every")
    if recorded:
        return int(recorded)
    return max(1, int(round(float(np.median(np.diff(out_t))) / dt)))


def rule_first_fire(monitor: StopMonitor, updates: pd.DataFrame, out_t: NDArray[np.float64],
                every: int, tolerance: float, min_time: float) -> tuple[float | None, str]:
    """The first check at which the rule fires, on the loop's schedule (an update whose step
    is at least ``every`` after the previous check's), as the output time it stops at."""
    steps = updates["step"].to_numpy(int)
    t_upd = updates["time_s"].to_numpy(float)
    last, state = 0, None
    for i, step in enumerate(steps):
        if step - last < every:
            continue
        last = int(step)
        if t_upd[i] < min_time - TIME_EPS_S:
            continue
        state, _, _ = rule_verdict(monitor, i + 1, float(t_upd[i]), tolerance, min_time)
        if state.converged:
            # The output written at that step (the same time, to its 10 digits).
            near = int(np.argmin(np.abs(out_t - t_upd[i])))
            return float(out_t[near] if abs(out_t[near] - t_upd[i]) < TIME_EPS_S
                         else t_upd[i]), state.reason
    if state is None:
        state, _, _ = rule_verdict(monitor, len(steps), float(t_upd[-1]), tolerance, min_time)
    return None, f"never fired; at {state.time_s:.4g} s: {state.reason}"
