"""Shortcuts recorded with their measured speed-up and error (drumflow.bench.skips), and the
'auto' process count."""

from __future__ import annotations

import pytest

from drumflow.bench import skips as skips_module
from drumflow.bench.skips import skips
from drumflow.case import PARTICLES_PER_PROCESS
from drumflow.verify.scenes import tiny_drum


def test_default_run_lists_its_shortcuts() -> None:
    case = tiny_drum(air__model="uniform")
    found = {s["skip"].split(" ")[0] for s in skips(case, "auto", True, "static_shell")}
    # static shell, auto time step, auto coupling interval, serial run, uniform air
    assert {"static", "time", "air", "serial", "uniform"} <= found


def test_skips_carry_measured_numbers_when_shipped() -> None:
    if not skips_module.MEASURED.exists():
        pytest.skip("no shipped bench results")
    entry = skips(tiny_drum(), "auto", False, "static_shell")[0]
    assert entry["measured"] is True
    assert entry["speedup"] > 1.0
    assert set(entry["errors_against_reference"]) == {"temperature", "h", "mass_flow"}


def test_nothing_listed_that_the_run_does_not_do() -> None:
    case = tiny_drum(run__processes=2)
    found = [s["skip"] for s in skips(case, "fixed", False, "moving_mesh")]
    assert found == []


def test_auto_processes_stay_serial_for_small_beds() -> None:
    assert tiny_drum().process_count == 1
    assert tiny_drum(run__processes=3).process_count == 3
    # A bed of many particles per process: more than one process where cores allow.
    import os

    big = tiny_drum(drum__diameter=1.0, drum__length=0.5, particles__count=4 * PARTICLES_PER_PROCESS)
    assert big.process_count == min(os.cpu_count() or 1, 4)
