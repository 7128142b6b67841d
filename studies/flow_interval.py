"""Which interval is honest for the cascading bed's falling mass flow (issue 35, item 3).

Paper model one's flow at 12.12 s was stated two ways: +-1.19 % by the online stop rule (means of
whole lifter cycles, :func:`drumflow.convergence.cycle_means`) and +-3.7 % by the time-to-answer
replay (batch means of 20 batches after MSER-5, the replay's rule before this study). This
script reproduces both from the shipped series, splits the flow into its periodic part (folded
at the lifter passing period) and the rest, measures the coverage of four intervals on
synthetic series built like the real one, and compares real replicate runs. No solver.

    python studies/flow_interval.py [--replications 2000] [--out results/bench/flow_interval]

Writes ``coverage.csv`` (one row per estimator, noise, window), ``real.json`` (the real runs'
intervals, the decomposition and the replicate comparisons), ``cycle_means.csv`` (model one's
whole-cycle means) and ``coverage.png``.
"""

from __future__ import annotations

import argparse
import csv
import json
import math
import sys
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray
from scipy import stats
from scipy.signal import lfilter

from drumflow.bench.answer import replay_answer
from drumflow.case import load_case
from drumflow.convergence import (
    MSER_BATCH,
    MeanInterval,
    batch_means,
    cycle_means,
    effective_sample_size_interval,
    integrated_autocorrelation_time,
    mser_truncation,
    overlapping_batch_means,
)
from drumflow.coupling.stop import discharge_cycle
from drumflow.readers import read_csv

ROOT = Path(__file__).resolve().parents[1]
MODEL_ONE = ROOT / "results" / "paper" / "model_one"
MODEL_ONE_FIRST = ROOT / "results" / "paper" / "model_one_replicate" / "first_run"
#: The two parcel runs of model two at the same step and case (other round-off):
#: results/bench/paper_model_two_spin/default_against_replicate compares them sample by sample.
PARCEL_PAIR = (ROOT / "results" / "bench" / "paper_model_two_spin" / "default_step",
               ROOT / "results" / "paper_parcels" / "model_two")
#: Window lengths of the synthetic study, in lifter periods (the brief: 5-15).
CYCLES = (5, 8, 10, 15)
#: AR(1) coefficients of the synthetic noise at the output step besides the measured one:
#: correlation times of 19 and 99 steps (0.1 and 0.5 of a 1 s period at 200 steps a period).
EXTRA_PHI = (0.9, 0.98)


def flow_series(run: Path) -> tuple[NDArray[np.float64], NDArray[np.float64],
                                    NDArray[np.float64], float, float]:
    """The falling mass flow per output step over the counting window.

    Returns the rates (kg/s), each step's duration (s), each step's end time (s), the lifter
    passing period (s) and ``run.mass_flow_start`` (s), as the replay's steady flow reads them.
    """
    case = load_case(run / "case.toml")
    temps = read_csv(run / "post" / "mean_temperature.csv", "mean temperature per output step",
                     columns=("time_s", "falling_mass_kg_in_step"), finite=("time_s",))
    times = temps["time_s"].to_numpy(float)
    mass = temps["falling_mass_kg_in_step"].to_numpy(float)
    start = float(case.run.mass_flow_start)
    inside = (np.r_[np.nan, times[:-1]] >= start - 1e-9) & np.isfinite(mass)
    gaps = np.r_[np.nan, np.diff(times)][inside]
    return mass[inside] / gaps, gaps, times[inside], discharge_cycle(case), start


def old_replay_interval(rate: NDArray[np.float64], gaps: NDArray[np.float64]) -> tuple[MeanInterval, int]:
    """The replay's steady flow before this study: MSER-5 cut, then 20 batch means."""
    cut = mser_truncation(rate, MSER_BATCH)
    return batch_means(rate[cut:], gaps[cut:]), cut


