"""Confidence intervals for the mean of an autocorrelated time series, and the stop rule.

A DEM run's observables (the air's heat-transfer coefficient at each coupling update, the
particles crossing the axis plane in each interval) are strongly autocorrelated: a lifter
discharges for a while, then the next one. The naive interval ``t s / sqrt(n)`` treats every
sample as independent and is far too narrow (for an AR(1) series with coefficient phi by the
factor ``sqrt((1 + phi) / (1 - phi))``). Two honest intervals:

* **batch means** (:func:`batch_means`): cut the series into ``B`` contiguous batches (20 by
  default); when batches are much longer than the correlation time their means are nearly
  independent and normal, and ``t_{B-1} s_B / sqrt(B)`` is a valid interval. The lag-1
  autocorrelation of the batch means checks the "nearly independent" part: when it is
  significantly positive the batches are too short and the interval is not trusted
  (:attr:`MeanInterval.batches_independent`).
* **cycle means** (:func:`cycle_means`): batch means whose batches are whole periods of a
  periodic flow (a flighted drum's lifter discharges); the interval of the cascading bed's
  falling mass flow, online (:mod:`drumflow.coupling.stop`) and in the replay
  (:mod:`drumflow.bench.answer`). Batches of any other length alias the period and give
  intervals several times too wide (``docs/flow-uncertainty.md``).
* **effective sample size** (:func:`effective_sample_size_interval`): the integrated
  autocorrelation time ``tau`` (Sokal's self-consistent window, :func:`integrated_autocorrelation_time`)
  gives ``n / tau`` effectively independent samples.

:func:`convergence_state` applies the stop rule of ``run.stop = "converged"`` to the two series.
Pure functions of arrays, on the ground floor of the package (no drumflow imports) so that the
coupling loop may call them online as well as any later stage; ``tests/unit/test_convergence.py``
checks their coverage on AR(1) series whose true variance of the mean is known.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import asdict, dataclass
from functools import lru_cache
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy import stats

__all__ = [
    "DEFAULT_BATCHES",
    "ConvergenceState",
    "MeanInterval",
    "batch_means",
    "convergence_state",
    "cycle_means",
    "decide",
    "effective_sample_size_interval",
    "integrated_autocorrelation_time",
    "mser_truncation",
    "naive_interval",
    "overlapping_batch_means",
]

#: Samples per batch of MSER-5 (White, Cobb & Spratt 2000): batching first smooths the
#: statistic, which on raw samples is noisy enough to pick a truncation point by chance.
MSER_BATCH = 5

#: Batches of the batch-means interval. 20 keeps the t quantile close to normal (2.09 against
#: 1.96) while each batch stays long against the correlation time; the literature's range is
#: 10-30 (Schmeiser 1982).
DEFAULT_BATCHES = 20

#: Fewest samples in one batch: below this a batch mean says little about the correlation.
MIN_BATCH_SAMPLES = 5

#: Fewest whole cycles for a cycle-means interval: with 5 the t quantile is 2.78 (against 1.96
#: for many), so an interval needs a flow steady to a few percent from cycle to cycle.
MIN_CYCLES = 5

#: How :func:`cycle_means` cuts the start-up: MSER-5 on the samples less their periodic profile
#: (up to the next whole cycle), MSER-1 on the cycle means, or not at all.
TRUNCATIONS = ("cycles", "samples", "none")

#: One-sided level of the batch-independence check. Under independence the lag-1
#: autocorrelation of B batch means is about normal with mean -1/B and variance 1/B; a value
#: above -1/B + z_0.95 / sqrt(B) (0.32 for 20 batches) means the batches are too short.
INDEPENDENCE_LEVEL = 0.05


@dataclass(frozen=True)
class MeanInterval:
    """A confidence interval for the (time-)mean of a series.

    Attributes
    ----------
    mean
        The (weighted) mean.
    half_width
        Half-width of the interval at ``confidence``; NaN when it cannot be formed.
    confidence
        Nominal coverage, e.g. 0.95.
    samples
        Samples used.
    method
        ``"batch_means"``, ``"cycle_means"``, ``"effective_sample_size"`` or ``"naive"``.
    batches
        Batches (batch means only).
    batch_lag1_autocorrelation
        Lag-1 autocorrelation of the batch means (batch means only).
    batches_independent
        False when the batch means are significantly positively correlated (the interval is then
        too narrow and must not be trusted); True for the other methods when they could be
        formed.
    autocorrelation_time
        Integrated autocorrelation time in samples (effective sample size only).
    truncated_batches
        Leading batches cut as start-up transient (cycle means only).
    window_start
        Start of the first batch kept, in the series' time unit (cycle means only).
    """

    mean: float
    half_width: float
    confidence: float
    samples: int
    method: str
    batches: int = 0
    batch_lag1_autocorrelation: float = math.nan
    batches_independent: bool = False
    autocorrelation_time: float = math.nan
    truncated_batches: int = 0
    window_start: float = math.nan

    @property
    def relative_half_width(self) -> float:
        """Half-width over |mean| (inf for a zero mean, NaN without an interval)."""
        if math.isnan(self.half_width):
            return math.nan
        return self.half_width / abs(self.mean) if self.mean != 0 else math.inf

    @property
    def low(self) -> float:
        return self.mean - self.half_width

    @property
    def high(self) -> float:
        return self.mean + self.half_width

    def as_dict(self) -> dict[str, Any]:
        """JSON-ready, with the relative half-width and the bounds."""
        return {**asdict(self), "relative_half_width": self.relative_half_width,
                "low": self.low, "high": self.high}


def _as_series(values: ArrayLike,
               weights: ArrayLike | None) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    x = np.asarray(values, dtype=float).ravel()
    w = np.ones_like(x) if weights is None else np.asarray(weights, dtype=float).ravel()
    if w.shape != x.shape:
        raise ValueError(f"weights: {w.size} values for {x.size} samples; allowed: one per sample")
    if np.any(w < 0) or (x.size and not np.any(w > 0)):
        raise ValueError("weights: must be >= 0 with a positive sum")
    return x, w


@lru_cache(maxsize=256)
def _t_quantile(confidence: float, dof: float) -> float:
    """Two-sided Student quantile, cached: the online rule asks for the same few at every
    check, and scipy's ``ppf`` costs more than the rest of :func:`cycle_means`."""
    return float(stats.t.ppf(0.5 + 0.5 * confidence, dof))


