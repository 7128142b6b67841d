"""The verification run: every check in order, written to ``verification.json``.

Each check runs the real solvers (or, for the references that need none, drumflow's physics
functions) and yields a :class:`~drumflow.verify.checks.Check`. ``quick`` keeps to what fits in
a few minutes on 2 cores.
"""

from __future__ import annotations

import json
import shutil
import time
from collections.abc import Callable
from pathlib import Path

from drumflow.runner import Runner
from drumflow.verify.air_field import air_field_checks, pipe_friction_check
from drumflow.verify.air_heat import air_heat_check
from drumflow.verify.bed import conduction_conservation, uniform_air_bed
from drumflow.verify.checks import Check, summary
from drumflow.verify.contacts import (
    contact_conduction_check,
    restitution_check,
    wall_restitution_check,
)
from drumflow.verify.interior import BIOTS, interior_series_check
from drumflow.verify.porous_bed import porous_bed_checks
from drumflow.verify.references import air_property_checks, drag_curve_check
from drumflow.verify.single_particle import (
    SETTLING_DIAMETERS,
    convective_h_check,
    coupling_interval_sweep,
    settling_check,
)


def couette_check(work: Path, runner: Runner) -> Check:
    """Laminar flow between rotating cylinders: u_theta = A r + B / r."""
    try:
        from drumflow.verify.couette import verify_couette  # type: ignore[import-not-found,unused-ignore]
    except ImportError:  # before the move out of drumflow.air
        from drumflow.air.verify_couette import verify_couette  # type: ignore[import-not-found,no-redef,unused-ignore]

    t0 = time.perf_counter()
    result = verify_couette(work, runner)
    return Check(
        name="couette_rotating_cylinders",
        measured=result.max_relative_error,
        expected=0.0,
        error=result.max_relative_error,
        tolerance=0.02,
        unit="of inner wall speed",
        note=f"{result.method}, {result.cells} cells, largest |u - u_exact| over all cells",
        reference="exact circular Couette flow u_theta = A r + B / r",
        wall_time_s=time.perf_counter() - t0,
    )


def verification_steps(out: Path, runner: Runner, quick: bool) -> list[Callable[[], list[Check]]]:
    """The checks to run, in order, each a callable writing under ``out``."""
    steps: list[Callable[[], list[Check]]] = [
        air_property_checks,
        lambda: [drag_curve_check()],
        lambda: [convective_h_check(out / "convective_h_1ms", runner, speed=1.0)],
        lambda: [convective_h_check(out / "convective_h_3ms", runner, speed=3.0)],
        lambda: [settling_check(out / f"settling_{d * 1e3:g}mm", runner, d) for d in SETTLING_DIAMETERS],
        lambda: [interior_series_check(out / f"interior_bi{b:g}", runner, b) for b in BIOTS],
        lambda: [air_heat_check(out / "air_warming", runner)],
        lambda: [conduction_conservation(out / "conduction")],
        lambda: uniform_air_bed(out / "uniform_air_bed"),
        lambda: air_field_checks(out / "air_field", runner),
        lambda: [couette_check(out / "couette", runner)],
        lambda: [contact_conduction_check(out / "conduction_517kPa", runner, youngs_modulus=517e3)],
        lambda: [contact_conduction_check(out / "conduction_5MPa", runner, youngs_modulus=5e6)],
        lambda: [restitution_check(out / "restitution_0.1", runner, restitution=0.1)],
        lambda: [restitution_check(out / "restitution_0.3", runner, restitution=0.3)],
        lambda: [wall_restitution_check(out / "wall_restitution_0.3", runner, restitution=0.3)],
    ]
    if not quick:
        # A LIGGGHTS-packed bed (1-3 min to pour) with porousSimpleFoam through and past it.
        steps.append(lambda: porous_bed_checks(out / "porous_bed", runner))
        steps.append(lambda: coupling_interval_sweep(out / "interval_sweep", runner))
        steps.append(lambda: [pipe_friction_check(out / "pipe_friction", runner)])
        # The paper's soft 517 kPa particles, and the restitution at a slower impact (1 m/s).
        steps.append(
            lambda: [
                restitution_check(
                    out / "restitution_0.1_517kPa", runner, restitution=0.1, youngs_modulus=517e3
                )
            ]
        )
        steps.append(
            lambda: [restitution_check(out / "restitution_0.1_1ms", runner, restitution=0.1, speed=1.0)]
        )
    return steps


def run_verification(
    out: Path,
    quick: bool = False,
    runner: Runner | None = None,
    on_check: Callable[[Check], None] | None = None,
) -> list[Check]:
    """Run the verification cases into ``out`` and write ``out/verification.json``.

    The file holds ``{"summary": ..., "checks": [...]}``; the summary counts the checks against
    independent references apart from the bookkeeping ones (:func:`~drumflow.verify.checks.summary`).
    """
    runner = runner or Runner()
    if out.exists():
        shutil.rmtree(out)
    out.mkdir(parents=True)
    checks: list[Check] = []
    for step in verification_steps(out, runner, quick):
        for check in step():
            checks.append(check)
            if on_check:
                on_check(check)
    (out / "verification.json").write_text(
        json.dumps(
            {"summary": summary(checks), "checks": [c.as_dict() for c in checks]}, indent=2, default=str
        )
    )
    return checks
