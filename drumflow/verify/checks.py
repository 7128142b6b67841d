"""A verification check's result: what was measured, against what, within which tolerance.

Every check says what it is compared with (``kind``):

* ``reference``: an independent reference that a wrong implementation would miss (an
  analytic solution, a published table or correlation, another library, a conservation law
  the solver does not enforce by construction);
* ``bookkeeping``: the same quantity reached by two routes through drumflow's own data (heat
  logged by the coupling loop against the enthalpy LIGGGHTS integrated from that same heat,
  mass flow in against out of a finite-volume solution, a held particle's cooling every N
  steps against the explicit hold formed from drumflow's own h). These close to round-off by
  construction: they catch broken plumbing (a lost log row, a wrong unit), not wrong physics,
  so their tolerances sit near round-off and :func:`summary` counts them apart.
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from dataclasses import asdict, dataclass, field
from typing import Any, Literal

CheckKind = Literal["reference", "bookkeeping"]


@dataclass
class Check:
    """One verification result (a row of ``verification.json``).

    Raises
    ------
    ValueError
        For a tolerance that is not a finite non-negative number (a check that cannot fail)
        or an unknown ``kind``.
    """

    name: str
    measured: float
    expected: float
    error: float
    tolerance: float
    unit: str = ""
    note: str = ""
    wall_time_s: float = 0.0
    details: dict[str, Any] = field(default_factory=dict)
    kind: CheckKind = "reference"
    reference: str = ""  # where the expected value comes from (table, paper, library)

    def __post_init__(self) -> None:
        if not (math.isfinite(self.tolerance) and self.tolerance >= 0):
            raise ValueError(
                f"check {self.name}: tolerance = {self.tolerance}: a check must be "
                "able to fail; allowed: a finite number >= 0"
            )
        if self.kind not in ("reference", "bookkeeping"):
            raise ValueError(f"check {self.name}: kind = {self.kind!r}; allowed: 'reference', 'bookkeeping'")

    @property
    def passed(self) -> bool:
        # NaN compares false: a check that produced no number fails.
        return bool(self.error <= self.tolerance)

    def as_dict(self) -> dict[str, Any]:
        data = asdict(self)
        data["passed"] = self.passed
        return data


def summary(checks: Iterable[Check]) -> dict[str, Any]:
    """Counts of passed and failed checks, independent references apart from bookkeeping."""
    every = list(checks)
    out: dict[str, Any] = {}
    for kind in ("reference", "bookkeeping"):
        chosen = [c for c in every if c.kind == kind]
        out[kind] = {
            "checks": len(chosen),
            "passed": sum(c.passed for c in chosen),
            "failed": [c.name for c in chosen if not c.passed],
        }
    return out
