"""The drum section built with gmsh's Python API: wall STL for LIGGGHTS, fluid mesh for OpenFOAM.

The cross-section (shell disk minus the lifters) is extruded along z over the section length.
Its lateral surfaces (shell and lifters) are the DEM walls, written as one ASCII STL; its two
end faces are the air inlet and outlet. In the DEM the ends are closed by two flat,
frictional, non-rotating planes (LIGGGHTS primitive walls), which is what the paper did: the
inlet and outlet were "phase-impermeable" to particles, so a constant number of particles stays
in the section. Planes are exact and cost no mesh contacts; an axially periodic section would
instead need the mesh to cross the periodic boundary, which LIGGGHTS' mesh walls handle poorly,
and would let the tilt drive an endless axial drift that the paper's closed section does not
have.

``drum.ends`` chooses otherwise: ``"rotating"`` closes the section with two flat disks that turn
with the shell (:func:`build_end_mesh`; a disk turning about its own axis is the same surface at
every instant, so LIGGGHTS keeps it in place with the shell's surface velocity), as a real drum's
end walls do; ``"periodic"`` has no end walls and a box periodic along z over exactly the section
length (:func:`simulation_box`), the middle of a long drum.
"""

from __future__ import annotations

import math
import signal
import threading
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from drumflow.case.lifter_shape import all_plates
from drumflow.errors import GeometryError

if TYPE_CHECKING:
    from drumflow.case import Case


def facet_size(case: Case) -> float:
    """The STL facet edge length, m.

    'auto' keeps facets at most four particle diameters and 1/72 of the circumference: a
    3 m drum with facets of the drum's own scale made LIGGGHTS 3.8 stop with
    ``assertion failed (region_neighbor_list_I.h:165)`` while a finely faceted shell ran.
    """
    if case.drum.facet_size != "auto":
        return float(case.drum.facet_size)
    R = case.drum.radius
    return min(4.0 * case.particles.diameter, 2.0 * math.pi * R / 72.0, 0.5 * case.drum.length)


@dataclass(frozen=True)
class WallMesh:
    """The triangulated walls: (n, 3) points and (m, 3) triangles."""

    points: NDArray[np.float64]
    triangles: NDArray[np.int64]

    @property
    def triangle_count(self) -> int:
        return len(self.triangles)


@dataclass(frozen=True)
class SimulationBox:
    """The DEM box: particles leaving it are lost (and counted)."""

    lo: tuple[float, float, float]
    hi: tuple[float, float, float]


def simulation_box(case: Case) -> SimulationBox:
    """A box hugging the drum with a margin of two particle diameters.

    A tight box means a particle that leaks through the shell leaves the box within a few
    steps and is counted as lost, instead of falling unseen outside the drum. With
    ``drum.ends = "periodic"`` the box spans exactly the section along z (0 to the length): its
    period is the section length, and the walls end on its faces.
    """
    R = case.drum.radius
    m = max(2.0 * case.particles.diameter, 0.01 * R)
    if case.drum.ends == "periodic":
        return SimulationBox((-R - m, -R - m, 0.0), (R + m, R + m, case.drum.length))
    return SimulationBox((-R - m, -R - m, -m), (R + m, R + m, case.drum.length + m))


def _build_cross_section(gmsh_model: object, case: Case, with_lifters: bool = True) -> int:
    """Create the shell disk minus lifters in OCC; return the surface tag."""
    import gmsh

    occ = gmsh.model.occ
    R = case.drum.radius
    disk = occ.addDisk(0.0, 0.0, 0.0, R, R)
    tools: list[tuple[int, int]] = []
    for plate in all_plates(R, case.lifters) if with_lifters else []:
        corners = plate.corners()
        pts = [occ.addPoint(float(x), float(y), 0.0) for x, y in corners]
        lines = [occ.addLine(pts[i], pts[(i + 1) % 4]) for i in range(4)]
        loop = occ.addCurveLoop(lines)
        tools.append((2, occ.addPlaneSurface([loop])))
    if tools:
        out, _ = occ.cut([(2, disk)], tools, removeObject=True, removeTool=True)
        surfaces = [tag for dim, tag in out if dim == 2]
        if len(surfaces) != 1:
            raise GeometryError(
                f"the lifters split the drum cross-section into {len(surfaces)} parts; "
                "check lifters.base_height, lip_length and lip_angle_deg"
            )
        return surfaces[0]
    return disk


