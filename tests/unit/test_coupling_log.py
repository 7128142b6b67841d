"""The coupling loop's per-rank logs read back: old logs without wall times and new ones with them."""

from __future__ import annotations

import math
from pathlib import Path

import pytest

from drumflow.coupling.log import WALL_COLUMNS, read_coupling

OLD_HEADER = "step,time_s,steps,heat_to_particles_W,drag_x_N,drag_y_N,drag_z_N,particles,mean_slip_m_s\n"
NEW_HEADER = OLD_HEADER.rstrip("\n") + ",python_wall_s,liggghts_wall_s\n"
DT = 1e-4


def _row(step: int, heat: float, particles: int) -> str:
    return f"{step},{step * DT},100,{heat},0.1,0,-0.2,{particles},2.5"


def test_old_logs_read_as_before_without_wall_columns(tmp_path: Path) -> None:
    (tmp_path / "rank0.0.csv").write_text(OLD_HEADER + _row(0, -2.0, 3) + "\n" + _row(100, -1.0, 3) + "\n")
    (tmp_path / "rank1.0.csv").write_text(OLD_HEADER + _row(0, -4.0, 2) + "\n" + _row(100, -3.0, 2) + "\n")
    table = read_coupling(tmp_path, DT)
    assert list(table.columns) == ["step", "time_s", "steps", "heat_to_particles_W", "drag_x_N", "drag_y_N",
                                   "drag_z_N", "particles", "heat_removed_J"]
    assert table["heat_to_particles_W"].tolist() == [-6.0, -4.0]
    assert table["particles"].tolist() == [5, 5]
    assert table["heat_removed_J"].iloc[-1] == pytest.approx((6.0 + 4.0) * 100 * DT)


def test_new_logs_carry_the_slowest_rank_wall_times_last(tmp_path: Path) -> None:
    # Rank 0 is slower in Python at step 0, rank 1 in LIGGGHTS; the last row of each rank was cut
    # by an interrupt during LIGGGHTS' run (no newline, no LIGGGHTS time).
    (tmp_path / "rank0.0.csv").write_text(
        NEW_HEADER + _row(0, -2.0, 3) + ",0.5,1.0\n" + _row(100, -1.0, 3) + ",0.25")
    (tmp_path / "rank1.0.csv").write_text(
        NEW_HEADER + _row(0, -4.0, 2) + ",0.1,2.0\n" + _row(100, -3.0, 2) + ",0.75")
    table = read_coupling(tmp_path, DT)
    assert list(table.columns[-2:]) == list(WALL_COLUMNS)
    assert table["heat_to_particles_W"].tolist() == [-6.0, -4.0]
    assert table["python_wall_s"].tolist() == [0.5, 0.75]
    assert table["liggghts_wall_s"].iloc[0] == 2.0
    assert math.isnan(table["liggghts_wall_s"].iloc[1])


def test_a_resume_with_wall_times_after_an_old_attempt(tmp_path: Path) -> None:
    # The old attempt logged steps 0-200 before it was killed; the resume from step 100 has
    # wall times and supersedes its rows from step 100 on.
    (tmp_path / "rank0.0.csv").write_text(
        OLD_HEADER + "".join(_row(s, -1.0, 5) + "\n" for s in (0, 100, 200)))
    (tmp_path / "rank0.100.csv").write_text(
        NEW_HEADER + "".join(_row(s, -2.0, 5) + ",0.1,0.9\n" for s in (100, 200)))
    table = read_coupling(tmp_path, DT)
    assert table["step"].tolist() == [0, 100, 200]
    assert table["heat_to_particles_W"].tolist() == [-1.0, -2.0, -2.0]
    assert math.isnan(table["python_wall_s"].iloc[0])
    assert table["liggghts_wall_s"].iloc[1:].tolist() == [0.9, 0.9]


def test_heat_counts_only_up_to_the_last_temperature_output() -> None:
    # Regression: post on an interrupted paper run (model two stopped at 3.52 s) found a 0.28 %
    # energy-balance error, one coupling update's heat (10.5 kJ of 3.68 MJ): the loop logs an
    # update before LIGGGHTS runs it, so the last update of a stopped run was never applied.
    import pandas as pd

    from drumflow.coupling.log import heat_removed_until

    dt = 1e-3
    log = pd.DataFrame({"time_s": [0.0, 0.01, 0.02], "steps": [10, 10, 10],
                        "heat_to_particles_W": [-100.0, -200.0, -400.0]})
    # A finished run: every update held for its 10 steps.
    assert heat_removed_until(log, 0.03, dt) == pytest.approx(100 * 0.01 + 200 * 0.01 + 400 * 0.01)
    # Stopped at the third update's start: its heat was never applied.
    assert heat_removed_until(log, 0.02, dt) == pytest.approx(100 * 0.01 + 200 * 0.01)
    # Half-way through the second update.
    assert heat_removed_until(log, 0.015, dt) == pytest.approx(100 * 0.01 + 200 * 0.005)


def test_coupled_wall_counts_every_attempt_and_estimates_pauses(tmp_path: Path) -> None:
    from drumflow.coupling.log import PAUSED_FACTOR, coupled_wall_s

    # An old attempt without wall times (2 updates), then a resumed one: 8 updates of 2 s, one of
    # them stopped from outside for an hour. Every update moves the same particle-steps, so the
    # three not measured (2 unlogged, 1 paused) count 2 s each: 7 x 2 + 3 x 2 = 20 s.
    (tmp_path / "rank0.0.csv").write_text(OLD_HEADER + _row(0, -1.0, 5) + "\n" + _row(100, -1.0, 5) + "\n")
    walls = [2.0] * 8
    walls[3] = 3600.0
    rows = [f"{_row(200 + 100 * k, -1.0, 5)},{w - 0.5},0.5" for k, w in enumerate(walls)]
    (tmp_path / "rank0.200.csv").write_text(NEW_HEADER + "\n".join(rows) + "\n")
    assert 3600.0 > PAUSED_FACTOR * 2.0
    wall = coupled_wall_s(read_coupling(tmp_path, DT))
    assert wall is not None
    assert wall["wall_s"] == pytest.approx(20.0)
    assert wall["measured_s"] == pytest.approx(14.0) and wall["estimated_s"] == pytest.approx(6.0)
    assert wall["paused_updates"] == 1 and wall["unlogged_updates"] == 2
    assert wall["particle_steps_per_s"] == pytest.approx(5 * 100 / 2.0)
    # Old logs alone: nothing measured, so no wall time (not a guess).
    (tmp_path / "rank0.200.csv").unlink()
    assert coupled_wall_s(read_coupling(tmp_path, DT)) is None
