"""The particle-curtain validation scene on LIGGGHTS, its short scale (``drumflow validate
particle_curtain --scale short``: Figure 3 for 0.5 s, until the first grains reach the floor):
the chain starts, feeds at the slit's rate, takes the grains out at the floor, and its
bookkeeping closes (fed = out + in flight; the grains' enthalpy gain = the heat given; the air's
gain = the heat it gave up). Not the comparison itself (the 'parcels' scale, shipped)."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from support.solvers import LIGGGHTS, requires_solver

from drumflow.validate.curtain_output import bookkeeping_closes
from drumflow.validate.particle_curtain import curtain_scene, load_experiment
from drumflow.validate.run import run_validation

pytestmark = [pytest.mark.solver, requires_solver(*LIGGGHTS)]


@pytest.mark.timeout(900)
def test_short_curtain_feeds_empties_and_closes(tmp_path: Path) -> None:
    record = run_validation("particle_curtain", tmp_path, "short", timeout=800)
    saved = json.loads((tmp_path / "validation.json").read_text())["scenes"]["particle_curtain_short"]
    assert saved["bookkeeping_closes"] is True
    (r,) = saved["experiments"]
    book = r["dem"]["bookkeeping"]
    assert bookkeeping_closes(book)
    # LIGGGHTS fed the slit's mass flow: fed parcels x parcel mass over the run against 0.04 kg/s
    # (insertions are whole parcels, every 2 ms: within 2 %).
    case = load_experiment("curtain_fig3")
    s = curtain_scene(case, 4.0, 0.5)
    parcel = case.solids.density * 3.141592653589793 / 6 * s.parcel_diameter**3
    assert book["fed"] * parcel / 0.5 == pytest.approx(0.04, rel=0.02)
    # Grains reached the floor and left; the air gave heat (cooler gas out, warmer solids out).
    assert book["out"] > 0 and book["in_flight"] > 0
    dem = r["dem"]
    assert case.solids.inlet_temperature_C < dem["solids_outlet_C"] < case.gas.inlet_temperature_C
    assert case.solids.inlet_temperature_C < dem["gas_outlet_C"] < case.gas.inlet_temperature_C
    assert dem["gas_side_duty_W"] > 0 and dem["outlet_speed_m_s"] > 1.0
    assert (tmp_path / record["csv"]).stat().st_size > 0 and (tmp_path / record["plot"]).stat().st_size > 0
    assert "NaN" not in (tmp_path / "validation.json").read_text()
