"""LIGGGHTS settings side by side from one restart of a coupled run (issue 11, levers 3 and 4).

``drumflow bench CASE --from RUN_DIR`` runs every
:data:`~drumflow.bench.settings_variants.VARIANTS` entry (the one list of what is compared) from
the same restart file of RUN_DIR (the newest ``dem/restart/drum.STEP.restart``
unless ``restart_step``): ``steps`` DEM steps through the real coupling loop
(``python -m drumflow.coupling.driver`` under mpirun, through :class:`drumflow.runner.Runner`:
drag and heat included, a timing breakdown after every coupling interval), each in its own
folder under ``OUT/variants``, read back with :func:`drumflow.bench.profile.profile_run`.
Written: ``settings.csv`` (one row per variant: status, loop and wall seconds, steps/s,
particle-steps/s, the breakdown, speed-up over the baseline, and the physics check) and
``settings.json`` beside it with the variants, the tolerances and the machine.

Why from a restart: at the paper's scale the cost per step depends on the state of the bed
(the rate falls 2.5 times once the bed forms and again 2 times once the curtain runs), so a
comparison from a fresh start measures the wrong state; the paper runs' restarts hold the
cascading bed.

The deck is RUN_DIR/dem/in.drum.resume when the run was resumed, else one rendered the way the
DEM stage renders resume decks (:func:`drumflow.dem.stage.write_deck`). The baseline uses the
default processor grid for the rank count (:func:`drumflow.dem.deck.processors_grid`).

Physics check: after the steps, the mass-weighted mean temperature and the kinetic energy must
match the baseline's within noise. A changed neighbour list or atom order changes round-off,
which a granular bed amplifies, but not the physics: the temperatures are held to
:data:`TEMPERATURE_TOLERANCE` of the baseline's own temperature change over the steps (plus
:data:`TEMPERATURE_FLOOR_K`) and the kinetic energy to :data:`KINETIC_ENERGY_TOLERANCE`. A
variant that misses contacts (a skin too small for its rebuild rule) changes both by far more,
and LIGGGHTS counts its "dangerous builds", which the CSV also shows.

Timings are only comparable on an otherwise idle machine, so the variants run one after the
other in one call. An interrupted study resumes: variants already measured from the same
restart, step count and rank count are kept (``settings.json`` names them as resumed).
"""

from __future__ import annotations

import json
import math
import re
import shutil
import time
from collections.abc import Callable
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from drumflow.bench.profile import profile_run
from drumflow.bench.settings_variants import (
    VARIANTS,
    Variant,
    apply_variant,
    replace_deck_line,
    variant_steps,
)
from drumflow.case import Case, load_case
from drumflow.coupling.interior import InteriorSpec
from drumflow.coupling.spec import (
    COUPLING_FILE,
    CouplingSpec,
    driver_command,
    loop_heat_options,
)
from drumflow.dem.deck import processors_grid
from drumflow.dem.dumps import dump_files, dump_step, read_dump
from drumflow.dem.impacts import approaching_pairs, snapshot_kinematics, weighted_quantiles
from drumflow.dem.stage import DemInputs, finished_loop, latest_restart, write_deck
from drumflow.dem.thermo import read_thermo
from drumflow.errors import DrumflowError, SettingsStudyError
from drumflow.geometry.stage import GeometryResult
from drumflow.rundir import RunDir, cpu_model
from drumflow.runner import Runner

#: The case sections that make the DEM scene: a case may differ from the run's in anything
#: else (its name, run length, output, plant block) and still be studied from its restarts.
SCENE_SECTIONS = ("drum", "lifters", "particles", "contacts", "air")
TABLE = "settings.csv"
#: Mean temperature after the steps: within this fraction of the baseline's change over them...
TEMPERATURE_TOLERANCE = 0.02
#: ...plus this, K (the thermo output has 12 digits, ~1e-10 K at 100 °C).
TEMPERATURE_FLOOR_K = 1e-6
#: Kinetic energy after the steps, relative to the baseline's.
KINETIC_ENERGY_TOLERANCE = 0.05
RESTART_INPUT = "input"


