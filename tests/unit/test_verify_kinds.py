"""How `drumflow verify` counts its checks (drumflow.verify.checks): the coupling-interval
checks are bookkeeping, not independent references, because their expected drop is formed with
drumflow's own h and its own update scheme (issue 36). No solver: the one-particle cooling run
is replaced by the exact held result it is checked against."""

from __future__ import annotations

import math
from pathlib import Path

import pytest

from drumflow.physics.particle_air import AirState, ranz_marshall_h
from drumflow.verify import single_particle as sp
from drumflow.verify.checks import summary


def _held_cooling(work: Path, runner: object, speed: float, interval: int, dt: float = 0.01
                  ) -> tuple[float, int]:
    """What the coupling loop gives when it is right: the exact explicit hold."""
    steps = math.ceil(sp.time_constant(speed) / dt)
    h = float(ranz_marshall_h(speed, sp.DIAMETER, AirState.at(sp.T_AIR, sp.PRESSURE_KPA)))
    return sp.T0 - sp.held_drop(sp.T0, h, interval, steps, dt), steps


def test_the_coupling_interval_checks_count_as_bookkeeping(tmp_path: Path, monkeypatch: pytest.MonkeyPatch
                                                           ) -> None:
    monkeypatch.setattr(sp, "_cooling_run", _held_cooling)
    checks = sp.coupling_interval_sweep(tmp_path, None)  # type: ignore[arg-type]
    kinds = {c.name: c.kind for c in checks}
    held = [n for n in kinds if n.startswith("coupling_interval_") and n.endswith("_steps")]
    # N = 10, 100, 1,000 and the 'auto' choice (which may coincide with one of them).
    assert {"coupling_interval_10_steps", "coupling_interval_100_steps",
            "coupling_interval_1000_steps"} <= set(held)
    assert all(kinds[n] == "bookkeeping" for n in held), kinds
    # The 'auto' interval against the continuous lumped solution: an analytic reference.
    assert kinds["coupling_interval_auto_error"] == "reference"
    assert all(c.passed for c in checks), [c.as_dict() for c in checks if not c.passed]
    counted = summary(checks)
    assert counted["bookkeeping"]["checks"] == len(held)
    assert counted["reference"]["checks"] == 1
