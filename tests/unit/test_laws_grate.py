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

Each ``check_*`` is a plain function (see ``test_law_mutants.py``) that calls the package
through its modules, so that a patched law is the one checked.
"""

from __future__ import annotations

import math

from support.law_references import INCROPERA_A4_AIR, cross_flow_unmixed_effectiveness

from drumflow.coolers.grate import model as grate_model
from drumflow.coolers.grate import properties as grate_props
from drumflow.coolers.grate.case import GrateCase, grate_case_from_dict

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