def bed_impact_speed(rundir: RunDir, restart_step: int, case: Case) -> tuple[float, int]:
    """The median particle-particle impact speed (m/s) in the run's last snapshot at or before
    ``restart_step``, and that snapshot's step: pairs closing within a tenth of a diameter,
    weighted by closing speed (a rate of impacts; :mod:`drumflow.dem.impacts`)."""
    files = [f for f in dump_files(rundir.dem_dumps, "snap") if dump_step(f) <= restart_step]
    if not files:
        raise SettingsStudyError(f"{rundir.dem_dumps}: no snapshot at or before step {restart_step} "
                                 "to measure the bed's impact speeds")
    snap = read_dump(files[-1])
    sample = approaching_pairs(*snapshot_kinematics(snap.columns), 0.1 * case.particles.diameter)
    if len(sample) == 0:
        raise SettingsStudyError(f"{files[-1]}: no particles about to collide")
    return float(weighted_quantiles(sample.speed, sample.weight, [0.5])[0]), snap.step


def restart_file(rundir: RunDir, step: int | None) -> tuple[Path, int]:
    """The run's restart file at ``step`` (default: the newest) and its step."""
    if step is None:
        newest = latest_restart(rundir.dem_restart)
        if newest is None:
            raise SettingsStudyError(f"{rundir.dem_restart}: no drum.STEP.restart file")
        return newest
    path = rundir.dem_restart / f"drum.{step}.restart"
    if not path.is_file():
        raise SettingsStudyError(f"{path}: no such restart file")
    return path, step


def baseline_deck(rundir: RunDir, restart_step: int, ranks: int, scratch: Path,
                  driver: dict[str, Any]) -> tuple[str, str]:
    """The deck every variant starts from, reading ``input/drum.STEP.restart``, on the default
    processor grid for ``ranks``; and where it came from.

    A rendered deck is the DEM's case (the parcels of a coarse-grained case, as the run's DEM
    stage renders it) at the run's own time step (the loop's input ``time_step``). Regression:
    rendered from the particles' case, model one's parcels of 2 got half the run's time step
    (5.78e-5 s for 1.156e-4 s), so the loop's heat per update was twice the DEM's time.
    """
    case = load_case(rundir.case_toml).dem_case()
    restart = f"{RESTART_INPUT}/drum.{restart_step}.restart"
    resume_deck = rundir.dem / "in.drum.resume"
    if resume_deck.is_file():
        deck = replace_deck_line(resume_deck.read_text(), r"^read_restart\s+.*$",
                                 f"read_restart    {restart}")
        deck = replace_deck_line(deck, r"^processors\s+.*$",
                                 f"processors      {processors_grid(case, ranks)}")
        return deck, str(resume_deck)
    # Rendered as the DEM stage renders a resume deck, in a scratch run directory.
    data = json.loads(rundir.geometry_json.read_text())
    geometry = GeometryResult(**{**data, "box_lo": tuple(data["box_lo"]), "box_hi": tuple(data["box_hi"])})
    # Everything of the loop's input that changes the deck (regression: a run with shells was
    # rendered without the deck's shell temperatures, and its loop stopped on a missing shellT).
    interior = driver.get("interior")
    coupling = CouplingSpec(field=driver["field"], field_key="", interval=int(driver["interval"]),
                            temperature_C=float(driver["air_temperature_C"]),
                            pressure_kPa=float(driver["air_pressure_kPa"]), omega=float(driver["omega"]),
                            coarse_grain=float(driver.get("coarse_grain", 1.0)),
                            heat_capacity=driver.get("heat_capacity"),
                            interior=InteriorSpec.from_json(interior) if interior else None,
                            warming=driver.get("warming"))
    inputs = DemInputs.for_case(case, geometry, coupling=coupling, processes=ranks)
    source = RunDir(scratch / "_deck")
    source.dem.mkdir(parents=True, exist_ok=True)
    fake_restart = source.dem / restart  # only its name goes into the deck
    deck_name, _ = write_deck(case, source, inputs, (fake_restart, restart_step))
    deck = replace_deck_line((source.dem / deck_name).read_text(), r"^timestep\s+.*$",
                             f"timestep        {float(driver['time_step']):.12g}")
    return deck, "rendered from the case (drumflow.dem.stage.write_deck) at the run's time step"


