"""The air's temperature on the field's grid (``drumflow.air.heat``): conservation, the mixed
outlet of plug flow, the projection of a field that is not divergence-free, the implicit
particle coupling against the explicit source, and the cells of points beside walls."""

from __future__ import annotations

import numpy as np
import pytest

import drumflow.air.heat as air_heat
from drumflow.air.field import AirField
from drumflow.air.heat import AirHeat, coarse_field

RHO, CP = 1.16, 1007.0


def _duct(shape: tuple[int, int, int] = (5, 5, 41), speed: float = 2.0,
          noise: float = 0.0, blocked: bool = False) -> AirField:
    velocity = np.zeros((*shape, 3))
    velocity[..., 2] = -speed
    if noise:
        velocity += np.random.default_rng(1).normal(0.0, noise, velocity.shape)
    fluid = np.ones(shape, dtype=bool)
    if blocked:
        fluid[2, 2, 10:20] = False  # a lifter-like obstacle
    return AirField(origin=np.zeros(3), spacing=np.array([0.01, 0.01, 0.005]), velocity=velocity,
                    pressure=np.zeros(shape), fluid=fluid, omega=0.0)


def test_plug_flow_outlet_is_the_mixed_temperature() -> None:
    """One source anywhere: the outlet's flow-weighted mean is T_in + Q / (rho c_p V)."""
    heat = AirHeat(_duct(), 30.0, RHO, CP)
    source = np.zeros(heat.cells)
    source[heat.cells_of(np.array([[0.02, 0.02, 0.1]]))] = 100.0
    temperature = heat.solve(source)
    assert heat.volume_flow == pytest.approx(5 * 5 * 1e-4 * 2.0)
    assert heat.outlet_temperature(temperature) == pytest.approx(30.0 + 100.0 / (RHO * CP * heat.volume_flow),
                                                                 rel=1e-10)
    # Upstream of the source the air is still at the inlet temperature.
    assert temperature[heat.cells_of(np.array([[0.02, 0.02, 0.19]]))][0] == pytest.approx(30.0, abs=1e-6)


def test_enthalpy_is_conserved_on_a_field_that_is_not_divergence_free() -> None:
    """Random velocities and an obstacle: the projection leaves no net flow in any cell, so the
    air carries out exactly the heat it was given."""
    heat = AirHeat(_duct(noise=0.3, blocked=True), 30.0, RHO, CP)
    source = np.random.default_rng(2).uniform(0.0, 10.0, heat.cells)
    gain = heat.enthalpy_gain(heat.solve(source))
    assert gain == pytest.approx(source.sum(), rel=1e-9)


def test_implicit_particles_give_the_same_field_as_their_heat_as_a_source() -> None:
    heat = AirHeat(_duct(), 30.0, RHO, CP)
    cells = heat.cells_of(np.array([[0.02, 0.02, 0.1], [0.02, 0.02, 0.15], [0.0, 0.04, 0.05]]))
    g = np.zeros(heat.cells)
    gt = np.zeros(heat.cells)
    np.add.at(g, cells, 0.5)
    np.add.at(gt, cells, 0.5 * 90.0)
    implicit = heat.solve_with_particles(g, gt)
    source = np.zeros(heat.cells)
    np.add.at(source, cells, 0.5 * (90.0 - implicit[cells]))
    np.testing.assert_allclose(heat.solve(source), implicit, atol=1e-8)
    # That solve starts from the implicit one's field, which already solves it to the tolerance:
    # at most one iteration (regression: every update solved both from the inlet temperature,
    # with the particles' curtain 61 % of the curtain scene's wall time).
    assert heat.iterations <= 1
    # A cold start gives the same field to the tolerance.
    cold = AirHeat(_duct(), 30.0, RHO, CP)
    np.testing.assert_allclose(cold.solve(source), implicit, atol=1e-8)
    assert cold.iterations > 1
    # A particle never heats its air past itself, however strong its film.
    strong = heat.solve_with_particles(g * 1e4, gt * 1e4)
    assert strong.max() <= 90.0 + 1e-6


def test_the_incomplete_lu_takes_over_when_the_lines_fail(monkeypatch: pytest.MonkeyPatch) -> None:
    """A cross-flow the lines along the axis leave out (random velocities, an obstacle) and a
    strong particle conductance: the lines converge in a few iterations; given one only, they
    fail, the incomplete LU gives the same field, and it stays in use."""
    field = _duct(noise=0.5, blocked=True)
    lines = AirHeat(field, 30.0, RHO, CP)
    g = np.random.default_rng(3).uniform(0.0, 5.0, lines.cells)
    expected = lines.solve_with_particles(g, 90.0 * g)
    assert lines.preconditioner["particles"] == "lines" and 0 < lines.iterations < 30
    monkeypatch.setattr(air_heat, "LINE_ITERATIONS", 1)
    fallback = AirHeat(field, 30.0, RHO, CP)
    np.testing.assert_allclose(fallback.solve_with_particles(g, 90.0 * g), expected, atol=1e-8)
    assert fallback.preconditioner["particles"] == "incomplete LU"
    np.testing.assert_allclose(fallback.solve(np.zeros(fallback.cells)), 30.0, atol=1e-8)
    assert fallback.preconditioner == {"particles": "incomplete LU", "transport": "incomplete LU"}


