"""Law tests of the slice coupling (issue 36): drag and convection against values worked out
by hand from the published correlations, and their analytic limits.

Each ``check_*`` is a plain function: the test calls it, and ``test_law_mutants.py`` calls it
with the law changed and expects an AssertionError. The checks call the package through its
module (``physics.drag_force``) so that a patched law is the one checked.

State used throughout: round air properties (close to air at 20 deg C), so the arithmetic is
easy to follow: rho = 1.2 kg/m3, mu = 1.8e-5 Pa s, k = 0.026 W/(m K), Pr = 0.71.
"""

from __future__ import annotations

import math

import numpy as np

from drumflow.physics import particle_air as physics

AIR = physics.AirState(temperature_C=20.0, density=1.2, viscosity=1.8e-5, conductivity=0.026,
                       prandtl=0.71)
# The arithmetic below is exact up to round-off; 1e-9 leaves room for the last bits of
# numpy's power functions and is 1e8 times smaller than a 10 % change of a law.
RTOL = 1e-9


def _close(value: float, reference: float, rtol: float, what: str) -> None:
    assert math.isfinite(value) and abs(value / reference - 1.0) <= rtol, (
        f"{what}: {value:.8g} vs independent {reference:.8g} "
        f"({value / reference - 1.0:+.3%}, allowed {rtol:.1e})")


def check_ranz_marshall() -> None:
    """Ranz and Marshall (1952, Chem. Eng. Prog. 48, 141), Nu = 2 + 0.6 Re^1/2 Pr^1/3.

    d = 3 mm, slip 2 m/s: Re = 1.2 * 2 * 0.003 / 1.8e-5 = 400, Re^1/2 = 20,
    Pr^1/3 = 0.71^(1/3) = 0.8921121, Nu = 2 + 0.6 * 20 * 0.8921121 = 12.705346,
    h = Nu k / d = 12.705346 * 0.026 / 0.003 = 110.11300 W/(m2 K).
    """
    pr3 = 0.71 ** (1.0 / 3.0)
    assert abs(pr3 - 0.8921121) < 1e-7
    h_hand = (2.0 + 0.6 * 20.0 * pr3) * 0.026 / 0.003
    assert abs(h_hand - 110.11300) < 1e-4
    _close(float(physics.ranz_marshall_h(2.0, 3e-3, AIR)), h_hand, RTOL, "Ranz-Marshall h, Re=400")
    # Still air: conduction from a sphere into an infinite medium, Nu = 2 exactly.
    _close(float(physics.ranz_marshall_h(0.0, 3e-3, AIR)), 2.0 * 0.026 / 3e-3, RTOL,
           "Ranz-Marshall h at zero slip (Nu = 2)")
    # The convective heat is h pi d^2 (T_air - T_p) at the slip |u_air - u_p|: two particles
    # at 80 C in the 20 C air, both 2 m/s slower than it (along x, and along y).
    q = physics.convective_heat(np.array([[2.5, 0.0, 0.0], [0.0, 2.5, 0.0]]),
                                np.array([[0.5, 0.0, 0.0], [0.0, 0.5, 0.0]]),
                                np.array([80.0, 80.0]), 3e-3, AIR)
    for value in q:
        _close(float(value), h_hand * math.pi * 9e-6 * (20.0 - 80.0), RTOL, "convective heat")


def check_drag() -> None:
    """Schiller and Naumann (1933): C_d = 24/Re (1 + 0.15 Re^0.687) below Re = 1000, then 0.44;
    F = C_d rho (pi d^2 / 4) V^2 / 2.

    d = 3 mm, slip 2 m/s, Re = 400: 400^0.687 = exp(0.687 ln 400) = 61.32185,
    C_d = 0.06 (1 + 9.198277) = 0.6118966, F = 0.6118966 * 0.6 * 7.068583e-6 * 4 = 1.038058e-5 N.
    """
    re_pow = math.exp(0.687 * math.log(400.0))
    assert abs(re_pow - 61.32185) < 1e-4
    cd = 24.0 / 400.0 * (1.0 + 0.15 * re_pow)
    f_hand = cd * 0.5 * 1.2 * (math.pi / 4.0 * 9e-6) * 2.0**2
    assert abs(f_hand - 1.038058e-5) < 1e-11
    f = physics.drag_force(np.array([[2.0, 0.0, 0.0]]), np.zeros((1, 3)), 3e-3, AIR)
    _close(float(f[0, 0]), f_hand, RTOL, "Schiller-Naumann drag, Re=400")
    assert abs(f[0, 1]) == 0.0 and abs(f[0, 2]) == 0.0, "drag not along the slip"
    # Newton regime, Re = 1.2 * 10 * 0.003 / 1.8e-5 = 2000: C_d = 0.44.
    f_n = physics.drag_force(np.array([[0.0, 0.0, 10.0]]), np.zeros((1, 3)), 3e-3, AIR)
    _close(float(f_n[0, 2]), 0.44 * 0.5 * 1.2 * (math.pi / 4.0 * 9e-6) * 100.0, RTOL,
           "drag at Re=2000 (C_d = 0.44)")
    # Stokes (1851): F = 3 pi mu d V as Re -> 0. At d = 10 um, V = 1 mm/s, Re = 6.7e-4 and the
    # Schiller-Naumann correction 0.15 Re^0.687 is 1.0e-3; 2e-3 covers it, 50x below 10 %.
    v, d = 1e-3, 1e-5
    f_s = physics.drag_force(np.array([[v, 0.0, 0.0]]), np.zeros((1, 3)), d, AIR)
    _close(float(f_s[0, 0]), 3.0 * math.pi * 1.8e-5 * d * v, 2e-3, "Stokes limit of the drag")


def check_terminal_velocity() -> None:
    """Settling in the Stokes regime: v_t = rho_p g d^2 / (18 mu) (no buoyancy, as the DEM).

    d = 20 um, rho_p = 1000: v_t = 1000 * 9.81 * 4e-10 / (18 * 1.8e-5) = 1.21111e-2 m/s,
    Re = 1.6e-2, the Schiller-Naumann correction 0.15 Re^0.687 = 0.9 %: 1.5 % tolerance.
    """
    v_stokes = 1000.0 * 9.81 * (20e-6) ** 2 / (18.0 * 1.8e-5)
    _close(physics.terminal_velocity(20e-6, 1000.0, AIR), v_stokes, 1.5e-2,
           "terminal velocity (Stokes)")


def test_ranz_marshall_against_hand_values() -> None:
    check_ranz_marshall()


def test_schiller_naumann_against_hand_values_and_stokes() -> None:
    check_drag()


def test_terminal_velocity_in_the_stokes_limit() -> None:
    check_terminal_velocity()