def _classify_surfaces(length: float, tol: float) -> dict[str, list[int]]:
    import gmsh

    groups: dict[str, list[int]] = {"walls": [], "inlet": [], "outlet": []}
    for _, tag in gmsh.model.getEntities(2):
        xmin, ymin, zmin, xmax, ymax, zmax = gmsh.model.getBoundingBox(2, tag)
        if zmax < tol:
            groups["inlet"].append(tag)
        elif zmin > length - tol:
            groups["outlet"].append(tag)
        else:
            groups["walls"].append(tag)
    return groups


#: The signals whose Python handlers a gmsh session must leave as it found them.
_KEPT_SIGNALS = (signal.SIGINT, signal.SIGTERM)


def _reinstall_python_handlers(saved: dict[signal.Signals, Any]) -> None:
    """Hand the signals back to Python's handlers: gmsh.initialize resets SIGTERM to the default
    action in C (Python's own record still names its handler), so a `kill` of the CLI ended it
    at once and left mpirun running. Only the main thread may set handlers."""
    if threading.current_thread() is not threading.main_thread():
        return
    for sig, handler in saved.items():
        if handler is not None:
            signal.signal(sig, handler)


class _Gmsh:
    """Context manager for one gmsh session (gmsh keeps global state; always finalize)."""

    def __enter__(self) -> None:
        import gmsh

        self._saved = {sig: signal.getsignal(sig) for sig in _KEPT_SIGNALS}
        if gmsh.isInitialized():
            gmsh.finalize()
        # interruptible=False: gmsh would otherwise install its own SIGINT handler, and
        # Ctrl-C must reach drumflow's runner instead.
        gmsh.initialize(interruptible=False)
        _reinstall_python_handlers(self._saved)
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.option.setNumber("General.Verbosity", 1)

    def __exit__(self, *exc: object) -> None:
        import gmsh

        gmsh.finalize()
        _reinstall_python_handlers(self._saved)


def build_wall_mesh(case: Case, size: float | None = None, with_lifters: bool = True) -> WallMesh:
    """Triangulate the shell and lifter surfaces of the section with gmsh.

    Parameters
    ----------
    case
        The validated case.
    size
        Facet edge length, m; default :func:`facet_size`.
    with_lifters
        ``False``: the bare cylinder (the static shell of ``run.wall_motion = "static_shell"``).
    """
    return _mesh_section(case, size, with_lifters, ("walls",))


def build_end_mesh(case: Case, size: float | None = None) -> WallMesh:
    """Triangulate the two end plates of the section (``drum.ends = "rotating"``): full disks of
    the shell's radius at z = 0 and z = length.

    Full disks, not the cross-section between the lifters: the plates turn with the shell but
    stay in place in LIGGGHTS (surface velocity), so holes cut where the lifters stand at t = 0
    would be open once the lifters have moved on. The lifters' open ends touch the disks.
    """
    return _mesh_section(case, size, False, ("inlet", "outlet"))