def _swirl(n: int = 16, layers: int = 3, axial: float = 0.05, spin: float = 2.0) -> AirField:
    """A round duct a few cells long whose air turns round the axis (2 m/s at the wall) far
    faster than it moves along it (0.05 m/s): the cross-flow the lines along the axis leave out."""
    h = 0.01
    x = (np.arange(n) - (n - 1) / 2) * h
    xx, yy = np.meshgrid(x, x, indexing="ij")
    radius = (n - 1) / 2 * h
    velocity = np.zeros((n, n, layers, 3))
    velocity[..., 0] = (-spin * yy / radius)[..., None]
    velocity[..., 1] = (spin * xx / radius)[..., None]
    velocity[..., 2] = -axial
    fluid = np.broadcast_to((np.hypot(xx, yy) <= radius)[..., None], (n, n, layers)).copy()
    return AirField(origin=np.array([-radius, -radius, 0.0]), spacing=np.array([h, h, 0.005]),
                    velocity=velocity, pressure=np.zeros((n, n, layers)), fluid=fluid, omega=0.0)


def test_a_failure_of_the_lines_on_the_transport_leaves_the_particles_their_lines() -> None:
    """Regression: on model one's air around the bed (a grid 5 cells long, the air turning round
    the bed) the lines failed once on the transport alone, which has no particles on its diagonal,
    and the switch moved the particles' implicit solve to the incomplete LU as well: some 70
    iterations per update where the lines take 5-10, a third of the run's wall time. Each system
    now keeps its own preconditioner, and both give the fields of the incomplete LU."""
    field = _swirl()
    heat = AirHeat(field, 30.0, RHO, CP)
    rng = np.random.default_rng(3)
    g = np.where(heat.nodes_xyz()[:, 1] < -0.03, rng.uniform(1.0, 5.0, heat.cells), 0.0)  # a bed
    first = heat.solve_with_particles(g, 90.0 * g)
    assert heat.preconditioner["particles"] == "lines"
    given = g * (90.0 - first) * rng.uniform(0.95, 1.05, heat.cells)  # the shells' heat, not the film's
    bookkeeping = heat.solve(given)
    assert heat.preconditioner == {"particles": "lines", "transport": "incomplete LU"}
    again = heat.solve_with_particles(1.1 * g, 99.0 * g)
    assert heat.preconditioner["particles"] == "lines"
    reference = AirHeat(field, 30.0, RHO, CP)
    reference.preconditioner = {"particles": "incomplete LU", "transport": "incomplete LU"}
    np.testing.assert_allclose(reference.solve(given), bookkeeping, atol=1e-8)
    np.testing.assert_allclose(reference.solve_with_particles(1.1 * g, 99.0 * g), again, atol=1e-8)
    # The bookkeeping still closes: the air carries out what it was given.
    assert heat.enthalpy_gain(bookkeeping) == pytest.approx(given.sum(), rel=1e-9)


def test_points_in_walls_go_to_the_nearest_fluid_cell() -> None:
    field = _duct(blocked=True)
    heat = AirHeat(field, 30.0, RHO, CP)
    inside_obstacle = np.array([[0.02, 0.02, 0.07]])  # node (2, 2, 14) is not fluid
    cell = heat.cells_of(inside_obstacle)[0]
    xyz = heat.nodes_xyz()[cell]
    # The obstacle runs 10 nodes (0.05 m) along z: the nearest air is one node across (0.01 m).
    assert np.linalg.norm(xyz - inside_obstacle[0]) == pytest.approx(0.01, rel=1e-9)


def test_coarse_field_keeps_the_box_and_the_flow() -> None:
    field = _duct(shape=(9, 9, 41))
    coarse = coarse_field(field, 0.02)
    assert coarse.shape == (5, 5, 11)
    np.testing.assert_allclose(coarse.velocity[..., 2], -2.0)
    hi = field.origin + field.spacing * (np.array(field.shape) - 1)
    np.testing.assert_allclose(coarse.origin + coarse.spacing * (np.array(coarse.shape) - 1), hi)
    assert coarse_field(field, 0.001) is field  # never finer than the field
