"""`drumflow export --vtk` on a real tiny run: pyvista reads back what was written.

The walls' angle is checked physically, not against the function that wrote it: LIGGGHTS'
particles never sit inside a lifter, so at each snapshot no particle centre may be closer to the
exported lifters than its radius (less the contact overlap). Measured on a 1.6 s run of this
drum: 0 particles closer than 0.9 r at the exported angle, 50-120 with the lifters left at
angle 0, turned the other way, or turned 10 degrees too far.
"""

from __future__ import annotations

import json
import math
import subprocess
import sys
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from support.solvers import LIGGGHTS, requires_solver

pytestmark = [pytest.mark.solver, requires_solver(*LIGGGHTS)]


@pytest.fixture(scope="module")
def run_dir(tmp_path_factory: pytest.TempPathFactory) -> Path:
    from drumflow.pipeline import run_case
    from drumflow.verify.scenes import tiny_drum

    case = tiny_drum(air__model="uniform", air__mass_flow=0.1, run__time=0.4,
                     run__snapshot_interval=0.1, run__mass_flow_start=0.2, run__processes=1)
    out = tmp_path_factory.mktemp("export") / "run"
    run_case(case, out, timeout=600)
    return out


def _export(run_dir: Path, out: Path) -> dict[str, Any]:
    proc = subprocess.run(
        [sys.executable, "-m", "drumflow.cli", "export", str(run_dir), "--vtk", "--out", str(out),
         "--json"], capture_output=True, text=True, timeout=300, check=False)
    assert proc.returncode == 0, proc.stderr[-2000:]
    return json.loads(proc.stdout)


@pytest.mark.timeout(900)
def test_particles_read_back(run_dir: Path, tmp_path: Path) -> None:
    import pyvista as pv

    from drumflow.dem.dumps import dump_files, read_dump

    info = _export(run_dir, tmp_path / "vtk")
    snaps = dump_files(run_dir / "dem" / "dumps", "snap")
    reader = pv.get_reader(str(tmp_path / "vtk" / "particles.pvd"))
    assert len(reader.time_values) == len(snaps) == len(info["times_s"]) >= 5
    last = read_dump(snaps[-1])
    reader.set_active_time_value(reader.time_values[-1])
    cloud = reader.read()[0]
    assert cloud.n_points == 500
    assert set(cloud.point_data.keys()) >= {"id", "velocity", "radius", "temperature"}
    # Same particle, same values as the text dump (rows sorted by id in both).
    k = 123
    assert int(cloud.point_data["id"][k]) == int(last.ids[k])
    assert float(cloud.point_data["temperature"][k]) == pytest.approx(last.columns["T"][k], rel=1e-12)
    assert np.allclose(cloud.points[:, 1], last.columns["y"], rtol=0, atol=1e-12)
    assert float(cloud.point_data["radius"][0]) == pytest.approx(0.004)
    # The air: plug flow -mdot/(rho A_free) along z on the grid, inside the air volume.
    air = pv.read(str(tmp_path / "vtk" / "air.vti"))
    from drumflow.air.source import mean_axial_velocity
    from drumflow.case import load_case

    case = load_case(run_dir / "case.toml")
    inside = air.point_data["fluid"] == 1
    assert inside.sum() > 0.5 * air.n_points
    assert np.allclose(air.point_data["velocity"][inside, 2], -mean_axial_velocity(case), rtol=1e-9)


