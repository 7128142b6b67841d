"""Air stage: the air field in the drum (one-way: the particles do not change it).

Entry point :func:`run` (``run(case, rundir, runner, inputs) -> AirResult | None``). The stage
returns only the field; how it acts on the particles (the coupling spec and its update
interval) is built by the pipeline with :func:`drumflow.coupling.spec.build_coupling`.

``air.model``:

* ``"none"``: no air; particles exchange heat only by conduction.
* ``"uniform"``: plug flow at the mean axial velocity mdot / (rho A_free), no CFD at all
  (quick studies and tests).
* ``"cfd"``: a steady OpenFOAM field (:mod:`drumflow.air.foam`), cached by a hash of
  everything it depends on, so a second run with the same drum and air settings does not run
  OpenFOAM.

The air flows counter-current, from the outlet end (z = l) towards the feed end (z = 0), at
the case's inlet temperature throughout (one-way coupling: the particles do not heat it).
"""

from __future__ import annotations

import json
import math
import os
import shutil
import time
from collections.abc import Callable
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

from drumflow.air.source import FieldSource, mean_axial_velocity, uniform_field
from drumflow.geometry.lifters import free_area
from drumflow.physics.air import ideal_gas_density
from drumflow.readers import read_json_object

if TYPE_CHECKING:
    from drumflow.air.bed_air import BedSnapshot
    from drumflow.case import Case
    from drumflow.rundir import RunDir
    from drumflow.runner import Runner

__all__ = ["AirInputs", "AirResult", "AirSummary", "air_cache_dir", "free_area", "run"]


def air_cache_dir() -> Path:
    """Where solved air fields are kept across runs (``DRUMFLOW_CACHE`` overrides it)."""
    root = os.environ.get("DRUMFLOW_CACHE") or os.path.join(
        os.environ.get("XDG_CACHE_HOME", os.path.expanduser("~/.cache")), "drumflow"
    )
    return Path(root) / "air"


@dataclass
class AirSummary:
    """What the run's summary reports about the air.

    ``coupling_interval_steps`` is filled in by the pipeline when it builds the coupling spec.
    """

    model: str
    density_kg_m3: float
    mean_axial_velocity_m_s: float
    mass_flow_in_kg_s: float
    mass_flow_out_kg_s: float
    coupling_interval_steps: int = 0
    cache_hit: bool = False
    solve_wall_time_s: float = 0.0
    extra: dict[str, Any] = field(default_factory=dict)

    def as_dict(self) -> dict[str, Any]:
        return asdict(self)


@dataclass(frozen=True)
class AirInputs:
    """What the air stage needs besides the case.

    Attributes
    ----------
    processes
        MPI ranks for simpleFoam (from the launch profile).
    progress
        ``progress(stage, done, total)``: SIMPLE iterations of the ``"air"`` stage.
    bed_states
        The states of ``air.bed_states``, read and checked against the scene by the caller
        (:func:`drumflow.dem.state.load_bed_states`): the air around each one's bed is solved
        (:mod:`drumflow.air.bed_phases`).
    """

    processes: int = 1
    progress: Callable[[str, float, float], None] | None = None
    bed_states: tuple[BedSnapshot, ...] = ()


@dataclass(frozen=True)
class AirResult:
    """The air field (as the coupling loop loads it) and what the summary reports."""

    source: FieldSource
    summary: AirSummary


def run(case: Case, rundir: RunDir, runner: Runner, inputs: AirInputs) -> AirResult | None:
    """The air stage: the field for ``air.model`` (``None`` for ``"none"``).

    ``"uniform"`` is plug flow at the mean axial velocity; ``"cfd"`` solves (or takes from the
    cache) the OpenFOAM field.
    """
    if case.air.model == "none":
        return None
    if case.air.model == "uniform":
        u_mean = mean_axial_velocity(case)
        rho = ideal_gas_density(case.air.inlet_temperature_C, case.air.pressure_kPa)
        summary = AirSummary("uniform", rho, u_mean, case.air.mass_flow, case.air.mass_flow)
        result = AirResult(_uniform_grid(case, rundir) if case.air.warming else uniform_field(case),
                           summary)
    else:
        result = _run_cfd(case, rundir, runner, inputs)
        if case.air.bed_states:
            result = _with_bed_phases(case, rundir, runner, inputs, result)
    if inputs.progress:
        # One bar per stage, finished when the stage ends (a converged solve stops before
        # air.max_iterations).
        inputs.progress("air", 1.0, 1.0)
    return result


