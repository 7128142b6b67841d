"""Issue 34: the air split into the stream through the curtains and the bypass, the range of
the prediction over it, and the plant's measured balance. Hand-written closures, no solver."""

from __future__ import annotations

import dataclasses
import json
import math
from pathlib import Path

import numpy as np
import pytest
from test_drum_model import CLOSURES

from drumflow.coolers._curtain_pass import curtain_pass
from drumflow.coolers._propagator import exposure_matrix
from drumflow.coolers._transport import calibrate
from drumflow.coolers.curtain_air import (
    curtain_air_for_outlet,
    curtain_air_scales,
    sweep_curtain_air,
)
from drumflow.coolers.drum import DrumModelError, DrumOptions, solve_drum
from drumflow.coolers.plant import PAPER_PLANT
from drumflow.coolers.plant_balance import measured_balance, shell_loss_coefficient
from drumflow.physics.particle_interior import Sphere, SphereConduction

# The hand-written closures of test_drum_model (a 0.4 m slice), shared with it.
SMALL = PAPER_PLANT.changed(length_m=6.0, feed_rate_kg_s=4.0, air_mass_flow_kg_s=8.0)
SMALL_LAW = calibrate(SMALL, 600.0)
SPHERE = Sphere(2.7e-3, 0.18596, 1050.0, 1465.38)


def _closes(r: object) -> None:
    from drumflow.coolers.drum import DrumResult

    assert isinstance(r, DrumResult)
    p = r.plant
    solids = p.feed_rate_kg_s * p.particle_heat_capacity_j_kgk * (
        p.material_inlet_temperature_c - r.material_outlet_c)
    air = p.air_mass_flow_kg_s * p.air_heat_capacity_j_kgk * (r.air_outlet_c
                                                              - p.air_inlet_temperature_c)
    assert abs(solids - air - r.wall_loss_w) <= 1e-9 * abs(solids)
    assert abs(r.energy_residual) < 1e-9


# -- the curtain pass ------------------------------------------------------------------------

def test_unbounded_air_through_the_curtain_is_the_plain_exposure() -> None:
    """With far more air than the particles can warm, the curtain's gas stays at its inlet
    temperature: the pass is the exposure to the cell's air (the all-air model's fall)."""
    model = SphereConduction(SPHERE, shells=10)
    plain = exposure_matrix(model, 150.0, 0.5)
    split = curtain_pass(model, 150.0, 0.5, particle_rate=1e5, gas_capacity_rate_w_k=1e12,
                         rows=5)
    state = np.concatenate([np.linspace(60.0, 80.0, 10), [30.0]])
    assert np.allclose(split.matrix @ state, plain @ state, atol=2e-5)
    assert split.gas_out @ state == pytest.approx(30.0, abs=1e-6)


def test_saturated_curtain_sends_the_air_out_at_the_particles_temperature() -> None:
    """A dense curtain crossed by little air: the air leaves at the particles' temperature and
    the particles hardly change (what the issue says limits the real cooler)."""
    model = SphereConduction(SPHERE, shells=10)
    # ~2.3e5 particles/s (about the plant's falls in 0.5 m of drum), 1 W/K of air: gas NTU ~ 400.
    p = curtain_pass(model, 150.0, 0.5, particle_rate=2.3e5, gas_capacity_rate_w_k=1.0, rows=5)
    assert p.gas_ntu > 100
    state = np.concatenate([np.full(10, 80.0), [30.0]])
    assert p.gas_out @ state == pytest.approx(80.0, abs=1e-3)
    # The particles lose only what the saturated air takes: 1 W/K x 50 K over their capacity
    # rate.
    drop = 1.0 * 50.0 / (2.3e5 * SPHERE.mass * SPHERE.heat_capacity)
    assert 80.0 - model.mean_temperature((p.matrix @ state)[:10]) == pytest.approx(drop, rel=1e-3)


def test_curtain_without_air_gives_no_heat() -> None:
    model = SphereConduction(SPHERE, shells=10)
    p = curtain_pass(model, 150.0, 0.5, particle_rate=1e5, gas_capacity_rate_w_k=0.0, rows=5)
    state = np.concatenate([np.linspace(60.0, 80.0, 10), [30.0]])
    after = (p.matrix @ state)[:10]
    assert model.enthalpy(after) == pytest.approx(model.enthalpy(state[:10]), rel=1e-12)