def _mesh_section(case: Case, size: float | None, with_lifters: bool,
                  parts: tuple[str, ...]) -> WallMesh:
    """The surfaces ``parts`` ("walls", "inlet", "outlet") of the extruded section as one mesh."""
    import gmsh

    size = facet_size(case) if size is None else size
    length = case.drum.length
    with _Gmsh():
        gmsh.model.add("drum")
        surface = _build_cross_section(gmsh.model, case, with_lifters)
        gmsh.model.occ.extrude([(2, surface)], 0.0, 0.0, length)
        gmsh.model.occ.synchronize()
        groups = _classify_surfaces(length, 1e-6 * max(length, 1.0))
        wanted = [tag for part in parts for tag in groups[part]]
        if not groups["walls"] or not wanted:
            raise GeometryError(f"gmsh produced no {' or '.join(parts)} surfaces for the drum")
        gmsh.option.setNumber("Mesh.MeshSizeMax", size)
        gmsh.option.setNumber("Mesh.MeshSizeMin", 0.2 * size)
        gmsh.option.setNumber("Mesh.MeshSizeFromCurvature", 36)
        gmsh.option.setNumber("Mesh.Algorithm", 6)  # Frontal-Delaunay: well-shaped facets
        gmsh.model.mesh.generate(2)
        node_tags, coords, _ = gmsh.model.mesh.getNodes()
        index = np.zeros(int(node_tags.max()) + 1, dtype=np.int64)
        index[node_tags.astype(np.int64)] = np.arange(len(node_tags))
        points = coords.reshape(-1, 3)
        tris: list[NDArray[np.int64]] = []
        for tag in wanted:
            etypes, _, enodes = gmsh.model.mesh.getElements(2, tag)
            for etype, nodes in zip(etypes, enodes, strict=True):
                if etype != 2:  # 3-node triangles only; anything else means a bad mesh
                    raise GeometryError(f"unexpected gmsh element type {etype} on the walls")
                tris.append(index[nodes.astype(np.int64)].reshape(-1, 3))
    triangles = np.concatenate(tris)
    used = np.unique(triangles)
    remap = np.full(len(points), -1, dtype=np.int64)
    remap[used] = np.arange(len(used))
    return WallMesh(points[used].copy(), remap[triangles])


def _on_shell(points: NDArray[np.float64], radius: float) -> NDArray[np.bool_]:
    return np.abs(np.hypot(points[..., 0], points[..., 1]) - radius) < 1e-6 * radius


def lifter_part(mesh: WallMesh, radius: float) -> WallMesh:
    """The lifters alone: the triangles of the combined walls not lying on the shell cylinder.

    A shell facet has all three corners on the cylinder; a lifter face is a plate side, whose
    corners cannot all sit on the cylinder without the triangle being degenerate.
    """
    on = _on_shell(mesh.points[mesh.triangles], radius).all(axis=1)
    triangles = mesh.triangles[~on]
    used = np.unique(triangles)
    remap = np.full(len(mesh.points), -1, dtype=np.int64)
    remap[used] = np.arange(len(used))
    return WallMesh(mesh.points[used].copy(), remap[triangles])


