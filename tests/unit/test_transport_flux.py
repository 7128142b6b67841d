"""The frozen bed's transport flux in the lab frame (drumflow.air.transport_flux), on a ring of
cells about the axis whose answers are known in closed form, and the film switch of the bed
heat (drumflow.air.bed_heat.exchange_rate with Ranz-Marshall)."""

from __future__ import annotations

import math
from types import SimpleNamespace

import numpy as np
import pytest

from drumflow.air.bed_heat import exchange_rate, heat_file_name
from drumflow.air.transport_flux import (
    frame_flux,
    net_outflow,
    project_like,
    transport_flux,
)
from drumflow.errors import AnalysisInputError
from drumflow.physics.particle_air import AirState, ranz_marshall_h

OMEGA = 0.5236  # the paper's 5 rpm, rad/s


def ring_mesh(n_theta: int = 12, radii: tuple[float, ...] = (0.5, 1.0, 1.5),
              dz: float = 0.1, n_z: int = 2) -> SimpleNamespace:
    """Internal faces of a ring of cells about +z: n_theta sectors (faces at constant theta,
    planar), the radial steps as flat chords, n_z layers. Owner -> neighbour along +theta,
    +r and +z (area vectors out of the owner). Cell centres are the cells' vertex means."""
    nr = len(radii) - 1
    cell = np.arange(n_theta * nr * n_z).reshape(n_theta, nr, n_z)
    theta = 2.0 * math.pi * np.arange(n_theta + 1) / n_theta
    owner, neighbour, centres, areas = [], [], [], []

    def point(i: int, j: float, k: float) -> np.ndarray:
        return np.array([radii[int(j)] * math.cos(theta[i]), radii[int(j)] * math.sin(theta[i]),
                         k * dz])

    for i in range(n_theta):
        for j in range(nr):
            for k in range(n_z):
                # The face at theta_{i+1} between sectors i and i + 1 (normal along +theta).
                a, b = point(i + 1, j, k), point(i + 1, j + 1, k)
                owner.append(cell[i, j, k])
                neighbour.append(cell[(i + 1) % n_theta, j, k])
                centres.append(0.5 * (a + b) + np.array([0.0, 0.0, 0.5 * dz]))
                t = np.array([-math.sin(theta[i + 1]), math.cos(theta[i + 1]), 0.0])
                areas.append(t * (radii[j + 1] - radii[j]) * dz)
                if j + 1 < nr:  # the chord between rings j and j + 1 (normal outward)
                    a, b = point(i, j + 1, k), point(i + 1, j + 1, k)
                    mid = 0.5 * (a + b)
                    owner.append(cell[i, j, k])
                    neighbour.append(cell[i, j + 1, k])
                    centres.append(mid + np.array([0.0, 0.0, 0.5 * dz]))
                    areas.append(mid / np.linalg.norm(mid) * np.linalg.norm(b - a) * dz)
                if k + 1 < n_z:  # the face between layers (normal +z), a flat quad
                    corners = [point(i, j, k + 1), point(i + 1, j, k + 1),
                               point(i + 1, j + 1, k + 1), point(i, j + 1, k + 1)]
                    owner.append(cell[i, j, k])
                    neighbour.append(cell[i, j, k + 1])
                    centres.append(np.mean(corners, axis=0))
                    r0, r1 = radii[j], radii[j + 1]
                    areas.append(np.array([0.0, 0.0, 0.5 * (r1**2 - r0**2)
                                           * math.sin(theta[1])]))
    order = np.lexsort((np.array(neighbour), np.array(owner)))
    cells_xyz = np.array([np.mean([point(a, b, c) for a in (i, i + 1) for b in (j, j + 1)
                                   for c in (k, k + 1)], axis=0)
                          for i in range(n_theta) for j in range(nr) for k in range(n_z)])
    return SimpleNamespace(owner=np.array(owner, np.int64)[order],
                           neighbour=np.array(neighbour, np.int64)[order],
                           face_centres=np.array(centres)[order], face_areas=np.array(areas)[order],
                           cells=cell.size, cell_centres=cells_xyz, dz=dz)


def test_the_frames_flux_through_a_radial_face_is_omega_times_the_integral_of_r() -> None:
    """Through a face at constant theta from r0 to r1, height dz, the drum frame's velocity
    omega r carries omega (r1^2 - r0^2) / 2 dz (exact: the velocity is linear in r); through
    the chords between rings and the faces between layers, nothing (it is tangential)."""
    mesh = ring_mesh()
    q = frame_flux(mesh.face_centres, mesh.face_areas, OMEGA)
    radial = np.abs(mesh.face_areas[:, 2]) < 1e-12
    tangential = np.abs(np.einsum("ij,ij->i", mesh.face_centres[:, :2],
                                  mesh.face_areas[:, :2])) < 1e-12
    sector = radial & tangential  # constant-theta faces: normal perpendicular to the radius
    assert sector.sum() == 12 * 2 * 2
    expected = []
    for c in mesh.face_centres[sector]:
        r = math.hypot(c[0], c[1])
        r0, r1 = (0.5, 1.0) if r < 1.0 else (1.0, 1.5)
        expected.append(OMEGA * 0.5 * (r1**2 - r0**2) * mesh.dz)
    assert q[sector] == pytest.approx(expected, rel=1e-12)
    assert np.max(np.abs(q[~sector])) < 1e-12
    # A ring closed on itself: the frame's flux leaves no cell with a net outflow.
    assert np.max(np.abs(net_outflow(mesh.owner, mesh.neighbour, q, mesh.cells))) < 1e-12


