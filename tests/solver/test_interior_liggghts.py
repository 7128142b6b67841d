"""Heat inside the granule (``particles.interior = "shells"``) through the real coupling loop.

One granule held in air against the exact series solution at Biot 0.1, 1 and 3 (the check of
``drumflow verify``), the same check failing when the loop's conductivity is 10 % off, and the
tiny drum at the shells level on 2 ranks across an interrupt: energy closed, the profiles kept
by the restart, and the surface cooler than the centre.
"""

from __future__ import annotations

import json
import tomllib
from pathlib import Path

import pandas as pd
import pytest
from support.solvers import CASES, LIGGGHTS, OPENFOAM, requires_solver

from drumflow.runner import Runner
from drumflow.verify.interior import BIOTS, TOLERANCE, interior_series_check

pytestmark = [pytest.mark.solver, requires_solver(*LIGGGHTS)]


@pytest.mark.timeout(300)
@pytest.mark.parametrize("biot", BIOTS)
def test_held_granule_matches_the_series_solution(tmp_path: Path, biot: float) -> None:
    check = interior_series_check(tmp_path, Runner(), biot)
    assert check.passed, check
    # The shells carry a real gradient where Bi is not small (the lumped particle has none).
    if biot >= 1.0:
        assert check.details["centre_minus_surface_K"] > 5.0


@pytest.mark.timeout(300)
@pytest.mark.parametrize("biot", [b for b in BIOTS if b >= 1.0])
@pytest.mark.parametrize("factor", [0.9, 1.1])
def test_the_check_fails_when_the_conductivity_is_10_percent_off(tmp_path: Path, biot: float,
                                                                  factor: float) -> None:
    # At Bi 0.1 the granule is nearly lumped: its conductivity hardly matters, by physics.
    check = interior_series_check(tmp_path, Runner(), biot, loop_conductivity_factor=factor)
    assert not check.passed, check
    assert check.error > TOLERANCE


def _bed_mean(logs: list[Path], column: str) -> pd.Series:
    """Particle-weighted mean over the ranks' interior logs of one attempt, by step."""
    table = pd.concat([pd.read_csv(p) for p in logs])
    table["weighted"] = table[column] * table["particles"]
    grouped = table.groupby("step")
    return grouped["weighted"].sum() / grouped["particles"].sum()


@pytest.mark.timeout(900)
def test_tiny_drum_with_shells_resumes_with_its_profiles_and_closes_energy(tmp_path: Path) -> None:
    from drumflow.errors import SolverTimeoutError
    from drumflow.pipeline import run_case
    from drumflow.verify.scenes import tiny_drum

    # 2 s of the tiny drum take about 36 s here when the machine is idle: the 12 s limit
    # interrupts it a third of the way, and a machine 4 times as busy still passes three of the
    # restarts every 0.05 s (regression: 1 s with a 40 s limit finished before the limit, idle).
    case = tiny_drum(air__model="uniform", air__mass_flow=0.1, run__time=2.0,
                     run__restart_interval=0.05, run__processes=2, particles__interior="shells")
    out = tmp_path / "run"
    with pytest.raises(SolverTimeoutError):
        run_case(case, out, timeout=12)
    summary = run_case(case, out, timeout=600)
    assert json.loads((out / "stages" / "dem.json").read_text())["result"]["resumed_from_step"]
    assert summary["energy_balance_error"] < 1e-6
    assert summary["particles_final"] == 500
    coupling = out / "dem" / "coupling"
    spec = json.loads((out / "dem" / "coupling.json").read_text())
    assert spec["interior"]["shells"] >= 3
    starts = sorted({int(p.name.split(".")[1]) for p in coupling.glob("interior_rank*.csv")})
    assert len(starts) == 2, starts
    first = _bed_mean(sorted(coupling.glob(f"interior_rank*.{starts[0]}.csv")), "mean_centre_C")
    again = _bed_mean(sorted(coupling.glob(f"interior_rank*.{starts[1]}.csv")), "mean_centre_C")
    mean = _bed_mean(sorted(coupling.glob(f"interior_rank*.{starts[0]}.csv")), "mean_C")
    # The restart kept the profiles: the centre goes on from where it was, one interval later.
    # A profile reset to uniform at the mean would drop the centre by its lead over the mean.
    lead = float(first.iloc[-1] - mean.iloc[-1])
    assert lead > 0.2
    assert abs(float(again.iloc[0] - first.iloc[-1])) < 0.25 * lead
    # Cooling from outside: the surface is cooler than the centre, everywhere in the bed.
    last = pd.concat([pd.read_csv(p) for p in coupling.glob(f"interior_rank*.{starts[1]}.csv")])
    assert (last["mean_surface_C"] < last["mean_centre_C"]).all()


@pytest.mark.timeout(900)
@requires_solver(*OPENFOAM)
@pytest.mark.parametrize("warming", [False, True], ids=["shells", "shells_warming"])
def test_smoke_case_with_cfd_air_at_the_shells_levels_closes_energy(tmp_path: Path, warming: bool) -> None:
    """The smoke case (CFD air) with heat inside the granule and air that warms, short: the heat
    the loop logged equals the enthalpy the particles lost and what the air carried out, the
    granules carry a gradient (Bi about 1.6 at 8 mm) and the air leaves warmer than it came."""
    from drumflow.case import case_from_dict
    from drumflow.pipeline import run_case

    data = tomllib.loads((CASES / "smoke.toml").read_text())
    data["particles"]["interior"] = "shells"
    data["air"]["mesh_size"] = 0.03
    data["air"]["warming"] = warming
    data["run"].update({"time": 0.6, "mass_flow_start": 0.2, "processes": 2})
    summary = run_case(case_from_dict(data), tmp_path / "run", timeout=800)
    assert summary["energy_balance_error"] < 1e-6
    assert summary["particles_final"] == 3000
    logs = list((tmp_path / "run" / "dem" / "coupling").glob("interior_rank*.csv"))
    table = pd.concat([pd.read_csv(p) for p in logs])
    assert table["max_biot"].max() > 1.0
    assert (table["mean_centre_C"] > table["mean_surface_C"]).all()
    if warming:
        assert summary["air_energy_balance_error"] < 1e-6
        assert summary["air_outlet_temperature_C"] > data["air"]["inlet_temperature_C"] + 0.1
    else:
        assert "air_energy_balance_error" not in summary
