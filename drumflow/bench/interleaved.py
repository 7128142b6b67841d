"""Arms side by side from one restart, interleaved: LIGGGHTS builds, or physics levels
(issue 35, items 5 and 6; issue 31, the levels' cost).

``drumflow bench CASE --from RUN_DIR --builds debian,/opt/drumflow/liggghts-native`` runs the
settings study's baseline (:mod:`drumflow.bench.settings`: the run's own deck, ``steps`` DEM
steps through the real coupling loop, drag and heat included) with each build;
``--levels`` runs it at each physics level the run has (one-way lumped; heat inside the
granule; air that warms; and air around the bed), by leaving the later levels' parts out of the
loop's input (and, below the air around the bed, by giving the loop the empty drum's air).
Each arm runs once per repeat, in the order A-B-A-B-A-B, so that a slow stretch of the machine
falls on every arm alike rather than on whichever ran second. Written: ``builds.csv`` or
``levels.csv`` (one row per run: arm, repeat, wall seconds, particle-steps per second, the load
average before the run, and for builds the physics check against the first arm's first run and
the library the loop really loaded) and the ``.json`` beside it (per arm the median and range,
the ratio to the first arm as the median of the per-repeat ratios with their range, the
machine, each build's flags).

Contention is measured, not guessed from the load average (which a run's own ranks keep up for a
minute after it): the machine's busy CPU time over the run (``/proc/stat``) less the CPU time of
the run's own processes (``getrusage`` of the waited-for children) is the CPU that other programs
took meanwhile; a run where they took more than :data:`BUSY_OTHER_CORES` of a core on average is
marked ``contended``. Its time is kept, and the summary counts them.

Physics check (builds only: levels change the physics on purpose): a build with other flags
changes round-off (-march=native contracts a*b+c into fused multiply-adds), which a granular bed
amplifies; the end state is held to the settings study's tolerances
(:func:`drumflow.bench.settings.physics_check`), not to equality.
"""

from __future__ import annotations

import json
import math
import os
import resource
import statistics
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import pandas as pd

from drumflow.bench.settings import (
    machine_info,
    measure_variant,
    open_coupled_run,
    physics_check,
    prepare_variant,
)
from drumflow.case import Case
from drumflow.coupling.spec import COUPLING_FILE, LIBRARY_RECORD, driver_command
from drumflow.dem.stage import finished_loop
from drumflow.errors import SettingsStudyError, SolverNotFoundError
from drumflow.machine_load import BUSY_OTHER_CORES, machine_busy_cpu_s
from drumflow.runner import (
    DEBIAN_LIGGGHTS,
    LIBRARY_VARIABLE,
    SYSTEM_LIBRARY,
    LaunchProfile,
    LiggghtsBuild,
    Runner,
    liggghts_build,
)

__all__ = ["BUSY_OTHER_CORES", "DEBIAN", "Arm", "Comparison", "build_arms", "level_arms", "run_arms"]

#: The name that means the Debian package's LIGGGHTS.
DEBIAN = "debian"
#: The coupling loop's inputs of each physics level above the paper's (drumflow.coupling.spec).
_INTERIOR, _WARMING = "interior", "warming"


@dataclass(frozen=True)
class Arm:
    """One side of the comparison.

    Attributes
    ----------
    name, description
        For the table.
    build
        The LIGGGHTS the loop loads.
    drop
        Keys of the run's coupling-loop input left out (a physics level's parts).
    one_way_field
        The air field the arm's loop samples instead of the run's (the levels below the air
        around the bed fly through the empty drum's one-way air, ``air/field.npz``).
    same_physics
        Whether the end state must match the first arm's (builds) or may not (levels).
    """

    name: str
    description: str
    build: LiggghtsBuild = DEBIAN_LIGGGHTS
    drop: tuple[str, ...] = ()
    same_physics: bool = True
    one_way_field: Path | None = None


@dataclass(frozen=True)
class Comparison:
    """What :func:`run_arms` measured and wrote.

    Attributes
    ----------
    table
        One row per run (arm, repeat, timings, checks).
    summary
        Per arm: median and range of the wall time and of particle-steps per second, and the
        ratio of the first arm's wall time to this arm's (median of the per-repeat ratios).
    csv, json
        The files written.
    """

    table: pd.DataFrame
    summary: dict[str, Any]
    csv: Path
    json: Path


