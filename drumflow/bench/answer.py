"""Time to answer: what a run stopped at each earlier time would have reported (issue 11).

How to use::

    drumflow answer RUN_DIR                  # writes RUN_DIR/post/answer.csv, .json, .png
    drumflow answer RUN_DIR --tolerance 0.02 --out /tmp/answer

    from drumflow.bench.answer import replay_answer
    from drumflow.bench.answer_result import write_answer
    replay = replay_answer(Path("results/paper/model_two"))   # AnswerReplay
    replay.table[["time_s", "h_W_m2K", "rel_h", "converged"]]
    replay.first_fire_s, replay.settled_s

The answer of a run is three numbers: (a) the mean particle temperature at 3.5 s (Tables 3-4 of
the paper), (b) the falling mass flow over the window from ``run.mass_flow_start`` (Table 6)
and (c) the paper's ``h`` (Eq. 39, :func:`drumflow.analysis.methodology.analyse_run`'s
``h_mean``). The speed of a run is the wall time until its answer is known within 1 % of what
the full run gives. This module replays a post-processed run (a run directory, or a shipped
results folder with the same ``case.toml`` and ``post/`` files) at a grid of end times ``t``
(every ``check_interval_s`` of simulated time, snapped to the output times):

* (b) and (c) come from :func:`~drumflow.analysis.methodology.analyse_run` with ``until=t``:
  the methodology on the truncated series, so the falling-mass window is
  ``[mass_flow_start, t]``. As in the methodology, ``h`` averages every valid step from the
  start of the run (Section 2.2), only the falling mass is measured in the window; the
  column ``h_window_W_m2K`` gives the average over the window's steps alone. Their
  half-widths are batch means (:func:`drumflow.convergence.batch_means`) of the per-step
  series: ``h`` per step, and falling mass per step over its length (the cascading bed's
  steady flow, (b'), takes whole lifter cycles instead, :func:`drumflow.convergence.cycle_means`,
  as the stop rule does). The falling mass cancels
  from Eq. 39 but for the air's warming (:func:`drumflow.analysis.published.eq39_as_lumped_h`), so
  the uncertainty of (b) hardly enters (c).
* (a) is read from the series (:func:`drumflow.analysis.published.temperature_at`) once ``t``
  reaches 3.5 s. Before that it is extrapolated with the lumped balance
  ``T(3.5) = T_air + (T(t) - T_air) exp(-h_s A (3.5 - t) / (M c_p))``, where ``h_s`` is the
  stop rule's whole-surface coefficient averaged over the window so far (exact while ``h_s``
  stays constant; ``temperature_extrapolated`` marks these rows). Relative differences of a
  temperature in deg C are small by construction (the paper's Tables 3-4 use them too);
  ``rel_temperature_drop`` measures the drop ``T(0) - T(3.5)`` instead.
* the verdict of ``run.stop = "converged"`` at ``t``: :func:`drumflow.convergence.decide` on
  the two intervals the online monitor forms (:meth:`drumflow.coupling.stop.StopMonitor.intervals`):
  ``h`` on the whole particle surface per coupling update from ``post/air_heat.csv`` and the
  mean temperature (:func:`drumflow.analysis.published.coupling_h`), and the falling mass flow from
  the crossings (``post/crossings.csv``) counted between consecutive updates. Besides the grid,
  the rule is checked the way the loop checks it (every output step) to find its first firing.

The reference is the longest time available, the last output time of
``post/mean_temperature.csv`` (:attr:`AnswerReplay.reference_time_s`): for a run still going it
is not the planned ``run.time``. Relative differences are ``value(t) / value(reference) - 1``;
the settled time of a quantity is the first grid time from which it stays within
``settle_tolerance`` of the reference.

Wall time at ``t``: the sum over the coupling updates before ``t`` of the slowest rank's
``python_wall_s + liggghts_wall_s`` from the run's coupling logs (``dem/coupling/rank*.csv``).
An update without them (an older attempt, a shipped folder without ``dem/``) is estimated from a
particle-steps-per-second rate: the one given, else the measured updates' own, else the run's
``run_record.json`` (LIGGGHTS loop time of the shipped run). So is a logged update slower than
:data:`drumflow.coupling.log.PAUSED_FACTOR` times the median (a process stopped from outside
for that long). Set-up, the air solve and post-processing are not counted.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
from numpy.typing import NDArray

from drumflow.analysis.methodology import analyse_run
from drumflow.analysis.methodology_result import FallingMassMode, MethodologyResult
from drumflow.analysis.observables import falling_mass_flow
from drumflow.analysis.published import coupling_h, temperature_at
from drumflow.bench.answer_result import QUANTITIES, TEMPERATURE_TIME_S, TIME_EPS_S, AnswerReplay
from drumflow.bench.answer_rule import (
    rule_check_every,
    rule_first_fire,
    rule_monitor,
    rule_verdict,
)
from drumflow.bench.answer_wall import wall_per_update
from drumflow.case import Case
from drumflow.convergence import MSER_BATCH, batch_means, cycle_means
from drumflow.coupling.stop import StopMonitor, discharge_cycle, min_stop_time
from drumflow.errors import (
    AnalysisInputError,
    MissingRunFileError,
    NoHeatTransferError,
    RunDirectoryError,
    RunTooShortError,
)
from drumflow.readers import read_csv
from drumflow.rundir import RunDir

__all__ = [
    "DEFAULT_CHECK_INTERVAL_S",
    "DEFAULT_TOLERANCE",
    "MIN_WINDOW_S",
    "regular_end_times",
    "replay_answer",
    "settled_time",
]

#: Largest relative difference from the full run at which the answer counts as known (issue 11).
DEFAULT_TOLERANCE = 0.01
#: Grid of end times, simulated seconds.
DEFAULT_CHECK_INTERVAL_S = 0.1
#: Least simulated time after ``run.mass_flow_start`` a run must hold to be replayed: below one
#: second the falling mass flow has seen about one lifter's discharge (paper model two: 12
#: lifters at 5 rpm, one per second).
MIN_WINDOW_S = 1.0
#: Columns of the run's tables that must hold a finite number in every row (the first row's
#: falling mass is NaN by construction: no step ends there).
_SERIES_FINITE = ("time_s", "mean_temperature_C")
_AIR_HEAT_FINITE = ("step", "time_s", "steps", "heat_to_particles_W")


def settled_time(times: Sequence[float] | NDArray[np.float64],
                 relative_difference: Sequence[float] | NDArray[np.float64],
                 tolerance: float) -> float | None:
    """The first time from which ``|relative_difference| <= tolerance`` holds to the end.

    Parameters
    ----------
    times
        Increasing times.
    relative_difference
        The relative difference from the reference at each time (NaN: not known, so not
        settled).
    tolerance
        Largest allowed ``|relative_difference|``.

    Returns
    -------
    float or None
        None when the last value itself is outside (or NaN).
    """
    t = np.asarray(times, dtype=float)
    rel = np.abs(np.asarray(relative_difference, dtype=float))
    ok = np.isfinite(rel) & (rel <= tolerance)
    if t.size == 0 or not ok[-1]:
        return None
    bad = np.flatnonzero(~ok)
    return float(t[0 if bad.size == 0 else bad[-1] + 1])


# -- the replay -----------------------------------------------------------------------------
def replay_answer(
    run_dir: Path | str,
    *,
    tolerance: float = DEFAULT_TOLERANCE,
    settle_tolerance: float = DEFAULT_TOLERANCE,
    check_interval_s: float = DEFAULT_CHECK_INTERVAL_S,
    times: Sequence[float] | None = None,
    particle_steps_per_s: float | None = None,
    falling_mass: FallingMassMode = "mean",
) -> AnswerReplay:
    """Replay a post-processed run: its answer and the stop rule's verdict at earlier end times.

    Parameters
    ----------
    run_dir
        A run directory after ``drumflow post``, or a shipped results folder of the same layout:
        ``case.toml``, ``post/mean_temperature.csv``, ``post/air_heat.csv``,
        ``post/crossings.csv`` (or ``.csv.gz``); optionally ``dem/coupling/rank*.csv`` (wall times) and
        ``run_record.json`` (wall time of a shipped run).
    tolerance
        The stop rule's largest relative half-width (``run.stop_tolerance``).
    settle_tolerance
        Largest relative difference from the reference for "settled".
    check_interval_s
        Spacing of the grid of end times, simulated seconds, from ``run.mass_flow_start``;
        each grid time is snapped to the last output time at or before it.
    times
        End times to use instead of the regular grid (each in
        ``(run.mass_flow_start, end of the run]``); the end of the run is always added.
    particle_steps_per_s
        Rate for the updates whose wall time was not logged (default: see the module notes).
    falling_mass
        Passed to :func:`~drumflow.analysis.methodology.analyse_run`.

    Returns
    -------
    AnswerReplay

    Raises
    ------
    MissingRunFileError
        A file the replay needs is missing (the message names it).
    RunTooShortError
        The run holds less than ``run.mass_flow_start + 1 s`` of simulated time.
    AnalysisInputError
        An argument is outside its allowed range (the message names it and the range).
    RunDirectoryError
        Not a run directory, or a file is malformed; also the errors of
        :func:`~drumflow.analysis.methodology.analyse_run` on the whole run.
    BadFileError
        A table or ``run_record.json`` is damaged: not UTF-8, cut short, a missing column, or
        a NaN or a word where a number belongs (file, row and column named).
    """
    for name, value in (("tolerance", tolerance), ("settle_tolerance", settle_tolerance)):
        if not (math.isfinite(value) and 0.0 < value < 1.0):
            raise AnalysisInputError(name, value, "a relative tolerance in (0, 1), e.g. 0.01")
    if not (math.isfinite(check_interval_s) and check_interval_s > 0.0):
        raise AnalysisInputError("check_interval_s", check_interval_s,
                                 "a positive number of simulated seconds, e.g. 0.1")
    if particle_steps_per_s is not None and not (math.isfinite(particle_steps_per_s)
                                                 and particle_steps_per_s > 0.0):
        raise AnalysisInputError("particle_steps_per_s", particle_steps_per_s,
                                 "a positive rate (particle-steps per wall second)")
    run = RunDir.existing(run_dir)
    for path, what in ((run.case_toml, "the validated case of the run"),
                       (run.mean_temperature_csv, "mean particle temperature and falling mass "
                        "per output step"),
                       (run.air_heat_csv, "the coupling log: heat the air took per update"),
                       (run.crossings_table, "the particles crossing the axis plane")):
        if not path.is_file():
            raise MissingRunFileError(path, what)
    # The whole run first: it validates the files and is the reference.
    full = analyse_run(run.root, falling_mass=falling_mass)
    case = full.case
    temps = read_csv(run.mean_temperature_csv, "mean particle temperature per output step",
                     columns=(*_SERIES_FINITE, "falling_mass_kg_in_step"), finite=_SERIES_FINITE,
                     min_rows=2)
    out_t = temps["time_s"].to_numpy(float)
    end = float(out_t[-1])
    start = float(case.run.mass_flow_start)
    if end < start + MIN_WINDOW_S - TIME_EPS_S:
        raise RunTooShortError(run.mean_temperature_csv, end, start + MIN_WINDOW_S,
                               f"run.mass_flow_start = {start:g} s plus {MIN_WINDOW_S:g} s")
    grid = _grid(out_t, start, check_interval_s, times)

    updates, dt = _updates(case, run, temps, end)
    # Checked: a cut .csv.gz ended in gzip's EOFError, which click turns into a bare "Aborted."
    crossings = read_csv(run.crossings_table, "the particles crossing the axis plane",
                         columns=("time",), finite=("time",))
    monitor = rule_monitor(case, run, updates, crossings, dt)
    wall, wall_info = wall_per_update(run, updates, dt, particle_steps_per_s)
    notes: list[str] = []

    min_time = min(min_stop_time(case), float(case.run.time))
    rows = [_row(t, case, run, full if t >= end - TIME_EPS_S else None, falling_mass, temps,
                 crossings, updates, monitor, wall, tolerance, min_time, notes) for t in grid]
    table = pd.DataFrame(rows)
    ref = table.iloc[-1]
    t0 = float(temps["mean_temperature_C"].iloc[0])
    for name, (col, _) in QUANTITIES.items():
        table[f"rel_{name}"] = table[col] / float(ref[col]) - 1.0
    drop = t0 - table["temperature_C"]
    table["rel_temperature_drop"] = drop / float(drop.iloc[-1]) - 1.0
    table["rel_steady_mass_flow"] = (table["steady_mass_flow_kg_s"]
                                     / float(ref["steady_mass_flow_kg_s"]) - 1.0)

    every = rule_check_every(run, out_t, dt)
    first_fire, reason = rule_first_fire(monitor, updates, out_t, every, tolerance, min_time)
    fired = table.loc[table["converged"], "time_s"]
    at_fire: dict[str, Any] = {}
    if first_fire is not None:
        fire_row = _row(first_fire, case, run, None, falling_mass, temps, crossings, updates,
                        monitor, wall, tolerance, min_time, [])
        at_fire = {key: fire_row[key] for key in
                   ("time_s", "temperature_C", "mass_flow_kg_s", "h_W_m2K", "wall_s",
                    "steady_mass_flow_kg_s", "steady_start_s")}
        for name, (col, _) in (*QUANTITIES.items(),
                               ("steady_mass_flow", ("steady_mass_flow_kg_s", ""))):
            at_fire[f"rel_{name}"] = float(fire_row[col]) / float(ref[col]) - 1.0
    settled = {name: settled_time(table["time_s"], table[f"rel_{name}"], settle_tolerance)
               for name in (*QUANTITIES, "temperature_drop", "steady_mass_flow")}

    wall_info["total_s"] = float(table["wall_s"].iloc[-1])
    planned = float(case.run.time)
    late = float(grid[-2]) if grid.size > 1 else end
    for name, when in settled.items():
        if when is None or when >= late - TIME_EPS_S:
            notes.append(f"{name} settles only at the end of the replay ({late:.4g} s or later): "
                         "it still drifts, so the run is too short to tell its answer")
    if end < planned - TIME_EPS_S:
        notes.append(f"the reference is the run's last output at {end:.4g} s, not the planned "
                     f"run.time = {planned:g} s: settled times are relative to it")
    if end < min_time - TIME_EPS_S:
        notes.append(f"the rule cannot fire before its minimum time {min_time:.4g} s "
                     f"(run.stop_min_time = {case.run.stop_min_time!r}); the run ends at "
                     f"{end:.4g} s")
    if end < TEMPERATURE_TIME_S - TIME_EPS_S:
        notes.append(f"the run ends before {TEMPERATURE_TIME_S:g} s: (a) is extrapolated at "
                     "every time, the reference too")
    if table["temperature_extrapolated"].any():
        notes.append(f"(a) before {TEMPERATURE_TIME_S:g} s is extrapolated with the whole-surface "
                     "h of the window so far (temperature_extrapolated)")
    return AnswerReplay(
        run_dir=run.root, case=case, table=table, reference_time_s=end, planned_time_s=planned,
        tolerance=tolerance, settle_tolerance=settle_tolerance, min_stop_time_s=min_time,
        check_every_steps=every,
        first_fire_s=first_fire,
        first_fire_grid_s=None if fired.empty else float(fired.iloc[0]),
        first_fire_reason=reason, at_first_fire=at_fire, settled_s=settled, wall=wall_info,
        notes=_merge_no_h(notes),
    )


def regular_end_times(start: float, end: float,
                      every: float = DEFAULT_CHECK_INTERVAL_S) -> NDArray[np.float64]:
    """The replay's regular grid of end times: every ``every`` s after ``start``, up to ``end``."""
    n = int(math.floor((end - start) / every + 1e-9))
    return start + every * np.arange(1, n + 1, dtype=np.float64)


