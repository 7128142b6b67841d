"""The air field on its drum-frame grid: sampling, filling, frames, plug flow, cache keys.

Pure tests: no OpenFOAM (the solver tests are in tests/solver/test_openfoam.py).
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from drumflow.air.field import AirField, air_cache_key
from drumflow.air.field_grid import fluid_mask_xy, local_linear_fit
from drumflow.air.field_picture import plot_air_cross_section
from drumflow.air.foam_case import inlet_turbulence
from drumflow.air.foam_results import parse_residual_log
from drumflow.air.mesh import parse_check_mesh
from drumflow.case import Case, case_from_dict
from drumflow.errors import AirNotConvergedError
from drumflow.geometry.lifters import lifter_area
from drumflow.physics.drum_frame import rotate_to_drum_frame, rotate_to_lab_frame


def _linear_field(shape: tuple[int, int, int] = (9, 7, 5)) -> tuple[AirField, np.ndarray, np.ndarray]:
    A = np.array([[0.3, -1.2, 0.5], [2.0, 0.1, -0.7], [-0.4, 0.9, 1.5]])
    b = np.array([0.2, -0.1, -3.0])
    origin = np.array([-0.2, -0.2, 0.0])
    spacing = np.array([0.05, 0.0667, 0.02])
    axes = [origin[i] + spacing[i] * np.arange(shape[i]) for i in range(3)]
    X = np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1)
    U = X @ A.T + b
    P = X @ np.array([10.0, -4.0, 25.0]) + 7.0
    field = AirField(origin, spacing, U, P, np.ones(shape, bool), omega=1.0)
    return field, A, b


def _case(smoke_dict: dict[str, Any], **air: Any) -> Case:
    smoke_dict["air"].update(air)
    return case_from_dict(smoke_dict)


def test_trilinear_sampling_is_exact_for_a_linear_field() -> None:
    field, A, b = _linear_field()
    rng = np.random.default_rng(1)
    lo = field.origin
    hi = field.origin + field.spacing * (np.array(field.shape) - 1)
    pts = lo + rng.random((5000, 3)) * (hi - lo)
    pts[:3] = [lo, hi, 0.5 * (lo + hi)]  # the grid's corners and centre too
    np.testing.assert_allclose(field.sample(pts), pts @ A.T + b, rtol=0, atol=1e-12)
    want_p = pts @ np.array([10.0, -4.0, 25.0]) + 7.0
    np.testing.assert_allclose(field.sample_pressure(pts), want_p, rtol=0, atol=1e-11)


def test_points_outside_the_grid_are_clamped_to_its_faces() -> None:
    field, A, b = _linear_field()
    hi = field.origin + field.spacing * (np.array(field.shape) - 1)
    far = np.array([hi + 1.0, field.origin - 1.0])
    np.testing.assert_allclose(field.sample(far), np.array([hi, field.origin]) @ A.T + b, atol=1e-12)


def test_local_linear_fit_is_exact_for_linear_data_and_bounded() -> None:
    rng = np.random.default_rng(7)
    support = rng.random((4000, 3))
    values = np.column_stack([support @ [1.0, -2.0, 0.5] + 3.0, support[:, 2] * 4.0])
    query = 0.2 + 0.6 * rng.random((500, 3))
    got = local_linear_fit(support, values, query)
    want = np.column_stack([query @ [1.0, -2.0, 0.5] + 3.0, query[:, 2] * 4.0])
    assert np.median(np.abs(got - want)) < 1e-8  # the ridge term biases ~1e-10
    assert np.abs(got - want).max() < 0.02  # clipped fits, rare inside
    # A step: the fit never leaves the data's range.
    step = (support[:, 0] > 0.5).astype(float)[:, None]
    got = local_linear_fit(support, step, rng.random((2000, 3)))
    assert got.min() >= 0.0 and got.max() <= 1.0


def test_nodes_in_lifters_and_outside_the_shell_take_the_nearest_fluid_cell(
    smoke_dict: dict[str, Any],
) -> None:
    from scipy.spatial import cKDTree

    case = _case(smoke_dict, model="cfd", mesh_size=0.04)
    R, L = case.drum.radius, case.drum.length
    rng = np.random.default_rng(3)
    pts = np.column_stack([rng.uniform(-R, R, 15000), rng.uniform(-R, R, 15000),
                           rng.uniform(0, L, 15000)])
    centres = pts[fluid_mask_xy(case, pts[:, 0], pts[:, 1])]
    velocity = np.column_stack([centres[:, 1], -centres[:, 0], -3.0 + centres[:, 2]])
    field = AirField.from_cells(centres, velocity, case, spacing=0.01)
    assert np.isfinite(field.velocity).all()
    nodes = np.stack(np.meshgrid(*field.axes(), indexing="ij"), axis=-1).reshape(-1, 3)
    solid = ~field.fluid.reshape(-1)
    assert solid.any() and (~solid).any()
    _, nearest = cKDTree(centres).query(nodes[solid])
    np.testing.assert_array_equal(field.velocity.reshape(-1, 3)[solid], velocity[nearest])
    # Inside the fluid the field is linear, and the local linear fit reproduces it, except
    # where the clip to the neighbours' range binds (nodes outside their neighbours' hull:
    # next to walls and at the end planes).
    inside = field.fluid.reshape(-1)
    got = field.velocity.reshape(-1, 3)[inside]
    want = np.column_stack([nodes[inside, 1], -nodes[inside, 0], -3.0 + nodes[inside, 2]])
    exact = np.abs(got - want).max(axis=1) < 1e-8
    assert exact.mean() > 0.6


def test_rotation_helpers_round_trip_and_turn_with_the_drum() -> None:
    rng = np.random.default_rng(5)
    pts = rng.normal(size=(100, 3))
    for angle in (0.0, 0.3, -2.0, 7.5):
        back = rotate_to_lab_frame(rotate_to_drum_frame(pts, angle), angle)
        np.testing.assert_allclose(back, pts, atol=1e-14)
    # After a quarter turn counter-clockwise, the lab point on +x is the drum point on -y.
    np.testing.assert_allclose(
        rotate_to_drum_frame(np.array([[1.0, 0.0, 0.2]]), 0.5 * math.pi), [[0.0, -1.0, 0.2]],
        atol=1e-15,
    )


def test_sample_lab_of_a_solid_body_rotation_is_the_same_at_every_drum_angle() -> None:
    # Solid-body rotation with the drum looks the same from every angle: the lab velocity at
    # a lab point must not depend on time if positions and velocities are both rotated.
    omega = 1.3
    origin, spacing, shape = np.array([-1.0, -1.0, 0.0]), np.array([0.05, 0.05, 0.5]), (41, 41, 3)
    axes = [origin[i] + spacing[i] * np.arange(shape[i]) for i in range(3)]
    X = np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1)
    U = np.stack([-omega * X[..., 1], omega * X[..., 0], np.full(shape, -2.0)], axis=-1)
    field = AirField(origin, spacing, U, np.zeros(shape), np.ones(shape, bool), omega=omega)
    pts = np.random.default_rng(2).uniform(-0.6, 0.6, (200, 3))
    pts[:, 2] = 0.4
    want = np.column_stack([-omega * pts[:, 1], omega * pts[:, 0], np.full(200, -2.0)])
    for t in (0.0, 0.37, 5.0):
        np.testing.assert_allclose(field.sample_lab(pts, t), want, atol=1e-12)


def test_uniform_field_moves_mdot_over_rho_free_area_towards_minus_z(
    smoke_dict: dict[str, Any],
) -> None:
    case = _case(smoke_dict, model="uniform")
    field = AirField.uniform(case)
    T = case.air.inlet_temperature_C + 273.15
    rho = case.air.pressure_kPa * 1e3 / (287.05 * T)
    # Independent free area: the shell disk minus the lifters' plates (drawn, not meshed).
    area = math.pi * case.drum.radius**2 - lifter_area(case.drum.radius, case.lifters)
    expected = case.air.mass_flow / (rho * area)
    assert field.mean_axial_velocity() == pytest.approx(expected, rel=0.01)
    u = field.sample(np.array([[0.0, 0.0, 0.5 * case.drum.length], [0.1, -0.05, 0.01]]))
    assert (u[:, 2] < 0).all()
    np.testing.assert_allclose(u[:, :2], 0.0)


def test_cache_key_follows_drum_and_air_but_not_particles(smoke_dict: dict[str, Any]) -> None:
    # A known base, whatever the shipped smoke case says today.
    smoke_dict["air"].update(model="uniform", mesh_size=0.03, turbulence="realizableKE",
                             mass_flow=0.44, residual_target=1e-4, inlet_temperature_C=30.0)
    base = case_from_dict(smoke_dict)
    key = air_cache_key(base)
    assert key == air_cache_key(case_from_dict(smoke_dict))

    def changed(section: str, **values: Any) -> str:
        d = {k: dict(v) if isinstance(v, dict) else v for k, v in smoke_dict.items()}
        d[section] = {**d[section], **values}
        return air_cache_key(case_from_dict(d))

    affecting: list[tuple[str, dict[str, Any]]] = [
        ("drum", {"diameter": 0.5}),
        ("drum", {"rpm": 10.0}),
        ("drum", {"length": 0.1}),
        ("lifters", {"count": 6}),
        ("lifters", {"base_height": 0.05}),
        ("air", {"mass_flow": 0.3}),
        ("air", {"inlet_temperature_C": 40.0}),
        ("air", {"mesh_size": 0.02}),
        ("air", {"turbulence": "laminar"}),
        ("air", {"residual_target": 1e-5}),
        ("air", {"model": "cfd"}),
    ]
    for section, values in affecting:
        assert changed(section, **values) != key, (section, values)
    neutral: list[tuple[str, dict[str, Any]]] = [
        ("air", {"warming": True}),
        ("particles", {"interior": "shells"}),
        ("particles", {"count": 1000}),
        ("particles", {"diameter": 0.006}),
        ("contacts", {"wall_youngs_modulus": 1e7}),
        ("run", {"time": 2.0}),
        ("air", {"coupling_interval": 50}),
        ("air", {"pressure_gradient_force": True}),
    ]
    for section, values in neutral:
        assert changed(section, **values) == key, (section, values)


def test_npz_round_trip(tmp_path: Path) -> None:
    field, _, _ = _linear_field()
    field.meta = {"model": "test", "cells": 3}
    field.to_npz(tmp_path / "f.npz")
    back = AirField.from_npz(tmp_path / "f.npz")
    np.testing.assert_array_equal(back.velocity, field.velocity)
    np.testing.assert_array_equal(back.fluid, field.fluid)
    np.testing.assert_array_equal(back.origin, field.origin)
    assert back.omega == field.omega and back.meta == field.meta
    pts = np.random.default_rng(0).random((10, 3)) * 0.1
    np.testing.assert_array_equal(back.sample(pts), field.sample(pts))


def test_cross_section_png(smoke_dict: dict[str, Any], tmp_path: Path) -> None:
    case = _case(smoke_dict, model="uniform")
    out = tmp_path / "air.png"
    plot_air_cross_section(AirField.uniform(case), case, out, resolution=80)
    assert out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


# -- pure helpers of the OpenFOAM stage ------------------------------------------------

_LOG = """\
Time = 1