def build_arms(names: Sequence[str]) -> list[Arm]:
    """``debian`` or an install prefix per name -> one arm each; refused by name if not a build.

    Raises
    ------
    SettingsStudyError
        Fewer than two builds, the same one twice, or a prefix without ``bin/liggghts`` and
        ``lib/libliggghts.so.3``.
    """
    names = [n.strip() for n in names if n.strip()]
    if len(names) < 2 or len(set(names)) != len(names):
        raise SettingsStudyError(f"--builds {','.join(names)}: give two or more different builds "
                                 f"('{DEBIAN}' or an install prefix), e.g. "
                                 f"{DEBIAN},/opt/drumflow/liggghts-native")
    arms = []
    for name in names:
        try:
            build = DEBIAN_LIGGGHTS if name == DEBIAN else liggghts_build(name)
        except SolverNotFoundError as exc:
            # A name typed on the command line: bad input (exit 2), not a failed run.
            raise SettingsStudyError(f"--builds: {exc.reason}") from None
        flags = build.flags or "the Debian package (-O2, no -march)"
        arms.append(Arm(name, flags.splitlines()[0][:120], build))
    return arms


def level_arms(driver: dict[str, Any], run_dir: Path) -> list[Arm]:
    """The physics levels of a run's coupling-loop input ``driver``: one-way lumped, then each
    level the run has, in the order they build on one another.

    Raises
    ------
    SettingsStudyError
        The run has no level above the paper's (neither ``particles.interior = "shells"`` nor
        ``air.warming``), or has air around the bed without the empty drum's air beside it.
    """
    # A run of air around the bed (its field the bed states' phases): the levels below it take
    # the empty drum's one-way air, which the run solved first and kept beside them.
    around = (driver.get("field") or {}).get("kind") == "phases"
    empty = run_dir / "air" / "field.npz" if around else None
    if empty is not None and not empty.is_file():
        raise SettingsStudyError(f"--levels: {run_dir} has air around the bed but not the empty "
                                 f"drum's air {empty} that the levels below it fly through")
    arms = [Arm("one-way lumped", "the paper's level: one temperature per particle, air at the "
                "inlet temperature", drop=(_INTERIOR, _WARMING), same_physics=False,
                one_way_field=empty)]
    if _INTERIOR in driver:
        arms.append(Arm("shells", "heat inside the granule (particles.interior = 'shells')",
                        drop=(_WARMING,), same_physics=False, one_way_field=empty))
    if _WARMING in driver:
        arms.append(Arm("shells + warming" if _INTERIOR in driver else "warming",
                        "and air that warms (air.warming = true)", same_physics=False,
                        one_way_field=empty))
    if around and _WARMING in driver:
        arms.append(Arm("air around the bed", "and the air of the bed's states, which goes around "
                        "the bed (air.bed_states)", same_physics=False))
    if len(arms) == 1:
        raise SettingsStudyError(f"--levels: {run_dir} was run at the paper's level only; give a run "
                                 "with particles.interior = 'shells' and/or air.warming = true")
    return arms


def _profile_for(build: LiggghtsBuild) -> LaunchProfile:
    profile = LaunchProfile()
    profile.liggghts = build.executable
    # Set either way: the Debian library by its soname even when the environment names a build.
    profile.env[LIBRARY_VARIABLE] = build.library or SYSTEM_LIBRARY
    return profile


def _library_used(folder: Path) -> str | None:
    record = folder / "dem" / LIBRARY_RECORD
    text = record.read_text().strip() if record.is_file() else ""
    return text if text and text != "None" else None


def library_matches(used: str | None, build: LiggghtsBuild, others: Sequence[LiggghtsBuild]) -> bool:
    """Whether the library a run mapped is its build's: the build's own file for a build from
    source; for the Debian package, a libliggghts that is none of the other builds' files."""
    if used is None:
        return False
    real = os.path.realpath(used)
    if build.library is not None:
        return real == os.path.realpath(build.library)
    return all(o.library is None or real != os.path.realpath(o.library) for o in others)


def children_cpu_s() -> float:
    """CPU seconds of this process's waited-for descendants (the runs' mpirun and its ranks)."""
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


def _stats(values: list[float]) -> dict[str, float]:
    return {"median": statistics.median(values), "min": min(values), "max": max(values)}


