"""Where the time of a coupled run goes: LIGGGHTS' own timing breakdowns and the loop's wall times.

How to use::

    drumflow profile RUN_DIR                 # table of 0.5 s windows; writes RUN_DIR/post/profile*
    drumflow profile RUN_DIR --window 0.1    # finer windows (simulated seconds)

    from drumflow.bench.profile import profile_run, write_profile
    profile = profile_run(Path("runs/m2_air"))       # RunProfile: intervals, windows, loops
    profile.windows[["window_start_s", "pair_pct", "walls_pct", "particle_steps_per_s"]]
    write_profile(profile, Path("runs/m2_air/post"))  # profile.csv, profile_windows.csv, .png

The coupling loop (:mod:`drumflow.coupling.driver`) ends about every 200 DEM steps, and its last
interval, with ``run N pre no post yes``, so LIGGGHTS prints its breakdown of that interval:
``Pair``, ``Neigh``, ``Comm``, ``Outpt``, ``Modfy`` (all fixes, timed one by one under
``modify_timing on``) and ``Other`` time with their percentages of the loop time, each fix's
time, the neighbours per atom and the neighbour-list builds. Every coupling-log row holds the
wall seconds of its interval in Python (air, drag, heat, crossings, stop rule) and in
LIGGGHTS' ``run`` call. This module joins the two.

Fix times are grouped by style: ``walls`` (mesh and primitive walls, their neighbour lists and
motion), ``conduction`` (heat/gran/conduction and the temperature equation), ``air_drag``
(addforce) and ``integration`` (nve/sphere, gravity); the rest are ``other_fixes``.

With more than one MPI rank, the fixes' own communication (forward communication of
temperatures, mesh data) is stamped as ``Comm`` and also timed inside the fix, so LIGGGHTS'
``Other`` (the loop time minus everything else) goes negative by that amount:
``comm_overlap_pct`` records it; ``comm_outside_fixes_pct`` and ``other_net_pct`` are Comm and
Other without it, and the shares of the wall time (``share_*``) count it with the fixes, once.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from drumflow._mpl import pyplot
from drumflow.coupling.log import WALL_COLUMNS, read_coupling
from drumflow.dem.thermo import LOOP_TIME
from drumflow.errors import BadFileError, RunDirectoryError
from drumflow.readers import read_json_object
from drumflow.rundir import RunDir

__all__ = [
    "BREAKDOWN",
    "FIX_GROUPS",
    "RunProfile",
    "parse_breakdowns",
    "profile_run",
    "write_profile",
]

#: LIGGGHTS' names of its timing categories and ours, in the order it prints them. A force
#: field's bond or k-space time (none in a granular run) counts with the pair time.
BREAKDOWN = {"Pair": "pair", "Bond": "pair", "Kspce": "pair", "Neigh": "neigh", "Comm": "comm",
             "Outpt": "output", "Modfy": "modify", "Other": "other"}
CATEGORIES = ("pair", "neigh", "comm", "output", "modify", "other")
#: Fix styles by what they do in a drum (the breakdown's ``Fix ID STYLE time`` lines).
FIX_GROUPS: dict[str, tuple[str, ...]] = {
    "walls": ("wall/gran", "mesh/surface", "mesh/surface/stress", "mesh/surface/planar",
              "neighlist/mesh", "contacthistory/mesh", "move/mesh"),
    "conduction": ("heat/gran/conduction", "heat/gran", "transportequation/scalar"),
    "air_drag": ("addforce",),
    "integration": ("nve/sphere", "gravity"),
}
GROUPS = (*FIX_GROUPS, "other_fixes")
#: Default width of the summary windows, simulated seconds.
WINDOW_S = 0.5

_LOOP = LOOP_TIME
_CATEGORY = re.compile(r"^(\w+)\s+time \(%\) = (\S+) \((\S+)\)")
_FIX = re.compile(r"^Fix (\S+) (\S+) time \(%\) = (\S+) \((\S+)\)")
_SCALARS = {
    "neighs_per_atom": re.compile(r"^Ave neighs/atom = (\S+)"),
    "neighbor_builds": re.compile(r"^Neighbor list builds = (\d+)"),
    "dangerous_builds": re.compile(r"^Dangerous builds = (\d+)"),
}
_ATTEMPT = re.compile(r"^log(?:\.resume-(\d+))?\.liggghts$")


def _group_of(style: str) -> str:
    for group, styles in FIX_GROUPS.items():
        if style in styles:
            return group
    return "other_fixes"


def _thermo_row(parts: list[str]) -> tuple[int, float] | None:
    """(step, simulated time) of a thermo row (``step v_sim_time ...``), or None."""
    if len(parts) < 2 or not parts[0].isdigit():
        return None
    try:
        return int(parts[0]), float(parts[1])
    except ValueError:
        return None


def parse_breakdowns(text: str) -> pd.DataFrame:
    """Every ``run`` of a LIGGGHTS log: its loop time and, where printed, the timing breakdown.

    Parameters
    ----------
    text
        A LIGGGHTS 3.8 log (``log.liggghts``), whole or in part.

    Returns
    -------
    pandas.DataFrame
        One row per ``Loop time`` line: ``step`` (the last step of the run, from the thermo row
        just before), ``sim_time_s`` (that row's second column, the deck's ``v_sim_time``),
        ``steps``, ``atoms``, ``procs``, ``loop_s``, ``breakdown`` (True when the run ended with
        ``post yes``), ``<category>_s`` and ``<category>_pct`` for pair, neigh, comm, output,
        modify and other (LIGGGHTS' numbers; modify NaN without ``modify_timing``), the fix
        groups' ``<group>_s`` and ``<group>_pct`` (:data:`FIX_GROUPS`, NaN without fix
        timings), ``neighs_per_atom``, ``neighbor_builds`` and ``dangerous_builds``.
    """
    rows: list[dict[str, Any]] = []
    last: tuple[int, float] | None = None
    current: dict[str, Any] | None = None
    set_up = False
    for line in text.splitlines():
        parts = line.split()
        if line.startswith("Setting up run"):
            set_up = True
            continue
        m = _LOOP.match(line)
        if m:
            step, sim_time = last if last is not None else (np.nan, np.nan)
            current = {"step": step, "sim_time_s": sim_time, "steps": int(m.group(3)),
                       "atoms": int(m.group(4)), "procs": int(m.group(2)),
                       "loop_s": float(m.group(1)), "breakdown": False, "set_up": set_up}
            set_up = False
            rows.append(current)
            continue
        row = _thermo_row(parts)
        if row is not None:
            last = row
            continue
        if current is None:
            continue
        m = _FIX.match(line)
        if m:
            group = _group_of(m.group(2))
            current[f"{group}_s"] = current.get(f"{group}_s", 0.0) + float(m.group(3))
            current[f"{group}_pct"] = current.get(f"{group}_pct", 0.0) + float(m.group(4))
            continue
        m = _CATEGORY.match(line)
        if m and m.group(1) in BREAKDOWN:
            name = BREAKDOWN[m.group(1)]
            current["breakdown"] = True
            current[f"{name}_s"] = current.get(f"{name}_s", 0.0) + float(m.group(2))
            current[f"{name}_pct"] = current.get(f"{name}_pct", 0.0) + float(m.group(3))
            continue
        for key, pattern in _SCALARS.items():
            m = pattern.match(line)
            if m:
                current[key] = float(m.group(1))
    _builds_since_previous(rows)
    columns = ["step", "sim_time_s", "steps", "atoms", "procs", "loop_s", "breakdown",
               *(f"{c}_{u}" for c in CATEGORIES for u in ("s", "pct")),
               *(f"{g}_{u}" for g in GROUPS for u in ("s", "pct")), *_SCALARS, *_SINCE]
    return pd.DataFrame(rows).reindex(columns=columns)


#: Increments of LIGGGHTS' cumulative counters between two printed breakdowns, and the steps
#: they cover.
_SINCE = ("neighbor_builds_since", "dangerous_builds_since", "steps_since")


def _builds_since_previous(rows: list[dict[str, Any]]) -> None:
    """Turn LIGGGHTS' build counts into increments, in place.

    "Neighbor list builds" and "Dangerous builds" count from the last run that was set up
    ("Setting up run"), not per run: the coupling loop's ``run N pre no`` does not reset them,
    so a breakdown every few intervals prints a running total (measured: 11, 22, 34, 45 ... on
    consecutive 34-step runs of paper model two). Summing those totals overcounts the builds
    several times; the increments over the steps since the previous printed count do not.
    """
    builds = dangerous = 0.0
    since_step: float | None = None
    for row in rows:
        if row["set_up"] or since_step is None:
            builds = dangerous = 0.0
            since_step = float(row["step"]) - row["steps"]
        if "neighbor_builds" not in row:
            continue
        row["neighbor_builds_since"] = row["neighbor_builds"] - builds
        row["dangerous_builds_since"] = row.get("dangerous_builds", 0.0) - dangerous
        row["steps_since"] = float(row["step"]) - since_step
        builds, dangerous = row["neighbor_builds"], row.get("dangerous_builds", 0.0)
        since_step = float(row["step"])


@dataclass(frozen=True)
class RunProfile:
    """Where a run's time went.

    Attributes
    ----------
    intervals
        One row per sampled interval (a run that printed its breakdown), by step; see
        :func:`profile_run`.
    windows
        The summary per window of simulated time.
    loops
        Every LIGGGHTS run of the DEM stage with steps: ``attempt, step, steps, atoms, loop_s``
        (the rates of the windows).
    window_s
        Width of the windows, simulated seconds.
    """

    intervals: pd.DataFrame
    windows: pd.DataFrame
    loops: pd.DataFrame
    window_s: float


def _attempts(rundir: RunDir) -> list[tuple[int, Path]]:
    """(start step, log) of the first DEM run and every resume, by start step."""
    found = []
    for path in rundir.dem_logs():
        m = _ATTEMPT.match(path.name)
        if m:
            found.append((int(m.group(1) or 0), path))
    return sorted(found)


def _clock(rundir: RunDir) -> tuple[float | None, tuple[int, float]]:
    """The DEM step and the (step, time) the run's clock counts from: (0, 0) but for a
    settings-study variant with another step, whose coupling input names its restart's."""
    spec_path = rundir.dem / "coupling.json"
    what = "the coupling loop's input"
    spec = read_json_object(spec_path, what) if spec_path.is_file() else {}
    try:
        step, time = spec.get("clock_origin", [0, 0.0])
        origin = (int(step), float(time))
        spec_step = float(spec["time_step"]) if "time_step" in spec else None
    except (TypeError, ValueError):
        # A word, a list of another length, or null: int() and float() said so without the file.
        raise BadFileError(spec_path, f"clock_origin = {spec.get('clock_origin')!r}, time_step = "
                           f"{spec.get('time_step')!r}: expected [step, time in s] and a time "
                           "step in s", what) from None
    if not math.isfinite(origin[1]) or (spec_step is not None
                                        and not (math.isfinite(spec_step) and spec_step > 0)):
        raise BadFileError(spec_path, f"clock_origin = {spec.get('clock_origin')!r}, time_step = "
                           f"{spec.get('time_step')!r}: expected finite numbers, a positive step",
                           what)
    value = (rundir.manifest.get("time_step") or {}).get("time_step")
    if value:
        return float(value), origin
    return spec_step, origin


