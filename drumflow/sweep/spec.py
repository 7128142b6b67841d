"""The sweep file and its expansion into member cases.

A sweep file (TOML) names a base case, the case fields to vary (the *axes*), how to combine
them (the *design*), the settings of each member run and where the members run::

    name = "smoke_rpm_air"
    base = "smoke.toml"                 # relative to the sweep file

    [overrides]                         # applied to every member
    "run.time" = 1.5

    [axes]                              # lists, or ranges {start, stop, num} / {start, stop, step}
    "drum.rpm" = [10.0, 15.0]
    "air.mass_flow" = { start = 0.3, stop = 0.6, num = 2 }
    lifters = [{ profile = "straight", lip_length = 0.0 }, { profile = "L", lip_length = 0.02 }]

    [design]                            # "full_factorial" or "latin_hypercube" (samples, seed)
    kind = "full_factorial"

    [runs]
    processes = 1                       # MPI ranks per member

    [executor]
    kind = "local"                      # or "slurm"; [executor.local] / [executor.slurm]

An axis is a dotted case field (``drum.rpm``), or a case section (``lifters``) whose values are
tables merged into that section, so that coupled fields (a lifter's profile and its lip) change
together. Every member is validated as a full case before anything runs; every problem names
the member, its axis values and the field (:class:`SweepError`). The ``[runs]`` and
``[executor]`` tables are read by :mod:`drumflow.sweep.run_settings`.
"""

from __future__ import annotations

import copy
import itertools
import math
import typing
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Literal

from pydantic import BaseModel, Field, model_validator

from drumflow.case import (
    Case,
    case_from_dict,
    case_to_toml,
    read_toml,
    validate_model,
)
from drumflow.errors import CaseError, SweepError
from drumflow.sweep.run_settings import ExecutorSpec, Runs, SweepTable

__all__ = [
    "AxisRange",
    "Member",
    "Sweep",
    "SweepError",
    "expand",
    "load_sweep",
    "member_id",
]

_RANGE_KEYS = frozenset({"start", "stop", "num", "step"})

#: Most members a sweep may have (the product of its axes' value counts, a range's ``step``
#: included, or a Latin hypercube's samples). Every member is validated as a full case and
#: written before anything runs: measured here (2 shared cores) `drumflow sweep --check` of
#: 100 x 100 smoke-case members took 98 s (3.3 ms each to expand and validate, the rest
#: writing members/<id>/case.toml and listing them), so 5,000 members take about a minute
#: before the first run starts. The old limit (100,000, with each axis up to 10,000 and the
#: product built first) meant half an hour, or no answer at all for 10,000^3.
MAX_MEMBERS = 5_000


class AxisRange(SweepTable):
    """Evenly spaced values from ``start`` to ``stop`` (both included).

    Give ``num`` (number of values) or ``step``; a Latin hypercube samples the interval
    continuously and takes neither.
    """

    start: float
    stop: float
    num: int | None = Field(None, ge=1, le=MAX_MEMBERS, description="number of values")
    step: float | None = Field(None, gt=0, description="spacing of the values")

    @model_validator(mode="after")
    def _ordered(self) -> AxisRange:
        if self.num is not None and self.step is not None:
            raise ValueError(f"give num or step, not both (num = {self.num}, step = {self.step})")
        if self.stop < self.start:
            raise ValueError(f"stop = {self.stop} is below start = {self.start}: the range is empty")
        if self.num is not None and self.num > 1 and self.stop == self.start:
            raise ValueError(f"start = stop = {self.start}: {self.num} values would all be equal")
        return self

    def count(self) -> int:
        """How many values :meth:`values` gives (known before they are built: a tiny
        ``step`` must be refused, not expanded)."""
        if self.num is not None:
            return self.num
        assert self.step is not None
        # Tolerate round-off so that start=0.1, stop=0.3, step=0.1 includes 0.3; a step so small
        # that the quotient overflows counts as "too many" (1e18), not an OverflowError.
        quotient = min((self.stop - self.start) / self.step, 1e18)
        return math.floor(quotient + 1e-9) + 1

    def values(self) -> list[float]:
        """The grid of the range (full factorial)."""
        if self.num is not None:
            if self.num == 1:
                return [self.start]
            width = (self.stop - self.start) / (self.num - 1)
            return [self.start + i * width for i in range(self.num)]
        assert self.step is not None
        return [self.start + i * self.step for i in range(self.count())]