def decompose(rate: NDArray[np.float64], gaps: NDArray[np.float64], times: NDArray[np.float64],
              period: float, start: float, from_s: float) -> dict[str, Any]:
    """Split the flow from ``from_s`` into its mean profile over one period and the rest."""
    mid = times - 0.5 * gaps
    steps = int(round(period / float(np.median(gaps))))
    phase = np.floor(np.mod(mid - start, period) / period * steps).astype(int) % steps
    sel = mid >= from_s
    profile = np.array([rate[sel & (phase == k)].mean() for k in range(steps)])
    periodic = profile[phase] - profile.mean()
    residual = rate - profile[phase]
    r = residual[sel] - residual[sel].mean()
    return {"steps_per_period": steps, "profile": profile, "periodic": periodic,
            "residual": residual, "residual_sd": float(r.std(ddof=1)),
            "residual_lag1": float(np.sum(r[1:] * r[:-1]) / np.sum(r * r)),
            "residual_tau_steps": integrated_autocorrelation_time(r),
            "periodic_sd": float(profile.std()),
            "half_period_means": [float(profile[: steps // 2].mean()),
                                  float(profile[steps // 2:].mean())]}


def real_model_one() -> dict[str, Any]:
    """Both statements of model one's flow, reproduced, and why they differ."""
    rate, gaps, times, period, start = flow_series(MODEL_ONE)
    old, cut = old_replay_interval(rate, gaps)
    cyc = cycle_means(rate, gaps, times, period, start)
    cyc_old = cycle_means(rate, gaps, times, period, start, truncation="cycles")
    replay = replay_answer(MODEL_ONE, times=[float(times[-1])]).table.iloc[-1]
    parts = decompose(rate, gaps, times, period, start, cyc.window_start)
    kept, kg = rate[cut:], gaps[cut:]
    n = kept.size
    size = n // 20
    first = n - 20 * size
    # The 20 batch means of the periodic part alone and of the rest alone (same batches).
    per_b = parts["periodic"][cut:][first:].reshape(20, size).mean(axis=1)
    res_b = parts["residual"][cut:][first:].reshape(20, size).mean(axis=1)
    all_b = kept[first:].reshape(20, size).mean(axis=1)
    # What the whole cycles of the old window would say: its rate from the MSER-5 cut on, in
    # whole periods from there (no further cut).
    whole_from_cut = cycle_means(kept, kg, times[cut:], period, float(times[cut] - gaps[cut]),
                                 min_cycles=2, truncation="none")
    resid_bm = batch_means(parts["residual"][cut:] + old.mean, kg)
    # The cycles after the first one kept against the noise's own scatter of a cycle mean
    # (the noise's variance times its autocorrelation time over the samples of one period).
    values = np.array(_cycle_values(rate, gaps, times, period, start))
    later = values[int(round((cyc.window_start - start) / period)) + 1:]
    noise_cycle_sd = parts["residual_sd"] * math.sqrt(parts["residual_tau_steps"]
                                                      / parts["steps_per_period"])
    # The periodic part's share of the old window's mean: it holds a partial period.
    partial_bias = float(np.sum(parts["periodic"][cut:] * kg) / np.sum(kg))
    return {
        "run": str(MODEL_ONE.relative_to(ROOT)), "period_s": period, "end_s": float(times[-1]),
        "samples_per_period": parts["steps_per_period"],
        "old_replay_batch_means": {**old.as_dict(), "mser5_window_start_s": float(times[cut] - gaps[cut]),
                                   "batch_length_s": float(size * np.median(gaps)),
                                   "batch_length_periods": float(size * np.median(gaps) / period)},
        "monitor_replayed_rel_half_width": float(replay["monitor_mass_flow_rel_half_width"]),
        "cycle_means_post_series": cyc.as_dict(),
        "cycle_means_post_series_old_cut": cyc_old.as_dict(),
        "replay_steady_flow_now": {"mean": float(replay["steady_mass_flow_kg_s"]),
                                   "half_width": float(replay["steady_mass_flow_half_width_kg_s"]),
                                   "start_s": float(replay["steady_start_s"])},
        "cycle_means_values_kg_s": _cycle_values(rate, gaps, times, period, start),
        "decomposition": {
            "periodic_sd_kg_s": parts["periodic_sd"],
            "half_period_means_kg_s": parts["half_period_means"],
            "residual_sd_kg_s": parts["residual_sd"], "residual_lag1": parts["residual_lag1"],
            "residual_tau_steps": parts["residual_tau_steps"],
            "batch_means_sd_all_kg_s": float(all_b.std(ddof=1)),
            "batch_means_sd_periodic_part_kg_s": float(per_b.std(ddof=1)),
            "batch_means_sd_residual_part_kg_s": float(res_b.std(ddof=1)),
            "batch_means_of_residual_rel_half_width": resid_bm.relative_half_width,
            "old_window_partial_period_bias_kg_s": partial_bias,
            "whole_cycles_from_mser5_cut": whole_from_cut.as_dict(),
            "cycles_after_the_first_kept_sd_kg_s": float(later.std(ddof=1)),
            "cycles_after_the_first_kept": int(later.size),
            "noise_alone_cycle_sd_kg_s": noise_cycle_sd,
        },
    }


def _cycle_values(rate: NDArray[np.float64], gaps: NDArray[np.float64], times: NDArray[np.float64],
                  period: float, start: float) -> list[float]:
    """The mean of every whole cycle of the window, in order (the cycle-means batches)."""
    mid = times - 0.5 * gaps
    cyc = np.floor((mid - start) / period + 1e-9).astype(int)
    whole = int(np.floor((times[-1] - start) / period + 1e-9))
    return [float(np.sum(rate[cyc == c] * gaps[cyc == c]) / np.sum(gaps[cyc == c]))
            for c in range(whole)]


def replicate_pair(first: Path, second: Path) -> dict[str, Any]:
    """Two runs of one case: each one's cycle-means interval and the z-score of the difference
    over their common whole cycles from the later of the two cuts."""
    a, b = flow_series(first), flow_series(second)
    end = min(float(a[2][-1]), float(b[2][-1]))
    ivs = [cycle_means(r[t <= end + 1e-9], g[t <= end + 1e-9], t[t <= end + 1e-9], p, s)
           for r, g, t, p, s in (a, b)]
    out: dict[str, Any] = {"first": str(first.relative_to(ROOT)),
                           "second": str(second.relative_to(ROOT)), "common_end_s": end,
                           "own_cut": [iv.as_dict() for iv in ivs]}
    cut_at = max(iv.window_start for iv in ivs)
    if not math.isfinite(cut_at):
        out["z"] = math.nan
        out["note"] = "no cascading window in common (a run ends before its flights are full)"
        return out
    # The same whole cycles in both, no further cut: a like-for-like difference.
    same = [cycle_means(r[(t <= end + 1e-9) & (t - g >= cut_at - 1e-9)],
                        g[(t <= end + 1e-9) & (t - g >= cut_at - 1e-9)],
                        t[(t <= end + 1e-9) & (t - g >= cut_at - 1e-9)], p, cut_at, min_cycles=2,
                        truncation="none")
            for r, g, t, p, s in (a, b)]
    q = [iv.half_width / float(_t_quantile(iv.batches)) for iv in same]  # standard errors
    diff = same[0].mean - same[1].mean
    out.update(common_window_start_s=cut_at, common=[iv.as_dict() for iv in same],
               difference_kg_s=diff, z=diff / math.hypot(q[0], q[1]))
    return out


def _t_quantile(batches: int) -> float:
    return float(stats.t.ppf(0.975, batches - 1))


def first_run_overlap() -> dict[str, Any]:
    """Model one's two full-particle runs: where their windows meet."""
    a, b = flow_series(MODEL_ONE), flow_series(MODEL_ONE_FIRST)
    end = float(b[2][-1])
    cyc_a = _cycle_values(*a[:3], a[3], a[4])
    cyc_b = _cycle_values(*b[:3], b[3], b[4])
    n = min(len(cyc_a), len(cyc_b))
    return {"first_run_end_s": end, "second_run_cut_s": cycle_means(*a[:3], a[3], a[4]).window_start,
            "common_whole_cycles_kg_s": {"second_run": cyc_a[:n], "first_run": cyc_b[:n]},
            "note": "the first run ended at its flights' first filling: no cascading cycle in "
                    "common, so no replicate test of the cascading flow is possible"}


# -- the synthetic study --------------------------------------------------------------------
Estimator = Callable[[NDArray[np.float64], int, int], MeanInterval]


def _estimators() -> dict[str, Estimator]:
    """Each interval as the library forms it, on one series of ``n`` samples, ``m`` a period."""
    def cyc(truncation: str) -> Estimator:
        def interval(x: NDArray[np.float64], m: int, whole: int) -> MeanInterval:
            t = (np.arange(x.size) + 1.0) / m  # end times in periods, the window from 0
            return cycle_means(x, None, t, 1.0, 0.0, truncation=truncation)
        return interval
    return {
        "batch_means_20": lambda x, m, whole: batch_means(x),
        "cycle_means": cyc("samples"),
        "cycle_means_mser_on_cycles": cyc("cycles"),
        "effective_sample_size": lambda x, m, whole: effective_sample_size_interval(x),
        "overlapping_batch_means_1_period": lambda x, m, whole: overlapping_batch_means(x[: whole * m], m),
    }


def synthetic(rng: np.random.Generator, reps: int, n: int, profile: NDArray[np.float64],
              sd: float, phi: float) -> NDArray[np.float64]:
    """``reps`` series of ``n`` steps: the periodic profile at a random phase plus stationary
    AR(1) noise of standard deviation ``sd`` (mean 0: the true mean is the profile's)."""
    m = profile.size
    e = rng.standard_normal((reps, n)) * sd * math.sqrt(1.0 - phi**2)
    e[:, 0] = rng.standard_normal(reps) * sd
    noise = np.asarray(lfilter([1.0], [1.0, -phi], e, axis=1))
    shift = rng.integers(0, m, reps)
    idx = (np.arange(n)[None, :] + shift[:, None]) % m
    return profile[idx] + noise


def ar1_sd_of_mean(sd: float, phi: float, n: int) -> float:
    """Exact standard deviation of the mean of ``n`` stationary AR(1) samples."""
    k = np.arange(1, n)
    return sd * math.sqrt((1.0 + 2.0 * float(np.sum((n - k) / n * phi**k))) / n)


def coverage_study(profile: NDArray[np.float64], sd: float, phis: list[float], reps: int,
                   seed: int = 35) -> list[dict[str, Any]]:
    """Coverage of each estimator's 95 % interval per noise, window length and alignment."""
    rows: list[dict[str, Any]] = []
    m = profile.size
    truth = float(profile.mean())
    rng = np.random.default_rng(seed)
    for phi in phis:
        for cycles in CYCLES:
            for ragged in (False, True):
                # Ragged: a window of cycles + U(0, 1) periods, as an MSER cut leaves it.
                n = cycles * m + (int(rng.integers(1, m)) if ragged else 0)
                sys.stderr.write(f"phi {phi:g}, {cycles} cycles, {'ragged' if ragged else 'whole'}\n")
                xs = synthetic(rng, reps, n, profile, sd, phi)
                exact = ar1_sd_of_mean(sd, phi, cycles * m)
                for name, est in _estimators().items():
                    ivs = [est(x, m, cycles) for x in xs]
                    half = np.array([iv.half_width for iv in ivs])
                    ok = np.isfinite(half)
                    hit = np.array([iv.low <= truth <= iv.high for iv in ivs])[ok]
                    rows.append({"estimator": name, "phi": phi, "cycles": cycles,
                                 "window": "ragged" if ragged else "whole_cycles",
                                 "samples": n, "replications": int(ok.sum()),
                                 "coverage": float(hit.mean()) if ok.any() else math.nan,
                                 "binomial_se": (math.sqrt(0.95 * 0.05 / ok.sum())
                                                 if ok.any() else math.nan),
                                 "mean_half_width_over_exact_1.96sd":
                                     float(np.mean(half[ok]) / (1.96 * exact)) if ok.any() else math.nan,
                                 "exact_sd_of_mean_whole_cycles": exact})
    return rows


def plot(rows: list[dict[str, Any]], real: dict[str, Any], path: Path) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, (ax0, ax1) = plt.subplots(1, 2, figsize=(11, 4.2))
    cyc = real["cycle_means_values_kg_s"]
    ax0.plot(np.arange(len(cyc)) + 1.5, cyc, "o-", label="whole-cycle means")
    d = real["decomposition"]
    ax0.set_xlabel("time (s), cycle midpoint")
    ax0.set_ylabel("falling mass flow (kg/s)")
    ax0.set_ylim(min(cyc[3:]) - 1.5, max(cyc[3:]) + 1.5)
    for level in d["half_period_means_kg_s"]:
        ax0.axhline(level, ls=":", c="grey")
    ax0.set_title("model one: cycle means; dotted: the two half-period means")
    phi_real = min(r["phi"] for r in rows)
    for name in sorted({r["estimator"] for r in rows}):
        sel = [r for r in rows if r["estimator"] == name and r["phi"] == phi_real
               and r["window"] == "ragged"]
        ax1.plot([r["cycles"] for r in sel], [r["coverage"] for r in sel], "o-", label=name)
    ax1.axhline(0.95, c="k", lw=0.8)
    ax1.set_xlabel("window (lifter periods), ragged")
    ax1.set_ylabel("coverage of the 95 % interval")
    ax1.set_title(f"synthetic flow, measured profile, AR(1) phi = {phi_real:.2f}")
    ax1.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--replications", type=int, default=2000)
    parser.add_argument("--out", type=Path, default=ROOT / "results" / "bench" / "flow_interval")
    args = parser.parse_args(argv)
    args.out.mkdir(parents=True, exist_ok=True)
    real = real_model_one()
    rate, gaps, times, period, start = flow_series(MODEL_ONE)
    parts = decompose(rate, gaps, times, period, start, real["cycle_means_post_series"]["window_start"])
    profile = parts["profile"]
    phis = [round(parts["residual_lag1"], 3), *EXTRA_PHI]
    rows = coverage_study(profile, parts["residual_sd"], phis, args.replications)
    with (args.out / "coverage.csv").open("w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=list(rows[0]))
        writer.writeheader()
        writer.writerows(rows)
    real["synthetic"] = {"profile": "model one's flow folded at the lifter period from the cycle "
                         "cut on, one value per output step", "noise_sd_kg_s": parts["residual_sd"],
                         "phis": phis, "replications": args.replications, "cycles": list(CYCLES)}
    real["replicates"] = {"model_one_full_particles": first_run_overlap(),
                          "model_two_parcels": replicate_pair(*PARCEL_PAIR)}
    (args.out / "real.json").write_text(json.dumps(real, indent=2, default=float))
    with (args.out / "cycle_means.csv").open("w", newline="") as f:
        cells = csv.writer(f)
        cells.writerow(["cycle_start_s", "mean_kg_s"])
        cells.writerows([start + period * k, v] for k, v in enumerate(real["cycle_means_values_kg_s"]))
    plot(rows, real, args.out / "coverage.png")
    sys.stdout.write(f"wrote {args.out}/coverage.csv, real.json, cycle_means.csv, coverage.png\n")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
