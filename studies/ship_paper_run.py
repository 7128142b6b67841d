"""Ship the small results of a paper run: what must last, never the dumps.

    python studies/ship_paper_run.py RUN_DIR results/paper/model_two [--no-3d]
        [--crossings-limit-mb 5] [--force]

Copies from a ``drumflow run`` directory (finished, or interrupted and post-processed with
``drumflow post RUN_DIR``) into DEST, keeping the run-directory layout so that
``drumflow paper --from results/paper`` and ``drumflow report DEST`` redraw from it:

* ``manifest.json``, ``case.toml``, ``summary.json``;
* ``post/mean_temperature.csv``, ``post/air_heat.csv``, ``post/crossings.csv`` (above
  ``--crossings-limit-mb`` gzipped, ``post/crossings.csv.gz``, with a per-time-bin summary
  ``post/crossings_summary.csv``), ``dem/coupling/rank*.csv`` (wall time per coupling update), the
  run's PNG plots (``post/*.png``, ``geometry/cross_section.png``, ``air/air_cross_section.png``);
* ``post/methodology.json`` and ``post/steps.csv`` (the paper's particle conductivity in Nu),
  when the run is long enough for the methodology; else the reason goes into the record;
* ``air/solution.json`` (the OpenFOAM solve: cells, residuals, mass flows);
* ``post/particles_times.png``: Figure 6 as the paper draws it, the section at up to four
  snapshot times on one colour scale (drawn here: the snapshots are not shipped);
* ``post/section_temperature.gif``: Figure 6 in motion, the section at every snapshot
  (:func:`drumflow.report.animation.render_animation`);
* ``post/air_side.json``: the bed and airborne h of the last snapshot in the run's air field,
  and ``post/particles_3d.png`` (Figure 6), both computed here because the snapshot and the
  100 MB air field are not shipped;
* ``run_record.json``: simulated time reached, wall times, machine, and the list of shipped
  files with their sizes.

Exit codes: 0 shipped, 2 bad input (not a run directory, no post-processing, DEST holds
another run), as every drumflow command.
"""

from __future__ import annotations

import argparse
import json
import shutil
import sys
import time
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from drumflow._json import json_safe
from drumflow.analysis.methodology import analyse_run, write_methodology
from drumflow.case import load_case
from drumflow.errors import DrumflowError, RunDirectoryError, exit_code
from drumflow.report.animation import ANIMATION, render_animation
from drumflow.report.paper_results import (
    AIR_SIDE,
    CROSSINGS_SUMMARY,
    PARTICLES_3D,
    PARTICLES_TIMES,
    RUN_RECORD,
    air_side_of_run,
    run_record,
)
from drumflow.report.snapshots import render_last_snapshot, render_snapshot_panels
from drumflow.rundir import RunDir

#: Files copied as they are when present (relative to the run directory).
COPIED = (
    "manifest.json", "case.toml", "summary.json",
    "post/mean_temperature.csv", "post/air_heat.csv",
    "post/mean_temperature.png", "post/crossings.png", "post/particles_final.png",
    "post/air_heat.png", "geometry/cross_section.png", "geometry/geometry.json",
    "air/solution.json", "air/air_cross_section.png",
)
#: Time bins of the crossings summary, s: 10 output steps of the paper's model two.
CROSSING_BIN_S = 0.1


def crossings_summary(crossings: pd.DataFrame, length_m: float) -> pd.DataFrame:
    """Crossings per time bin and axial fifth of the section (Figure 4 at a glance)."""
    t = crossings["time"].to_numpy(float)
    z = crossings["z"].to_numpy(float)
    edges = np.arange(0.0, (t.max() if t.size else 0.0) + CROSSING_BIN_S, CROSSING_BIN_S)
    if edges.size < 2:
        edges = np.array([0.0, CROSSING_BIN_S])
    z_edges = np.linspace(0.0, length_m, 6)
    counts, _, _ = np.histogram2d(t, np.clip(z, 0.0, length_m), bins=[edges, z_edges])
    table = pd.DataFrame(counts.astype(int), columns=[f"z_{a:.3g}_{b:.3g}_m" for a, b in
                                                      zip(z_edges[:-1], z_edges[1:], strict=True)])
    table.insert(0, "t_end_s", edges[1:])
    table.insert(0, "t_start_s", edges[:-1])
    table["crossings"] = table.iloc[:, 2:].sum(axis=1)
    return table


