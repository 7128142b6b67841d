"""The time-to-answer ladder: several runs of one scene, each stopped by its own rule, against
one reference run's answer (issue 11).

How to use::

    drumflow ladder results/bench/paper_model_two_ladder/ladder.toml   # ladder.csv, .json, .png

    from drumflow.bench.time_to_answer import load_ladder_spec, answer_ladder, write_ladder
    ladder = answer_ladder(load_ladder_spec(Path("ladder.toml")))
    ladder.table[["rung", "wall_s", "speedup", "error_h", "within_tolerance"]]

A rung is a finished (or still going) run directory, or a shipped results folder, replayed by
:func:`drumflow.bench.answer.replay_answer`, and a way to stop it:

* ``fixed``: the run to its last output time (the paper's fixed 17.5 s);
* ``settled``: the first time from which every answer stays within the tolerance of the
  *reference's* answer. Known only in hindsight: it is the best any stop rule could do with
  this run, the bound a rule is measured against;
* ``rule``: the first firing of ``run.stop = "converged"`` replayed on the run's own series (the
  rule a user can switch on); a rule that never fires runs to the end.

A rung may set ``until``: its run is replayed as if it had ended there (the last output at or
before it), for a ladder over a window shorter than some of its runs, e.g. paper model one,
whose full-particle run has only its first 3.5 s, against a parcel run to 17.5 s.

The reference rung's answer at its end gives the errors of every rung. Its half-widths are the
noise floor (the cascading bed's flow from whole lifter cycles, :func:`drumflow.convergence.cycle_means`;
the others batch means of the per-step series): an error below it is chaos, not a setting. Wall times are the
replay's (coupling updates, no set-up or air solve), times ``wall_scale`` when a rung's run is a
stand-in for a run with other settings whose rate was measured side by side (the reference of
issue 11 is the conservative settings, 2.34 times slower than the defaults from the same
restart, and the same physics within the noise floor over that window): such a wall time is
marked estimated, and the spec must say where the factor comes from.
"""

from __future__ import annotations

import json
import math
import tomllib
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any, Literal, NamedTuple

import numpy as np
import pandas as pd
from numpy.typing import NDArray
from pydantic import BaseModel, ConfigDict, Field, ValidationError, model_validator

from drumflow._json import json_safe
from drumflow._mpl import pyplot
from drumflow.bench.answer import (
    DEFAULT_TOLERANCE,
    regular_end_times,
    replay_answer,
    settled_time,
)
from drumflow.bench.answer_result import AnswerReplay, path_from
from drumflow.errors import CaseError
from drumflow.machine_load import contended_share
from drumflow.readers import read_text

if TYPE_CHECKING:
    from matplotlib.axes import Axes

Answer = Literal["temperature", "mass_flow", "steady_mass_flow", "h"]
StopMode = Literal["fixed", "settled", "rule"]

class LadderQuantity(NamedTuple):
    """One quantity the ladder reports, and where the answer replay keeps it."""

    column: str  #: its column in the replay table
    half_width: str  #: the reference's half-width column (the noise floor)
    short: str  #: for tables
    label: str  #: for people


#: Every quantity the ladder reports.
LADDER_QUANTITIES: dict[str, LadderQuantity] = {
    "temperature": LadderQuantity("temperature_C", "temperature_half_width_K", "T(3.5)",
                                  "mean temperature at 3.5 s"),
    "mass_flow": LadderQuantity("mass_flow_kg_s", "mass_flow_half_width_kg_s", "ṁ paper",
                                "falling mass flow, paper's window"),
    "steady_mass_flow": LadderQuantity("steady_mass_flow_kg_s", "steady_mass_flow_half_width_kg_s",
                                       "ṁ steady", "falling mass flow, cascading bed (whole cycles)"),
    "h": LadderQuantity("h_W_m2K", "h_half_width_W_m2K", "h", "h, Eq. 39"),
}
_TIME_EPS_S = 1e-6
LADDER_FILES = ("ladder.csv", "ladder.json", "ladder.png")


