"""What a time-to-answer replay found (:class:`AnswerReplay`), and its files.

:func:`drumflow.bench.answer.replay_answer` makes the replay; :func:`write_answer` writes its
table (``answer.csv``), its summary (``answer.json``) and its picture (``answer.png``).
"""

from __future__ import annotations

import json
import math
import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from drumflow._json import json_safe
from drumflow._mpl import pyplot
from drumflow.case import Case

__all__ = [
    "QUANTITIES",
    "TEMPERATURE_TIME_S",
    "TIME_EPS_S",
    "AnswerReplay",
    "path_from",
    "plot_answer",
    "write_answer",
]

#: Tables 3-4 of the paper read the mean particle temperature at this time.
TEMPERATURE_TIME_S = 3.5
#: The answer's three quantities: column of the value, and its label.
QUANTITIES = {"temperature": ("temperature_C", "(a) mean temperature at 3.5 s"),
              "mass_flow": ("mass_flow_kg_s", "(b) falling mass flow"),
              "h": ("h_W_m2K", "(c) h, Eq. 39")}

# Output and update times are multiples of the DEM step (~1e-4 s) written with 10 significant
# digits, a few 1e-9 s off at 17.5 s; 1e-6 s tells them apart from their neighbours safely.
TIME_EPS_S = 1e-6


