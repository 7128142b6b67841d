"""drum.ends on real LIGGGHTS runs of a tiny drum without lifters (300 particles, 0.6 s).

The drum is tilted 25 degrees, so that gravity presses the bed against the end plate at z = L
with 42 % of its weight: what that plate does shows in how far the shell lifts the bed.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from support.solvers import LIGGGHTS, requires_solver, tiny_case_dict

from drumflow.case import case_from_dict
from drumflow.dem.dumps import read_series
from drumflow.pipeline import run_case

pytestmark = [pytest.mark.solver, requires_solver(*LIGGGHTS)]


def _run(ends: str, root: Path) -> tuple[dict, Path]:
    case = case_from_dict(tiny_case_dict(
        drum__ends=ends, drum__tilt_deg=25.0, lifters__count=0, particles__count=300,
        run__time=0.6, run__mass_flow_start=0.3, run__snapshot_interval=0.05))
    out = root / ends
    return run_case(case, out, timeout=300), out


def _series(out: Path) -> object:
    ts = json.loads((out / "manifest.json").read_text())["time_step"]["time_step"]
    return read_series(out / "dem" / "dumps", ts, columns=("x", "y", "z"))


@pytest.fixture(scope="module")
def runs(tmp_path_factory: pytest.TempPathFactory) -> dict[str, tuple[dict, Path]]:
    root = tmp_path_factory.mktemp("ends")
    return {ends: _run(ends, root) for ends in ("fixed", "rotating", "periodic")}


@pytest.mark.timeout(300)
def test_rotating_end_plates_turn_with_the_shell(runs: dict[str, tuple[dict, Path]]) -> None:
    """Still plates hold the pressed bed back (the shell slides under it); plates that turn
    with the shell carry it up the rising side: its centre of mass moves further to +x."""
    summary, out = runs["rotating"]
    assert summary["particles_final"] == 300
    deck = (out / "dem" / "in.drum").read_text()
    assert "zplane" not in deck and "meshes shell ends" in deck
    # The plates: two disks, at z = 0 and z = L, whose surface moves at the shell's omega.
    stl = (out / "geometry" / "ends.stl").read_text()
    z = np.array([float(line.split()[3]) for line in stl.splitlines() if line.strip().startswith("vertex")])
    assert set(np.round(z, 9)) == {0.0, 0.048}
    assert "surface_ang_vel origin 0. 0. 0. axis 0. 0. 1. omega 3.14159265" in deck
    lift = {e: np.nanmean(_series(runs[e][1])["x"], axis=1).max() for e in ("fixed", "rotating")}
    assert lift["rotating"] > 1.3 * lift["fixed"], lift


@pytest.mark.timeout(300)
def test_periodic_ends_have_no_plates_and_particles_wrap(runs: dict[str, tuple[dict, Path]]) -> None:
    summary, out = runs["periodic"]
    assert summary["particles_final"] == 300
    deck = (out / "dem" / "in.drum").read_text()
    assert "boundary        f f p" in deck and "zplane" not in deck and "fix ends" not in deck
    assert not (out / "geometry" / "ends.stl").exists()
    z = _series(out)["z"]
    L, skin = 0.048, 0.004
    # Inside the period (up to the neighbour skin a particle may pass before it is wrapped).
    assert np.nanmin(z) >= -skin and np.nanmax(z) <= L + skin
    # Gravity's axial pull moves the bed along +z: particles leave at z = L and come back at 0.
    assert np.nanmax(-np.diff(z, axis=0)) > 0.5 * L