def _grid(out_t: NDArray[np.float64], start: float, every: float,
          times: Sequence[float] | None) -> NDArray[np.float64]:
    """End times, snapped to the last output time at or before each; the run's end last."""
    end = float(out_t[-1])
    if times is None:
        targets = regular_end_times(start, end, every)
    else:
        targets = np.asarray(list(times), dtype=float)
        bad = targets[~np.isfinite(targets) | (targets <= start) | (targets > end + TIME_EPS_S)]
        if bad.size:
            raise AnalysisInputError("times", float(bad[0]),
                                     f"end times in ({start:g}, {end:.10g}] s "
                                     "(after run.mass_flow_start, up to the end of the run)")
    at = np.searchsorted(out_t, targets + TIME_EPS_S, side="right") - 1
    snapped = out_t[at[at >= 0]]
    snapped = snapped[snapped > start + TIME_EPS_S]
    return np.unique(np.concatenate([snapped, [end]]))


def _updates(case: Case, run: RunDir, temps: pd.DataFrame,
             end: float) -> tuple[pd.DataFrame, float]:
    """The coupling updates up to the end of the temperature series, with the whole-surface h
    the stop rule uses (:func:`drumflow.analysis.published.coupling_h`), and the DEM time step."""
    air_heat = read_csv(run.air_heat_csv, "the heat the air took at each coupling update",
                        columns=_AIR_HEAT_FINITE, finite=_AIR_HEAT_FINITE, min_rows=1)
    try:
        coupling = coupling_h(case, air_heat, temps)
    except AnalysisInputError as exc:
        raise RunDirectoryError(f"{run.air_heat_csv} with {run.mean_temperature_csv}: {exc}") from exc
    table = air_heat[["step", "time_s", "steps"]].copy()
    table["particles"] = air_heat["particles"] if "particles" in air_heat else case.particle_count
    table["h_W_m2K"] = coupling.series["h_W_m2K"].to_numpy(float)
    step = table["step"].to_numpy(float)
    dt = float(np.median(table["time_s"].to_numpy(float)[step > 0] / step[step > 0]))
    table["held_s"] = table["steps"].to_numpy(float) * dt
    # A run stopped part way logged one update past its last output; it has no temperature.
    return table[table["time_s"] <= end + TIME_EPS_S].reset_index(drop=True), dt