def variant_clock(deck: str, start_step: int, start_time: float) -> str:
    """The deck with its thermo clock counting from the restart's (step, time): after a change
    of step the deck's ``step*dt`` would put the restart at another time (a regression: the
    half-step variants' thermo times were half the run's)."""
    return replace_deck_line(deck, r"^variable\s+sim_time\s+equal\s+.*$",
                         f"variable sim_time equal {start_time:.12g}+(step-{start_step})*dt")


def prepare_variant(folder: Path, rundir: RunDir, restart: Path, deck: str, driver: dict[str, Any],
             end_step: int, time_step_factor: float = 1.0, start_step: int = 0,
             loop_heat: bool = False, overlap_every_row: bool = False) -> None:
    """A run-directory-like folder: case, geometry, the deck, the restart (linked, read only)
    and the coupling loop's input for ``end_step``."""
    if folder.exists():
        shutil.rmtree(folder)
    dem = folder / "dem"
    for sub in ("dumps", "restart", "coupling", RESTART_INPUT):
        (dem / sub).mkdir(parents=True)
    shutil.copy2(rundir.case_toml, folder / "case.toml")
    shutil.copytree(rundir.geometry, folder / "geometry")
    # Linked under input/, never under restart/: LIGGGHTS writes its own restarts there.
    (dem / RESTART_INPUT / restart.name).symlink_to(restart.resolve())
    spec = {k: v for k, v in driver.items() if k != "stop"}  # exactly --steps steps
    spec.update(deck="in.drum.resume", log="log.liggghts", total_steps=end_step, tail=[],
                profile_every_steps=1)  # a breakdown after every coupling interval
    if time_step_factor != 1.0:
        dt = float(driver["time_step"])
        spec.update(time_step=dt * time_step_factor,
                    interval=max(1, round(int(driver["interval"]) / time_step_factor)),
                    clock_origin=[start_step, start_step * dt])
        deck = variant_clock(deck, start_step, start_step * dt)
    (dem / "in.drum.resume").write_text(deck)
    if overlap_every_row:
        # The loop leaves the deck's overlap formula alone: every row (or none) evaluates it.
        spec.pop("overlap_every", None)
    if loop_heat:
        # As the DEM stage sets it up for run.conduction = false.
        thermo = re.search(r"^thermo\s+(\d+)\s*$", deck, flags=re.M)
        spec.update(loop_heat_options(load_case(rundir.case_toml).particles.heat_capacity,
                                      int(thermo.group(1)) if thermo else int(spec["interval"])))
    (dem / COUPLING_FILE).write_text(json.dumps(spec, indent=2))


def measure_variant(folder: Path, steps: int) -> dict[str, Any]:
    """Timings, breakdown and end state of a finished variant."""
    profile = profile_run(folder, window_s=math.inf)
    window = profile.windows.iloc[0]
    loops = profile.loops
    thermo = read_thermo(folder / "dem")
    first, last = thermo.iloc[0], thermo.iloc[-1]
    atoms = int(loops["atoms"].iloc[-1])
    row: dict[str, Any] = {
        "steps": int(last["step"] - first["step"]),
        "atoms": atoms,
        "loop_s": float(loops["loop_s"].sum()),
        "python_wall_s": float(profile.intervals["python_wall_s"].sum()),
        "liggghts_wall_s": float(profile.intervals["liggghts_wall_s"].sum()),
    }
    coupled = row["python_wall_s"] + row["liggghts_wall_s"]
    row["coupled_wall_s"] = coupled
    row["steps_per_s"] = steps / coupled if coupled > 0 else math.nan
    row["particle_steps_per_s"] = atoms * steps / coupled if coupled > 0 else math.nan
    row["liggghts_particle_steps_per_s"] = float(window["liggghts_particle_steps_per_s"])
    for key in ("pair_pct", "neigh_pct", "comm_pct", "comm_outside_fixes_pct", "output_pct", "modify_pct",
                "other_pct", "walls_pct", "conduction_pct", "air_drag_pct", "integration_pct",
                "other_fixes_pct", "neighs_per_atom", "neighbor_builds_per_1000_steps",
                "dangerous_builds", "python_share"):
        row[key] = float(window[key])
    row.update(T_start_C=float(first["T_mean"]), T_end_C=float(last["T_mean"]),
               kinetic_energy_J=float(last["ke"]),
               # Reported, not checked: the spin of the bed's enduring contacts is what the time
               # step moves most (model one at 5.5 s: 2.0 J at the default step).
               rotational_kinetic_energy_J=float(last["ke_rot"]))
    return row


