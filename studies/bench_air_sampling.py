"""Benchmark: air-field sampling at particle positions (drumflow's grid against scipy).

Writes runs/bench/air_sampling.json: samples per second of drumflow.air.field.AirField.sample
and of scipy's RegularGridInterpolator on the same grid and points, measured side by side in
one run, and their ratio. Usage: .venv/bin/python studies/bench_air_sampling.py [OUT.json]
"""

from __future__ import annotations

import json
import platform
import sys
import time
from pathlib import Path

import numpy as np
from scipy.interpolate import RegularGridInterpolator

from drumflow.air.field import AirField


def rate(fn, points: np.ndarray, repeats: int = 3) -> float:
    best = np.inf
    for _ in range(repeats):
        t0 = time.perf_counter()
        fn(points)
        best = min(best, time.perf_counter() - t0)
    return len(points) / best


def main() -> None:
    out = Path(sys.argv[1]) if len(sys.argv) > 1 else Path("runs/bench/air_sampling.json")
    # 1.2 million nodes (larger than the CPU caches) and a million random particle positions:
    # one air update of a million-particle run.
    shape = (120, 120, 84)
    spacing = 0.01
    rng = np.random.default_rng(0)
    velocity = rng.random((*shape, 3))
    field = AirField(np.zeros(3), np.full(3, spacing), velocity, np.zeros(shape),
                     np.ones(shape, bool), omega=1.0)
    hi = (np.array(shape) - 1) * spacing
    points = rng.random((1_000_000, 3)) * hi
    axes = [np.arange(n) * spacing for n in shape]
    scipy_interp = RegularGridInterpolator(axes, velocity, method="linear")
    ours = rate(field.sample, points)
    theirs = rate(scipy_interp, points)
    # Same answer: both are trilinear on the same grid.
    diff = float(np.abs(field.sample(points[:1000]) - scipy_interp(points[:1000])).max())
    result = {
        "grid_nodes": int(np.prod(shape)),
        "points": len(points),
        "drumflow_samples_per_s": ours,
        "scipy_regular_grid_samples_per_s": theirs,
        "speedup": ours / theirs,
        "max_abs_difference": diff,
        "target_samples_per_s": 1e6,
        "machine": platform.platform(),
    }
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text(json.dumps(result, indent=2))
    print(json.dumps(result, indent=2))


if __name__ == "__main__":
    main()
