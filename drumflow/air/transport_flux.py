"""The face flux a frozen bed's air temperature is carried with: in which frame, and with what.

A bed-air solution (:mod:`drumflow.air.bed_air`) is MRF: ``U`` is the absolute velocity and
``phi`` the flux *relative to the drum* (OpenFOAM's frozen-rotor convention). The bed and the
curtains, frozen on the cells, then sit still in the drum's frame, and a temperature carried
with ``phi`` sweeps them with the air's velocity relative to the drum: the bed's air, nearly
still in the lab (the Ergun drag holds it), passes through the packing at up to the wall's
speed. The bed's region stays where gravity holds it while the drum turns, so in the lab frame
the heat sources are steady and the air's temperature is carried with the absolute flux;
the coupled loop (:mod:`drumflow.air.heat`) does that. Which one stands nearer the truth is what
:func:`transport_flux`'s choices (:data:`FLUX`) let one measure on the same solved flow:

- ``"relative"``: ``phi`` as solved (the frozen analysis' convention until 2026-11-29);
- ``"absolute"``: ``phi + (omega z x C_f) . S_f`` on the internal faces, the lab frame; the
  lifters' walls, which move in the lab, carry nothing (as in the loop), so the flux is made
  divergence-free again (:func:`project_like`);
- ``"carried"``: the absolute flux plus the air the rolling bed carries in its voids,
  ``eps v_p`` on the faces of the bed's cells (the cells' particle means), made divergence-free:
  the bed's particles turn with the drum and their air with them (the air in a packing follows
  its particles within milliseconds), which the drag on the absolute velocity leaves out. Only
  in the bed's cells: a dilute curtain's air is not its particles' (the drag is weak there).

The MRF zone is the whole fluid, turning about +z through the origin
(:func:`drumflow.air.foam_case.write_mrf`), so the frame's flux is exact on planar
faces: omega z x r is linear in r, and its integral over a planar face is its value at the
centroid times the area vector.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
import scipy.sparse as sp
from numpy.typing import NDArray
from scipy.sparse.linalg import LinearOperator, cg

from drumflow.errors import AnalysisInputError

if TYPE_CHECKING:
    from drumflow.air.poly_mesh import PolyMesh

__all__ = ["FLUX", "frame_flux", "net_outflow", "project_like", "transport_flux"]

#: The transport flux's choices (module docstring): relative (as solved), absolute, carried.
FLUX = ("relative", "absolute", "carried")


def frame_flux(face_centres: NDArray[np.float64], face_areas: NDArray[np.float64],
               omega: float) -> NDArray[np.float64]:
    """(omega z x C_f) . S_f per face, m^3/s: the drum frame's own flux through each face."""
    c, s = np.asarray(face_centres, float), np.asarray(face_areas, float)
    # omega z x (x, y, z) = omega (-y, x, 0)
    return np.asarray(omega * (-c[:, 1] * s[:, 0] + c[:, 0] * s[:, 1]), float)


def net_outflow(owner: NDArray[np.int64], neighbour: NDArray[np.int64], flux: NDArray[np.float64],
                cells: int) -> NDArray[np.float64]:
    """Each cell's net outflow through its internal faces, m^3/s (``flux`` owner -> neighbour)."""
    ni = len(neighbour)
    q = np.asarray(flux, float)[:ni]
    return np.asarray(np.bincount(owner[:ni], weights=q, minlength=cells)
                      - np.bincount(neighbour, weights=q, minlength=cells), float)


