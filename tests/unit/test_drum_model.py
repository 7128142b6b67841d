"""Whole-cooler model with hand-written slice closures (no solver): energy closure, cell
convergence, the transport law's calibration, limits and bad input."""

from __future__ import annotations

import dataclasses
import math

import pytest

from drumflow.analysis.closures import SliceClosures
from drumflow.coolers._transport import TransportLaw, calibrate
from drumflow.coolers.drum import DrumModelError, DrumOptions, solve_drum
from drumflow.coolers.plant import PAPER_PLANT

# Closures of the order a 0.4 m slice gives (smoke case): per metre of drum.
CLOSURES = SliceClosures(
    source="hand-written", case_name="hand", drum_diameter_m=0.4, section_length_m=0.08,
    rpm=15.0, tilt_deg=1.5, lifter_count=8, particle_diameter_m=8e-3,
    particle_density_kg_m3=1050.0, holdup_kg_per_m=10.56, solids_volume_fraction=0.08,
    air_axial_velocity_m_s=3.0, falling_mass_flow_kg_s_m=3.4, airborne_fraction=0.04,
    fall_time_s=0.13, fall_height_m=0.16, airborne_speed_m_s=1.3,
    airborne_downward_speed_m_s=1.25, slip_velocity_m_s=3.3, bed_slip_velocity_m_s=3.1,
    bed_surface_m2_per_m=0.25, snapshots=9, window_s=(1.0, 3.0),
)
LAW = calibrate(PAPER_PLANT, 1800.0)
# A short, small plant keeps the tests fast; the physics is the same.
SMALL = PAPER_PLANT.changed(length_m=6.0, feed_rate_kg_s=4.0, air_mass_flow_kg_s=8.0)
SMALL_LAW = calibrate(SMALL, 600.0)


def test_transport_law_calibrates_to_the_residence_time() -> None:
    assert LAW.residence_time_s(PAPER_PLANT) == pytest.approx(1800.0, rel=1e-12)
    # Hold-up = feed x residence time: the paper's 25,000 kg (Section 3.1).
    assert LAW.holdup_kg(PAPER_PLANT) == pytest.approx(25_000.0, rel=1e-5)
    # Friedman-Marshall: faster rotation and steeper tilt shorten the residence time.
    assert LAW.residence_time_s(PAPER_PLANT.changed(rpm=7.0)) < 1800.0
    assert LAW.residence_time_s(PAPER_PLANT.changed(tilt_deg=3.0)) < 1800.0
    with pytest.raises(ValueError, match="residence_time_s"):
        calibrate(PAPER_PLANT, 60.0)  # below the air-drag term alone


@pytest.mark.parametrize("options", [
    DrumOptions(cells=20),
    DrumOptions(cells=20, wall_loss_w_m2k=5.0),
    DrumOptions(cells=20, lumped_particles=True, bed_exchange=False),
])
def test_energy_closes(options: DrumOptions) -> None:
    r = solve_drum(SMALL, CLOSURES, SMALL_LAW, options)
    solids = SMALL.feed_rate_kg_s * SMALL.particle_heat_capacity_j_kgk * (
        SMALL.material_inlet_temperature_c - r.material_outlet_c)
    air = SMALL.air_mass_flow_kg_s * SMALL.air_heat_capacity_j_kgk * (
        r.air_outlet_c - SMALL.air_inlet_temperature_c)
    # Every cell's heat is the particle's enthalpy change, the air takes exactly it, and the
    # air outlet is solved exactly: closure at round-off.
    assert abs(solids - air - r.wall_loss_w) / solids < 1e-9
    assert abs(r.energy_residual) < 1e-9
    assert r.air_c[-1] == pytest.approx(SMALL.air_inlet_temperature_c, abs=1e-9)
    assert r.heat_curtain_w + r.heat_bed_w == pytest.approx(r.heat_to_air_w, rel=1e-12)
    # Second law: counter-current, the solids stay above the air entering their cell.
    assert all(s >= a - 1e-9 for s, a in zip(r.solids_c[1:], r.air_c[1:], strict=True))


def test_cell_count_converged() -> None:
    coarse = solve_drum(PAPER_PLANT, CLOSURES, LAW, DrumOptions(cells=40))
    fine = solve_drum(PAPER_PLANT, CLOSURES, LAW, DrumOptions(cells=80))
    # The criterion: outlets move less than 0.05 K from N to 2N.
    assert abs(coarse.material_outlet_c - fine.material_outlet_c) < 0.05
    assert abs(coarse.air_outlet_c - fine.air_outlet_c) < 0.05


