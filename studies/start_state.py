"""Benchmark: a run started from a start state against the run it was taken from.

A start state (drumflow.dem.state) carries positions, velocities, spins, radii and temperatures
but not LIGGGHTS' contact history (the tangential springs), which the second run starts at
zero. This script compares the two runs over the second one's time (its thermo rows: mean
temperature, translational and rotational kinetic energy; its snapshots: mean speed and how far
the particles drift apart; the falling crossings), and measures the state itself: size, bytes
per particle, the round trip of its positions, and what float32 positions would do to the
contacts' overlaps (on a text snapshot, the %.8g original).

Usage: .venv/bin/python studies/start_state.py BASE_RUN STATE_RUN STATE.npz TEXT_SNAPSHOT OUT_DIR

BASE_RUN: the run the state was taken from (run longer than STATE_RUN); STATE_RUN: the run
started from STATE.npz; TEXT_SNAPSHOT: a full snapshot still in text (snap.STEP.txt) of the
same bed. Writes OUT_DIR/comparison.json and OUT_DIR/comparison.csv.
"""

from __future__ import annotations

import json
import platform
import sys
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
from numpy.typing import NDArray
from scipy.spatial import cKDTree

from drumflow.dem.dumps import dump_files, dump_step, read_dump
from drumflow.dem.state import read_state
from drumflow.dem.thermo import read_thermo

#: Particles of paper model one, for the size a state of it would have.
MODEL_ONE_PARTICLES = 467_443


def overlaps(x: NDArray[np.float64], r: NDArray[np.float64],
             pairs: NDArray[np.int64] | None = None) -> tuple[NDArray[np.int64], NDArray[np.float64]]:
    """Every pair closer than two radii (or the given pairs) and its overlap, m."""
    if pairs is None:
        pairs = cKDTree(x).query_pairs(2.0 * float(r.max()), output_type="ndarray")
    d = np.linalg.norm(x[pairs[:, 0]] - x[pairs[:, 1]], axis=1)
    return pairs, r[pairs[:, 0]] + r[pairs[:, 1]] - d


def precision(text_snapshot: Path) -> dict[str, Any]:
    """What float32 positions would do to the overlaps of a text snapshot's contacts."""
    s = read_dump(text_snapshot)
    x = np.column_stack([s.columns[c] for c in "xyz"])
    r = s.columns["radius"]
    pairs, ov = overlaps(x, r)
    _, ov32 = overlaps(x.astype(np.float32).astype(np.float64), r, pairs)
    touching = ov > 0
    change = np.abs(ov32 - ov)[touching]
    text = text_snapshot.read_text().splitlines()[9:]
    # The three spin columns are the 8th to 10th of each row: their characters and spaces.
    spin_chars = sum(sum(len(f) + 1 for f in line.split()[7:10]) for line in text)
    return {
        "snapshot": str(text_snapshot),
        "contacts": int(touching.sum()),
        "max_overlap_m": float(ov.max()),
        "mean_overlap_m": float(ov[touching].mean()),
        "float32_positions": {
            "max_overlap_change_m": float(change.max()),
            "median_relative_overlap_change": float(np.median(change / ov[touching])),
            "contacts_overlapping_more": int((ov32 > ov)[touching].sum()),
            "max_overlap_m": float(ov32.max()),
        },
        "float64_positions": {"max_overlap_change_m": 0.0, "contacts_overlapping_more": 0},
        "snapshot_text_bytes_per_particle": text_snapshot.stat().st_size / len(s),
        "spin_columns_text_bytes_per_particle": spin_chars / len(s),
        "spin_columns_packed_bytes_per_particle": 12,
    }


def round_trip(state_path: Path, base: Path) -> dict[str, Any]:
    """The state against the snapshot it was made from, and its size."""
    state = read_state(state_path)
    source = next(p for p in dump_files(base / "dem" / "dumps") if dump_step(p) == state.step)
    snap = read_dump(source)
    x = np.column_stack([snap.columns[c] for c in "xyz"])
    size = state_path.stat().st_size
    restarts = sorted((base / "dem" / "restart").glob("drum.*.restart"))
    return {
        "state": str(state_path), "particles": len(state), "time_s": state.time_s,
        "bytes": size, "bytes_per_particle": size / len(state),
        "model_one_MB_estimate": size / len(state) * MODEL_ONE_PARTICLES / 1e6,
        "restart_bytes_per_particle": (restarts[-1].stat().st_size / len(state)) if restarts else None,
        "source_snapshot": str(source),
        "max_position_difference_m": float(np.abs(state.positions - x).max()),
        "max_temperature_difference_K": float(np.abs(state.temperatures_C - snap.columns["T"]).max()),
        "max_velocity_difference_m_s": float(np.abs(
            state.velocities - np.column_stack([snap.columns[c] for c in ("vx", "vy", "vz")])).max()),
    }


