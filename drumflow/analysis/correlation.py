"""Levenberg-Marquardt fit of ``Nu = a Re^b Pr^c`` with a Statgraphics-style ANOVA (Eq. 56).

Method of Burgos-Florez et al., Processes 2019, 7, 673, Sections 2.5 and 4.4. The paper fits the
per-step dimensionless numbers of both models with the Marquardt method of Statgraphics
Centurion and reports (Eq. 58, Table 8)::

    Nu = 0.0531283 Re^0.523707 Pr^1.00824,   3073 < Re < 7686

    Source   Sum of squares   DoF    Mean square   F            p
    Model    58466.6          3      19488.87      23,086,378   0.0000
    Error    4.05118          4799   0.000844
    Total    58470.6          4802
    Adjusted R-squared 99.8634 %

Fit. The model is fitted on the original (not logarithmic) scale, like Statgraphics, with
:func:`scipy.optimize.least_squares` (``method="lm"``, MINPACK's Levenberg-Marquardt) and an
analytic Jacobian. Starting values come from the log-linear least-squares fit
``ln Nu = ln a + b ln Re + c ln Pr``.

ANOVA and serially correlated steps: :mod:`drumflow.analysis.fit_statistics`.

R-squared. Both R-squared values use the *corrected* total ``sum((Nu - mean)^2)``, as Statgraphics
does for its nonlinear-regression R-squared: ``R2 = 1 - SSE / SST_c`` and
``R2_adj = 1 - (SSE / (n - p)) / (SST_c / (n - 1))``. (With the uncorrected total every fit of
positive data would score ~100 %.) Table 8's 99.8634 % is consistent with this definition: it
implies a variance of Nu of about 0.62, as expected for two clusters of steps at Nu ~ 2.6 and ~ 4.2.

Identifiability of c. Within one run the Reynolds number changes only through ``nu(T_ma)`` and
the Prandtl number only through ``T_ma``, so ``ln Pr`` is (nearly) constant or a linear function
of ``ln Re``; ``c`` cannot then be separated from ``a`` and ``b``. The fit checks the spread of
``ln Pr`` left after regressing it on ``[1, ln Re]``; below ``spread_tol`` the exponent ``c`` is
held at ``fixed_prandtl_exponent`` (default 1/3) and only ``a`` and ``b`` are fitted, and the result
says so. The paper's data (two runs at Pr ~ 0.728) are in that situation: its c = 1.008 is not
determined by the data; only ``a Pr^c`` is.
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, Protocol

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy import stats
from scipy.optimize import least_squares

from drumflow.analysis.fit_statistics import (
    AnovaTable,
    SerialCorrelation,
    anova_table,
    effective_sample_size,
    lag1_autocorrelation,
)
from drumflow.physics.validation import (
    AnalysisInputError,
    as_float_array,
    check_positive,
    check_same_length,
)

if TYPE_CHECKING:
    pass

__all__ = [
    "CorrelationRangeWarning",
    "NusseltCorrelation",
    "fit_nusselt_correlation",
    "fit_nusselt_correlation_from_runs",
]


class CorrelationRangeWarning(UserWarning):
    """A correlation is evaluated outside the Re or Pr range of the data it was fitted on."""


class _HasNumbers(Protocol):
    nusselt: ArrayLike
    reynolds: ArrayLike
    prandtl: ArrayLike


@dataclass(frozen=True)
class NusseltCorrelation:
    """Fitted correlation ``Nu = a Re^b Pr^c`` with its statistics.

    Attributes
    ----------
    a, b, c
        Coefficients. ``c`` is the fixed value when ``prandtl_exponent_fitted`` is False.
    se_a, se_b, se_c
        Asymptotic standard errors ``sqrt(diag(s^2 (J^T J)^-1))``; ``se_c`` is 0 when c was fixed.
    ci_a, ci_b, ci_c
        95 % confidence intervals ``estimate +/- t(0.975, n - p) se``.
    prandtl_exponent_fitted
        False when Pr did not vary independently of Re and ``c`` was held fixed.
    note
        Human-readable remark on the fit (e.g. why c was fixed); empty otherwise.
    n, n_params
        Number of points used and of fitted parameters.
    n_dropped
        Points dropped before fitting (non-finite values, e.g. masked steps; and non-positive
        values when ``drop_nonpositive`` was set).
    anova
        The Table 8 ANOVA.
    r_squared, adjusted_r_squared
        Against the corrected total sum of squares (see module notes).
    residual_std
        ``sqrt(SSE / (n - p))``.
    reynolds_range, prandtl_range
        ``(min, max)`` of the data, the validity range of the correlation.
    serial
        The standard errors allowing for serially correlated steps (module notes); None when
        there is no pair of consecutive points.
    """

    a: float
    b: float
    c: float
    se_a: float
    se_b: float
    se_c: float
    ci_a: tuple[float, float]
    ci_b: tuple[float, float]
    ci_c: tuple[float, float]
    prandtl_exponent_fitted: bool
    note: str
    n: int
    n_params: int
    n_dropped: int
    anova: AnovaTable
    r_squared: float
    adjusted_r_squared: float
    residual_std: float
    reynolds_range: tuple[float, float]
    prandtl_range: tuple[float, float]
    serial: SerialCorrelation | None = None

    def in_range(self, reynolds: ArrayLike, prandtl: ArrayLike) -> NDArray[np.bool_]:
        """True where ``(Re, Pr)`` lies inside the ranges of the fitted data."""
        re = np.asarray(reynolds, dtype=np.float64)
        pr = np.asarray(prandtl, dtype=np.float64)
        return (
            (re >= self.reynolds_range[0])
            & (re <= self.reynolds_range[1])
            & (pr >= self.prandtl_range[0])
            & (pr <= self.prandtl_range[1])
        )

    def predict(
        self, reynolds: ArrayLike, prandtl: ArrayLike, *, warn: bool = True
    ) -> float | NDArray[np.float64]:
        """Evaluate ``a Re^b Pr^c``.

        Parameters
        ----------
        reynolds, prandtl
            Reynolds and Prandtl numbers (> 0), broadcastable.
        warn
            Emit a :class:`CorrelationRangeWarning` when a point is outside the fitted range
            (the correlation is an empirical fit and should not be extrapolated).

        Returns
        -------
        float or numpy.ndarray
            Nu; a float when both inputs are scalars.

        Raises
        ------
        AnalysisInputError
            If a value is not finite and positive.
        """
        re = np.asarray(reynolds, dtype=np.float64)
        pr = np.asarray(prandtl, dtype=np.float64)
        for name, arr in (("reynolds", re), ("prandtl", pr)):
            bad = ~(np.isfinite(arr) & (arr > 0.0))
            if np.any(bad):
                first = float(np.ravel(arr[bad] if arr.ndim else arr)[0])
                raise AnalysisInputError(name, first, "finite numbers > 0")
        if warn and not np.all(self.in_range(re, pr)):
            warnings.warn(
                f"correlation evaluated outside its fitted range "
                f"Re in [{self.reynolds_range[0]:.6g}, {self.reynolds_range[1]:.6g}], "
                f"Pr in [{self.prandtl_range[0]:.6g}, {self.prandtl_range[1]:.6g}]",
                CorrelationRangeWarning,
                stacklevel=2,
            )
        out = self.a * re**self.b * pr**self.c
        return float(out) if np.ndim(out) == 0 else out


def _collect(
    nusselt: ArrayLike,
    reynolds: ArrayLike,
    prandtl: ArrayLike,
    drop_nonpositive: bool,
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64], NDArray[np.bool_]]:
    nu = as_float_array("nusselt", nusselt, allow_nan=True)
    re = as_float_array("reynolds", reynolds, allow_nan=True)
    pr = as_float_array("prandtl", prandtl, allow_nan=True)
    check_same_length([("nusselt", nu), ("reynolds", re), ("prandtl", pr)])
    keep = np.isfinite(nu) & np.isfinite(re) & np.isfinite(pr)
    if drop_nonpositive:
        keep &= (nu > 0.0) & (re > 0.0) & (pr > 0.0)
    nu, re, pr = nu[keep], re[keep], pr[keep]
    for name, arr in (("nusselt", nu), ("reynolds", re), ("prandtl", pr)):
        nonpos = arr <= 0.0
        if nonpos.any():
            raise AnalysisInputError(
                f"{name} ({int(nonpos.sum())} of {arr.size} values)",
                float(arr[nonpos][0]),
                "values > 0 (a power law needs positive data; filter the steps, e.g. h > 0, "
                "or pass drop_nonpositive=True)",
            )
    return nu, re, pr, keep


def _residual_spread(y: NDArray[np.float64], x: NDArray[np.float64] | None) -> float:
    # Standard deviation of y after removing its least-squares fit on [1, x] (or on [1] only):
    # the part of y that other regressors cannot explain.
    cols = [np.ones_like(y)] if x is None else [np.ones_like(y), x]
    design = np.column_stack(cols)
    coef, *_ = np.linalg.lstsq(design, y, rcond=None)
    return float(np.std(y - design @ coef))


def _prandtl_choice(ln_pr: NDArray[np.float64], ln_re: NDArray[np.float64],
                    fit_prandtl_exponent: bool | None, c_fixed: float, tol: float) -> tuple[bool, str]:
    """Whether ``c`` is fitted, and the note saying why not (module notes)."""
    if fit_prandtl_exponent is not None:
        fit_c = bool(fit_prandtl_exponent)
        return fit_c, "" if fit_c else f"c held at {c_fixed:.6g} by request"
    pr_spread = _residual_spread(ln_pr, ln_re)
    if pr_spread >= tol:
        return True, ""
    return False, (f"Pr does not vary independently of Re (residual spread of ln Pr {pr_spread:.3g} "
                   f"< {tol:g}); c held at {c_fixed:.6g}, a absorbs Pr^c")


def _power_law_fit(nu: NDArray[np.float64], ln_re: NDArray[np.float64], ln_pr: NDArray[np.float64],
                   fit_c: bool, c_fixed: float,
                   ) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """Levenberg-Marquardt on ``Nu = a Re^b Pr^c`` (c held unless ``fit_c``), from the
    log-linear least-squares start: the parameters, the residuals and the Jacobian there."""
    n = nu.size
    ln_nu = np.log(nu)
    # Starting values: linear least squares on the logarithms.
    if fit_c:
        design = np.column_stack([np.ones(n), ln_re, ln_pr])
        target = ln_nu
    else:
        design = np.column_stack([np.ones(n), ln_re])
        target = ln_nu - c_fixed * ln_pr
    start, *_ = np.linalg.lstsq(design, target, rcond=None)
    x0 = np.array([math.exp(start[0]), *start[1:]])

    def model(x: NDArray[np.float64]) -> NDArray[np.float64]:
        c = x[2] if fit_c else c_fixed
        return x[0] * np.exp(x[1] * ln_re + c * ln_pr)

    def residuals(x: NDArray[np.float64]) -> NDArray[np.float64]:
        return model(x) - nu

    def jacobian(x: NDArray[np.float64]) -> NDArray[np.float64]:
        base = model(x) / x[0]  # Re^b Pr^c
        cols = [base, x[0] * base * ln_re]
        if fit_c:
            cols.append(x[0] * base * ln_pr)
        return np.column_stack(cols)

    # x_scale="jac" keeps a (order 0.01-1) and the exponents (order 0.1-1) equally well
    # conditioned; tolerances near machine precision so the fit is limited by the data only.
    sol = least_squares(
        residuals,
        x0,
        jac=jacobian,
        method="lm",
        x_scale="jac",
        ftol=1e-14,
        xtol=1e-14,
        gtol=1e-14,
        max_nfev=10000,
    )
    if not sol.success:
        raise AnalysisInputError(
            "nusselt", f"{n} points", f"data a power law can be fitted to ({sol.message})"
        )
    x = sol.x
    return x, residuals(x), jacobian(x)


def fit_nusselt_correlation(
    nusselt: ArrayLike,
    reynolds: ArrayLike,
    prandtl: ArrayLike,
    *,
    fit_prandtl_exponent: bool | None = None,
    fixed_prandtl_exponent: float = 1.0 / 3.0,
    spread_tol: float = 1e-3,
    drop_nonpositive: bool = False,
    confidence: float = 0.95,
    segments: ArrayLike | None = None,
) -> NusseltCorrelation:
    """Fit ``Nu = a Re^b Pr^c`` by Levenberg-Marquardt, Eq. 56.

    Parameters
    ----------
    nusselt, reynolds, prandtl
        Data points, 1-D and of equal length (concatenate several runs first, or use
        :func:`fit_nusselt_correlation_from_runs`). Points with a NaN (masked steps) are dropped
        and counted in ``n_dropped``.
    fit_prandtl_exponent
        ``None`` (default): fit ``c`` only if Pr varies independently of Re (see module notes);
        ``True``: always fit it; ``False``: always hold it at ``fixed_prandtl_exponent``.
    fixed_prandtl_exponent
        Value of ``c`` when it is not fitted (default 1/3, the usual laminar-boundary-layer value).
    spread_tol
        Threshold on the standard deviation of ``ln Pr`` not explained by ``[1, ln Re]``, and of
        ``ln Re`` itself, below which the exponent is considered not identifiable. 1e-3 (a 0.1 %
        independent variation) is well above rounding noise and well below the spread needed for
        a meaningful exponent.
    drop_nonpositive
        Drop points with a non-positive value instead of raising.
    confidence
        Level of the confidence intervals (default 0.95).
    segments
        A label per point naming the run (time series) it belongs to, in time order within a
        run; used only for the serial-correlation errors (``serial``). None: the points are one
        time series.

    Returns
    -------
    NusseltCorrelation

    Raises
    ------
    AnalysisInputError
        If the arrays differ in length, a value is infinite or non-positive (unless dropped),
        there are not more points than parameters, or Re does not vary (``b`` not identifiable).
    """
    tol = check_positive("spread_tol", spread_tol)
    c_fixed = float(fixed_prandtl_exponent)
    if not math.isfinite(c_fixed):
        raise AnalysisInputError("fixed_prandtl_exponent", c_fixed, "a finite number")
    if not 0.0 < confidence < 1.0:
        raise AnalysisInputError("confidence", confidence, "a value in (0, 1)")
    nu, re, pr, keep = _collect(nusselt, reynolds, prandtl, drop_nonpositive)
    n_dropped = int((~keep).sum())
    labels: NDArray[np.int64] | None = None
    if segments is not None:
        all_labels = np.asarray(segments)
        if all_labels.shape != keep.shape:
            raise AnalysisInputError("segments", f"{all_labels.size} label(s)",
                                     f"one per point ({keep.size})")
        labels = all_labels[keep]

    ln_re, ln_pr = np.log(re), np.log(pr)
    n = int(nu.size)
    if n < 3:
        raise AnalysisInputError("nusselt", f"{n} usable point(s)", "at least 3 points")
    if _residual_spread(ln_re, None) < tol:
        raise AnalysisInputError(
            "reynolds",
            f"spread of ln(Re) {_residual_spread(ln_re, None):.3g}",
            f"a spread >= spread_tol = {tol:g} to identify the Re exponent b "
            "(combine runs with different particle diameters or air velocities)",
        )

    fit_c, note = _prandtl_choice(ln_pr, ln_re, fit_prandtl_exponent, c_fixed, tol)
    n_params = 3 if fit_c else 2
    if n <= n_params:
        raise AnalysisInputError(
            "nusselt", f"{n} usable point(s)", f"more points than parameters (> {n_params})"
        )

    x, res, jac = _power_law_fit(nu, ln_re, ln_pr, fit_c, c_fixed)
    sse = float(res @ res)
    dof = n - n_params
    s2 = sse / dof
    # Covariance from the Gauss-Newton approximation; pinv guards a nearly singular J^T J.
    cov = s2 * np.linalg.pinv(jac.T @ jac)
    se = np.sqrt(np.clip(np.diag(cov), 0.0, None))
    t_crit = float(stats.t.ppf(0.5 + confidence / 2.0, dof))

    def ci(value: float, err: float) -> tuple[float, float]:
        return (value - t_crit * err, value + t_crit * err)

    a, b = float(x[0]), float(x[1])
    c = float(x[2]) if fit_c else c_fixed
    se_a, se_b = float(se[0]), float(se[1])
    se_c = float(se[2]) if fit_c else 0.0

    serial = _serial(res, labels, n, n_params, (a, b, c), (se_a, se_b, se_c), confidence)

    sst_c = float(np.sum((nu - nu.mean()) ** 2))
    if sst_c > 0.0:
        r2 = 1.0 - sse / sst_c
        r2_adj = 1.0 - (sse / dof) / (sst_c / (n - 1))
    else:
        r2 = r2_adj = math.nan

    return NusseltCorrelation(
        a=a,
        b=b,
        c=c,
        se_a=se_a,
        se_b=se_b,
        se_c=se_c,
        ci_a=ci(a, se_a),
        ci_b=ci(b, se_b),
        ci_c=ci(c, se_c),
        prandtl_exponent_fitted=fit_c,
        note=note,
        n=n,
        n_params=n_params,
        n_dropped=n_dropped,
        anova=anova_table(float(nu @ nu), sse, n, n_params),
        r_squared=r2,
        adjusted_r_squared=r2_adj,
        residual_std=math.sqrt(s2),
        reynolds_range=(float(re.min()), float(re.max())),
        prandtl_range=(float(pr.min()), float(pr.max())),
        serial=serial,
    )


def _serial(residuals: NDArray[np.float64], labels: NDArray[np.int64] | None, n: int,
            n_params: int, estimates: tuple[float, float, float],
            naive_se: tuple[float, float, float], confidence: float) -> SerialCorrelation | None:
    """The naive errors widened for the lag-1 autocorrelation of the residuals (module notes)."""
    rho = lag1_autocorrelation(residuals, labels)
    if not math.isfinite(rho):
        return None
    n_eff = effective_sample_size(n, rho)
    inflation = math.sqrt(n / n_eff)
    df = max(n_eff - n_params, 1.0)
    t_crit = float(stats.t.ppf(0.5 + confidence / 2.0, df))
    se = tuple(inflation * e for e in naive_se)
    ci = tuple((v - t_crit * e, v + t_crit * e) for v, e in zip(estimates, se, strict=True))
    return SerialCorrelation(lag1=rho, n_effective=n_eff, df_effective=df, inflation=inflation,
                             se_a=se[0], se_b=se[1], se_c=se[2], ci_a=ci[0], ci_b=ci[1],
                             ci_c=ci[2])


def fit_nusselt_correlation_from_runs(
    runs: Iterable[_HasNumbers | Sequence[ArrayLike]],
    **kwargs: object,
) -> NusseltCorrelation:
    """Fit one correlation to the steps of several runs.

    Parameters
    ----------
    runs
        Each run is either an object with ``nusselt``, ``reynolds`` and ``prandtl`` arrays (e.g.
        :class:`~drumflow.analysis.dimensionless.DimensionlessSteps`) or a ``(nusselt, reynolds,
        prandtl)`` triple. The arrays of all runs are concatenated.
    **kwargs
        Passed to :func:`fit_nusselt_correlation`.

    Returns
    -------
    NusseltCorrelation

    Raises
    ------
    AnalysisInputError
        If no run is given, a run has the wrong shape, or the fit itself rejects the data.
    """
    nus: list[NDArray[np.float64]] = []
    res: list[NDArray[np.float64]] = []
    prs: list[NDArray[np.float64]] = []
    for i, run in enumerate(runs):
        triple: tuple[Any, ...]
        if all(hasattr(run, k) for k in ("nusselt", "reynolds", "prandtl")):
            triple = (run.nusselt, run.reynolds, run.prandtl)  # type: ignore[union-attr]
        else:
            try:
                triple = tuple(run)  # type: ignore[arg-type]
            except TypeError:
                triple = ()
            if len(triple) != 3:
                raise AnalysisInputError(
                    f"runs[{i}]",
                    type(run).__name__,
                    "an object with nusselt/reynolds/prandtl or a (nu, re, pr) triple",
                )
        names = [f"runs[{i}].{k}" for k in ("nusselt", "reynolds", "prandtl")]
        arrays = [
            as_float_array(name, v, allow_nan=True)
            for name, v in zip(names, triple, strict=True)
        ]
        check_same_length(list(zip(names, arrays, strict=True)))
        nus.append(arrays[0])
        res.append(arrays[1])
        prs.append(arrays[2])
    if not nus:
        raise AnalysisInputError("runs", "an empty sequence", "at least one run")
    # Each run is its own time series: the serial correlation is measured within runs.
    kwargs.setdefault("segments", np.concatenate([np.full(v.size, i) for i, v in enumerate(nus)]))
    return fit_nusselt_correlation(
        np.concatenate(nus),
        np.concatenate(res),
        np.concatenate(prs),
        **kwargs,  # type: ignore[arg-type]
    )
