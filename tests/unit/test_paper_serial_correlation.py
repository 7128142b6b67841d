"""Table 8's errors with serially correlated time steps (issue 10, item c).

The paper's ANOVA counts every time step as an independent observation. On a synthetic AR(1)
series, where the true sampling spread of the fitted exponent is known by Monte Carlo, the naive
standard error is far too small and the effective-sample-size error is close to the truth.
"""

from __future__ import annotations

import numpy as np
import pytest

from drumflow.analysis.correlation import fit_nusselt_correlation, fit_nusselt_correlation_from_runs
from drumflow.analysis.fit_statistics import effective_sample_size, lag1_autocorrelation

#: Two "runs" like the paper's: 400 steps each at Re about 3073 and 7686, Re drifting slowly
#: within a run (it moves only with the air viscosity), Pr fixed, c held at 1/3.
N = 400
RE = np.concatenate([np.linspace(3000.0, 3150.0, N), np.linspace(7600.0, 7800.0, N)])
PR = np.full(2 * N, 0.7282)
SEGMENTS = np.repeat([0, 1], N)
NU_TRUE = 0.05 * RE**0.52 * PR ** (1.0 / 3.0)
PHI = 0.9  # lag-1 autocorrelation of the noise
SD = 0.02  # marginal standard deviation of the noise
REPLICATES = 200


def _ar1(rng: np.random.Generator, n: int) -> np.ndarray:
    e = np.empty(n)
    e[0] = rng.normal(0.0, SD)
    innovations = rng.normal(0.0, SD * np.sqrt(1.0 - PHI**2), n)
    for i in range(1, n):
        e[i] = PHI * e[i - 1] + innovations[i]
    return e


def _fits(noise: str) -> list:  # type: ignore[type-arg]
    rng = np.random.default_rng(20190673)
    fits = []
    for _ in range(REPLICATES):
        if noise == "ar1":
            e = np.concatenate([_ar1(rng, N), _ar1(rng, N)])
        else:
            e = rng.normal(0.0, SD, 2 * N)
        fits.append(fit_nusselt_correlation(NU_TRUE + e, RE, PR, fit_prandtl_exponent=False,
                                            segments=SEGMENTS))
    return fits


def test_naive_errors_are_too_small_for_ar1_steps_and_the_serial_ones_are_not() -> None:
    fits = _fits("ar1")
    spread = float(np.std([f.b for f in fits], ddof=1))  # the true sampling spread of b
    naive = float(np.mean([f.se_b for f in fits]))
    honest = float(np.mean([f.serial.se_b for f in fits]))
    # Theory: for a regressor that barely moves within a run, the variance of b is inflated by
    # (1 + phi) / (1 - phi) = 19, i.e. the naive error is sqrt(19) = 4.4 times too small.
    # Measured: naive / spread = 0.22; 0.4 leaves room for the Monte Carlo error of the spread
    # (200 replicates: 5 % relative) and still fails a correct naive error by far.
    assert naive < 0.4 * spread
    # The serial-correlation error: measured 0.92 of the spread. rho, estimated from 400
    # residuals per run, comes out a little low (measured mean 0.89 for 0.9), which shrinks the
    # inflation by a few %; with the 5 % Monte Carlo error, 25 % either way.
    assert honest == pytest.approx(spread, rel=0.25)
    # The measured lag-1 autocorrelation of the residuals is the noise's, less that bias.
    assert float(np.mean([f.serial.lag1 for f in fits])) == pytest.approx(PHI, abs=0.03)
    # 95 % intervals: the naive ones miss the true b most of the time (measured coverage 35 %);
    # the serial ones cover it about 95 % of the time (binomial sd over 200: 1.5 %; 0.88 allows
    # the few % low bias above).
    naive_cover = np.mean([f.ci_b[0] <= 0.52 <= f.ci_b[1] for f in fits])
    honest_cover = np.mean([f.serial.ci_b[0] <= 0.52 <= f.serial.ci_b[1] for f in fits])
    assert naive_cover < 0.6
    assert 0.88 <= honest_cover <= 0.995


def test_independent_steps_keep_the_naive_errors() -> None:
    fits = _fits("white")
    # Independent noise: rho is about 0 (its sampling sd is 1/sqrt(800) = 0.035), n_eff about n,
    # so the serial errors stay within a few % of the naive ones (negative rho is clipped to 0).
    inflation = np.array([f.serial.inflation for f in fits])
    assert np.all(inflation >= 1.0)
    assert float(np.mean(inflation)) == pytest.approx(1.0, abs=0.05)


def test_lag1_counts_pairs_within_a_run_only() -> None:
    # Each run's residuals are constant with opposite signs: within a run the lag-1 product
    # is always +r^2 (rho = 1); the seam between the runs would add a -r^2 pair if counted.
    r = np.r_[np.full(5, 1.0), np.full(5, -1.0)]
    assert lag1_autocorrelation(r, np.repeat([0, 1], 5)) == pytest.approx(1.0, rel=1e-12)
    assert lag1_autocorrelation(r) == pytest.approx((8 - 1) / 9, rel=1e-12)
    # A strictly alternating series: rho = -1 per pair; n_eff clips it to n.
    alt = np.array([1.0, -1.0] * 5)
    assert lag1_autocorrelation(alt) == pytest.approx(-1.0, rel=1e-12)
    assert effective_sample_size(10, -1.0) == 10.0
    assert effective_sample_size(100, 0.9) == pytest.approx(100 * 0.1 / 1.9, rel=1e-12)


def test_fit_from_runs_labels_each_run() -> None:
    rng = np.random.default_rng(1)
    e = np.concatenate([_ar1(rng, N), _ar1(rng, N)])
    nu = NU_TRUE + e
    runs = [(nu[:N], RE[:N], PR[:N]), (nu[N:], RE[N:], PR[N:])]
    by_runs = fit_nusselt_correlation_from_runs(runs, fit_prandtl_exponent=False)
    direct = fit_nusselt_correlation(nu, RE, PR, fit_prandtl_exponent=False, segments=SEGMENTS)
    assert by_runs.serial is not None and direct.serial is not None
    assert by_runs.serial.lag1 == direct.serial.lag1
    assert by_runs.serial.se_b == direct.serial.se_b
