"""What a run skips for speed, with the speed-up and error measured by ``drumflow bench``.

Every shortcut drumflow takes (or the case asks for) is recorded in the run's manifest under
``skips``: what is skipped, the speed-up and the errors against the finest setting as
measured on the reference scene (``drumflow/data/measured_smoke.json``, package data written
by ``studies/ship_bench.py`` from ``drumflow bench cases/smoke.toml`` on the machine named in
it). The pipeline records them; this module sits low (it imports no stage) so that any stage or
the bench can use it. The numbers are the smoke scene's; on another
scene they are a guide, and ``drumflow bench`` on that scene measures its own.
"""

from __future__ import annotations

import json
from functools import lru_cache
from importlib import resources
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from drumflow.case import Case

#: The shipped bench results, as package data (found in a wheel as well as in a checkout).
MEASURED = resources.files("drumflow") / "data" / "measured_smoke.json"


@lru_cache(maxsize=1)
def measured() -> dict[str, Any]:
    """The shipped bench results: ``{"source": ..., "rows": {rung: {...}}}`` ({} if absent)."""
    if not MEASURED.is_file():
        return {}
    data = json.loads(MEASURED.read_text())
    return data if isinstance(data, dict) else {}


def _pair(with_skip: str, without: str) -> dict[str, Any]:
    rows = measured().get("rows", {})
    a, b = rows.get(with_skip), rows.get(without)
    if not a or not b:
        return {"measured": False}
    t_with, t_without = a.get("dem_wall_time_s"), b.get("dem_wall_time_s")
    errors = {k: a.get(f"err_{k}") for k in ("temperature", "h", "mass_flow")}
    errors_without = {k: b.get(f"err_{k}") for k in ("temperature", "h", "mass_flow")}
    return {
        "measured": True,
        "speedup": (t_without / t_with) if t_with and t_without else None,
        "errors_against_reference": errors,
        "errors_against_reference_without_skip": errors_without,
        "rungs": [with_skip, without],
        "source": measured().get("source"),
    }


def skips(case: Case, time_step_mode: str, coupled: bool, wall_motion: str,
          processes: int) -> list[dict[str, Any]]:
    """The shortcuts this run takes, each with its measured speed-up and error.

    Parameters
    ----------
    case
        The case.
    time_step_mode
        How the time step was chosen (:attr:`drumflow.dem.timestep.TimeStepChoice.mode`).
    coupled
        The air acts on the particles.
    wall_motion
        ``"static_shell"`` or ``"moving_mesh"`` (the geometry stage's choice).
    processes
        MPI processes of the run.
    """
    out: list[dict[str, Any]] = []

    def add(skip: str, applies: bool, with_skip: str, without: str) -> None:
        if applies:
            out.append({"skip": skip, **_pair(with_skip, without)})

    add("static shell with a surface velocity instead of a rotating shell mesh (only the "
        "lifters move)", wall_motion == "static_shell", "default", "moving_mesh")
    # Each rule its own rung: "default" is the bench's "auto", "contact" the rule without the
    # spin limit (a bench without that rung records it as not measured).
    add("time step 'contact' (min of 20% of the Rayleigh time and 1/10 of the Hertz contact) "
        "instead of 10% of the Rayleigh time", time_step_mode == "contact", "contact", "dt_10pct")
    add("time step 'auto' (min of 20% of the Rayleigh time, 1/10 of the Hertz contact and 0.8 "
        "of the bed's spin limit) instead of 10% of the Rayleigh time", time_step_mode == "auto",
        "default", "dt_10pct")
    add("air updated every 'auto' steps (0.2% of the particles' thermal time constant) instead "
        "of every 10 steps", coupled and case.air.coupling_interval == "auto", "default", "coupling_10")
    add("serial run (few particles per process) instead of 2 MPI processes",
        processes == 1, "default", "mpi_2")
    add("no particle-particle conduction", not case.run.conduction, "no_conduction", "default")
    # Measured over a whole run on paper model two's parcels too (README, 'The fast profile').
    add("no tangential dashpot between particles (a step free of the bed's spin limit)",
        not case.contacts.tangential_damping, "no_tangential_damping", "default")
    add("uniform plug-flow air instead of the CFD air field", case.air.model == "uniform",
        "uniform_air", "default")
    softened = case.particles.youngs_modulus_reference
    if softened and case.particles.youngs_modulus < softened:
        add("Young's modulus softened for a larger time step", True, "E_x0.5", "default")
    return out