class Design(SweepTable):
    """How the axes combine into members."""

    kind: Literal["full_factorial", "latin_hypercube"] = Field(
        "full_factorial",
        description="'full_factorial': every combination of the axis values; "
        "'latin_hypercube': 'samples' points of a scrambled Latin hypercube (scipy.stats.qmc)",
    )
    samples: int | None = Field(None, ge=2, le=MAX_MEMBERS, description="members of a Latin hypercube")
    seed: int = Field(1, ge=0, lt=2**32, description="seed of the Latin hypercube")

    @model_validator(mode="after")
    def _samples(self) -> Design:
        if self.kind == "latin_hypercube" and self.samples is None:
            raise ValueError(f"design.samples: missing; a latin_hypercube needs samples (2 to "
                             f"{MAX_MEMBERS:,})")
        if self.kind == "full_factorial" and self.samples is not None:
            raise ValueError(
                f"design.samples = {self.samples}: only a latin_hypercube takes samples "
                "(a full factorial has one member per combination)"
            )
        return self


class Analysis(SweepTable):
    """Settings of ``drumflow sweep DIR --analyse``."""

    conductivity: Literal["air", "particle"] = Field(
        "air", description="k in Nu = h Dp / k: 'air' or 'particle' (the paper's)"
    )
    falling_mass: Literal["mean", "per_step"] = "mean"



AxisValues = list[Any] | AxisRange


class Sweep(SweepTable):
    """A validated sweep file."""

    name: str = Field(min_length=1, max_length=60, pattern=r"^[A-Za-z0-9_.-]+$")
    description: str = ""
    base: str = Field(min_length=1, description="the base case file, relative to the sweep file")
    overrides: dict[str, Any] = Field(
        default_factory=dict, description="dotted case fields set in every member"
    )
    axes: dict[str, AxisValues] = Field(min_length=1, description="case fields to vary")
    design: Design = Design()
    runs: Runs = Runs()
    analysis: Analysis = Analysis()
    executor: ExecutorSpec = ExecutorSpec()


@dataclass(frozen=True)
class Member:
    """One case of the sweep.

    Attributes
    ----------
    index
        Position in the design (the SLURM array task id).
    id
        ``m000``, ``m001``, ...: the member's directory name under ``DIR/members``.
    values
        The axis values of this member, by axis name.
    case
        The validated case.
    """

    index: int
    id: str
    values: dict[str, Any]
    case: Case

    @property
    def hash(self) -> str:
        """The case hash (the run directory is bound to it)."""
        return self.case.hash()

    @property
    def case_toml(self) -> str:
        return case_to_toml(self.case)

    def label(self) -> str:
        """Axis values as ``rpm=10, mass_flow=0.3``."""
        return ", ".join(f"{short_axis(k)}={format_value(v)}" for k, v in self.values.items())


def member_id(index: int, count: int) -> str:
    """``m000`` style id, wide enough for ``count`` members."""
    width = max(3, len(str(max(count - 1, 0))))
    return f"m{index:0{width}d}"


def short_axis(axis: str) -> str:
    """The last part of a dotted axis name (``air.mass_flow`` -> ``mass_flow``)."""
    return axis.rsplit(".", 1)[-1]


def format_value(value: Any) -> str:
    """A compact text for an axis value (tables, plot labels)."""
    if isinstance(value, float):
        return f"{value:.6g}"
    if isinstance(value, dict):
        return "{" + ", ".join(f"{k}={format_value(v)}" for k, v in value.items()) + "}"
    return str(value)


def _flatten(table: dict[str, Any], prefix: str = "") -> dict[str, Any]:
    """Nested TOML tables to dotted keys, keeping range tables ({start, stop, ...}) whole."""
    flat: dict[str, Any] = {}
    for key, value in table.items():
        name = f"{prefix}{key}"
        if isinstance(value, dict) and value and not set(value) <= _RANGE_KEYS:
            flat.update(_flatten(value, name + "."))
        else:
            flat[name] = value
    return flat


def _case_fields() -> dict[str, set[str] | None]:
    """Sections of a case and their fields (None for a top-level scalar field)."""
    out: dict[str, set[str] | None] = {}
    for name, info in Case.model_fields.items():
        ann = info.annotation
        if isinstance(ann, type) and issubclass(ann, BaseModel):
            fields = set(ann.model_fields)
            if name == "contacts":
                # Nested pairs: contacts.particle_particle.friction.
                for sub, sub_info in ann.model_fields.items():
                    sub_ann = sub_info.annotation
                    if isinstance(sub_ann, type) and issubclass(sub_ann, BaseModel):
                        fields |= {f"{sub}.{f}" for f in sub_ann.model_fields}
            out[name] = fields
        else:
            out[name] = None
    return out


