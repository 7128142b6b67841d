"""The paper's cases at the physics levels of issue 31: one-way lumped (as shipped) against heat
inside the granule (``particles.interior = "shells"``), run side by side on one machine.

How to use::

    .venv/bin/python studies/interior_levels.py [--model two] [--coarse-grain 2] [--time 5]
        [--runs /var/tmp/drumflow-runs/levels] [--out results/paper/levels]

Each level is the shipped case file with only ``particles.interior`` (and the parcels and the
run's end) changed; the runs go to ``--runs`` (outside the work tree) one after the other, so
their wall times are measured on the same machine in one sitting; a finished run is reused.
Measured per run, with the choices fixed before any run (``results/paper/levels/prediction.json``
holds the prediction written first): the mean temperature at 3.5 s; h by the paper's Eq. 39
(:func:`drumflow.analysis.methodology.analyse_run`) and from the coupling log
(:func:`drumflow.analysis.published.coupling_h`); the granules' centre-minus-surface difference at
3.5 s (the interior log; 0 for lumped particles); the air's outlet temperature if it took the
heat of the slice (one-way air does not warm: this is what it would reach), and the volumetric
coefficient Q / (V (T_particles - T_air)) of the slice over 1 s to the end, beside the plant's
~290 W/(m3 K); the DEM wall time over every attempt of the run (its coupling logs). Written:
OUT/levels_model_X.csv and .json.
"""

from __future__ import annotations

import argparse
import json
import math
import subprocess
import sys
import tomllib
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
import tomli_w

ROOT = Path(__file__).resolve().parents[1]
#: The levels, as (name, particles.interior, air.warming, air around the bed). The last needs
#: ``--bed-states`` (issue 32: ``drumflow export RUN --state --phases N``).
LEVELS = (("lumped", "lumped", False, False), ("shells", "shells", False, False),
          ("shells_warming", "shells", True, False), ("around_bed", "shells", True, True))
#: The plant's measured volumetric coefficient (issue 34: its outlets imply 200-320 W/(m3 K)).
PLANT_UA = 290.0


def level_case(model: str, level: tuple[str, str, bool, bool], coarse_grain: float, end: float,
               folder: Path, bed_states: list[Path] | None = None,
               mesh_size: float | None = None, suffix: str = "") -> Path:
    """The shipped case with only the level, the parcels and the end changed (and, when given,
    the air mesh: the air around the bed solves the porous drum once per state)."""
    name, interior, warming, around = level
    data = tomllib.loads((ROOT / "cases" / f"paper_model_{model}.toml").read_text())
    mesh = "" if mesh_size is None else f"_mesh{mesh_size:g}"
    data["name"] = f"paper_model_{model}_{name}_cg{coarse_grain:g}{mesh}{suffix}"
    data["particles"]["interior"] = interior
    if warming:
        data["air"]["warming"] = True
    if around:
        if not bed_states:
            raise SystemExit(f"level {name}: give --bed-states (drumflow export RUN --state --phases N)")
        data["air"]["bed_states"] = [str(p.resolve()) for p in bed_states]
    if mesh_size is not None:
        data["air"]["mesh_size"] = mesh_size
    data["particles"]["coarse_grain"] = coarse_grain
    data["run"]["time"] = end
    folder.mkdir(parents=True, exist_ok=True)
    path = folder / f"{data['name']}.toml"
    path.write_text(tomli_w.dumps(data))
    return path


def run(case: Path, out: Path) -> None:
    """Run (or resume, or reuse) a case."""
    proc = subprocess.run([str(ROOT / ".venv" / "bin" / "drumflow"), "run", str(case), "--out", str(out)],
                          check=False)
    if proc.returncode != 0:
        raise SystemExit(f"drumflow run {case} failed with exit {proc.returncode}")


#: What is shipped of each run (small text files): enough to measure it again without the run.
SHIPPED = ("case.toml", "summary.json", "post/mean_temperature.csv", "post/air_heat.csv",
           "post/crossings.csv", "post/methodology.json", "post/steps.csv", "post/mean_temperature.png",
           "post/closures.json", "air/bed_phases.json")


def ship(out: Path, folder: Path) -> Path:
    """Copy a run's small files (:data:`SHIPPED`, and its coupling and interior logs) into
    ``folder``; return it."""
    import shutil

    for name in SHIPPED:
        if (out / name).exists():
            (folder / name).parent.mkdir(parents=True, exist_ok=True)
            shutil.copyfile(out / name, folder / name)
    _relative_bed_states(folder / "case.toml")
    logs = folder / "dem" / "coupling"
    logs.mkdir(parents=True, exist_ok=True)
    coupling = out / "dem" / "coupling"
    for log in [*coupling.glob("*rank*.csv"), *coupling.glob("air.*.csv")]:
        shutil.copyfile(log, logs / log.name)
    return folder