def physics_check(row: dict[str, Any], base: dict[str, Any]) -> dict[str, Any]:
    """The variant's end state against the baseline's (module docstring)."""
    change = abs(base["T_end_C"] - base["T_start_C"])
    t_tol = TEMPERATURE_TOLERANCE * change + TEMPERATURE_FLOOR_K
    t_err = abs(row["T_end_C"] - base["T_end_C"])
    ke_err = abs(row["kinetic_energy_J"] - base["kinetic_energy_J"]) / abs(base["kinetic_energy_J"])
    return {"T_difference_K": t_err, "T_tolerance_K": t_tol, "ke_relative_difference": ke_err,
            "ke_tolerance": KINETIC_ENERGY_TOLERANCE,
            "physics_ok": bool(t_err <= t_tol and ke_err <= KINETIC_ENERGY_TOLERANCE)}


def machine_info(runner: Runner, ranks: int) -> dict[str, Any]:
    versions = runner.profile.software_versions()
    return {"platform": versions["platform"], "cpu": cpu_model(), "cpus": runner.profile.cores,
            "ranks": ranks, "liggghts": versions["liggghts"], "openmpi": versions["openmpi"],
            "python": versions["python"]}


@dataclass
class SettingsStudy:
    """What :func:`run_settings_study` measured and wrote.

    Attributes
    ----------
    table
        One row per variant (``status`` is ``ok``, ``skipped: ...`` or ``failed: ...``).
    csv, json
        The files written.
    resumed
        Variants kept from an earlier, interrupted call.
    """

    table: pd.DataFrame
    csv: Path
    json: Path
    resumed: list[str] = field(default_factory=list)

    @property
    def failed(self) -> list[str]:
        """Names of the variants whose run failed."""
        return [str(r["variant"]) for _, r in self.table.iterrows()
                if str(r["status"]).startswith("failed")]


def check_scene(case: Case, rundir: RunDir) -> None:
    """Refuse a run directory whose DEM scene is not ``case``'s (:data:`SCENE_SECTIONS`)."""
    if not rundir.case_toml.is_file():
        raise SettingsStudyError(f"{rundir.case_toml}: missing; --from needs a run directory "
                                 "written by `drumflow run`")
    theirs = load_case(rundir.case_toml)
    differ = [s for s in SCENE_SECTIONS if case.section_hash(s) != theirs.section_hash(s)]
    if differ:
        raise SettingsStudyError(
            f"{rundir.root} holds a run of another scene: its case ({theirs.name}) differs from "
            f"{case.name} in [{', '.join(differ)}]; pass the run's own case file "
            f"({rundir.case_toml}) or another run directory")


def _plain(value: Any) -> Any:
    """A JSON value that reads back as the same float (NaN and infinities as null)."""
    if isinstance(value, np.generic):
        value = value.item()
    if isinstance(value, float) and not math.isfinite(value):
        return None
    return value


def write_study(rows: list[dict[str, Any]], meta: dict[str, Any], csv_path: Path,
                json_path: Path) -> pd.DataFrame:
    """Write the table (CSV, 6 digits) and its JSON (every float exact) and return the table.

    The JSON holds the rows a resumed study keeps, so its floats are written in full: rounded
    there (pandas' ``to_json`` keeps 10 digits), a kept row's CSV value could round differently
    the second time (0.05116254999 -> 0.0511625500 -> 0.0511626) and the resumed table would
    not be the one measured.
    """
    table = pd.DataFrame(rows)
    table.to_csv(csv_path, index=False, float_format="%.6g")
    records = [{key: _plain(value) for key, value in row.items()} for row in rows]
    json_path.write_text(json.dumps({**meta, "results": records}, indent=2))
    return table


