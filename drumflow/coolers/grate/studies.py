"""Parameter studies of the grate cooler: one case, one field varied (the report's Figures
11-15), and the grid-convergence study.

A varied field is named by its dotted case path (``cooler.grate_speed``) or by a short alias
(``grate_speed``); every varied case is validated like a case file, so a value outside the
field's range is reported with the field's name and range before anything runs.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any, get_args

import numpy as np

from drumflow.coolers.grate.case import GrateCase, grate_case_from_dict
from drumflow.coolers.grate.model import solve_grate
from drumflow.coolers.grate.solution import GrateSolution
from drumflow.errors import CaseError

__all__ = [
    "ALIASES",
    "GridStudy",
    "Sweep",
    "case_with",
    "grid_study",
    "parse_vary",
    "resolve_field",
    "run_sweep",
    "vary_cases",
]

#: Short names of the fields most studies vary, and their case paths.
ALIASES: dict[str, str] = {
    "grate_speed": "cooler.grate_speed",
    "length": "cooler.length",
    "width": "cooler.width",
    "clinker_flow": "clinker.mass_flow",
    "clinker_inlet_temperature": "clinker.inlet_temperature",
    "particle_diameter": "clinker.particle_diameter",
    "bed_porosity": "clinker.bed_porosity",
    "emissivity": "clinker.emissivity",
    "air_flow": "air.mass_flow",
    "air_inlet_temperature": "air.inlet_temperature",
    "fan_pressure": "fan.shutoff_pressure",
    "fan_free_delivery": "fan.free_delivery",
}

_MAX_POINTS = 200

#: Most balance cells a --vary study may solve in all (the sum over its cases). A converged
#: solve costs about 9 sweeps at 0.65-2 us per cell and sweep here (2 shared cores), so
#: 10,000,000 cells take about a minute: the report's 120 x 90 grid at the 200 points --vary
#: allows (2,160,000 cells) passes; 200 points of a 1,000,000-cell grid (hours) do not.
MAX_STUDY_CELLS = 10_000_000


def resolve_field(name: str) -> str:
    """The case path of a field given by alias or dotted path.

    Raises
    ------
    CaseError
        If the name is neither an alias nor a ``section.field`` path of a numeric field.
    """
    path = ALIASES.get(name, name)
    allowed = ", ".join(sorted(ALIASES)) + ", or section.field of a numeric case field"
    parts = path.split(".")
    if len(parts) != 2 or parts[0] not in GrateCase.model_fields:
        raise CaseError([f"--vary {name!r}: unknown field; allowed: {allowed}"])
    section = GrateCase.model_fields[parts[0]].annotation
    # An optional section (fan: Fan | None) is varied through its model.
    section = next((t for t in get_args(section) if t is not type(None)), section)
    fields = getattr(section, "model_fields", {})
    numeric = (float, int, float | None)
    if parts[1] not in fields or fields[parts[1]].annotation not in numeric:
        raise CaseError([f"--vary {name!r}: unknown or non-numeric field; allowed: {allowed}"])
    return path


def parse_vary(text: str) -> tuple[str, list[float]]:
    """Parse ``FIELD=START:STOP:COUNT`` (evenly spaced, both ends included) or
    ``FIELD=V1,V2,...``.

    Raises
    ------
    CaseError
        Naming ``--vary``, the bad part and the allowed form.
    """
    form = "FIELD=START:STOP:COUNT (COUNT 2 to 200) or FIELD=V1,V2,..."
    name, sep, spec = text.partition("=")
    if not sep or not name.strip() or not spec.strip():
        raise CaseError([f"--vary {text!r}: expected {form}"])
    path = resolve_field(name.strip())
    count = 0
    try:
        if ":" in spec:
            start_s, stop_s, count_s = spec.split(":")
            start, stop, count = float(start_s), float(stop_s), int(count_s)
        else:
            values = [float(v) for v in spec.split(",")]
    except ValueError:
        raise CaseError([f"--vary {text!r}: expected {form}"]) from None
    if ":" in spec:
        values = [start, stop]
    if not all(math.isfinite(v) for v in values):
        # float() reads "inf" and "nan"; no field means them (and int(round(inf)) would crash).
        raise CaseError([f"--vary {text!r}: not a finite number; allowed: finite numbers"])
    if ":" in spec:
        if not 2 <= count <= _MAX_POINTS:
            raise CaseError([f"--vary {text!r}: COUNT = {count}; allowed: 2 to {_MAX_POINTS}"])
        # Rounded to 12 digits so 0.05:0.2:4 gives 0.15, not 0.15000000000000002.
        values = [float(f"{v:.12g}") for v in np.linspace(start, stop, count)]
    if not 1 <= len(values) <= _MAX_POINTS:
        raise CaseError([f"--vary {text!r}: {len(values)} values; allowed: 1 to {_MAX_POINTS}"])
    return path, values


def case_with(case: GrateCase, path: str, value: float) -> GrateCase:
    """A copy of the case with one field changed, validated again (``CaseError`` names the
    field and its range when the value is outside it)."""
    data: dict[str, Any] = case.model_dump(exclude_none=True)
    section, name = path.split(".")
    if section not in data:
        raise CaseError([f"--vary {path}: the case has no [{section}] section"])
    current = data[section].get(name)
    data[section][name] = int(round(value)) if isinstance(current, int) else value
    return grate_case_from_dict(data, f"{case.name} with {path} = {value:g}")


def vary_cases(case: GrateCase, path: str, values: Sequence[float]) -> list[GrateCase]:
    """The cases of a --vary study, each validated, and their total size bounded.

    Raises
    ------
    CaseError
        A varied value is outside its field's range, or the study would solve more than
        :data:`MAX_STUDY_CELLS` cells.
    """
    if path == "air.mass_flow" and case.air.supply == "fan":
        raise CaseError([f"--vary {path}: with air.supply = 'fan' the air flow is solved "
                         "(air.mass_flow is only its first guess); allowed: vary a fan.* "
                         "field, or air.supply = 'fixed'"])
    cases = [case_with(case, path, v) for v in values]
    cells = sum(c.numerics.cells_length * c.numerics.cells_height for c in cases)
    if cells > MAX_STUDY_CELLS:
        raise CaseError([f"--vary {path}: {len(cases)} values x the cases' cells "
                         f"(numerics.cells_length x numerics.cells_height) = {cells:,} cells; "
                         f"allowed up to {MAX_STUDY_CELLS:,} (fewer values or a coarser grid)"])
    return cases


@dataclass(frozen=True)
class Sweep:
    """Solutions of one case with one field varied."""

    field: str
    values: list[float]
    solutions: list[GrateSolution]

    def peak(self, column: str) -> tuple[float, float, bool]:
        """The varied value at the largest ``column`` of :meth:`rows`, that largest value, and
        whether it is inside the range (not at either end: an interior maximum)."""
        rows = self.rows()
        k = int(np.argmax([r[column] for r in rows]))
        return self.values[k], rows[k][column], 0 < k < len(rows) - 1

    def rows(self) -> list[dict[str, float]]:
        """One row per value: the headline numbers (the shipped study tables)."""
        out = []
        for value, sol in zip(self.values, self.solutions, strict=True):
            out.append({
                self.field: value,
                "clinker_outlet_K": sol.clinker_outlet_temperature,
                "secondary_air_K": sol.secondary_air_temperature,
                "heat_recovered_MW": sol.heat_recovered / 1e6,
                "efficiency": sol.efficiency,
                "radiation_MW": sol.radiation_heat / 1e6,
                "air_flow_kg_s": sol.air_flow,
                "bed_pressure_drop_Pa": sol.bed_pressure_drop,
                "bed_height_m": sol.bed_height,
                "residence_time_s": sol.case.cooler.length / sol.case.cooler.grate_speed,
                "sweeps": float(sol.sweeps),
                "wall_time_s": sol.wall_time_s,
            })
        return out


def run_sweep(case: GrateCase, path: str, values: Sequence[float],
              progress: Callable[[int, int], None] | None = None) -> Sweep:
    """Solve the case once per value of one field (all cases validated before the first
    solve)."""
    cases = vary_cases(case, path, values)
    solutions = []
    for k, c in enumerate(cases):
        solutions.append(solve_grate(c))
        if progress is not None:
            progress(k + 1, len(cases))
    return Sweep(path, list(values), solutions)


@dataclass(frozen=True)
class GridStudy:
    """Outlet temperatures of one case on refined grids, for both exchange forms."""

    rows: list[dict[str, Any]]


def grid_study(case: GrateCase, factors: Sequence[float] = (0.5, 1.0, 2.0),
               exchanges: Sequence[str] = ("mean", "outlet")) -> GridStudy:
    """Solve the case with its cell counts scaled by each factor (the report's grid is
    factor 1 for the shipped case) and tabulate the outlet temperatures."""
    rows: list[dict[str, Any]] = []
    for exchange in exchanges:
        for f in factors:
            num = case.numerics.model_copy(update={
                "cells_length": max(2, int(round(case.numerics.cells_length * f))),
                "cells_height": max(1, int(round(case.numerics.cells_height * f))),
                "exchange": exchange,
            })
            sol = solve_grate(case.model_copy(update={"numerics": num}))
            rows.append({
                "exchange": exchange,
                "cells_length": num.cells_length,
                "cells_height": num.cells_height,
                "clinker_outlet_K": sol.clinker_outlet_temperature,
                "secondary_air_K": sol.secondary_air_temperature,
                "top_layer_outlet_K": float(sol.clinker_temperature[-1, -1]),
                "sweeps": sol.sweeps,
                "wall_time_s": sol.wall_time_s,
            })
    return GridStudy(rows)
