"""A run started from the shipped start state (results/states/smoke_1.0s.npz) puts the particles
where the state holds them, at the state's step, with the lifters at the state's drum angle."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest
from support.solvers import CASES, LIGGGHTS, ROOT, requires_solver

pytestmark = [pytest.mark.solver, requires_solver(*LIGGGHTS)]

STATE = ROOT / "results" / "states" / "smoke_1.0s.npz"


@pytest.mark.timeout(600)
def test_smoke_case_starts_from_the_shipped_state(tmp_path: Path) -> None:
    from drumflow.case import case_from_dict, read_toml
    from drumflow.dem.dumps import dump_files, dump_step, read_dump
    from drumflow.dem.state import read_state
    from drumflow.dem.thermo import read_thermo
    from drumflow.pipeline import run_case
    from drumflow.verify.resume import read_stl_triangles, rotation_about_axis, wrap_angle

    data = read_toml(CASES / "smoke.toml")
    # Uniform air and one process keep it cheap; the scene (drum, lifters, particles) is the
    # smoke case's, which the state belongs to.
    data["air"]["model"] = "uniform"
    data["run"]["processes"] = 1
    data["run"]["start_state"] = str(STATE)
    case = case_from_dict(data)
    state = read_state(STATE)
    run_case(case, tmp_path / "run", steps=200, timeout=500)

    dem = tmp_path / "run" / "dem"
    first = next(p for p in dump_files(dem / "dumps") if dump_step(p) == state.step)
    snap = read_dump(first)
    assert len(snap) == len(state)
    assert np.array_equal(snap.ids, state.ids)
    x = np.column_stack([snap.columns[c] for c in "xyz"])
    # The snapshot text has 8 significant digits and its packed form float32: 0.1 um at 0.2 m.
    assert np.abs(x - state.positions).max() < 1e-7
    assert abs(float(np.mean(snap.columns["T"])) - float(np.mean(state.temperatures_C))) < 1e-6
    assert np.abs(snap.columns["T"] - state.temperatures_C).max() < 1e-6
    v = np.column_stack([snap.columns[c] for c in ("vx", "vy", "vz")])
    assert np.allclose(v, state.velocities, rtol=1e-5, atol=1e-7)
    w = np.column_stack([snap.columns[c] for c in ("omegax", "omegay", "omegaz")])
    assert np.allclose(w, state.spins, rtol=1e-5, atol=1e-6)

    thermo = read_thermo(dem)
    assert int(thermo["step"].iloc[0]) == state.step
    assert int(thermo["step"].iloc[-1]) == state.step + 200
    # Equal particles: the mass-weighted mean is the plain mean.
    assert abs(float(thermo["T_mean"].iloc[0]) - float(np.mean(state.temperatures_C))) < 1e-6

    # The lifters stand at the state's drum angle (omega t), as a resume's are checked.
    manifest = json.loads((tmp_path / "run" / "manifest.json").read_text())
    assert manifest["start_state"]["step"] == state.step
    moved = read_stl_triangles(dem / f"mesh_at_resume.{state.step}.stl")
    original = read_stl_triangles(tmp_path / "run" / "geometry" / "lifters.stl")
    pitch = 2.0 * math.pi / case.lifters.count
    lifter = wrap_angle(rotation_about_axis(original, moved, case.lifters.count), pitch)
    assert abs(wrap_angle(lifter - state.drum_angle_rad, pitch)) < 1e-4
