"""Stability under stress, on real LIGGGHTS runs of the tiny drum (drumflow.dem.stability).

* A time-step sweep up to blow-up: below the limit the run finishes; forced far above it the
  run is stopped within its first output steps with a diagnosis, and nothing is post-processed.
* Extreme but valid scenes run cleanly: no particle lost, no stop, kinetic energy within the
  bound; every scene starts with a hot and a cold half (20 K apart), and with no air and
  adiabatic walls conduction must keep the mean temperature where it started while it narrows
  the spread (a uniform bed would stay at its temperature with no heat model at all).
* Invalid extremes are refused before any solver starts, naming the field.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from support.solvers import LIGGGHTS, requires_solver, tiny_case_dict

from drumflow.case import case_from_dict
from drumflow.dem.dumps import read_series
from drumflow.errors import CaseError, UnstableRunError
from drumflow.pipeline import run_case

pytestmark = [
    pytest.mark.solver,
    pytest.mark.timeout(300),
    requires_solver(*LIGGGHTS),
]


def _manifest(run: Path) -> dict:
    return json.loads((run / "manifest.json").read_text())


#: Every scene's bed starts with its left half 10 K above and its right half 10 K below 90 C.
SPREAD = {"particles__initial_temperature_spread_C": 20.0}


def _assert_clean(run: Path, particles: int, narrows: bool = True) -> None:
    manifest = _manifest(run)
    # What the run chose is on record: the corrected restitution and the shortcuts taken.
    assert manifest["restitution"]["particle_particle"]["target"] == 0.1
    assert manifest["restitution"]["particle_particle"]["liggghts_value"] >= 0.1
    assert any(s["skip"].startswith("static shell") for s in manifest["skips"])
    stability = manifest["stability"]
    assert stability["stopped"] is False
    assert stability["max_kinetic_energy_J"] < stability["limits"]["kinetic_energy_limit"]
    series = pd.read_csv(run / "post" / "mean_temperature.csv")
    assert (series["particles"] == particles).all()
    # No air and adiabatic walls: heat only moves between particles of equal m cp, so the mean
    # stays where it started (thermo prints 12 digits: 1e-7 K is round-off headroom), under the
    # real fluxes between the hot and the cold half...
    T = series["mean_temperature_C"].to_numpy()
    assert np.abs(T - T[0]).max() < 1e-7
    if not narrows:
        return
    # ...which conduction must narrow: the standard deviation of the snapshot temperatures
    # (written to 10 digits, 1e-8 K at 90 C) falls by more than 1e-6 K. A run without contact
    # conduction keeps it to the last digit; one that leaks heat fails the line above.
    snaps = read_series(run / "dem" / "dumps", manifest["time_step"]["time_step"])
    spread = np.nanstd(snaps["T"], axis=1)
    assert spread[0] == pytest.approx(10.0, rel=0.1)
    assert spread[-1] < spread[0] - 1e-6, (spread[0], spread[-1])


@pytest.mark.parametrize("time_step", [1.0e-4, 2.0e-4, 4.0e-4])
def test_time_step_sweep_to_blow_up(tmp_path: Path, time_step: float) -> None:
    """The tiny drum's Rayleigh time is 3.26e-4 s and its limit (10 steps per Hertz contact)
    5.3e-5 s. Forced to 1e-4 s (~5 steps per contact) it still runs cleanly; at 2e-4 and 4e-4 s
    contacts last 1-3 steps, particles pass through each other, and the run must be stopped
    within its first 5% of steps with a diagnosis naming the forced time step."""
    case = case_from_dict(tiny_case_dict(run__time_step=time_step, run__force_time_step=True,
                                         run__time=0.6, run__mass_flow_start=0.3, **SPREAD))
    run = tmp_path / "run"
    if time_step <= 1.0e-4:
        run_case(case, run, timeout=240)
        _assert_clean(run, 500)
        return
    with pytest.raises(UnstableRunError) as info:
        run_case(case, run, timeout=240)
    err = info.value
    planned = round(0.6 / time_step)
    assert err.step <= 0.05 * planned, (err.step, planned)
    assert "kinetic energy running away" in err.diagnosis or "non-finite" in err.diagnosis
    assert "forced above the stability limit" in err.diagnosis
    assert _manifest(run)["stability"]["stopped"] is True
    assert not (run / "post").exists() or not any((run / "post").iterdir())


def test_near_centrifuging_runs(tmp_path: Path) -> None:
    """Froude number 0.9: a 0.45 m drum at 60 rpm (the case allows up to Fr < 1)."""
    d = tiny_case_dict(drum__diameter=0.45, drum__rpm=60.0, run__time=0.4, run__mass_flow_start=0.2,
                       **SPREAD)
    d["lifters"].update(base_height=0.05, lip_length=0.025)
    case = case_from_dict(d)
    assert 0.89 < case.drum.froude < 1.0
    run_case(case, tmp_path / "run", timeout=240)
    _assert_clean(tmp_path / "run", 500)


@pytest.mark.parametrize(("name", "count"), [("nearly_empty", 20), ("half_full", 1900)])
def test_fill_extremes_run(tmp_path: Path, name: str, count: int) -> None:
    """20 particles, and 1,900 (solids 34% of the drum volume: the bed fills about half the
    drum; the case allows up to 35%)."""
    case = case_from_dict(tiny_case_dict(particles__count=count, run__time=0.3, run__mass_flow_start=0.15,
                                         **SPREAD))
    run_case(case, tmp_path / name, timeout=240)
    # 20 particles barely touch across the hot-cold line: only the mean is asserted there.
    _assert_clean(tmp_path / name, count, narrows=count > 100)


@pytest.mark.parametrize(("name", "modulus", "time"), [("very_soft", 1e5, 0.4), ("very_stiff", 1e9, 0.05)])
def test_material_extremes_run(tmp_path: Path, name: str, modulus: float, time: float) -> None:
    """100 kPa (below the paper's 517 kPa: soft_particles, large overlaps reported as a warning,
    not a stop) and 1 GPa (a time step 14 times smaller than the smoke case's)."""
    case = case_from_dict(tiny_case_dict(
        particles__youngs_modulus=modulus, run__time=time, run__mass_flow_start=0.5 * time,
        run__dump_interval=time / 10, run__snapshot_interval=time / 2, run__restart_interval=time / 2,
        **SPREAD))
    run_case(case, tmp_path / name, timeout=240)
    _assert_clean(tmp_path / name, 500)
    if modulus < 517e3:
        assert any("large overlap" in w for w in _manifest(tmp_path / name)["stability"]["warnings"])


@pytest.mark.parametrize(("override", "field"), [
    ({"drum__rpm": 60.0, "drum__diameter": 0.6}, "drum.rpm"),
    ({"particles__count": 2100}, "particles.count"),
])
def test_invalid_extremes_are_refused_before_any_solver(tmp_path: Path, override: dict, field: str) -> None:
    """Centrifuging (Froude number 1.2) and a drum over 35% full: refused, naming the field."""
    with pytest.raises(CaseError) as info:
        run_case(case_from_dict(tiny_case_dict(**override)), tmp_path / "run")
    assert field in str(info.value)
    assert not (tmp_path / "run" / "dem").exists()