@lru_cache(maxsize=16)
def _independence_z() -> float:
    return float(stats.norm.ppf(1.0 - INDEPENDENCE_LEVEL))


def naive_interval(values: ArrayLike, confidence: float = 0.95) -> MeanInterval:
    """The interval that treats every sample as independent (``t s / sqrt(n)``).

    Too narrow for a correlated series; kept as the reference the honest intervals are tested
    against.
    """
    x, _ = _as_series(values, None)
    n = x.size
    if n < 2:
        return MeanInterval(float(x.mean()) if n else math.nan, math.nan, confidence, n, "naive")
    half = float(stats.t.ppf(0.5 + 0.5 * confidence, n - 1) * x.std(ddof=1) / math.sqrt(n))
    return MeanInterval(float(x.mean()), half, confidence, n, "naive", batches_independent=True)


def batch_means(values: ArrayLike, weights: ArrayLike | None = None,
                n_batches: int = DEFAULT_BATCHES, confidence: float = 0.95) -> MeanInterval:
    """Batch-means confidence interval for the (weighted) mean of a stationary series.

    Parameters
    ----------
    values
        The series, in time order.
    weights
        Per-sample weights, e.g. the duration each sample stands for (a shorter last coupling
        interval); default equal. The mean is then ``sum(w x) / sum(w)``, each batch's mean is
        its own weighted mean, and batches are cut at (nearly) equal sample counts.
    n_batches
        Batches ``B``; the interval uses Student's t with ``B - 1`` degrees of freedom.
    confidence
        Nominal coverage.

    Returns
    -------
    MeanInterval
        ``half_width`` NaN when there are fewer than ``MIN_BATCH_SAMPLES`` samples per batch.
        ``batches_independent`` is False when the lag-1 autocorrelation of the batch means is
        above its one-sided 95% bound under independence.
    """
    if n_batches < 4:
        raise ValueError(f"n_batches = {n_batches}: allowed >= 4")
    x, w = _as_series(values, weights)
    n = x.size
    mean = float(np.sum(w * x) / np.sum(w)) if n else math.nan
    size = n // n_batches
    if size < MIN_BATCH_SAMPLES:
        return MeanInterval(mean, math.nan, confidence, n, "batch_means", batches=n_batches)
    # Drop the oldest remainder so every batch has the same sample count (the newest samples
    # are the most stationary).
    start = n - size * n_batches
    xb = x[start:].reshape(n_batches, size)
    wb = w[start:].reshape(n_batches, size)
    means = np.sum(wb * xb, axis=1) / np.sum(wb, axis=1)
    # The batch-weighted grand mean equals the mean above when all batches weigh the same.
    bw = wb.sum(axis=1)
    grand = float(np.sum(bw * means) / bw.sum())
    spread = float(means.std(ddof=1))
    half = float(stats.t.ppf(0.5 + 0.5 * confidence, n_batches - 1)) * spread / math.sqrt(n_batches)
    dev = means - means.mean()
    denom = float(np.sum(dev**2))
    r1 = float(np.sum(dev[:-1] * dev[1:]) / denom) if denom > 0 else 0.0
    bound = -1.0 / n_batches + float(stats.norm.ppf(1.0 - INDEPENDENCE_LEVEL)) / math.sqrt(n_batches)
    return MeanInterval(grand, half, confidence, n, "batch_means", batches=n_batches,
                        batch_lag1_autocorrelation=r1, batches_independent=r1 <= bound)


