"""``drumflow bench``: run time against error on one reference scene.

:func:`run_bench` runs every rung of :func:`~drumflow.bench.ladder.ladder` (one setting
changed per rung) through the normal pipeline, each into its own run directory under
``out/rungs``, and writes

* ``results.csv``: per rung the time step, wall time, particle-steps per second, mean
  temperature, falling mass flow and h, and their errors against the reference (the finest
  setting), plus the speed-up against the conservative rung;
* ``results.json``: the same with the machine, the software versions and the overhead and
  noise-floor figures;
* ``pareto.png``: wall time against error, with the Pareto front.

Rungs already finished in ``out`` are reused (an interrupted bench resumes). Timing ratios
come from one bench run on one machine, side by side; nothing here is a timed unit test.

Entry point :func:`run` (``run(case, rundir, runner, inputs) -> BenchResult``); every program,
the by-hand LIGGGHTS run included, starts through the runner.
"""

from __future__ import annotations

import json
import math
import platform
import shutil
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
import pandas as pd

from drumflow.bench.ladder import (
    CONSERVATIVE,
    DEFAULT,
    NOISE_FLOOR,
    REFERENCE,
    Rung,
    apply_rung,
    ladder,
    select,
)
from drumflow.bench.pareto import pareto_front, plot_pareto
from drumflow.errors import CaseError, DrumflowError
from drumflow.physics.validation import relative_error
from drumflow.readers import read_json_object
from drumflow.rundir import RunDir
from drumflow.runner import Runner

if TYPE_CHECKING:
    from drumflow.case import Case

__all__ = ["BenchInputs", "BenchResult", "Rung", "ladder", "run", "run_bench", "TOLERANCES"]

#: What the fast-and-accurate issue accepts against the finest setting: 1% on the cooling
#: (mean temperature drop) and on h, 5% on the falling mass flow.
TOLERANCES = {"temperature": 0.01, "h": 0.01, "mass_flow": 0.05}

#: on_rung(rung, index, total, row): called after each rung.
RungCallback = Callable[[Rung, int, int, dict[str, Any]], None]


@dataclass(frozen=True)
class BenchResult:
    table: pd.DataFrame
    summary: dict[str, Any]
    csv: Path
    json: Path
    plot: Path


def _h_mean(run: Path) -> float:
    from drumflow.analysis.methodology import analyse_run

    try:
        return float(analyse_run(run).h_mean_w_m2k)
    except DrumflowError:
        return math.nan  # no air, or no valid step


def _loop_time(log: Path) -> float:
    """LIGGGHTS' own 'Loop time of X on N procs' summed over the runs of a log, s."""
    total = 0.0
    for line in log.read_text(errors="replace").splitlines():
        if line.startswith("Loop time of"):
            total += float(line.split()[3])
    return total


def _by_hand(out: Path, base: Path, processes: int, runner: Runner) -> dict[str, Any]:
    """Run the base rung's DEM deck directly with mpirun, as a user would by hand.

    Through the runner like every program (time limit, process-group kill, a log), but with
    no monitor and no drumflow stage around it: the overhead pair compares this with the
    drumflow DEM stage.
    """
    if out.exists():
        shutil.rmtree(out)
    hand, source = RunDir(out), RunDir(base, create=False)
    shutil.copytree(source.geometry, hand.geometry)
    hand.dem.mkdir(parents=True)
    for name in ("in.drum", "particles.data"):
        shutil.copy2(source.dem / name, hand.dem / name)
    hand.dem_dumps.mkdir()
    hand.dem_restart.mkdir()
    command = runner.profile.liggghts_command("in.drum", hand.dem_log.name, processes)
    record = runner.run("liggghts", command, hand.dem, hand.dem / "liggghts.out")
    return {"dem_wall_time_s": record.wall_time_s, "wall_time_s": record.wall_time_s,
            "liggghts_loop_time_s": _loop_time(hand.dem_log), "command": " ".join(command)}


def _cooling_at(run: Path, time_s: float) -> float | None:
    """Drop of the mean temperature from its start to ``time_s``, K (linear between outputs).

    Every rung is compared at the same simulated time: a run ends on a whole output step, so
    a coarser output step would otherwise end later and count more cooling.
    """
    path = RunDir(run, create=False).mean_temperature_csv
    if not path.exists():
        return None
    series = pd.read_csv(path)
    t = series["time_s"].to_numpy(dtype=float)
    T = series["mean_temperature_C"].to_numpy(dtype=float)
    if len(t) < 2 or time_s > t[-1] + 1e-9:
        return None
    return float(T[0] - np.interp(time_s, t, T))