def _runs(rundir: RunDir) -> pd.DataFrame:
    """The runs with steps of every attempt; a resumed attempt supersedes what earlier ones
    ran past its start (as :func:`drumflow.coupling.log.read_coupling` does for the heat)."""
    attempts = _attempts(rundir)
    frames = []
    for i, (_, path) in enumerate(attempts):
        runs = parse_breakdowns(path.read_text(errors="replace"))
        runs = runs[runs["steps"] > 0]
        end = attempts[i + 1][0] if i + 1 < len(attempts) else math.inf
        runs = runs[runs["step"] <= end].assign(attempt=path.name)
        frames.append(runs)
    if not frames:
        return pd.DataFrame()
    return pd.concat(frames, ignore_index=True).sort_values("step", kind="stable").reset_index(drop=True)


def _shares(table: pd.DataFrame) -> pd.DataFrame:
    """Shares of each interval's wall time (python + LIGGGHTS' run, or the loop alone when the
    coupling log has no wall times), fix communication counted once (module docstring)."""
    out = pd.DataFrame(index=table.index)
    overlap = (-table["other_pct"]).clip(lower=0.0)
    has_wall = table["python_wall_s"].notna() & table["liggghts_wall_s"].notna()
    wall = (table["python_wall_s"] + table["liggghts_wall_s"]).where(has_wall, table["loop_s"])
    loop = table["loop_s"] / wall
    out["share_python"] = (table["python_wall_s"] / wall).where(has_wall, 0.0)
    out["share_run_overhead"] = ((table["liggghts_wall_s"] - table["loop_s"]) / wall).where(has_wall, 0.0)
    timed_fixes = table["modify_pct"].notna()
    for name in ("pair", "neigh", "output"):
        out[f"share_{name}"] = table[f"{name}_pct"] / 100.0 * loop
    out["share_comm"] = (table["comm_pct"] - overlap.where(timed_fixes, 0.0)) / 100.0 * loop
    for group in GROUPS:
        out[f"share_{group}"] = table[f"{group}_pct"].fillna(0.0) / 100.0 * loop
    out["share_other"] = table["other_pct"].clip(lower=0.0) / 100.0 * loop
    return out


