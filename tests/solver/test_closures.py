"""Slice closures measured on a real (tiny) LIGGGHTS run with plug-flow air: no mocks.

Marked ``solver``; needs /usr/bin/liggghts and mpirun.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import pytest
from support.solvers import LIGGGHTS, requires_solver, tiny_case_dict

from drumflow.analysis.closures import extract_closures, load_closures
from drumflow.case import case_from_dict
from drumflow.pipeline import run_case

pytestmark = [pytest.mark.solver, requires_solver(*LIGGGHTS)]


@pytest.fixture(scope="module")
def tiny_run(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """0.2 m drum, 500 particles, uniform (plug-flow) air, 2 s: about a minute."""
    case = case_from_dict(tiny_case_dict(
        air__model="uniform", air__mass_flow=0.06, run__time=2.0, run__snapshot_interval=0.1))
    out = tmp_path_factory.mktemp("closures") / "run"
    run_case(case, out, timeout=400)
    return out


@pytest.mark.timeout(600)
def test_closures_of_a_real_run(tiny_run: Path, tmp_path: Path) -> None:
    c = extract_closures(tiny_run)
    summary = json.loads((tiny_run / "summary.json").read_text())
    # Eq. 57 per metre: the same crossings the run's post-processing counted, read back from
    # post/crossings.csv, whose times are written to 6 significant digits: the window length
    # (about 1 s) is then known to ~1e-6 relative.
    assert c.falling_mass_flow_kg_s_m == pytest.approx(
        summary["falling_mass_flow_kg_s"] / c.section_length_m, rel=1e-5)
    assert 0.0 < c.airborne_fraction < 0.5
    # Little's law: the airborne hold-up is the falling flow times the fall time.
    assert c.fall_time_s == pytest.approx(
        c.airborne_fraction * c.holdup_kg_per_m / c.falling_mass_flow_kg_s_m, rel=1e-12)
    # A fall starts at a flight and ends on the bed: inside the drum.
    assert 0.0 < c.fall_height_m < c.drum_diameter_m
    # A fall of H from rest cannot be faster than free fall, nor (near the bed) much slower
    # than a few free-fall times.
    free_fall = math.sqrt(2 * c.fall_height_m / 9.81)
    assert 0.3 * free_fall < c.fall_time_s < 5 * free_fall
    # The bed's free surface is a chord of the cross-section: shorter than the diameter.
    assert 0.0 < c.bed_surface_m2_per_m < c.drum_diameter_m
    assert c.slip_velocity_m_s > 0 and c.cascades_per_revolution > 0
    path = c.write(tmp_path / "closures.json")
    assert load_closures(path) == c


@pytest.mark.timeout(300)
def test_plant_closures_from_a_later_start(tiny_run: Path, tmp_path: Path) -> None:
    """`drumflow cooler drum RUN --start S --save-closures F`: the closures of the run from S on
    (a paper run's flights fill for seconds; the plant wants the cascading bed's), written to a
    file that is itself a SOURCE."""
    import subprocess
    import sys

    import pandas as pd

    from drumflow.analysis.observables import falling_mass_flow
    from drumflow.case import load_case

    saved = tmp_path / "closures.json"
    args = [sys.executable, "-m", "drumflow.cli", "cooler", "drum", str(tiny_run), "--start", "1.5",
            "--save-closures", str(saved), "--out", str(tmp_path / "plant"), "--json"]
    out = subprocess.run(args, capture_output=True, text=True, timeout=240, check=False)
    assert out.returncode == 0, out.stdout + out.stderr
    late = load_closures(saved)
    case = load_case(tiny_run / "case.toml")
    crossings = pd.read_csv(tiny_run / "post" / "crossings.csv")
    expected = falling_mass_flow(crossings, case.particles.mass, start=1.5).mass_flow_kg_s
    assert late.falling_mass_flow_kg_s_m == pytest.approx(expected / case.drum.length, rel=1e-12)
    # Only the snapshots from 1.5 s (every 0.1 s to 2 s): fewer than the default window's.
    assert late.window_s[0] >= 1.5 - 1e-6
    assert 0 < late.snapshots < extract_closures(tiny_run).snapshots
    # The saved file is a SOURCE: the same prediction without the run directory.
    again = subprocess.run([*args[:5], str(saved), "--json", "--out", str(tmp_path / "again")],
                           capture_output=True, text=True, timeout=240, check=False)
    assert again.returncode == 0, again.stdout + again.stderr
    first = json.loads(out.stdout)
    second = json.loads(again.stdout)
    assert second["material_outlet_temperature_C"] == first["material_outlet_temperature_C"]


@pytest.mark.timeout(300)
def test_post_records_the_closures_and_shipped_results_use_them(tiny_run: Path, tmp_path: Path) -> None:
    """`drumflow post` writes post/closures.json; a copy of the run without its snapshots (as
    results are shipped) gives the same closures from it, and refuses another --start by name."""
    import shutil

    from drumflow.case import load_case
    from drumflow.errors import RunDirectoryError

    recorded = load_closures(tiny_run / "post" / "closures.json")
    assert recorded == extract_closures(tiny_run)
    start = load_case(tiny_run / "case.toml").run.mass_flow_start
    assert recorded.start_s == pytest.approx(start)
    shipped = tmp_path / "shipped"
    shutil.copytree(tiny_run, shipped, ignore=shutil.ignore_patterns("dumps", "restart"))
    assert extract_closures(shipped) == recorded
    with pytest.raises(RunDirectoryError, match=rf"--start = 1\.5 s.*measured from {start:g} s"):
        extract_closures(shipped, start_s=1.5)
    (shipped / "post" / "closures.json").unlink()
    with pytest.raises(RunDirectoryError, match="no particle snapshot .* and no closures.json"):
        extract_closures(shipped)


@pytest.mark.timeout(600)
def test_closures_of_a_coarse_grained_run_count_parcels(tmp_path: Path) -> None:
    """Regression: with particles.coarse_grain = k each crossing is a parcel of k**3 particles;
    the closures counted it with one particle's mass, so G_f came out k**3 times too small
    (12.8 against 102.3 kg/(s m) on model two's parcels of k = 2; 3.4 times here, k = 1.5)."""
    case = case_from_dict(tiny_case_dict(
        air__model="uniform", air__mass_flow=0.06, run__time=2.0, run__snapshot_interval=0.25,
        particles__coarse_grain=1.5))  # the largest parcels the tiny drum's lifters pass
    out = tmp_path / "run"
    run_case(case, out, timeout=400)
    summary = json.loads((out / "summary.json").read_text())
    assert summary["falling_mass_flow_kg_s"] > 0
    c = extract_closures(out)
    # post counts the parcels with their own mass (case.dem_case()): the same flow per metre.
    assert c.falling_mass_flow_kg_s_m == pytest.approx(
        summary["falling_mass_flow_kg_s"] / c.section_length_m, rel=1e-5)
    # The granule stays the real one (the heat-transfer closures need its diameter).
    assert c.particle_diameter_m == pytest.approx(case.particles.diameter)
