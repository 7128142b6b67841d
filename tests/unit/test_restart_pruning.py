"""Restart files: a long run keeps only the newest two (drumflow.dem.stage.prune_restarts), a
finished one its end state.
The solver side (a 20-restart run left with two, and resumed) is in
tests/solver/test_liggghts_drum.py::test_interrupted_run_resumes."""

from __future__ import annotations

from pathlib import Path

from drumflow.dem.stage import latest_restart, prune_restarts


def _touch(folder: Path, *names: str) -> None:
    for name in names:
        (folder / name).write_bytes(b"x")


def test_keeps_the_newest_by_step_number_not_by_name(tmp_path: Path) -> None:
    # Lexical order would keep 9996 over 11662 and 13328.
    _touch(tmp_path, "drum.9996.restart", "drum.11662.restart", "drum.13328.restart",
           "drum.1666.restart", "final.restart", "notes.txt")
    removed = prune_restarts(tmp_path)
    assert sorted(p.name for p in removed) == ["drum.1666.restart", "drum.9996.restart"]
    left = sorted(p.name for p in tmp_path.iterdir())
    assert left == ["drum.11662.restart", "drum.13328.restart", "final.restart", "notes.txt"]
    latest = latest_restart(tmp_path)
    assert latest is not None and latest[1] == 13328


def test_nothing_to_remove_with_two_or_fewer(tmp_path: Path) -> None:
    _touch(tmp_path, "drum.10.restart", "drum.20.restart")
    assert prune_restarts(tmp_path) == []
    assert prune_restarts(tmp_path, keep=1) == [tmp_path / "drum.10.restart"]
    assert [p.name for p in tmp_path.iterdir()] == ["drum.20.restart"]