class RungSpec(BaseModel):
    """One rung: a run and the rule that stops it."""

    model_config = ConfigDict(extra="forbid")

    name: str = Field(pattern=r"^[A-Za-z0-9_.-]+$", description="identifier (table row)")
    description: str = Field(description="one line for the table")
    run: Path = Field(description="run directory or shipped results folder, relative to the "
                                  "spec file")
    stop: StopMode = Field("fixed", description="'fixed' | 'settled' | 'rule'")
    wall_scale: float = Field(1.0, gt=0.0, le=1000.0,
                              description="multiply the run's wall times (a stand-in run)")
    wall_scale_source: str = Field("", description="where wall_scale was measured (required "
                                                   "when it is not 1)")
    rate: float | None = Field(None, gt=0.0, description="particle-steps per wall second for "
                                                         "updates without logged wall times")
    until: float | None = Field(None, gt=0.0, description="replay the run as if it had ended "
                                                          "here, s (its last output at or before)")

    @model_validator(mode="after")
    def _scale_has_a_source(self) -> RungSpec:
        if self.wall_scale != 1.0 and not self.wall_scale_source.strip():
            raise ValueError(f"wall_scale = {self.wall_scale} needs wall_scale_source: the "
                             "file and row where the factor was measured")
        return self


class LadderSpec(BaseModel):
    """A time-to-answer ladder: the rungs, the reference, the answers and the tolerance."""

    model_config = ConfigDict(extra="forbid")

    title: str
    reference: str = Field(description="name of the rung whose answer at its end is the "
                                       "reference (its stop must be 'fixed')")
    tolerance: float = Field(DEFAULT_TOLERANCE, gt=0.0, lt=1.0,
                             description="largest relative error of a known answer")
    answers: list[Answer] = Field(["temperature", "steady_mass_flow", "h"], min_length=1,
                                  description="the quantities that make the answer")
    rungs: list[RungSpec] = Field(min_length=1)
    machine: str = Field("", description="where the runs ran (for the table)")

    @model_validator(mode="after")
    def _reference_is_a_fixed_rung(self) -> LadderSpec:
        names = [r.name for r in self.rungs]
        twice = sorted({n for n in names if names.count(n) > 1})
        if twice:
            raise ValueError(f"rung names must be unique; repeated: {', '.join(twice)}")
        if self.reference not in names:
            raise ValueError(f"reference = {self.reference!r} is not a rung; allowed: "
                             f"{', '.join(names)}")
        ref = self.rungs[names.index(self.reference)]
        if ref.stop != "fixed":
            raise ValueError(f"reference = {self.reference!r} has stop = {ref.stop!r}; the "
                             "reference runs to its end: allowed 'fixed'")
        return self


def load_ladder_spec(path: Path) -> LadderSpec:
    """Read a ladder spec (TOML); rung runs are resolved against the file's folder.

    Raises
    ------
    CaseError
        Missing or not TOML, an invalid field (named, with its value and what is allowed), or
        a run folder that does not exist.
    BadFileError
        Not UTF-8 text, or a folder.
    """
    if not path.exists():
        raise CaseError([f"ladder spec {path}: not found"], path)
    # read_text names a folder given for the file and a spec not saved as UTF-8 (the byte and
    # its line); Path.read_text ended in a traceback.
    text = read_text(path, "a ladder spec")
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as err:
        raise CaseError([f"ladder spec {path}: not valid TOML: {err}"], path) from None
    try:
        spec = LadderSpec.model_validate(data)
    except ValidationError as err:
        problems = []
        for e in err.errors():
            loc = ".".join(str(p) for p in e["loc"])
            value = e.get("input")
            shown = "" if isinstance(value, dict) else f" (got {value!r})"
            problems.append(f"{loc or 'spec'}: {e['msg']}{shown}")
        raise CaseError(problems, path) from None
    rungs = []
    for i, rung in enumerate(spec.rungs):
        run = rung.run if rung.run.is_absolute() else (path.parent / rung.run).resolve()
        if not (run / "case.toml").is_file():
            raise CaseError([f"rungs[{i}].run = {str(rung.run)!r}: {run} holds no run "
                             "(no case.toml); allowed: a run directory after `drumflow post` or "
                             "a shipped results folder"], path)
        rungs.append(rung.model_copy(update={"run": run}))
    return spec.model_copy(update={"rungs": rungs})


