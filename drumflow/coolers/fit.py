"""Fitting the fluid-bed cooler's two parameters to plant data (the source's sec. 2.4, Fig. 8).

Given operating points (ambient air, product inlet, the cooled-air supply temperature if
section C was chilled) with the measured product outlet and mixed air outlet temperatures,
:func:`fit_parameters` finds the convective efficiency f_c and the hood loss conductance
hLosses A that minimise the sum of squared residuals of both temperatures (K, equal weights:
both are thermocouple readings of similar accuracy), with :func:`scipy.optimize.least_squares`
(trust-region reflective, bounds 0 < f_c <= 1, 0 <= hA). The 95 % confidence intervals are
the linearised ones: covariance s^2 (J^T J)^-1 with s^2 = SSR / (m - 2) and Student's t at
m - 2 degrees of freedom (Bates and Watts 1988, ch. 2).

The source's plant data are confidential, so :func:`synthetic_points` makes a data set from
the model itself at known parameters plus Gaussian noise, and the tests check that the fit
recovers the known parameters within its confidence intervals.
"""

from __future__ import annotations

import csv
import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray
from scipy import stats
from scipy.optimize import least_squares

from drumflow.coolers import _fluidization as fl
from drumflow.coolers.fluid_bed import operate, run_unit
from drumflow.coolers.fluid_bed_case import KELVIN, Conditions, FluidBedCase
from drumflow.errors import BadFileError, CaseError
from drumflow.readers import read_text

FloatArray = NDArray[np.float64]

#: Columns of an operating-points CSV (t_cooled_air_C empty = ambient air in section C).
COLUMNS = ("t_ambient_C", "rh_pct", "t_product_in_C", "t_cooled_air_C", "t_product_out_C",
           "t_air_out_C")


@dataclass(frozen=True)
class OperatingPoint:
    """One measured operating point (temperatures in K)."""

    ambient_temperature: float
    relative_humidity: float  # 0..1
    product_inlet_temperature: float
    cooled_air_temperature: float | None
    product_outlet_temperature: float
    air_outlet_temperature: float


def read_points(path: Path | str) -> list[OperatingPoint]:
    """Read an operating-points CSV.

    Raises
    ------
    CaseError
        Missing file or columns, not UTF-8 text, or a value that is not a number or outside its
        range (the row and column named).
    """
    path = Path(path)
    if not path.is_file():
        raise CaseError([f"data file {path}: not found"], path)
    try:
        text = read_text(path, "operating points")
    except BadFileError as exc:
        raise CaseError([exc.problem], path) from None
    lines = [ln for ln in text.splitlines() if ln.strip() and not ln.startswith("#")]
    reader = csv.DictReader(lines)
    missing = [c for c in COLUMNS if c not in (reader.fieldnames or [])]
    if missing:
        raise CaseError([f"columns {', '.join(missing)} missing; required: {', '.join(COLUMNS)}"], path)
    points: list[OperatingPoint] = []
    problems: list[str] = []
    limits = {"t_ambient_C": (-40, 60), "rh_pct": (0, 100), "t_product_in_C": (-20, 200),
              "t_cooled_air_C": (-20, 60), "t_product_out_C": (-40, 200), "t_air_out_C": (-40, 200)}
    for i, row in enumerate(reader, start=2):
        values: dict[str, float | None] = {}
        for col in COLUMNS:
            text = (row.get(col) or "").strip()
            if col == "t_cooled_air_C" and text == "":
                values[col] = None
                continue
            try:
                v = float(text)
            except ValueError:
                problems.append(f"row {i}, {col} = {text!r}: not a number")
                continue
            lo, hi = limits[col]
            if not (lo <= v <= hi) or not math.isfinite(v):
                problems.append(f"row {i}, {col} = {v:g}: allowed >= {lo} and <= {hi}")
            values[col] = v
        if len(values) == len(COLUMNS):
            cooled = values["t_cooled_air_C"]
            points.append(OperatingPoint(
                float(values["t_ambient_C"] or 0.0) + KELVIN, float(values["rh_pct"] or 0.0) / 100.0,
                float(values["t_product_in_C"] or 0.0) + KELVIN,
                None if cooled is None else cooled + KELVIN,
                float(values["t_product_out_C"] or 0.0) + KELVIN,
                float(values["t_air_out_C"] or 0.0) + KELVIN))
    if problems:
        raise CaseError(problems, path)
    if len(points) < 3:
        raise CaseError([f"{len(points)} operating points: at least 3 are needed to fit 2 parameters"], path)
    return points