def test_no_falling_no_bed_means_no_heat() -> None:
    # An (almost) empty curtain and the bed term off: nothing takes heat from the solids.
    still = dataclasses.replace(CLOSURES, falling_mass_flow_kg_s_m=1e-9)
    r = solve_drum(SMALL, still, SMALL_LAW, DrumOptions(cells=5, bed_exchange=False))
    # 1e-9 of the hand closures' falls: the heat scales with it, ~1e-7 K of the 60 K.
    assert r.material_outlet_c == pytest.approx(SMALL.material_inlet_temperature_c, abs=1e-5)
    assert r.air_outlet_c == pytest.approx(SMALL.air_inlet_temperature_c, abs=1e-5)


def test_wall_loss_cools_the_solids_and_not_the_air() -> None:
    base = solve_drum(SMALL, CLOSURES, SMALL_LAW, DrumOptions(cells=20))
    lossy = solve_drum(SMALL, CLOSURES, SMALL_LAW, DrumOptions(cells=20, wall_loss_w_m2k=20.0))
    assert lossy.wall_loss_w > 0
    assert lossy.material_outlet_c < base.material_outlet_c
    assert lossy.air_outlet_c < base.air_outlet_c


def test_interior_conduction_slows_cooling() -> None:
    # Bi ~ 1 for 2.7 mm NPK: the interior resistance can only reduce the heat given off.
    real = solve_drum(SMALL, CLOSURES, SMALL_LAW, DrumOptions(cells=20))
    lumped = solve_drum(SMALL, CLOSURES, SMALL_LAW, DrumOptions(cells=20, lumped_particles=True))
    assert real.biot_fall > 0.5
    assert lumped.material_outlet_c < real.material_outlet_c


def test_bad_input_names_the_field() -> None:
    with pytest.raises(DrumModelError, match="cells = 0"):
        DrumOptions(cells=0)
    hot_air = SMALL.changed(air_inlet_temperature_c=120.0)
    with pytest.raises(DrumModelError, match="material_inlet_temperature_c"):
        solve_drum(hot_air, CLOSURES, SMALL_LAW, DrumOptions(cells=5))
    assert math.isfinite(TransportLaw().residence_time_s(PAPER_PLANT))


def test_the_plants_own_slice_needs_no_scaling() -> None:
    """results/paper/model_one/post/closures.json: the closures of paper model one, a 0.1 m slice of
    the plant itself (docs/plant.md, 'The plant's own slice'). Its drum is the plant's, and its hold-up
    per metre, set from the paper's particle count, is the one the plant's measured residence
    time gives (feed x 30 min / 19 m): two independent routes to one number. So the drum model
    must carry the falling flow, falls per revolution and fall height over unchanged."""
    from pathlib import Path

    from drumflow.analysis.closures import load_closures

    shipped = Path(__file__).resolve().parents[2] / "results" / "paper" / "model_one"
    shipped = shipped / "post" / "closures.json"
    closures = load_closures(shipped)
    assert closures.case_name == "paper_model_one"
    assert (closures.drum_diameter_m, closures.rpm, closures.tilt_deg) == (
        PAPER_PLANT.diameter_m, PAPER_PLANT.rpm, PAPER_PLANT.tilt_deg)
    assert PAPER_PLANT.residence_time_s is not None
    plant_holdup = PAPER_PLANT.feed_rate_kg_s * PAPER_PLANT.residence_time_s / PAPER_PLANT.length_m
    assert closures.holdup_kg_per_m == pytest.approx(plant_holdup, rel=1e-5)
    # Measured over the cascading bed, after the flights' first filling (about 3.5 s).
    assert closures.window_s[0] > 3.0
    r = solve_drum(PAPER_PLANT, closures, LAW, DrumOptions(cells=40))
    s = r.scaled
    assert s.falling_mass_flow_kg_s_m == pytest.approx(closures.falling_mass_flow_kg_s_m, rel=1e-5)
    assert s.cascades_per_revolution == pytest.approx(closures.cascades_per_revolution, rel=1e-12)
    assert s.fall_height_m == pytest.approx(closures.fall_height_m, rel=1e-12)
    assert abs(r.energy_residual) < 1e-9
    inlet_air, inlet_solids = PAPER_PLANT.air_inlet_temperature_c, PAPER_PLANT.material_inlet_temperature_c
    assert inlet_air < r.material_outlet_c < inlet_solids
