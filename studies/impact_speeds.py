"""Impact speeds at paper scale from a run's snapshots, and the DEM step they allow (issue 11).

Usage: python studies/impact_speeds.py RUN_DIR OUT_DIR [--from-time 2.5] [--gap 0.1]
                                       [--check-gap 0.05]

Reads RUN_DIR/case.toml, RUN_DIR/manifest.json (the time step, to date the snapshots) and
RUN_DIR/dem/dumps/snap.*.txt (read-only). Every snapshot gets its own rows; snapshots at
t >= --from-time (the cascading regime) are pooled. Gaps are fractions of a particle diameter:
--gap is the window reported, --check-gap a second one that shows the result does not depend on
it. Writes OUT_DIR/impact_speeds.csv, impact_speeds.json and impact_speeds.png. The method is
the docstring of drumflow.dem.impacts.
"""

from __future__ import annotations

import argparse
import csv
import json
import math
import sys
import time
from pathlib import Path
from typing import Any, Literal

import numpy as np

from drumflow.case import Case, load_case
from drumflow.dem import impacts
from drumflow.dem.collision_speed import G, impact_velocity
from drumflow.dem.dumps import dump_files, read_dump
from drumflow.dem.impacts import WALL_EQUIVALENT_SPEED_FACTOR, ImpactSample
from drumflow.dem.timestep import MIN_STEPS_PER_CONTACT, choose_time_step
from drumflow.errors import DrumflowError

QUANTILES = (0.5, 0.9, 0.99, 0.999, 1.0)
QNAMES = ("q50", "q90", "q99", "q99.9", "max")
POPULATIONS = ("particle-particle", "particle-wall", "all")
# "all" pools wall impacts at their sphere-sphere equivalent speed (same contact time).


def _samples(snap_cols: dict[str, np.ndarray], case: Case, gap: float) -> dict[str, ImpactSample]:
    x, v, r = impacts.snapshot_kinematics(snap_cols)
    pp = impacts.approaching_pairs(x, v, r, gap)
    pw = impacts.wall_approaches(x, v, r, gap, case.drum.radius, 0.0, case.drum.length)
    both = impacts.pool([pp, pw], speed_factors=[1.0, WALL_EQUIVALENT_SPEED_FACTOR], instants=1)
    return {"particle-particle": pp, "particle-wall": pw, "all": both}


def _quantiles(s: ImpactSample) -> list[float]:
    return [float(q) for q in impacts.weighted_quantiles(s.speed, s.weight, QUANTILES)]


def _row(step: object, t: object, pooled: object, gap_frac: float, gap: float, pop: str,
         s: ImpactSample) -> dict[str, Any]:
    row: dict[str, Any] = {"snapshot_step": step, "time_s": t, "pooled": pooled,
                           "gap_diameters": gap_frac, "gap_m": gap, "population": pop,
                           "n_approaching": len(s), "impact_rate_per_s": s.rate}
    row.update(dict(zip(QNAMES, _quantiles(s), strict=True)))
    return row


def _steps_block(speeds: list[float], case: Case, dt_now: float, dt_cap: float,
                 v_max: float, kind: Literal["particle", "wall"]) -> dict[str, Any]:
    p = case.particles
    dts = impacts.implied_time_steps(speeds, p.radius, p.density, p.youngs_modulus,
                                     p.poisson_ratio, contact=kind)
    t_max = impacts.implied_time_steps([v_max], p.radius, p.density, p.youngs_modulus,
                                       p.poisson_ratio, steps_per_contact=1.0,
                                       contact=kind)[0]
    return {
        "implied_time_step_s": [float(d) for d in dts],
        "ratio_to_current": [float(d / dt_now) for d in dts],
        "implied_time_step_capped_s": [float(min(d, dt_cap)) for d in dts],
        "ratio_to_current_capped": [float(min(d, dt_cap) / dt_now) for d in dts],
        "steps_per_contact_at_max_speed": [float(t_max / d) for d in dts],
    }