def compare(base: Path, started: Path) -> tuple[dict[str, Any], pd.DataFrame]:
    """The two runs over the started one's time, row by row (thermo) and snapshot by snapshot."""
    a = read_thermo(base / "dem").set_index("step")
    b = read_thermo(started / "dem").set_index("step")
    steps = b.index.intersection(a.index)
    table = pd.DataFrame({"step": steps, "time_s": b.loc[steps, "time"].to_numpy()})
    for column, name in (("T_mean", "T_mean"), ("ke", "ke"), ("ke_rot", "ke_rot")):
        unit = "C" if column == "T_mean" else "J"
        table[f"{name}_base_{unit}"] = a.loc[steps, column].to_numpy()
        table[f"{name}_state_{unit}"] = b.loc[steps, column].to_numpy()
    table["T_mean_difference_K"] = table["T_mean_state_C"] - table["T_mean_base_C"]
    table["ke_relative_difference"] = table["ke_state_J"] / table["ke_base_J"] - 1.0
    table["ke_rot_relative_difference"] = table["ke_rot_state_J"] / table["ke_rot_base_J"] - 1.0
    snaps = []
    base_snaps = {dump_step(p): p for p in dump_files(base / "dem" / "dumps")}
    for p in dump_files(started / "dem" / "dumps"):
        q = base_snaps.get(dump_step(p))
        if q is None:
            continue
        sa, sb = read_dump(q), read_dump(p)
        va = np.column_stack([sa.columns[c] for c in ("vx", "vy", "vz")])
        vb = np.column_stack([sb.columns[c] for c in ("vx", "vy", "vz")])
        xa = np.column_stack([sa.columns[c] for c in "xyz"])
        xb = np.column_stack([sb.columns[c] for c in "xyz"])
        snaps.append({
            "step": dump_step(p), "time_s": float(b["time"].get(dump_step(p), np.nan)),
            "mean_speed_base_m_s": float(np.linalg.norm(va, axis=1).mean()),
            "mean_speed_state_m_s": float(np.linalg.norm(vb, axis=1).mean()),
            "rms_position_difference_m": float(np.sqrt(np.mean(np.sum((xa - xb) ** 2, axis=1)))),
            "max_position_difference_m": float(np.linalg.norm(xa - xb, axis=1).max()),
        })
    t0, t1 = float(table["time_s"].iloc[0]), float(table["time_s"].iloc[-1])
    crossings = {}
    for name, run in (("base", base), ("state", started)):
        c = pd.read_csv(run / "post" / "crossings.csv")
        crossings[name] = int(((c["time"] > t0) & (c["time"] <= t1)).sum())
    summary = {
        "window_s": [t0, t1],
        "thermo_rows": len(table),
        "max_abs_T_mean_difference_K": float(table["T_mean_difference_K"].abs().max()),
        "T_mean_drop_base_K": float(table["T_mean_base_C"].iloc[0] - table["T_mean_base_C"].iloc[-1]),
        "T_mean_drop_state_K": float(table["T_mean_state_C"].iloc[0] - table["T_mean_state_C"].iloc[-1]),
        "ke_mean_base_J": float(table["ke_base_J"].mean()),
        "ke_mean_state_J": float(table["ke_state_J"].mean()),
        "max_abs_ke_relative_difference": float(table["ke_relative_difference"].abs().max()),
        "ke_rot_mean_base_J": float(table["ke_rot_base_J"].mean()),
        "ke_rot_mean_state_J": float(table["ke_rot_state_J"].mean()),
        "max_abs_ke_rot_relative_difference": float(table["ke_rot_relative_difference"].abs().max()),
        "first_row_ke_relative_difference": float(table["ke_relative_difference"].iloc[0]),
        "first_row_T_mean_difference_K": float(table["T_mean_difference_K"].iloc[0]),
        "falling_crossings_in_window": crossings,
        "snapshots": snaps,
    }
    return summary, table


def main(argv: list[str]) -> int:
    if len(argv) != 5:
        sys.stderr.write(__doc__ or "")
        return 2
    base, started, state, text, out = (Path(a) for a in argv)
    summary, table = compare(base, started)
    result = {
        "compared": "run from the start state against the run it was taken from, same case "
                    "scene, air.model uniform, 1 process",
        "state": round_trip(state, base),
        "precision": precision(text),
        "comparison": summary,
        "machine": {"platform": platform.platform(), "processor": platform.processor()},
    }
    out.mkdir(parents=True, exist_ok=True)
    (out / "comparison.json").write_text(json.dumps(result, indent=2) + "\n")
    table.to_csv(out / "comparison.csv", index=False, float_format="%.10g")
    return 0


if __name__ == "__main__":
    raise SystemExit(main(sys.argv[1:]))
