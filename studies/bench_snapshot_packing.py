"""Benchmark: a full particle snapshot as LIGGGHTS' text and packed (drumflow.dem.dumps).

Copies one text snapshot of a run (the newest complete one, ``dem/dumps/snap.STEP.txt``) to a
scratch folder, reads it as text, packs it, reads the packed file, side by side in one run
(best of three reads each), and writes OUT.json: sizes, read times, their ratios and the
largest difference per column. The run's own files are not touched.

Usage: .venv/bin/python studies/bench_snapshot_packing.py RUN_DIR OUT.json
"""

from __future__ import annotations

import json
import platform
import shutil
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from drumflow.dem.dumps import pack_dump, read_dump


def best_read(path: Path, repeats: int = 3) -> float:
    best = float("inf")
    for _ in range(repeats):
        t0 = time.perf_counter()
        read_dump(path)
        best = min(best, time.perf_counter() - t0)
    return best


def main(argv: list[str]) -> int:
    if len(argv) != 2:
        sys.stderr.write(__doc__ or "")
        return 2
    run_dir, out = Path(argv[0]), Path(argv[1])
    texts = sorted((run_dir / "dem" / "dumps").glob("snap.*.txt"))
    if len(texts) < 2:
        sys.stderr.write(f"{run_dir}: fewer than two text snapshots (the newest may be in writing)\n")
        return 2
    source = texts[-2]  # the newest may still be being written
    with tempfile.TemporaryDirectory() as scratch:
        text = Path(scratch) / source.name
        shutil.copy2(source, text)
        text_bytes = text.stat().st_size
        text_read = best_read(text)
        before = read_dump(text)
        t0 = time.perf_counter()
        packed = pack_dump(text)
        pack_s = time.perf_counter() - t0
        packed_read = best_read(packed)
        after = read_dump(packed)
        packed_bytes = packed.stat().st_size
    diff = {name: float(np.max(np.abs(after.columns[name] - before.columns[name])))
            for name in before.columns}
    result = {
        "snapshot": str(source), "particles": len(before),
        "text_MB": text_bytes / 1e6, "packed_MB": packed_bytes / 1e6,
        "size_ratio": text_bytes / packed_bytes,
        "text_read_s": text_read, "packed_read_s": packed_read,
        "read_speedup": text_read / packed_read, "pack_s": pack_s,
        "largest_difference_per_column": diff,
        "machine": {"platform": platform.platform(), "processor": platform.processor()},
        "note": "best of three reads each, side by side in one run",
    }
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text(json.dumps(result, indent=2) + "\n")
    print(json.dumps({k: v for k, v in result.items() if k != "largest_difference_per_column"}, indent=2))
    return 0


if __name__ == "__main__":
    raise SystemExit(main(sys.argv[1:]))