def test_air_at_rest_in_the_lab_has_no_absolute_flux() -> None:
    """MRF writes the flux relative to the drum: air at rest in the lab flows at -omega x r.
    The absolute flux is then zero on every face; with omega 10 % off, it is not."""
    mesh = ring_mesh()
    relative = -frame_flux(mesh.face_centres, mesh.face_areas, OMEGA)
    absolute = transport_flux(mesh, relative, OMEGA, "absolute")  # type: ignore[arg-type]
    scale = np.max(np.abs(relative))
    assert np.max(np.abs(absolute)) < 1e-9 * scale
    off = transport_flux(mesh, relative, 1.1 * OMEGA, "absolute")  # type: ignore[arg-type]
    assert np.max(np.abs(off)) > 0.09 * scale
    assert np.array_equal(transport_flux(mesh, relative, OMEGA, "relative"),  # type: ignore[arg-type]
                          relative)


def test_air_carried_by_a_bed_turning_with_the_drum_moves_with_it() -> None:
    """Air at rest in the lab, and a bed filling every cell at voidage 0.4 that turns with the
    drum: the carried flux is 0.4 of the frame's own (the face mean of the cells' eps omega x r,
    within the chords' geometry: the centres' radii are cos^2(pi / 48) = 0.4 % short)."""
    mesh = ring_mesh(n_theta=48)
    frame = frame_flux(mesh.face_centres, mesh.face_areas, OMEGA)
    c = mesh.cell_centres
    carried = 0.4 * OMEGA * np.column_stack([-c[:, 1], c[:, 0], np.zeros(len(c))])
    q = transport_flux(mesh, -frame, OMEGA, "carried", carried)  # type: ignore[arg-type]
    sector = np.abs(frame) > 1e-9
    assert q[sector] == pytest.approx(0.4 * frame[sector], rel=0.01)
    assert np.max(np.abs(q[~sector])) < 0.01 * np.max(np.abs(q))


def test_the_projection_keeps_each_cells_net_outflow() -> None:
    """A random flux projected to a random balanced target has that net per cell; a flux that
    already has it is returned unchanged; an unbalanced target is refused."""
    mesh = ring_mesh()
    rng = np.random.default_rng(7)
    target = rng.normal(size=mesh.cells)
    target -= target.mean()
    flux = rng.normal(size=len(mesh.neighbour))
    out = project_like(mesh.owner, mesh.neighbour, flux, target)
    assert net_outflow(mesh.owner, mesh.neighbour, out, mesh.cells) == pytest.approx(target,
                                                                                     abs=1e-9)
    again = project_like(mesh.owner, mesh.neighbour, out, target)
    assert again == pytest.approx(out, abs=1e-9)
    with pytest.raises(AnalysisInputError, match="transport flux"):
        project_like(mesh.owner, mesh.neighbour, flux, target + 1.0)


def test_bad_flux_choices_are_refused_by_name() -> None:
    mesh = ring_mesh()
    q = np.zeros(len(mesh.neighbour))
    with pytest.raises(AnalysisInputError, match="flux"):
        transport_flux(mesh, q, OMEGA, "lab")  # type: ignore[arg-type]
    with pytest.raises(AnalysisInputError, match="carried_velocity"):
        transport_flux(mesh, q, OMEGA, "carried")  # type: ignore[arg-type]


def test_the_loops_film_law_in_the_frozen_analysis() -> None:
    """``film="ranz_marshall"``: h = Ranz-Marshall at |U - v_p| and the granule's diameter,
    k = h a_v / (rho c_p), a_v = 6 phi / d (by hand); against Gunn's at the same cell it is
    lower in a packed bed at low Re (Gunn's fixed-bed term (7 - 10 eps + 5 eps^2) > 2)."""
    air = AirState.at(30.0)
    cp, d = 1007.0, 0.008
    phi = np.array([0.6, 0.3])
    U = np.array([[0.2, 0.0, 0.0], [1.0, 0.0, 0.5]])
    v_p = np.array([[0.0, 0.5, 0.0], [0.0, 0.0, 0.0]])
    h, k = exchange_rate(phi, U, v_p, d, air, cp, film="ranz_marshall")
    slip = np.array([math.hypot(0.2, 0.5), math.hypot(1.0, 0.5)])
    re = air.density * slip * d / air.viscosity
    by_hand = 2.0 * (1.0 + 0.3 * np.sqrt(re) * air.prandtl ** (1.0 / 3.0)) * air.conductivity / d
    assert h == pytest.approx(by_hand, rel=1e-12)
    assert h == pytest.approx(ranz_marshall_h(slip, d, air), rel=1e-12)
    assert k == pytest.approx(by_hand * 6.0 * phi / d / (air.density * cp), rel=1e-12)
    gunn, _ = exchange_rate(phi, U, v_p, d, air, cp)
    assert h[0] < gunn[0]
    with pytest.raises(AnalysisInputError, match="film"):
        exchange_rate(phi, U, v_p, d, air, cp, film="whitaker")


def test_heat_file_names_name_what_differs_from_the_defaults() -> None:
    assert heat_file_name() == "heat.json"
    assert heat_file_name("molecular") == "heat_molecular.json"
    assert heat_file_name("turbulent") == "heat_turbulent.json"
    assert heat_file_name(flux="absolute") == "heat_absolute.json"
    assert (heat_file_name("molecular", "absolute", "ranz_marshall")
            == "heat_molecular_absolute_ranz_marshall.json")
