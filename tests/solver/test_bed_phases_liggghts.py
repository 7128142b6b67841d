"""The air around the bed in the coupled loop (``air.bed_states``, issue 32) on the smoke drum:
the air stage solves the air with the shipped state's bed as porosity (OpenFOAM, periodic axial
air), the loop's particles feel it and warm it, energy closes, and the bed's particles meet far
slower air than the empty drum's."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from support.solvers import CASES, LIGGGHTS, OPENFOAM, ROOT, requires_solver

pytestmark = [pytest.mark.solver, requires_solver(*LIGGGHTS, *OPENFOAM)]

STATE = ROOT / "results" / "states" / "smoke_1.0s.npz"


@pytest.mark.timeout(1200)
def test_smoke_drum_with_the_air_around_its_bed(tmp_path: Path) -> None:
    from drumflow.air.bed_phases import PhaseLockedAir
    from drumflow.air.field import AirField
    from drumflow.case import case_from_dict, read_toml
    from drumflow.coupling.driver import air_velocity_at
    from drumflow.dem.state import read_state
    from drumflow.pipeline import run_case

    data = read_toml(CASES / "smoke.toml")
    data["air"].update({"bed_states": [str(STATE)], "warming": True})
    data["run"].update({"start_state": str(STATE), "time": 1.06, "mass_flow_start": 1.0,
                        "processes": 2})
    case = case_from_dict(data)
    summary = run_case(case, tmp_path / "run", timeout=900)

    manifest = json.loads((tmp_path / "run" / "manifest.json").read_text())
    phases = manifest["air"]["extra"]["bed_phases"]
    # The shipped state is the smoke run's snapshot nearest 1 s (1.009 s).
    assert len(phases["angles_rad"]) == 1 and phases["time_s"] == [pytest.approx(1.0, abs=0.02)]
    assert summary["energy_balance_error"] < 1e-6
    assert summary["air_energy_balance_error"] < 1e-6
    air_log = pd.concat(pd.read_csv(p) for p in (tmp_path / "run" / "dem" / "coupling").glob("air.*.csv"))
    assert len(air_log) > 0 and (air_log["phase"] == 0).all()

    # What the loop's particles sampled: the bed's particles (the lower half of the drum, slow)
    # meet the air that goes around the bed, far slower than the empty drum's.
    state = read_state(STATE)
    spec = json.loads(next((tmp_path / "run" / "dem").glob("coupling*.json")).read_text())
    around = PhaseLockedAir.from_spec(spec["field"])
    empty = AirField.from_npz(tmp_path / "run" / "air" / "field.npz")
    bed = (state.positions[:, 1] < -0.5 * case.drum.radius) & (
        np.linalg.norm(state.velocities, axis=1) < 0.5)
    assert bed.sum() > 0.2 * len(state)
    x = state.positions[bed]
    u_bed = air_velocity_at(around, x, state.time_s, case.drum.omega)
    u_empty = air_velocity_at(empty, x, state.time_s, case.drum.omega)
    slow, free = (float(np.abs(u[:, 2]).mean()) for u in (u_bed, u_empty))
    assert slow < 0.5 * free, (slow, free)

    # What ParaView gets: the field the loop applied for each bed state beside the empty drum's
    # (the empty drum's alone was exported before: a run with bed states showed air that it
    # never applied).
    import pyvista as pv

    from drumflow.report.vtk import export_vtk

    exported = export_vtk(tmp_path / "run", tmp_path / "vtk")
    assert exported.air == "air.vti" and exported.air_bed_phases == ["air_bed_phase_0.vti"]
    phase = pv.read(str(tmp_path / "vtk" / "air_bed_phase_0.vti"))
    assert float(phase.field_data["phase_angle_rad"][0]) == pytest.approx(phases["angles_rad"][0])
    assert np.allclose(phase.point_data["velocity"][:, 2],
                       around.fields[0].velocity[..., 2].ravel(order="F"))
