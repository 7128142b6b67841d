"""The particle-curtain validation scene (drumflow.validate.particle_curtain) without a solver:
registry, the scene's plan, the duct's air, the deck, and the reading of the loop's logs on logs
whose answer is known (a 10 % error in any of its formulas moves a checked number by 10 %)."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from drumflow.air.heat import AirHeat
from drumflow.coupling.outlet import OUTLET_LOG_COLUMNS, read_outlet_log
from drumflow.dem.deck import render_deck
from drumflow.validate import SCENES, ValidationDataError, scene
from drumflow.validate.curtain_output import bookkeeping_closes, plot_curtain, write_curtain_csv
from drumflow.validate.particle_curtain import (
    EXPERIMENTS,
    SETUP,
    CurtainScene,
    curtain_scene,
    deck_context,
    duct_air,
    load_experiment,
    reduced_order,
    run_particle_curtain,
    summarise_run,
)


def test_registry_names_the_curtain_scene_and_its_source() -> None:
    sc = scene("particle_curtain")
    assert SCENES["particle_curtain"] is sc
    assert "Wardjiman" in sc.source and "Powder Technology 191" in sc.source
    assert sc.scales[0] == "parcels" and "short" in sc.scales
    assert all(c.item and c.value and c.source for c in SETUP)


def test_experiments_are_the_reduced_order_cases() -> None:
    assert EXPERIMENTS == tuple(f"curtain_fig{i}" for i in range(3, 9))
    case = load_experiment("curtain_fig7")
    assert case.geometry.thickness == 0.10 and case.solids.fall_velocity == 1.3
    with pytest.raises(ValidationDataError, match="'curtain_fig9'.*allowed: curtain_fig3"):
        load_experiment("curtain_fig9")


def test_a_missing_case_file_is_named(tmp_path: Path) -> None:
    with pytest.raises(ValidationDataError, match="curtain_fig3.toml: the case file"):
        load_experiment("curtain_fig3", tmp_path)


def test_an_unknown_scale_is_refused_before_any_run(tmp_path: Path) -> None:
    with pytest.raises(ValidationDataError, match="scale = 'huge'.*allowed: parcels, short, finer"):
        run_particle_curtain(tmp_path, "huge")


def test_scene_plan_resolves_collisions_and_ends_updates_on_thermo_rows() -> None:
    s = curtain_scene(load_experiment("curtain_fig3"), 4.0)
    assert s.parcel_diameter == pytest.approx(4 * 204e-6)
    assert 1e-6 < s.time_step <= 2e-5
    # Feed and snapshots fall on thermo rows, on which the loop ends its updates.
    assert s.feed_every % s.thermo_every == 0 and s.snapshot_every % s.thermo_every == 0
    assert 1 <= s.interval <= s.thermo_every
    # The window starts after 1.2 fall-time bounds and averages 0.25 s.
    assert s.window[0] == pytest.approx(1.2 * s.fall_time_bound)
    assert s.window[1] - s.window[0] == pytest.approx(0.25, abs=s.time_step)
    # The fall-time bound: the height over the smaller of exit (1.35) and settling (~1.5) speeds.
    assert s.fall_time_bound == pytest.approx(0.6 / 1.35)
    # Updates about every 0.2 ms at either parcel size (a regression: two rounded step counts
    # once had 1 as their common divisor, and the loop updated at every step).
    for k in (4.0, 2.5):
        finer = curtain_scene(load_experiment("curtain_fig3"), k)
        assert finer.interval * finer.time_step >= 1e-4
    assert s.slit == (-0.02, 0.02) and s.z_high == pytest.approx(0.07) and s.z_low == pytest.approx(-0.52)


def test_duct_air_carries_the_ducts_volume_flow() -> None:
    s = curtain_scene(load_experiment("curtain_fig4"), 4.0)
    field = duct_air(s)
    heat = AirHeat(field, 45.0, 1.1, 1007.0)
    # Width x height x gas velocity: 0.15 x 0.6 x 1.2 m3/s, the cells tiling the duct exactly.
    assert heat.volume_flow == pytest.approx(0.15 * 0.6 * 1.2, rel=1e-9)
    axes = field.axes()
    assert axes[1][0] - 0.5 * field.spacing[1] == pytest.approx(0.0)
    assert axes[1][-1] + 0.5 * field.spacing[1] == pytest.approx(0.6)
    assert axes[2][-1] + 0.5 * field.spacing[2] == pytest.approx(s.z_high)


def test_deck_feeds_the_slit_and_refuses_silent_losses() -> None:
    s = curtain_scene(load_experiment("curtain_fig5"), 4.0)
    deck = render_deck(deck_context(s), "curtain_duct.in.j2")
    assert "massrate 0.04" in deck and "vel constant 0. -1.35 0." in deck
    assert "region feed block 0 0.15" in deck and "-0.03 0.03" in deck  # the 6 cm slit
    assert "thermo_modify   lost error" in deck
    assert "fix Temp all property/atom Temp scalar yes no no 12.6" in deck
    assert "boundary        p f f" in deck
    ctx = deck_context(s)
    # One insertion's layer is as deep as the exit speed carries the parcels in that time.
    assert ctx["height"] - ctx["feed_low"] == pytest.approx(1.35 * s.feed_every * s.time_step)


def _scene() -> CurtainScene:
    return CurtainScene(case=load_experiment("curtain_fig3"), coarse_grain=4.0,
                        parcel_diameter=8.16e-4, time_step=1e-5, interval=10, thermo_every=10,
                        feed_every=10, snapshot_every=100, total_steps=100, window=(0.0005, 0.001),
                        z_low=-0.27, z_high=0.07, slit=(-0.02, 0.02), fall_time_bound=0.44)


def _logs(work: Path) -> None:
    """Logs of a loop whose answer is known: four takes 0.25 ms apart, each taking 10 parcels of
    1e-6 kg at 30 C falling at 2 m/s, 0.05 m downstream; 100 fed in all."""
    (work / "coupling").mkdir(parents=True)
    (work / "dumps").mkdir()
    rows = [",".join(OUTLET_LOG_COLUMNS)]
    for i, t in enumerate((0.0, 0.00025, 0.0005, 0.00075, 0.001)):
        out = 0 if i == 0 else 10
        left = 100 - 10 * i
        rows.append(f"{t},100,{left},{left * 1e-6},{left * 1e-6 * 20.0},{out},{out * 1e-6},"
                    f"{out * 1e-6 * 30.0},{-out * 1e-6 * 2.0},{-out * 1e-6 * 0.05}")
    (work / "coupling/outlet.0.csv").write_text("\n".join(rows) + "\n")
    # The heat the loop gave: what the enthalpies say (40 parcels from 15.8 to 30, 60 to 20 C).
    gained = 753.1 * (40e-6 * (30.0 - 15.8) + 60e-6 * (20.0 - 15.8))
    (work / "coupling/rank0.0.csv").write_text(
        "step,time_s,steps,heat_to_particles_W\n" + f"0,0,100,{gained / (100 * 1e-5)}\n")
    (work / "coupling/air.0.csv").write_text(
        "step,time_s,steps,heat_to_air_W,air_enthalpy_gain_W,outlet_C\n"
        "50,0.0005,10,-600,-600,35\n100,0.001,10,-600,-600,37\n")
    (work / "dumps/snap.100.txt").write_text(
        "ITEM: TIMESTEP\n100\nITEM: NUMBER OF ATOMS\n2\nITEM: BOX BOUNDS pp ff ff\n0 1\n0 1\n0 1\n"
        "ITEM: ATOMS id x y z vx vy vz f_Temp[0]\n1 0.1 0.55 -0.01 0 -1.4 -0.1 16\n"
        "2 0.1 0.04 -0.06 0 -1.6 -0.2 29\n")


def test_summary_reads_the_loops_logs(tmp_path: Path) -> None:
    _logs(tmp_path)
    r = summarise_run(tmp_path, _scene())
    # The window (0.5, 1.0] ms holds two takes: 20 parcels over 0.5 ms.
    assert r["solids_flow_out_kg_s"] == pytest.approx(20e-6 / 0.0005)
    assert r["solids_outlet_C"] == pytest.approx(30.0)
    assert r["heat_duty_W"] == pytest.approx(0.04 * 753.1 * (30.0 - 15.8))
    assert r["gas_side_duty_W"] == pytest.approx(600.0)
    assert r["gas_outlet_C"] == pytest.approx(36.0)
    assert r["outlet_speed_m_s"] == pytest.approx(2.0)
    assert r["outlet_drift_m"] == pytest.approx(0.05)
    book = r["bookkeeping"]
    assert book["count_residual"] == 0 and abs(book["energy_residual"]) < 1e-12
    assert bookkeeping_closes(book)
    top, bottom = r["profile"][0], r["profile"][-1]
    assert top["solids_C"] == 16.0 and bottom["solids_C"] == 29.0 and bottom["speed_m_s"] == 1.6


def test_a_lost_parcel_or_missing_heat_fails_the_bookkeeping(tmp_path: Path) -> None:
    _logs(tmp_path)
    log = tmp_path / "coupling/outlet.0.csv"
    lines = log.read_text().splitlines()
    lines[-1] = lines[-1].replace(",100,", ",101,", 1)  # one fed that is neither out nor in flight
    log.write_text("\n".join(lines) + "\n")
    book = summarise_run(tmp_path, _scene())["bookkeeping"]
    assert book["count_residual"] == 1 and not bookkeeping_closes(book)
    heat = tmp_path / "coupling/rank0.0.csv"
    head, row = heat.read_text().splitlines()
    w = float(row.split(",")[-1])
    heat.write_text(f"{head}\n0,0,100,{1.1 * w}\n")
    book = summarise_run(tmp_path, _scene())["bookkeeping"]
    assert book["energy_residual"] == pytest.approx(-0.1 / 1.1, rel=1e-9)


def test_outlet_log_without_its_columns_is_refused(tmp_path: Path) -> None:
    path = tmp_path / "outlet.0.csv"
    path.write_text("time_s,fed\n0,1\n")
    with pytest.raises(ValueError, match="not an outlet log.*in_flight"):
        read_outlet_log(path)


def test_reduced_order_uses_drumflows_air_and_the_constant_fall() -> None:
    r = reduced_order(load_experiment("curtain_fig3"))
    # The shipped table's Figure 3 row (paper air): 677 W, 38.29 C; drumflow's air moves it a little.
    assert r["heat_duty_W"] == pytest.approx(677.4, rel=0.05)
    assert r["outlet_speed_m_s"] == 1.35 and r["outlet_drift_m"] == 0.0
    assert math.isclose(r["profile"]["depth_m"][-1], 0.6, rel_tol=1e-9)


def test_csv_and_plot_of_records(tmp_path: Path) -> None:
    _logs(tmp_path / "run")
    dem = summarise_run(tmp_path / "run", _scene())
    rom = reduced_order(load_experiment("curtain_fig3"))
    records = [{"experiment": "curtain_fig3", "coarse_grain": 4.0, "dem": dem, "reduced_order": rom,
                "wall_time_s": 1.0}]
    write_curtain_csv(tmp_path / "c.csv", records)
    header, row = (tmp_path / "c.csv").read_text().splitlines()
    cells = dict(zip(header.split(","), row.split(","), strict=True))
    assert float(cells["dem_solids_outlet_C"]) == pytest.approx(30.0)
    assert float(cells["reduced_order_outlet_speed_m_s"]) == 1.35
    plot_curtain(tmp_path / "c.png", records, "short")
    assert (tmp_path / "c.png").stat().st_size > 0
    assert np.isfinite(float(cells["energy_residual"]))
