"""What sets the mean temperature of a one-way slice: the h its particles see, per air field.

Reads the full snapshots of a drumflow run (``dem/dumps/snap.*.txt``) and samples one or more
saved air fields (``field.npz``: the run's own, or the same drum solved on other meshes) at
every particle, with the particles' own velocities. For each field and snapshot it writes the
surface-mean Ranz-Marshall h over all, bed and airborne particles, and the mean temperature at
3.5 s that a lumped particle would reach at that h (drumflow.analysis.air_side). No solver.

    python studies/air_side_study.py RUN_DIR --field coarse=PATH.npz --field fine=PATH.npz \
        --out results/paper/model_two/air_side.csv [--paper-h 38.93]

The run's case gives the drum speed, the air temperature and the particle properties.
"""

from __future__ import annotations

import argparse
import csv
import sys
from pathlib import Path

import numpy as np

from drumflow.air.field import AirField
from drumflow.analysis.air_side import lumped_mean_temperature, sample_air_side
from drumflow.case import load_case
from drumflow.dem.dumps import dump_files, read_dump


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("run_dir", type=Path)
    parser.add_argument("--field", action="append", default=[], metavar="NAME=PATH",
                        help="an air field to sample (repeat); default: the run's air/field.npz")
    parser.add_argument("--out", type=Path, required=True, help="CSV to write")
    parser.add_argument("--paper-h", type=float, default=None,
                        help="also give the lumped temperature at the paper's h")
    parser.add_argument("--at", type=float, default=3.5, help="time of the temperature, s")
    args = parser.parse_args(argv)

    case = load_case(args.run_dir / "case.toml")
    fields = dict(f.split("=", 1) for f in args.field) or {"run": str(args.run_dir / "air" / "field.npz")}
    manifest_dt = _time_step(args.run_dir)
    snaps = dump_files(args.run_dir / "dem" / "dumps", "snap")
    if not snaps:
        print(f"{args.run_dir}: no snapshots yet", file=sys.stderr)
        return 2
    rows = []
    for name, path in fields.items():
        field = AirField.from_npz(Path(path))
        for snap_path in snaps:
            snap = read_dump(snap_path)
            t = snap.step * manifest_dt
            s = sample_air_side(case, field, snap.columns, t)
            t_lumped = float(lumped_mean_temperature(case, s.h_mean_w_m2k, np.array([args.at]))[0])
            rows.append({"field": name, "cells": field.meta.get("cells", ""), **s.to_dict(),
                         f"lumped_T_at_{args.at:g}s_C": t_lumped})
    if args.paper_h is not None:
        t_paper = float(lumped_mean_temperature(case, args.paper_h, np.array([args.at]))[0])
        rows.append({"field": "paper h", "h_mean_w_m2k": args.paper_h,
                     f"lumped_T_at_{args.at:g}s_C": t_paper})
    args.out.parent.mkdir(parents=True, exist_ok=True)
    keys: list[str] = []
    for r in rows:
        keys += [k for k in r if k not in keys]
    with args.out.open("w", newline="") as fh:
        writer = csv.DictWriter(fh, fieldnames=keys)
        writer.writeheader()
        writer.writerows(rows)
    for r in rows:
        print({k: (round(v, 4) if isinstance(v, float) else v) for k, v in r.items()})
    return 0


def _time_step(run_dir: Path) -> float:
    import json

    manifest = json.loads((run_dir / "manifest.json").read_text())
    for key in ("time_step", "dem"):
        value = manifest.get(key)
        if isinstance(value, dict) and "time_step" in value:
            return float(value["time_step"])
        if isinstance(value, (int, float)):
            return float(value)
    raise SystemExit(f"{run_dir}/manifest.json: no time step recorded")


if __name__ == "__main__":
    raise SystemExit(main())
