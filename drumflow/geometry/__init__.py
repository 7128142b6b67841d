"""Geometry stage: the drum shell and lifters as an ASCII STL for LIGGGHTS, and a picture.

Skipped when the run directory already holds the geometry of the same drum and lifters.
"""

from __future__ import annotations

import json
import time
from dataclasses import asdict, dataclass
from typing import TYPE_CHECKING

from drumflow.geometry.drum import (
    build_wall_mesh,
    check_wall_mesh,
    facet_size,
    plot_cross_section,
    simulation_box,
    write_ascii_stl,
)
from drumflow.rundir import file_hash

if TYPE_CHECKING:
    from drumflow.case import Case
    from drumflow.rundir import RunDir

__all__ = ["GeometryResult", "build_geometry", "geometry_key"]


@dataclass(frozen=True)
class GeometryResult:
    stl: str
    stl_sha256: str
    facet_size_m: float
    triangles: int
    wall_area_m2: float
    min_quality: float
    box_lo: tuple[float, float, float]
    box_hi: tuple[float, float, float]


def geometry_key(case: Case) -> str:
    """What the geometry depends on: drum, lifters and (through 'auto' facets) particle size."""
    return case.section_hash("drum", "lifters") + f":{facet_size(case):.9g}"


def build_geometry(case: Case, rundir: RunDir) -> GeometryResult:
    """Build, check and write the walls; reuse them when the inputs have not changed."""
    key = geometry_key(case)
    done = rundir.stage_done("geometry", key)
    stl = rundir.geometry / "walls.stl"
    if done and stl.exists() and file_hash(stl) == done["result"]["stl_sha256"]:
        r = done["result"]
        return GeometryResult(**{**r, "box_lo": tuple(r["box_lo"]), "box_hi": tuple(r["box_hi"])})
    t0 = time.perf_counter()
    mesh = build_wall_mesh(case)
    stats = check_wall_mesh(mesh, case)
    write_ascii_stl(mesh, stl)
    plot_cross_section(case, rundir.geometry / "cross_section.png")
    box = simulation_box(case)
    result = GeometryResult(
        stl=str(stl.relative_to(rundir.root)),
        stl_sha256=file_hash(stl),
        facet_size_m=facet_size(case),
        triangles=int(stats["triangles"]),
        wall_area_m2=float(stats["wall_area_m2"]),
        min_quality=float(stats["min_quality"]),
        box_lo=box.lo,
        box_hi=box.hi,
    )
    (rundir.geometry / "geometry.json").write_text(json.dumps(asdict(result), indent=2))
    rundir.mark_done("geometry", key, asdict(result), time.perf_counter() - t0)
    return result