def _plot(out: Path, pooled: dict[float, dict[str, ImpactSample]], gaps: list[float],
          diameter: float, v_design: float, summary: dict[str, Any]) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    main, check = gaps[0], gaps[1] if len(gaps) > 1 else None
    pp = pooled[main]["particle-particle"]
    pw = pooled[main]["particle-wall"]
    lo = max(1e-3, float(np.min(pp.speed)) if len(pp) else 1e-3)
    hi = max(2.0 * v_design, float(np.max(pp.speed)) if len(pp) else 0.0)
    bins = [float(b) for b in np.logspace(math.log10(lo), math.log10(hi), 81)]
    total = float(np.sum(pp.weight) + np.sum(pw.weight))
    fig, ax = plt.subplots(figsize=(9, 5.5))
    ax.hist(pp.speed, bins=bins, weights=pp.weight / total, histtype="stepfilled", alpha=0.45,
            color="C0", label=f"particle-particle, gap <= {main:g} d")
    ax.hist(pw.speed, bins=bins, weights=pw.weight / total, histtype="step", color="C2", lw=1.5,
            label=f"particle-wall (shell, end plates), gap <= {main:g} d")
    if check is not None:
        c = pooled[check]["particle-particle"]
        ctot = float(np.sum(c.weight) + np.sum(pooled[check]["particle-wall"].weight))
        ax.hist(c.speed, bins=bins, weights=c.weight / ctot, histtype="step", color="k", ls="--",
                lw=1.0, label=f"particle-particle, gap <= {check:g} d")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("impact (normal approach) speed, m/s")
    ax.set_ylabel("fraction of impacts per bin (rate-weighted)")
    entry = summary["gaps"][f"{main:g}"]["particle-particle"]
    qs, ratios = entry["quantiles_m_per_s"], entry["ratio_to_current"]
    for name, vq, rq, ls in zip(QNAMES, qs, ratios, (":", ":", "-.", "--", "-"), strict=True):
        ax.axvline(vq, color="C1", ls=ls, lw=1.2,
                   label=f"pp {name} = {vq:.2f} m/s: step x {rq:.2f}")
    ax.axvline(v_design, color="C3", lw=2.0,
               label=f"design speed sqrt(2 g D) = {v_design:.2f} m/s (current step)")
    top = ax.secondary_xaxis("top", functions=(lambda v: (v_design / np.maximum(v, 1e-9)) ** 0.2,
                                               lambda r: v_design / np.maximum(r, 1e-9) ** 5))
    from matplotlib.ticker import FixedLocator, NullLocator, ScalarFormatter

    top.xaxis.set_major_locator(FixedLocator([1.0, 1.2, 1.5, 2.0, 3.0, 4.0, 5.0]))
    top.xaxis.set_minor_locator(NullLocator())
    top.xaxis.set_major_formatter(ScalarFormatter())
    top.set_xlabel("step allowed at 10 steps per contact / current step "
                   f"= ({v_design:.2f} m/s / v)^(1/5)")
    t_pool = summary["pooled_times_s"]
    fig.suptitle(f"{summary['case']}: rate-weighted impact speeds, "
                 f"{summary['snapshots_pooled']} snapshots at t = {t_pool[0]:.2f}-{t_pool[-1]:.2f} s, "
                 f"d = {diameter * 1e3:g} mm", fontsize=10)
    ax.legend(fontsize=7.5, loc="upper right")
    ax.grid(True, which="both", alpha=0.25)
    fig.tight_layout()
    fig.savefig(out, dpi=130)
    plt.close(fig)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("run_dir", type=Path)
    ap.add_argument("out_dir", type=Path)
    ap.add_argument("--from-time", type=float, default=2.5,
                    help="pool snapshots at or after this time, s (default 2.5)")
    ap.add_argument("--gap", type=float, default=0.1,
                    help="gap window, in particle diameters (default 0.1)")
    ap.add_argument("--check-gap", type=float, default=0.05,
                    help="a second window to check independence (default 0.05; 0 to skip)")
    args = ap.parse_args(argv)
    try:
        return _run(args)
    except DrumflowError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2


