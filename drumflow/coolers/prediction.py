"""Predict the plant's outlet temperatures at other operating conditions (the paper's purpose).

Burgos-Florez et al., Processes 2019, 7, 673, Conclusions: with the dimensionless correlation
``Nu = a Re^b Pr^c`` (Eq. 56), "heat-transfer coefficients and overall process operating
characteristics can be predicted when process variables such as drum angular velocity, air
velocity, material inlet-outlet temperatures, and the average particle diameter are changed
inside the range of valid Reynolds numbers for the defined correlation". The paper does not say
how each variable enters the exchanger model (Eqs. 42-48). :func:`predict_plant` makes the
first-order assumptions below. They are listed in :data:`ASSUMPTIONS` and copied into every
:class:`Prediction`.

Reference state. One run of the case gives ``h`` (or a correlation from several runs gives
``Nu``), the section's falling mass flow ``F_ref``, and with it the cooler's exchange area
``A_he,ref`` (Eq. 46 with ``L / l``). A prediction changes some of the rotation speed ``N``,
the air mass flow ``mdot_a``, the feed rate ``mdot_m`` and the particle diameter ``Dp``, and
scales from that reference:

1. Falling mass flow ``F = F_ref (mdot_m / mdot_m,ref) (N / N_ref)``. The flights empty their
   load once per revolution (``~ N``), and the load is a fixed share of the hold-up. The hold-up
   is ``mdot_m`` times the residence time, and the residence time is held at the case's value
   (the paper: 30 min). A residence time that falls with ``N`` (Sullivan-type ``tau ~ 1/N``)
   would cancel the ``N`` factor, so the rpm predictions are the least certain ones. The particle
   diameter and the air flow do not change ``F``. The paper found almost the same falling mass
   for 8 and 20 mm particles once scaled to equal ``dt`` and ``l`` (Section 4.2), and the air
   drag on the curtain is ignored.
2. Exchange area ``A_he = A_he,ref (F / F_ref) (Dp_ref / Dp)``. Eq. 41 gives the surface per
   unit falling mass as ``6 / (rho Dp)``.
3. Void fraction (Eq. 53). The solids volume of the section scales with the hold-up, so
   ``V_m = V_m,ref (mdot_m / mdot_m,ref)``. A change of ``Dp`` at equal hold-up mass keeps
   ``V_m``.
4. Reynolds number (Eqs. 51-52). ``V_ai = mdot_a / (rho(T_ai) pi D^2 / 4)`` is proportional to
   ``mdot_a``, ``v_max = V_ai / Vf`` and ``Re = v_max Dp / nu``.
5. Air properties (``nu``, ``Pr``, ``k``) are taken at one temperature. With a reference
   :class:`~drumflow.analysis.methodology_result.MethodologyResult`, that is the mean of its valid
   steps' ``T_ma`` (Eq. 50), so the case's own point lies inside the range the correlation was
   fitted on. Otherwise it is ``T_ai``. The per-step air warming (``T_ma - T_ai``, hundredths of
   a kelvin in the paper) is not rescaled with the new conditions.
6. ``h = Nu k / Dp`` (Eq. 49), with ``k`` the conductivity the correlation was fitted with
   (``nusselt_conductivity``). A fixed ``h`` is used unchanged: it ignores how ``h`` depends on
   ``Re`` and suits only small changes.
7. The plant streams (Eqs. 42-48) are the case's ``plant`` and ``air`` sections with the new
   feed rate and air flow. ``T_mo`` comes from
   :func:`~drumflow.physics.exchanger.solve_outlet_temperature`.

Range. The correlation is empirical. A fitted :class:`NusseltCorrelation` carries its own range,
in the Re it was fitted with: drumflow's, Eqs. 51-54 as printed (the mean inlet velocity over
the whole drum cross-section, divided by the void factor).

One definition of Re. The paper's correlation (Eq. 58) is valid for 3073 < Re < 7686
(:data:`PAPER_REYNOLDS_RANGE`), but in the paper's own Re: its two models give 3073 and 7686
where Eqs. 51-54 give drumflow 1844 and 4609, the same ratio 1.667 for both (the paper's Re
implies v_max = 6.23 m/s; drumflow's V_ai / Vf is 3.74 m/s;
:func:`drumflow.analysis.published.reynolds_conversion`). Every Re that :func:`predict_plant`
computes and compares is drumflow's. The paper's correlation enters only through
:func:`paper_correlation`, which converts it to drumflow's definitions once: its range is
``PAPER_REYNOLDS_RANGE / 1.667`` and its coefficient is ``a 1.667^b (0.7282 / 0.7066)^c`` (the
second factor converts the paper's Pr of air at 30 deg C, from another property table, to
drumflow's), so that at drumflow's Re and Pr of a paper model it returns the paper's Nu.
:data:`PAPER_CORRELATION` and :data:`PAPER_REYNOLDS_RANGE` keep the published numbers and must
not be compared with drumflow's Re directly.

A prediction whose ``Re`` leaves the correlation's range gets a :class:`CorrelationRangeWarning`
in ``Prediction.range_warnings`` and a message in ``Prediction.warnings``. So does a ``Pr`` more
than 1 % outside the fitted ``Pr`` range. The function itself emits no Python warning, so that
a batch of predictions can be collected and reported.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, field
from typing import Any, Literal

from drumflow._json import json_safe
from drumflow.analysis.correlation import CorrelationRangeWarning, NusseltCorrelation
from drumflow.analysis.dimensionless import (
    drum_volume,
    mean_air_inlet_velocity,
    particle_volume,
)
from drumflow.analysis.heat_transfer import falling_particle_area
from drumflow.analysis.methodology_result import MethodologyResult, exchanger_to_dict
from drumflow.case import Case
from drumflow.coolers.plant import OperatingPoint, PlantSpec
from drumflow.physics import air
from drumflow.physics.exchanger import ExchangerResult, solve_outlet_temperature
from drumflow.physics.validation import AnalysisInputError, check_positive

__all__ = [
    "ASSUMPTIONS",
    "PAPER_CORRELATION",
    "PAPER_REYNOLDS_RANGE",
    "CorrelationRangeWarning",
    "Prediction",
    "paper_correlation",
    "predict_plant",
]

PAPER_REYNOLDS_RANGE: tuple[float, float] = (3073.0, 7686.0)
"""Validity range of the paper's correlation, Eq. 58 and Figure 9, as published: in the paper's
Re, 1.667 times drumflow's (module notes). Compare drumflow's Re with
``paper_correlation().reynolds_range`` instead."""

PAPER_CORRELATION: tuple[float, float, float] = (0.0531283, 0.523707, 1.00824)
"""``(a, b, c)`` of the paper's Eq. 58 as published (the particle conductivity in Nu, the
paper's Re and Pr); :func:`paper_correlation` gives it in drumflow's definitions."""


def paper_correlation() -> NusseltCorrelation:
    """The paper's Eq. 58 in drumflow's definitions of Re and Pr (module notes).

    ``Nu = a' Re^b Pr^c`` with ``a' = a f_Re^b f_Pr^c``, ``f_Re = Re_paper / Re_drumflow``
    (1.667, from the paper's two models) and ``f_Pr = 0.7282 / Pr_drumflow(30 C)``; the Re range
    is the published one divided by ``f_Re``, the Pr range drumflow's Pr at 30 deg C. Nu uses
    the particle conductivity (``nusselt_conductivity="particle"`` in :func:`predict_plant`).
    The ANOVA is the paper's Table 8; the paper gives no standard errors (NaN here).

    Returns
    -------
    NusseltCorrelation
    """
    from drumflow.analysis.fit_statistics import anova_table
    from drumflow.analysis.published import EQ58, reynolds_conversion

    conv = reynolds_conversion()
    a, b, c = PAPER_CORRELATION
    a_df = a * conv.factor**b * conv.prandtl_factor**c
    pr = conv.per_model["one"]["prandtl_drumflow"]
    nan_ci = (math.nan, math.nan)
    ms_error = 0.000844  # Table 8
    return NusseltCorrelation(
        a=a_df, b=b, c=c, se_a=math.nan, se_b=math.nan, se_c=math.nan,
        ci_a=nan_ci, ci_b=nan_ci, ci_c=nan_ci, prandtl_exponent_fitted=True,
        note=(f"the paper's Eq. 58 in drumflow's Re and Pr: a = {a:g} x {conv.factor:.4f}^{b:g} x "
              f"{conv.prandtl_factor:.4f}^{c:g} = {a_df:.6g}; Re range "
              f"{PAPER_REYNOLDS_RANGE[0]:g}-{PAPER_REYNOLDS_RANGE[1]:g} / {conv.factor:.4f}"),
        n=int(EQ58["observations"]), n_params=3, n_dropped=0,
        anova=anova_table(58470.6, 4.05118, int(EQ58["observations"]), 3),
        r_squared=math.nan, adjusted_r_squared=float(EQ58["adjusted_r2"]),
        residual_std=math.sqrt(ms_error),
        reynolds_range=(conv.to_drumflow(PAPER_REYNOLDS_RANGE[0]),
                        conv.to_drumflow(PAPER_REYNOLDS_RANGE[1])),
        prandtl_range=(pr, pr),
    )

# A fit on per-step data spans only the Pr of the per-step air temperatures, a few hundredths
# of a kelvin wide, so a strict Pr test would flag every prediction. Air Pr changes by about 1 %
# over 25 K (Incropera Table A.4, 300-350 K), so a 1 % excess means a really different air
# temperature.
_PRANDTL_RTOL = 0.01

ASSUMPTIONS: tuple[str, ...] = (
    "Falling mass flow F scales as (feed rate / reference) x (rpm / reference): the flights empty "
    "their load once per revolution, and the load follows the hold-up at the case's residence "
    "time. A residence time falling as 1/rpm would cancel the rpm factor, so rpm predictions are "
    "the least certain ones. Dp and the air flow leave F unchanged.",
    "Exchange area A_he scales as (F / F_ref) x (Dp_ref / Dp) (Eq. 41: surface per mass 6/(rho Dp)).",
    "Solids volume of the section scales with the feed rate (hold-up at fixed residence time); "
    "Dp at equal hold-up mass keeps it; the void fraction follows (Eq. 53).",
    "Air inlet velocity is proportional to the air mass flow (density at T_ai, full drum "
    "cross-section); v_max = V_ai / Vf; Re = v_max Dp / nu (Eqs. 51-52). This is drumflow's Re "
    "throughout; the paper's Re is 1.667 times it, and its Eq. 58 enters converted "
    "(paper_correlation).",
    "Air properties at one temperature: the reference run's mean T_ma, else T_ai; the per-step "
    "air warming is not rescaled.",
    "h = Nu k / Dp with the conductivity the correlation was fitted with; a fixed h is used "
    "unchanged (valid for small changes only).",
    "Plant streams: the case's plant and air sections with the new feed rate and air flow; T_mo "
    "from the counter-current exchanger model (Eq. 48).",
)


@dataclass(frozen=True)
class Prediction:
    """Outlet temperatures of the plant at new operating conditions, with the reference point.

    Attributes
    ----------
    h_source
        ``"correlation"`` or ``"fixed"``.
    reference, conditions
        The case's operating point and the predicted one.
    air_property_temperature_c
        Temperature at which ``nu``, ``Pr`` and (air) ``k`` were taken (deg C).
    conductivity_w_mk
        ``k`` in ``Nu = h Dp / k`` (W/(m K)).
    void_fraction, reference_void_fraction
        Eq. 53 at the new and the reference point.
    air_inlet_velocity_m_s, max_air_velocity_m_s
        ``V_ai`` and ``v_max`` at the new point (m/s).
    reynolds, reference_reynolds
        Eq. 51 at the new and the reference point.
    prandtl
        Air Prandtl number.
    nusselt
        ``h Dp / k`` at the new point.
    h_w_m2k, reference_h_w_m2k
        Heat-transfer coefficient at the new and the reference point (W/(m2 K)); equal for a
        fixed ``h``.
    measured_h_w_m2k
        The reference run's time-averaged ``h`` when a reference result was given, else None.
    falling_mass_flow_kg_s, reference_falling_mass_flow_kg_s
        Falling mass flow of the simulated section (kg/s).
    exchanger_area_m2, reference_exchanger_area_m2
        ``A_he`` of the cooler (m2).
    exchanger, reference_exchanger
        The exchanger model at the new and at the reference point (``T_mo``, ``T_ao``, ``Q_m``...).
    range_warnings
        A :class:`CorrelationRangeWarning` for each range the prediction leaves.
    warnings
        Human-readable remarks, including every range warning.
    assumptions
        The scaling assumptions (:data:`ASSUMPTIONS`).
    """

    h_source: Literal["correlation", "fixed"]
    reference: OperatingPoint
    conditions: OperatingPoint
    air_property_temperature_c: float
    conductivity_w_mk: float
    void_fraction: float
    reference_void_fraction: float
    air_inlet_velocity_m_s: float
    max_air_velocity_m_s: float
    reynolds: float
    reference_reynolds: float
    prandtl: float
    nusselt: float
    h_w_m2k: float
    reference_h_w_m2k: float
    measured_h_w_m2k: float | None
    falling_mass_flow_kg_s: float
    reference_falling_mass_flow_kg_s: float
    exchanger_area_m2: float
    reference_exchanger_area_m2: float
    exchanger: ExchangerResult
    reference_exchanger: ExchangerResult
    range_warnings: list[CorrelationRangeWarning] = field(default_factory=list)
    warnings: list[str] = field(default_factory=list)
    assumptions: tuple[str, ...] = ASSUMPTIONS

    @property
    def material_outlet_temperature_c(self) -> float:
        """Predicted ``T_mo`` (deg C)."""
        return self.exchanger.material_outlet_temperature_c

    @property
    def air_outlet_temperature_c(self) -> float:
        """Predicted ``T_ao`` (deg C)."""
        return self.exchanger.air_outlet_temperature_c

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dict (NaN as ``null``; warnings as strings)."""
        data = {
            "h_source": self.h_source,
            "reference": asdict(self.reference),
            "conditions": asdict(self.conditions),
            "air_property_temperature_C": self.air_property_temperature_c,
            "conductivity_W_mK": self.conductivity_w_mk,
            "void_fraction": self.void_fraction,
            "reference_void_fraction": self.reference_void_fraction,
            "air_inlet_velocity_m_s": self.air_inlet_velocity_m_s,
            "max_air_velocity_m_s": self.max_air_velocity_m_s,
            "reynolds": self.reynolds,
            "reference_reynolds": self.reference_reynolds,
            "prandtl": self.prandtl,
            "nusselt": self.nusselt,
            "h_W_m2K": self.h_w_m2k,
            "reference_h_W_m2K": self.reference_h_w_m2k,
            "measured_h_W_m2K": self.measured_h_w_m2k,
            "falling_mass_flow_kg_s": self.falling_mass_flow_kg_s,
            "reference_falling_mass_flow_kg_s": self.reference_falling_mass_flow_kg_s,
            "area_he_m2": self.exchanger_area_m2,
            "reference_area_he_m2": self.reference_exchanger_area_m2,
            "exchanger": exchanger_to_dict(self.exchanger),
            "reference_exchanger": exchanger_to_dict(self.reference_exchanger),
            "warnings": list(self.warnings),
            "assumptions": list(self.assumptions),
        }
        return json_safe(data)


def _reynolds(
    case: Case, point: OperatingPoint, solids_volume_m3: float, property_t_c: float
) -> tuple[float, float, float, float]:
    """``(Re, Vf, V_ai, v_max)`` at an operating point (Eqs. 51-54, assumptions 3-5)."""
    v_d = drum_volume(case.drum.diameter, case.drum.length)
    if solids_volume_m3 >= v_d:
        raise AnalysisInputError(
            "feed_rate",
            point.feed_rate_kg_s,
            f"a feed rate whose hold-up fits the drum section (solids {solids_volume_m3:.4g} m3 "
            f"in {v_d:.4g} m3 of drum)",
        )
    vf = (v_d - solids_volume_m3) / v_d
    v_ai = mean_air_inlet_velocity(
        air_mass_flow_kg_s=point.air_mass_flow_kg_s,
        drum_diameter_m=case.drum.diameter,
        air_inlet_temperature_c=case.air.inlet_temperature_C,
    )
    v_max = v_ai / vf
    nu = float(air.kinematic_viscosity(property_t_c, name="air property temperature"))
    return v_max * point.particle_diameter_m / nu, vf, v_ai, v_max


@dataclass(frozen=True)
class _ReferenceBasis:
    """What the prediction scales from: the reference section's fall, area and air temperature."""

    falling_mass_flow_kg_s: float
    area_m2: float
    property_temperature_c: float
    measured_h_w_m2k: float | None
    notes: tuple[str, ...] = ()


def _correlation_or_fixed_h(
    correlation_or_h: NusseltCorrelation | float,
) -> tuple[NusseltCorrelation | None, float]:
    """``(correlation, nan)`` for a fitted correlation, ``(None, h)`` for a fixed coefficient."""
    if isinstance(correlation_or_h, NusseltCorrelation):
        return correlation_or_h, math.nan
    if isinstance(correlation_or_h, (int, float)) and not isinstance(correlation_or_h, bool):
        return None, check_positive("correlation_or_h", correlation_or_h)
    raise AnalysisInputError(
        "correlation_or_h",
        type(correlation_or_h).__name__,
        "a NusseltCorrelation or a heat-transfer coefficient in W/(m2 K)",
    )


def _new_operating_point(
    ref: OperatingPoint,
    rpm: float | None,
    air_mass_flow: float | None,
    feed_rate: float | None,
    particle_diameter: float | None,
) -> OperatingPoint:
    """The reference point with the given values replaced (each checked finite and positive)."""
    check_positive("air.mass_flow of the case", ref.air_mass_flow_kg_s)
    return OperatingPoint(
        rpm=ref.rpm if rpm is None else check_positive("rpm", rpm),
        air_mass_flow_kg_s=ref.air_mass_flow_kg_s
        if air_mass_flow is None
        else check_positive("air_mass_flow", air_mass_flow),
        feed_rate_kg_s=ref.feed_rate_kg_s
        if feed_rate is None
        else check_positive("feed_rate", feed_rate),
        particle_diameter_m=ref.particle_diameter_m
        if particle_diameter is None
        else check_positive("particle_diameter", particle_diameter),
    )


def _check_not_centrifuging(case: Case, rpm: float) -> None:
    """Refuse a speed at which the bed would stick to the shell (Froude >= 1): no curtain."""
    omega = rpm * 2.0 * math.pi / 60.0
    froude = omega**2 * case.drum.radius / 9.81
    if froude >= 1.0:
        limit = 60.0 / (2.0 * math.pi) * math.sqrt(9.81 / case.drum.radius)
        raise AnalysisInputError(
            "rpm", rpm, f"a speed below {limit:.3g} rpm (Froude {froude:.3g} >= 1: centrifuging)"
        )


def _reference_basis(
    case: Case,
    ref: OperatingPoint,
    reference: MethodologyResult | None,
    falling_mass_flow_kg_s: float | None,
) -> _ReferenceBasis:
    """The reference fall, ``A_he`` and air property temperature, from a run or a mass flow."""
    if reference is not None:
        valid = reference.steps["valid"].to_numpy(dtype=bool)
        notes: tuple[str, ...] = ()
        if reference.case.hash() != case.hash():
            notes = (
                f"the reference run's case ({reference.case.name}) differs from the case given "
                f"({case.name}); the reference falling mass flow and area are used as they are",
            )
        return _ReferenceBasis(
            falling_mass_flow_kg_s=reference.falling_mass_flow_kg_s,
            area_m2=reference.exchanger_area_m2,
            property_temperature_c=float(
                reference.steps["mean_air_temperature_C"].to_numpy()[valid].mean()),
            measured_h_w_m2k=reference.h_mean_w_m2k,
            notes=notes,
        )
    f_ref = check_positive("falling_mass_flow_kg_s", falling_mass_flow_kg_s)
    # Eq. 46 with m_mf = F * dt is independent of dt: evaluate it for dt = 1 s.
    one_second = 1.0
    area = float(falling_particle_area(f_ref * one_second, ref.particle_diameter_m,
                                       case.particles.density))
    area *= case.plant.length / case.drum.length / one_second
    return _ReferenceBasis(
        falling_mass_flow_kg_s=f_ref,
        area_m2=area,
        property_temperature_c=float(case.air.inlet_temperature_C),
        measured_h_w_m2k=None,
    )


def _range_warnings(correlation: NusseltCorrelation, re: float, pr: float) -> list[CorrelationRangeWarning]:
    """Warnings for an ``Re`` outside the fitted range or a ``Pr`` well outside it."""
    found: list[CorrelationRangeWarning] = []
    lo, hi = correlation.reynolds_range
    if not lo <= re <= hi:
        found.append(CorrelationRangeWarning(
            f"Re = {re:.5g} is outside the correlation's range [{lo:.5g}, {hi:.5g}]: "
            "the predicted h is an extrapolation"))
    p_lo, p_hi = correlation.prandtl_range
    if pr < p_lo * (1.0 - _PRANDTL_RTOL) or pr > p_hi * (1.0 + _PRANDTL_RTOL):
        found.append(CorrelationRangeWarning(
            f"Pr = {pr:.4g} is more than {_PRANDTL_RTOL:.0%} outside the correlation's range "
            f"[{p_lo:.4g}, {p_hi:.4g}]"))
    return found


def predict_plant(
    correlation_or_h: NusseltCorrelation | float,
    case: Case,
    *,
    rpm: float | None = None,
    air_mass_flow: float | None = None,
    feed_rate: float | None = None,
    particle_diameter: float | None = None,
    reference: MethodologyResult | None = None,
    falling_mass_flow_kg_s: float | None = None,
    nusselt_conductivity: Literal["air", "particle"] = "air",
) -> Prediction:
    """Predict the plant outlet temperatures when rpm, air flow, feed rate or Dp change.

    See the module notes for the scaling assumptions; they are also in
    ``Prediction.assumptions``.

    Parameters
    ----------
    correlation_or_h
        A fitted :class:`~drumflow.analysis.correlation.NusseltCorrelation` (``h`` follows the
        new ``Re``), or a fixed heat-transfer coefficient in W/(m2 K) (used unchanged).
    case
        The case the reference was obtained with. Its drum, particles, air and plant sections
        give the reference operating point and the plant streams.
    rpm, air_mass_flow, feed_rate, particle_diameter
        New rotation speed (1/min), air mass flow (kg/s), material feed rate (kg/s) and particle
        diameter (m). None keeps the case's value.
    reference
        The methodology result of a run of ``case``. It gives the reference falling mass flow,
        ``A_he`` and the air property temperature. Give this or ``falling_mass_flow_kg_s``.
    falling_mass_flow_kg_s
        The section's falling mass flow at the case's conditions (kg/s, e.g.
        ``summary.json``'s ``falling_mass_flow_kg_s``), when no reference result is at hand.
    nusselt_conductivity
        Conductivity in ``Nu = h Dp / k``. It must be the one the correlation was fitted with:
        ``"air"`` (air at the property temperature) or ``"particle"``
        (``particles.conductivity``, as in the paper's Eq. 58).

    Returns
    -------
    Prediction
        The predicted and the reference exchanger results, ``Re``, ``h``, ``A_he``, and the
        warnings.

    Raises
    ------
    AnalysisInputError
        If a value is not finite and positive, neither or both of ``reference`` and
        ``falling_mass_flow_kg_s`` are given, the new rpm makes the drum centrifuge
        (Froude >= 1), the hold-up no longer fits the section, or the streams are not a cooler.
    """
    if nusselt_conductivity not in ("air", "particle"):
        raise AnalysisInputError("nusselt_conductivity", nusselt_conductivity, "'air' or 'particle'")
    if (reference is None) == (falling_mass_flow_kg_s is None):
        raise AnalysisInputError(
            "reference or falling_mass_flow_kg_s",
            "both given" if reference is not None else "none given",
            "exactly one: the reference run's methodology result or its falling mass flow",
        )
    correlation, fixed_h = _correlation_or_fixed_h(correlation_or_h)
    plant = PlantSpec.from_case(case)
    ref = plant.operating_point()
    new = _new_operating_point(ref, rpm, air_mass_flow, feed_rate, particle_diameter)
    _check_not_centrifuging(case, new.rpm)
    basis = _reference_basis(case, ref, reference, falling_mass_flow_kg_s)
    notes = list(basis.notes)

    # Assumptions 1-3.
    fall_ratio = (new.feed_rate_kg_s / ref.feed_rate_kg_s) * (new.rpm / ref.rpm)
    f_new = basis.falling_mass_flow_kg_s * fall_ratio
    a_new = basis.area_m2 * fall_ratio * (ref.particle_diameter_m / new.particle_diameter_m)
    v_m_ref = particle_volume(case.particle_count, ref.particle_diameter_m)
    v_m_new = v_m_ref * (new.feed_rate_kg_s / ref.feed_rate_kg_s)

    # Assumptions 4-6.
    property_t = basis.property_temperature_c
    re_ref, vf_ref, _, _ = _reynolds(case, ref, v_m_ref, property_t)
    re_new, vf_new, v_ai, v_max = _reynolds(case, new, v_m_new, property_t)
    pr = float(air.prandtl(property_t, name="air property temperature"))
    if nusselt_conductivity == "particle":
        k = float(case.particles.conductivity)
    else:
        k = float(air.thermal_conductivity(property_t, name="air property temperature"))
    if correlation is not None:
        nu_new = float(correlation.predict(re_new, pr, warn=False))
        h_new = nu_new * k / new.particle_diameter_m
        h_ref = float(correlation.predict(re_ref, pr, warn=False)) * k / ref.particle_diameter_m
        range_warnings = _range_warnings(correlation, re_new, pr)
        notes.extend(str(w) for w in range_warnings)
    else:
        h_new = h_ref = fixed_h
        nu_new = h_new * new.particle_diameter_m / k
        range_warnings = []
        if new != ref:
            notes.append(
                f"h held at {fixed_h:.4g} W/(m2 K): the prediction ignores how h changes with Re "
                f"(here {re_ref:.4g} -> {re_new:.4g}); use a fitted correlation for larger changes"
            )

    # Assumption 7.
    exchanger = solve_outlet_temperature(
        h_w_m2k=h_new,
        area_m2=a_new,
        **plant.changed(feed_rate_kg_s=new.feed_rate_kg_s,
                        air_mass_flow_kg_s=new.air_mass_flow_kg_s).streams(),
    )
    reference_exchanger = solve_outlet_temperature(
        h_w_m2k=h_ref, area_m2=basis.area_m2, **plant.streams()
    )
    return Prediction(
        h_source="correlation" if correlation is not None else "fixed",
        reference=ref,
        conditions=new,
        air_property_temperature_c=property_t,
        conductivity_w_mk=k,
        void_fraction=vf_new,
        reference_void_fraction=vf_ref,
        air_inlet_velocity_m_s=v_ai,
        max_air_velocity_m_s=v_max,
        reynolds=re_new,
        reference_reynolds=re_ref,
        prandtl=pr,
        nusselt=nu_new,
        h_w_m2k=h_new,
        reference_h_w_m2k=h_ref,
        measured_h_w_m2k=basis.measured_h_w_m2k,
        falling_mass_flow_kg_s=f_new,
        reference_falling_mass_flow_kg_s=basis.falling_mass_flow_kg_s,
        exchanger_area_m2=a_new,
        reference_exchanger_area_m2=basis.area_m2,
        exchanger=exchanger,
        reference_exchanger=reference_exchanger,
        range_warnings=range_warnings,
        warnings=notes,
    )