def cycle_means(values: ArrayLike, weights: ArrayLike | None, times: ArrayLike, period: float,
                start: float, confidence: float = 0.95,
                min_cycles: int = MIN_CYCLES, truncation: str = "samples") -> MeanInterval:
    """Confidence interval for the mean of a periodic flow, with whole cycles as the batches.

    A flighted drum's falling mass flow is periodic: each lifter discharges in turn, one every
    ``60 / (rpm x lifters)`` seconds. Batches of any other length mix phases of that cycle, and
    their means scatter with the phase they happen to start at (the 20 batches of
    :func:`batch_means` over 13 s of paper model two are 0.65 lifter periods each). The mean
    over one whole cycle has no phase left in it, so successive cycle means are the batch means
    of the flow: the interval is ``t_{B-1} s_B / sqrt(B)`` over the ``B`` cycles kept. The flights
    fill during the first cycles of a run; :func:`mser_truncation` (MSER-5) on the samples less
    their mean profile over a cycle cuts that start-up, up to the next whole cycle, so the
    interval is the cascading bed's.

    The cut is chosen on the samples, not on the cycle means whose spread makes the interval:
    MSER on the cycle means themselves (``truncation="cycles"``, the rule until issue 35)
    drops the leading cycles that happen to stray, which narrows the interval it then forms;
    ``studies/flow_interval.py`` measured 0.91-0.93 coverage of its 95 % interval on
    stationary series of 10-15 cycles, against 0.95 with the cut on the samples
    (``docs/flow-uncertainty.md``).

    Parameters
    ----------
    values, weights
        The series (e.g. the mass flow over each coupling interval) and each sample's duration.
    times
        Each sample's end time; a sample belongs to the cycle its midpoint falls in
        (``time - weight / 2``; without weights, half the gap to the previous sample).
    period
        Cycle length, same unit as ``times``.
    start
        Start of the first cycle (the counting window's start).
    confidence
        Nominal coverage.
    min_cycles
        Fewest whole cycles after the cut for an interval.
    truncation
        The start-up cut: ``"samples"`` (MSER-5 on the samples less their mean profile over a
        cycle, up to the next whole cycle),
        ``"cycles"`` (MSER-1 on the cycle means, with at least ``2 min_cycles`` of them) or
        ``"none"``.

    Returns
    -------
    MeanInterval
        Method ``"cycle_means"``; ``batches`` the cycles kept, ``truncated_batches`` those cut,
        ``window_start`` where the kept cycles begin; ``half_width`` NaN with fewer than
        ``min_cycles`` cycles; ``batches_independent`` from the lag-1 autocorrelation of the
        cycle means, as in :func:`batch_means`.
    """
    if not period > 0.0:
        raise ValueError(f"period = {period}: allowed > 0")
    if truncation not in TRUNCATIONS:
        raise ValueError(f"truncation = {truncation!r}: allowed {', '.join(TRUNCATIONS)}")
    x, w = _as_series(values, weights)
    t = np.asarray(times, dtype=float).ravel()
    if t.shape != x.shape:
        raise ValueError(f"times: {t.size} values for {x.size} samples; allowed: one per sample")
    if t.size == 0:  # the window has not begun
        return MeanInterval(math.nan, math.nan, confidence, 0, "cycle_means")
    # Each sample's duration: its weight, or without weights the gap to the previous sample.
    gaps = np.diff(t, prepend=t[0] - (float(np.median(np.diff(t))) if t.size > 1 else 0.0))
    duration = w if weights is not None else gaps
    ok = np.isfinite(x) & np.isfinite(t) & np.isfinite(w)
    x, w, t, duration = x[ok], w[ok], t[ok], duration[ok]
    mid = t - 0.5 * duration
    cycle = np.floor((mid - start) / period + 1e-9).astype(int)
    # Whole cycles only: the last one is complete when a sample ends at or after its end.
    end = float(t.max()) if t.size else start
    whole = int(np.floor((end - start) / period + 1e-9))
    keep = (cycle >= 0) & (cycle < whole)
    n_cycles = whole if keep.any() else 0
    if n_cycles == 0:
        return MeanInterval(math.nan, math.nan, confidence, 0, "cycle_means")
    sw = np.bincount(cycle[keep], weights=w[keep], minlength=n_cycles)
    swx = np.bincount(cycle[keep], weights=(w * x)[keep], minlength=n_cycles)
    filled = sw > 0
    means = np.where(filled, swx / np.where(filled, sw, 1.0), math.nan)
    means = means[filled]
    if truncation == "cycles":
        cut = mser_truncation(means, batch=1) if means.size >= 2 * min_cycles else 0
    elif truncation == "samples":
        # MSER-5 on the samples of the whole cycles less their mean profile over a cycle: the
        # periodic swing, larger than a start-up offset, would hide it from MSER, and it is not
        # what the interval is about. Up to the next whole cycle: a discharge pulse may fill
        # a fraction of its cycle, so the part of a cycle before the cut may hold its whole
        # transient; on a stationary series MSER cuts nothing once the profile is out.
        cut_at = mser_truncation(_less_profile(x[keep], mid[keep], duration[keep], start, period))
        begins = float(mid[keep][cut_at] - 0.5 * duration[keep][cut_at])
        cut_cycle = int(np.ceil((begins - start) / period - 1e-9))
        cut = min(int(np.sum(np.flatnonzero(filled) < cut_cycle)), means.size)
    else:
        cut = 0
    kept = means[cut:]
    first = float(start + period * np.flatnonzero(filled)[cut]) if kept.size else math.nan
    samples = int(np.sum(keep & (cycle >= np.flatnonzero(filled)[cut]))) if kept.size else 0
    b = kept.size
    mean = float(kept.mean()) if b else math.nan
    if b < min_cycles:
        return MeanInterval(mean, math.nan, confidence, samples, "cycle_means", batches=b,
                            truncated_batches=cut, window_start=first)
    half = _t_quantile(confidence, b - 1) * float(kept.std(ddof=1)) / math.sqrt(b)
    dev = kept - mean
    denom = float(np.sum(dev**2))
    r1 = float(np.sum(dev[:-1] * dev[1:]) / denom) if denom > 0 else 0.0
    bound = -1.0 / b + _independence_z() / math.sqrt(b)
    return MeanInterval(mean, half, confidence, samples, "cycle_means", batches=b,
                        batch_lag1_autocorrelation=r1, batches_independent=r1 <= bound,
                        truncated_batches=cut, window_start=first)