@dataclass(frozen=True)
class AnswerLadder:
    """The ladder's result.

    Attributes
    ----------
    spec
        The spec it was made from (runs resolved).
    table
        One row per rung: ``rung``, ``description``, ``stop``, ``stop_time_s`` (NaN: the rung
        never reaches the answer), ``wall_s``, ``wall_estimated`` (scaled or partly from a
        rate), ``contended_share`` (the share of the run's logged wall time other programs
        contended, :func:`drumflow.machine_load.contended_share`; NaN: the run has no load log),
        ``speedup`` (the reference's wall over this rung's), per quantity ``value_Q``
        and ``error_Q`` (relative to the reference), ``max_error`` over the answers,
        ``within_tolerance``, ``note``.
    reference_values
        The reference's answer per quantity.
    noise_floor
        The reference's relative batch-means half-width per quantity.
    """

    spec: LadderSpec
    table: pd.DataFrame
    reference_values: dict[str, float]
    noise_floor: dict[str, float]

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready (NaN as null)."""
        rows = self.table.replace({np.nan: None}).to_dict(orient="records")
        return {
            "title": self.spec.title, "machine": self.spec.machine,
            "reference": self.spec.reference, "tolerance": self.spec.tolerance,
            "answers": list(self.spec.answers),
            "reference_values": self.reference_values, "noise_floor": self.noise_floor,
            "rungs": rows,
            "spec": json.loads(self.spec.model_dump_json()),
        }


def _value(replay: AnswerReplay, time_s: float, column: str) -> float:
    rows = replay.table[np.abs(replay.table["time_s"] - time_s) < _TIME_EPS_S]
    return math.nan if rows.empty else float(rows[column].iloc[0])


def _relative(values: Any, reference: float) -> NDArray[np.float64]:
    return np.asarray(values, dtype=float) / reference - 1.0


def estimated_share(table: pd.DataFrame, t: float) -> float:
    """Share of the wall time up to ``t`` that was estimated (not logged), from the replay
    table's grid: the last grid time at or before ``t`` (the first, before the grid starts).

    The converged rule fires between grid times: looking for ``t`` itself on the grid found
    nothing there, and called such a rung's wall time measured.
    """
    upto = table[table["time_s"] <= t + _TIME_EPS_S]
    return float(upto["wall_estimated_share"].iloc[-1] if not upto.empty
                 else table["wall_estimated_share"].iloc[0])


def _stop(rung: RungSpec, replay: AnswerReplay, spec: LadderSpec,
          reference_values: dict[str, float]) -> tuple[float | None, dict[str, float], str]:
    """When the rung stops, what it reports then, and a note."""
    times = replay.table["time_s"].to_numpy(float)
    end = float(times[-1])
    columns = {q: quantity.column for q, quantity in LADDER_QUANTITIES.items()}
    if rung.stop == "rule" and replay.first_fire_s is not None:
        t = replay.first_fire_s
        values = {q: float(replay.at_first_fire.get(col, math.nan)) for q, col in columns.items()}
        return t, values, f"the converged rule fired at {t:.4g} s"
    if rung.stop == "settled":
        when = [settled_time(times, _relative(replay.table[columns[q]], reference_values[q]),
                             spec.tolerance) for q in spec.answers]
        if any(w is None for w in when):
            late = [q for q, w in zip(spec.answers, when, strict=True) if w is None]
            values = {q: _value(replay, end, col) for q, col in columns.items()}
            return None, values, (f"never within {spec.tolerance:.0%} of the reference: "
                                  f"{', '.join(late)} (errors shown at the run's end, {end:.4g} s)")
        t = max(w for w in when if w is not None)
        return t, {q: _value(replay, t, col) for q, col in columns.items()}, (
            f"every answer within {spec.tolerance:.0%} of the reference from {t:.4g} s")
    values = {q: _value(replay, end, col) for q, col in columns.items()}
    note = f"to its end, {end:.4g} s"
    if rung.stop == "rule":
        note = f"the converged rule {replay.first_fire_reason}; ran {note}"
    return end, values, note


def _grid_until(run: Path, until: float) -> list[float]:
    """The replay's regular end times up to ``until``, and ``until``."""
    from drumflow.case import load_case

    start = float(load_case(run / "case.toml").run.mass_flow_start)
    return [*regular_end_times(start, until), until]


