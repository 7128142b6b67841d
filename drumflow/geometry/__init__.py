"""Geometry: the drum shell and lifters (gmsh), the fluid mesh, lifter shapes.

The stage's entry point is :func:`drumflow.geometry.stage.run`; the names below are re-exported
lazily, so importing :mod:`drumflow.geometry.lifters` does not load gmsh.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from drumflow._lazy import lazy_exports

_EXPORTS = {name: "drumflow.geometry.stage" for name in
            ("GeometryInputs", "GeometryResult", "build_geometry", "geometry_key", "run", "wall_motion")}
__all__ = [
    "GeometryInputs",
    "GeometryResult",
    "build_geometry",
    "geometry_key",
    "run",
    "wall_motion",
]
__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS, globals())

if TYPE_CHECKING:
    from drumflow.geometry.stage import (
        GeometryInputs,
        GeometryResult,
        build_geometry,
        geometry_key,
        run,
        wall_motion,
    )