def summarise(table: pd.DataFrame, names: Sequence[str]) -> dict[str, Any]:
    """Per arm: median and range of the timings; the first arm's wall time over this arm's as
    the median of the per-repeat ratios (each repeat's runs are neighbours in time): above 1 is
    faster than the first arm."""
    ok = table[table["status"] == "ok"]
    base = ok[ok["arm"] == names[0]].set_index("repeat")["coupled_wall_s"]
    first = ok[ok["arm"] == names[0]]
    base_loop = statistics.median(first["python_wall_s"].astype(float)) if len(first) else math.nan
    base_wall = statistics.median(first["coupled_wall_s"].astype(float)) if len(first) else math.nan
    out: dict[str, Any] = {}
    for name in names:
        rows = ok[ok["arm"] == name]
        if rows.empty:
            out[name] = {"runs": 0}
            continue
        mine = rows.set_index("repeat")["coupled_wall_s"]
        ratios = [float(base[r] / mine[r]) for r in mine.index if r in base.index]
        checked = rows["physics_ok"].dropna()
        out[name] = {
            "runs": len(rows), "contended_runs": int(rows["contended"].sum()),
            "coupled_wall_s": _stats(rows["coupled_wall_s"].astype(float).tolist()),
            "particle_steps_per_s": _stats(rows["particle_steps_per_s"].astype(float).tolist()),
            # The loop's own work (air, drag, heat, shells, the air's temperature) and LIGGGHTS':
            # a physics level adds to the first, a build changes the second.
            "python_wall_s": _stats(rows["python_wall_s"].astype(float).tolist()),
            "liggghts_wall_s": _stats(rows["liggghts_wall_s"].astype(float).tolist()),
            # Levels run the same deck, so LIGGGHTS' work is the same in every arm and its run-to-
            # run noise (several per cent) is no part of a level's cost: the level adds loop time
            # only. Its cost against the first arm is then 1 + (extra loop time) / (first arm's
            # wall time), medians; for builds it means nothing (they change LIGGGHTS' time).
            "loop_cost_vs_first": 1.0 + (statistics.median(rows["python_wall_s"].astype(float))
                                         - base_loop) / base_wall,
            "speedup_vs_first": _stats(ratios) if ratios else None,
            "physics_ok": bool(checked.astype(bool).all()) if len(checked) else None,
            "library_ok": bool(rows["library_ok"].all()),
        }
    return out


