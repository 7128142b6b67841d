"""The spin limit of the time step (drumflow.dem.timestep.spin_mode) against LIGGGHTS itself:
two held particles spinning on one contact, just below and just above the predicted step.
A few seconds."""

from __future__ import annotations

from pathlib import Path

import pytest
from support.solvers import LIGGGHTS, requires_solver

from drumflow.runner import Runner
from drumflow.verify.contacts import run_spin

pytestmark = [pytest.mark.solver, pytest.mark.timeout(120), requires_solver(*LIGGGHTS)]


@pytest.mark.parametrize("overlap_fraction", [0.05, 0.19])
def test_the_dashpot_damps_spin_below_the_limit_and_excites_it_above(
        tmp_path: Path, overlap_fraction: float) -> None:
    """Paper model one's particles (517 kPa, its default step's e = 0.1205). The prediction is
    the stability limit of velocity Verlet with LIGGGHTS' half-step dashpot velocity, lever arm
    r - delta/2 (measured by bisection at 0.19 r: LIGGGHTS' limit 3.5-3.6e-4 s, predicted
    3.54e-4). 10 % either side: 400 steps take the energy down by tens of decades below, and
    up above, until the contact slides (a small overlap slides soonest: x7 at 0.05 r)."""
    below = run_spin(tmp_path / "below", Runner(), 0.9, overlap_fraction)
    above = run_spin(tmp_path / "above", Runner(), 1.1, overlap_fraction)
    assert below.energy_ratio < 1e-6, below
    assert above.energy_ratio > 1.0, above
