"""Law tests of the vibrating fluid-bed cooler (:mod:`drumflow.coolers.fluid_bed`), issue 36.

The existing recovery test of the fit makes its data with the same model, so it cannot see a
wrong h. Independent references here:

* Gunn's (1978, Int. J. Heat Mass Transfer 21, 467) Nusselt number worked out by hand;
* a section of the deck in the lumped-particle limit, solved in closed form: well-mixed
  particles (bubbling) crossed once by plug-flow air, so the air seen is the path mean
  T_p - (T_p - T_air)(1 - e^-NTU)/NTU, with NTU = N_p f_c h A tau / (m_air c_p); the particle
  then decays exponentially at the rate (f_c h A / (m c)) (1 - e^-NTU)/NTU. h is
  Gunn's Nu k / d, with the gas properties taken straight from CoolProp's HAPropsSI and the
  bed voidage from the model's hydrodynamics (an input to the heat law, not part of it).

* the bed's expansion (issue 34) at one point worked out by hand: Wen and Yu's u_mf and
  eps_mf, Johnsson et al.'s (1991) bubble fraction, the two-phase voidage and the bed height
  that holds the solids.

Each ``check_*`` is a plain function (see ``test_law_mutants.py``) that calls the package
through its modules, so that a patched law is the one checked.
"""

from __future__ import annotations

import math
from pathlib import Path

import CoolProp.CoolProp as CP

from drumflow.coolers import _fluidization as fl
from drumflow.coolers import fluid_bed as fb
from drumflow.coolers import fluid_bed_case as fbc

CASE = Path(__file__).resolve().parents[2] / "cases" / "fluid_bed_npk.toml"
# The largest product conductivity the case allows: Bi = f_c h R / k < 1e-3, lumped.
K_LUMPED = 100.0


def _close(value: float, reference: float, rtol: float, what: str) -> None:
    assert math.isfinite(value) and abs(value / reference - 1.0) <= rtol, (
        f"{what}: {value:.8g} vs independent {reference:.8g} "
        f"({value / reference - 1.0:+.3%}, allowed {rtol:.1e})")


def check_gunn_nusselt() -> None:
    """Gunn (1978): Nu = (7 - 10 e + 5 e^2)(1 + 0.7 Re^0.2 Pr^1/3)
    + (1.33 - 2.4 e + 1.2 e^2) Re^0.7 Pr^1/3, at Re = 100, Pr = 0.71, e = 0.6:
    7 - 6 + 1.8 = 2.8; 100^0.2 = 2.511886, 0.71^(1/3) = 0.8921121, 1 + 0.7 * 2.511886 * 0.8921121
    = 2.568619; 1.33 - 1.44 + 0.432 = 0.322; 100^0.7 = 25.11886;
    Nu = 2.8 * 2.568619 + 0.322 * 25.11886 * 0.8921121 = 7.192133 + 7.215648 = 14.40778.
    Exact arithmetic: 1e-9."""
    pr3 = 0.71 ** (1.0 / 3.0)
    nu_hand = (2.8 * (1.0 + 0.7 * 100.0**0.2 * pr3) + 0.322 * 100.0**0.7 * pr3)
    assert abs(nu_hand - 14.40778) < 1e-4
    _close(fl.gunn_nusselt(100.0, 0.71, 0.6), nu_hand, 1e-9, "Gunn Nusselt number")