# -- the drum with the split air -------------------------------------------------------------

def test_unbounded_through_curtain_flow_is_the_all_air_model() -> None:
    """The all-air behaviour (issue 34's starting point) stays one setting, and the split model
    tends to it as the through-curtain flow grows."""
    legacy = solve_drum(SMALL, CLOSURES, SMALL_LAW, DrumOptions(cells=20))
    split = solve_drum(SMALL, CLOSURES, SMALL_LAW,
                       DrumOptions(cells=20, curtain_air_m3_s_m=1e4))
    assert legacy.options.all_air_meets_curtain
    assert split.material_outlet_c == pytest.approx(legacy.material_outlet_c, abs=0.01)
    assert split.air_outlet_c == pytest.approx(legacy.air_outlet_c, abs=0.01)
    _closes(split)


def test_no_air_through_the_curtains_leaves_only_the_bed() -> None:
    r = solve_drum(SMALL, CLOSURES, SMALL_LAW, DrumOptions(cells=20, curtain_air_m3_s_m=0.0))
    assert abs(r.heat_curtain_w) < 1e-9 * r.heat_bed_w
    assert r.heat_bed_w > 0
    _closes(r)
    # And with the bed term off nothing cools the solids.
    still = solve_drum(SMALL, CLOSURES, SMALL_LAW,
                       DrumOptions(cells=10, curtain_air_m3_s_m=0.0, bed_exchange=False))
    assert still.material_outlet_c == pytest.approx(SMALL.material_inlet_temperature_c, abs=1e-9)
    assert still.air_outlet_c == pytest.approx(SMALL.air_inlet_temperature_c, abs=1e-9)


def test_more_air_through_the_curtains_cools_more() -> None:
    points = sweep_curtain_air(SMALL, CLOSURES, SMALL_LAW, DrumOptions(cells=20),
                               (0.0, 0.05, 0.2, 1.0, None))
    outlets = [p.material_outlet_c for p in points]
    assert all(a > b for a, b in zip(outlets[:-1], outlets[1:], strict=True))
    assert points[0].curtain_passes == 0.0 and points[-1].curtain_passes is None


def test_flow_for_an_outlet_is_found_and_reproduces_it() -> None:
    opt = DrumOptions(cells=20)
    points = sweep_curtain_air(SMALL, CLOSURES, SMALL_LAW, opt, (0.0, 0.05, 0.2, 1.0, None))
    target = 0.5 * (points[1].material_outlet_c + points[2].material_outlet_c)
    needed = curtain_air_for_outlet(SMALL, CLOSURES, SMALL_LAW, opt, target, points)
    assert needed.curtain_air_m3_s_m is not None and 0.05 < needed.curtain_air_m3_s_m < 0.2
    at = solve_drum(SMALL, CLOSURES, SMALL_LAW,
                    dataclasses.replace(opt, curtain_air_m3_s_m=needed.curtain_air_m3_s_m))
    assert at.material_outlet_c == pytest.approx(target, abs=0.01)
    # Out of reach on both sides: no flow, a reason.
    hot = curtain_air_for_outlet(SMALL, CLOSURES, SMALL_LAW, opt, 89.9, points)
    cold = curtain_air_for_outlet(SMALL, CLOSURES, SMALL_LAW, opt, 30.1, points)
    assert hot.curtain_air_m3_s_m is None and "bed alone" in hot.reason
    assert cold.curtain_air_m3_s_m is None and "all the air" in cold.reason


def test_air_streams_are_reported() -> None:
    r = solve_drum(SMALL, CLOSURES, SMALL_LAW, DrumOptions(cells=20, curtain_air_m3_s_m=0.5))
    streams = r.to_dict()["air_streams"]
    rho = r.curtain_air_kg_s_m / 0.5
    assert 1.1 < rho < 1.2  # air at the 30 C inlet
    assert streams["through_curtain_kg_s_total"] == pytest.approx(rho * 0.5 * SMALL.length_m)
    share = streams["through_share_per_cell"]
    assert share + streams["bypass_share_per_cell"] == pytest.approx(1.0)
    assert len(r.to_dict()["profile"]["cell_curtain_air_out_C"]) == 20
    scales = curtain_air_scales(SMALL, r.scaled)
    assert scales["axial_air_per_metre"]["m3_s_per_m"] == pytest.approx(
        SMALL.air_mass_flow_kg_s / rho / SMALL.length_m, rel=1e-9)