def _row(t: float, case: Case, run: RunDir, result: MethodologyResult | None,
         falling_mass: FallingMassMode, temps: pd.DataFrame, crossings: pd.DataFrame,
         updates: pd.DataFrame, monitor: StopMonitor, wall: NDArray[np.float64],
         tolerance: float, min_time: float, notes: list[str]) -> dict[str, Any]:
    """Everything a run stopped at ``t`` reports."""
    start = float(case.run.mass_flow_start)
    row: dict[str, Any] = {"time_s": t}
    # (b), (c): the methodology on the series up to t.
    if result is None:
        try:
            result = analyse_run(run.root, falling_mass=falling_mass, until=t)
        except NoHeatTransferError as exc:
            notes.append(f"no h at {t:.4g} s: {str(exc).split(': ', 1)[-1]}")
    if result is None:
        row.update(mass_flow_kg_s=math.nan, mass_flow_half_width_kg_s=math.nan, h_W_m2K=math.nan,
                   h_half_width_W_m2K=math.nan, h_window_W_m2K=math.nan)
    else:
        steps = result.steps
        valid = steps["valid"].to_numpy(bool)
        dt_step = steps["dt_s"].to_numpy(float)
        h = steps["h_W_m2K"].to_numpy(float)
        window = steps["in_mass_flow_window"].to_numpy(bool)
        in_h = valid & window
        flow = batch_means(steps["falling_mass_in_step_kg"].to_numpy(float)[window] / dt_step[window],
                           dt_step[window])
        row.update(
            mass_flow_kg_s=result.falling_mass_flow_kg_s,
            mass_flow_half_width_kg_s=flow.half_width,
            h_W_m2K=result.h_mean_w_m2k,
            h_half_width_W_m2K=batch_means(h[valid], dt_step[valid]).half_width,
            h_window_W_m2K=(float(np.sum(h[in_h] * dt_step[in_h]) / np.sum(dt_step[in_h]))
                            if in_h.any() else math.nan),
        )
    upto = crossings[crossings["time"] <= t + TIME_EPS_S]
    eq57 = falling_mass_flow(upto, float(monitor.rule["particle_mass_kg"]), start=start)
    row["eq57_mass_flow_kg_s"] = eq57.mass_flow_kg_s if eq57.crossings >= 2 else math.nan
    row.update(_steady_mass_flow(temps, start, t, discharge_cycle(case)))

    # The stop rule on the updates up to t.
    n = int(np.searchsorted(updates["time_s"].to_numpy(float), t + TIME_EPS_S, side="right"))
    state, narrow, h_window = rule_verdict(monitor, n, t, tolerance, min_time)
    h_iv = state.intervals["h_W_m2K"]
    m_iv = state.intervals["falling_mass_flow_kg_s"]
    row.update(monitor_h_W_m2K=h_iv.mean, monitor_h_rel_half_width=h_iv.relative_half_width,
               monitor_mass_flow_kg_s=m_iv.mean,
               monitor_mass_flow_rel_half_width=m_iv.relative_half_width,
               converged=state.converged, intervals_within_tolerance=narrow, reason=state.reason)

    # (a): read at 3.5 s, or extrapolated with the window's whole-surface h.
    times = temps["time_s"].to_numpy(float)
    series = temps["mean_temperature_C"].to_numpy(float)
    if t >= TEMPERATURE_TIME_S - 1e-9:  # temperature_at's own slack
        row.update(temperature_C=temperature_at(times, series, TEMPERATURE_TIME_S),
                   temperature_half_width_K=0.0, temperature_extrapolated=False)
    else:
        t_air = case.air.inlet_temperature_C
        rate = (case.particle_count * math.pi * case.particles.diameter**2
                / (case.particle_mass_total * case.particles.heat_capacity))  # 1/(s W/(m2 K))
        lead = TEMPERATURE_TIME_S - t
        excess = (float(np.interp(t, times, series)) - t_air) * math.exp(-h_window.mean * rate * lead)
        row.update(temperature_C=t_air + excess,
                   temperature_half_width_K=abs(excess) * rate * lead * h_window.half_width,
                   temperature_extrapolated=True)
    # Wall time of the updates that ended by t.
    done = (updates["time_s"].to_numpy(float) + updates["held_s"].to_numpy(float)
            <= t + TIME_EPS_S)
    row["wall_s"] = float(np.sum(wall[done, 0] + wall[done, 1]))
    row["wall_estimated_share"] = (float(np.sum(wall[done, 1]) / row["wall_s"])
                                   if row["wall_s"] > 0 else math.nan)
    return row