def check_bed_expansion() -> None:
    """Section C of the case at a gas of round properties (rho_g = 1.2 kg/m^3, mu = 1.8e-5 Pa s):
    2.7 mm granules of 1750 kg/m^3 at 7.5 m/s, S = 13.88889 kg/s, v = 0.2 m/s, B = 1 m.

    Wen and Yu (1966): Ar = 1.2 * 1748.8 * 9.81 * (2.7e-3)^3 / (1.8e-5)^2 = 1 250 652.6,
    Re_mf = sqrt(33.7^2 + 0.0408 Ar) - 33.7 = 194.6907, u_mf = Re_mf mu / (rho d) = 1.081615 m/s;
    eps_mf = 14^(-1/3) = 0.4149133.
    Johnsson et al. (1991): u - u_mf = 6.418385 m/s; f = (0.26 + 0.70 e^(-3.3 * 2.7))
    (0.15 + 6.418385)^-0.33 = 0.2600945 * 0.5373270 = 0.1397558; 1.3 / f * 6.418385^-0.8
    = 9.301998 * 0.2259745 = 2.102001; delta_b = 1 / 3.102001 = 0.3223726.
    Voidage 0.3223726 + 0.6776274 * 0.4149133 = 0.6035292 (the old Richardson-Zaki bed: 0.989);
    height 13.88889 / (0.2 * 1 * 1750 * 0.3964708) = 0.1000894 m (old: 3.63 m).
    Exact arithmetic both sides: 1e-6 (the typed values carry 7 digits); a 10 % change of
    Johnsson's 1.3 moves the voidage by 1.8 % and the height by 2.7 %.
    """
    gas = fl.HumidAir(temperature=293.15, pressure=101325.0, humidity_ratio=0.0, density=1.2,
                      heat_capacity=1006.0, viscosity=1.8e-5, conductivity=0.026)
    bed = fl.bed_state(7.5, gas, 2.7e-3, 1750.0, solids_flow=13.88889, solids_velocity=0.2,
                       width=1.0, orifice_area=4e-4)
    _close(bed.min_fluidization_velocity, 1.081615, 1e-6, "u_mf (Wen and Yu)")
    _close(bed.dense_phase_voidage, 0.4149133, 1e-6, "eps_mf = 14^(-1/3)")
    _close(bed.bubble_fraction, 0.3223726, 1e-6, "bubble fraction (Johnsson et al. 1991)")
    _close(bed.voidage, 0.6035292, 1e-6, "bed voidage")
    _close(bed.bed_height, 0.1000894, 1e-6, "bed height")


def _lumped_case() -> fbc.FluidBedCase:
    case = fbc.load_fluid_bed_case(CASE)
    return case.model_copy(update={
        "product": case.product.model_copy(update={"conductivity": K_LUMPED}),
        "numerics": fbc.Numerics(shells=10, steps_per_section=200)})


def check_lumped_sections() -> None:
    """Both sections on ambient air (30 C, 30 % RH, 93 kPa), the product in at 46.5 C, lumped:
    h and the product's excess temperature over the air after each section in closed form.

    h is exact arithmetic on both sides (1e-9). The product excess differs from the closed
    form by 4e-4 (measured: the Crank-Nicolson steps, 200 per section, and the half-shell
    resistance at Bi < 1e-3); 2e-3 is allowed, while a 10 % change of h moves it by about
    4 % (section B) and 1.3 % (section C).
    """
    case = _lumped_case()
    cond = fbc.case_conditions(case)
    r = fb.run_unit(case, cond)
    prod, unit = case.product, case.unit
    d = prod.diameter
    particle_mass = prod.density * math.pi * d**3 / 6.0
    particles_per_s = prod.mass_flow / particle_mass
    area = math.pi * d**2
    t_air = cond.ambient_temperature
    state = ("T", t_air, "P", case.air.pressure_kPa * 1e3, "W", cond.humidity_ratio)
    rho = 1.0 / float(CP.HAPropsSI("Vha", *state))
    cp = float(CP.HAPropsSI("cp_ha", *state))
    mu = float(CP.HAPropsSI("mu", *state))
    k = float(CP.HAPropsSI("k", *state))
    fc = case.losses.convective_efficiency
    t_p = cond.product_inlet_temperature
    lengths = (unit.ambient_fraction * unit.length, (1.0 - unit.ambient_fraction) * unit.length)
    velocities = (case.air.ambient.velocity, case.air.cooled.velocity)
    for section, length, u in zip(r.sections, lengths, velocities, strict=True):
        e = section.bed.voidage
        re = rho * u * d / mu
        pr3 = (cp * mu / k) ** (1.0 / 3.0)
        nu = ((7.0 - 10.0 * e + 5.0 * e**2) * (1.0 + 0.7 * re**0.2 * pr3)
              + (1.33 - 2.4 * e + 1.2 * e**2) * re**0.7 * pr3)
        h = nu * k / d
        _close(section.h_correlation, h, 1e-9, f"section {section.name} h = Nu k / d")
        tau = length / unit.solids_velocity
        ntu = particles_per_s * fc * h * area * tau / (rho * u * unit.width * length * cp)
        rate = fc * h * area / (particle_mass * prod.heat_capacity) * (-math.expm1(-ntu)) / ntu
        t_p = t_air + (t_p - t_air) * math.exp(-rate * tau)
        _close(section.product_outlet_temperature - t_air, t_p - t_air, 2e-3,
               f"section {section.name} product excess temperature vs closed form")


def test_gunn_nusselt_by_hand() -> None:
    check_gunn_nusselt()


def test_lumped_deck_in_closed_form() -> None:
    check_lumped_sections()


def test_bed_expansion_by_hand() -> None:
    check_bed_expansion()
