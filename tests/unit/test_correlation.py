"""Levenberg-Marquardt fit of Nu = a Re^b Pr^c (Eq. 56) and its Table 8 style ANOVA."""

from __future__ import annotations

import warnings
from types import SimpleNamespace

import numpy as np
import pytest
from scipy import stats

from drumflow.analysis.correlation import (
    CorrelationRangeWarning,
    fit_nusselt_correlation,
    fit_nusselt_correlation_from_runs,
)
from drumflow.analysis.fit_statistics import anova_table
from drumflow.errors import AnalysisInputError

# Paper, Eq. 58 and Table 8.
A, B, C = 0.0531283, 0.523707, 1.00824
N_PAPER = 4802
SIGMA = float(np.sqrt(0.000844))  # sqrt(MS_error) of Table 8: the paper's scatter of Nu


def _paper_like(seed: int, n: int = N_PAPER, pr: tuple[float, float] = (0.69, 0.73)):
    """Synthetic data from Eq. 58 over the paper's Re range, Pr near 0.7, Table 8 scatter."""
    rng = np.random.default_rng(seed)
    re = rng.uniform(3073.0, 7686.0, n)
    prs = rng.uniform(*pr, n)
    nu = A * re**B * prs**C + rng.normal(0.0, SIGMA, n)
    return nu, re, prs


def test_recovers_paper_coefficients_inside_confidence_intervals() -> None:
    nu, re, pr = _paper_like(seed=20190673)
    fit = fit_nusselt_correlation(nu, re, pr)
    assert fit.prandtl_exponent_fitted and fit.note == "" and fit.n_params == 3
    assert fit.ci_a[0] < A < fit.ci_a[1]
    assert fit.ci_b[0] < B < fit.ci_b[1]
    assert fit.ci_c[0] < C < fit.ci_c[1]
    # Interval widths follow from n = 4802 and the Table 8 scatter: b is pinned to about
    # +/- 0.001 and c to about +/- 0.02 (a 4x margin on the observed half-widths).
    assert fit.ci_b[1] - fit.ci_b[0] < 0.008
    assert fit.ci_c[1] - fit.ci_c[0] < 0.12
    assert fit.reynolds_range[0] >= 3073.0 and fit.reynolds_range[1] <= 7686.0


def test_exact_data_are_fitted_exactly() -> None:
    rng = np.random.default_rng(1)
    re = rng.uniform(3000.0, 8000.0, 50)
    pr = rng.uniform(0.68, 0.74, 50)
    nu = A * re**B * pr**C
    fit = fit_nusselt_correlation(nu, re, pr)
    # Noise-free data: LM with tolerances 1e-14 lands on the generating values to ~1e-9.
    assert fit.a == pytest.approx(A, rel=1e-7)
    assert fit.b == pytest.approx(B, rel=1e-7)
    assert fit.c == pytest.approx(C, rel=1e-7)


def test_anova_adds_up_and_matches_its_definitions() -> None:
    nu, re, pr = _paper_like(seed=7)
    fit = fit_nusselt_correlation(nu, re, pr)
    t = fit.anova
    resid = nu - fit.predict(re, pr, warn=False)
    # Sums computed here independently of the module; rel 1e-10 is float summation noise.
    assert t.ss_total == pytest.approx(float(np.sum(nu**2)), rel=1e-10)
    assert t.ss_error == pytest.approx(float(np.sum(resid**2)), rel=1e-10)
    assert t.ss_model + t.ss_error == pytest.approx(t.ss_total, rel=1e-12)
    assert (t.df_model, t.df_error, t.df_total) == (3, N_PAPER - 3, N_PAPER)
    assert t.df_model + t.df_error == t.df_total
    assert t.ms_model == pytest.approx(t.ss_model / 3, rel=1e-12)
    assert t.ms_error == pytest.approx(t.ss_error / (N_PAPER - 3), rel=1e-12)
    assert t.f_value == pytest.approx(t.ms_model / t.ms_error, rel=1e-12)
    assert t.p_value == stats.f.sf(t.f_value, 3, N_PAPER - 3)
    sst_c = float(np.sum((nu - nu.mean()) ** 2))
    assert fit.r_squared == pytest.approx(1 - t.ss_error / sst_c, rel=1e-10)
    assert fit.adjusted_r_squared == pytest.approx(
        1 - (t.ss_error / (N_PAPER - 3)) / (sst_c / (N_PAPER - 1)), rel=1e-10
    )
    # The error mean square estimates the generating scatter: with 4799 dof its relative
    # standard error is sqrt(2/4799) = 2 %, so 10 % is a 5-sigma bound.
    assert t.ms_error == pytest.approx(SIGMA**2, rel=0.10)