@pytest.mark.timeout(900)
def test_walls_turn_with_the_drum(run_dir: Path, tmp_path: Path) -> None:
    import pyvista as pv

    from drumflow.case import load_case
    from drumflow.dem.dumps import dump_files, read_dump

    _export(run_dir, tmp_path / "vtk")
    case = load_case(run_dir / "case.toml")
    r = case.particles.radius
    reader = pv.get_reader(str(tmp_path / "vtk" / "walls.pvd"))
    lifters0 = pv.read(str(run_dir / "geometry" / "lifters.stl"))
    snaps = dump_files(run_dir / "dem" / "dumps", "snap")
    assert len(reader.time_values) == len(snaps)
    for t, path in zip(reader.time_values[1:], snaps[1:], strict=True):
        reader.set_active_time_value(t)
        walls = reader.read()
        moving, shell = walls[0], walls[1]
        assert shell.n_cells > 0
        # The lifters' first node, turned by omega t about +z (mod 2 pi).
        a0 = math.atan2(lifters0.points[0, 1], lifters0.points[0, 0])
        a1 = math.atan2(moving.points[0, 1], moving.points[0, 0])
        turned = (a1 - a0) % (2 * math.pi)
        assert turned == pytest.approx((case.drum.omega * t) % (2 * math.pi), abs=1e-6)
        # Physical check: no particle centre inside a lifter plate's contact range.
        snap = read_dump(path)
        centres = np.column_stack([snap.columns["x"], snap.columns["y"], snap.columns["z"]])
        _, closest = moving.find_closest_cell(centres, return_closest_point=True)
        distance = np.linalg.norm(centres - closest, axis=1)
        # Hertz overlaps here are below 1% of r (soft 5 MPa spheres at these speeds); 0.9 r
        # leaves a margin of ten times that and still fails for any wrong angle (see above).
        assert int((distance < 0.9 * r).sum()) == 0, t


@pytest.mark.timeout(600)
def test_animation_has_a_frame_per_snapshot(run_dir: Path, tmp_path: Path) -> None:
    from PIL import Image

    from drumflow.dem.dumps import dump_files

    gif = tmp_path / "section.gif"
    proc = subprocess.run(
        [sys.executable, "-m", "drumflow.cli", "export", str(run_dir), "--animation", "--out", str(gif),
         "--json"], capture_output=True, text=True, timeout=300, check=False)
    assert proc.returncode == 0, proc.stderr[-2000:]
    info = json.loads(proc.stdout)
    snaps = dump_files(run_dir / "dem" / "dumps", "snap")
    with Image.open(gif) as image:
        assert image.n_frames == len(snaps) == info["frames"] >= 5
        # Snapshots every 0.1 s played in real time: 10 frames a second, 100 ms per frame.
        assert image.info["duration"] == pytest.approx(100, abs=1)
    assert info["fps"] == 10
    lo, hi = info["temperature_range_C"]
    assert lo < hi <= 90.0 + 1e-6  # the particles start at 90 C and only cool


@pytest.mark.timeout(300)
def test_states_over_a_lifter_period(run_dir: Path, tmp_path: Path) -> None:
    """--state --phases 3 --time 0.1: the tiny drum's 6 lifters at 30 rpm pass every 1/3 s, so
    the targets are 0.1, 0.211 and 0.322 s; the snapshots every 0.1 s give 0.1, 0.2 and 0.3 s,
    18 and 36 degrees into the 60-degree spacing against the targets' 20 and 40."""
    from drumflow.dem.state import read_state

    proc = subprocess.run(
        [sys.executable, "-m", "drumflow.cli", "export", str(run_dir), "--state", "--phases", "3",
         "--time", "0.1", "--out", str(tmp_path / "phases"), "--json"],
        capture_output=True, text=True, timeout=300, check=False)
    assert proc.returncode == 0, proc.stderr[-2000:]
    records = json.loads(proc.stdout)
    assert [round(r["time_s"], 3) for r in records] == [0.1, 0.2, 0.3]
    assert [round(r["target_phase_deg"], 1) for r in records] == [0.0, 20.0, 40.0]
    # The drum turned pi rad/s: the phases are the states' own angles, read back from the files.
    angles = [read_state(Path(r["path"])).drum_angle_rad for r in records]
    phases = [math.degrees((a - angles[0]) % (math.pi / 3)) for a in angles]
    assert phases == pytest.approx([0.0, 18.0, 36.0], abs=0.1)
    assert [r["phase_deg"] for r in records] == pytest.approx(phases, abs=1e-9)
    # A period that runs past the last snapshot (0.35 + 1/6 s > 0.4 s): refused by name.
    late = subprocess.run(
        [sys.executable, "-m", "drumflow.cli", "export", str(run_dir), "--state", "--phases", "2",
         "--time", "0.35", "--out", str(tmp_path / "late")],
        capture_output=True, text=True, timeout=300, check=False)
    assert late.returncode == 2 and "no full snapshot at t = 0.516667 s" in " ".join(late.stderr.split())