def project_like(owner: NDArray[np.int64], neighbour: NDArray[np.int64],
                 flux: NDArray[np.float64], target: NDArray[np.float64],
                 rtol: float = 1e-12) -> NDArray[np.float64]:
    """The internal-face fluxes nearest ``flux`` (least squares) whose net outflow per cell is
    ``target``: ``flux - (p_N - p_O)`` with L p = target - net(flux), L the cells' graph
    Laplacian (one potential pinned; the sums of both sides agree when the boundary fluxes are
    those of ``target``'s flux).

    Raises
    ------
    drumflow.errors.AnalysisInputError
        The two nets do not sum alike (the boundary fluxes differ), or the solve did not converge.
    """
    n = len(target)
    ni = len(neighbour)
    o, nb = owner[:ni], neighbour
    rhs = np.asarray(target, float) - net_outflow(owner, neighbour, flux, n)
    scale = float(np.sum(np.abs(rhs))) or 1.0
    if abs(float(rhs.sum())) > 1e-9 * scale + 1e-15:
        raise AnalysisInputError("transport flux", f"net imbalance {rhs.sum():.3g} m3/s",
                                 "the same boundary fluxes as the solved flux")
    ones = np.ones(ni)
    lap = sp.coo_matrix((np.concatenate([ones, ones, -ones, -ones]),
                         (np.concatenate([o, nb, o, nb]), np.concatenate([o, nb, nb, o]))),
                        shape=(n, n)).tocsr()
    # Pin cell 0's potential: the rest is symmetric positive definite.
    inner = lap[1:, 1:]
    diagonal = inner.diagonal()
    jacobi = LinearOperator(inner.shape, lambda r: r / diagonal)
    p_inner, info = cg(inner, rhs[1:], rtol=rtol, atol=0.0, maxiter=50 * n, M=jacobi)
    if info != 0:
        raise AnalysisInputError("transport flux", f"projection not converged ({info})",
                                 "a connected mesh")
    p = np.concatenate([[0.0], p_inner])
    # net(flux - (p_N - p_O)) = net(flux) + L p
    return np.asarray(np.asarray(flux, float)[:ni] - (p[nb] - p[o]), float)


def transport_flux(mesh: PolyMesh, relative: NDArray[np.float64], omega: float, choice: str,
                   carried_velocity: NDArray[np.float64] | None = None) -> NDArray[np.float64]:
    """The internal faces' flux (m^3/s) to carry the air's temperature with (module docstring).

    Parameters
    ----------
    mesh
        The bed case's mesh (the MRF zone the whole fluid, about +z through the origin).
    relative
        ``phi`` as solved, internal faces first (its boundary fluxes are kept).
    omega
        The drum's angular speed, rad/s (the MRF zone's).
    choice
        One of :data:`FLUX`.
    carried_velocity
        ``"carried"`` only: per cell the superficial velocity of the air the particles carry,
        m/s (eps v_p in the bed's cells, zero elsewhere), in the mesh's axes.

    Returns
    -------
    The internal faces' fluxes, owner -> neighbour, with the same net outflow per cell as
    ``relative`` (so the boundary's fluxes, the walls' zero among them, still close every cell).
    """
    if choice not in FLUX:
        raise AnalysisInputError("flux", choice, " or ".join(FLUX))
    ni = len(mesh.neighbour)
    q = np.asarray(relative, float)[:ni]
    if choice == "relative":
        return q.copy()
    cells = int(max(mesh.owner.max(), mesh.neighbour.max())) + 1
    target = net_outflow(mesh.owner, mesh.neighbour, q, cells)
    absolute = q + frame_flux(mesh.face_centres[:ni], mesh.face_areas[:ni], omega)
    if choice == "carried":
        shape = None if carried_velocity is None else np.shape(carried_velocity)
        if carried_velocity is None or shape != (cells, 3):
            raise AnalysisInputError("carried_velocity", shape,
                                     f"one velocity per cell ({cells}, 3)")
        u = np.asarray(carried_velocity, float)
        face_u = 0.5 * (u[mesh.owner[:ni]] + u[mesh.neighbour])
        absolute = absolute + np.einsum("ij,ij->i", face_u, mesh.face_areas[:ni])
    return project_like(mesh.owner, mesh.neighbour, absolute, target)