def test_anova_reproduces_table8_layout() -> None:
    t = anova_table(58470.6, 4.05118, N_PAPER, 3)
    assert (t.df_model, t.df_error, t.df_total) == (3, 4799, 4802)
    # Table 8 rounds SS to 0.1, so MS_model is known to ~1e-5 and MS_error to its 3 figures.
    assert t.ms_model == pytest.approx(19488.87, rel=1e-5)
    assert t.ms_error == pytest.approx(0.000844, abs=5e-7)
    assert t.f_value == pytest.approx(23_086_378, rel=1e-5)
    assert t.p_value < 5e-5  # printed as 0.0000
    frame = t.to_frame()
    assert list(frame.index) == ["Model", "Error", "Total"]


def test_standard_errors_match_monte_carlo_scatter() -> None:
    # The asymptotic standard error of b should equal the spread of b over repeated samples.
    rng = np.random.default_rng(42)
    re = rng.uniform(3073.0, 7686.0, 300)
    pr = rng.uniform(0.69, 0.73, 300)
    clean = A * re**B * pr**C
    bs, ses = [], []
    for _ in range(200):
        fit = fit_nusselt_correlation(clean + rng.normal(0.0, 0.05, re.size), re, pr)
        bs.append(fit.b)
        ses.append(fit.se_b)
    # 200 replicates estimate a standard deviation to +/- 5 % (1/sqrt(2*199)); 20 % is 4 sigma.
    assert np.std(bs, ddof=1) == pytest.approx(np.mean(ses), rel=0.20)


# ------------------------------------------------------------------ Prandtl not identifiable


def test_constant_prandtl_fixes_c_and_fits_a_and_b() -> None:
    nu, re, _ = _paper_like(seed=3)
    pr = np.full(re.size, 0.7282)  # one value, as in a single run at ~30 deg C
    nu = A * re**B * pr**C + np.random.default_rng(4).normal(0.0, SIGMA, re.size)
    fit = fit_nusselt_correlation(nu, re, pr)
    assert not fit.prandtl_exponent_fitted and fit.n_params == 2
    assert fit.c == pytest.approx(1.0 / 3.0) and fit.se_c == 0.0
    assert "c held at 0.333333" in fit.note
    # a absorbs Pr^(C - 1/3): the identifiable combination is a Pr^c.
    a_eff = A * 0.7282 ** (C - 1.0 / 3.0)
    assert fit.ci_a[0] < a_eff < fit.ci_a[1]
    assert fit.ci_b[0] < B < fit.ci_b[1]
    assert fit.anova.df_model == 2 and fit.anova.df_error == re.size - 2


def test_prandtl_tied_to_reynolds_is_not_identifiable_either() -> None:
    # Within a run Pr and Re both follow T_ma, so ln Pr is a linear function of ln Re.
    rng = np.random.default_rng(5)
    re = rng.uniform(3073.0, 7686.0, 500)
    pr = 0.7282 * (re / 3073.0) ** -0.01
    nu = A * re**B * pr**C
    fit = fit_nusselt_correlation(nu, re, pr, fixed_prandtl_exponent=C)
    assert not fit.prandtl_exponent_fitted
    # With c fixed at its true value and Pr^c exactly a power of Re, b absorbs -0.01 C.
    assert fit.b == pytest.approx(B, rel=1e-6)
    assert fit.a == pytest.approx(A, rel=1e-6)