def _row(rung: Rung, case: Case | None, summary: dict[str, Any], run: Path, status: str,
         compare_at: float | None = None) -> dict[str, Any]:
    row: dict[str, Any] = {"rung": rung.name, "group": rung.group, "description": rung.description,
                           "status": status}
    if case is not None:
        manifest = RunDir(run, create=False).manifest
        ts = manifest.get("time_step", {})
        row.update(
            time_step_s=ts.get("time_step"), fraction_of_rayleigh=ts.get("fraction_of_rayleigh"),
            steps_per_contact=ts.get("steps_per_contact"), particles=case.particle_count,
            processes=manifest.get("processes"), wall_motion=case.run.wall_motion,
        )
    row.update(
        dem_wall_time_s=summary.get("dem_wall_time_s"), wall_time_s=summary.get("wall_time_s"),
        particle_steps_per_s=summary.get("particle_steps_per_s"),
        liggghts_loop_time_s=summary.get("liggghts_loop_time_s"),
        mean_temperature_C=summary.get("mean_temperature_C"),
        cooling_K=_cooling_at(run, compare_at) if compare_at is not None else None,
        falling_mass_flow_kg_s=summary.get("falling_mass_flow_kg_s"),
        h_W_m2K=summary.get("h_W_m2K"),
    )
    return row


@dataclass(frozen=True)
class BenchInputs:
    """What the bench needs besides the reference scene.

    Attributes
    ----------
    names
        Only these rungs (the reference always runs, unless ``speed_only``).
    timeout
        Solver time limit per rung, s.
    on_rung
        Called after each rung with its row.
    on_progress
        The pipeline's progress callback, passed to every rung.
    speed_only
        Skip the reference: run times only (a scene too large for its 5% time step).
    """

    names: list[str] | None = None
    timeout: float | None = None
    on_rung: RungCallback | None = None
    on_progress: Callable[[str, float, float], None] | None = None
    speed_only: bool = False


def run_bench(
    case: Case,
    out: Path,
    names: list[str] | None = None,
    timeout: float | None = None,
    on_rung: RungCallback | None = None,
    on_progress: Callable[[str, float, float], None] | None = None,
    speed_only: bool = False,
) -> BenchResult:
    """Run the ladder for ``case`` into ``out`` and write the results files (see :func:`run`)."""
    inputs = BenchInputs(names, timeout, on_rung, on_progress, speed_only)
    return run(case, RunDir(out), Runner(), inputs)


def run(case: Case, rundir: RunDir, runner: Runner, inputs: BenchInputs) -> BenchResult:
    """Run the ladder for ``case`` into the bench directory and write the results files.

    Parameters
    ----------
    case
        The reference scene.
    rundir
        Bench directory: ``rungs/<name>`` run directories, ``results.csv``, ``results.json``,
        ``pareto.png``.
    runner
        Starts the by-hand run of the overhead pair (each rung's pipeline has its own).
    inputs
        Rungs, time limit, callbacks.
    """
    from drumflow.pipeline import run_case

    out = rundir.root
    names, timeout, on_rung = inputs.names, inputs.timeout, inputs.on_rung
    on_progress, speed_only = inputs.on_progress, inputs.speed_only
    rungs = select(ladder(case), names, speed_only)
    out.mkdir(parents=True, exist_ok=True)
    rows: list[dict[str, Any]] = []
    done: dict[str, tuple[Case, Path]] = {}
    # The overhead pair is timed side by side, never from an earlier bench: a reused run would
    # compare timings taken at different times (run-to-run spread here is several percent).
    fresh = {r.base for r in rungs if r.by_hand and r.base}
    for index, rung in enumerate(rungs):
        run = out / "rungs" / rung.name
        if rung.name in fresh and run.exists():
            shutil.rmtree(run)
        if rung.by_hand:
            base = done.get(rung.base or "")
            if base is None:
                rows.append(_row(rung, None, {}, run, "skipped: its base rung did not run"))
                continue
            base_case = base[0]
            hand = _by_hand(run, base[1], runner.profile.processes_for(base_case), runner)
            summary = read_json_object(RunDir(base[1], create=False).summary_path, "the base rung's summary")
            summary = {**summary, **hand}
            row = _row(rung, base_case, summary, base[1], "ok", case.run.time)
        else:
            try:
                rung_case = apply_rung(case, rung)
            except CaseError as exc:
                rows.append(_row(rung, None, {}, run, f"refused: {'; '.join(exc.problems)}"))
                if on_rung:
                    on_rung(rung, index, len(rungs), rows[-1])
                continue
            try:
                summary = run_case(rung_case, run, timeout=timeout, progress=on_progress, force=True)
            except DrumflowError as exc:
                rows.append(_row(rung, rung_case, {}, run, f"failed: {exc}"))
                if on_rung:
                    on_rung(rung, index, len(rungs), rows[-1])
                continue
            summary = dict(summary)
            summary["h_W_m2K"] = _h_mean(run)
            loop = sum(_loop_time(p) for p in RunDir(run, create=False).dem_logs())
            summary["liggghts_loop_time_s"] = loop or None
            done[rung.name] = (rung_case, run)
            row = _row(rung, rung_case, summary, run, "ok", case.run.time)
        rows.append(row)
        if on_rung:
            on_rung(rung, index, len(rungs), row)

    table = pd.DataFrame(rows)
    _add_errors(table)
    summary_out = _summarise(table, case)
    summary_out["software"] = runner.profile.software_versions()
    summary_out["machine"] = {"platform": platform.platform(), "cpus": runner.profile.cores,
                              "processor": platform.processor()}
    csv = out / "results.csv"
    table.to_csv(csv, index=False, float_format="%.6g")
    js = out / "results.json"
    records = json.loads(table.to_json(orient="records"))  # with the errors, NaN as null
    js.write_text(json.dumps({"summary": summary_out, "rows": records}, indent=2, default=str))
    plot = out / "pareto.png"
    plot_pareto(table, plot, TOLERANCES, title=f"drumflow bench: {case.name}")
    return BenchResult(table, summary_out, csv, js, plot)


