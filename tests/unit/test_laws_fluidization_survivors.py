"""Law tests for the mutation survivors of :mod:`drumflow.coolers._fluidization` (issue 36;
results/mutation/survivors.md).

The mutmut run left alive: the bed height with the deck width divided instead of multiplied
(the law test had B = 1 m), the reported bubble diameters (not checked), Johnsson's
correlation refused below 1 m/s of excess velocity, the sign of the gas density in the Geldart
boundaries, the humid-air state's own fields, and the edges of the range guards. Every
expected value below is arithmetic written out from the cited correlation, a closed-form
integral or a psychrometric formula; none comes from the module.
"""

from __future__ import annotations

import math

import pytest

from drumflow.coolers import _fluidization as fl

# The round-property gas of test_laws_fluid_bed (rho_g = 1.2 kg/m3, mu = 1.8e-5 Pa s).
GAS = fl.HumidAir(temperature=293.15, pressure=101325.0, humidity_ratio=0.0, density=1.2,
                  heat_capacity=1006.0, viscosity=1.8e-5, conductivity=0.026)


def _close(value: float, reference: float, rtol: float, what: str) -> None:
    assert math.isfinite(value) and abs(value / reference - 1.0) <= rtol, (
        f"{what}: {value:.8g} vs independent {reference:.8g} "
        f"({value / reference - 1.0:+.3%}, allowed {rtol:.1e})")


def check_bed_on_a_wide_deck() -> None:
    """Section C of the case (test_laws_fluid_bed) on a 2 m wide deck, A_0 = 4e-4 m2.

    Wen and Yu: u_mf = 1.081615 m/s; eps_mf = 14^(-1/3) = 0.4149133; Johnsson et al. (1991):
    delta_b = 0.3223726, eps = 0.6035292 (test_laws_fluid_bed's arithmetic).
    Picado and Martinez: H = S / (v B rho_p (1 - eps)) = 13.88889 / (0.2 * 2 * 1750 *
    0.3964708) = 0.05004472 m (half the 1 m deck's 0.1000894 m).
    Darton et al. (1977): d_v(h) = K (h + c)^0.8, K = 0.54 * 6.418385^0.4 / 9.81^0.2 =
    0.7194991, c = 4 sqrt(4e-4) = 0.08 m. At the surface K (0.13004472)^0.8 = 0.1407034 m;
    its mean over the height, in closed form, K ((H + c)^1.8 - c^1.8) / (1.8 H) = 0.1184112 m.
    The typed values carry 7 digits: 1e-6; the 16-point Gauss-Legendre mean of a smooth
    power law is exact to far below that.
    """
    bed = fl.bed_state(7.5, GAS, 2.7e-3, 1750.0, solids_flow=13.88889, solids_velocity=0.2,
                       width=2.0, orifice_area=4e-4)
    assert bed.geldart == "D"  # (1750 - 1.2) * (2.7e-3)^2 = 0.01275 kg/m > 1e-3
    _close(bed.voidage, 0.6035292, 1e-6, "bed voidage")
    _close(bed.bed_height, 0.05004472, 1e-6, "bed height on a 2 m deck")
    _close(bed.surface_bubble_diameter, 0.1407034, 1e-6, "Darton bubble at the surface")
    _close(bed.bubble_diameter, 0.1184112, 1e-6, "Darton bubble averaged over the height")


def check_johnsson_at_low_excess_velocity() -> None:
    """Johnsson et al. (1991) at u - u_mf = 0.5 m/s, d_p = 2.7 mm:
    f = (0.26 + 0.70 e^(-8.91)) (0.65)^-0.33 = 0.2600945 * 1.152759 = 0.2998264;
    1.3 / f * 0.5^-0.8 = 4.335842 * 1.741101 = 7.549143; delta_b = 1 / 8.549143 = 0.1169708."""
    _close(fl.johnsson_bubble_fraction(0.5, 2.7e-3), 0.1169708, 1e-6,
           "Johnsson bubble fraction at 0.5 m/s excess")


def test_bed_on_a_wide_deck() -> None:
    check_bed_on_a_wide_deck()


def test_johnsson_below_one_metre_per_second() -> None:
    check_johnsson_at_low_excess_velocity()


