"""The parts of an OpenFOAM polyMesh that measurements on a solved air case need: the face
owners and neighbours, centres and area vectors, and the patches (read with foamlib)."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

__all__ = ["PolyMesh", "read_poly_mesh"]


@dataclass(frozen=True)
class PolyMesh:
    """The parts of an OpenFOAM polyMesh the measurements need.

    ``owner`` of every face, ``neighbour`` of the internal ones (the first faces); per face its
    centre (m) and area vector (m^2, out of the owner); ``patches``: name -> (start face,
    count); ``bounds``: the lower and upper corner of the mesh points, m.
    """

    owner: NDArray[np.int64]
    neighbour: NDArray[np.int64]
    face_centres: NDArray[np.float64]
    face_areas: NDArray[np.float64]
    patches: dict[str, tuple[int, int]]
    bounds: tuple[NDArray[np.float64], NDArray[np.float64]]

    def patch_faces(self, name: str) -> slice:
        start, count = self.patches[name]
        return slice(start, start + count)


def read_poly_mesh(case_dir: Path) -> PolyMesh:
    """Read ``constant/polyMesh`` (ascii) and compute the face centres and area vectors.

    Faces are split into triangles fanned about their mean point; the area vector is the sum
    of the triangles', the centre their area-weighted mean (exact for the triangles of a
    tetrahedral mesh).
    """
    from foamlib import FoamFile

    poly = case_dir / "constant" / "polyMesh"
    points = np.asarray(FoamFile(poly / "points")[None], dtype=float).reshape(-1, 3)
    owner = np.asarray(FoamFile(poly / "owner")[None], dtype=np.int64).ravel()
    neighbour = np.asarray(FoamFile(poly / "neighbour")[None], dtype=np.int64).ravel()
    faces: Any = FoamFile(poly / "faces")[None]
    sizes = np.array([len(f) for f in faces])
    centres = np.zeros((len(faces), 3))
    areas = np.zeros((len(faces), 3))
    for size in np.unique(sizes):
        which = np.flatnonzero(sizes == size)
        verts = points[np.array([np.asarray(faces[i], dtype=np.int64) for i in which])]
        mid = verts.mean(axis=1)
        a = np.zeros((len(which), 3))
        weighted = np.zeros((len(which), 3))
        total = np.zeros(len(which))
        for j in range(size):
            p0, p1 = verts[:, j], verts[:, (j + 1) % size]
            tri = 0.5 * np.cross(p0 - mid, p1 - mid)
            a += tri
            w = np.linalg.norm(tri, axis=1)
            weighted += w[:, None] * (p0 + p1 + mid) / 3.0
            total += w
        areas[which] = a
        centres[which] = weighted / np.maximum(total, 1e-300)[:, None]
    boundary: Any = FoamFile(poly / "boundary")[None]
    patches = {str(name): (int(p["startFace"]), int(p["nFaces"])) for name, p in boundary}
    return PolyMesh(owner, neighbour, centres, areas, patches,
                    (points.min(axis=0), points.max(axis=0)))