def earlier_rows(out: Path, meta: dict[str, Any]) -> dict[str, dict[str, Any]]:
    """Measured rows of an interrupted study with the same restart, steps and ranks."""
    json_path = out / TABLE.replace(".csv", ".json")
    try:
        old = json.loads(json_path.read_text())
    except (OSError, ValueError):
        return {}
    same = all(old.get(k) == meta[k] for k in ("run_dir", "restart_step", "steps", "ranks"))
    if not same:
        return {}
    return {str(r["variant"]): r for r in old.get("results", []) if r.get("status") == "ok"}


@dataclass(frozen=True)
class CoupledStart:
    """A coupled run opened for runs from one of its restarts (:func:`open_coupled_run`)."""

    rundir: RunDir
    #: The run's coupling-loop input (``dem/coupling.json``).
    driver: dict[str, Any]
    restart: Path
    start: int
    #: The baseline deck and where it came from (:func:`baseline_deck`).
    deck: str
    deck_source: str
    #: The folder the runs go in (created).
    scratch: Path


def open_coupled_run(case: Case, run_dir: Path, restart_step: int | None, ranks: int, scratch: Path,
                     who: str) -> CoupledStart:
    """Check that ``run_dir`` is a coupled run of ``case``'s scene and open its restart.

    Shared by the settings study and the interleaved arms (:mod:`drumflow.bench.interleaved`);
    ``who`` names the caller in the error.

    Raises
    ------
    SettingsStudyError
        Not a run directory, another scene, no coupling loop (no air), no such restart.
    """
    rundir = RunDir.existing(run_dir)
    check_scene(case, rundir)
    driver_path = rundir.dem / COUPLING_FILE
    if not driver_path.is_file():
        raise SettingsStudyError(f"{driver_path}: missing; {who} runs the coupling loop, so "
                                 "the run must have air (air.model 'uniform' or 'cfd')")
    driver = json.loads(driver_path.read_text())
    restart, start = restart_file(rundir, restart_step)
    scratch.mkdir(parents=True, exist_ok=True)
    deck, deck_source = baseline_deck(rundir, start, ranks, scratch, driver)
    return CoupledStart(rundir, driver, restart, start, deck, deck_source, scratch)


