"""The fast profile (``drumflow run --fast``, drumflow.case.fast_profile): what it changes, that
the changed case is a case of its own (name and hash, so its own run directory), and that
``drumflow check --fast`` shows the step it gives. Its answers are measured, not tested here:
docs/benchmarks.md, 'The fast profile'."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

from drumflow.case import FAST_PROFILE, Case, fast_profile, load_case
from drumflow.dem.timestep import choose_time_step

CASES = Path(__file__).resolve().parents[2] / "cases"


def test_the_profile_sets_its_fields_and_names_the_case() -> None:
    case = load_case(CASES / "paper_model_two.toml")
    fast, changed = fast_profile(case)
    for section, name, value in FAST_PROFILE:
        assert getattr(getattr(fast, section), name) == value
    assert len(changed) == len(FAST_PROFILE)
    assert "contacts.tangential_damping: true -> false" in changed
    assert fast.name == f"{case.name}_fast" and fast.hash() != case.hash()
    # The step it buys: the contact step, about twice the damped bed's "auto".
    assert choose_time_step(fast).time_step > 1.9 * choose_time_step(case).time_step
    # Applied twice: nothing more to change, the same case.
    again, nothing = fast_profile(fast)
    assert nothing == [] and again.hash() == fast.hash()


def test_without_air_the_stop_stays_fixed() -> None:
    """The converged stop watches the air's h: a case without air keeps its fixed time (the
    case would otherwise be refused by its own validation)."""
    data = load_case(CASES / "smoke.toml").model_dump(mode="json")
    data["air"]["model"] = "none"
    data["run"]["stop"] = "fixed"
    fast, changed = fast_profile(Case.model_validate(data))
    assert fast.run.stop == "fixed" and not any(c.startswith("run.stop") for c in changed)
    assert fast.contacts.tangential_damping is False


def test_check_fast_prints_what_it_changed_and_the_step() -> None:
    done = subprocess.run(
        [sys.executable, "-m", "drumflow.cli", "check", str(CASES / "paper_model_one.toml"), "--fast"],
        capture_output=True, text=True, timeout=120, env={"COLUMNS": "240", "PATH": "/usr/bin:/bin"},
    )
    assert done.returncode == 0, done.stderr
    assert "fast profile, as case paper_model_one_fast" in done.stderr
    assert "tangential_damping: true -> false" in done.stderr
    assert "the tangential spring's own" in done.stdout
    assert "set by the fastest contact" in done.stdout
