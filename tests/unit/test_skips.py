"""Shortcuts recorded with their measured speed-up and error (drumflow.skips), and the
'auto' process count."""

from __future__ import annotations

import pytest

from drumflow import skips as skips_module
from drumflow.case import PARTICLES_PER_PROCESS
from drumflow.runner import LaunchProfile
from drumflow.skips import skips
from drumflow.verify.scenes import tiny_drum


def test_default_run_lists_its_shortcuts() -> None:
    case = tiny_drum(air__model="uniform")
    found = {s["skip"].split(" ")[0] for s in skips(case, "auto", True, "static_shell", 1)}
    # static shell, auto time step, auto coupling interval, serial run, uniform air
    assert {"static", "time", "air", "serial", "uniform"} <= found


def test_skips_carry_measured_numbers_when_shipped() -> None:
    if not skips_module.MEASURED.is_file():
        pytest.skip("no shipped bench results")
    entry = skips(tiny_drum(), "contact", False, "static_shell", 1)[1]
    assert entry["skip"].startswith("time step 'contact'")
    assert entry["measured"] is True
    assert entry["speedup"] > 1.0
    assert set(entry["errors_against_reference"]) == {"temperature", "h", "mass_flow"}
    # Each rule its own rung: 'auto' is the bench's default, 'contact' its contact rung (the
    # shipped bench has both since 2026-11-25), so their speed-ups differ.
    auto = skips(tiny_drum(), "auto", False, "static_shell", 1)[1]
    assert auto["skip"].startswith("time step 'auto'") and auto["measured"] is True
    assert auto["rungs"] == ["default", "dt_10pct"] and entry["rungs"] == ["contact", "dt_10pct"]
    assert entry["speedup"] > auto["speedup"]
    dashpot = [e for e in skips(tiny_drum(contacts__tangential_damping=False), "auto", False,
                                "static_shell", 1) if "tangential dashpot" in e["skip"]]
    assert len(dashpot) == 1 and dashpot[0]["measured"] is True


def test_nothing_listed_that_the_run_does_not_do() -> None:
    case = tiny_drum(run__processes=2)
    found = [s["skip"] for s in skips(case, "fixed", False, "moving_mesh", 2)]
    assert found == []


def test_auto_processes_stay_serial_for_small_beds() -> None:
    # The case only says how many particles a process should hold; the core count comes from
    # the launch profile, so the choice is checked here for two machines.
    assert tiny_drum().processes(cores=8) == 1
    assert tiny_drum(run__processes=3).processes(cores=1) == 3
    # A bed of many particles per process: one process per PARTICLES_PER_PROCESS, capped by
    # the cores.
    big = tiny_drum(drum__diameter=1.0, drum__length=0.5, particles__count=4 * PARTICLES_PER_PROCESS)
    assert big.processes(cores=8) == 4
    assert big.processes(cores=2) == 2
    assert LaunchProfile(cores=3).processes_for(big) == 3
