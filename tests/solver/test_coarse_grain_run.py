"""Coarse-graining on the real solver: the tiny drum with parcels of 1.45 particle diameters
against the same drum with every particle, in the same plug-flow air.

With one-way air every particle sees the air, so the mean temperature follows the air's heat per
kilogram. Parcels keep it per kilogram by construction (drumflow.coupling.driver.air_load); what
they change is the bed's motion, hence each particle's slip (bed or flight), and the Ranz-Marshall
h varies about as the square root of the slip. Slip here is the air's 2.8 m/s against particle
speeds of a few tenths of a metre per second, so a bed moving differently moves the mean slip by
at most ~10 % and h by ~5 %: the tolerance on the cooling. Plain size scaling (larger spheres
without the scaled load) cools about 1.45**-1.5 = 0.57 times as fast (surface per kilogram 1/k,
h ~ d^-1/2), far outside it.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest
from support.solvers import LIGGGHTS, requires_solver

pytestmark = [pytest.mark.solver, pytest.mark.timeout(900), requires_solver(*LIGGGHTS)]

PARCEL = 1.45
#: Cooling of the parcels against every particle's (module docstring).
COOLING_TOLERANCE = 0.05


def _run(root: Path, name: str, **overrides: Any) -> dict[str, Any]:
    from drumflow.pipeline import run_case
    from drumflow.verify.scenes import tiny_drum

    case = tiny_drum(air__model="uniform", air__mass_flow=0.1, run__time=0.4, run__mass_flow_start=0.2,
                     run__processes=1, **overrides)
    return run_case(case, root / name, timeout=600)


@pytest.fixture(scope="module")
def runs(tmp_path_factory: pytest.TempPathFactory) -> dict[str, dict[str, Any]]:
    root = tmp_path_factory.mktemp("coarse")
    return {"particles": _run(root, "particles"),
            "parcels": _run(root, "parcels", particles__coarse_grain=PARCEL),
            "root": {"path": str(root)}}


def test_parcels_run_whole_and_close_the_energy_balance(runs: dict[str, dict[str, Any]]) -> None:
    parcels = runs["parcels"]
    assert parcels["status"] == "ok", parcels["status"]
    assert parcels["particles_initial"] == parcels["particles_final"] == round(500 / PARCEL**3)
    assert parcels["coarse_grain"] == PARCEL and "coarse_grain" not in runs["particles"]
    # The heat the loop gave the parcels is their enthalpy loss: k**3 scaling on both sides.
    assert parcels["energy_balance_error"] < 1e-6
    # The DEM moved parcels: its deck has their radius.
    data = (Path(runs["root"]["path"]) / "parcels" / "dem" / "particles.data").read_text()
    assert f"{0.5 * PARCEL * 0.008:g}" in data or f"{PARCEL * 0.008:g}" in data


def test_parcels_cool_as_the_particles(runs: dict[str, dict[str, Any]]) -> None:
    drop = {k: v["mean_temperature_initial_C"] - v["mean_temperature_C"]
            for k, v in runs.items() if k != "root"}
    # The air does cool them: lumped at the Ranz-Marshall h of the air speed (72 W/m2K at
    # 2.8 m/s for 8 mm) 2.1 K/s, 0.85 K in 0.4 s.
    assert 0.6 < drop["particles"] < 1.1
    ratio = drop["parcels"] / drop["particles"]
    assert abs(ratio - 1.0) < COOLING_TOLERANCE, (drop, ratio)


def test_the_run_record_says_parcels(runs: dict[str, dict[str, Any]]) -> None:
    manifest = json.loads((Path(runs["root"]["path"]) / "parcels" / "manifest.json").read_text())
    assert manifest["case_hash"] == runs["parcels"]["case_hash"]
