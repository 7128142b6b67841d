"""The falling mass flow of each variant of a settings study, and of the run it started from.

How to use::

    .venv/bin/python studies/variant_flow.py STUDY_DIR OUT_DIR [--run RUN_DIR] [--window 0.05]

STUDY_DIR is what ``drumflow bench CASE --from RUN_DIR --out STUDY_DIR`` wrote: every variant
ran the same simulated time from one restart, with the crossings counted in the coupling loop
(``variants/NAME/dem/coupling/crossings.csv``). For each variant, and with ``--run`` for the run
itself over the same interval (it went on from that restart at the baseline's settings: a
replicate of the baseline whose round-off differs, i.e. the noise floor of the comparison):

* OUT_DIR/flow.csv: per window of ``--window`` s, the crossings and the falling mass flow
  (crossings x particle mass / window, kg/s);
* OUT_DIR/flow.json: over the whole interval, each source's crossings and flow and its
  difference from the baseline's.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from drumflow.case import load_case


def _interval(study: Path) -> tuple[float, float, Path]:
    """Start and end time of the study's common interval, and the run it started from."""
    info = json.loads((study / "settings.json").read_text())
    run = Path(info["run_dir"])
    spec = json.loads((study / "variants" / "baseline" / "dem" / "coupling.json").read_text())
    dt = float(spec["time_step"])
    start = int(info["restart_step"]) * dt
    return start, start + int(info["steps"]) * dt, run


def flows(study: Path, run: Path | None, window: float) -> tuple[pd.DataFrame, dict[str, Any]]:
    if not window > 0:  # also refuses NaN
        raise ValueError(f"--window = {window:g} s: must be positive")
    start, end, source = _interval(study)
    mass = load_case(source / "case.toml").dem_case().particles.mass
    crossings: dict[str, pd.Series] = {}
    for folder in sorted((study / "variants").iterdir()):
        path = folder / "dem" / "coupling" / "crossings.csv"
        if path.exists():
            crossings[folder.name] = pd.read_csv(path)["time"]
    if "baseline" not in crossings:
        raise ValueError(f"{study}: no baseline crossings (run.crossings = 'loop' needed)")
    if run is not None:
        crossings["run"] = pd.read_csv(run / "dem" / "coupling" / "crossings.csv")["time"]
    # Whole windows from the start; a last part shorter than half a window joins the one before.
    edges = start + window * np.arange(int((end - start) / window + 1e-9) + 1)
    if end - edges[-1] > 0.5 * window or len(edges) == 1:
        edges = np.append(edges, end)
    else:
        edges[-1] = end
    rows = []
    totals: dict[str, Any] = {}
    for name, times in crossings.items():
        inside = times[(times >= start) & (times < end)]
        if name == "run" and float(times.max()) < end:
            raise ValueError(f"{run}: its crossings end at {float(times.max()):.4f} s, before {end:.4f} s")
        counts, _ = np.histogram(inside, bins=edges)
        for lo, hi, n in zip(edges[:-1], edges[1:], counts, strict=True):
            rows.append({"source": name, "window_start_s": lo, "window_end_s": hi,
                         "crossings": int(n), "falling_mass_flow_kg_s": n * mass / (hi - lo)})
        totals[name] = {"crossings": len(inside),
                        "falling_mass_flow_kg_s": len(inside) * mass / (end - start)}
    base = totals["baseline"]["crossings"]
    for entry in totals.values():
        entry["relative_to_baseline"] = entry["crossings"] / base - 1.0 if base else float("nan")
    summary = {"study": str(study), "run": None if run is None else str(run), "start_s": start,
               "end_s": end, "particle_mass_kg": mass, "window_s": window, "sources": totals}
    return pd.DataFrame(rows), summary


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("study", type=Path)
    parser.add_argument("out", type=Path)
    parser.add_argument("--run", type=Path, help="the run the study started from (noise floor)")
    parser.add_argument("--window", type=float, default=0.05, help="window length, s")
    args = parser.parse_args(argv)
    try:
        table, summary = flows(args.study, args.run, args.window)
    except (OSError, KeyError, ValueError) as exc:
        sys.stderr.write(f"error: {exc}\n")
        return 2
    args.out.mkdir(parents=True, exist_ok=True)
    table.to_csv(args.out / "flow.csv", index=False, float_format="%.6g")
    (args.out / "flow.json").write_text(json.dumps(summary, indent=2))
    print(table.pivot(index="window_start_s", columns="source", values="falling_mass_flow_kg_s").to_string())
    print(json.dumps(summary["sources"], indent=2))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