def _relative_bed_states(case_file: Path) -> None:
    """Name the shipped case's bed states relative to it (the loader resolves them beside the
    case file), so that the shipped case loads, and hashes as the run did, in any checkout."""
    import os

    if not case_file.exists():
        return
    data = tomllib.loads(case_file.read_text())
    states = data.get("air", {}).get("bed_states")
    if not states:
        return
    data["air"]["bed_states"] = [os.path.relpath(Path(s).resolve(), case_file.parent.resolve())
                                 for s in states]
    case_file.write_text(tomli_w.dumps(data))


def dem_wall_s(out: Path, summary: dict[str, Any]) -> float | None:
    """The DEM stage's wall seconds over every attempt of the run: the coupling logs' updates
    (:func:`drumflow.coupling.log.coupled_wall_s`). ``summary.json`` has only the last call's:
    until 2026-11-30 the table took it, and a run resumed at 3.65 s counted its last 1.35 s
    (model one's shells: 604 s of 3,995)."""
    from drumflow.coupling.log import coupled_wall_s, read_coupling

    logs = out / "dem" / "coupling"
    last = sorted(logs.glob("rank0.*.csv"), key=lambda p: int(p.name.split(".")[1]))
    if last:
        tail = pd.read_csv(last[-1]).iloc[-1]
        if float(tail["step"]) > 0:
            walls = coupled_wall_s(read_coupling(logs, float(tail["time_s"]) / float(tail["step"])))
            if walls is not None:
                return float(walls["wall_s"])
    value = summary.get("dem_wall_time_s")
    return None if value is None else float(value)