@pytest.mark.parametrize("bad", [-0.1, math.inf, math.nan, 2e4])
def test_bad_through_curtain_flow_is_refused_by_name(bad: float) -> None:
    with pytest.raises(DrumModelError, match="curtain_air_m3_s_m"):
        DrumOptions(curtain_air_m3_s_m=bad)


# -- the plant's measured balance ------------------------------------------------------------

def test_measured_balance_of_the_paper_plant() -> None:
    """Written out: 13.88889 kg/s x 1465.38 J/(kg K) x (90 - 46.5) K against
    25 kg/s x 1005 J/(kg K) x (59 - 30) K."""
    b = measured_balance(PAPER_PLANT)
    solids = 13.88889 * 1465.38 * 43.5
    air = 25.0 * 1005.0 * 29.0
    assert b.solids_heat_w == pytest.approx(solids, rel=1e-12)  # 885.3 kW
    assert b.air_heat_w == pytest.approx(air, rel=1e-12)  # 728.6 kW
    assert b.gap_w == pytest.approx(156_709.0, abs=1.0)
    gap = solids - air
    shell = math.pi * 3.0 * 19.0
    assert b.option("wall loss").needed == pytest.approx(gap / (shell * (68.25 - 30.0)))
    assert b.option("evaporation").needed == pytest.approx(gap / (13.88889 * 2.4e6))  # 0.47 %
    assert b.option("evaporation").heat_at_bound_w == pytest.approx(0.005 * 13.88889 * 2.4e6)
    assert b.option("heat capacity").needed == pytest.approx(air / (13.88889 * 43.5))  # ~1206
    assert b.option("air leaking in").needed == pytest.approx(gap / (1005.0 * 29.0))  # 5.4 kg/s
    # Wall loss is bounded to tens of kW: it cannot close the gap alone.
    wall = b.option("wall loss")
    assert wall.heat_at_bound_w is not None and 30e3 < wall.heat_at_bound_w < b.gap_w


def test_shell_loss_coefficient_written_out() -> None:
    """Churchill-Chu and linearised radiation for a 3 m shell at 68.25 C in 30 C air, with the
    Incropera Table A.4 300/350 K rows interpolated at the 322.3 K film by hand."""
    film_k = 0.5 * (68.25 + 30.0) + 273.15
    w = (film_k - 300.0) / 50.0
    nu = 15.89e-6 + w * (20.92e-6 - 15.89e-6)
    k = 26.3e-3 + w * (30.0e-3 - 26.3e-3)
    pr = 0.707 + w * (0.700 - 0.707)
    ra = 9.81 / film_k * 38.25 * 27.0 / (nu * nu / pr)
    nusselt = (0.60 + 0.387 * ra ** (1 / 6) / (1 + (0.559 / pr) ** (9 / 16)) ** (8 / 27)) ** 2
    expected = nusselt * k / 3.0 + 4 * 0.9 * 5.670374419e-8 * film_k**3
    assert shell_loss_coefficient(3.0, 68.25, 30.0) == pytest.approx(expected, rel=1e-6)
    assert 8.0 < expected < 14.0  # still air: ~4 convection + ~7 radiation


# -- the command -----------------------------------------------------------------------------

