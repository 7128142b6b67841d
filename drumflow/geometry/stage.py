"""Geometry stage: the drum shell and lifters as an ASCII STL for LIGGGHTS, and a picture.

Entry point :func:`run` (``run(case, rundir, runner, inputs) -> GeometryResult``). Skipped when
the run directory already holds the geometry of the same drum and lifters.
"""

from __future__ import annotations

import json
import time
from dataclasses import asdict, dataclass
from typing import TYPE_CHECKING

from drumflow.geometry.drum import (
    build_end_mesh,
    build_wall_mesh,
    check_wall_mesh,
    facet_size,
    lifter_part,
    plot_cross_section,
    simulation_box,
    write_ascii_stl,
)
from drumflow.rundir import file_hash

if TYPE_CHECKING:
    from drumflow.case import Case
    from drumflow.rundir import RunDir
    from drumflow.runner import Runner

__all__ = ["GeometryInputs", "GeometryResult", "build_geometry", "geometry_key", "run", "wall_motion"]


@dataclass(frozen=True)
class GeometryInputs:
    """What the geometry stage needs besides the case (nothing yet: the case says it all)."""


@dataclass(frozen=True)
class GeometryResult:
    stl: str  # the walls that carry the shell: combined walls, or the bare static cylinder
    stl_sha256: str
    facet_size_m: float
    triangles: int
    wall_area_m2: float
    min_quality: float
    box_lo: tuple[float, float, float]
    box_hi: tuple[float, float, float]
    wall_motion: str = "moving_mesh"
    lifters_stl: str | None = None  # static_shell only: the lifters, the one moving mesh
    lifters_stl_sha256: str | None = None
    ends_stl: str | None = None  # drum.ends = "rotating" only: the two end plates
    ends_stl_sha256: str | None = None


def wall_motion(case: Case) -> str:
    """The wall representation: 'auto' is the static shell with a surface velocity.

    A cylinder turning about its own axis is the same surface at every instant, so only its
    surface velocity matters; moving its facets every step costs mesh updates and neighbour
    rebuilds for nothing. The lifters do move. Without lifters nothing needs to move at all.
    """
    motion = case.run.wall_motion
    return "static_shell" if motion == "auto" else motion


def geometry_key(case: Case) -> str:
    """What the geometry depends on: drum, lifters, (through 'auto' facets) particle size, and
    the wall representation (``drum.ends`` through the drum section, left out at "fixed" so
    that geometry made before it existed is reused)."""
    return case.section_hash("drum", "lifters") + f":{facet_size(case):.9g}:{wall_motion(case)}"


def _reusable(done: dict | None, rundir: RunDir) -> bool:
    if not done:
        return False
    r = done["result"]
    for name, sha in (("stl", "stl_sha256"), ("lifters_stl", "lifters_stl_sha256"),
                      ("ends_stl", "ends_stl_sha256")):
        if r.get(name) is None:
            continue
        path = rundir.root / r[name]
        if not path.exists() or file_hash(path) != r[sha]:
            return False
    return True


def run(case: Case, rundir: RunDir, runner: Runner | None = None,
        inputs: GeometryInputs | None = None) -> GeometryResult:
    """The geometry stage's entry point (gmsh runs in-process: ``runner`` is not used)."""
    return build_geometry(case, rundir)


def build_geometry(case: Case, rundir: RunDir) -> GeometryResult:
    """Build, check and write the walls; reuse them when the inputs have not changed."""
    key = geometry_key(case)
    done = rundir.stage_done("geometry", key)
    if done and _reusable(done, rundir):
        r = done["result"]
        return GeometryResult(**{**r, "box_lo": tuple(r["box_lo"]), "box_hi": tuple(r["box_hi"])})
    t0 = time.perf_counter()
    motion = wall_motion(case)
    walls = build_wall_mesh(case)
    stats = check_wall_mesh(walls, case)
    lifters_rel = lifters_sha = None
    if motion == "static_shell":
        stl = rundir.geometry / "shell.stl"
        shell = build_wall_mesh(case, with_lifters=False)
        shell_stats = check_wall_mesh(shell, case)
        write_ascii_stl(shell, stl)
        if case.lifters.count > 0:
            lifters = lifter_part(walls, case.drum.radius)
            check_wall_mesh(lifters, case, open_at_shell=True)
            lifters_stl = rundir.geometry / "lifters.stl"
            write_ascii_stl(lifters, lifters_stl)
            lifters_rel = str(lifters_stl.relative_to(rundir.root))
            lifters_sha = file_hash(lifters_stl)
            stats["triangles"] = shell_stats["triangles"] + len(lifters.triangles)
        else:
            stats = shell_stats
    else:
        stl = rundir.geometry / "walls.stl"
        write_ascii_stl(walls, stl)
    ends_rel = ends_sha = None
    if case.drum.ends == "rotating":
        ends = build_end_mesh(case)
        check_wall_mesh(ends, case, open_edges=True)
        ends_stl = rundir.geometry / "ends.stl"
        write_ascii_stl(ends, ends_stl)
        ends_rel = str(ends_stl.relative_to(rundir.root))
        ends_sha = file_hash(ends_stl)
        stats["triangles"] = int(stats["triangles"]) + len(ends.triangles)
    plot_cross_section(case, rundir.geometry_picture)
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
        wall_motion=motion,
        lifters_stl=lifters_rel,
        lifters_stl_sha256=lifters_sha,
        ends_stl=ends_rel,
        ends_stl_sha256=ends_sha,
    )
    rundir.geometry_json.write_text(json.dumps(asdict(result), indent=2))
    rundir.mark_done("geometry", key, asdict(result), time.perf_counter() - t0)
    return result
