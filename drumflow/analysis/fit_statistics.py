"""Statistics of the ``Nu = a Re^b Pr^c`` fit: the paper's ANOVA and the serial correlation of
its time steps (:mod:`drumflow.analysis.correlation` fits; this module judges the fit).

ANOVA. For nonlinear regression Statgraphics reports *uncorrected* sums of squares: the total
is ``sum(Nu^2)`` with ``n`` degrees of freedom, the error is the residual sum of squares with
``n - p``, and the model is their difference with ``p`` (Table 8: 3 + 4799 = 4802 = n). The model
sum of squares is therefore defined as ``SS_total - SS_error`` (for a nonlinear model this is not
exactly ``sum(Nu_hat^2)``, and the paper's table adds up). ``F = MS_model / MS_error`` and its
p-value is from the F distribution with ``(p, n - p)`` degrees of freedom.

Serially correlated steps. The ANOVA and the standard errors above treat every time step as an
independent observation. Consecutive steps of one run are not: the residuals of the paper-style
fit follow the slow drift of the mean temperature, so the lag-1 autocorrelation of the residuals
is close to 1 and the 4,799 error degrees of freedom of Table 8 overstate the information in the
data. :class:`SerialCorrelation` gives the honest version beside it: the pooled lag-1
autocorrelation ``rho`` of the residuals within each run, the effective sample size of an AR(1)
series ``n_eff = n (1 - rho) / (1 + rho)`` (Bayley and Hammersley 1946; the variance of a mean of
AR(1) data is ``(1 + rho) / (1 - rho)`` times the independent one), the standard errors inflated
by ``sqrt(n / n_eff)`` and confidence intervals from the t distribution with ``n_eff - p``
degrees of freedom. The inflation is exact for a regressor that varies slowly within a run (as
Re does here: only through ``nu(T_ma)``); for a regressor that jumps at random from step to step
it overstates the error. A negative ``rho`` is taken as 0 (never narrower than the naive errors).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike
from scipy import stats

from drumflow.physics.validation import AnalysisInputError, as_float_array, check_positive

if TYPE_CHECKING:
    import pandas as pd

__all__ = ["AnovaTable", "SerialCorrelation", "anova_table", "effective_sample_size", "lag1_autocorrelation"]


@dataclass(frozen=True)
class AnovaTable:
    """Analysis of variance in the layout of the paper's Table 8 (uncorrected sums of squares).

    Attributes
    ----------
    ss_model, ss_error, ss_total
        Sums of squares; ``ss_total = sum(Nu^2)``, ``ss_model = ss_total - ss_error``.
    df_model, df_error, df_total
        Degrees of freedom ``p``, ``n - p``, ``n``.
    ms_model, ms_error
        Mean squares ``SS / df``.
    f_value
        ``ms_model / ms_error``.
    p_value
        Upper tail of the F(p, n - p) distribution at ``f_value``.
    """

    ss_model: float
    ss_error: float
    ss_total: float
    df_model: int
    df_error: int
    df_total: int
    ms_model: float
    ms_error: float
    f_value: float
    p_value: float

    def to_frame(self) -> pd.DataFrame:
        """The table as a :class:`pandas.DataFrame` with rows Model, Error, Total."""
        import pandas as pd  # local: keeps this module importable without pandas

        return pd.DataFrame(
            {
                "Sum of Squares": [self.ss_model, self.ss_error, self.ss_total],
                "Degrees of Freedom": [self.df_model, self.df_error, self.df_total],
                "Mean Square": [self.ms_model, self.ms_error, math.nan],
                "F Observed": [self.f_value, math.nan, math.nan],
                "P-Value": [self.p_value, math.nan, math.nan],
            },
            index=pd.Index(["Model", "Error", "Total"], name="Source of Variance"),
        )


def anova_table(ss_total: float, ss_error: float, n: int, n_params: int) -> AnovaTable:
    """Build the uncorrected ANOVA of a nonlinear fit (Statgraphics layout).

    Parameters
    ----------
    ss_total
        Uncorrected total sum of squares ``sum(y^2)``.
    ss_error
        Residual sum of squares.
    n
        Number of observations.
    n_params
        Number of fitted parameters ``p``; ``n > p`` is required.

    Returns
    -------
    AnovaTable

    Raises
    ------
    AnalysisInputError
        If ``n <= p``, ``p < 1`` or a sum of squares is negative or non-finite.

    Examples
    --------
    The paper's Table 8 (n = 4802, p = 3):

    >>> t = anova_table(58470.6, 4.05118, 4802, 3)
    >>> round(t.ms_error, 6), t.df_error
    (0.000844, 4799)
    """
    if n_params < 1:
        raise AnalysisInputError("n_params", n_params, "an integer >= 1")
    if n <= n_params:
        raise AnalysisInputError("n", n, f"more observations than parameters (> {n_params})")
    sst = check_positive("ss_total", ss_total)
    sse = float(ss_error)
    if not (math.isfinite(sse) and 0.0 <= sse <= sst):
        raise AnalysisInputError("ss_error", sse, f"a value in [0, ss_total = {sst:g}]")
    ssm = sst - sse
    df_m, df_e = int(n_params), int(n - n_params)
    ms_m, ms_e = ssm / df_m, sse / df_e
    f_value = ms_m / ms_e if ms_e > 0.0 else math.inf
    p_value = float(stats.f.sf(f_value, df_m, df_e)) if math.isfinite(f_value) else 0.0
    return AnovaTable(
        ss_model=ssm,
        ss_error=sse,
        ss_total=sst,
        df_model=df_m,
        df_error=df_e,
        df_total=int(n),
        ms_model=ms_m,
        ms_error=ms_e,
        f_value=f_value,
        p_value=p_value,
    )


def lag1_autocorrelation(residuals: ArrayLike, segments: ArrayLike | None = None) -> float:
    """Pooled lag-1 autocorrelation of residuals, pairs taken within a segment only.

    Parameters
    ----------
    residuals
        Residuals in time order (1-D).
    segments
        A label per residual (e.g. the run it comes from); a pair of neighbours counts only when
        both have the same label, so the seam between two runs is not a lag. None: one series.

    Returns
    -------
    float
        ``(sum r_i r_(i+1) / pairs) / (sum r_i^2 / n)``; NaN with no pair or zero residuals.
        The residuals are not centred: a run whose residuals share a sign (a misfit of that
        run) is serial correlation too, and centring would hide it.
    """
    r = as_float_array("residuals", residuals)
    labels = np.zeros(r.size, dtype=np.int64) if segments is None else np.asarray(segments)
    if labels.shape != r.shape:
        raise AnalysisInputError("segments", f"{labels.size} label(s)", f"one per residual ({r.size})")
    same = labels[1:] == labels[:-1]
    pairs = int(same.sum())
    power = float(r @ r) / r.size if r.size else 0.0
    if pairs == 0 or power == 0.0:
        return math.nan
    return float(np.sum(r[1:][same] * r[:-1][same]) / pairs / power)


def effective_sample_size(n: int, rho: float) -> float:
    """Effective number of independent observations of an AR(1) series of ``n`` points.

    ``n (1 - rho) / (1 + rho)`` with ``rho`` clipped to ``[0, 1)``: a negative autocorrelation
    is not allowed to claim more information than ``n`` independent points.
    """
    if not math.isfinite(rho):
        return float(n)
    r = min(max(rho, 0.0), 1.0 - 1e-12)
    return n * (1.0 - r) / (1.0 + r)


@dataclass(frozen=True)
class SerialCorrelation:
    """Standard errors of the fit allowing for serially correlated time steps.

    Attributes
    ----------
    lag1
        Pooled lag-1 autocorrelation of the residuals within each run (:func:`lag1_autocorrelation`).
    n_effective
        ``n (1 - rho) / (1 + rho)`` (:func:`effective_sample_size`).
    df_effective
        ``max(n_effective - p, 1)``: degrees of freedom of the t quantile.
    inflation
        ``sqrt(n / n_effective)``: the factor on the naive standard errors.
    se_a, se_b, se_c
        The naive standard errors times ``inflation`` (``se_c`` stays 0 when c was fixed).
    ci_a, ci_b, ci_c
        Confidence intervals ``estimate +/- t(df_effective) se``.
    """

    lag1: float
    n_effective: float
    df_effective: float
    inflation: float
    se_a: float
    se_b: float
    se_c: float
    ci_a: tuple[float, float]
    ci_b: tuple[float, float]
    ci_c: tuple[float, float]
