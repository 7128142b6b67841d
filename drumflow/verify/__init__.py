"""``drumflow verify``: real small cases checked against analytic solutions and conservation laws.

Each check runs the real solvers and yields a :class:`~drumflow.verify.checks.Check` (name,
measured, expected, error, tolerance, passed); :func:`run_verification` writes them all to
``verification.json``. ``quick`` keeps to what fits in a couple of minutes on 2 cores.
"""

from __future__ import annotations

import json
import shutil
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pandas as pd

from drumflow.runner import Runner
from drumflow.verify.checks import Check, relative_error
from drumflow.verify.contacts import contact_conduction_check, restitution_check
from drumflow.verify.scenes import tiny_drum
from drumflow.verify.single_particle import lumped_cooling, terminal_settling

__all__ = ["Check", "run_verification"]


def conduction_conservation(work: Path) -> Check:
    """Conduction only, adiabatic walls: the mass-weighted mean temperature must not move."""
    from drumflow.pipeline import run_case

    t0 = time.perf_counter()
    # A metal's conductivity (100 W/m K) so that much heat flows in the short run.
    case = tiny_drum(particles__initial_temperature_spread_C=20.0, particles__conductivity=100.0,
                     run__time=0.6, run__mass_flow_start=0.3)
    run_case(case, work, timeout=600)
    series = pd.read_csv(work / "post" / "mean_temperature.csv")
    T = series["mean_temperature_C"].to_numpy()
    drift = float(np.abs(T - T[0]).max())
    return Check(
        name="conduction_conserves_mean_temperature", measured=drift, expected=0.0, error=drift,
        tolerance=1e-7, unit="K",
        note="500 particles, half 20 K hotter, adiabatic walls, no air, 0.6 s; thermo prints 12 "
             "digits, so 1e-7 K is round-off headroom",
        wall_time_s=time.perf_counter() - t0,
    )


def energy_balance(work: Path) -> Check:
    """Uniform air: the particles' enthalpy loss equals the integrated convective heat."""
    from drumflow.pipeline import run_case

    t0 = time.perf_counter()
    case = tiny_drum(air__model="uniform", air__mass_flow=0.1, run__time=0.6, run__mass_flow_start=0.3)
    summary = run_case(case, work, timeout=600)
    return Check(
        name="energy_balance_air_heat", measured=summary["particle_enthalpy_loss_J"],
        expected=summary["heat_removed_by_air_J"], error=summary["energy_balance_error"],
        tolerance=0.005, unit="J",
        note="tiny drum in uniform air (0.1 kg/s), 0.6 s: enthalpy loss from LIGGGHTS' mean "
             "temperature against the coupling loop's integrated heat",
        wall_time_s=time.perf_counter() - t0,
    )


def air_field_checks(work: Path, runner: Runner) -> list[Check]:
    """OpenFOAM on the tiny drum: mass flow in = out, and the bulk axial velocity."""
    from drumflow.air.foam import solve_air

    t0 = time.perf_counter()
    case = tiny_drum(air__model="cfd", air__mass_flow=0.1, air__mesh_size=0.02)
    sol = solve_air(case, work, runner)
    wall = time.perf_counter() - t0
    note = f"tiny drum, {sol.mesh.get('cells')} cells, {sol.iterations} SIMPLE iterations"
    return [
        Check(name="air_mass_flow_in_equals_out", measured=sol.outlet_mass_flow,
              expected=sol.inlet_mass_flow,
              error=relative_error(sol.outlet_mass_flow, sol.inlet_mass_flow), tolerance=0.005,
              unit="kg/s", note=note, wall_time_s=wall),
        Check(name="air_mean_axial_velocity", measured=sol.mean_axial_velocity,
              expected=sol.expected_axial_velocity,
              error=relative_error(sol.mean_axial_velocity, sol.expected_axial_velocity),
              tolerance=0.01, unit="m/s",
              note="volume-mean axial velocity through the free cross-section against "
                   "mdot / (rho A_free); " + note, wall_time_s=wall),
    ]


def couette_check(work: Path, runner: Runner) -> Check:
    """Laminar flow between rotating cylinders: u_theta = A r + B / r."""
    from drumflow.air.verify_couette import verify_couette

    t0 = time.perf_counter()
    result = verify_couette(work, runner)
    return Check(
        name="couette_rotating_cylinders", measured=result.max_relative_error, expected=0.0,
        error=result.max_relative_error, tolerance=0.02, unit="of inner wall speed",
        note=f"{result.method}, {result.cells} cells, largest |u - u_exact| over all cells",
        wall_time_s=time.perf_counter() - t0,
    )


def coupling_interval_sweep(work: Path, runner: Runner) -> list[Check]:
    """Heat removed from a particle in 1 m/s air over one time constant, against N = 1."""
    from drumflow.coupling.physics import AirState, auto_coupling_interval

    reference = lumped_cooling(work / "n1", runner, interval=1)
    base = reference.measured
    checks = []
    air = AirState.at(30.0)
    auto = auto_coupling_interval(0.01, 0.008, 1050.0, 1465.38, air, 1.0, cap=10_000)
    for n in sorted({10, 100, 1000, auto}):
        c = lumped_cooling(work / f"n{n}", runner, interval=n)
        checks.append(Check(
            name=f"coupling_interval_{n}_steps", measured=c.measured, expected=base,
            error=relative_error(c.measured, base), tolerance=0.001 if n == auto else float("inf"),
            unit="K", note=f"{n} steps of 0.01 s between air updates"
                           + (" (the 'auto' choice: must stay within 0.1%)" if n == auto else " (reported)"),
            wall_time_s=c.wall_time_s,
        ))
    return checks


def run_verification(
    out: Path, quick: bool = False, runner: Runner | None = None,
    on_check: Callable[[Check], None] | None = None,
) -> list[Check]:
    """Run the verification cases into ``out`` and write ``out/verification.json``."""
    runner = runner or Runner()
    if out.exists():
        shutil.rmtree(out)
    out.mkdir(parents=True)
    steps: list[Callable[[], list[Check]]] = [
        lambda: [lumped_cooling(out / "lumped_cooling", runner)],
        lambda: [terminal_settling(out / "terminal_velocity", runner)],
        lambda: [conduction_conservation(out / "conduction")],
        lambda: [energy_balance(out / "energy_balance")],
        lambda: air_field_checks(out / "air_field", runner),
        lambda: [couette_check(out / "couette", runner)],
        lambda: [contact_conduction_check(out / "conduction_517kPa", runner, youngs_modulus=517e3)],
        lambda: [contact_conduction_check(out / "conduction_5MPa", runner, youngs_modulus=5e6)],
        lambda: [restitution_check(out / "restitution_0.1", runner, restitution=0.1)],
        lambda: [restitution_check(out / "restitution_0.3", runner, restitution=0.3)],
    ]
    if not quick:
        steps.append(lambda: coupling_interval_sweep(out / "interval_sweep", runner))
        # The paper's soft 517 kPa particles, and the restitution at a slower impact (1 m/s).
        steps.append(lambda: [restitution_check(out / "restitution_0.1_517kPa", runner,
                                                restitution=0.1, youngs_modulus=517e3)])
        steps.append(lambda: [restitution_check(out / "restitution_0.1_1ms", runner,
                                                restitution=0.1, speed=1.0)])
    checks: list[Check] = []
    for step in steps:
        for check in step():
            checks.append(check)
            if on_check:
                on_check(check)
    (out / "verification.json").write_text(
        json.dumps([c.as_dict() for c in checks], indent=2, default=str)
    )
    return checks
