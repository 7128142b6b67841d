"""Independent references for the law tests (``tests/unit/test_laws_*.py``, issue 36).

Nothing here imports drumflow: these are closed forms from the heat-exchanger literature and
table rows typed from the printed sources, so a wrong law in the package cannot leak into the
value a test compares with.
"""

from __future__ import annotations

import math

__all__ = [
    "INCROPERA_A4_AIR",
    "counter_current_effectiveness",
    "cross_flow_unmixed_effectiveness",
    "incropera_air",
    "lumped_fraction",
]

#: Incropera, DeWitt, Bergman, Lavine, *Fundamentals of Heat and Mass Transfer*, 6th ed.,
#: Table A.4 (air at 1 atm), typed again here from the book (not copied from the package):
#: T (K): (rho kg/m3, c_p J/(kg K), mu Pa s, nu m2/s, k W/(m K), Pr).
INCROPERA_A4_AIR: dict[float, tuple[float, float, float, float, float, float]] = {
    250.0: (1.3947, 1006.0, 159.6e-7, 11.44e-6, 22.3e-3, 0.720),
    300.0: (1.1614, 1007.0, 184.6e-7, 15.89e-6, 26.3e-3, 0.707),
    350.0: (0.9950, 1009.0, 208.2e-7, 20.92e-6, 30.0e-3, 0.700),
    400.0: (0.8711, 1014.0, 230.1e-7, 26.41e-6, 33.8e-3, 0.690),
}


def incropera_air(temperature_k: float) -> tuple[float, float, float, float, float, float]:
    """Linear interpolation between two rows of :data:`INCROPERA_A4_AIR`, written out."""
    rows = sorted(INCROPERA_A4_AIR)
    for lo, hi in zip(rows[:-1], rows[1:], strict=True):
        if lo <= temperature_k <= hi:
            w = (temperature_k - lo) / (hi - lo)
            a, b = INCROPERA_A4_AIR[lo], INCROPERA_A4_AIR[hi]
            return tuple(x + w * (y - x) for x, y in zip(a, b, strict=True))  # type: ignore[return-value]
    raise ValueError(f"{temperature_k} K outside the typed rows {rows[0]}-{rows[-1]} K")


def counter_current_effectiveness(ntu: float, cr: float) -> float:
    """Counter-current exchanger, epsilon(NTU, C_min/C_max) (Incropera 6th ed. Eq. 11.29a;
    Kays and London, Compact Heat Exchangers, Table 2-13); Cr = 1 is NTU / (1 + NTU)."""
    if abs(1.0 - cr) < 1e-12:
        return ntu / (1.0 + ntu)
    e = math.exp(-ntu * (1.0 - cr))
    return (1.0 - e) / (1.0 - cr * e)


def cross_flow_unmixed_effectiveness(ntu: float, cr: float, terms: int = 200) -> float:
    """Cross-flow exchanger with both fluids unmixed: the exact series of Nusselt (1911) in
    the form of Mason (1954, Trans. ASME 76, 665; Kays and London, Table 2-13),

        epsilon = 1/(Cr NTU) sum_{n>=0} [1 - e^{-NTU} sum_{m<=n} NTU^m/m!]
                                         [1 - e^{-Cr NTU} sum_{m<=n} (Cr NTU)^m/m!].

    Kays and London tabulate 0.476 at NTU = 1, Cr = 1 (this gives 0.47622).
    """
    a, b = ntu, cr * ntu
    term_a = term_b = 1.0
    sum_a = sum_b = 0.0
    total = 0.0
    for n in range(terms):
        if n:
            term_a *= a / n
            term_b *= b / n
        sum_a += term_a
        sum_b += term_b
        total += (1.0 - math.exp(-a) * sum_a) * (1.0 - math.exp(-b) * sum_b)
    return total / (cr * ntu)


def lumped_fraction(h: float, diameter: float, density: float, heat_capacity: float,
                    time_s: float) -> float:
    """(T - T_gas) / (T0 - T_gas) of a lumped sphere after ``time_s`` at constant h:
    exp(-h A t / (m c)) with A / m = 6 / (rho d) (Incropera Eq. 5.6)."""
    return math.exp(-6.0 * h * time_s / (density * heat_capacity * diameter))
