"""The air coupling on the real LIGGGHTS library: `drumflow verify --quick` end to end."""

from __future__ import annotations

import json
import math
import re
import subprocess
import sys
from pathlib import Path

import pytest
from support.solvers import LIGGGHTS, OPENFOAM, requires_solver

pytestmark = [
    pytest.mark.solver,
    requires_solver(*LIGGGHTS, *OPENFOAM),
]


@pytest.mark.timeout(1500)
def test_verify_quick_passes_and_writes_json(tmp_path: Path) -> None:
    out = tmp_path / "verify"
    proc = subprocess.run(
        [sys.executable, "-m", "drumflow.cli", "verify", "--quick", "--out", str(out)],
        capture_output=True, text=True, timeout=1400, check=False,
    )
    assert proc.returncode == 0, proc.stderr[-3000:]
    data = json.loads((out / "verification.json").read_text())
    checks = data["checks"]
    names = {c["name"] for c in checks}
    assert {"convective_h_ranz_marshall_1ms", "convective_h_ranz_marshall_3ms",
            "drag_coefficient_standard_curve", "conduction_conserves_mean_temperature",
            "heat_bookkeeping_air", "bed_cooling_lumped_slip_estimate",
            "air_mass_flow_in_equals_out", "air_mean_axial_velocity",
            "couette_rotating_cylinders", "wall_restitution_e0.3_v2"} <= names
    assert sum(n.startswith("settling_drag_re") for n in names) == 2
    for c in checks:
        assert set(c) >= {"name", "measured", "expected", "error", "tolerance", "passed", "kind"}
        assert c["passed"], c
        assert math.isfinite(c["tolerance"]), c  # no check that cannot fail
    # The summary counts independent references apart from bookkeeping.
    kinds = {c["name"]: c["kind"] for c in checks}
    assert kinds["heat_bookkeeping_air"] == kinds["air_mass_flow_in_equals_out"] == "bookkeeping"
    assert data["summary"]["bookkeeping"]["checks"] == sum(k == "bookkeeping" for k in kinds.values())
    assert data["summary"]["reference"]["failed"] == []