def test_cli_reports_the_streams_the_range_and_the_balance(tmp_path: Path) -> None:
    import json
    import subprocess
    import sys


    root = Path(__file__).resolve().parents[2]
    out = subprocess.run([sys.executable, "-m", "drumflow.cli", "plant",
                          str(root / "docs" / "plant" / "smoke_closures.json"), "--json",
                          "--cells", "20", "--out", str(tmp_path / "plant")],
                         capture_output=True, text=True, timeout=400, check=False)
    assert out.returncode == 0, out.stdout + out.stderr
    answer = json.loads(out.stdout)
    assert answer["air_streams"]["setting"] == "all"
    sweep = answer["curtain_air"]["sweep"]
    assert sweep[0]["curtain_air_m3_s_per_m"] == 0.0 and sweep[-1]["curtain_air_m3_s_per_m"] is None
    assert sweep[-1]["material_outlet_C"] == pytest.approx(answer["material_outlet_temperature_C"])
    assert answer["plant_balance"]["gap_W"] == pytest.approx(156_709.0, abs=1.0)
    assert (tmp_path / "plant" / "curtain_air.csv").exists()
    assert (tmp_path / "plant" / "curtain_air.png").exists()


@pytest.mark.parametrize("value", ["-1", "lots", "1e9"])
def test_cli_refuses_a_bad_curtain_air(value: str, tmp_path: Path) -> None:
    import subprocess
    import sys


    root = Path(__file__).resolve().parents[2]
    out = subprocess.run([sys.executable, "-m", "drumflow.cli", "plant",
                          str(root / "docs" / "plant" / "smoke_closures.json"),
                          f"--curtain-air={value}", "--out", str(tmp_path / "plant")],
                         capture_output=True, text=True, timeout=120, check=False)
    assert out.returncode == 2, out.stdout + out.stderr
    assert f"--curtain-air = {value}" in out.stderr and "allowed 'all', 0 to" in out.stderr
    assert "Traceback" not in out.stderr


def test_the_curtain_air_comes_from_a_periodic_slice_file(tmp_path: Path) -> None:
    """A periodic bed-air heat.json gives its saturated flow; an inlet-outlet one, a missing
    or a broken file are refused by name."""
    from drumflow.coolers.drum import DrumModelError
    from drumflow.coolers.plant_from_slice import curtain_air_setting

    shipped = Path(__file__).resolve().parents[2] / "results" / "air" / \
        "bed_air_model_two_5.0s_mesh0.1_periodic"
    heat, split = tmp_path / "heat.json", tmp_path / "split.json"
    warm, flow = json.loads((shipped / "heat.json").read_text()), json.loads(
        (shipped / "split.json").read_text())
    warm["saturated_flow_m3_s_m"] = 1.25
    heat.write_text(json.dumps(warm))
    split.write_text(json.dumps(flow))
    assert curtain_air_setting(str(heat)) == pytest.approx(1.25)
    split.write_text(json.dumps({**flow, "axial": "inlet-outlet"}))
    with pytest.raises(DrumModelError, match="axial = inlet-outlet: allowed periodic"):
        curtain_air_setting(str(heat))
    split.write_text(json.dumps(flow))
    heat.write_text(json.dumps({**warm, "saturated_flow_m3_s_m": -3.0}))
    with pytest.raises(DrumModelError, match="curtain_air_m3_s_m = -3.0"):
        curtain_air_setting(str(heat))
    heat.write_text(json.dumps({**warm, "saturated_flow_m3_s_m": 2e4}))
    with pytest.raises(DrumModelError, match="saturated_flow_m3_s_m = 20000.0: allowed 0 to"):
        curtain_air_setting(str(heat))
    heat.write_text("{ truncated")
    with pytest.raises(DrumModelError, match="heat.json: not a periodic slice's bed-air heat.json"):
        curtain_air_setting(str(heat))
    with pytest.raises(DrumModelError, match="nothing.json"):
        curtain_air_setting(str(tmp_path / "nothing.json"))


def test_the_plant_from_the_shipped_periodic_slice_records_its_source() -> None:
    from drumflow.coolers.plant_from_slice import plant_from_slice

    root = Path(__file__).resolve().parents[2]
    heat = root / "results" / "air" / "bed_air_model_two_5.0s_mesh0.1_periodic" / "heat.json"
    evaluation = plant_from_slice(root / "docs" / "plant" / "smoke_closures.json",
                                  curtain_air=str(heat), sweep=False)
    flow = json.loads(heat.read_text())["saturated_flow_m3_s_m"]
    answer = evaluation.to_dict()
    assert answer["curtain_air"]["setting_m3_s_per_m"] == pytest.approx(flow)
    assert answer["curtain_air"]["from_slice"] == str(heat)