def _cut(replay: AnswerReplay, until: float) -> AnswerReplay:
    """``replay`` as if its run had ended at ``until``: the rows after it dropped, and a rule
    firing after it not seen."""
    from dataclasses import replace

    table = replay.table[replay.table["time_s"] <= until + _TIME_EPS_S].reset_index(drop=True)
    end = float(table["time_s"].iloc[-1])
    if replay.first_fire_s is not None and replay.first_fire_s <= end + _TIME_EPS_S:
        return replace(replay, table=table, reference_time_s=end)
    return replace(replay, table=table, reference_time_s=end, first_fire_s=None,
                   first_fire_grid_s=None, at_first_fire={},
                   first_fire_reason=f"did not fire by {end:.4g} s (the rung's until)")


def answer_ladder(spec: LadderSpec) -> AnswerLadder:
    """Replay every rung's run and set each stop's wall time and errors against the reference.

    Raises
    ------
    AnalysisInputError, MissingRunFileError, RunTooShortError
        A rung's run cannot be replayed (from :func:`~drumflow.bench.answer.replay_answer`).
    """
    replays: dict[tuple[Path, float | None, float | None], AnswerReplay] = {}

    def replay_of(rung: RungSpec) -> AnswerReplay:
        key = (rung.run, rung.rate, rung.until)
        if key not in replays:
            times = None if rung.until is None else _grid_until(rung.run, rung.until)
            replay = replay_answer(rung.run, tolerance=spec.tolerance,
                                   settle_tolerance=spec.tolerance,
                                   particle_steps_per_s=rung.rate, times=times)
            replays[key] = replay if rung.until is None else _cut(replay, rung.until)
        return replays[key]

    ref_rung = next(r for r in spec.rungs if r.name == spec.reference)
    ref = replay_of(ref_rung)
    last = ref.reference
    reference_values = {q: float(last[quantity.column]) for q, quantity in LADDER_QUANTITIES.items()}
    noise_floor = {q: abs(float(last[quantity.half_width]) / reference_values[q])
                   for q, quantity in LADDER_QUANTITIES.items()}
    ref_wall = ref.wall_at(float(last["time_s"]))
    reference_wall = None if ref_wall is None else ref_wall * ref_rung.wall_scale

    rows = []
    for rung in spec.rungs:
        replay = replay_of(rung)
        t, values, note = _stop(rung, replay, spec, reference_values)
        wall = replay.wall_at(t) if t is not None else None
        wall_s = math.nan if wall is None else wall * rung.wall_scale
        share = 0.0 if t is None else estimated_share(replay.table, t)
        row: dict[str, Any] = {
            "rung": rung.name, "description": rung.description, "stop": rung.stop,
            "stop_time_s": math.nan if t is None else t, "run_end_s": replay.reference_time_s,
            "wall_s": wall_s,
            "wall_estimated": bool(rung.wall_scale != 1.0 or share > 0.0),
            # A wall time measures the settings only on a machine the run had to itself.
            "contended_share": contended_share(rung.run),
            "speedup": (reference_wall / wall_s if reference_wall and wall_s == wall_s
                        and wall_s > 0 else math.nan),
        }
        errors = []
        for q in LADDER_QUANTITIES:
            row[f"value_{q}"] = values[q]
            err = values[q] / reference_values[q] - 1.0
            row[f"error_{q}"] = err
            if q in spec.answers:
                errors.append(abs(err))
        row["max_error"] = max(errors) if all(e == e for e in errors) else math.nan
        row["within_tolerance"] = bool(row["max_error"] <= spec.tolerance and t is not None)
        row["note"] = note + ("" if rung.wall_scale == 1.0 else
                              f"; wall x{rung.wall_scale:g} ({rung.wall_scale_source})")
        rows.append(row)
    return AnswerLadder(spec=spec, table=pd.DataFrame(rows), reference_values=reference_values,
                        noise_floor=noise_floor)


