"""A verification check's result: what was measured, against what, within which tolerance."""

from __future__ import annotations

from dataclasses import asdict, dataclass, field
from typing import Any


@dataclass
class Check:
    """One verification result (a row of ``verification.json``)."""

    name: str
    measured: float
    expected: float
    error: float
    tolerance: float
    unit: str = ""
    note: str = ""
    wall_time_s: float = 0.0
    details: dict[str, Any] = field(default_factory=dict)

    @property
    def passed(self) -> bool:
        return bool(self.error <= self.tolerance)

    def as_dict(self) -> dict[str, Any]:
        data = asdict(self)
        data["passed"] = self.passed
        return data


def relative_error(measured: float, expected: float) -> float:
    return abs(measured - expected) / abs(expected) if expected else abs(measured)