def _windows(intervals: pd.DataFrame, loops: pd.DataFrame, coupling: pd.DataFrame,
             window_s: float) -> pd.DataFrame:
    rows = []
    span = float(loops["end_time_s"].max()) if len(loops) else 0.0
    for k in range(max(1, math.ceil(span / window_s - 1e-9))):
        # (window_s may be infinite: one window over the whole run.)
        lo, hi = (k * window_s if k else 0.0), (k + 1) * window_s
        sampled = intervals[(intervals["start_time_s"] >= lo) & (intervals["start_time_s"] < hi)]
        ran = loops[(loops["start_time_s"] >= lo) & (loops["start_time_s"] < hi)]
        if ran.empty:
            continue
        row: dict[str, Any] = {"window_start_s": lo, "window_end_s": hi, "steps": int(ran["steps"].sum()),
                               "sampled_intervals": len(sampled),
                               "sampled_steps": int(sampled["steps"].sum())}
        loop = float(sampled["loop_s"].sum())
        for name in (*CATEGORIES, *GROUPS):
            seconds = sampled[f"{name}_s"]
            row[f"{name}_pct"] = (100.0 * float(seconds.sum()) / loop
                                  if loop > 0 and seconds.notna().any() else np.nan)
        for name in ("comm_overlap", "comm_outside_fixes", "other_net"):
            seconds = sampled[f"{name}_pct"] / 100.0 * sampled["loop_s"]
            row[f"{name}_pct"] = 100.0 * float(seconds.sum()) / loop if loop > 0 else np.nan
        row["neighs_per_atom"] = float(sampled["neighs_per_atom"].mean()) if len(sampled) else np.nan
        covered = float(sampled["steps_since"].sum())
        row["neighbor_builds_per_1000_steps"] = (1000.0 * float(sampled["neighbor_builds_since"].sum())
                                                 / covered if covered > 0 else np.nan)
        row["dangerous_builds"] = float(sampled["dangerous_builds_since"].sum()) if len(sampled) else np.nan
        row["liggghts_particle_steps_per_s"] = float((ran["atoms"] * ran["steps"]).sum()
                                                     / ran["loop_s"].sum())
        updates = pd.DataFrame()
        if set(WALL_COLUMNS) <= set(coupling.columns):
            inside = (coupling["time_s"] >= lo) & (coupling["time_s"] < hi)
            updates = coupling[inside].dropna(subset=list(WALL_COLUMNS))
        if len(updates):
            wall = updates["python_wall_s"] + updates["liggghts_wall_s"]
            row["python_share"] = float(updates["python_wall_s"].sum() / wall.sum())
            row["particle_steps_per_s"] = float((updates["particles"] * updates["steps"]).sum() / wall.sum())
        else:
            row["python_share"] = np.nan
            row["particle_steps_per_s"] = row["liggghts_particle_steps_per_s"]
        rows.append(row)
    return pd.DataFrame(rows)


