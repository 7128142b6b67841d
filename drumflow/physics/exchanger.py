"""Thermodynamic and counter-current heat-exchanger model of the whole cooler (Eqs. 42-48).

Method of Burgos-Florez et al., Processes 2019, 7, 673, Section 2.3. The cooler is a
counter-current exchanger between the material (hot, ``mdot_m``, ``cp_m``, ``T_mi -> T_mo``) and
the air (cold, ``mdot_a``, ``cp_a``, ``T_ai -> T_ao``), with the heat-transfer coefficient ``h``
from the per-step model (:mod:`drumflow.analysis.heat_transfer`) and an exchange area ``A_he``:

=======  ============================================================================
Eq. 43   ``Q_m = mdot_m cp_m (T_mi - T_mo)``  heat removed from the material (W)
Eq. 44   ``T_ao = T_ai + Q_m / (mdot_a cp_a)``
Eq. 45   ``Q_he = h A_he LMTD_he``
Eq. 47   ``LMTD_he = ((T_mi - T_ao) - (T_mo - T_ai)) / ln((T_mi - T_ao) / (T_mo - T_ai))``
Eq. 48   ``Q_he = Q_m``  closes the model
=======  ============================================================================

The paper writes Eq. 43 as ``mdot_m cp_m (T_mo - T_mi)`` (negative) but reports the thermal power
as a positive number in Table 7; here ``Q_m`` and ``Q_he`` are the positive heat removed from the
material.

Two directions are offered:

* :func:`solve_outlet_temperature` (forward): ``h`` and ``A_he`` known, find ``T_mo`` such that
  ``Q_he = Q_m``. The paper did this "by trial and error"; here :func:`scipy.optimize.brentq`.
* :func:`area_for_outlet_temperature` (inverse): ``T_mo`` known (the plant), find ``A_he``.

:func:`exchanger_area_from_section` scales the falling-particle area of the simulated drum
section to the whole cooler (Eq. 46, see its notes on the missing ``l``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.optimize import brentq

from drumflow.errors import InfeasibleExchangerError
from drumflow.physics.validation import (
    AnalysisInputError,
    check_finite,
    check_positive,
    exactly_one,
)

__all__ = [
    "ExchangerResult",
    "InfeasibleExchangerError",
    "area_for_outlet_temperature",
    "counter_current_exchanger",
    "exchanger_area_from_section",
    "log_mean_temperature_difference",
    "solve_outlet_temperature",
]


# Relative difference below which the two end differences of an exchanger are treated as equal:
# the LMTD formula is 0/0 there and its limit (the common difference) is used instead. 1e-12 is
# far below any physical significance yet well above double rounding of temperatures ~100.
_EQUAL_ENDS_RTOL = 1e-12


def log_mean_temperature_difference(
    delta_a: ArrayLike, delta_b: ArrayLike
) -> float | NDArray[np.float64]:
    """Log-mean temperature difference of a counter-current exchanger, NaN where undefined.

    ``LMTD = (dA - dB) / ln(dA / dB)`` with ``dA``, ``dB`` the hot-minus-cold temperature
    differences at the two ends (Eqs. 38 and 47).

    Parameters
    ----------
    delta_a, delta_b
        End temperature differences (K or deg C), broadcastable arrays or scalars.

    Returns
    -------
    float or numpy.ndarray
        LMTD; where ``dA == dB`` (to a relative 1e-12) the limit ``dA``; NaN where either difference
        is ``<= 0`` or not finite (log argument undefined: temperature cross). A float when both
        inputs are scalars.
    """
    a = np.asarray(delta_a, dtype=np.float64)
    b = np.asarray(delta_b, dtype=np.float64)
    a, b = np.broadcast_arrays(a, b)
    out = np.full(a.shape, np.nan)
    ok = np.isfinite(a) & np.isfinite(b) & (a > 0.0) & (b > 0.0)
    equal = ok & (np.abs(a - b) <= _EQUAL_ENDS_RTOL * np.maximum(np.abs(a), np.abs(b)))
    general = ok & ~equal
    # log1p((a-b)/b) == ln(a/b) but stays accurate when a and b are close, where the plain
    # quotient would lose digits to cancellation.
    out[general] = (a[general] - b[general]) / np.log1p((a[general] - b[general]) / b[general])
    out[equal] = 0.5 * (a[equal] + b[equal])
    return float(out) if out.ndim == 0 else out


@dataclass(frozen=True)
class ExchangerResult:
    """Operating point of the cooler as a counter-current exchanger (Table 7 layout).

    Attributes
    ----------
    material_inlet_temperature_c
        T_mi (deg C).
    material_outlet_temperature_c
        T_mo (deg C).
    air_inlet_temperature_c
        T_ai (deg C).
    air_outlet_temperature_c
        T_ao, Eq. 44 (deg C).
    heat_removed_w
        Q_m, Eq. 43, heat removed from the material (W), positive for cooling.
    heat_exchanged_w
        Q_he = h A_he LMTD_he, Eq. 45 (W); equals ``heat_removed_w`` at the solution.
    lmtd_c
        LMTD_he, Eq. 47 (K).
    h_w_m2k
        Heat-transfer coefficient used (W/(m2 K)).
    area_m2
        A_he (m2), given (forward) or computed (inverse).
    """

    material_inlet_temperature_c: float
    material_outlet_temperature_c: float
    air_inlet_temperature_c: float
    air_outlet_temperature_c: float
    heat_removed_w: float
    heat_exchanged_w: float
    lmtd_c: float
    h_w_m2k: float
    area_m2: float

    @property
    def balance_residual_w(self) -> float:
        """``Q_he - Q_m`` (W), the Eq. 48 check; ~0 for a converged solution."""
        return self.heat_exchanged_w - self.heat_removed_w


@dataclass(frozen=True)
class _Streams:
    c_m: float  # material capacity rate mdot_m cp_m (W/K)
    c_a: float  # air capacity rate mdot_a cp_a (W/K)
    t_mi: float
    t_ai: float

    def air_outlet(self, t_mo: float) -> float:
        return self.t_ai + self.c_m * (self.t_mi - t_mo) / self.c_a  # Eqs. 43-44

    def lmtd(self, t_mo: float) -> float:
        return float(
            log_mean_temperature_difference(self.t_mi - self.air_outlet(t_mo), t_mo - self.t_ai)
        )

    @property
    def lowest_outlet(self) -> float:
        # The material cannot leave below the air inlet (end B difference > 0), and the air
        # cannot leave above the material inlet (end A difference > 0): T_ao < T_mi
        # <=> T_mo > T_mi - (C_a / C_m)(T_mi - T_ai). The larger bound applies.
        return max(self.t_ai, self.t_mi - self.c_a / self.c_m * (self.t_mi - self.t_ai))


def _streams(
    material_mass_flow_kg_s: float,
    material_cp_j_kgk: float,
    material_inlet_temperature_c: float,
    air_mass_flow_kg_s: float,
    air_cp_j_kgk: float,
    air_inlet_temperature_c: float,
) -> _Streams:
    mdot_m = check_positive("material_mass_flow_kg_s", material_mass_flow_kg_s)
    cp_m = check_positive("material_cp_j_kgk", material_cp_j_kgk)
    t_mi = check_finite("material_inlet_temperature_c", material_inlet_temperature_c)
    mdot_a = check_positive("air_mass_flow_kg_s", air_mass_flow_kg_s)
    cp_a = check_positive("air_cp_j_kgk", air_cp_j_kgk)
    t_ai = check_finite("air_inlet_temperature_c", air_inlet_temperature_c)
    if t_mi <= t_ai:
        raise AnalysisInputError(
            "material_inlet_temperature_c",
            t_mi,
            f"a temperature above air_inlet_temperature_c = {t_ai:g} deg C (a cooler)",
        )
    return _Streams(mdot_m * cp_m, mdot_a * cp_a, t_mi, t_ai)


def _result(s: _Streams, t_mo: float, h: float, area: float) -> ExchangerResult:
    q_m = s.c_m * (s.t_mi - t_mo)
    lmtd = s.lmtd(t_mo)
    return ExchangerResult(
        material_inlet_temperature_c=s.t_mi,
        material_outlet_temperature_c=t_mo,
        air_inlet_temperature_c=s.t_ai,
        air_outlet_temperature_c=s.air_outlet(t_mo),
        heat_removed_w=q_m,
        heat_exchanged_w=h * area * lmtd,
        lmtd_c=lmtd,
        h_w_m2k=h,
        area_m2=area,
    )


def solve_outlet_temperature(
    *,
    h_w_m2k: float,
    area_m2: float,
    material_mass_flow_kg_s: float,
    material_cp_j_kgk: float,
    material_inlet_temperature_c: float,
    air_mass_flow_kg_s: float,
    air_cp_j_kgk: float,
    air_inlet_temperature_c: float,
) -> ExchangerResult:
    """Material outlet temperature for a known ``h`` and area (forward model, Eq. 48).

    Solves ``h A LMTD_he(T_mo) - mdot_m cp_m (T_mi - T_mo) = 0`` for ``T_mo`` with
    :func:`scipy.optimize.brentq`.

    Parameters
    ----------
    h_w_m2k
        Heat-transfer coefficient (W/(m2 K)), > 0.
    area_m2
        Exchange area A_he (m2), > 0.
    material_mass_flow_kg_s, material_cp_j_kgk, material_inlet_temperature_c
        Material stream: mass flow (kg/s), specific heat (J/(kg K)), inlet temperature (deg C).
    air_mass_flow_kg_s, air_cp_j_kgk, air_inlet_temperature_c
        Air stream: mass flow (kg/s), specific heat (J/(kg K)), inlet temperature (deg C), which
        must be below the material inlet temperature.

    Returns
    -------
    ExchangerResult
        T_mo, Q_m, T_ao, LMTD_he, Q_he and the inputs h, A_he.

    Raises
    ------
    AnalysisInputError
        For a non-positive or non-finite argument, or ``T_mi <= T_ai``.

    Notes
    -----
    Bracket. Physically ``T_ai < T_mo < T_mi`` (the material is cooled, and cannot leave colder
    than the air that cools it) and ``T_ao < T_mi`` (in counter-current the air leaves at the hot
    end and cannot exceed the material inlet), which with Eq. 44 means
    ``T_mo > T_mi - (mdot_a cp_a / mdot_m cp_m)(T_mi - T_ai)``. On the lower end of this interval
    one end difference of the exchanger goes to zero, so ``LMTD_he -> 0`` and the residual tends
    to ``-Q_m < 0``; at ``T_mo -> T_mi``, ``Q_m -> 0`` while ``LMTD_he -> T_mi - T_ai > 0`` and the
    residual is positive. The residual is continuous inside, so brentq converges; the root is
    unique (it is the epsilon-NTU solution of a counter-current exchanger). The ends are pulled in
    by 1e-12 of the interval so that both end differences stay strictly positive.

    Table 7, model one: ``h = 60.15``, ``A_he = 1099.28`` with the plant streams gives
    ``T_mo = 40.90`` deg C, ``Q_m = 998.40`` kW, ``T_ao = 69.73`` deg C, ``LMTD_he = 15.10`` K.
    """
    h = check_positive("h_w_m2k", h_w_m2k)
    area = check_positive("area_m2", area_m2)
    s = _streams(
        material_mass_flow_kg_s,
        material_cp_j_kgk,
        material_inlet_temperature_c,
        air_mass_flow_kg_s,
        air_cp_j_kgk,
        air_inlet_temperature_c,
    )
    lo_bound = s.lowest_outlet
    span = s.t_mi - lo_bound
    lo = lo_bound + 1e-12 * span
    hi = s.t_mi - 1e-12 * span

    def residual(t_mo: float) -> float:
        return h * area * s.lmtd(t_mo) - s.c_m * (s.t_mi - t_mo)

    if residual(lo) >= 0.0:
        # Pinched: the area is so large for the air's heat capacity rate that the air leaves at
        # the material inlet temperature. The LMTD falls only logarithmically as that end
        # difference vanishes, so the residual is still positive 1e-12 of the span from the
        # bound; the root lies closer than that, i.e. at the air-limited bound itself.
        return _result(s, lo, h, area)
    # xtol far below the 0.01 deg C the paper reports; rtol at brentq's floor (4 eps).
    t_mo = float(brentq(residual, lo, hi, xtol=1e-12, rtol=4.0 * 2.220446049250313e-16))
    return _result(s, t_mo, h, area)


def area_for_outlet_temperature(
    *,
    h_w_m2k: float,
    material_outlet_temperature_c: float,
    material_mass_flow_kg_s: float,
    material_cp_j_kgk: float,
    material_inlet_temperature_c: float,
    air_mass_flow_kg_s: float,
    air_cp_j_kgk: float,
    air_inlet_temperature_c: float,
) -> ExchangerResult:
    """Exchange area implied by a known material outlet temperature (inverse model).

    ``A_he = Q_m / (h LMTD_he)`` with ``Q_m`` from Eq. 43, ``T_ao`` from Eq. 44 and ``LMTD_he`` from
    Eq. 47.

    Parameters
    ----------
    h_w_m2k
        Heat-transfer coefficient (W/(m2 K)), > 0.
    material_outlet_temperature_c
        Known material outlet temperature T_mo (deg C).
    material_mass_flow_kg_s, material_cp_j_kgk, material_inlet_temperature_c
        Material stream (kg/s, J/(kg K), deg C).
    air_mass_flow_kg_s, air_cp_j_kgk, air_inlet_temperature_c
        Air stream (kg/s, J/(kg K), deg C).

    Returns
    -------
    ExchangerResult
        With the computed ``area_m2``; ``heat_exchanged_w`` equals ``heat_removed_w``.

    Raises
    ------
    InfeasibleExchangerError
        If ``T_mo`` is not strictly between ``T_ai`` and ``T_mi``, or if it would make the air leave
        at or above the material inlet temperature (temperature cross, infinite area). The
        message gives the feasible range of ``T_mo`` for the given streams.
    AnalysisInputError
        For any other invalid argument.

    Notes
    -----
    Table 7, industry cooler: ``h = 60.15``, ``T_mo = 45`` deg C gives ``A_he = 802.01`` m2,
    ``LMTD_he = 18.97`` K, ``Q_m = 915.04`` kW, ``T_ao = 66.42`` deg C.
    """
    h = check_positive("h_w_m2k", h_w_m2k)
    t_mo = check_finite("material_outlet_temperature_c", material_outlet_temperature_c)
    s = _streams(
        material_mass_flow_kg_s,
        material_cp_j_kgk,
        material_inlet_temperature_c,
        air_mass_flow_kg_s,
        air_cp_j_kgk,
        air_inlet_temperature_c,
    )
    lowest = s.lowest_outlet
    if not lowest < t_mo < s.t_mi:
        t_ao = s.air_outlet(t_mo)
        if t_mo >= s.t_mi:
            why = "the material must be cooled"
        elif t_mo <= s.t_ai:
            why = "the material cannot leave colder than the inlet air"
        else:
            why = (
                f"the air would leave at {t_ao:.4g} deg C, at or above the material inlet "
                f"{s.t_mi:g} deg C (temperature cross)"
            )
        raise InfeasibleExchangerError(
            "material_outlet_temperature_c",
            t_mo,
            f"a temperature in ({lowest:.6g}, {s.t_mi:g}) deg C for these streams; {why}",
        )
    q_m = s.c_m * (s.t_mi - t_mo)
    lmtd = s.lmtd(t_mo)
    area = q_m / (h * lmtd)
    return _result(s, t_mo, h, area)


def counter_current_exchanger(
    *,
    h_w_m2k: float,
    material_mass_flow_kg_s: float,
    material_cp_j_kgk: float,
    material_inlet_temperature_c: float,
    air_mass_flow_kg_s: float,
    air_cp_j_kgk: float,
    air_inlet_temperature_c: float,
    area_m2: float | None = None,
    material_outlet_temperature_c: float | None = None,
) -> ExchangerResult:
    """Cooler as a counter-current exchanger given either its area or its material outlet.

    Dispatches to :func:`solve_outlet_temperature` when ``area_m2`` is given and to
    :func:`area_for_outlet_temperature` when ``material_outlet_temperature_c`` is given.

    Parameters
    ----------
    h_w_m2k
        Heat-transfer coefficient (W/(m2 K)).
    material_mass_flow_kg_s, material_cp_j_kgk, material_inlet_temperature_c
        Material stream (kg/s, J/(kg K), deg C).
    air_mass_flow_kg_s, air_cp_j_kgk, air_inlet_temperature_c
        Air stream (kg/s, J/(kg K), deg C).
    area_m2
        Exchange area (m2). Exactly one of this and ``material_outlet_temperature_c``.
    material_outlet_temperature_c
        Known material outlet temperature (deg C).

    Returns
    -------
    ExchangerResult

    Raises
    ------
    AnalysisInputError
        If neither or both alternatives are given, or an argument is invalid.
    InfeasibleExchangerError
        If the requested outlet temperature is impossible.
    """
    streams = {
        "h_w_m2k": h_w_m2k,
        "material_mass_flow_kg_s": material_mass_flow_kg_s,
        "material_cp_j_kgk": material_cp_j_kgk,
        "material_inlet_temperature_c": material_inlet_temperature_c,
        "air_mass_flow_kg_s": air_mass_flow_kg_s,
        "air_cp_j_kgk": air_cp_j_kgk,
        "air_inlet_temperature_c": air_inlet_temperature_c,
    }
    which = exactly_one(
        area_m2=area_m2, material_outlet_temperature_c=material_outlet_temperature_c
    )
    if which == "area_m2":
        return solve_outlet_temperature(area_m2=area_m2, **streams)  # type: ignore[arg-type]
    return area_for_outlet_temperature(
        material_outlet_temperature_c=material_outlet_temperature_c,  # type: ignore[arg-type]
        **streams,
    )


def exchanger_area_from_section(
    falling_area_m2: float,
    *,
    cooler_length_m: float,
    section_length_m: float,
    dt_s: float,
) -> float:
    """Total exchange area of the cooler from the simulated section (Eq. 46, corrected).

    ``A_he = A_fp * (L / l) / dt * (1 s)``: the particle surface falling per second in the
    simulated section of length ``l``, scaled to the cooler length ``L``.

    Parameters
    ----------
    falling_area_m2
        A_fp, surface of the particles falling during one step (m2, Eq. 41).
    cooler_length_m
        Length of the real cooler L (m).
    section_length_m
        Length of the simulated drum section l (m).
    dt_s
        Step length the falling mass refers to (s).

    Returns
    -------
    float
        A_he (m2).

    Raises
    ------
    AnalysisInputError
        If an argument is not finite and positive.

    Notes
    -----
    Eq. 46 as printed, ``4 pi (Dp/2)^2 m_mf L / (dt m_p)``, has ``L`` but not the simulated length
    ``l``: it would give an area in m2 per metre of section. Table 7 follows
    ``A_fp (L / l) / dt``: model one, ``0.028928 * (19 / 0.1) / 0.005 = 1099.28`` m2; model two,
    ``0.23323 * (19 / 1) / 0.01 = 443.13`` m2 (A_fp values back-computed from Table 7; Table 6
    rounds them to 0.029 and 0.233). The factor ``1 s`` makes the dimensions explicit: the paper
    takes the area renewed by falling particles during one second as the exchange area.
    """
    a_fp = check_positive("falling_area_m2", falling_area_m2)
    big_l = check_positive("cooler_length_m", cooler_length_m)
    small_l = check_positive("section_length_m", section_length_m)
    dt = check_positive("dt_s", dt_s)
    one_second = 1.0
    return a_fp * (big_l / small_l) / dt * one_second