def run_arms(case: Case, run_dir: Path, out: Path, arms: Sequence[Arm] | None = None,
             builds: Sequence[str] | None = None, steps: int = 200, ranks: int = 2, repeats: int = 3,
             restart_step: int | None = None, timeout: float = 3600.0,
             on_run: Callable[[str, int, int, int, dict[str, Any] | None], None] | None = None,
             ) -> Comparison:
    """Run the baseline deck once per arm and repeat, A-B-A-B...

    Parameters
    ----------
    case
        The scene; must match the run's.
    run_dir
        A coupled run with ``dem/restart/drum.STEP.restart`` files.
    out
        Folder for ``builds.csv`` (or ``levels.csv``), its ``.json`` and the runs (``runs/``).
    arms
        The arms, the first the reference; ``None``: ``builds`` if given, else the run's levels
        (:func:`level_arms`).
    builds
        ``"debian"`` or install prefixes of builds from source (:func:`build_arms`).
    steps, ranks, repeats
        DEM steps per run, MPI ranks, and how many times each arm runs.
    restart_step
        The restart to start from (default: the newest).
    timeout
        Solver time limit per run, s.
    on_run
        ``on_run(arm, repeat, index, total, row)`` before (row None) and after each run.

    Raises
    ------
    SettingsStudyError
        Bad input: steps, ranks or repeats below 1, fewer than two builds, a run without
        levels, another scene, not a coupled run.
    drumflow.errors.SolverError
        A run failed (no failure is hidden in a row: the comparison needs every arm).
    """
    for field_name, value in (("steps", steps), ("ranks", ranks), ("repeats", repeats)):
        if value < 1:
            raise SettingsStudyError(f"{field_name} = {value}: must be at least 1")
    kind = "builds" if arms is None and builds is not None else "levels" if arms is None else "arms"
    chosen = list(arms) if arms is not None else build_arms(builds) if builds is not None else None
    opened = open_coupled_run(case, run_dir, restart_step, ranks, out / "runs", "the comparison")
    rundir, driver, restart, start = opened.rundir, opened.driver, opened.restart, opened.start
    deck, deck_source, scratch = opened.deck, opened.deck_source, opened.scratch
    chosen = chosen if chosen is not None else level_arms(driver, rundir.root)
    meta: dict[str, Any] = {
        "kind": kind, "run_dir": str(rundir.root.resolve()), "restart": str(restart),
        "restart_step": start, "steps": steps, "ranks": ranks, "repeats": repeats,
        "deck": deck_source, "order": "interleaved: each repeat runs every arm once, in the order given",
        "busy_other_cores": BUSY_OTHER_CORES,
        "arms": {a.name: {"description": a.description, "build": a.build.describe(),
                          "left_out_of_the_loop": list(a.drop),
                          "air_field": str(a.one_way_field) if a.one_way_field else "the run's"}
                 for a in chosen},
        "machine": machine_info(Runner(), ranks),
    }
    rows: list[dict[str, Any]] = []
    base: dict[str, Any] | None = None
    table_name = f"{kind}.csv"
    csv_path, json_path = out / table_name, out / table_name.replace(".csv", ".json")
    names = [a.name for a in chosen]
    total = repeats * len(chosen)

    def write() -> pd.DataFrame:
        table = pd.DataFrame(rows)
        table.to_csv(csv_path, index=False, float_format="%.6g")
        summary = summarise(table, names) if not table.empty else {}
        json_path.write_text(json.dumps({**meta, "summary": summary,
                                         "results": json.loads(table.to_json(orient="records"))},
                                        indent=2))
        return table

    for repeat in range(repeats):
        for position, arm in enumerate(chosen):
            index = repeat * len(chosen) + position
            if on_run is not None:
                on_run(arm.name, repeat, index, total, None)
            folder = scratch / f"{repeat}_{position}"
            spec = {k: v for k, v in driver.items() if k not in arm.drop}
            if arm.one_way_field is not None:
                spec["field"] = {"kind": "grid", "path": str(arm.one_way_field.resolve())}
            prepare_variant(folder, rundir, restart, deck, spec, start + steps, 1.0, start)
            busy0, own0 = machine_busy_cpu_s(), children_cpu_s()
            runner = Runner(_profile_for(arm.build))
            record = runner.run("liggghts", driver_command(runner.profile, ranks, COUPLING_FILE),
                                folder / "dem", folder / "dem" / "liggghts.out", timeout=timeout,
                                check=finished_loop, follow=folder / "dem" / "log.liggghts")
            own = children_cpu_s() - own0
            other = max(0.0, machine_busy_cpu_s() - busy0 - own) / max(record.wall_time_s, 1e-9)
            row: dict[str, Any] = {"arm": arm.name, "repeat": repeat, "status": "ok",
                                   "run_cpu_s": own, "other_programs_cores": other,
                                   "contended": bool(other > BUSY_OTHER_CORES),
                                   "wall_s": record.wall_time_s, **measure_variant(folder, steps),
                                   # What really ran, from the loop's own process maps.
                                   "library": _library_used(folder)}
            row["library_ok"] = library_matches(row["library"], arm.build, [a.build for a in chosen])
            if base is None:
                base = row
            if arm.same_physics:
                row.update(physics_check(row, base))
            else:
                row["physics_ok"] = None
            rows.append(row)
            write()
            if on_run is not None:
                on_run(arm.name, repeat, index, total, row)
    table = write()
    return Comparison(table=table, summary=summarise(table, names), csv=csv_path, json=json_path)


def speedup_line(summary: dict[str, Any], name: str, levels: bool = False) -> str:
    """One line for the CLI: the arm's speed against the first arm's, median and range; for a
    level, first its cost from the loop's extra time (:func:`summarise`)."""
    entry = summary.get(name, {})
    stats = entry.get("speedup_vs_first")
    if not stats:
        return f"{name}: no run"
    ratio = (f"{stats['median']:.3f} x the first arm's speed (range {stats['min']:.3f}-"
             f"{stats['max']:.3f} over the repeats)")
    if levels:
        return (f"{name}: cost {entry['loop_cost_vs_first']:.3f} x the first arm's from its extra loop "
                f"time; wall time: {ratio}")
    return f"{name}: {ratio}"
