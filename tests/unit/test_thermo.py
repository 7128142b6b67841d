"""Thermo series across an interrupted and resumed run (regression: an off-grid row survived)."""

from __future__ import annotations

import math
from pathlib import Path

from drumflow.dem.thermo import read_thermo

HEADER = "Step v_sim_time Atoms KinEng c_ke_rot v_T_mean CPU \n"


def _log(path: Path, steps: list[int], T: float) -> None:
    rows = "".join(f"{s} {s * 1e-3} 500 0.1 0.01 {T} 1.0 \n" for s in steps)
    path.write_text("LIGGGHTS (Version LIGGGHTS-PUBLIC 3.8.0)\n" + HEADER + rows + "Loop time of 1\n")


def test_resumed_attempt_supersedes_the_interrupted_one(tmp_path: Path) -> None:
    # First attempt: output every 10 steps, killed at step 42 (LIGGGHTS prints that step).
    _log(tmp_path / "log.liggghts", [0, 10, 20, 30, 40, 42], 90.0)
    # Resumed from the restart at step 30; ends with the repeated last step of `run 0`.
    _log(tmp_path / "log.resume-30.liggghts", [30, 40, 50, 60, 60], 80.0)
    table = read_thermo(tmp_path)
    assert table["step"].tolist() == [0, 10, 20, 30, 40, 50, 60]
    assert table["T_mean"].tolist() == [90.0, 90.0, 90.0, 80.0, 80.0, 80.0, 80.0]


def test_no_logs_gives_empty_table(tmp_path: Path) -> None:
    assert read_thermo(tmp_path).empty


def test_a_step_printed_twice_in_one_attempt_keeps_its_first_row(tmp_path: Path) -> None:
    """Regression: each coupled `run` prints its first step again, after the loop's update; when
    the loop integrates the temperatures (run.conduction = false) that row already holds the
    next interval's heat, and keeping it put the series one interval ahead (the smoke drum's
    energy balance was off by 0.3 %)."""
    row = "{} {} 500 0.1 0.01 {} 1.0 \n"
    first_run = HEADER + row.format(0, 0.0, 90.0) + row.format(10, 0.01, 89.0) + "Loop time of 1\n"
    # The second run starts at 89.0 at step 10 but prints 88.0 there, after the update.
    second_run = HEADER + row.format(10, 0.01, 88.0) + row.format(20, 0.02, 87.0) + "Loop time of 1\n"
    banner = "LIGGGHTS (Version LIGGGHTS-PUBLIC 3.8.0)\n"
    (tmp_path / "log.liggghts").write_text(banner + first_run + second_run)
    table = read_thermo(tmp_path)
    assert table["step"].tolist() == [0, 10, 20]
    assert table["T_mean"].tolist() == [90.0, 89.0, 87.0]


def test_rows_without_the_overlap_read_nan(tmp_path: Path) -> None:
    """The coupling loop leaves the overlap column out of most rows (-1, `overlap_every`): those
    read NaN, the evaluated rows their overlap."""
    from drumflow.coupling.spec import OVERLAP_NOT_EVALUATED

    header = "Step v_sim_time Atoms KinEng c_ke_rot v_T_mean v_overlap CPU \n"
    overlaps = {0: 1e-4, 10: OVERLAP_NOT_EVALUATED, 20: 2e-4}
    rows = "".join(f"{s} {s * 1e-3} 500 0.1 0.01 90.0 {o:g} 1.0 \n" for s, o in overlaps.items())
    (tmp_path / "log.liggghts").write_text("LIGGGHTS (Version LIGGGHTS-PUBLIC 3.8.0)\n" + header
                                           + rows + "Loop time of 1\n")
    table = read_thermo(tmp_path)
    assert table["overlap_max"].iloc[[0, 2]].tolist() == [1e-4, 2e-4]
    assert math.isnan(table["overlap_max"].iloc[1])