def profile_run(run_dir: Path, window_s: float = WINDOW_S) -> RunProfile:
    """Where the time of a run went, per sampled interval and per window of simulated time.

    Parameters
    ----------
    run_dir
        A run directory (``drumflow run``); its LIGGGHTS logs (``dem/log.liggghts``,
        ``dem/log.resume-*.liggghts``) and coupling logs (``dem/coupling/rank*.csv``) are read.
    window_s
        Width of the summary windows, simulated seconds.

    Returns
    -------
    RunProfile
        ``intervals``: per sampled interval ``attempt, step`` (its last step), ``start_time_s,
        end_time_s, steps, atoms, procs, loop_s``, LIGGGHTS' ``<category>_s/_pct`` (pair, neigh,
        comm, output, modify, other) and the fix groups' (walls, conduction, air_drag,
        integration, other_fixes), ``comm_overlap_pct, comm_outside_fixes_pct, other_net_pct``
        (module docstring), ``neighs_per_atom, neighbor_builds,
        dangerous_builds``, ``liggghts_particle_steps_per_s`` (atoms x steps / loop time), the
        coupling log's ``python_wall_s, liggghts_wall_s`` (NaN without them), ``python_share``,
        ``particle_steps_per_s`` (atoms x steps over both wall times, else the loop's rate) and
        the ``share_*`` of the interval's wall time (they add up to 1). ``windows``: per window
        the loop-weighted percentages, neighbours, builds per 1000 steps, dangerous builds, the
        Python share and the particle-steps per second of all intervals in it.

    Raises
    ------
    RunDirectoryError
        Not a run directory, no LIGGGHTS log, or no run in the logs printed its breakdown (a
        run made before the coupling loop asked for them).
    """
    if window_s <= 0:
        raise RunDirectoryError(f"profile window must be positive, got {window_s:g} s")
    rundir = RunDir.existing(run_dir)
    runs = _runs(rundir)
    if runs.empty:
        raise RunDirectoryError(f"{rundir.root}: no LIGGGHTS log with a run in {rundir.dem}; "
                                "run `drumflow run` first")
    dt, (origin_step, origin_time) = _clock(rundir)
    if dt is None:
        # The deck's thermo prints step and step*dt side by side.
        valid = runs[runs["step"] > 0]
        dt = float((valid["sim_time_s"] / valid["step"]).median())
    runs["end_time_s"] = origin_time + (runs["step"] - origin_step) * dt
    runs["start_time_s"] = runs["end_time_s"] - runs["steps"] * dt
    coupling = read_coupling(rundir.dem_coupling_logs, dt, (origin_step, origin_time))
    sampled = runs[runs["breakdown"]].copy()
    if sampled.empty:
        raise RunDirectoryError(
            f"{rundir.root}: no run in the LIGGGHTS logs printed its timing breakdown (a run "
            "made before the coupling loop printed them every ~200 steps)")
    sampled["start_step"] = (sampled["step"] - sampled["steps"]).astype(float)
    walls = (coupling[["step", *WALL_COLUMNS]].rename(columns={"step": "start_step"})
             if set(WALL_COLUMNS) <= set(coupling.columns)
             else pd.DataFrame(columns=["start_step", *WALL_COLUMNS], dtype=float))
    table = sampled.merge(walls.astype(float), on="start_step", how="left")
    table["comm_overlap_pct"] = (-table["other_pct"]).clip(lower=0.0).where(table["modify_pct"].notna(), 0.0)
    table["comm_outside_fixes_pct"] = table["comm_pct"] - table["comm_overlap_pct"]
    table["other_net_pct"] = table["other_pct"] + table["comm_overlap_pct"]
    table["liggghts_particle_steps_per_s"] = table["atoms"] * table["steps"] / table["loop_s"]
    wall = table["python_wall_s"] + table["liggghts_wall_s"]
    table["python_share"] = table["python_wall_s"] / wall
    table["particle_steps_per_s"] = (table["atoms"] * table["steps"] / wall).fillna(
        table["liggghts_particle_steps_per_s"])
    table = pd.concat([table, _shares(table)], axis=1)
    order = ["attempt", "step", "start_time_s", "end_time_s", "steps", "atoms", "procs", "loop_s",
             *(f"{c}_{u}" for c in CATEGORIES for u in ("pct", "s")),
             *(f"{g}_{u}" for g in GROUPS for u in ("pct", "s")), "comm_overlap_pct",
             "comm_outside_fixes_pct", "other_net_pct",
             *_SCALARS, *_SINCE, "liggghts_particle_steps_per_s", *WALL_COLUMNS, "python_share",
             "particle_steps_per_s"]
    intervals = table[order + [c for c in table.columns if c.startswith("share_")]]
    loops = runs[["attempt", "step", "steps", "atoms", "loop_s", "start_time_s", "end_time_s"]]
    windows = _windows(intervals, loops, coupling, window_s)
    return RunProfile(intervals.reset_index(drop=True), windows, loops.reset_index(drop=True), window_s)