def ship(run_dir: Path, dest: Path, *, render_3d: bool = True, crossings_limit_mb: float = 5.0,
         force: bool = False) -> dict[str, Any]:
    """Copy the lasting results of ``run_dir`` into ``dest``; return the run record written.

    Raises
    ------
    RunDirectoryError
        ``run_dir`` is not a post-processed run directory, or ``dest`` holds another run.
    """
    run = RunDir.existing(run_dir)
    run.require(run.case_toml, run.manifest_path)
    if not run.mean_temperature_csv.is_file():
        raise RunDirectoryError(f"{run.root}: missing post/mean_temperature.csv; post-process the "
                                f"run first: drumflow post {run.root}")
    case = load_case(run.case_toml)
    dest = dest.resolve()
    old = dest / "manifest.json"
    if old.is_file() and not force:
        old_hash = json.loads(old.read_text()).get("case_hash")
        if old_hash and old_hash != case.hash():
            raise RunDirectoryError(f"{dest} holds the results of another case (hash {old_hash[:12]}); "
                                    "choose another destination or pass --force")
    dest.mkdir(parents=True, exist_ok=True)
    for rel in COPIED:
        src = run.root / rel
        if src.is_file():
            (dest / rel).parent.mkdir(parents=True, exist_ok=True)
            shutil.copy2(src, dest / rel)
    notes: list[str] = []

    crossings = run.crossings_csv
    if crossings.is_file():
        size_mb = crossings.stat().st_size / 1e6
        if size_mb <= crossings_limit_mb:
            shutil.copy2(crossings, dest / "post" / "crossings.csv")
        else:
            table = pd.read_csv(crossings)
            crossings_summary(table, case.drum.length).to_csv(dest / "post" / CROSSINGS_SUMMARY,
                                                              index=False)
            # Every crossing still, compressed: the time-to-answer replay counts them per
            # coupling update (drumflow.rundir.RunDir.crossings_table reads it).
            table.to_csv(dest / "post" / "crossings.csv.gz", index=False, float_format="%.6g",
                         compression={"method": "gzip", "mtime": 0})
            (dest / "post" / "crossings.csv").unlink(missing_ok=True)
            notes.append(f"post/crossings.csv is {size_mb:.1f} MB: shipped gzipped "
                         f"(post/crossings.csv.gz) with {CROSSINGS_SUMMARY} (crossings per "
                         f"{CROSSING_BIN_S:g} s and axial fifth)")

    # The coupling loop's per-update log (heat, drag, Python and LIGGGHTS wall seconds per
    # rank): the measured wall times of `drumflow answer`, a few hundred kB.
    logs = sorted(run.dem_coupling_logs.glob("rank*.csv")) if run.dem_coupling_logs.is_dir() else []
    if logs:
        target = dest / "dem" / "coupling"
        if target.is_dir():
            for old_log in target.glob("rank*.csv"):
                old_log.unlink()
        target.mkdir(parents=True, exist_ok=True)
        for log in logs:
            shutil.copy2(log, target / log.name)

    methodology_shipped = False
    try:
        # Analysed here rather than copied: the paper's particle conductivity in Nu, whatever
        # `drumflow methodology` was last run with.
        write_methodology(dest, analyse_run(run.root, nusselt_conductivity="particle"))
        methodology_shipped = True
    except DrumflowError as exc:
        notes.append(f"methodology not shipped: {exc}")

    try:
        side = air_side_of_run(run.root)
        (dest / "post" / AIR_SIDE).write_text(json.dumps(json_safe(side), indent=2, allow_nan=False))
    except DrumflowError as exc:
        notes.append(f"air side (bed and airborne h) not shipped: {exc}")

    figure6 = run.post / PARTICLES_3D
    if figure6.is_file():
        shutil.copy2(figure6, dest / "post" / PARTICLES_3D)
    elif render_3d:
        try:
            render_last_snapshot(run, case, dest / "post" / PARTICLES_3D, timeout_s=600.0)
        except (DrumflowError, OSError) as exc:
            notes.append(f"Figure 6 not rendered: {exc}")

    try:
        render_snapshot_panels(run, case, dest / "post" / PARTICLES_TIMES)
    except (DrumflowError, OSError) as exc:
        notes.append(f"Figure 6 (snapshots over time) not drawn: {exc}")
    try:
        render_animation(run, case, dest / "post" / ANIMATION)
    except (DrumflowError, OSError) as exc:
        notes.append(f"Figure 6 in motion (animation) not drawn: {exc}")

    record = run_record(run.root)
    files = sorted(p for p in dest.rglob("*") if p.is_file() and p.name != RUN_RECORD)
    record.update({
        "shipped": True,
        "shipped_at": time.strftime("%Y-%m-%dT%H:%M:%S%z"),
        "shipped_from": str(run.root),
        "methodology_shipped": methodology_shipped,
        "notes": notes,
        "files": {str(p.relative_to(dest)): p.stat().st_size for p in files},
    })
    (dest / RUN_RECORD).write_text(json.dumps(json_safe(record), indent=2, default=str) + "\n")
    return record


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=(__doc__ or "").splitlines()[0])
    parser.add_argument("run_dir", type=Path, help="a drumflow run directory (post-processed)")
    parser.add_argument("dest", type=Path, help="e.g. results/paper/model_two")
    parser.add_argument("--no-3d", dest="render_3d", action="store_false",
                        help="do not render Figure 6 from the last snapshot")
    parser.add_argument("--crossings-limit-mb", type=float, default=5.0,
                        help="ship a summary instead of post/crossings.csv above this size")
    parser.add_argument("--force", action="store_true", help="overwrite results of another case")
    args = parser.parse_args(argv)
    try:
        record = ship(args.run_dir, args.dest, render_3d=args.render_3d,
                      crossings_limit_mb=args.crossings_limit_mb, force=args.force)
    except DrumflowError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return exit_code(exc)
    total = sum(record["files"].values())
    print(f"shipped {len(record['files'])} files, {total / 1e6:.2f} MB, into {args.dest}")
    for note in record["notes"]:
        print(f"note: {note}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