def overlapping_batch_means(values: ArrayLike, batch_size: int,
                            confidence: float = 0.95) -> MeanInterval:
    """Overlapping-batch-means interval (Meketon & Schmeiser 1984) for an evenly sampled series.

    Every run of ``m = batch_size`` consecutive samples is a batch (``n - m + 1`` of them); the
    variance constant of the mean is ``V = n m / ((n - m + 1)(n - m)) sum_j (mean_j - mean)^2``
    and the half-width ``t_d sqrt(V / n)`` with ``d = 1.5 (n / m - 1)`` degrees of freedom: the
    overlapping estimator's variance is 2/3 of the non-overlapping one's at the same batch size
    (Meketon & Schmeiser), hence the 1.5. With ``m`` one period of a periodic flow, sampled
    evenly, every batch holds one whole cycle and the periodic part cancels from each, as in
    :func:`cycle_means`, which it is compared with in ``studies/flow_interval.py``.

    Parameters
    ----------
    values
        The series, evenly spaced in time.
    batch_size
        Samples per batch, ``2 <= m <= n / 2``.
    confidence
        Nominal coverage.

    Returns
    -------
    MeanInterval
        Method ``"overlapping_batch_means"``; ``batches`` the whole batches the series holds
        (``n // m``); ``half_width`` NaN when ``n < 2 m``.
    """
    if batch_size < 2:
        raise ValueError(f"batch_size = {batch_size}: allowed >= 2")
    x, _ = _as_series(values, None)
    n = x.size
    mean = float(x.mean()) if n else math.nan
    m = int(batch_size)
    if n < 2 * m:
        return MeanInterval(mean, math.nan, confidence, n, "overlapping_batch_means",
                            batches=n // m)
    csum = np.concatenate(([0.0], np.cumsum(x - mean)))  # centred: no cancellation in the sums
    means = (csum[m:] - csum[:-m]) / m  # the n - m + 1 batch means, less the grand mean
    variance = n * m * float(np.sum(means**2)) / ((n - m + 1) * (n - m))
    dof = 1.5 * (n / m - 1.0)
    half = _t_quantile(confidence, dof) * math.sqrt(variance / n)
    return MeanInterval(mean, half, confidence, n, "overlapping_batch_means", batches=n // m,
                        batches_independent=True)


def _less_profile(x: NDArray[np.float64], mid: NDArray[np.float64],
                  duration: NDArray[np.float64], start: float,
                  period: float) -> NDArray[np.float64]:
    """``x`` less its mean over each phase bin of the cycle (bins one sample long)."""
    bins = max(1, int(round(period / float(np.median(duration))))) if x.size else 1
    phase = np.floor(np.mod(mid - start, period) / period * bins).astype(int) % bins
    count = np.bincount(phase, minlength=bins)
    profile = np.bincount(phase, weights=x, minlength=bins) / np.maximum(count, 1)
    return np.asarray(x - profile[phase], dtype=float)


def mser_truncation(values: ArrayLike, batch: int = MSER_BATCH) -> int:
    """Where a series' start-up transient ends, by the marginal standard error rule (MSER-b).

    MSER (White 1997; MSER-5, White, Cobb & Spratt 2000) truncates the first ``d`` samples for
    the ``d`` that minimises the squared standard error of the mean of what remains,
    ``sum((x_i - mean_d)^2 for i >= d) / (n - d)^2``: cutting more removes bias from the
    transient, cutting too much leaves too few samples, and the minimum balances the two. The
    series is first averaged over batches of ``batch`` samples, ``d`` is searched over the
    first half of the batches only (a minimum in the second half says the series has not
    settled; the first half's best is returned, and the caller's interval will be wide).

    Parameters
    ----------
    values
        The series in time order (e.g. the falling mass flow per output step).
    batch
        Samples per batch (5: MSER-5).

    Returns
    -------
    int
        Index of the first sample kept (a multiple of ``batch``; 0 for a series too short to
        batch twice).
    """
    if batch < 1:
        raise ValueError(f"batch = {batch}: allowed >= 1")
    x = np.asarray(values, dtype=float)
    x = x[np.isfinite(x)]
    k = x.size // batch
    if k < 2:
        return 0
    means = x[: k * batch].reshape(k, batch).mean(axis=1)
    # Suffix sums give every candidate's mean and spread in one pass.
    tail = means[::-1]
    count = np.arange(1, k + 1, dtype=float)
    mean_d = (np.cumsum(tail) / count)[::-1]
    sq_d = (np.cumsum(tail**2) / count)[::-1]
    remain = count[::-1]
    stat = np.maximum(sq_d - mean_d**2, 0.0) / remain  # variance / (n - d), per batch
    half = max(1, k // 2)
    return int(np.argmin(stat[:half])) * batch


def integrated_autocorrelation_time(values: ArrayLike, window_factor: float = 5.0) -> float:
    """Integrated autocorrelation time ``tau = 1 + 2 sum_k rho_k``, in samples.

    The sum runs up to the smallest lag ``M >= window_factor * tau(M)`` (Sokal's automatic
    window), which balances the bias of cutting the sum against the noise of long lags. The
    autocorrelation comes from an FFT (zero-padded, so it is the linear, not circular, one).
    ``n / tau`` is the effective sample size. Returns NaN for fewer than 4 samples or a
    constant series.
    """
    x = np.asarray(values, dtype=float).ravel()
    n = x.size
    if n < 4:
        return math.nan
    dev = x - x.mean()
    size = 1 << (2 * n - 1).bit_length()
    spectrum = np.fft.rfft(dev, size)
    acov = np.fft.irfft(spectrum * np.conj(spectrum), size)[:n] / n
    if acov[0] <= 0:
        return math.nan
    rho = acov / acov[0]
    taus = 2.0 * np.cumsum(rho) - 1.0  # tau(M) = 1 + 2 sum_{k=1..M} rho_k
    lags = np.arange(n)
    ok = lags >= window_factor * taus
    m = int(np.argmax(ok)) if ok.any() else n - 1
    return float(max(taus[m], 1.0))


def effective_sample_size_interval(values: ArrayLike, confidence: float = 0.95) -> MeanInterval:
    """Confidence interval for the mean with ``n / tau`` effective samples.

    ``half_width = z s / sqrt(n / tau)`` with the normal quantile (``n / tau`` is an estimate,
    not a count, so Student's t has no exact degrees of freedom here). NaN half-width when
    ``tau`` cannot be estimated or the window reached past a tenth of the series (the series is
    then too short for its correlation).
    """
    x = np.asarray(values, dtype=float).ravel()
    n = x.size
    tau = integrated_autocorrelation_time(x)
    mean = float(x.mean()) if n else math.nan
    if math.isnan(tau) or tau * 10.0 > n:
        return MeanInterval(mean, math.nan, confidence, n, "effective_sample_size",
                            autocorrelation_time=tau)
    z = float(stats.norm.ppf(0.5 + 0.5 * confidence))
    half = z * float(x.std(ddof=1)) * math.sqrt(tau / n)
    return MeanInterval(mean, half, confidence, n, "effective_sample_size",
                        batches_independent=True, autocorrelation_time=tau)


@dataclass(frozen=True)
class ConvergenceState:
    """The stop rule's verdict at one moment of a run.

    Attributes
    ----------
    time_s
        Simulated time of the verdict.
    converged
        Every interval is trusted and narrower than the tolerance, and ``time_s`` has reached the
        minimum time.
    reason
        Why (or why not), one line.
    intervals
        The intervals by observable name.
    tolerance
        Largest allowed relative half-width.
    """

    time_s: float
    converged: bool
    reason: str
    intervals: dict[str, MeanInterval]
    tolerance: float

    def as_dict(self) -> dict[str, Any]:
        return {"time_s": self.time_s, "converged": self.converged, "reason": self.reason,
                "tolerance": self.tolerance,
                "intervals": {k: v.as_dict() for k, v in self.intervals.items()}}


def convergence_state(series: Mapping[str, tuple[ArrayLike, ArrayLike | None]], time_s: float,
                      tolerance: float, min_time_s: float,
                      n_batches: int = DEFAULT_BATCHES,
                      confidence: float = 0.95) -> ConvergenceState:
    """Apply the stop rule: every observable's batch-means interval trusted and narrow enough.

    Parameters
    ----------
    series
        ``name -> (values, weights)`` over the counting window, in time order.
    time_s
        The current simulated time.
    tolerance
        Largest relative half-width (e.g. 0.01 for +-1% at ``confidence``).
    min_time_s
        No verdict of convergence before this time.
    """
    intervals = {name: batch_means(v, w, n_batches, confidence) for name, (v, w) in series.items()}
    return decide(intervals, time_s, tolerance, min_time_s, confidence)


_METHOD_WORDS = {"batch_means": "batch means", "cycle_means": "means of whole cycles"}


def decide(intervals: Mapping[str, MeanInterval], time_s: float, tolerance: float,
           min_time_s: float, confidence: float = 0.95) -> ConvergenceState:
    """The stop rule on intervals already formed: every one trusted and narrow enough, and
    ``time_s`` past ``min_time_s``."""
    intervals = dict(intervals)
    if time_s < min_time_s:
        return ConvergenceState(time_s, False, f"before the minimum time {min_time_s:g} s",
                                intervals, tolerance)
    for name, iv in intervals.items():
        if math.isnan(iv.half_width):
            what = (f"too few whole cycles ({iv.batches} after cutting {iv.truncated_batches} of "
                    f"start-up; {MIN_CYCLES} needed)" if iv.method == "cycle_means"
                    else f"too few samples for {iv.batches} batches")
            return ConvergenceState(time_s, False, f"{name}: {what}", intervals, tolerance)
        if not iv.batches_independent:
            return ConvergenceState(
                time_s, False, f"{name}: batch means correlated (lag-1 "
                f"{iv.batch_lag1_autocorrelation:.2f}); batches too short", intervals, tolerance)
        if not iv.relative_half_width <= tolerance:
            return ConvergenceState(
                time_s, False, f"{name}: +-{iv.relative_half_width:.2%} > {tolerance:.2%}",
                intervals, tolerance)
    widths = ", ".join(f"{k} +-{v.relative_half_width:.2%}" for k, v in intervals.items())
    methods = "+".join(sorted({v.method for v in intervals.values()}))
    return ConvergenceState(time_s, True, f"converged at {time_s:.4g} s: {widths} "
                            f"(tolerance {tolerance:.2%}, {confidence:.0%} "
                            f"{_METHOD_WORDS.get(methods, 'intervals')})",
                            intervals, tolerance)
