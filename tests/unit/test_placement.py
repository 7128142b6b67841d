"""Initial bed: exact count, no overlaps, clear of shell, lifters and end planes."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial import cKDTree

from drumflow.case import case_from_dict
from drumflow.dem.placement import place_particles, write_data_file
from drumflow.errors import InsertionError
from drumflow.geometry.lifters import distance_to_lifters


def test_exact_count_without_overlap(smoke_dict: dict, tmp_path) -> None:
    case = case_from_dict(smoke_dict)
    pos = place_particles(case)
    d = case.particles.diameter
    assert pos.shape == (3000, 3)
    pairs = cKDTree(pos).query_pairs(d * (1 - 1e-9))
    assert not pairs, "overlapping particles in the initial bed"
    r = np.hypot(pos[:, 0], pos[:, 1])
    assert r.max() <= case.drum.radius - 0.5 * d
    assert (distance_to_lifters(pos[:, :2], case.drum.radius, case.lifters) >= 0.5 * d).all()
    assert pos[:, 2].min() >= 0.5 * d and pos[:, 2].max() <= case.drum.length - 0.5 * d
    # The bed fills from the bottom: its centre of mass lies below the axis.
    assert pos[:, 1].mean() < -0.5 * case.drum.radius
    path = tmp_path / "p.data"
    write_data_file(case, pos, path, ((-1, -1, -1), (1, 1, 1)))
    text = path.read_text()
    assert "3000 atoms" in text and "2 atom types" in text


def test_too_many_particles_is_a_clear_error(smoke_dict: dict) -> None:
    case = case_from_dict(smoke_dict)
    with pytest.raises(InsertionError, match="only .* of the requested 60000 particles"):
        place_particles(case, count=60000)


def test_random_placement_is_a_loose_random_bed(smoke_dict: dict) -> None:
    import copy

    data = copy.deepcopy(smoke_dict)
    data["particles"]["placement"] = "random"
    case = case_from_dict(data)
    pos = place_particles(case)
    d, R = case.particles.diameter, case.drum.radius
    assert pos.shape == (3000, 3)
    assert not cKDTree(pos).query_pairs(d * (1 - 1e-9)), "overlapping particles"
    assert np.hypot(pos[:, 0], pos[:, 1]).max() <= R - 0.5 * d
    assert (distance_to_lifters(pos[:, :2], R, case.lifters) >= 0.5 * d).all()
    assert pos[:, 2].min() >= 0.5 * d and pos[:, 2].max() <= case.drum.length - 0.5 * d
    assert (np.diff(pos[:, 1]) >= 0).all()  # lowest first
    # Not a crystal: the lattice's neighbours sit at exactly 1.02 d, the random bed's spread.
    nearest = cKDTree(pos).query(pos, k=2)[0][:, 1] / d
    assert np.std(nearest) > 0.05
    lattice = place_particles(case_from_dict(smoke_dict))
    assert np.std(cKDTree(lattice).query(lattice, k=2)[0][:, 1] / d) < 1e-6
    # Loose: the random bed stands higher than the lattice's (solids fraction ~0.3 against ~0.7).
    assert pos[:, 1].max() > lattice[:, 1].max() + 2 * d
    # Seeded: the same case gives the same bed, another seed another.
    assert np.array_equal(pos, place_particles(case))
    data["run"]["seed"] = 12345
    assert not np.array_equal(pos, place_particles(case_from_dict(data)))
    assert case.hash() != case_from_dict(smoke_dict).hash()  # the placement is part of the run


def test_random_placement_refuses_a_drum_it_cannot_fill(smoke_dict: dict) -> None:
    import copy

    data = copy.deepcopy(smoke_dict)
    data["particles"]["placement"] = "random"
    case = case_from_dict(data)
    from drumflow.dem.placement import random_packing

    # The whole drum at the jamming fraction holds far fewer than this.
    with pytest.raises(InsertionError, match="random placement"):
        random_packing(case, 10 * case.particle_count, max_rounds=6)