def write_points(path: Path | str, points: list[OperatingPoint], header: str = "") -> None:
    """Write operating points as CSV (degC), with optional '#' comment lines first."""
    lines = [f"# {ln}" for ln in header.splitlines()] if header else []
    lines.append(",".join(COLUMNS))
    for p in points:
        cooled = "" if p.cooled_air_temperature is None else f"{p.cooled_air_temperature - KELVIN:.3f}"
        lines.append(f"{p.ambient_temperature - KELVIN:.2f},{p.relative_humidity * 100:.1f},"
                     f"{p.product_inlet_temperature - KELVIN:.2f},{cooled},"
                     f"{p.product_outlet_temperature - KELVIN:.3f},{p.air_outlet_temperature - KELVIN:.3f}")
    Path(path).write_text("\n".join(lines) + "\n")


def point_conditions(case: FluidBedCase, point: OperatingPoint) -> Conditions:
    p = case.air.pressure_kPa * 1e3
    w = fl.humidity_ratio(point.ambient_temperature, p, point.relative_humidity)
    river = case.refrigeration.river_water_temperature_C
    return Conditions(point.ambient_temperature, w, point.product_inlet_temperature,
                      (river + KELVIN) if river is not None else point.ambient_temperature)


def predict(case: FluidBedCase, points: list[OperatingPoint], convective_efficiency: float,
            losses_conductance: float) -> tuple[FloatArray, FloatArray]:
    """Model product and measured-air outlet temperatures (K) at each point."""
    product, air = [], []
    for pt in points:
        r = run_unit(case, point_conditions(case, pt), convective_efficiency=convective_efficiency,
                     losses_conductance=losses_conductance,
                     cooled_air_temperature=pt.cooled_air_temperature)
        product.append(r.product_outlet_temperature)
        air.append(r.air_measured_temperature)
    return np.asarray(product), np.asarray(air)


@dataclass
class FitResult:
    """Fitted f_c and hLosses A with 95 % confidence intervals and the residuals."""

    convective_efficiency: float
    losses_conductance: float  # W/K
    ci_convective_efficiency: tuple[float, float]
    ci_losses_conductance: tuple[float, float]
    standard_errors: tuple[float, float]
    correlation: float
    residual_std: float  # K
    points: int
    measured_product: FloatArray
    measured_air: FloatArray
    model_product: FloatArray
    model_air: FloatArray
    success: bool
    message: str
    evaluations: int

    def summary(self) -> dict[str, Any]:
        return {
            "convective_efficiency": self.convective_efficiency,
            "convective_efficiency_ci95": list(self.ci_convective_efficiency),
            "h_losses_A_kW_per_K": self.losses_conductance / 1e3,
            "h_losses_A_kW_per_K_ci95": [v / 1e3 for v in self.ci_losses_conductance],
            "standard_errors": {"convective_efficiency": self.standard_errors[0],
                                "h_losses_A_kW_per_K": self.standard_errors[1] / 1e3},
            "parameter_correlation": self.correlation,
            "residual_std_K": self.residual_std,
            "points": self.points,
            "rms_product_K": float(np.sqrt(np.mean((self.model_product - self.measured_product) ** 2))),
            "rms_air_K": float(np.sqrt(np.mean((self.model_air - self.measured_air) ** 2))),
            "success": self.success,
            "message": self.message,
            "model_evaluations": self.evaluations,
        }


