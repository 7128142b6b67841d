"""Law tests of the grate-cooler model (:mod:`drumflow.coolers.grate`), issue 36.

Independent references:

* the packed-bed correlation of Bird, Stewart and Lightfoot (2nd ed., Section 14.5; the
  report's Eqs. 29-31) worked out by hand with Incropera's Table A.4 row at 300 K;
* the whole solver in the limit of a small temperature span (air in at 297.5 K, clinker at
  302.5 K, so every film temperature is within 2.5 K of the 300 K row), no radiation,
  negligible clinker conductivity and constant c_p: the bed is then a cross-flow exchanger
  with both streams unmixed (the clinker layers do not mix, the air columns do not mix), with
  UA = h a V_bed, a = 6 (1 - eps) / (psi d_p), V_bed = L W H and H = m_s / (rho_s (1 - eps)
  v_g W). Its effectiveness is Nusselt's exact series (:mod:`support.law_references`).
  The same with the Jeschar internal resistance, 1/h_eff = 1/h + d_p / (10 k_s).
* Ergun's packed-bed pressure drop (Bird, Stewart and Lightfoot, Eq. 6.4-12) by hand at
  300 K and at 1000 K (Incropera's viscosity rows, the ideal-gas density p M / (R T));
* the fan operating point solved by hand: a quadratic fan curve p_0 [1 - (Q / Q_free)^2]
  against the bed's Ergun resistance A m + B m^2 at a uniform 300 K, the positive root of
  (B + C) m^2 + A m - p_0 = 0, both through the operating-point function and through the
  whole solver in the small-span limit (air in at 300 K, clinker at 300.05 K).

Each ``check_*`` is a plain function (see ``test_law_mutants.py``) that calls the package
through its modules, so that a patched law is the one checked.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from support.law_references import INCROPERA_A4_AIR, cross_flow_unmixed_effectiveness

from drumflow.coolers.grate import fans as grate_fans
from drumflow.coolers.grate import model as grate_model
from drumflow.coolers.grate import properties as grate_props
from drumflow.coolers.grate.case import Fan, GrateCase, grate_case_from_dict

_, CP_AIR, MU_AIR, _, _, PR_AIR = INCROPERA_A4_AIR[300.0]
LENGTH, WIDTH, SPEED = 11.0, 1.0, 0.1
M_S, M_A, CP_S = 33.0, 25.0, 750.0
D_P, POROSITY, RHO_S = 0.02, 0.5, 3150.0
T_AIR, T_CLINKER = 297.5, 302.5


def _close(value: float, reference: float, rtol: float, what: str) -> None:
    assert math.isfinite(value) and abs(value / reference - 1.0) <= rtol, (
        f"{what}: {value:.8g} vs independent {reference:.8g} "
        f"({value / reference - 1.0:+.3%}, allowed {rtol:.1e})")


def _packed_bed_h_by_hand(mass_flux: float) -> float:
    """Re = d G0 / ((1 - eps) mu psi), j_H = 2.19 Re^-2/3 + 0.78 Re^-0.381,
    h = j_H c_p G0 Pr^-2/3, with the 300 K row of Incropera Table A.4."""
    re = D_P * mass_flux / ((1.0 - POROSITY) * MU_AIR * 1.0)
    j_h = 2.19 * re ** (-2.0 / 3.0) + 0.78 * re ** (-0.381)
    return j_h * CP_AIR * mass_flux * PR_AIR ** (-2.0 / 3.0)


def check_packed_bed_h() -> None:
    """At G0 = 25 / 11 = 2.272727 kg/(m2 s), 300 K, d = 20 mm, eps = 0.5, psi = 1:
    Re = 0.02 * 2.272727 / (0.5 * 1.846e-5) = 4924.65, Re^-2/3 = 3.45475e-3,
    Re^-0.381 = 3.91927e-2, j_H = 7.56590e-3 + 3.05703e-2 = 3.81362e-2,
    h = 3.81362e-2 * 1007 * 2.272727 * 0.707^(-2/3) = 109.977 W/(m2 K).
    Exact arithmetic on both sides (the film temperature sits on the table row): 1e-9."""
    g = M_A / (LENGTH * WIDTH)
    h_hand = _packed_bed_h_by_hand(g)
    assert abs(h_hand - 109.977) < 1e-3
    h = float(grate_props.packed_bed_h(g, 300.0, diameter=D_P, porosity=POROSITY, sphericity=1.0))
    _close(h, h_hand, 1e-9, "packed-bed h (Bird-Stewart-Lightfoot)")
    _close(grate_props.bed_specific_surface(POROSITY, D_P, 1.0), 6.0 * 0.5 / 0.02, 1e-12,
           "bed specific surface 6 (1 - eps) / (psi d)")
    # Non-spherical nodules, psi = 0.8: Re = 4924.65 / 0.8 = 6155.82, a = 3 / (0.8 * 0.02).
    re = D_P * g / ((1.0 - POROSITY) * MU_AIR * 0.8)
    h_psi = (2.19 * re ** (-2.0 / 3.0) + 0.78 * re ** (-0.381)) * CP_AIR * g * PR_AIR ** (-2.0 / 3.0)
    _close(float(grate_props.packed_bed_h(g, 300.0, diameter=D_P, porosity=POROSITY,
                                          sphericity=0.8)), h_psi, 1e-9, "packed-bed h at psi = 0.8")
    _close(grate_props.bed_specific_surface(POROSITY, D_P, 0.8), 6.0 * 0.5 / (0.8 * 0.02), 1e-12,
           "bed specific surface at psi = 0.8")


def _case(interior: str = "none", conductivity: float = 1e-6) -> GrateCase:
    return grate_case_from_dict({
        "name": "law",
        "cooler": {"length": LENGTH, "width": WIDTH, "grate_speed": SPEED},
        "clinker": {"mass_flow": M_S, "inlet_temperature": T_CLINKER, "particle_diameter": D_P,
                    "sphericity": 1.0, "bed_porosity": POROSITY, "density": RHO_S,
                    "heat_capacity": CP_S, "heat_capacity_slope": 0.0,
                    "conductivity": conductivity, "conductivity_slope": 0.0, "emissivity": 0.9},
        "air": {"mass_flow": M_A, "inlet_temperature": T_AIR},
        "model": {"radiation": False, "interior_resistance": interior},
        "numerics": {"cells_length": 20, "cells_height": 15},
    })


def _check_cross_flow(case: GrateCase, h: float) -> None:
    sol = grate_model.solve_grate(case)
    _close(float(sol.heat_transfer_coefficient.mean()), h, 1e-3, "grate mean h")
    bed_height = M_S / (RHO_S * (1.0 - POROSITY) * SPEED * WIDTH)
    ua = h * 6.0 * (1.0 - POROSITY) / D_P * LENGTH * WIDTH * bed_height
    c_s, c_a = M_S * CP_S, M_A * CP_AIR
    c_min, c_max = min(c_s, c_a), max(c_s, c_a)
    duty = cross_flow_unmixed_effectiveness(ua / c_min, c_min / c_max) * c_min * (T_CLINKER - T_AIR)
    _close(T_CLINKER - sol.clinker_outlet_temperature, duty / c_s, 1e-3,
           "grate clinker cooling vs cross-flow epsilon-NTU")
    _close(sol.secondary_air_temperature - T_AIR, duty / c_a, 1e-3,
           "grate air warming vs cross-flow epsilon-NTU")


def check_cross_flow_limit() -> None:
    """The solver against the cross-flow exchanger (NTU = 1.54, Cr = 0.98).

    The grid converges at second order: 7e-4 from epsilon-NTU on 10 x 8 cells, 1.8e-4 on
    20 x 15 (used here), 3.6e-5 on 40 x 30; the mean h is 8e-5 from the 300 K value (the film
    temperatures spread +-2.5 K around it). 1e-3 is allowed: a 10 % change of h moves the
    outlets by 3 %.
    """
    _check_cross_flow(_case(), _packed_bed_h_by_hand(M_A / (LENGTH * WIDTH)))


def check_jeschar_limit() -> None:
    """As :func:`check_cross_flow_limit` with k_s = 1.5 W/(m K) and the Jeschar resistance:
    h_eff = 1 / (1/109.977 + 0.02 / 15) = 95.913 W/(m2 K) (measured 6e-5 and 1e-5 from the
    references; the clinker conduction between cells is 1e-4 of the advection)."""
    h = _packed_bed_h_by_hand(M_A / (LENGTH * WIDTH))
    h_eff = 1.0 / (1.0 / h + D_P / (10.0 * 1.5))
    _check_cross_flow(_case("jeschar", 1.5), h_eff)


def test_packed_bed_h_by_hand() -> None:
    check_packed_bed_h()


def test_grate_is_a_cross_flow_exchanger_in_the_small_span_limit() -> None:
    check_cross_flow_limit()


def test_grate_with_jeschar_resistance() -> None:
    check_jeschar_limit()


# --- fan-limited air: Ergun and the fan operating point (issue 34) ---------------------------

#: Ideal-gas constants written out here (CODATA 2018 R, US Standard Atmosphere 1976 M).
P_ATM, M_AIR, R_GAS = 101325.0, 0.0289644, 8.314462618
FAN_P0, FAN_Q_FREE = 1460.0, 35.4  # cases/grate_cooler_fans.toml


def _ergun_by_hand(mass_flux: float, mu: float, temperature: float, d_eff: float) -> float:
    """150 mu (1 - eps)^2 u / (eps^3 d^2) + 1.75 rho (1 - eps) u^2 / (eps^3 d), u = G / rho."""
    rho = P_ATM * M_AIR / (R_GAS * temperature)
    u = mass_flux / rho
    eps3 = POROSITY**3
    return (150.0 * mu * (1.0 - POROSITY) ** 2 * u / (eps3 * d_eff**2)
            + 1.75 * rho * (1.0 - POROSITY) * u * u / (eps3 * d_eff))


def check_ergun() -> None:
    """At G0 = 25 / 11 = 2.272727 kg/(m2 s), 300 K, d = 20 mm, eps = 0.5, psi = 1:
    rho = 101325 * 0.0289644 / (8.314462618 * 300) = 1.1765915 kg/m3, u = 1.931619 m/s,
    viscous 150 * 1.846e-5 * 0.25 * 1.931619 / (0.125 * 4e-4) = 26.743 Pa/m,
    inertial 1.75 * 1.1765915 * 0.5 * 1.931619^2 / (0.125 * 0.02) = 1536.515 Pa/m,
    together 1563.259 Pa/m. At 1000 K and psi = 0.8 (d_eff = 16 mm, mu = 424.4e-7 from the
    table row): 6722.37 Pa/m. Exact arithmetic on both sides (table rows): 1e-9."""
    g = M_A / (LENGTH * WIDTH)
    by_hand = _ergun_by_hand(g, MU_AIR, 300.0, D_P)
    assert abs(by_hand - 1563.259) < 1e-3
    _close(float(grate_props.ergun_pressure_gradient(g, 300.0, diameter=D_P, porosity=POROSITY,
                                                     sphericity=1.0)),
           by_hand, 1e-9, "Ergun pressure gradient at 300 K")
    hot = _ergun_by_hand(g, 424.4e-7, 1000.0, 0.8 * D_P)
    assert abs(hot - 6722.37) < 1e-2
    _close(float(grate_props.ergun_pressure_gradient(g, 1000.0, diameter=D_P, porosity=POROSITY,
                                                     sphericity=0.8)),
           hot, 1e-9, "Ergun pressure gradient at 1000 K, psi = 0.8")


def _operating_point_by_hand() -> tuple[float, float]:
    """The report's bed (H = 33 / (3150 * 0.5 * 0.1) = 0.2095238 m on 11 m x 1 m) with air at
    300 K throughout: A = H * 150 mu (1 - eps)^2 / (rho eps^3 d^2) / (L W) = 0.2241341
    Pa/(kg/s), B = H * 1.75 (1 - eps) / (rho eps^3 d) / (L W)^2 = 0.5150986 Pa/(kg/s)^2;
    the fan p_0 = 1460 Pa, Q_free = 35.4 m3/s gives C = p_0 / (rho Q_free)^2 = 0.8415790;
    m = (-A + sqrt(A^2 + 4 (B + C) p_0)) / (2 (B + C)) = 32.72235 kg/s, where both sides are
    558.877 Pa. Returns (m, Delta p)."""
    rho = P_ATM * M_AIR / (R_GAS * 300.0)
    height = M_S / (RHO_S * (1.0 - POROSITY) * SPEED * WIDTH)
    area = LENGTH * WIDTH
    a = height * 150.0 * MU_AIR * (1.0 - POROSITY) ** 2 / (rho * POROSITY**3 * D_P**2) / area
    b = height * 1.75 * (1.0 - POROSITY) / (rho * POROSITY**3 * D_P) / area**2
    c = FAN_P0 / (rho * FAN_Q_FREE) ** 2
    m = (-a + math.sqrt(a * a + 4.0 * (b + c) * FAN_P0)) / (2.0 * (b + c))
    return m, a * m + b * m * m


def _fan_case(t_air: float = 300.0, t_clinker: float = 300.05) -> GrateCase:
    data = _case().model_dump(exclude_none=True)
    data["clinker"]["inlet_temperature"] = t_clinker
    data["air"] |= {"inlet_temperature": t_air, "supply": "fan"}
    data["fan"] = {"shutoff_pressure": FAN_P0, "free_delivery": FAN_Q_FREE}
    return grate_case_from_dict(data)


def check_fan_operating_point() -> None:
    """The operating point of the fan curve against a frozen 300 K bed, by hand (1e-9), and
    the fan curve's pressure there equal to the bed's."""
    m_hand, dp_hand = _operating_point_by_hand()
    assert abs(m_hand - 32.72235) < 1e-4 and abs(dp_hand - 558.877) < 1e-3
    case = _fan_case(300.0, 302.5)
    n, m = case.numerics.cells_length, case.numerics.cells_height
    field = np.full((m, n), 300.0)
    shares = np.full(n, 1.0 / n)
    resistance = grate_fans.bed_resistance(case, field, shares, case.bed_height)
    fan = case.fan
    assert isinstance(fan, Fan)
    flow = grate_fans.operating_point(fan, resistance, 300.0)
    _close(flow, m_hand, 1e-9, "fan operating point (quadratic curve vs Ergun bed)")
    _close(resistance.pressure_drop(flow), dp_hand, 1e-9, "bed pressure drop at the operating point")
    _close(grate_fans.fan_pressure(fan, flow, 300.0), dp_hand, 1e-9,
           "fan-curve pressure at the operating point")
    column = grate_fans.column_pressure_drops(case, field, shares * flow, case.bed_height)
    _close(float(column.mean()), dp_hand, 1e-9, "column pressure drops at the operating point")


def check_fan_limit() -> None:
    """The whole solver with air.supply = "fan" in the small-span limit: every air cell is
    within 0.05 K of 300 K, so the solved air flow is the hand operating point (measured
    9e-6 from it; with air in at 299.5 K and clinker at 300.5 K the mean air is 299.78 K and
    the flow 1.2e-3 off). 1e-3 allowed, where 10 % on the fan pressure or on Ergun moves
    it by 1.8-2 %."""
    sol = grate_model.solve_grate(_fan_case())
    m_hand, dp_hand = _operating_point_by_hand()
    _close(sol.air_flow, m_hand, 1e-3, "solved fan-limited air flow")
    _close(sol.bed_pressure_drop, dp_hand, 1e-3, "solved bed pressure drop")
    fan_p = sol.fan_pressure
    assert fan_p is not None
    _close(fan_p, sol.bed_pressure_drop, 1e-6, "fan pressure = bed pressure drop at convergence")


def test_ergun_by_hand() -> None:
    check_ergun()


def test_fan_operating_point_by_hand() -> None:
    check_fan_operating_point()


def test_fan_limited_solver_meets_the_hand_operating_point() -> None:
    check_fan_limit()


def _scaled(mp: pytest.MonkeyPatch, owner: object, name: str, factor: float) -> None:
    original = getattr(owner, name)

    def scaled(*args: object, **kwargs: object) -> object:
        return factor * original(*args, **kwargs)

    mp.setattr(owner, name, scaled)


def _fan_p0_scaled(mp: pytest.MonkeyPatch, owner: object, factor: float) -> None:
    # The fan curve off by 10 %: the operating point computed for a shut-off pressure 10 %
    # higher (what a wrong p_0 term in the quadratic would do).
    original = grate_fans.operating_point

    def wrong(fan: Fan, resistance: grate_fans.BedResistance, inlet_temperature: float) -> float:
        bigger = fan.model_copy(update={"shutoff_pressure": factor * fan.shutoff_pressure})
        return original(bigger, resistance, inlet_temperature)

    mp.setattr(owner, "operating_point", wrong)


#: Laws of the fan-limited air off by 10 %, and the check that must catch each.
FAN_MUTANTS = {
    "Ergun x1.1": (lambda mp: _scaled(mp, grate_props, "ergun_pressure_gradient", 1.1),
                   check_ergun),
    "Ergun x0.9 as the fans use it": (
        lambda mp: _scaled(mp, grate_fans, "ergun_pressure_gradient", 0.9), check_fan_limit),
    "Ergun x1.1 in the hand operating point": (
        lambda mp: _scaled(mp, grate_fans, "ergun_pressure_gradient", 1.1),
        check_fan_operating_point),
    "air density x1.1": (lambda mp: _scaled(mp, grate_props, "air_density", 1.1), check_ergun),
    "fan shut-off pressure x1.1": (
        lambda mp: _fan_p0_scaled(mp, grate_fans, 1.1), check_fan_operating_point),
    "fan shut-off pressure x1.1 in the solver": (
        lambda mp: _fan_p0_scaled(mp, grate_model, 1.1), check_fan_limit),
    "fan curve pressure x1.1": (lambda mp: _scaled(mp, grate_fans, "fan_pressure", 1.1),
                                check_fan_operating_point),
}


@pytest.mark.parametrize("name", sorted(FAN_MUTANTS))
def test_fan_law_off_by_ten_percent_is_caught(name: str) -> None:
    apply, check = FAN_MUTANTS[name]
    check()  # the law as written passes
    with pytest.MonkeyPatch.context() as mp:
        apply(mp)
        with pytest.raises(AssertionError):
            check()
