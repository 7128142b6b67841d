"""The section animation's frame rate and frame choice (no solver; the GIF itself is checked on a
real run in tests/solver/test_export.py)."""

from __future__ import annotations

import pytest

from drumflow.report.animation import MAX_FPS, _pick, frame_rate


def test_frame_rate_plays_the_snapshots_in_real_time() -> None:
    # Snapshots every 0.5 s in real time: 2 frames a second; twice as slow: 1 frame a second.
    times = [0.5 * k for k in range(10)]
    assert frame_rate(times) == 2
    assert frame_rate(times, 2.0) == 1
    # Snapshot times are whole steps: 0.1008 s apart still plays at 10 frames a second.
    assert frame_rate([0.1008 * k for k in range(5)]) == 10


def test_frame_rate_is_bounded() -> None:
    dense = [0.001 * k for k in range(10)]  # 1000 snapshots a simulated second
    assert frame_rate(dense) == MAX_FPS
    sparse = [10.0 * k for k in range(3)]
    assert frame_rate(sparse) == 1.0
    assert frame_rate([0.0]) == 1.0


def test_frame_rate_refuses_a_non_positive_speed() -> None:
    with pytest.raises(ValueError, match="seconds_per_simulated_second"):
        frame_rate([0.0, 1.0], 0.0)


def test_frames_are_spread_over_the_snapshots_first_and_last_kept() -> None:
    assert _pick(5, 10) == [0, 1, 2, 3, 4]
    picked = _pick(101, 11)
    assert picked[0] == 0 and picked[-1] == 100 and len(picked) == 11
    assert picked == list(range(0, 101, 10))
