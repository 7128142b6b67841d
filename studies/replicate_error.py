"""Two runs of one case, side by side: how far apart a replicate lands, and how fast each ran.

How to use::

    .venv/bin/python studies/replicate_error.py FIRST SECOND OUT_DIR [--until T] [--window 0.5]
                                                [--progress]

FIRST and SECOND are run directories (or shipped results folders, see
``studies/ship_paper_run.py``) of the same case (same physics; the launch, the processor grid
and the attempt history may differ, so their round-off does and the trajectories part
chaotically), or of two cases that differ only in the fields named by ``--differ FIELD``
(``--differ name --differ run.time_step``: one setting against another). Compared over the
output times both reached, up to ``--until``:

* the mean temperature (post/mean_temperature.csv): the largest difference over all common
  times, the difference at the last one, and the cooling from the start to it;
* per window of ``--window`` s: the mean temperature at its end, the crossings' falling mass
  flow (post/crossings.csv, kg/s) and the coupling loop's wall seconds per simulated second
  (its own timing of each update, paused updates left out; NaN where no update logged one).

Written: OUT_DIR/replicate.csv (one row per window) and OUT_DIR/replicate.json (the summary and
both runs' sources). With ``--progress``, also OUT_DIR/progress.csv: the same windows for the
SECOND run alone over everything it has reached (a run still going past the first's end). The
difference of two replicates is the noise floor of a comparison: what chaos and round-off alone
move. The wall rates are each run's own: two runs on one machine at different times are not a
side-by-side speed ratio.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from drumflow.case import load_case
from drumflow.coupling.log import read_coupling, update_walls
from drumflow.errors import DrumflowError, exit_code


def _series(root: Path) -> pd.DataFrame:
    return pd.read_csv(root / "post" / "mean_temperature.csv")


def _crossings(root: Path) -> pd.Series:
    for name in ("crossings.csv", "crossings.csv.gz"):
        if (root / "post" / name).exists():
            return pd.read_csv(root / "post" / name)["time"]
    raise FileNotFoundError(f"{root / 'post'}: no crossings.csv")


def _time_step(root: Path) -> float:
    return float(json.loads((root / "manifest.json").read_text())["time_step"]["time_step"])


def _window_edges(end: float, window: float) -> np.ndarray:
    """0, window, 2 window, ... and ``end`` itself when it falls between two of them."""
    if not window > 0:  # also refuses NaN
        raise ValueError(f"--window = {window:g} s: must be positive")
    edges = np.arange(0.0, end + 1e-9, window)
    return np.append(edges, end) if edges[-1] < end - 1e-9 else edges


def _count(times: pd.Series, lo: float, hi: float) -> int:
    return int(((times >= lo) & (times < hi)).sum())


def _wall_per_window(root: Path, time_step: float, edges: np.ndarray) -> np.ndarray:
    """Wall seconds per simulated second in each window, from the unpaused logged updates."""
    coupling = read_coupling(root / "dem" / "coupling", time_step)
    out = np.full(len(edges) - 1, np.nan)
    if coupling.empty:
        return out
    updates = update_walls(coupling)
    updates = updates[~updates["paused"].astype(bool)]
    for i, (a, b) in enumerate(zip(edges[:-1], edges[1:], strict=True)):
        inside = updates[(updates["time_s"] >= a) & (updates["time_s"] < b)]
        simulated = float((inside["steps"] * time_step).sum())
        if simulated > 0.5 * (b - a):  # most of the window logged
            out[i] = float(inside["wall_s"].sum()) / simulated
    return out


def _case_differences(a: dict[str, Any], b: dict[str, Any], prefix: str = "") -> list[str]:
    """Dotted names of the fields where two case dumps differ."""
    out = []
    for key in sorted(set(a) | set(b)):
        x, y = a.get(key), b.get(key)
        if isinstance(x, dict) and isinstance(y, dict):
            out += _case_differences(x, y, f"{prefix}{key}.")
        elif x != y:
            out.append(f"{prefix}{key}")
    return out


def compare(first: Path, second: Path, until: float, window: float,
            differ: tuple[str, ...] = ()) -> tuple[pd.DataFrame, dict[str, Any]]:
    """The per-window table and the summary (see the module docstring). ``differ`` names the
    case fields the two runs may differ in (``run.time_step``: a comparison of two settings)."""
    case_a, case_b = load_case(first / "case.toml"), load_case(second / "case.toml")
    differences = _case_differences(case_a.model_dump(), case_b.model_dump())
    unexpected = [name for name in differences if name not in differ]
    if unexpected:
        raise ValueError(f"{first} and {second} are not runs of the same case: they differ in "
                         f"{', '.join(unexpected)} (--differ FIELD allows a field)")
    moved = case_a.dem_case()
    mass = moved.particles.mass
    a, b = _series(first), _series(second)
    merged = a.merge(b, on="time_s", suffixes=("_a", "_b"))
    merged = merged[merged["time_s"] <= until + 1e-9]
    if len(merged) < 2:
        raise ValueError("the two runs share fewer than two output times")
    diff = merged["mean_temperature_C_b"] - merged["mean_temperature_C_a"]
    end = float(merged["time_s"].iloc[-1])
    t0 = float(merged["mean_temperature_C_a"].iloc[0])
    cooling_a = t0 - float(merged["mean_temperature_C_a"].iloc[-1])
    cooling_b = float(merged["mean_temperature_C_b"].iloc[0]) - float(merged["mean_temperature_C_b"].iloc[-1])
    edges = _window_edges(end, window)
    cross_a, cross_b = _crossings(first), _crossings(second)
    wall_a = _wall_per_window(first, _time_step(first), edges)
    wall_b = _wall_per_window(second, _time_step(second), edges)

    def flow(times: pd.Series, lo: float, hi: float) -> float:
        return _count(times, lo, hi) * mass / (hi - lo)

    rows = []
    for i, (lo, hi) in enumerate(zip(edges[:-1], edges[1:], strict=True)):
        at = merged[merged["time_s"] <= hi + 1e-9].iloc[-1]
        rows.append({
            "window_start_s": lo, "window_end_s": hi,
            "temperature_first_C": float(at["mean_temperature_C_a"]),
            "temperature_second_C": float(at["mean_temperature_C_b"]),
            "temperature_difference_K": float(at["mean_temperature_C_b"] - at["mean_temperature_C_a"]),
            "falling_mass_flow_first_kg_s": flow(cross_a, lo, hi),
            "falling_mass_flow_second_kg_s": flow(cross_b, lo, hi),
            "wall_s_per_simulated_s_first": wall_a[i],
            "wall_s_per_simulated_s_second": wall_b[i],
        })
    summary = {
        "first": str(first), "second": str(second), "case": case_a.name, "differ_in": differences,
        "common_output_times": len(merged), "last_common_time_s": end, "window_s": window,
        "max_abs_temperature_difference_K": float(np.abs(diff).max()),
        "temperature_difference_at_end_K": float(diff.iloc[-1]),
        "cooling_first_K": cooling_a, "cooling_second_K": cooling_b,
        "cooling_relative_difference": (cooling_b - cooling_a) / cooling_a if cooling_a else math.nan,
        "crossings_first": int((cross_a <= end).sum()), "crossings_second": int((cross_b <= end).sum()),
    }
    return pd.DataFrame(rows), summary


def progress(run: Path, window: float) -> pd.DataFrame:
    """One run alone, per window of ``window`` s over its whole length: the mean temperature at
    the window's end, the crossings (count and falling mass flow, kg/s) and the wall seconds per
    simulated second."""
    case = load_case(run / "case.toml")
    mass = case.dem_case().particles.mass
    series = _series(run)
    end = float(series["time_s"].iloc[-1])
    edges = _window_edges(end, window)
    crossings = _crossings(run)
    wall = _wall_per_window(run, _time_step(run), edges)
    rows = []
    for i, (lo, hi) in enumerate(zip(edges[:-1], edges[1:], strict=True)):
        count = _count(crossings, lo, hi)
        at = series[series["time_s"] <= hi + 1e-9].iloc[-1]
        rows.append({"window_start_s": lo, "window_end_s": hi,
                     "temperature_C": float(at["mean_temperature_C"]), "crossings": count,
                     "falling_mass_flow_kg_s": count * mass / (hi - lo),
                     "wall_s_per_simulated_s": wall[i]})
    return pd.DataFrame(rows)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("first", type=Path)
    parser.add_argument("second", type=Path)
    parser.add_argument("out", type=Path)
    parser.add_argument("--until", type=float, default=math.inf, help="compare up to this time, s")
    parser.add_argument("--window", type=float, default=0.5, help="window length, s")
    parser.add_argument("--differ", action="append", default=[], metavar="FIELD",
                        help="a case field the two runs may differ in (e.g. run.time_step); repeat")
    parser.add_argument("--progress", action="store_true",
                        help="also write progress.csv: the second run alone over all it reached")
    args = parser.parse_args(argv)
    try:
        table, summary = compare(args.first, args.second, args.until, args.window, tuple(args.differ))
        ahead = progress(args.second, args.window) if args.progress else None
    except (DrumflowError, OSError, KeyError, ValueError) as exc:
        sys.stderr.write(f"error: {exc}\n")
        return exit_code(exc) if isinstance(exc, DrumflowError) else 2
    args.out.mkdir(parents=True, exist_ok=True)
    table.to_csv(args.out / "replicate.csv", index=False, float_format="%.6g")
    (args.out / "replicate.json").write_text(json.dumps(summary, indent=2))
    if ahead is not None:
        ahead.to_csv(args.out / "progress.csv", index=False, float_format="%.6g")
        print(ahead.to_string(index=False))
    print(table.to_string(index=False))
    print(json.dumps(summary, indent=2))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