def plot_ladder(ladder: AnswerLadder, path: Path) -> None:
    """Wall time against the largest answer error, one point per rung, the tolerance and the
    noise floor drawn: the Pareto picture of the ladder."""
    plt = pyplot()

    fig, ax = plt.subplots(figsize=(8.0, 5.0))
    table = ladder.table
    floor = max(ladder.noise_floor[q] for q in ladder.spec.answers)
    _draw_ladder(ax, table, ladder.spec.tolerance, floor)
    ax.set_title(ladder.spec.title, fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def _draw_ladder(ax: Axes, table: pd.DataFrame, tolerance: float, floor: float) -> None:
    from matplotlib.ticker import NullFormatter, ScalarFormatter

    shown = table[np.isfinite(table["wall_s"]) & np.isfinite(table["max_error"])]
    labels: dict[tuple[float, float], list[str]] = {}
    for _, row in shown.iterrows():
        marker = "o" if not row["wall_estimated"] else "s"
        colour = "tab:green" if row["within_tolerance"] else "tab:red"
        point = (round(row["wall_s"] / 3600.0, 6), round(100.0 * row["max_error"], 6))
        ax.scatter(*point, marker=marker, color=colour, zorder=3)
        labels.setdefault(point, []).append(str(row["rung"]))
    # Rungs that stop at the same point (the same run to its end) share one label.
    for point, names in labels.items():
        ax.annotate(", ".join(names), point, textcoords="offset points", xytext=(5, 4), fontsize=8)
    ax.axhline(100.0 * tolerance, color="tab:gray", ls="--", lw=1,
               label=f"tolerance {tolerance:.0%}")
    ax.axhline(100.0 * floor, color="tab:blue", ls=":", lw=1,
               label=f"noise floor {floor:.2%} (reference's interval)")
    ax.set_xscale("log")
    ax.xaxis.set_major_formatter(ScalarFormatter())
    # Minor ticks are labelled only within a decade: over more they run into each other
    # (model one's ladder spans 0.1-8 h).
    lo, hi = ax.get_xlim()
    ax.xaxis.set_minor_formatter(ScalarFormatter() if hi / lo <= 10.0 else NullFormatter())
    ax.set_xlabel("wall time to the answer, h (squares: estimated)")
    ax.set_ylabel("largest answer error against the reference, %")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8, loc="upper right")


def write_ladder(ladder: AnswerLadder, folder: Path) -> dict[str, Path]:
    """Write ``ladder.csv``, ``ladder.json`` and ``ladder.png`` into ``folder``."""
    folder.mkdir(parents=True, exist_ok=True)
    paths = {name.split(".")[1]: folder / name for name in LADDER_FILES}
    ladder.table.to_csv(paths["csv"], index=False, float_format="%.6g")
    summary = ladder.to_dict()
    for rung in summary["spec"]["rungs"]:
        rung["run"] = path_from(folder, rung["run"])
    paths["json"].write_text(json.dumps(json_safe(summary), indent=2) + "\n")
    plot_ladder(ladder, paths["png"])
    return paths