def _run(args: argparse.Namespace) -> int:
    run: Path = args.run_dir
    case = load_case(run / "case.toml")
    choice = choose_time_step(case)
    manifest = json.loads((run / "manifest.json").read_text()) if (run / "manifest.json").exists() else {}
    dt_run = float(manifest.get("time_step", {}).get("time_step", choice.time_step))
    files = dump_files(run / "dem" / "dumps", "snap")
    if not files:
        print(f"error: no snapshots in {run / 'dem' / 'dumps'}", file=sys.stderr)
        return 2
    d = case.particles.diameter
    gap_fracs = [args.gap] + ([args.check_gap] if args.check_gap > 0 else [])
    rows: list[dict[str, Any]] = []
    per_snap: dict[float, list[dict[str, ImpactSample]]] = {g: [] for g in gap_fracs}
    times: list[float] = []
    steps: list[int] = []
    t0 = time.time()
    for f in files:
        snap = read_dump(f)
        t = snap.step * dt_run
        in_pool = t >= args.from_time - 1e-9
        for g in gap_fracs:
            samples = _samples(snap.columns, case, g * d)
            for pop in POPULATIONS:
                rows.append(_row(snap.step, round(t, 4), in_pool, g, g * d, pop, samples[pop]))
            if in_pool:
                per_snap[g].append(samples)
        if in_pool:
            times.append(t)
            steps.append(snap.step)
        print(f"  {f.name}: t = {t:.3f} s, {len(snap)} particles, pooled={in_pool} "
              f"({time.time() - t0:.0f} s)", flush=True)
    if not times:
        print(f"error: no snapshot at t >= {args.from_time} s", file=sys.stderr)
        return 2

    v_design = impact_velocity(case)
    dt_now = choice.time_step
    dt_cap = case.run.rayleigh_fraction * choice.rayleigh_time
    p = case.particles
    pooled: dict[float, dict[str, ImpactSample]] = {}
    summary: dict[str, Any] = {
        "case": case.name,
        "run_dir": str(run.resolve()),
        "method": impacts.__doc__,
        "snapshots_pooled": len(times),
        "pooled_steps": steps,
        "pooled_times_s": [round(t, 4) for t in times],
        "material": {"diameter_m": d, "density_kg_m3": p.density,
                     "youngs_modulus_Pa": p.youngs_modulus, "poisson_ratio": p.poisson_ratio,
                     "restitution_pp": case.contacts.particle_particle.restitution,
                     "restitution_pw": case.contacts.particle_wall.restitution,
                     "drum_diameter_m": case.drum.diameter, "rpm": case.drum.rpm,
                     "shell_speed_m_per_s": case.drum.omega * case.drum.radius},
        "current": {"design_impact_speed_m_per_s": v_design,
                    "time_step_s": dt_now, "time_step_in_manifest_s": dt_run,
                    "hertz_time_at_design_speed_s": choice.hertz_time,
                    "rayleigh_time_s": choice.rayleigh_time,
                    "rayleigh_fraction_cap": case.run.rayleigh_fraction,
                    "rayleigh_cap_time_step_s": dt_cap,
                    "rayleigh_cap_ratio_to_current": dt_cap / dt_now,
                    "half_rayleigh_stability_limit_s": 0.5 * choice.rayleigh_time,
                    "steps_per_contact": MIN_STEPS_PER_CONTACT},
        "quantile_levels": list(QUANTILES),
        "quantile_names": list(QNAMES),
        "notes": {
            "ratio_to_current": "t_H(v_q) / 10 over the current step (= t_H(7.67 m/s) / 10): "
                                "(7.67 / v_q)^(1/5)",
            "capped": "also limited by the case's Rayleigh fraction (run.rayleigh_fraction x t_R)",
            "all": "particle-particle and particle-wall impacts pooled, wall impacts at half "
                   "their speed (a sphere-wall Hertz contact at v lasts as long as a "
                   "sphere-sphere one at v/2)",
            "walls": "shell (normal velocity 0: it turns about its axis) and the two end plates; "
                     "lifters are not counted",
        },
        "gaps": {},
    }
    for g in gap_fracs:
        pooled[g] = {pop: impacts.pool([s[pop] for s in per_snap[g]]) for pop in POPULATIONS}
        block: dict[str, Any] = {"gap_m": g * d}
        for pop in POPULATIONS:
            s = pooled[g][pop]
            qs = _quantiles(s)
            per = np.array([_quantiles(x[pop]) for x in per_snap[g]])
            entry: dict[str, Any] = {
                "n_approaching": len(s),
                "impact_rate_per_s": s.rate,
                "quantiles_m_per_s": qs,
                "per_snapshot_min": [float(v) for v in np.nanmin(per, axis=0)],
                "per_snapshot_max": [float(v) for v in np.nanmax(per, axis=0)],
                "pairs_above_quantile": [int(np.sum(s.speed > q)) for q in qs],
                "unweighted_quantiles_m_per_s": [float(v) for v in
                                                 np.quantile(s.speed, QUANTILES)] if len(s) else [],
                "gravity_gain_over_gap_m_per_s": [math.sqrt(q * q + 2 * G * g * d) - q for q in qs],
            }
            kind: Literal["particle", "wall"] = "wall" if pop == "particle-wall" else "particle"
            entry.update(_steps_block(qs, case, dt_now, dt_cap, qs[-1], kind))
            block[pop] = entry
        summary["gaps"][f"{g:g}"] = block

    pooled_rows = []
    for g in gap_fracs:
        for pop in POPULATIONS:
            pooled_rows.append(_row("pooled", f"{times[0]:.3f}-{times[-1]:.3f}", True, g, g * d, pop,
                                    pooled[g][pop]))
    out: Path = args.out_dir
    out.mkdir(parents=True, exist_ok=True)
    with (out / "impact_speeds.csv").open("w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=list(rows[0]))
        w.writeheader()
        for r in rows + pooled_rows:
            w.writerow({k: (f"{v:.6g}" if isinstance(v, float) else v) for k, v in r.items()})
    (out / "impact_speeds.json").write_text(json.dumps(summary, indent=1) + "\n")
    _plot(out / "impact_speeds.png", pooled, gap_fracs, d, v_design, summary)

    # A short table for the terminal.
    for g in gap_fracs:
        for pop in POPULATIONS:
            e = summary["gaps"][f"{g:g}"][pop]
            q_text = ", ".join(f"{n} {v:.3g}"
                               for n, v in zip(QNAMES, e["quantiles_m_per_s"], strict=True))
            rs = ", ".join(f"{v:.3g}" for v in e["ratio_to_current"])
            print(f"gap {g:g} d, {pop}: rate {e['impact_rate_per_s']:.3g}/s; {q_text} m/s; "
                  f"step ratio {rs}")
    print(f"current step {dt_now:.4g} s (t_H at {v_design:.2f} m/s / 10); Rayleigh cap "
          f"{dt_cap:.4g} s ({dt_cap / dt_now:.3g}x)")
    print(f"written {out}/impact_speeds.{{csv,json,png}}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