#: What the stacked plot shows, bottom to top, with its colours.
_STACK = (("share_pair", "pair", "tab:blue"), ("share_neigh", "neighbour lists", "tab:cyan"),
          ("share_walls", "walls (mesh)", "tab:brown"), ("share_conduction", "conduction", "tab:red"),
          ("share_air_drag", "air drag (addforce)", "tab:olive"),
          ("share_integration", "integration, gravity", "tab:gray"),
          ("share_other_fixes", "other fixes", "lightgray"), ("share_comm", "communication", "tab:purple"),
          ("share_output", "output", "tab:pink"), ("share_other", "other", "whitesmoke"),
          ("share_run_overhead", "run set-up/finish", "khaki"),
          ("share_python", "Python: air, drag, heat", "tab:green"))


def plot_profile(profile: RunProfile, path: Path, title: str = "") -> None:
    """Stacked shares of each sampled interval's wall time against simulated time, and the
    particle-steps per second on a second axis."""
    plt = pyplot()

    table = profile.intervals
    t = 0.5 * (table["start_time_s"] + table["end_time_s"]).to_numpy(float)
    fig, ax = plt.subplots(figsize=(8.0, 4.6), dpi=120)
    shares = [table[col].clip(lower=0.0).to_numpy(float) for col, _, _ in _STACK]
    ax.stackplot(t, *shares, labels=[label for _, label, _ in _STACK],
                 colors=[colour for _, _, colour in _STACK], step="mid" if len(t) > 1 else None)
    if len(t) == 1:
        ax.set_xlim(t[0] - 0.5 * profile.window_s, t[0] + 0.5 * profile.window_s)
    ax.set_ylim(0.0, 1.0)
    ax.set_xlabel("simulated time (s)")
    ax.set_ylabel("share of the interval's wall time")
    ax2 = ax.twinx()
    ax2.plot(t, table["particle_steps_per_s"].to_numpy(float), color="black", lw=1.4, marker=".",
             label="particle-steps per second")
    ax2.set_ylabel("particle-steps per second")
    ax2.set_ylim(bottom=0.0)
    handles, labels = ax.get_legend_handles_labels()
    h2, l2 = ax2.get_legend_handles_labels()
    ax.legend(handles + h2, labels + l2, fontsize=7, loc="upper center", ncol=4,
              bbox_to_anchor=(0.5, -0.14), frameon=False)
    ax.set_title(title or "where the time goes (sampled intervals)", fontsize=9)
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, bbox_inches="tight")
    plt.close(fig)


def write_profile(profile: RunProfile, folder: Path, title: str = "") -> dict[str, Path]:
    """Write ``profile.csv`` (sampled intervals), ``profile_windows.csv`` and ``profile.png``
    into ``folder`` (created if missing); return their paths by name."""
    folder.mkdir(parents=True, exist_ok=True)
    paths = {"intervals": folder / "profile.csv", "windows": folder / "profile_windows.csv",
             "plot": folder / "profile.png"}
    profile.intervals.to_csv(paths["intervals"], index=False, float_format="%.6g")
    profile.windows.to_csv(paths["windows"], index=False, float_format="%.6g")
    plot_profile(profile, paths["plot"], title)
    return paths
