"""DEM: the LIGGGHTS deck, particle placement, time step, stability, dumps and the run.

The stage's entry point is :func:`drumflow.dem.stage.run`; the names below are re-exported
lazily, so importing :mod:`drumflow.dem.timestep` does not load the stage.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from drumflow._lazy import lazy_exports

_EXPORTS = {
    **{name: "drumflow.dem.stage" for name in
       ("DemInputs", "DemResult", "ProgressCallback", "dem_key", "kept_time_step", "plan_run",
        "run")},
    "ThermoParser": "drumflow.dem.thermo",
}
__all__ = [
    "DemInputs",
    "DemResult",
    "ProgressCallback",
    "ThermoParser",
    "dem_key",
    "kept_time_step",
    "plan_run",
    "run",
]
__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS, globals())

if TYPE_CHECKING:
    from drumflow.dem.stage import (
        DemInputs,
        DemResult,
        ProgressCallback,
        dem_key,
        kept_time_step,
        plan_run,
        run,
    )
    from drumflow.dem.thermo import ThermoParser
