"""Air: the field in the drum (OpenFOAM or plug flow), its mesh, and sampling it.

The stage's entry point is :func:`drumflow.air.stage.run`; the names below are re-exported
lazily, so importing :mod:`drumflow.air.field` does not load the stage.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from drumflow._lazy import lazy_exports

_EXPORTS = {name: "drumflow.air.stage" for name in
            ("AirInputs", "AirResult", "AirSummary", "air_cache_dir", "free_area", "run")}
__all__ = [
    "AirInputs",
    "AirResult",
    "AirSummary",
    "air_cache_dir",
    "free_area",
    "run",
]
__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS, globals())

if TYPE_CHECKING:
    from drumflow.air.stage import (
        AirInputs,
        AirResult,
        AirSummary,
        air_cache_dir,
        free_area,
        run,
    )
