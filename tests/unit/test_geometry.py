"""Lifter shapes, the gmsh wall mesh and its checks."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from drumflow.case import case_from_dict
from drumflow.case.lifter_shape import lifter_gap, lifter_plates
from drumflow.errors import GeometryError
from drumflow.geometry.drum import (
    WallMesh,
    build_wall_mesh,
    check_wall_mesh,
    lifter_part,
    simulation_box,
    write_ascii_stl,
)
from drumflow.geometry.lifters import distance_to_lifters


def test_straight_lifter_gap_is_analytic(smoke_dict: dict) -> None:
    smoke_dict["lifters"].update(profile="straight", lip_length=0.0, count=8)
    case = case_from_dict(smoke_dict)
    R, h, t = 0.2, 0.04, 0.004
    # Two radial plates 45 degrees apart: closest corners are at the tips, on the sides that
    # face each other: chord between the tip corners minus nothing (corners are the points).
    tip = R - h
    a = np.array([tip, t / 2])
    b_ang = math.pi / 4
    rot = np.array([[math.cos(b_ang), -math.sin(b_ang)], [math.sin(b_ang), math.cos(b_ang)]])
    b = rot @ np.array([tip, -t / 2])
    assert lifter_gap(R, case.lifters) == pytest.approx(float(np.linalg.norm(a - b)), rel=1e-9)


def test_distance_to_lifters_signs(smoke_dict: dict) -> None:
    case = case_from_dict(smoke_dict)
    R = case.drum.radius
    base = lifter_plates(R, case.lifters, 0.0)[0]
    inside = np.array([base.center])
    far = np.array([[0.0, 0.0]])
    assert distance_to_lifters(inside, R, case.lifters)[0] < 0
    # The centre is R - base_height - lip thickness/2 ... at least R - h - t from every plate.
    assert distance_to_lifters(far, R, case.lifters)[0] > R - 0.04 - 0.004 - 1e-9 - 0.02


def test_wall_mesh_is_closed_and_checked(smoke_dict: dict, tmp_path: Path) -> None:
    case = case_from_dict(smoke_dict)
    mesh = build_wall_mesh(case)
    stats = check_wall_mesh(mesh, case)
    # Lateral area: shell circumference minus lifter roots, plus both faces of every plate;
    # bounded between the bare shell and shell + two faces of every plate.
    shell = 2 * math.pi * 0.2 * 0.08
    plates = 8 * 2 * (0.04 + 0.02) * 0.08
    assert shell < stats["wall_area_m2"] < shell + plates + 1e-9
    path = tmp_path / "walls.stl"
    write_ascii_stl(mesh, path)
    text = path.read_text()
    assert text.startswith("solid") and text.count("facet normal") == stats["triangles"]


def test_static_shell_parts(smoke_dict: dict) -> None:
    """The bare cylinder is closed with area 2 pi R l (to faceting); the lifters alone are open
    only at their feet and the end rims, and shell + lifters cover the combined walls."""
    case = case_from_dict(smoke_dict)
    R, length = case.drum.radius, case.drum.length
    shell = build_wall_mesh(case, with_lifters=False)
    shell_stats = check_wall_mesh(shell, case)
    assert shell_stats["wall_area_m2"] == pytest.approx(2 * math.pi * R * length, rel=2e-3)
    walls = build_wall_mesh(case)
    lifters = lifter_part(walls, R)
    lifter_stats = check_wall_mesh(lifters, case, open_at_shell=True)
    with pytest.raises(GeometryError, match="open along"):
        check_wall_mesh(lifters, case)
    # Every lifter point lies inside the shell; lifters lose only shell facets.
    assert np.hypot(lifters.points[:, 0], lifters.points[:, 1]).max() <= R * (1 + 1e-6)
    walls_area = check_wall_mesh(walls, case)["wall_area_m2"]
    upper = lifter_stats["wall_area_m2"] + shell_stats["wall_area_m2"]
    assert lifter_stats["wall_area_m2"] < walls_area < upper


def test_check_rejects_a_hole(smoke_dict: dict) -> None:
    case = case_from_dict(smoke_dict)
    mesh = build_wall_mesh(case)
    # Drop one triangle in the middle of the shell: the mesh is then open away from the rims.
    z = mesh.points[mesh.triangles][:, :, 2].mean(axis=1)
    middle = int(np.argmin(np.abs(z - 0.04)))
    holed = WallMesh(mesh.points, np.delete(mesh.triangles, middle, axis=0))
    with pytest.raises(GeometryError, match="open along"):
        check_wall_mesh(holed, case)


def test_check_rejects_degenerate_triangle(smoke_dict: dict) -> None:
    case = case_from_dict(smoke_dict)
    mesh = build_wall_mesh(case)
    bad = np.vstack([mesh.triangles, [[0, 0, 1]]])
    with pytest.raises(GeometryError, match="degenerate"):
        check_wall_mesh(WallMesh(mesh.points, bad), case)


def test_check_rejects_points_outside_box(smoke_dict: dict) -> None:
    case = case_from_dict(smoke_dict)
    mesh = build_wall_mesh(case)
    moved = WallMesh(mesh.points * 1.5, mesh.triangles)
    with pytest.raises(GeometryError):
        check_wall_mesh(moved, case)


def test_auto_facets_are_small_for_the_paper_drum() -> None:
    from drumflow.case import load_case
    from drumflow.geometry.drum import facet_size

    case = load_case(Path(__file__).resolve().parents[2] / "cases" / "paper_model_one.toml")
    # Coarse facets on a 3 m drum tripped LIGGGHTS' region_neighbor_list assertion.
    assert facet_size(case) <= 4 * case.particles.diameter
    box = simulation_box(case)
    assert box.hi[0] - box.lo[0] < 3.1