def fit_parameters(case: FluidBedCase, points: list[OperatingPoint],
                   initial: tuple[float, float] | None = None) -> FitResult:
    """Least-squares fit of (f_c, hLosses A) to measured outlet temperatures.

    Parameters
    ----------
    case
        The unit (its own f_c and hA are only the default starting point).
    points
        Operating points with measurements.
    initial
        Starting (f_c, hA in W/K).
    """
    measured_p = np.array([p.product_outlet_temperature for p in points])
    measured_a = np.array([p.air_outlet_temperature for p in points])
    start = initial or (case.losses.convective_efficiency, case.losses.h_losses_A_kW_per_K * 1e3)
    # hA is fitted in kW/K so both unknowns are of order one for the trust region.
    x0 = np.array([start[0], start[1] / 1e3])

    def residuals(x: FloatArray) -> FloatArray:
        tp, ta = predict(case, points, float(x[0]), float(x[1]) * 1e3)
        return np.concatenate([tp - measured_p, ta - measured_a])

    sol = least_squares(residuals, x0, bounds=([1e-3, 0.0], [1.0, 1000.0]), x_scale=[0.1, 1.0],
                        diff_step=1e-4, xtol=1e-10, ftol=1e-10)
    m, n = sol.fun.size, 2
    ssr = float(sol.fun @ sol.fun)
    s2 = ssr / (m - n)
    jac = sol.jac
    cov = s2 * np.linalg.inv(jac.T @ jac)
    se = np.sqrt(np.diag(cov))
    t = float(stats.t.ppf(0.975, m - n))
    fc, ha_kw = float(sol.x[0]), float(sol.x[1])
    tp, ta = predict(case, points, fc, ha_kw * 1e3)
    return FitResult(
        convective_efficiency=fc, losses_conductance=ha_kw * 1e3,
        ci_convective_efficiency=(fc - t * se[0], fc + t * se[0]),
        ci_losses_conductance=((ha_kw - t * se[1]) * 1e3, (ha_kw + t * se[1]) * 1e3),
        standard_errors=(float(se[0]), float(se[1]) * 1e3),
        correlation=float(cov[0, 1] / (se[0] * se[1])), residual_std=math.sqrt(s2), points=len(points),
        measured_product=measured_p, measured_air=measured_a, model_product=tp, model_air=ta,
        success=bool(sol.success), message=str(sol.message), evaluations=int(sol.nfev))


def synthetic_points(case: FluidBedCase, count: int, convective_efficiency: float,
                     losses_conductance: float, noise: float = 0.3, seed: int = 1) -> list[OperatingPoint]:
    """Operating points made by the model at known parameters, plus N(0, noise^2) K noise.

    Ambient temperature uniform on 0..32 degC, relative humidity on 40..85 %, product inlet
    on the case's +-3 K; section C chilled by the 'auto' control of the true model when
    ambient air is not enough (as the plant would run). ``noise`` is the thermocouple
    standard deviation, K.
    """
    rng = np.random.default_rng(seed)
    p = case.air.pressure_kPa * 1e3
    auto = case.model_copy(update={"air": case.air.model_copy(
        update={"cooled": case.air.cooled.model_copy(update={"temperature_C": "auto"})})})
    out: list[OperatingPoint] = []
    for _ in range(count):
        t_amb = rng.uniform(0.0, 32.0) + KELVIN
        rh = rng.uniform(0.40, 0.85)
        rh = min(rh, 1.0)
        t_in = case.product.inlet_temperature_C + KELVIN + rng.uniform(-3.0, 3.0)
        river = case.refrigeration.river_water_temperature_C
        cond = Conditions(t_amb, fl.humidity_ratio(t_amb, p, rh), t_in,
                          (river + KELVIN) if river is not None else t_amb)
        op = operate(auto, cond, convective_efficiency=convective_efficiency,
                     losses_conductance=losses_conductance)
        unit = op.unit
        out.append(OperatingPoint(
            t_amb, rh, t_in, unit.cooled_air_temperature,
            unit.product_outlet_temperature + rng.normal(0.0, noise),
            unit.air_measured_temperature + rng.normal(0.0, noise)))
    return out