def _integer_field(path: str) -> bool:
    """True when the dotted case field takes integers (``lifters.count``, ``run.seed``)."""
    model: Any = Case
    info = None
    for part in path.split("."):
        fields = getattr(model, "model_fields", None)
        if not fields or part not in fields:
            return False
        info = fields[part]
        model = info.annotation
    if info is None:
        return False

    def has_int(ann: Any) -> bool:
        if ann is int:
            return True
        return any(has_int(a) for a in typing.get_args(ann))

    return has_int(info.annotation)


def _check_field(path: str, where: str, allow_section: bool) -> str | None:
    """A problem line when ``path`` is not a case field (or section), else None."""
    fields = _case_fields()
    section, _, rest = path.partition(".")
    if section == "name":
        return f"{where}.{path}: the member name is set by the sweep (base name and member id)"
    if section not in fields:
        return (f"{where}.{path}: unknown case field; allowed sections: "
                f"{', '.join(k for k, v in fields.items() if v is not None)}")
    members = fields[section]
    if members is None:
        return None if not rest else f"{where}.{path}: unknown case field ({section} has no fields)"
    if not rest:
        if allow_section:
            return None
        return f"{where}.{path}: a whole section; give a field such as {section}.{sorted(members)[0]}"
    if rest not in members:
        return (f"{where}.{path}: unknown case field; allowed in {section}: "
                f"{', '.join(sorted(members))}")
    return None


def _set(data: dict[str, Any], path: str, value: Any) -> None:
    parts = path.split(".")
    node = data
    for part in parts[:-1]:
        child = node.get(part)
        if not isinstance(child, dict):
            child = {}
            node[part] = child
        node = child
    if isinstance(value, dict) and isinstance(node.get(parts[-1]), dict):
        node[parts[-1]] = {**node[parts[-1]], **copy.deepcopy(value)}
    else:
        node[parts[-1]] = copy.deepcopy(value)


def _get(data: dict[str, Any], path: str) -> Any:
    node: Any = data
    for part in path.split("."):
        if not isinstance(node, dict) or part not in node:
            return None
        node = node[part]
    return node


def load_sweep(
    path: Path | str, base: Path | str | None = None
) -> tuple[Sweep, dict[str, Any], list[Member]]:
    """Read, validate and expand a sweep file.

    Parameters
    ----------
    path
        The sweep file (TOML).
    base
        The base case file to use instead of the one the sweep names (a sweep directory keeps
        its own copy).

    Returns
    -------
    sweep, base_data, members
        The validated sweep, the base case as nested dictionaries, and the members, each a
        validated case.

    Raises
    ------
    SweepError
        Listing every problem of the sweep file and of every member, before anything runs.
    """
    path = Path(path)
    try:
        raw = read_toml(path)
    except CaseError as exc:
        raise SweepError([p.replace("case file", "sweep file") for p in exc.problems], path) from None
    raw = dict(raw)
    for key in ("axes", "overrides"):
        if isinstance(raw.get(key), dict):
            raw[key] = _flatten(raw[key])
    try:
        sweep = validate_model(Sweep, raw, path)
    except CaseError as exc:
        raise SweepError(exc.problems, path) from None
    base_path = Path(base) if base is not None else (path.parent / sweep.base)
    if not base_path.is_file():
        raise SweepError([f"base = {sweep.base!r}: case file {base_path} not found"], path)
    try:
        base_data = read_toml(base_path)
    except CaseError as exc:
        raise SweepError([f"base = {sweep.base!r}: {p}" for p in exc.problems], path) from None
    members = expand(sweep, base_data, source=path)
    return sweep, base_data, members


def _axis_levels(sweep: Sweep) -> tuple[dict[str, list[Any] | AxisRange], list[str]]:
    problems: list[str] = []
    levels: dict[str, list[Any] | AxisRange] = {}
    lhs = sweep.design.kind == "latin_hypercube"
    for axis, spec in sweep.axes.items():
        bad = _check_field(axis, "axes", allow_section=True)
        if bad:
            problems.append(bad)
            continue
        if isinstance(spec, AxisRange):
            if lhs:
                if spec.num is not None or spec.step is not None:
                    problems.append(
                        f"axes.{axis} = {spec.model_dump(exclude_none=True)}: a latin_hypercube "
                        "samples a range continuously; give start and stop only (or a list)"
                    )
                    continue
                if spec.stop == spec.start:
                    problems.append(f"axes.{axis}: start = stop = {spec.start}: the range is empty")
                    continue
                levels[axis] = spec
                continue
            if spec.num is None and spec.step is None:
                problems.append(
                    f"axes.{axis} = {spec.model_dump(exclude_none=True)}: a full factorial needs "
                    "num or step for a range"
                )
                continue
            if spec.count() > MAX_MEMBERS:
                problems.append(
                    f"axes.{axis} = {spec.model_dump(exclude_none=True)}: {spec.count():,} values; "
                    f"allowed up to {MAX_MEMBERS:,} members in all (a larger step, or fewer values)"
                )
                continue
            values: list[Any] = spec.values()
            if _integer_field(axis):
                # A range on an integer field (lifters.count): its values are whole numbers
                # computed as floats; the strict case model takes only integers there.
                values = [int(v) if float(v).is_integer() else v for v in values]
            levels[axis] = values
        else:
            if len(spec) == 0:
                problems.append(f"axes.{axis} = []: empty list; allowed: at least one value")
                continue
            if "." not in axis and not all(isinstance(v, dict) for v in spec):
                problems.append(
                    f"axes.{axis}: a section axis takes tables of fields, e.g. "
                    f"[{{...}}, {{...}}]; got {spec!r}"
                )
                continue
            if "." not in axis:
                for value in spec:
                    for field in value:
                        bad = _check_field(f"{axis}.{field}", "axes", allow_section=False)
                        if bad:
                            problems.append(bad)
            levels[axis] = list(spec)
    return levels, problems


