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
