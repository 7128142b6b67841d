"""Coarse-graining's error at paper scale: a parcel run against the full-particle run (issue 11,
lever 7).

How to use::

    .venv/bin/python studies/coarse_grain_error.py FULL PARCELS OUT_DIR [--at 3.5] [--until 3.5219]

FULL and PARCELS are run directories (or shipped results folders) of the same case, PARCELS
with ``particles.coarse_grain > 1``. Compared, with the choices fixed before looking: the mean
temperature at ``--at`` s (the paper's Tables 3-4) and the cooling to it; the paper's h (Eq. 39,
:func:`drumflow.analysis.methodology.analyse_run`) and its falling mass flow over the same
window, both runs cut at ``--until`` (the full run's shipped end); and the axis-plane crossing
rate in three windows (the first crossings, the flights filling, the cascading bed), in kg/s,
each crossing counted at the mass of what crossed (a particle or a parcel). Written: OUT_DIR/
comparison.csv (one row per quantity: full, parcels, relative difference) and comparison.json
(the same with both runs' wall times, particle-steps and counts).
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from drumflow.analysis.methodology import analyse_run
from drumflow.case import load_case
from drumflow.errors import DrumflowError, exit_code

#: Crossing-rate windows, s: first crossings, flights filling, cascading bed (model two).
WINDOWS = ((1.0, 1.6), (1.6, 2.5), (2.5, 3.5))


def measure(root: Path, at_s: float, until_s: float) -> dict[str, Any]:
    """The compared quantities of one run."""
    case = load_case(root / "case.toml")
    moved = case.dem_case()
    series = pd.read_csv(root / "post" / "mean_temperature.csv")
    t_at = float(np.interp(at_s, series["time_s"], series["mean_temperature_C"]))
    method = analyse_run(root, until=until_s)
    crossings = pd.read_csv(root / "post" / "crossings.csv")
    row: dict[str, Any] = {
        f"mean_temperature_at_{at_s:g}_s_C": t_at,
        f"cooling_to_{at_s:g}_s_K": float(series["mean_temperature_C"].iloc[0]) - t_at,
        "h_eq39_W_m2K": float(method.h_mean_w_m2k),
        "falling_mass_flow_methodology_kg_s": float(method.falling_mass_flow_kg_s),
    }
    for a, b in WINDOWS:
        count = int(((crossings["time"] >= a) & (crossings["time"] < b)).sum())
        row[f"crossing_rate_{a:g}_{b:g}_s_kg_s"] = count * moved.particles.mass / (b - a)
    record = json.loads((root / "run_record.json").read_text()) if (root / "run_record.json").exists() else {}
    summary = json.loads((root / "summary.json").read_text())
    info = {"spheres": moved.particle_count, "sphere_diameter_m": moved.particles.diameter,
            "coarse_grain": case.particles.coarse_grain,
            "simulated_time_s": summary.get("simulated_time_s"),
            "dem_wall_time_s": record.get("dem_wall_time_s", summary.get("dem_wall_time_s")),
            "particle_steps_per_s": summary.get("particle_steps_per_s")}
    return {"values": row, "run": info}


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("full", type=Path)
    parser.add_argument("parcels", type=Path)
    parser.add_argument("out", type=Path)
    parser.add_argument("--at", type=float, default=3.5, help="time of the mean temperature, s")
    parser.add_argument("--until", type=float, default=3.5219, help="both runs cut here, s")
    args = parser.parse_args(argv)
    try:
        full = measure(args.full, args.at, args.until)
        parcels = measure(args.parcels, args.at, args.until)
    except (DrumflowError, OSError, KeyError) as exc:
        sys.stderr.write(f"error: {exc}\n")
        return exit_code(exc) if isinstance(exc, DrumflowError) else 2
    rows = [{"quantity": k, "full": v, "parcels": parcels["values"][k],
             "relative_difference": (parcels["values"][k] - v) / v if v else float("nan")}
            for k, v in full["values"].items()]
    args.out.mkdir(parents=True, exist_ok=True)
    table = pd.DataFrame(rows)
    table.to_csv(args.out / "comparison.csv", index=False, float_format="%.6g")
    (args.out / "comparison.json").write_text(json.dumps(
        {"full": {"dir": str(args.full), **full}, "parcels": {"dir": str(args.parcels), **parcels},
         "at_s": args.at, "until_s": args.until, "windows_s": WINDOWS, "rows": rows}, indent=2))
    print(table.to_string(index=False))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
