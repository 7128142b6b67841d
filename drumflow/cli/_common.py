"""Small pieces several command groups share: reading a case file, writing a span of time."""

from __future__ import annotations

from pathlib import Path
from typing import Any

__all__ = ["clock", "load_case_file", "records", "rough_duration"]


def load_case_file(case_file: Path) -> Any:
    """The validated case of a case file (imported when a command runs: start-up stays light)."""
    from drumflow.case import load_case

    return load_case(case_file)


def clock(seconds: float | None) -> str:
    """``H:MM:SS`` (a run's elapsed time, ETA, a log's idle time); "–" when not known."""
    if seconds is None:
        return "–"
    whole = max(0, round(seconds))
    return f"{whole // 3600}:{whole // 60 % 60:02d}:{whole % 60:02d}"


def rough_duration(seconds: float | None) -> str:
    """Seconds, minutes or hours with one decimal (a sweep member's ETA); "–" when not known."""
    if seconds is None:
        return "–"
    seconds = max(0.0, seconds)
    if seconds < 90:
        return f"{seconds:.0f} s"
    if seconds < 5400:
        return f"{seconds / 60:.1f} min"
    return f"{seconds / 3600:.1f} h"


def records(frame: Any) -> list[dict[str, Any]]:
    """A results table (pandas) as JSON-ready rows: NaN as null, numbers as plain floats."""
    import json

    rows: list[dict[str, Any]] = json.loads(frame.to_json(orient="records"))
    return rows
