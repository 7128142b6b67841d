"""Confidence intervals for autocorrelated series (drumflow.convergence).

Reference: an AR(1) series x_t = phi x_{t-1} + e_t (e_t standard normal, started in its
stationary law) has mean 0, autocorrelation phi^k and integrated autocorrelation time
(1 + phi) / (1 - phi); the exact variance of the mean of n samples is
sigma^2 / n^2 * sum_{|k|<n} (n - |k|) phi^|k| with sigma^2 = 1 / (1 - phi^2). Coverage is
counted over many seeds: a 95% interval must contain the true mean 0 in about 95% of them.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from numpy.typing import NDArray
from scipy.signal import lfilter

from drumflow.convergence import (
    batch_means,
    convergence_state,
    effective_sample_size_interval,
    integrated_autocorrelation_time,
    naive_interval,
)

SEEDS = 400
# Binomial standard error of a 95% coverage over 400 seeds: sqrt(0.95 * 0.05 / 400) = 0.011.
# The accepted band 0.91-0.98 is about 3.5 standard errors below and 2.7 above; batch means
# with batches 10 tau long are known to under-cover by 1-2 points (bias of the batch variance).
LOW, HIGH = 0.91, 0.98


def ar1(phi: float, n: int, seeds: int, offset: int = 0) -> NDArray[np.float64]:
    """``seeds`` independent stationary AR(1) series of length ``n``, one per row."""
    rng = np.random.default_rng(12345 + offset)
    e = rng.standard_normal((seeds, n))
    e[:, 0] /= math.sqrt(1.0 - phi**2)  # the stationary variance for the first sample
    return np.asarray(lfilter([1.0], [1.0, -phi], e, axis=1))


def exact_variance_of_mean(phi: float, n: int) -> float:
    k = np.arange(1, n)
    return (1.0 + 2.0 * float(np.sum((n - k) / n * phi**k))) / (n * (1.0 - phi**2))


def coverage(intervals: list) -> float:
    return float(np.mean([iv.low <= 0.0 <= iv.high for iv in intervals]))


def test_naive_interval_under_covers_and_batch_means_covers() -> None:
    phi, n = 0.9, 4000  # tau = 19 samples; 20 batches of 200 samples = 10.5 tau each
    xs = ar1(phi, n, SEEDS)
    naive = [naive_interval(x) for x in xs]
    bm = [batch_means(x) for x in xs]
    # The naive half-width is too narrow by sqrt(tau) = 4.4: coverage near 2 Phi(1.96/4.4) - 1
    # = 0.34.
    assert coverage(naive) < 0.5
    assert LOW <= coverage(bm) <= HIGH
    # The batch-means variance of the mean agrees with the exact one (mean over seeds of
    # (half/t)^2, 19 degrees of freedom: standard error of the average about 0.32/sqrt(400)
    # = 1.6%; allowed 10% for the finite-batch bias).
    from scipy import stats

    t = stats.t.ppf(0.975, 19)
    estimated = float(np.mean([(iv.half_width / t) ** 2 for iv in bm]))
    assert estimated == pytest.approx(exact_variance_of_mean(phi, n), rel=0.10)


def test_effective_sample_size_interval_covers() -> None:
    phi, n = 0.8, 4000  # tau = 9
    xs = ar1(phi, n, SEEDS, offset=1)
    ess = [effective_sample_size_interval(x) for x in xs]
    assert all(iv.batches_independent for iv in ess)
    assert LOW <= coverage(ess) <= HIGH


def test_integrated_autocorrelation_time_of_ar1() -> None:
    # Sokal's window estimate: relative standard error about sqrt(2 (2M + 1) / n) = 0.14 for
    # one series with M = 5 tau = 95, n = 20,000; over 100 series 1.4%, so 5% is 3.5 standard
    # errors (measured: 18.9 +- 0.23 over another 100 seeds, no visible bias).
    phi = 0.9
    xs = ar1(phi, 20_000, 100, offset=2)
    taus = [integrated_autocorrelation_time(x) for x in xs]
    assert float(np.mean(taus)) == pytest.approx((1 + phi) / (1 - phi), rel=0.05)
    assert integrated_autocorrelation_time(np.ones(10)) != integrated_autocorrelation_time(np.ones(10))


def test_short_batches_are_flagged_as_correlated() -> None:
    # tau = 1999 samples against batches of 100: the batch means follow one slow wave.
    phi = 0.999
    xs = ar1(phi, 2000, 50, offset=3)
    flagged = [not batch_means(x).batches_independent for x in xs]
    assert np.mean(flagged) > 0.9
    # Independent samples pass the check in about 95% of series (its level is 5%).
    white = np.random.default_rng(7).standard_normal((SEEDS, 400))
    passed = np.mean([batch_means(x).batches_independent for x in white])
    assert 0.90 <= passed <= 0.99


def test_weights_give_the_time_mean() -> None:
    x = np.array([1.0, 1.0, 1.0, 1.0, 4.0] * 40)
    w = np.array([1.0, 1.0, 1.0, 1.0, 2.0] * 40)
    iv = batch_means(x, w, n_batches=8)
    assert iv.mean == pytest.approx((4 * 1.0 + 2 * 4.0) / 6.0)
    # Every batch holds whole periods of the pattern: identical batch means, zero width.
    assert iv.half_width == pytest.approx(0.0, abs=1e-12)
    with pytest.raises(ValueError, match="weights"):
        batch_means(x, w[:-1])


def test_too_few_samples_give_no_interval() -> None:
    iv = batch_means(np.arange(50.0))  # 2 samples per batch < MIN_BATCH_SAMPLES
    assert math.isnan(iv.half_width)
    assert math.isnan(iv.relative_half_width)


def test_stop_rule() -> None:
    rng = np.random.default_rng(11)
    h = 50.0 + rng.standard_normal(2000)  # +-0.05 / 50: relative width about 0.1%
    flow = 2.0 + 0.5 * rng.standard_normal(2000)  # relative width about 1.1%
    series = {"h": (h, None), "falling_mass_flow": (flow, None)}
    early = convergence_state(series, time_s=1.0, tolerance=0.05, min_time_s=2.0)
    assert not early.converged and "minimum time" in early.reason
    tight = convergence_state(series, time_s=3.0, tolerance=0.005, min_time_s=2.0)
    assert not tight.converged and tight.reason.startswith("falling_mass_flow")
    loose = convergence_state(series, time_s=3.0, tolerance=0.02, min_time_s=2.0)
    assert loose.converged, loose.reason
    record = loose.as_dict()
    assert record["intervals"]["h"]["relative_half_width"] < 0.002
    # A drifting series (not stationary) has correlated batch means: no verdict of convergence
    # however small the noise.
    drift = np.linspace(1.0, 1.002, 2000) + 1e-5 * rng.standard_normal(2000)
    verdict = convergence_state({"h": (drift, None)}, 3.0, 0.05, 0.0)
    assert not verdict.converged and "correlated" in verdict.reason


# -- the case fields of the stop rule -------------------------------------------------------
def test_stop_rule_case_fields() -> None:
    from drumflow.case import case_from_dict
    from drumflow.coupling.stop import min_stop_time
    from drumflow.errors import CaseError
    from drumflow.verify.scenes import tiny_drum_dict

    fixed = case_from_dict(tiny_drum_dict())
    # A fixed-time case keeps the hash it had before the rule existed (its run directories and
    # caches stay valid): the stop fields are left out of the canonical JSON.
    assert "stop" not in fixed.canonical_json()
    converged = case_from_dict(tiny_drum_dict(air__model="uniform", run__stop="converged"))
    assert converged.hash() != fixed.hash()
    # 'auto': mass_flow_start 0.6 s + max(1 s, 3 x 60 / (30 rpm x 6 lifters) = 1 s).
    assert min_stop_time(converged) == pytest.approx(1.6)
    with pytest.raises(CaseError, match=r"run.stop = 'converged': needs air"):
        case_from_dict(tiny_drum_dict(run__stop="converged"))
    with pytest.raises(CaseError, match=r"run.stop_min_time = 5.0 s: must be above"):
        case_from_dict(tiny_drum_dict(air__model="uniform", run__stop="converged",
                                      run__stop_min_time=5.0))
    with pytest.raises(CaseError, match=r"run.stop_tolerance = 0.0"):
        case_from_dict(tiny_drum_dict(air__model="uniform", run__stop_tolerance=0.0))


def test_mser_cuts_a_step_transient_where_it_ends() -> None:
    from drumflow.convergence import mser_truncation

    rng = np.random.default_rng(11)
    x = rng.normal(0.0, 1.0, 2000)
    x[:300] += 5.0  # a start-up offset of five standard deviations for 300 samples
    d = mser_truncation(x)
    assert 300 <= d <= 305  # the first whole batch of 5 after the step


def test_mser_cuts_a_decaying_transient_and_little_of_a_stationary_series() -> None:
    from drumflow.convergence import mser_truncation

    rng = np.random.default_rng(12)
    t = np.arange(2000)
    noise = rng.normal(0.0, 1.0, t.size)
    d = mser_truncation(10.0 * np.exp(-t / 50.0) + noise)
    # The offset falls below the noise of a 5-sample batch mean (0.45) after 50 ln(10/0.45)
    # = 155 samples; MSER stops between where it is a tenth and twice that.
    assert 50 <= d <= 400
    assert mser_truncation(noise) <= 200  # stationary: at most a tenth cut
    assert mser_truncation(noise[:7]) == 0  # too short to batch twice


# --------------------------------------------------------------- whole cycles of a periodic flow
CYCLE = 1.0  # s, one lifter's discharge
PER_CYCLE = 100  # samples (coupling updates) per cycle
# A discharge pulse in the first 40 % of each cycle (mean 1 over a cycle), its height varying
# 5 % from cycle to cycle, plus sample noise: the shape of a flighted drum's falling mass flow.
_PHASE = (np.arange(PER_CYCLE) + 0.5) / PER_CYCLE
_PULSE = np.where(_PHASE < 0.4, np.sin(np.pi * _PHASE / 0.4), 0.0) * np.pi / 0.8
TRUE_FLOW = float(_PULSE.mean())


def _discharge(seed: int, cycles: int, start_up: tuple[float, ...] = ()) -> tuple[np.ndarray, np.ndarray]:
    rng = np.random.default_rng(seed)
    height = 1.0 + 0.05 * rng.standard_normal(cycles)
    height[: len(start_up)] *= start_up  # the flights' first filling
    x = np.tile(_PULSE, cycles) * np.repeat(height, PER_CYCLE)
    x += 0.3 * rng.standard_normal(x.size)
    t_end = np.arange(1, x.size + 1) * (CYCLE / PER_CYCLE)
    return x, t_end


def test_cycle_means_cover_the_flow_and_are_narrower_than_phase_mixing_batches() -> None:
    from drumflow.convergence import cycle_means

    dt = np.full(15 * PER_CYCLE, CYCLE / PER_CYCLE)
    covered = batch_covered = 0
    width, batch_width = [], []
    for seed in range(SEEDS):
        x, t = _discharge(seed, 15)
        iv = cycle_means(x, dt, t, CYCLE, 0.0)
        assert iv.method == "cycle_means" and iv.batches + iv.truncated_batches == 15
        covered += abs(iv.mean - TRUE_FLOW) <= iv.half_width
        width.append(iv.half_width)
        b = batch_means(x, dt)  # 20 batches of 0.75 cycles: each starts at another phase
        batch_covered += abs(b.mean - TRUE_FLOW) <= b.half_width
        batch_width.append(b.half_width)
    # Nominal 95 %; MSER's cut of stationary cycles that happen to stray selects a little
    # (measured 0.93 over these seeds), and the band allows the binomial 0.011 of 400 seeds.
    assert 0.90 <= covered / SEEDS <= HIGH
    # Phase-mixing batches over-cover with intervals about six times wider (measured 0.185
    # against 0.031): what kept the paper runs' rule from ever firing at 1 %.
    assert batch_covered / SEEDS > 0.99
    assert np.mean(batch_width) > 4.0 * np.mean(width)


def test_cycle_means_cut_the_first_filling_and_drop_the_unfinished_cycle() -> None:
    from drumflow.convergence import cycle_means

    x, t = _discharge(1, 15, start_up=(0.0, 0.3, 0.7))
    extra = 37  # a cycle under way: 37 samples of the 16th, not counted
    x = np.r_[x, np.full(extra, 50.0)]
    t = np.r_[t, t[-1] + np.arange(1, extra + 1) * (CYCLE / PER_CYCLE)]
    iv = cycle_means(x, np.full(x.size, CYCLE / PER_CYCLE), t, CYCLE, 0.0)
    assert iv.truncated_batches >= 3 and iv.window_start == iv.truncated_batches * CYCLE
    assert iv.batches == 15 - iv.truncated_batches
    assert iv.samples == iv.batches * PER_CYCLE
    assert abs(iv.mean - TRUE_FLOW) <= iv.half_width  # the start-up does not bias it


def test_cycle_means_need_five_whole_cycles() -> None:
    from drumflow.convergence import cycle_means, decide

    x, t = _discharge(2, 4)
    iv = cycle_means(x, None, t, CYCLE, 0.0)
    assert math.isnan(iv.half_width) and iv.batches == 4
    state = decide({"falling_mass_flow_kg_s": iv}, 5.0, 0.5, 1.0)
    assert not state.converged and "too few whole cycles (4 after cutting 0" in state.reason
    # Without weights, each sample lasts the gap to the previous one: the same cycles.
    weighted = cycle_means(x, np.full(x.size, CYCLE / PER_CYCLE), t, CYCLE, 0.0)
    assert iv.mean == pytest.approx(weighted.mean, rel=1e-12) and iv.samples == weighted.samples
    # Regression: the loop's first checks come before the window holds a sample (an empty
    # series crashed the coupling loop of the tiny drum's converged run).
    empty = cycle_means([], [], [], CYCLE, 0.0)
    assert empty.samples == 0 and math.isnan(empty.half_width)
    with pytest.raises(ValueError, match="period = 0"):
        cycle_means(x, None, t, 0.0, 0.0)
