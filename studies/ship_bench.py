"""Copy a smoke-scene bench's measured numbers into the package (drumflow/data/measured_smoke.json).

Usage: python studies/ship_bench.py [runs/bench/smoke/results.json]

Runs record their shortcuts with these numbers in the manifest (drumflow.skips).
"""

from __future__ import annotations

import json
import sys
import time
from pathlib import Path

KEYS = ("dem_wall_time_s", "particle_steps_per_s", "fraction_of_rayleigh", "steps_per_contact",
        "err_temperature", "err_h", "err_mass_flow", "speedup_vs_conservative")


def main() -> None:
    src = Path(sys.argv[1] if len(sys.argv) > 1 else "runs/bench/smoke/results.json")
    data = json.loads(src.read_text())
    summary = data["summary"]
    import csv

    with (src.parent / "results.csv").open() as fh:
        table = list(csv.DictReader(fh))
    rows = {r["rung"]: {k: (float(r[k]) if r.get(k) not in (None, "") else None) for k in KEYS}
            for r in table if r.get("status") == "ok"}
    meta = {
        "scene": summary["scene"],
        "written": time.strftime("%Y-%m-%d", time.localtime(src.stat().st_mtime)),
        "machine": summary.get("machine"),
        "liggghts": summary.get("software", {}).get("liggghts"),
        "command": f"drumflow bench cases/{summary['scene']}.toml",
    }
    out = Path(__file__).resolve().parents[1] / "drumflow" / "data" / "measured_smoke.json"
    out.write_text(json.dumps({"source": meta, "rows": rows}, indent=1, default=str) + "\n")
    print(f"written {out} ({len(rows)} rungs)")


if __name__ == "__main__":
    main()