def _design_points(sweep: Sweep, levels: dict[str, list[Any] | AxisRange],
                   base: dict[str, Any]) -> list[dict[str, Any]]:
    axes = list(levels)
    if sweep.design.kind == "full_factorial":
        lists = [levels[a] for a in axes]
        return [dict(zip(axes, combo, strict=True)) for combo in itertools.product(*lists)]  # type: ignore[arg-type]
    from scipy.stats import qmc

    assert sweep.design.samples is not None
    sampler = qmc.LatinHypercube(d=len(axes), seed=sweep.design.seed)
    unit = sampler.random(sweep.design.samples)
    points = []
    for row in unit:
        point: dict[str, Any] = {}
        for axis, u in zip(axes, row, strict=True):
            spec = levels[axis]
            if isinstance(spec, AxisRange):
                value: Any = spec.start + float(u) * (spec.stop - spec.start)
                if _integer_field(axis) or (isinstance(_get(base, axis), int)
                                            and not isinstance(_get(base, axis), bool)):
                    value = int(round(value))  # an integer field (lifters.count)
            else:
                # A list is a set of levels: the stratum of u picks one, evenly.
                value = spec[min(int(u * len(spec)), len(spec) - 1)]
            point[axis] = value
        points.append(point)
    return points


def expand(sweep: Sweep, base: dict[str, Any], source: Path | str | None = None) -> list[Member]:
    """Expand a sweep into validated member cases.

    Each member is the base case with the overrides and its axis values, named
    ``<base name>-<member id>``, with ``run.processes`` set to ``runs.processes``.

    Raises
    ------
    SweepError
        Listing every unknown field and every member the case model refuses (member id, axis
        values, field, value, allowed range).
    """
    problems: list[str] = []
    for key in sweep.overrides:
        bad = _check_field(key, "overrides", allow_section=False)
        if bad:
            problems.append(bad)
    levels, axis_problems = _axis_levels(sweep)
    problems += axis_problems
    if problems:
        raise SweepError(problems, source)
    if sweep.design.kind == "full_factorial":
        # The product is counted, never built: 10,000 values on each of three axes would
        # otherwise be 10^12 combinations in memory before any check.
        sizes = {a: len(v) for a, v in levels.items() if isinstance(v, list)}
        product = math.prod(sizes.values())
        if product > MAX_MEMBERS:
            factors = " x ".join(f"{a} ({n:,})" for a, n in sizes.items())
            raise SweepError([f"axes: {factors} = {product:,} members; allowed up to "
                              f"{MAX_MEMBERS:,} (fewer values per axis, or a latin_hypercube "
                              "with design.samples)"], source)
    base_name = str(base.get("name", sweep.name))
    points = _design_points(sweep, levels, base)
    count = len(points)
    members: list[Member] = []
    for index, point in enumerate(points):
        mid = member_id(index, count)
        data = copy.deepcopy(base)
        for key, value in sweep.overrides.items():
            _set(data, key, value)
        for axis, value in point.items():
            _set(data, axis, value)
        data["name"] = f"{base_name}-{mid}"[:80]
        data.setdefault("run", {})["processes"] = sweep.runs.processes
        try:
            case = case_from_dict(data)
        except CaseError as exc:
            label = ", ".join(f"{a} = {format_value(v)}" for a, v in point.items())
            problems += [f"member {mid} ({label}): {p}" for p in exc.problems]
            continue
        if case.air.pressure_gradient_force:
            problems.append(f"member {mid}: air.pressure_gradient_force = true: not available "
                            "in this version; allowed: false")
            continue
        members.append(Member(index, mid, point, case))
    if problems:
        raise SweepError(problems, source)
    return members