def test_fit_prandtl_exponent_can_be_forced_off() -> None:
    nu, re, pr = _paper_like(seed=8)
    fit = fit_nusselt_correlation(nu, re, pr, fit_prandtl_exponent=False, fixed_prandtl_exponent=C)
    assert not fit.prandtl_exponent_fitted and fit.c == C and "by request" in fit.note
    assert fit.ci_a[0] < A < fit.ci_a[1]


# ------------------------------------------------------------------------- runs, predict


def test_runs_are_concatenated_and_masked_steps_dropped() -> None:
    nu, re, pr = _paper_like(seed=11, n=400)
    nu_masked = nu.copy()
    nu_masked[[3, 250]] = np.nan  # two masked steps
    run_a = SimpleNamespace(nusselt=nu_masked[:200], reynolds=re[:200], prandtl=pr[:200])
    run_b = (nu_masked[200:], re[200:], pr[200:])
    fit = fit_nusselt_correlation_from_runs([run_a, run_b])
    keep = np.isfinite(nu_masked)
    direct = fit_nusselt_correlation(nu[keep], re[keep], pr[keep])
    assert fit.n == 398 and fit.n_dropped == 2
    # Same points, same deterministic algorithm: identical to float noise.
    assert fit.a == pytest.approx(direct.a, rel=1e-12)
    assert fit.b == pytest.approx(direct.b, rel=1e-12)


def test_predict_and_range_warning() -> None:
    nu, re, pr = _paper_like(seed=12, n=300)
    fit = fit_nusselt_correlation(nu, re, pr)
    inside_re, inside_pr = 5000.0, 0.71
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # no warning inside the fitted range
        value = fit.predict(inside_re, inside_pr)
    assert isinstance(value, float)
    assert value == pytest.approx(fit.a * inside_re**fit.b * inside_pr**fit.c, rel=1e-12)
    with pytest.warns(CorrelationRangeWarning, match="outside its fitted range"):
        fit.predict(np.array([5000.0, 20000.0]), 0.71)
    assert fit.in_range(np.array([5000.0, 20000.0]), 0.71).tolist() == [True, False]


# ------------------------------------------------------------------------------ errors


def test_too_few_points() -> None:
    with pytest.raises(AnalysisInputError, match="at least 3 points"):
        fit_nusselt_correlation([2.5, 4.0], [3000.0, 7000.0], [0.70, 0.72])


def test_non_positive_values_are_rejected_or_dropped() -> None:
    nu, re, pr = _paper_like(seed=13, n=100)
    nu[5] = -0.5  # a heating step gives a negative h, hence a negative Nu
    with pytest.raises(AnalysisInputError, match=r"nusselt \(1 of 100 values\) = -0.5"):
        fit_nusselt_correlation(nu, re, pr)
    fit = fit_nusselt_correlation(nu, re, pr, drop_nonpositive=True)
    assert fit.n == 99 and fit.n_dropped == 1


def test_constant_reynolds_is_rejected() -> None:
    with pytest.raises(AnalysisInputError, match="reynolds = spread of ln"):
        fit_nusselt_correlation([2.5, 2.6, 2.55, 2.52], [3073.0] * 4, [0.70, 0.71, 0.72, 0.73])


def test_mismatched_lengths_and_bad_options() -> None:
    with pytest.raises(AnalysisInputError, match="prandtl = 2 value"):
        fit_nusselt_correlation([1.0, 2.0, 3.0], [1.0, 2.0, 3.0], [0.7, 0.7])
    with pytest.raises(AnalysisInputError, match="reynolds\\[1\\] = inf"):
        fit_nusselt_correlation([1.0, 2.0, 3.0], [1.0, np.inf, 3.0], [0.7, 0.7, 0.7])
    with pytest.raises(AnalysisInputError, match="spread_tol = 0"):
        fit_nusselt_correlation([1.0, 2.0, 3.0], [1.0, 2.0, 3.0], [0.7, 0.7, 0.7], spread_tol=0.0)
    with pytest.raises(AnalysisInputError, match="runs = an empty sequence"):
        fit_nusselt_correlation_from_runs([])
    with pytest.raises(AnalysisInputError, match=r"runs\[0\]"):
        fit_nusselt_correlation_from_runs([(np.ones(3), np.ones(3))])
