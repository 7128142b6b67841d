"""Air stage: the air field in the drum, and how it acts on the particles (one-way).

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
from dataclasses import asdict, dataclass, field
from pathlib import Path
from collections.abc import Callable
from typing import TYPE_CHECKING, Any

from drumflow.coupling.physics import AirState, auto_coupling_interval
from drumflow.dem import AirCoupling
from drumflow.geometry.lifters import lifter_area
from drumflow.rundir import hash_text

if TYPE_CHECKING:
    from drumflow.case import Case
    from drumflow.rundir import RunDir
    from drumflow.runner import Runner

__all__ = ["AirSummary", "prepare_air", "free_area", "air_cache_dir"]


def free_area(case: Case) -> float:
    """Cross-section open to the air: the shell's disk minus the lifters, m^2."""
    return math.pi * case.drum.radius**2 - lifter_area(case.drum.radius, case.lifters)


def air_cache_dir() -> Path:
    """Where solved air fields are kept across runs (``DRUMFLOW_CACHE`` overrides it)."""
    root = os.environ.get("DRUMFLOW_CACHE") or os.path.join(
        os.environ.get("XDG_CACHE_HOME", os.path.expanduser("~/.cache")), "drumflow"
    )
    return Path(root) / "air"


@dataclass
class AirSummary:
    """What the run's summary reports about the air."""

    model: str
    density_kg_m3: float
    mean_axial_velocity_m_s: float
    mass_flow_in_kg_s: float
    mass_flow_out_kg_s: float
    coupling_interval_steps: int
    cache_hit: bool = False
    solve_wall_time_s: float = 0.0
    extra: dict[str, Any] = field(default_factory=dict)


def prepare_air(
    case: Case,
    rundir: RunDir,
    runner: Runner,
    time_step: float,
    dump_every: int,
    progress: Callable[[str, float, float], None] | None = None,
) -> tuple[AirCoupling, AirSummary] | None:
    """Build (or fetch from cache) the air field and the coupling settings for the DEM run.

    Returns ``None`` for ``air.model = "none"``.
    """
    if case.air.model == "none":
        return None
    state = AirState.at(case.air.inlet_temperature_C, case.air.pressure_kPa)
    area = free_area(case)
    u_mean = case.air.mass_flow / (state.density * area)
    if case.air.coupling_interval == "auto":
        # Largest slip: the air speed plus a particle falling across the whole drum.
        max_slip = u_mean + math.sqrt(2 * 9.81 * case.drum.diameter)
        interval = auto_coupling_interval(
            time_step, case.particles.diameter, case.particles.density,
            case.particles.heat_capacity, state, max_slip, cap=dump_every,
        )
    else:
        interval = int(case.air.coupling_interval)
    if case.air.model == "uniform":
        velocity = [0.0, 0.0, -u_mean]
        coupling = AirCoupling(
            field={"kind": "uniform", "velocity": velocity},
            field_key=hash_text(json.dumps(velocity)),
            interval=interval,
            temperature_C=case.air.inlet_temperature_C,
            pressure_kPa=case.air.pressure_kPa,
            omega=0.0,
        )
        summary = AirSummary("uniform", state.density, u_mean, case.air.mass_flow,
                             case.air.mass_flow, interval)
        return coupling, summary
    return _prepare_cfd(case, rundir, runner, state, interval, progress)


def _prepare_cfd(
    case: Case,
    rundir: RunDir,
    runner: Runner,
    state: AirState,
    interval: int,
    progress: Callable[[str, float, float], None] | None,
) -> tuple[AirCoupling, AirSummary]:
    from drumflow.air.field import AirField, air_cache_key, plot_air_cross_section
    from drumflow.air.foam import solve_air

    key = air_cache_key(case)
    cache = air_cache_dir() / key
    cached = cache / "field.npz"
    info_path = cache / "solution.json"
    hit = cached.exists() and info_path.exists()
    t0 = time.perf_counter()
    if not hit:
        work = rundir.root / "air" / "openfoam"
        if work.exists():
            shutil.rmtree(work)
        total = float(case.air.max_iterations)

        def on_iteration(iteration: int, *_: object) -> None:
            if progress:
                progress("air (OpenFOAM)", min(float(iteration), total), total)

        solution = solve_air(case, work, runner, processes=case.process_count,
                             on_iteration=on_iteration)
        field_ = AirField.from_solution(solution, case)
        cache.mkdir(parents=True, exist_ok=True)
        field_.to_npz(cached)
        info_path.write_text(json.dumps(solution.summary(), indent=2, default=str))
    info = json.loads(info_path.read_text())
    local = rundir.root / "air" / "field.npz"
    local.parent.mkdir(parents=True, exist_ok=True)
    shutil.copyfile(cached, local)
    (rundir.root / "air" / "solution.json").write_text(json.dumps(info, indent=2))
    field_ = AirField.from_npz(local)
    plot_air_cross_section(field_, case, rundir.root / "air" / "air_cross_section.png")
    coupling = AirCoupling(
        field={"kind": "grid", "path": str(local)},
        field_key=key,
        interval=interval,
        temperature_C=case.air.inlet_temperature_C,
        pressure_kPa=case.air.pressure_kPa,
        omega=case.drum.omega,
    )
    summary = AirSummary(
        "cfd",
        state.density,
        float(info.get("mean_axial_velocity_m_s", float("nan"))),
        float(info.get("mass_flow_in_kg_s", float("nan"))),
        float(info.get("mass_flow_out_kg_s", float("nan"))),
        interval,
        cache_hit=hit,
        solve_wall_time_s=time.perf_counter() - t0,
        extra={k: v for k, v in info.items() if k in ("iterations", "final_residuals", "cells", "wall_time_s")},
    )
    return coupling, summary


def summary_dict(summary: AirSummary) -> dict[str, Any]:
    return asdict(summary)
