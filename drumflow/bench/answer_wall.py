"""Wall time of a replayed run, per coupling update: measured where the coupling logs have it,
estimated from a particle-steps-per-second rate where not (module notes of
:mod:`drumflow.bench.answer`)."""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import pandas as pd
from numpy.typing import NDArray

from drumflow.bench.answer_result import TIME_EPS_S
from drumflow.coupling.log import measured_rate, read_coupling, update_walls
from drumflow.errors import BadFileError
from drumflow.readers import read_json_object
from drumflow.report.paper_results import RUN_RECORD
from drumflow.rundir import RunDir

__all__ = ["rate_from_record", "wall_per_update"]


def wall_per_update(run: RunDir, updates: pd.DataFrame, dt: float,
                     rate: float | None) -> tuple[NDArray[np.float64], dict[str, Any]]:
    """Per update: measured wall seconds (column 0) and estimated ones (column 1), one of them
    zero; and how they were obtained."""
    measured = np.full(len(updates), math.nan)
    logged = pd.DataFrame()
    paused_updates = 0
    folder = run.dem_coupling_logs
    if folder.is_dir() and any(folder.glob("rank*.csv")):
        logs = update_walls(read_coupling(folder, dt))
        if not logs.empty:
            # The logs may reach past the post-processed series (a run still going): every
            # logged update gives the rate, those in the series their own wall time.
            # A process stopped from outside (SIGSTOP, a suspended laptop, a pre-empted node)
            # logs the pause in the update it interrupted: hours against seconds. Such an
            # update is not the code's speed; it is estimated from the rate like an unlogged one.
            paused_updates = int(logs["paused"].sum())
            logged = logs[~logs["paused"].astype(bool)]
            per_step = dict(zip(logged["step"].to_numpy(int), logged["wall_s"].to_numpy(float),
                                strict=True))
            measured = np.array([per_step.get(int(s), math.nan) for s in updates["step"]])
    work = updates["particles"].to_numpy(float) * updates["steps"].to_numpy(float)
    have = np.isfinite(measured)
    rate_source = "argument particle_steps_per_s"
    if rate is None and not logged.empty:
        rate = measured_rate(logged)
        rate_source = (f"the {len(logged)} coupling updates with logged wall times "
                       f"({float(logged['time_s'].min()):.4g}-{float(logged['time_s'].max()):.4g} s "
                       "simulated): the speed of the code that ran them")
    if rate is None:
        rate, rate_source = rate_from_record(run, updates)
    estimated = np.where(have, 0.0, work / rate if rate else math.nan)
    wall = np.column_stack([np.where(have, measured, 0.0), estimated])
    source = ("measured" if have.all() else "none" if rate is None
              else "rate" if not have.any() else "measured+rate")
    info: dict[str, Any] = {
        "source": source, "particle_steps_per_s": rate,
        "rate_source": rate_source if not have.all() else "not used",
        "measured_updates": int(have.sum()), "estimated_updates": int((~have).sum()),
        "logged_updates_with_wall_times": len(logged),
        "paused_updates": paused_updates,
        "counts": "python_wall_s + liggghts_wall_s of the slowest rank per coupling update; "
                  "no set-up, air solve or post-processing"}
    if not logged.empty:
        info["logged_wall_s_per_simulated_s"] = (float(logged["wall_s"].sum())
                                                 / (float(logged["steps"].sum()) * dt))
    return wall, info


def rate_from_record(run: RunDir, updates: pd.DataFrame) -> tuple[float | None, str]:
    """Particle-steps per wall second of a shipped run, from its ``run_record.json``."""
    path = run.root / RUN_RECORD
    if not path.is_file():
        return None, "none: no wall times logged and no run_record.json"
    what = "the shipped run's timings"
    record = read_json_object(path, what)
    wall = record.get("dem_wall_time_s")
    simulated = record.get("simulated_time_s")
    if not wall or not simulated:
        return None, f"none: {path.name} has no dem_wall_time_s"
    for name, value in (("dem_wall_time_s", wall), ("simulated_time_s", simulated)):
        # A NaN is truthy: it would give every estimated wall time as NaN, in silence.
        if (not isinstance(value, int | float) or isinstance(value, bool)
                or not math.isfinite(value) or value <= 0):
            raise BadFileError(path, f"{name} = {value!r}: expected a positive number of "
                               "seconds", what)
    t_upd = updates["time_s"].to_numpy(float)
    done = t_upd < float(simulated) - TIME_EPS_S
    work = float(np.sum(updates["particles"].to_numpy(float)[done]
                        * updates["steps"].to_numpy(float)[done]))
    return work / float(wall), (f"{path.name}: dem_wall_time_s = {float(wall):.6g} s over "
                                f"{float(simulated):.4g} s simulated "
                                f"({record.get('dem_wall_time_source', 'DEM wall time')})")