def _add_errors(table: pd.DataFrame) -> None:
    """Errors against the reference rung, normalised score, speed-up, Pareto membership."""
    ref = table[table["rung"] == REFERENCE]
    cons = table[table["rung"] == CONSERVATIVE]

    def ref_value(col: str) -> float:
        return float(ref[col].iloc[0]) if len(ref) and pd.notna(ref[col].iloc[0]) else math.nan

    # Temperature: error of the cooling (the drop of the mean temperature by the scene's end
    # time), the quantity the air removes; relative to 90 C absolute it would look ten times
    # smaller.
    table["err_temperature"] = [relative_error(v, ref_value("cooling_K")) for v in table.get("cooling_K", [])]
    table["err_mass_flow"] = [relative_error(v, ref_value("falling_mass_flow_kg_s"))
                              for v in table.get("falling_mass_flow_kg_s", [])]
    table["err_h"] = [relative_error(v, ref_value("h_W_m2K")) for v in table.get("h_W_m2K", [])]
    # The overhead pair runs without air on purpose: timing only, its errors mean nothing.
    timing_only = table["group"] == "overhead"
    table.loc[timing_only, ["err_temperature", "err_mass_flow", "err_h"]] = math.nan
    score = []
    for _, r in table.iterrows():
        parts = [r["err_temperature"] / TOLERANCES["temperature"], r["err_h"] / TOLERANCES["h"],
                 r["err_mass_flow"] / TOLERANCES["mass_flow"]]
        finite = [p for p in parts if pd.notna(p)]
        score.append(max(finite) if finite else math.nan)
    # 1 = at the tolerance on the worst of the three; the reference scores 0.
    table["error_over_tolerance"] = score
    has_base = len(cons) and pd.notna(cons["dem_wall_time_s"].iloc[0])
    base = float(cons["dem_wall_time_s"].iloc[0]) if has_base else math.nan
    table["speedup_vs_conservative"] = base / table["dem_wall_time_s"].astype(float)
    # Everything in the DEM stage outside LIGGGHTS' own run loops (start-up, reading the mesh,
    # the coupling loop's Python, the monitor), as a share of the loop time.
    if "liggghts_loop_time_s" in table:
        loop = table["liggghts_loop_time_s"].astype(float)
        table["overhead_of_loop"] = table["dem_wall_time_s"].astype(float) / loop - 1.0
    ok = (table["status"] == "ok") & table["error_over_tolerance"].notna()
    front = pareto_front(table.loc[ok, "dem_wall_time_s"].astype(float).to_numpy(),
                         table.loc[ok, "error_over_tolerance"].astype(float).to_numpy())
    table["pareto"] = False
    table.loc[table.index[ok][front], "pareto"] = True


def _summarise(table: pd.DataFrame, case: Case) -> dict[str, Any]:
    def row(name: str) -> dict[str, Any] | None:
        r = table[table["rung"] == name]
        return None if r.empty else {k: (None if pd.isna(v) else v) for k, v in r.iloc[0].to_dict().items()}

    out: dict[str, Any] = {"scene": case.name, "tolerances": TOLERANCES}
    default, noise = row(DEFAULT), row(NOISE_FLOOR)
    if default:
        out["default"] = {k: default.get(k) for k in (
            "dem_wall_time_s", "speedup_vs_conservative", "err_temperature", "err_h", "err_mass_flow",
            "error_over_tolerance", "fraction_of_rayleigh", "steps_per_contact")}
        out["default_meets_issue"] = bool(
            (default.get("speedup_vs_conservative") or 0) >= 3.0
            and all(default.get(f"err_{k}") is not None and default[f"err_{k}"] <= tol
                    for k, tol in TOLERANCES.items()))
    if noise:
        out["noise_floor"] = {k: noise.get(f"err_{k}") for k in TOLERANCES}
    hand, mine = row("no_air_by_hand"), row("no_air")
    if hand and mine and hand.get("liggghts_loop_time_s"):
        loop = float(hand["liggghts_loop_time_s"])
        out["overhead"] = {
            "liggghts_loop_time_by_hand_s": loop,
            "by_hand_wall_s": hand["dem_wall_time_s"],
            "drumflow_dem_stage_wall_s": mine["dem_wall_time_s"],
            "drumflow_whole_run_wall_s": mine["wall_time_s"],
            "dem_stage_overhead_of_loop":
                (float(mine["dem_wall_time_s"]) - float(hand["dem_wall_time_s"])) / loop,
            "whole_run_overhead_of_loop":
                (float(mine["wall_time_s"]) - float(hand["dem_wall_time_s"])) / loop,
        }
    return out