@dataclass(frozen=True)
class AnswerReplay:
    """What a run stopped at each grid time would have reported, and when its answer settled.

    Attributes
    ----------
    run_dir
        The replayed directory (absolute).
    case
        Its case.
    table
        One row per grid time (the last row is the reference). Columns: ``time_s`` (the output
        time a run stopped there ends at); ``temperature_C``, ``temperature_half_width_K``,
        ``temperature_extrapolated``; ``mass_flow_kg_s``, ``mass_flow_half_width_kg_s``;
        ``h_W_m2K``, ``h_half_width_W_m2K``, ``h_window_W_m2K``; ``eq57_mass_flow_kg_s`` (Eq. 57
        from the crossings, first to last); the stop rule's ``monitor_h_W_m2K``,
        ``monitor_h_rel_half_width``, ``monitor_mass_flow_kg_s``,
        ``monitor_mass_flow_rel_half_width``, ``converged``, ``intervals_within_tolerance``
        (the same verdict without the minimum time), ``reason``; ``rel_temperature``,
        ``rel_temperature_drop``, ``rel_mass_flow``, ``rel_h``; ``steady_mass_flow_kg_s``,
        ``steady_mass_flow_half_width_kg_s``, ``steady_start_s`` (the falling mass flow from the
        end of the start-up transient, ``_steady_mass_flow`` of :mod:`drumflow.bench.answer`) and
        ``rel_steady_mass_flow``; ``wall_s`` (cumulative) and
        ``wall_estimated_share`` (share of it from the rate, not measured).
    reference_time_s
        The end time the relative differences refer to: the last output time of the run.
    planned_time_s
        The case's ``run.time`` (the full run the answer is meant to match).
    tolerance
        The stop rule's tolerance (largest relative half-width).
    settle_tolerance
        Largest relative difference from the reference for "settled".
    min_stop_time_s
        The rule's minimum time (:func:`drumflow.coupling.stop.min_stop_time`).
    check_every_steps
        DEM steps between the rule's checks (the output step).
    first_fire_s
        First time the rule fires, checked as the coupling loop checks it; None if never.
    first_fire_grid_s
        First grid time at which it fires; None if never.
    first_fire_reason
        The verdict's line at ``first_fire_s`` (or at the reference when it never fires).
    at_first_fire
        Values and relative differences a run stopped at ``first_fire_s`` reports (empty if
        the rule never fires).
    settled_s
        Per quantity (``temperature``, ``mass_flow``, ``h``, ``temperature_drop``,
        ``steady_mass_flow``: the cascading bed's flow after MSER's cut of the window): the first
        grid time from which it stays within ``settle_tolerance``; None if not even the
        reference qualifies.
    wall
        How the wall times were obtained: ``source`` (``measured``, ``rate``,
        ``measured+rate``, or ``none``: no wall times and no rate, ``wall_s`` NaN),
        ``particle_steps_per_s``, ``rate_source``, ``measured_updates``,
        ``estimated_updates``, ``total_s`` (up to the reference).
    notes
        Remarks (the reference is not the planned end, the rule cannot fire yet, ...).
    """

    run_dir: Path
    case: Case
    table: pd.DataFrame
    reference_time_s: float
    planned_time_s: float
    tolerance: float
    settle_tolerance: float
    min_stop_time_s: float
    check_every_steps: int
    first_fire_s: float | None
    first_fire_grid_s: float | None
    first_fire_reason: str
    at_first_fire: dict[str, Any]
    settled_s: dict[str, float | None]
    wall: dict[str, Any]
    notes: tuple[str, ...] = field(default=())

    @property
    def reference(self) -> pd.Series:
        """The reference row of :attr:`table`."""
        return self.table.iloc[-1]

    @property
    def answer_settled_s(self) -> float | None:
        """When all three quantities (a), (b), (c) have settled; None if one never does."""
        times = [self.settled_s[name] for name in QUANTITIES]
        return None if any(t is None for t in times) else max(t for t in times if t is not None)

    def wall_at(self, time_s: float | None) -> float | None:
        """Cumulative wall time at a grid time, or at the first firing (None for None)."""
        if time_s is None:
            return None
        if self.first_fire_s is not None and abs(time_s - self.first_fire_s) < TIME_EPS_S:
            return _finite_or_none(self.at_first_fire.get("wall_s"))
        rows = self.table[np.abs(self.table["time_s"] - time_s) < TIME_EPS_S]
        return None if rows.empty else _finite_or_none(rows["wall_s"].iloc[0])

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready summary (NaN as ``null``); the per-time table is not included."""
        ref = self.reference
        values = {name: float(ref[col]) for name, (col, _) in QUANTITIES.items()}
        half = {"temperature": float(ref["temperature_half_width_K"]),
                "mass_flow": float(ref["mass_flow_half_width_kg_s"]),
                "h": float(ref["h_half_width_W_m2K"])}
        settled = self.answer_settled_s
        return json_safe({
            "run_dir": str(self.run_dir),
            "case": self.case.name,
            "reference": {
                "time_s": self.reference_time_s,
                "source": "the longest time available: the last output time of "
                          "post/mean_temperature.csv",
                "planned_time_s": self.planned_time_s,
                "values": values,
                "half_widths": half,
                "h_window_W_m2K": float(ref["h_window_W_m2K"]),
                "eq57_mass_flow_kg_s": float(ref["eq57_mass_flow_kg_s"]),
                "steady_mass_flow_kg_s": float(ref["steady_mass_flow_kg_s"]),
                "steady_mass_flow_half_width_kg_s": float(ref["steady_mass_flow_half_width_kg_s"]),
                "steady_start_s": float(ref["steady_start_s"]),
            },
            "temperature_time_s": TEMPERATURE_TIME_S,
            "settle_tolerance": self.settle_tolerance,
            "settled_s": self.settled_s,
            "answer_settled_s": settled,
            "wall_at_answer_settled_s": self.wall_at(settled),
            "rule": {
                "tolerance": self.tolerance,
                "min_time_s": self.min_stop_time_s,
                "check_every_steps": self.check_every_steps,
                "first_fire_s": self.first_fire_s,
                "first_fire_grid_s": self.first_fire_grid_s,
                "reason": self.first_fire_reason,
                "wall_at_first_fire_s": self.wall_at(self.first_fire_s),
                "at_first_fire": self.at_first_fire,
            },
            "wall": self.wall,
            "grid_times": int(len(self.table)),
            "notes": list(self.notes),
        })


def _finite_or_none(value: Any) -> float | None:
    try:
        f = float(value)
    except (TypeError, ValueError):
        return None
    return f if math.isfinite(f) else None


# -- output ---------------------------------------------------------------------------------
def plot_answer(replay: AnswerReplay, path: Path, title: str = "") -> None:
    """|relative difference| from the reference of (a), (b), (c) against simulated time (log
    axis), the settle band and the rule's first firing."""
    plt = pyplot()
    table = replay.table
    t = table["time_s"].to_numpy(float)
    fig, ax = plt.subplots(figsize=(7.5, 4.4), dpi=120)
    floor = 1e-6
    for (name, (_, label)), colour in zip(QUANTITIES.items(), ("tab:red", "tab:blue", "tab:green"),
                                         strict=True):
        rel = np.abs(table[f"rel_{name}"].to_numpy(float))
        # The reference is 0 by definition: drawn at the floor of the axis.
        ax.plot(t, np.clip(rel, floor, None), marker=".", lw=1.3, color=colour, label=label)
        when = replay.settled_s.get(name)
        if when is not None:
            ax.axvline(when, color=colour, lw=0.8, ls=":")
    steady = np.abs(table["rel_steady_mass_flow"].to_numpy(float))
    if np.isfinite(steady).any():
        ax.plot(t, np.clip(steady, floor, None), marker=".", lw=1.3, color="tab:purple",
                label="(b') falling mass flow of the cascading bed (MSER window)")
        when = replay.settled_s.get("steady_mass_flow")
        if when is not None:
            ax.axvline(when, color="tab:purple", lw=0.8, ls=":")
    ax.axhspan(floor, replay.settle_tolerance, color="0.9", zorder=0,
               label=f"within {replay.settle_tolerance:.0%} (settled times dotted)")
    ax.axhline(replay.settle_tolerance, color="0.4", lw=0.8)
    if replay.first_fire_s is not None:
        ax.axvline(replay.first_fire_s, color="black", lw=1.4, ls="--",
                   label=f"stop rule fires ({replay.tolerance:.0%}): {replay.first_fire_s:.3g} s")
    else:
        ax.plot([], [], color="black", ls="--",
                label=f"stop rule ({replay.tolerance:.0%}) never fires by {replay.reference_time_s:.3g} s")
    ax.axvline(replay.min_stop_time_s, color="0.5", lw=0.8, ls="-.",
               label=f"rule's minimum time {replay.min_stop_time_s:.3g} s")
    ax.set_yscale("log")
    ax.set_ylim(floor, max(1.0, float(np.nanmax(np.abs(table[[f"rel_{n}" for n in QUANTITIES]]
                                                             .to_numpy(float)))) * 1.5))
    ax.set_xlabel("simulated time at which the run stops (s)")
    ax.set_ylabel(f"|value / value at {replay.reference_time_s:.3g} s - 1|")
    ax.set_title(title or f"{replay.case.name}: time to answer", fontsize=9)
    ax.legend(fontsize=7, loc="upper right")
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, bbox_inches="tight")
    plt.close(fig)


def path_from(folder: Path, path: Path | str) -> str:
    """``path`` as written in a results file kept in ``folder``: relative to it, so a shipped
    file names its run the same in every checkout."""
    return os.path.relpath(Path(path).resolve(), Path(folder).resolve())


def write_answer(replay: AnswerReplay, folder: Path, title: str = "") -> dict[str, Path]:
    """Write ``answer.csv`` (per end time), ``answer.json`` and ``answer.png`` into ``folder``
    (created if missing); return their paths by name."""
    folder.mkdir(parents=True, exist_ok=True)
    paths = {"table": folder / "answer.csv", "summary": folder / "answer.json",
             "plot": folder / "answer.png"}
    replay.table.to_csv(paths["table"], index=False, float_format="%.10g")
    summary = replay.to_dict()
    summary["run_dir"] = path_from(folder, replay.run_dir)
    paths["summary"].write_text(json.dumps(summary, indent=2, allow_nan=False) + "\n")
    plot_answer(replay, paths["plot"], title)
    return paths