smoothSolver:  Solving for Ux, Initial residual = 1, Final residual = 0.05, No Iterations 2
smoothSolver:  Solving for Uy, Initial residual = 1, Final residual = 0.05, No Iterations 2
GAMG:  Solving for p, Initial residual = 1, Final residual = 0.04, No Iterations 3
GAMG:  Solving for p, Initial residual = 0.3, Final residual = 0.01, No Iterations 3
ExecutionTime = 0.1 s  ClockTime = 0 s

Time = 2

smoothSolver:  Solving for Ux, Initial residual = 5e-05, Final residual = 1e-6, No Iterations 2
smoothSolver:  Solving for Uy, Initial residual = 4e-05, Final residual = 1e-6, No Iterations 2
GAMG:  Solving for p, Initial residual = 2e-05, Final residual = 1e-7, No Iterations 3


SIMPLE solution converged in 2 iterations

End
"""


def test_residual_log_parser_keeps_the_first_solve_of_each_field() -> None:
    df = parse_residual_log(_LOG)
    assert list(df["iteration"]) == [1, 2]
    assert df.loc[0, "p"] == 1.0  # not the second (non-orthogonal) pressure solve
    assert df.loc[1, "Ux"] == pytest.approx(5e-5)


def test_residual_log_parser_counts_the_iterations_a_field_was_left_unsolved() -> None:
    from drumflow.air.foam_results import ResidualParser

    parser = ResidualParser()
    for line in _LOG.replace("Initial residual = 4e-05, Final residual = 1e-6, No Iterations 2",
                             "Initial residual = 4e-09, Final residual = 4e-09, No Iterations 0"
                             ).splitlines():
        parser(line)
    assert parser.unsolved == {"Uy": 1}


def test_turbulence_fields_get_a_sweep_every_iteration(tmp_path: Path) -> None:
    """Regression: k's normalised residual fell below the absolute tolerance in periodic drums
    and k was never solved again (model two's periodic bed never converged)."""
    from foamlib import FoamFile

    from drumflow.air.foam_case import write_fv_solution

    (tmp_path / "system").mkdir()
    write_fv_solution(tmp_path, 1e-4, ["p", "U", "k", "epsilon"])
    solvers = FoamFile(tmp_path / "system" / "fvSolution")["solvers"]
    assert solvers['"(U|k|epsilon)"']["minIter"] == 1  # type: ignore[index]


def test_not_converged_error_names_the_worst_residual() -> None:
    err = AirNotConvergedError(10, {"Ux": 1e-3, "epsilon": 2e-2}, 1e-4, Path("log.simpleFoam"))
    assert "epsilon" in str(err) and "10 SIMPLE iterations" in str(err)
    assert isinstance(err, RuntimeError)


def test_inlet_turbulence_from_intensity_and_mixing_length() -> None:
    k, eps, lm = inlet_turbulence(3.0, 0.2)
    assert k == pytest.approx(1.5 * (0.05 * 3.0) ** 2)
    assert lm == pytest.approx(0.014)
    assert eps == pytest.approx(0.09**0.75 * k**1.5 / 0.014)


def test_check_mesh_parser() -> None:
    text = (
        "    cells:            9145\n    Max aspect ratio = 9.39 OK.\n"
        "    Min volume = 1.6e-08. Max volume = 1.3e-05.  Total volume = 0.0098.  OK.\n"
        "    Mesh non-orthogonality Max: 75.4 average: 24.9\n    Max skewness = 1.17 OK.\n\n"
        "Mesh OK.\n"
    )
    info = parse_check_mesh(text)
    assert info["ok"] and info["cells"] == 9145
    assert info["min_volume"] == pytest.approx(1.6e-8)
    assert info["max_non_orthogonality"] == pytest.approx(75.4)
    assert not parse_check_mesh(text.replace("Mesh OK.", "Failed 1 mesh checks."))["ok"]


def test_cache_key_of_a_shipped_case_is_pinned() -> None:
    """Regression: adding ``air.warming`` put a new key into the air section and moved every
    case's air key, so every cached field was solved again and every run keyed on its field
    restarted its DEM stage (paper model two's parcels began re-solving their air). The key of
    the shipped model two, computed before that option existed, must not move; a case-file
    change to model two's drum, lifters or air is the only reason to update it."""
    from drumflow.case import load_case

    case = load_case(Path(__file__).resolve().parents[2] / "cases" / "paper_model_two.toml")
    assert air_cache_key(case) == "15be31a7e0d79cc9014c38105f9d5242817ae1da1733ccf915f5784174c9cd76"