def _steady_mass_flow(temps: pd.DataFrame, start: float, t: float,
                      period: float) -> dict[str, float]:
    """The falling mass flow of the cascading bed: the window's per-output-step rate from the
    end of its start-up transient to ``t``, over whole lifter cycles of ``period`` s.

    The interval is the online rule's (:func:`drumflow.convergence.cycle_means`, as
    :meth:`drumflow.coupling.stop.StopMonitor.intervals` forms it, here on the output steps): the
    cut is MSER-5 on the rate less its mean profile over a cycle, up to the next whole cycle,
    and the batches are whole cycles. 20 equal batches (the replay's rule before issue 35) are
    shorter than the lifters' period and alias it: on paper model one at 12.12 s they gave
    +-3.7 % for a flow whose whole cycles scatter by +-1.2 % (``docs/flow-uncertainty.md``).
    The paper's window opens at a fixed 1 s, while the flights are still filling for the first
    time, so its average keeps rising with the run's length; the steady flow does not.
    """
    times = temps["time_s"].to_numpy(float)
    mass = temps["falling_mass_kg_in_step"].to_numpy(float)
    # Row k holds the mass fallen in (t_{k-1}, t_k]: in the window when that interval is.
    inside = (np.r_[np.nan, times[:-1]] >= start - TIME_EPS_S) & (times <= t + TIME_EPS_S)
    inside &= np.isfinite(mass)
    gaps = np.r_[np.nan, np.diff(times)][inside]
    rate = mass[inside] / gaps
    if rate.size < 2 * MSER_BATCH:
        return {"steady_mass_flow_kg_s": math.nan, "steady_mass_flow_half_width_kg_s": math.nan,
                "steady_start_s": math.nan}
    flow = cycle_means(rate, gaps, times[inside], period, start, truncation="samples")
    return {"steady_mass_flow_kg_s": flow.mean, "steady_mass_flow_half_width_kg_s": flow.half_width,
            "steady_start_s": flow.window_start}


def _merge_no_h(notes: list[str]) -> tuple[str, ...]:
    """One note for the early times without h (they give the same reason), then the rest."""
    early = [n for n in notes if n.startswith("no h at ")]
    rest = [n for n in notes if not n.startswith("no h at ")]
    if early:
        times = ", ".join(n.split(" ")[3] for n in early)
        rest.insert(0, f"no h at {times} s (the methodology raised NoHeatTransferError; at the "
                       f"first: {early[0].split(': ', 1)[-1]})")
    return tuple(dict.fromkeys(rest))
