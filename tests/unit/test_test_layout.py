"""The test tree itself: pytest imports test modules by basename (no packages), so two test files
with one name in different folders stop the whole run at collection."""

from __future__ import annotations

from collections import Counter
from pathlib import Path


def test_no_two_test_files_share_a_name() -> None:
    # Regression: tests/unit/test_profile.py beside tests/solver/test_profile.py failed CI at
    # collection ("import file mismatch") although each passed when run on its own.
    root = Path(__file__).resolve().parents[1]
    names = Counter(p.name for p in root.rglob("test_*.py"))
    assert [name for name, n in names.items() if n > 1] == []
