"""The many-particle shell model of the coupling loop (``ShellBatch``) against the one-particle
solver, the series solution and its own conservation, and the shell count from the Biot number."""

from __future__ import annotations

import math

import numpy as np
import pytest

from drumflow.coupling.interior import InteriorLoop, InteriorSpec
from drumflow.physics.particle_interior import (
    ShellBatch,
    Sphere,
    SphereConduction,
    series_mean_temperature,
    shell_drop_error,
    shells_for_biot,
)

NPK = Sphere(0.008, 0.18596, 1050.0, 1465.38)


def test_each_row_is_the_one_particle_solver() -> None:
    shells = 9
    one = SphereConduction(NPK, shells)
    batch = ShellBatch(shells, NPK.conductivity, NPK.diffusivity)
    start = one.uniform(90.0)
    expected, heat = one.step(start, 60.0, 30.0, 0.3)
    rows, given = batch.step(np.tile(start, (4, 1)), np.full(4, 60.0), 30.0, np.full(4, NPK.radius),
                             np.full(4, NPK.mass * NPK.heat_capacity), 0.3)
    np.testing.assert_allclose(rows, np.tile(expected, (4, 1)), rtol=1e-13)
    np.testing.assert_allclose(given, heat, rtol=1e-12)


def test_rows_differ_in_size_film_and_gas() -> None:
    """Every row its own particle: a batch of two equals the two solved alone."""
    small = Sphere(0.004, 0.3, 1200.0, 900.0)
    big = Sphere(0.02, 0.3, 1200.0, 900.0)
    batch = ShellBatch(6, 0.3, small.diffusivity)
    start = np.array([np.linspace(80, 90, 6), np.linspace(50, 70, 6)])
    rows, given = batch.advance(start, np.array([30.0, 120.0]), np.array([20.0, 40.0]),
                                np.array([small.radius, big.radius]),
                                np.array([small.mass * 900.0, big.mass * 900.0]), 2.0)
    for i, (sphere, h, gas) in enumerate([(small, 30.0, 20.0), (big, 120.0, 40.0)]):
        alone = SphereConduction(sphere, 6)
        steps = batch.sub_steps(2.0, np.array([small.radius, big.radius]))
        expected, heat = alone.advance(start[i], h, gas, 2.0, max_step=2.0 / steps)
        np.testing.assert_allclose(rows[i], expected, rtol=1e-12)
        assert given[i] == pytest.approx(heat, rel=1e-12)


def test_heat_given_equals_the_enthalpy_lost() -> None:
    batch = ShellBatch(12, NPK.conductivity, NPK.diffusivity)
    capacity = np.full(3, NPK.mass * NPK.heat_capacity)
    start = np.full((3, 12), 90.0)
    rows, given = batch.advance(start, np.array([20.0, 77.0, 300.0]), 30.0, np.full(3, NPK.radius),
                                capacity, 5.0)
    lost = capacity * (batch.mean(start) - batch.mean(rows))
    np.testing.assert_allclose(given, lost, rtol=1e-12)


@pytest.mark.parametrize("biot", [0.1, 1.0, 3.0])
def test_mean_follows_the_series_solution(biot: float) -> None:
    """Independent of the loop: the batch at the chosen shell count against the exact sphere."""
    h = biot * NPK.conductivity / NPK.radius
    shells = shells_for_biot(biot)
    batch = ShellBatch(shells, NPK.conductivity, NPK.diffusivity)
    tau = NPK.mass * NPK.heat_capacity / (h * NPK.surface)
    rows, _ = batch.advance(np.full((1, shells), 90.0), np.array([h]), 30.0, np.array([NPK.radius]),
                            np.array([NPK.mass * NPK.heat_capacity]), tau)
    exact = float(series_mean_temperature(NPK, h, 90.0, 30.0, tau)[0])
    drop, exact_drop = 90.0 - batch.mean(rows)[0], 90.0 - exact
    # The rule's promise (0.125 % at 63 % of the drop), with room for the other instant.
    assert drop == pytest.approx(exact_drop, rel=2.5e-3)


def test_shell_count_grows_with_biot_and_meets_its_tolerance() -> None:
    counts = [shells_for_biot(b) for b in (0.1, 1.0, 3.0)]
    assert counts == sorted(counts) and counts[0] < counts[-1]
    for b, n in zip((0.1, 1.0, 3.0), counts, strict=True):
        assert shell_drop_error(b, n) <= 1.25e-3
        assert shell_drop_error(b, n - 1) > 1.25e-3 or n == 3


def test_surface_heat_enters_the_outer_shell_and_keeps_the_mean() -> None:
    batch = ShellBatch(5, NPK.conductivity, NPK.diffusivity)
    rows = np.full((2, 5), 50.0)
    batch.add_surface_heat(rows, np.array([1.0, -2.0]))
    np.testing.assert_allclose(batch.mean(rows), [51.0, 48.0], rtol=1e-14)
    np.testing.assert_allclose(rows[:, :-1], 50.0)


def test_surface_temperature_lies_between_the_outer_shell_and_the_air() -> None:
    batch = ShellBatch(8, NPK.conductivity, NPK.diffusivity)
    rows = np.tile(np.linspace(90.0, 70.0, 8), (1, 1))
    surface = batch.surface_temperature(rows, np.array([77.0]), np.array([NPK.radius]), 30.0)
    assert 30.0 < surface[0] < 70.0
    # Insulated (h = 0): the surface is the outer shell.
    assert batch.surface_temperature(rows, np.array([0.0]), np.array([NPK.radius]), 30.0)[0] == 70.0


def test_loop_starts_unset_profiles_at_their_temperature_and_adds_contact_heat(tmp_path) -> None:
    from drumflow.coupling.interior import UNSET

    spec = InteriorSpec(6, NPK.conductivity, NPK.density, NPK.heat_capacity)
    loop = InteriorLoop(spec, tmp_path / "interior.csv")
    shells = np.array([np.full(6, UNSET), np.full(6, 60.0)])
    # Particle 1's Temp is 0.5 K above its shells' mean: contact heat since the last update.
    temperature = np.array([90.0, 60.5])
    d, m = np.full(2, NPK.diameter), np.full(2, NPK.mass)
    new, heat = loop.advance(shells, temperature, np.array([0.0, 0.0]), 30.0, d, m, 0.1)
    assert (shells[0] == UNSET).all()  # nothing written before commit
    np.testing.assert_allclose(loop.batch.mean(new), [90.0, 60.5], rtol=1e-13)
    np.testing.assert_array_equal(heat, 0.0)  # insulated: no heat to the air
    loop.commit(shells, new, np.zeros(2), 30.0, d, 0, 0.0)
    loop.close()
    np.testing.assert_array_equal(shells, new)
    assert math.isclose(float(shells[1, -1] - shells[1, 0]), 0.5 / loop.batch.fractions[-1], rel_tol=0.2)