def measure(out: Path, at_s: float, until_s: float) -> dict[str, Any]:
    """The level table's numbers for one run directory (or shipped results folder), over its
    first ``until_s`` seconds (runs of different lengths compare over the same window)."""
    from drumflow.analysis.methodology import analyse_run
    from drumflow.analysis.published import coupling_h
    from drumflow.case import load_case

    case = load_case(out / "case.toml")
    summary = json.loads((out / "summary.json").read_text())
    series = pd.read_csv(out / "post" / "mean_temperature.csv")
    air_heat = pd.read_csv(out / "post" / "air_heat.csv")
    air_heat = air_heat[air_heat["time_s"] <= until_s]
    t_at = float(np.interp(at_s, series["time_s"], series["mean_temperature_C"]))
    method = analyse_run(out, until=until_s)
    log_h = coupling_h(case, air_heat, series)
    # Interior: the bed's centre-minus-surface difference at the update nearest `at_s`.
    logs = sorted((out / "dem" / "coupling").glob("interior_rank*.csv"))
    gap = 0.0
    interior_share = 0.0
    if logs:
        table = pd.concat([pd.read_csv(p) for p in logs])
        near = table.loc[(table["time_s"] - at_s).abs() == (table["time_s"] - at_s).abs().min()]
        gap = float(((near["mean_centre_C"] - near["mean_surface_C"]) * near["particles"]).sum()
                    / near["particles"].sum())
        # The interior's own wall time against the whole loop's (Python and LIGGGHTS), summed
        # over the ranks' logs: its price measured inside the run, whatever else the machine did.
        loop = pd.concat([pd.read_csv(p) for p in (out / "dem" / "coupling").glob("rank*.csv")])
        total = float(loop["python_wall_s"].sum() + loop["liggghts_wall_s"].sum())
        interior_share = float(table["interior_wall_s"].sum()) / total if total > 0 else math.nan
    window = air_heat[air_heat["time_s"] >= 1.0]
    heat_w = float(-window["heat_to_particles_W"].mean())
    t_air = case.air.inlet_temperature_C
    t_particles = float(np.interp(window["time_s"], series["time_s"], series["mean_temperature_C"]).mean())
    volume = math.pi / 4.0 * case.drum.diameter**2 * case.drum.length
    # The air's outlet: solved (air.warming, its log over the window) or, for one-way air,
    # what the heat would warm it to; the coefficient on the log-mean difference between the
    # particles and the air at inlet and outlet, as the plant's ~290 W/(m3 K) is defined.
    air_logs = sorted((out / "dem" / "coupling").glob("air.*.csv"))
    outlet_if_warmed = t_air + heat_w / (case.air.mass_flow * case.air.heat_capacity)
    outlet = outlet_if_warmed
    if air_logs:
        air = pd.concat([pd.read_csv(p) for p in air_logs])
        air = air[(air["time_s"] >= 1.0) & (air["time_s"] <= until_s)]
        outlet = float(air["outlet_C"].mean())
    contact = math.nan
    if air_logs and "heat_if_fresh_W" in air:
        contact = float(air["heat_to_air_W"].sum() / air["heat_if_fresh_W"].sum())
    from drumflow.physics.air import ideal_gas_density

    rho = ideal_gas_density(t_air, case.air.pressure_kPa)
    d_in, d_out = t_particles - t_air, t_particles - outlet
    lmtd = (d_in - d_out) / math.log(d_in / d_out) if abs(d_in - d_out) > 1e-9 else d_in
    return {
        "mean_temperature_3.5s_C": t_at,
        "h_eq39_W_m2K": float(method.h_mean_w_m2k),
        "h_coupling_log_W_m2K": float(log_h.h_run_w_m2k),
        "centre_minus_surface_3.5s_K": gap,
        "interior_share_of_loop_wall": interior_share,
        "air_outlet_if_warmed_C": outlet_if_warmed,
        "air_outlet_solved_C": outlet if air_logs else math.nan,
        "volumetric_coefficient_W_m3K": heat_w / (volume * (t_particles - t_air)),
        "volumetric_coefficient_lmtd_W_m3K": heat_w / (volume * lmtd),
        # The heat the air took over the heat with inlet air at every particle (air that warms
        # only), and the air per metre that the heat would bring to the particles' mean
        # temperature (the plant's through-curtain closure, as drumflow bed-air --heat defines it).
        "contact_efficiency": contact,
        "saturated_flow_m3_s_m": heat_w / (rho * case.air.heat_capacity * (t_particles - t_air)
                                           * case.drum.length),
        "plant_volumetric_coefficient_W_m3K": PLANT_UA,
        "energy_balance_error": summary.get("energy_balance_error"),
        "simulated_s": summary.get("simulated_time_s"),
        "window_s": [1.0, until_s],
        "dem_wall_time_s": dem_wall_s(out, summary),
        "particles": case.particle_count,
        "coarse_grain": case.particles.coarse_grain,
    }


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--model", choices=("one", "two"), default="two")
    parser.add_argument("--coarse-grain", type=float, default=2.0)
    parser.add_argument("--time", type=float, default=5.0, help="simulated end, s (>= 5)")
    parser.add_argument("--runs", type=Path, default=Path("/var/tmp/drumflow-runs/levels"))
    parser.add_argument("--out", type=Path, default=ROOT / "results" / "paper" / "levels")
    parser.add_argument("--lumped-from", type=Path, default=None,
                        help="a finished lumped run (or shipped results) of the same case and "
                        "parcels, measured over the same window instead of running it again")
    parser.add_argument("--levels", nargs="+", default=[name for name, *_ in LEVELS[:3]],
                        choices=[name for name, *_ in LEVELS])
    parser.add_argument("--bed-states", nargs="+", type=Path, default=None,
                        help="the around_bed level's air.bed_states (this scene's states)")
    parser.add_argument("--mesh-size", type=float, default=None,
                        help="air.mesh_size of every level run here, m (default the case's)")
    parser.add_argument("--suffix", default="", help="appended to the runs' and the table's names "
                        "(e.g. _1phase: the same level with another set of bed states)")
    parser.add_argument("--note", default="", help="what else ran on the machine, for the record")
    args = parser.parse_args(argv)
    rows = []
    for level in LEVELS:
        if level[0] not in args.levels:
            continue
        if level[0] == "lumped" and args.lumped_from is not None:
            out = args.lumped_from
            name = str(out.resolve().relative_to(ROOT)) if out.resolve().is_relative_to(ROOT) else out.name
        else:
            case = level_case(args.model, level, args.coarse_grain, args.time, args.runs / "cases",
                              args.bed_states, args.mesh_size, args.suffix)
            out = args.runs / case.stem
            run(case, out)
            # Measured from the shipped copy, so the table can be made again from the repository.
            out = ship(out, args.out / "runs" / out.name)
            name = str(out.relative_to(ROOT)) if out.is_relative_to(ROOT) else out.name
        rows.append({"model": args.model, "level": level[0], "run": name, **measure(out, 3.5, args.time)})
    table = pd.DataFrame(rows)
    args.out.mkdir(parents=True, exist_ok=True)
    mesh = "" if args.mesh_size is None else f"_mesh{args.mesh_size:g}"
    stem = f"levels_model_{args.model}_cg{args.coarse_grain:g}{mesh}{args.suffix}"
    table.to_csv(args.out / f"{stem}.csv", index=False, float_format="%.6g")
    (args.out / f"{stem}.json").write_text(json.dumps(
        {"machine": subprocess.run(["uname", "-a"], capture_output=True, text=True).stdout.strip(),
         "cpus": subprocess.run(["nproc"], capture_output=True, text=True).stdout.strip(),
         # The runs' wall times are what they took, not a comparison: other jobs may have
         # shared the machine. The interior's price is its share of the loop's own wall time,
         # measured inside each run (interior_share_of_loop_wall).
         "note": args.note,
         "rows": table.to_dict(orient="records")}, indent=2))
    sys.stdout.write(table.T.to_string() + "\n")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