def _uniform_grid(case: Case, rundir: RunDir) -> FieldSource:
    """Plug flow on the air field's grid: air that warms is solved on a grid
    (:mod:`drumflow.air.heat`), and the particles sample the same uniform velocity from it."""
    from drumflow.air.field import AirField, air_cache_key

    rundir.air.mkdir(parents=True, exist_ok=True)
    AirField.uniform(case).to_npz(rundir.air_field)
    return FieldSource({"kind": "grid", "path": str(rundir.air_field)},
                       "uniform-grid:" + air_cache_key(case), 0.0)


def _solve_into_cache(case: Case, rundir: RunDir, runner: Runner, inputs: AirInputs,
                      cache: Path) -> None:
    from drumflow.air.field import AirField
    from drumflow.air.foam import solve_air

    work = rundir.air_openfoam
    if work.exists():
        shutil.rmtree(work)
    total = float(case.air.max_iterations)
    progress = inputs.progress

    def on_iteration(iteration: int, *_: object) -> None:
        if progress:
            progress("air", min(float(iteration), total), total)

    solution = solve_air(case, work, runner, processes=inputs.processes, on_iteration=on_iteration)
    field_ = AirField.from_solution(solution, case)
    cache.mkdir(parents=True, exist_ok=True)
    field_.to_npz(cache / "field.npz")
    (cache / "solution.json").write_text(json.dumps(solution.summary(), indent=2, default=str))


def _run_cfd(case: Case, rundir: RunDir, runner: Runner, inputs: AirInputs) -> AirResult:
    from drumflow.air.field import AirField, air_cache_key
    from drumflow.air.field_picture import plot_air_cross_section

    key = air_cache_key(case)
    cache = air_cache_dir() / key
    hit = (cache / "field.npz").exists() and (cache / "solution.json").exists()
    t0 = time.perf_counter()
    if not hit:
        _solve_into_cache(case, rundir, runner, inputs, cache)
    # A cache entry cut short (a killed writer) is refused by name: delete it to solve again.
    info = read_json_object(cache / "solution.json",
                            "the air field cache's record (delete its folder to solve again)")
    rundir.air.mkdir(parents=True, exist_ok=True)
    shutil.copyfile(cache / "field.npz", rundir.air_field)
    rundir.air_solution.write_text(json.dumps(info, indent=2))
    plot_air_cross_section(AirField.from_npz(rundir.air_field), case, rundir.air_picture)
    source = FieldSource({"kind": "grid", "path": str(rundir.air_field)}, key, case.drum.omega)
    summary = AirSummary(
        "cfd",
        ideal_gas_density(case.air.inlet_temperature_C, case.air.pressure_kPa),
        float(info.get("mean_axial_velocity_m_s", float("nan"))),
        float(info.get("mass_flow_in_kg_s", float("nan"))),
        float(info.get("mass_flow_out_kg_s", float("nan"))),
        cache_hit=hit,
        solve_wall_time_s=time.perf_counter() - t0,
        extra={k: v for k, v in info.items()
               if k in ("iterations", "final_residuals", "cells", "wall_time_s")},
    )
    return AirResult(source, summary)


#: Version of the bed phases' solve and fields (not of the cache's layout); part of the keys.
BED_PHASES_VERSION = 1


