"""The coupling loop's logs: heat and drag the air applied, summed over MPI ranks and attempts."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pandas as pd

_NAME = re.compile(r"rank(\d+)\.(\d+)\.csv$")
#: Wall seconds of each update in Python and in LIGGGHTS' run (logs written since the loop
#: profiles itself; older logs lack them). The ranks run in lockstep, so an update takes as
#: long as its slowest rank: the maximum over ranks.
WALL_COLUMNS = ("python_wall_s", "liggghts_wall_s")


#: A logged update slower than this many times the run's median update was paused from outside
#: (a stopped process, a suspended machine), not computed. Real updates of one run differ by
#: less than 2 times (paper model two: median 9.1 s, slowest 13.3 s over 3.5-5.2 s); the pauses
#: seen were hours long.
PAUSED_FACTOR = 20.0


#: Columns of a coupling log that hold the physics: every value a finite number.
PHYSICS_COLUMNS = ("step", "steps", "heat_to_particles_W", "drag_x_N", "drag_y_N", "drag_z_N",
                   "particles")


def read_coupling(folder: Path, time_step: float,
                  origin: tuple[int, float] = (0, 0.0),
                  covers_s: float | None = None) -> pd.DataFrame:
    """One row per coupling update: step, time, steps held, heat (W) and drag (N) on all particles.

    ``origin`` is the (step, time) the clock counts from: a run that changed its step at a
    restart (a settings study's time-step variant, ``clock_origin`` in its coupling input) is
    not at ``step * time_step``.

    Each rank logs its own particles (``rank<R>.<start step>.csv``); a resumed attempt supersedes
    what earlier attempts logged from its start step on.

    ``covers_s`` (the run's last output time, for ``drumflow post``) makes the read strict: every
    physics value must be a finite number, and every rank's log of every attempt must reach
    the next attempt's start (the last attempt: ``covers_s``). A log cut short otherwise sums
    fewer updates (or fewer ranks) and gives a heat balance that is wrong without a word. A
    run still going may be mid-line, so the default read is lenient.

    Returns
    -------
    pandas.DataFrame
        Columns ``step, time_s, steps, heat_to_particles_W, drag_x_N, drag_y_N, drag_z_N,
        particles, heat_removed_J`` (cumulative heat taken from the particles), sorted by step;
        empty when the run had no air. Logs that record wall times add ``python_wall_s,
        liggghts_wall_s`` last (the slowest rank's wall seconds of the update; NaN for an update
        of an older attempt without them, or one cut by an interrupt).

    Raises
    ------
    BadFileError
        With ``covers_s``: a log that is empty, not a table, holds a non-finite value, or ends
        before the time it must reach (the file, its last time and that time named).
    """
    from drumflow.readers import read_csv

    attempts: dict[int, list[pd.DataFrame]] = {}
    files: dict[int, list[tuple[Path, pd.DataFrame]]] = {}
    for path in sorted(folder.glob("rank*.csv")):
        m = _NAME.search(path.name)
        if not m:
            continue
        if covers_s is not None:
            frame = read_csv(path, "a coupling log", columns=PHYSICS_COLUMNS, finite=PHYSICS_COLUMNS)
        else:
            try:
                frame = pd.read_csv(path)
            except pd.errors.EmptyDataError:  # created, not yet written (a run starting)
                continue
        files.setdefault(int(m.group(2)), []).append((path, frame))
        if not frame.empty:
            attempts.setdefault(int(m.group(2)), []).append(frame)
    if not attempts:
        return pd.DataFrame()
    starts = sorted(attempts)
    if covers_s is not None:
        _require_coverage(files, starts, time_step, origin, covers_s)
    kept = []
    for i, start in enumerate(starts):
        frame = pd.concat(attempts[start], ignore_index=True)
        walls = {name: (name, "max") for name in WALL_COLUMNS if name in frame.columns}
        summed = frame.groupby("step", as_index=False).agg(
            steps=("steps", "first"),
            heat_to_particles_W=("heat_to_particles_W", "sum"),
            drag_x_N=("drag_x_N", "sum"),
            drag_y_N=("drag_y_N", "sum"),
            drag_z_N=("drag_z_N", "sum"),
            particles=("particles", "sum"),
            **walls,
        )
        end = starts[i + 1] if i + 1 < len(starts) else np.inf
        kept.append(summed[summed["step"] < end])
    table = pd.concat(kept, ignore_index=True).sort_values("step").reset_index(drop=True)
    table.insert(1, "time_s", origin[1] + (table["step"] - origin[0]) * time_step)
    # The heat is held constant over `steps` DEM steps: LIGGGHTS adds it at each of them.
    table["heat_removed_J"] = np.cumsum(-table["heat_to_particles_W"] * table["steps"] * time_step)
    present = [name for name in WALL_COLUMNS if name in table.columns]
    if not present:
        return table
    # The wall times after the physics, as in the logs (NaN for an attempt that predates them).
    return table[[c for c in table.columns if c not in present] + present]


def _require_coverage(files: dict[int, list[tuple[Path, pd.DataFrame]]], starts: list[int],
                      time_step: float, origin: tuple[int, float], covers_s: float) -> None:
    """Refuse a rank's log that ends before its attempt hands over (module notes of
    :func:`read_coupling`)."""
    from drumflow.errors import BadFileError

    def at(step: float) -> float:
        return origin[1] + (step - origin[0]) * time_step

    for i, start in enumerate(starts):
        until = at(starts[i + 1]) if i + 1 < len(starts) else covers_s
        for path, frame in files[start]:
            # An update holds its heat over `steps` DEM steps from its own step on.
            reached = (at(float(frame["step"].iloc[-1]) + float(frame["steps"].iloc[-1]))
                       if not frame.empty else at(start))
            if reached < until - max(1e-9, 1e-9 * abs(until)) - time_step:
                raise BadFileError(path, f"its updates end at {reached:.6g} s, before {until:.6g} s "
                                   f"({'the next attempt' if i + 1 < len(starts) else 'the run'}'s "
                                   "last output): cut short? The heat balance would miss the rest",
                                   "a coupling log")


def heat_removed_until(coupling: pd.DataFrame, t_end: float, time_step: float) -> float:
    """Heat the air took from the particles from the start to ``t_end`` (J).

    Each update's heat is held over its ``steps`` DEM steps; an update that reaches past
    ``t_end`` counts only up to it. The loop logs an update before LIGGGHTS runs its steps, so
    a run stopped part way (an interrupt, a time limit) has logged heat it never applied: the
    particles' temperatures end at the last output, and so must the heat they are checked
    against.

    Parameters
    ----------
    coupling
        :func:`read_coupling`'s table (``time_s``, ``steps``, ``heat_to_particles_W``).
    t_end
        The time of the last temperature output, s.
    time_step
        DEM time step, s.
    """
    start = coupling["time_s"].to_numpy(float)
    held = coupling["steps"].to_numpy(float) * time_step
    applied = np.clip(t_end - start, 0.0, held)
    return float(np.sum(-coupling["heat_to_particles_W"].to_numpy(float) * applied))


def update_walls(coupling: pd.DataFrame) -> pd.DataFrame:
    """The updates with a logged wall time, each with ``wall_s`` (Python plus LIGGGHTS) and
    ``paused`` (slower than :data:`PAUSED_FACTOR` times the median: stopped from outside, its
    time is not the code's). Empty when the logs have no wall times."""
    if not set(WALL_COLUMNS) <= set(coupling.columns):
        return pd.DataFrame(columns=[*coupling.columns, "wall_s", "paused"])
    logged = coupling.assign(wall_s=coupling["python_wall_s"] + coupling["liggghts_wall_s"])
    logged = logged[np.isfinite(logged["wall_s"])]
    median = float(logged["wall_s"].median()) if not logged.empty else np.nan
    return logged.assign(paused=logged["wall_s"] > PAUSED_FACTOR * median)


def measured_rate(updates: pd.DataFrame) -> float:
    """Particle-steps per wall second of logged, unpaused updates (:func:`update_walls` rows):
    the speed of the code that ran them, the one rate every wall-time estimate uses."""
    return float((updates["particles"] * updates["steps"]).sum() / updates["wall_s"].sum())


def coupled_wall_s(coupling: pd.DataFrame) -> dict[str, float | int] | None:
    """Wall seconds the coupling loop computed, over every attempt of a run.

    Every logged update counts its own time, except a paused one, and an update without a
    logged time (an older attempt's, one cut by an interrupt), which count the time the
    others' rate (particle-steps per wall second) gives. Set-up, the air solve and
    post-processing are not in it. None when no update logged a wall time.

    Returns
    -------
    dict
        ``wall_s`` (the total), ``measured_s``, ``estimated_s``, ``paused_updates``,
        ``unlogged_updates``, ``particle_steps_per_s`` (the rate of the measured updates).
    """
    logged = update_walls(coupling)
    good = logged[~logged["paused"].astype(bool)]
    if good.empty:
        return None
    rate = measured_rate(good)
    rest = coupling[~coupling["step"].isin(good["step"])]
    estimated = float((rest["particles"] * rest["steps"]).sum() / rate)
    measured = float(good["wall_s"].sum())
    return {"wall_s": measured + estimated, "measured_s": measured, "estimated_s": estimated,
            "paused_updates": int(logged["paused"].sum()),
            "unlogged_updates": int(len(rest) - logged["paused"].sum()),
            "particle_steps_per_s": rate}
