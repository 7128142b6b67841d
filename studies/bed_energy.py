"""A run's translational and rotational kinetic energy over time, against its spin limit.

How to use::

    .venv/bin/python studies/bed_energy.py RUN_DIR OUT_DIR [--every 0.05]

Reads the LIGGGHTS logs of RUN_DIR's DEM stage (every attempt, a resumed one superseding what
earlier attempts wrote after its restart: ``drumflow.dem.thermo.read_thermo``) and writes, one
row per ``--every`` s of simulated time:

* OUT_DIR/energy.csv: ``time_s``, ``kinetic_energy_J`` (LIGGGHTS ``ke``, translational),
  ``rotational_kinetic_energy_J`` (``compute erotate/sphere``) and ``spin_rms_rad_s``, the
  root-mean-square spin rate that energy means for the run's particles;
* OUT_DIR/energy.png: both energies over time, with the run's time step against its spin limit
  (``drumflow.dem.timestep.bed_spin_mode``) in the title.

Above the spin limit the tangential dashpot excites the spin of the bed's enduring contacts
(README, "The spin limit"): the rotational energy then rises as soon as the bed has formed and
stays about ten times what a resolved step gives.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import pandas as pd  # noqa: E402

from drumflow.case import load_case  # noqa: E402
from drumflow.dem.thermo import read_thermo  # noqa: E402
from drumflow.dem.timestep import bed_spin_mode  # noqa: E402


def energy_table(run: Path, every: float) -> pd.DataFrame:
    """One thermo row per ``every`` s (the first in each bin) with the spin rate."""
    if not every > 0:  # also refuses NaN
        raise ValueError(f"--every = {every:g} s: must be positive")
    case = load_case(run / "case.toml").dem_case()
    thermo = read_thermo(run / "dem")
    if thermo.empty:
        raise ValueError(f"{run / 'dem'}: no LIGGGHTS thermo rows")
    thermo = thermo[thermo["atoms"] > 0]
    bins = (thermo["time"] / every + 1e-9).astype(int)
    rows = thermo.groupby(bins).first().reset_index(drop=True)
    p = case.particles
    inertia = 0.4 * p.mass * p.radius**2
    spin = (2.0 * rows["ke_rot"] / (rows["atoms"] * inertia)).clip(lower=0.0) ** 0.5
    return pd.DataFrame({"time_s": rows["time"], "kinetic_energy_J": rows["ke"],
                         "rotational_kinetic_energy_J": rows["ke_rot"], "spin_rms_rad_s": spin})


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("run", type=Path)
    parser.add_argument("out", type=Path)
    parser.add_argument("--every", type=float, default=0.05, help="one row per this many s")
    args = parser.parse_args(argv)
    try:
        table = energy_table(args.run, args.every)
        case = load_case(args.run / "case.toml").dem_case()
        dt = float(json.loads((args.run / "manifest.json").read_text())["time_step"]["time_step"])
    except (OSError, KeyError, ValueError) as exc:
        sys.stderr.write(f"error: {exc}\n")
        return 2
    limit = bed_spin_mode(case, dt).time_step_limit
    args.out.mkdir(parents=True, exist_ok=True)
    table.to_csv(args.out / "energy.csv", index=False, float_format="%.6g")
    fig, ax = plt.subplots(figsize=(8, 4.5))
    ax.plot(table["time_s"], table["kinetic_energy_J"], label="translational (LIGGGHTS ke)")
    ax.plot(table["time_s"], table["rotational_kinetic_energy_J"], label="rotational (erotate/sphere)")
    ax.set_xlabel("simulated time (s)")
    ax.set_ylabel("kinetic energy (J)")
    ax.set_yscale("log")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend()
    ax.set_title(f"{case.name}: step {dt:.3g} s = {dt / limit:.2f} × the bed's spin limit "
                 f"{limit:.3g} s", fontsize=10)
    fig.tight_layout()
    fig.savefig(args.out / "energy.png", dpi=120)
    last = table.iloc[-1]
    print(f"{len(table)} rows to {last['time_s']:.3f} s; last: ke {last['kinetic_energy_J']:.4g} J, "
          f"ke_rot {last['rotational_kinetic_energy_J']:.4g} J, spin rms {last['spin_rms_rad_s']:.3g} rad/s; "
          f"step / spin limit {dt / limit:.2f}")
    return 0 if math.isfinite(limit) else 1


if __name__ == "__main__":
    raise SystemExit(main())