def bed_phase_cache(empty_key: str, state_content: str) -> Path:
    """The cache folder of one bed state's air (``bed_phase.npz`` and its record), keyed by the
    empty drum's air and the state file's content (its SHA-256), so that runs with any subset of
    the same states (1, 2, 4 phases: the convergence question) solve each state once."""
    from drumflow.rundir import hash_text

    return air_cache_dir() / ("bed-" + hash_text(json.dumps(
        {"air": empty_key, "state": state_content, "version": BED_PHASES_VERSION})))


def _with_bed_phases(case: Case, rundir: RunDir, runner: Runner, inputs: AirInputs,
                     empty: AirResult) -> AirResult:
    """The air around the bed (``air.bed_states``): each state's air solved once, cached by the
    empty drum's key and the state's content (:func:`bed_phase_cache`), its field beside the
    empty drum's in the run directory; the coupling loop gets them all (field kind ``phases``)."""
    import hashlib

    from drumflow.air.bed_phases import PHASES_RECORD, lifter_spacing, solve_bed_phases
    from drumflow.rundir import hash_text

    if len(inputs.bed_states) != len(case.air.bed_states):
        raise ValueError(f"air.bed_states names {len(case.air.bed_states)} state(s), the stage "
                         f"was given {len(inputs.bed_states)} (drumflow.dem.state.load_bed_states)")
    contents = [hashlib.sha256(Path(p).read_bytes()).hexdigest() for p in case.air.bed_states]
    caches = [bed_phase_cache(empty.source.key, c) for c in contents]
    # The fields the loop gets, by the drum's air and the states' contents in order.
    key = hash_text(json.dumps({"air": empty.source.key, "states": contents,
                                "version": BED_PHASES_VERSION}))
    missing = [k for k, c in enumerate(caches) if not (c / PHASES_RECORD).exists()]
    t0 = time.perf_counter()
    if missing:
        work = rundir.air / "bed_openfoam"
        if work.exists():
            shutil.rmtree(work)
        progress = inputs.progress

        def on_phase(done: int, total: int) -> None:
            if progress:
                progress("air around the bed", float(done), float(total))

        on_phase(0, len(missing))
        solved = solve_bed_phases(case, [inputs.bed_states[k] for k in missing], work,
                                  work / "fields", runner, processes=inputs.processes,
                                  on_phase=on_phase)
        for k, phase in zip(missing, solved, strict=True):
            caches[k].mkdir(parents=True, exist_ok=True)
            shutil.copyfile(phase.path, caches[k] / "bed_phase.npz")
            # The record last: its presence says the field beside it is whole.
            (caches[k] / PHASES_RECORD).write_text(json.dumps(phase.record(), indent=2, default=float))
        shutil.rmtree(work, ignore_errors=True)
    what = "a bed state's cached air record (delete its folder to solve again)"
    states = [read_json_object(c / PHASES_RECORD, what) for c in caches]
    paths = []
    for k, cache in enumerate(caches):
        paths.append(rundir.air / f"bed_phase_{k}.npz")
        shutil.copyfile(cache / "bed_phase.npz", paths[-1])
        states[k]["path"] = str(paths[-1])
    solve_wall = sum(float(s.get("wall_time_s", math.nan)) for s in states)
    (rundir.air / PHASES_RECORD).write_text(json.dumps(
        {"states": states, "spacing_rad": lifter_spacing(case.lifters.count),
         "wall_time_s": solve_wall}, indent=2))
    angles = [float(s["angle_rad"]) for s in states]
    field_spec = {"kind": "phases", "paths": [str(p) for p in paths], "angles": angles,
                  "spacing": lifter_spacing(case.lifters.count), "omega": case.drum.omega}
    summary = empty.summary
    summary.extra["bed_phases"] = {
        "states": [s["source"] for s in states],
        "angles_rad": angles,
        "time_s": [float(s["time_s"]) for s in states],
        "cache_hit": not missing,
        "solved_here": len(missing),
        # What the states' solves took, here or in the run that cached them.
        "solve_wall_time_s": solve_wall,
        "stage_wall_time_s": time.perf_counter() - t0,
    }
    return AirResult(FieldSource(field_spec, f"phases:{key}", case.drum.omega), summary)