def run_settings_study(case: Case, run_dir: Path, out: Path, steps: int = 400, ranks: int = 2,
                       restart_step: int | None = None, only: list[str] | None = None,
                       timeout: float = 3600.0,
                       on_variant: Callable[[Variant, int, int, dict[str, Any] | None], None] | None = None,
                       ) -> SettingsStudy:
    """Run the variants one after the other from one restart of ``run_dir``.

    Parameters
    ----------
    case
        The scene; must match the run's (:func:`check_scene`).
    run_dir
        A coupled run (air field) with ``dem/restart/drum.STEP.restart`` files.
    out
        Folder for ``settings.csv``, ``settings.json`` and the variants' runs (``variants/``).
    steps
        DEM steps of the baseline; a time-step variant covers the same simulated time.
    ranks
        MPI ranks of every variant.
    restart_step
        The restart to start from (default: the newest).
    only
        Variant names (default: all); the baseline is always run, first.
    timeout
        Solver time limit per variant, s.
    on_variant
        Called before each variant (``row`` None) and after it (its row), with its index and
        the number of variants: progress for the CLI.

    Raises
    ------
    SettingsStudyError
        Bad input: not a coupled run, no such restart, another scene, an unknown variant.
    drumflow.errors.SolverError
        The baseline's run failed (a later variant's failure is a ``failed:`` row).
    """
    if steps < 1:
        raise SettingsStudyError(f"steps = {steps}: must be at least 1")
    if ranks < 1:
        raise SettingsStudyError(f"ranks = {ranks}: must be at least 1")
    known = [v.name for v in VARIANTS]
    unknown = [n for n in (only or []) if n not in known]
    if unknown:
        raise SettingsStudyError(f"unknown variant(s) {', '.join(unknown)}; known: {', '.join(known)}")
    opened = open_coupled_run(case, run_dir, restart_step, ranks, out / "variants", "the study")
    rundir, driver, restart, start = opened.rundir, opened.driver, opened.restart, opened.start
    deck, deck_source, scratch = opened.deck, opened.deck_source, opened.scratch
    variants = [v for v in VARIANTS if v.name == "baseline" or only is None or v.name in only]
    meta: dict[str, Any] = {"run_dir": str(rundir.root.resolve()), "restart": str(restart),
                            "restart_step": start, "steps": steps, "ranks": ranks}
    earlier = earlier_rows(out, meta)
    bed_speed = None
    if any(v.bed_restitution for v in variants):
        bed_speed, snapshot_step = bed_impact_speed(rundir, start, case.dem_case())
        meta["bed_impact_speed"] = {"median_m_s": bed_speed, "snapshot_step": snapshot_step}
    runner = Runner()
    meta.update(deck=deck_source, variants=[asdict(v) for v in variants],
                tolerances={"temperature_of_change": TEMPERATURE_TOLERANCE,
                            "temperature_floor_K": TEMPERATURE_FLOOR_K,
                            "kinetic_energy_relative": KINETIC_ENERGY_TOLERANCE},
                machine=machine_info(runner, ranks))
    rows: list[dict[str, Any]] = []
    resumed: list[str] = []
    base: dict[str, Any] | None = None
    baseline_grid = processors_grid(load_case(rundir.case_toml), ranks)
    csv_path, json_path = out / TABLE, out / TABLE.replace(".csv", ".json")

    def write() -> pd.DataFrame:
        # After every variant, so an interrupted study keeps what it measured.
        return write_study(rows, {**meta, "resumed": resumed}, csv_path, json_path)

    for index, variant in enumerate(variants):
        row: dict[str, Any] = {"variant": variant.name, "description": variant.description}
        grid = variant.processors.format(np=ranks) if variant.processors else None
        if ranks < variant.min_ranks:
            rows.append({**row, "status": f"skipped: needs {variant.min_ranks} MPI ranks"})
            continue
        if grid is not None and grid == baseline_grid:
            rows.append({**row, "status": f"skipped: the baseline's grid ({grid})"})
            continue
        if variant.name in earlier:
            row = earlier[variant.name]
            resumed.append(variant.name)
        else:
            if on_variant is not None:
                on_variant(variant, index, len(variants), None)
            folder = scratch / variant.name
            n_steps = variant_steps(steps, variant)
            edited = apply_variant(deck, variant, ranks, case.dem_case(), bed_speed)
            prepare_variant(folder, rundir, restart, edited, driver, start + n_steps,
                     variant.time_step_factor, start, variant.no_conduction,
                     overlap_every_row=variant.overlap_every_row or variant.no_overlap)
            t0 = time.perf_counter()
            try:
                record = runner.run("liggghts", driver_command(runner.profile, ranks, COUPLING_FILE),
                                    folder / "dem", folder / "dem" / "liggghts.out", timeout=timeout,
                                    check=finished_loop, follow=folder / "dem" / "log.liggghts")
            except DrumflowError as exc:
                if base is None:
                    raise
                rows.append({**row, "status": f"failed: {exc}"[:300]})
                write()
                continue
            row.update(status="ok", wall_s=record.wall_time_s or time.perf_counter() - t0,
                       time_step_factor=variant.time_step_factor, **measure_variant(folder, n_steps))
        if base is None:
            base = row
        row.update(physics_check(row, base))
        row["speedup_vs_baseline"] = base["coupled_wall_s"] / row["coupled_wall_s"]
        rows.append(row)
        write()
        if on_variant is not None:
            on_variant(variant, index, len(variants), row)
    return SettingsStudy(table=write(), csv=csv_path, json=json_path, resumed=resumed)