@pytest.mark.timeout(600)
def test_smoke_drum_with_uniform_air_cools_and_closes_energy(tmp_path: Path) -> None:
    from drumflow.pipeline import run_case
    from drumflow.verify.scenes import tiny_drum

    case = tiny_drum(air__model="uniform", air__mass_flow=0.1, run__processes=2)
    summary = run_case(case, tmp_path / "run", timeout=500)
    # Cooling happened, through the air, on 2 MPI ranks (each rank logs its own particles).
    assert summary["mean_temperature_C"] < 90.0 - 0.1
    # Heat bookkeeping (logged heat against LIGGGHTS' enthalpy, summed over both ranks'
    # logs): the same numbers twice, closing to ~1e-9 with 12-digit output.
    assert summary["energy_balance_error"] < 1e-6
    ranks = list((tmp_path / "run" / "dem" / "coupling").glob("rank1.*.csv"))
    assert ranks, "rank 1 wrote no coupling log: the run did not use 2 ranks"
    assert summary["particles_final"] == 500
    # The loop evaluates the overlap column on every OVERLAP_EVERY_ROWS-th output row only (and
    # the last): LIGGGHTS took the switched formula, the other rows read NaN.
    from drumflow.dem.thermo import read_thermo

    spec = json.loads((tmp_path / "run" / "dem" / "coupling.json").read_text())
    thermo = read_thermo(tmp_path / "run" / "dem")
    every, interval = int(spec["overlap_every"]), int(spec["interval"])
    # The loop runs `interval` steps at a time from step 0, and switches the column on for a
    # whole run that reaches a multiple of `every`, and for the last run. A row closes the run
    # it ends (read_thermo keeps a step's first row). Regression: the test took only rows at or
    # just before a multiple as evaluated, which held while `every` was a multiple of
    # `interval` and failed when the spin-limited step changed both.
    step = thermo["step"]
    run_start = ((step - 1) // interval) * interval
    evaluated = ((run_start + interval) // every > run_start // every) | (step > step.max() - interval)
    on, off = thermo[evaluated & (step > 0)], thermo[~evaluated & (step > 0)]
    assert len(on) >= 3 and len(off) >= 3 * len(on) // 2
    assert step[(step > 0) & (step % every == 0)].isin(on["step"]).all()  # every multiple is on
    # A bed: contacts overlap (at step 0 the particles are placed apart: LIGGGHTS' max of none).
    assert (on["overlap_max"] > 0.0).all()
    assert off["overlap_max"].isna().all()


@pytest.mark.timeout(600)
def test_interrupted_coupled_run_resumes_with_its_heat_log(tmp_path: Path) -> None:
    from drumflow.errors import SolverTimeoutError
    from drumflow.pipeline import run_case
    from drumflow.verify.scenes import tiny_drum

    # A hot and a cold half (not a uniform bed): the heat log and the enthalpy must still close
    # across the resume when every particle's heat differs (tests/solver/test_coupled_resume.py
    # compares a resumed CFD-air run with an uninterrupted one).
    case = tiny_drum(air__model="uniform", air__mass_flow=0.1, run__time=2.0, run__restart_interval=0.1,
                     particles__initial_temperature_spread_C=20.0)
    out = tmp_path / "run"
    with pytest.raises(SolverTimeoutError):
        run_case(case, out, timeout=7)
    summary = run_case(case, out, timeout=300)
    dem = json.loads((out / "stages" / "dem.json").read_text())["result"]
    assert dem["resumed_from_step"]
    # Two attempts logged heat; stitched, the bookkeeping still closes (a row lost or
    # counted twice at the resume would show at 1e-3 or more).
    assert len(list((out / "dem" / "coupling").glob("rank0.*.csv"))) == 2
    assert summary["energy_balance_error"] < 1e-6
    assert summary["particles_final"] == 500


@pytest.mark.timeout(600)
def test_conduction_off_loop_integrates_temperatures_across_a_resume(tmp_path: Path) -> None:
    """run.conduction = false leaves LIGGGHTS' heat fix out and the coupling loop integrates each
    particle's temperature: on 2 ranks (particles migrate between them) and across an
    interrupt, the heat the loop logged must still equal the enthalpy LIGGGHTS' temperatures
    lost, and the per-atom temperatures must come back from the restart."""
    from drumflow.errors import SolverTimeoutError
    from drumflow.pipeline import run_case
    from drumflow.verify.scenes import tiny_drum

    case = tiny_drum(air__model="uniform", air__mass_flow=0.1, run__time=2.0, run__restart_interval=0.1,
                     run__conduction=False, run__processes=2,
                     particles__initial_temperature_spread_C=20.0)
    out = tmp_path / "run"
    with pytest.raises(SolverTimeoutError):
        run_case(case, out, timeout=9)
    summary = run_case(case, out, timeout=300)
    deck = (out / "dem" / "in.drum").read_text()
    assert not re.search(r"^fix \S+ all heat/gran", deck, flags=re.M)
    assert re.search(r"^fix Temp all property/atom Temp ", deck, flags=re.M)
    assert json.loads((out / "stages" / "dem.json").read_text())["result"]["resumed_from_step"]
    # The first thermo row of the series is the state before any heat (regression: the row a
    # coupled `run` prints at its start comes after the loop's update and used to win): the
    # deck sets x <= 0 to 100 C and the rest to 80 C, equal particles.
    data = (out / "dem" / "particles.data").read_text().split("Atoms")[1].split()
    x = [float(v) for v in data[4::7]]
    expected = 80.0 + 20.0 * sum(v <= 0.0 for v in x) / len(x)
    assert len(x) == 500
    assert summary["mean_temperature_initial_C"] == pytest.approx(expected, abs=1e-6)
    assert summary["mean_temperature_C"] < 90.0 - 0.1
    # A temperature reset at the resume, a heat row applied twice or not at all, or an update
    # lost by a particle that changed rank would each show at 1e-3 or more.
    assert summary["energy_balance_error"] < 1e-6
    assert summary["particles_final"] == 500