def check_wall_mesh(mesh: WallMesh, case: Case, open_at_shell: bool = False,
                    open_edges: bool = False) -> dict[str, float | int]:
    """Check the wall mesh before LIGGGHTS sees it; return its statistics.

    Checks: no degenerate triangles (area or smallest angle); every edge shared by exactly two
    triangles except the open rims at the two end planes (the shell is closed around the
    circumference and along the lifters); every point inside the simulation box.
    ``open_at_shell``: the lifters alone, open also where their feet meet the shell.
    ``open_edges``: flat end plates, whose rims are open by nature (edges are not checked).

    Raises
    ------
    GeometryError
        Naming the failed check and what was found.
    """
    p, t = mesh.points, mesh.triangles
    a, b, c = p[t[:, 0]], p[t[:, 1]], p[t[:, 2]]
    area = 0.5 * np.linalg.norm(np.cross(b - a, c - a), axis=1)
    edges_len = np.stack(
        [np.linalg.norm(b - a, axis=1), np.linalg.norm(c - b, axis=1), np.linalg.norm(a - c, axis=1)],
        axis=1,
    )
    longest = edges_len.max(axis=1)
    # Smallest altitude over longest edge: 0 for a sliver, sqrt(3)/2 for equilateral.
    quality = 2.0 * area / np.maximum(longest, 1e-300) ** 2
    if (area <= 1e-14 * longest.max() ** 2).any():
        raise GeometryError(f"{int((area <= 0).sum())} degenerate (zero-area) triangles in the walls")
    if quality.min() < 0.02:
        raise GeometryError(
            f"wall mesh has a sliver triangle (altitude/edge {quality.min():.3g} < 0.02)"
        )
    e = np.sort(np.concatenate([t[:, [0, 1]], t[:, [1, 2]], t[:, [2, 0]]]), axis=1)
    uniq, counts = np.unique(e, axis=0, return_counts=True)
    if (counts > 2).any():
        raise GeometryError(f"{int((counts > 2).sum())} non-manifold edges in the walls")
    rim_edges = uniq[counts == 1]
    length = case.drum.length
    tol = 1e-6 * max(length, 1.0)
    z = p[rim_edges][:, :, 2]
    on_rim = ((np.abs(z) < tol) | (np.abs(z - length) < tol)).all(axis=1)
    if open_at_shell:
        on_rim |= _on_shell(p[rim_edges], case.drum.radius).all(axis=1)
    if open_edges:
        on_rim[:] = True
    if not on_rim.all():
        raise GeometryError(
            f"the walls are open along {int((~on_rim).sum())} edges away from the end planes"
        )
    box = simulation_box(case)
    if (p < np.array(box.lo)).any() or (p > np.array(box.hi)).any():
        raise GeometryError("the wall mesh reaches outside the simulation box")
    return {
        "triangles": int(len(t)),
        "points": int(len(p)),
        "open_rim_edges": int(len(rim_edges)),
        "min_quality": float(quality.min()),
        "max_edge_m": float(longest.max()),
        "wall_area_m2": float(area.sum()),
    }


def write_ascii_stl(mesh: WallMesh, path: Path) -> None:
    """Write the walls as ASCII STL (LIGGGHTS 3.8 reads ASCII only)."""
    import meshio

    path.parent.mkdir(parents=True, exist_ok=True)
    m = meshio.Mesh(mesh.points, [("triangle", mesh.triangles)])
    meshio.write(path, m, file_format="stl", binary=False)


def plot_cross_section(
    case: Case, path: Path, particles_xy: NDArray[np.float64] | None = None
) -> None:
    """PNG of the drum cross-section with its lifters (and optionally particle positions)."""
    from drumflow._mpl import pyplot

    plt = pyplot()
    from matplotlib.patches import Circle, Polygon

    R = case.drum.radius
    fig, ax = plt.subplots(figsize=(5.5, 5.5), dpi=120)
    ax.add_patch(Circle((0, 0), R, fill=False, lw=2, color="0.2"))
    for plate in all_plates(R, case.lifters):
        corners = plate.corners()
        # Clip the part of the base beyond the shell for drawing.
        r = np.hypot(corners[:, 0], corners[:, 1])
        scale = np.minimum(1.0, R / np.maximum(r, 1e-300))
        ax.add_patch(Polygon(corners * scale[:, None], closed=True, color="0.35"))
    if particles_xy is not None and len(particles_xy):
        ax.scatter(particles_xy[:, 0], particles_xy[:, 1], s=2, color="tab:orange", lw=0)
    ax.annotate(
        "", xy=(0.85 * R * math.cos(0.5), 0.85 * R * math.sin(0.5)),
        xytext=(0.85 * R * math.cos(-0.2), 0.85 * R * math.sin(-0.2)),
        arrowprops={"arrowstyle": "->", "color": "tab:blue", "connectionstyle": "arc3,rad=0.3"},
    )
    ax.set_xlim(-1.08 * R, 1.08 * R)
    ax.set_ylim(-1.08 * R, 1.08 * R)
    ax.set_aspect("equal")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    lf = case.lifters
    ax.set_title(
        f"{case.name}: D = {case.drum.diameter:g} m, {lf.count} {lf.profile} lifters, "
        f"{case.drum.rpm:g} rpm",
        fontsize=9,
    )
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path)
    plt.close(fig)