@pytest.mark.parametrize(("diameter", "particle_density", "gas_density", "group"), [
    (20e-6, 2500.0, 1.2, "C"),  # below 30 um
    (30e-6, 2000.0, 0.0, "A"),  # at 30 um: not C; 2000 * 30e-6 = 0.06 <= 0.225
    (1e-4, 2250.0, 0.0, "A"),  # (rho_p - rho_g) d = 0.225 exactly: A (the boundary is A's)
    (1.5e-4, 1500.0, 1.2, "A"),  # 1498.8 * 1.5e-4 = 0.22482 <= 0.225 (with + rho_g: 0.22518)
    (1e-3, 1000.0, 0.0, "D"),  # (rho_p - rho_g) d^2 = 1e-3 exactly: D (B is below it)
    (5e-4, 1000.0, 1.2, "B"),  # 998.8 * 2.5e-7 = 2.5e-4 < 1e-3; 0.4994 > 0.225
])
def test_geldart_boundaries(diameter: float, particle_density: float, gas_density: float,
                            group: str) -> None:
    """Geldart (1973) boundaries as the docstring states them, at and on each side of them."""
    assert fl.geldart_group(diameter, particle_density, gas_density) == group


def test_humid_air_state_and_dew_point() -> None:
    """The state keeps its inputs; the dew point of W = 0.01 at 101.325 kPa is where the
    vapour pressure p_w = W P / (0.621945 + W) = 1603.40 Pa saturates: Magnus (Alduchov and
    Eskridge 1996), T_d = 243.04 ln(p/610.94) / (17.625 - ln(p/610.94)) = 14.08 C. Magnus is
    within ~0.1 K of IAPWS here, and the enhancement factor (1.004) moves it < 0.1 K: 0.2 K."""
    air = fl.humid_air(300.0, 101325.0, 0.01)
    assert (air.temperature, air.pressure, air.humidity_ratio) == (300.0, 101325.0, 0.01)
    p_w = 0.01 * 101325.0 / (0.621945 + 0.01)
    x = math.log(p_w / 610.94)
    assert air.dew_point - 273.15 == pytest.approx(243.04 * x / (17.625 - x), abs=0.2)


def test_range_guards_at_their_edges() -> None:
    """Gunn (1978) holds for 0.35 <= eps <= 1 (both ends included), Nu written out at Re = 100,
    Pr = 0.7 (Re^0.2 = 2.511886, Re^0.7 = 25.11886, Pr^1/3 = 0.8879040; 0.7 Re^0.2 Pr^1/3 =
    1.561220, Re^0.7 Pr^1/3 = 22.30314):
    eps = 1: (7 - 10 + 5) = 2, (1.33 - 2.4 + 1.2) = 0.13: 2 * 2.561220 + 0.13 * 22.30314 = 8.021848;
    eps = 0.35: 4.1125 * 2.561220 + 0.637 * 22.30314 = 24.74012.
    The emulsion voidage is allowed 0.35 to 0.6 (ends included), the sphericity 0 < phi <= 1,
    the excess velocity any positive value."""
    re3, pr3 = 100.0, 0.7 ** (1.0 / 3.0)
    assert pr3 == pytest.approx(0.8879040, rel=1e-7)
    _close(fl.gunn_nusselt(re3, 0.7, 1.0), 8.021848, 1e-6, "Gunn Nu at eps = 1")
    _close(fl.gunn_nusselt(re3, 0.7, 0.35), 24.74012, 1e-6, "Gunn Nu at eps = 0.35")
    with pytest.raises(ValueError, match="voidage"):
        fl.gunn_nusselt(re3, 0.7, 1.5)
    for eps_mf in (0.35, 0.6):
        bed = fl.bed_state(7.5, GAS, 2.7e-3, 1750.0, solids_flow=13.88889, solids_velocity=0.2,
                           width=1.0, orifice_area=4e-4, dense_phase_voidage=eps_mf)
        assert bed.dense_phase_voidage == eps_mf
    with pytest.raises(ValueError, match="minimum fluidisation voidage"):
        fl.bed_state(7.5, GAS, 2.7e-3, 1750.0, solids_flow=13.88889, solids_velocity=0.2,
                     width=1.0, orifice_area=4e-4, dense_phase_voidage=0.7)
    with pytest.raises(ValueError, match="sphericity"):
        fl.min_fluidization_voidage(0.0)
