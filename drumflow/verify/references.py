"""Independent references for the air-side physics, and the checks that need no solver.

Nothing here calls :mod:`drumflow.physics.particle_air` or drumflow's air table to form an
expected value, so a wrong correlation, exponent or air property in the implementation shows
up as a failed check:

* air properties from CoolProp (``"Air"``: Lemmon et al. 2000 equation of state, Lemmon &
  Jacobsen 2004 viscosity and conductivity), an implementation and a data source of its own
  (drumflow's :class:`~drumflow.physics.particle_air.AirState` interpolates Incropera's Table A.4);
* the standard drag curve of a sphere from Clift, Grace & Weber, *Bubbles, Drops, and
  Particles* (Academic Press, 1978), Table 5.2 (a fit to the body of drag measurements), not
  Schiller-Naumann;
* the Ranz-Marshall Nusselt number written out again here,
  Nu = 2 + 0.6 Re^(1/2) Pr^(1/3) (Ranz & Marshall 1952; the paper's Eq. 23), with CoolProp's
  properties;
* the smooth-pipe friction factor of Petukhov (1970), f = (0.790 ln Re - 1.64)^-2,
  3e3 <= Re <= 5e6 (Incropera et al., *Fundamentals of Heat and Mass Transfer*, Eq. 8.21).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from scipy.optimize import brentq

from drumflow.physics.validation import relative_error
from drumflow.verify.checks import Check

G = 9.81
KELVIN = 273.15


@dataclass(frozen=True)
class ReferenceAir:
    """Air properties from CoolProp at one temperature and pressure (SI)."""

    temperature_C: float
    density: float
    viscosity: float
    conductivity: float
    prandtl: float

    @classmethod
    def at(cls, temperature_C: float, pressure_kPa: float = 101.325) -> ReferenceAir:
        from CoolProp.CoolProp import PropsSI

        T, p = temperature_C + KELVIN, pressure_kPa * 1e3
        return cls(
            temperature_C=temperature_C,
            density=float(PropsSI("D", "T", T, "P", p, "Air")),
            viscosity=float(PropsSI("V", "T", T, "P", p, "Air")),
            conductivity=float(PropsSI("L", "T", T, "P", p, "Air")),
            prandtl=float(PropsSI("Prandtl", "T", T, "P", p, "Air")),
        )


def standard_drag_coefficient(reynolds: float) -> float:
    """C_d of a smooth sphere on the standard drag curve, 20 < Re <= 1500 (CGW Table 5.2).

    20 < Re <= 260: C_d = 24/Re (1 + 0.1935 Re^0.6305);
    260 < Re <= 1500: log10 C_d = 1.6435 - 1.1242 w + 0.1558 w^2, w = log10 Re.

    Raises
    ------
    ValueError
        Outside 20 < Re <= 1500 (the range these two rows cover).
    """
    if not 20.0 < reynolds <= 1500.0:
        raise ValueError(f"reynolds = {reynolds:g}: outside the tabulated rows; allowed: > 20 and <= 1500")
    if reynolds <= 260.0:
        return 24.0 / reynolds * (1.0 + 0.1935 * reynolds**0.6305)
    w = math.log10(reynolds)
    return 10.0 ** (1.6435 - 1.1242 * w + 0.1558 * w * w)


def settling_velocity(diameter: float, particle_density: float, air: ReferenceAir) -> float:
    """Terminal speed on the standard drag curve, m/s: m g = C_d(Re) rho pi d^2 / 8 v^2.

    No buoyancy: the DEM applies full gravity and no pressure-gradient force.
    """
    mass = particle_density * math.pi / 6.0 * diameter**3

    def balance(v: float) -> float:
        re = air.density * v * diameter / air.viscosity
        return standard_drag_coefficient(re) * air.density * math.pi / 8.0 * diameter**2 * v**2 - mass * G

    lo = 20.0001 * air.viscosity / (air.density * diameter)
    hi = 1500.0 * air.viscosity / (air.density * diameter)
    return float(brentq(balance, lo, hi, xtol=1e-12, rtol=1e-12))


def drag_coefficient_from_settling(
    speed: float, diameter: float, particle_density: float, air: ReferenceAir
) -> tuple[float, float]:
    """(C_d, Re) that a measured terminal speed implies: C_d = 8 m g / (rho pi d^2 v^2)."""
    mass = particle_density * math.pi / 6.0 * diameter**3
    cd = 8.0 * mass * G / (air.density * math.pi * diameter**2 * speed**2)
    return cd, air.density * speed * diameter / air.viscosity


def ranz_marshall_reference(slip_speed: float, diameter: float, air: ReferenceAir) -> float:
    """h, W/(m2 K), from Nu = 2 + 0.6 Re^(1/2) Pr^(1/3) with CoolProp's air."""
    re = air.density * slip_speed * diameter / air.viscosity
    return (2.0 + 0.6 * math.sqrt(re) * air.prandtl ** (1.0 / 3.0)) * air.conductivity / diameter


def petukhov_friction_factor(reynolds: float) -> float:
    """Darcy friction factor of a smooth pipe, (0.790 ln Re - 1.64)^-2 (3e3 <= Re <= 5e6)."""
    if not 3e3 <= reynolds <= 5e6:
        raise ValueError(f"reynolds = {reynolds:g}: outside Petukhov's range; allowed: >= 3e3 and <= 5e6")
    return (0.790 * math.log(reynolds) - 1.64) ** -2


# -- checks without a solver -------------------------------------------------------------

#: Agreement asked of drumflow's air table with CoolProp. Incropera's Table A.4 and the
#: Lemmon-Jacobsen correlations are independent data; Lemmon & Jacobsen state uncertainties of
#: about 1% (viscosity) and 2% (conductivity) near ambient; the ideal gas against the real-gas
#: equation of state differs by Z - 1 ~ 3e-4. Pr = mu cp / k inherits the 2% of k.
AIR_PROPERTY_TOLERANCE = {"density": 0.005, "viscosity": 0.01, "conductivity": 0.02, "prandtl": 0.02}


def air_property_checks(temperatures_C: tuple[float, ...] = (30.0, 90.0)) -> list[Check]:
    """drumflow's air (``AirState``) against CoolProp at the cooler's air temperatures."""
    from drumflow.physics.particle_air import AirState

    checks = []
    for t in temperatures_C:
        ours, ref = AirState.at(t), ReferenceAir.at(t)
        for name, tol in AIR_PROPERTY_TOLERANCE.items():
            m, e = float(getattr(ours, name)), float(getattr(ref, name))
            checks.append(
                Check(
                    name=f"air_{name}_{t:g}C",
                    measured=m,
                    expected=e,
                    error=relative_error(m, e),
                    tolerance=tol,
                    unit={"density": "kg/m3", "viscosity": "Pa s", "conductivity": "W/(m K)", "prandtl": "-"}[
                        name
                    ],
                    note=f"drumflow's air at {t:g} C, 1 atm (Incropera Table A.4 interpolated) "
                    "against CoolProp",
                    reference="CoolProp 'Air' (Lemmon et al. 2000; Lemmon & Jacobsen 2004)",
                )
            )
    return checks


#: Schiller-Naumann is a fit to the standard drag curve within about 5% for Re < 800 (CGW
#: 1978, Ch. 5); CGW's curve itself is a fit to scattered measurements (a couple of percent).
DRAG_TOLERANCE = 0.07


def drag_curve_check(reynolds: tuple[float, ...] = (50.0, 100.0, 200.0, 500.0)) -> Check:
    """drumflow's drag law at the drum's slip Reynolds numbers against the standard curve.

    The coefficient is read back from :func:`drumflow.physics.particle_air.drag_force` (the force
    the coupling applies), not from ``schiller_naumann_cd``.
    """
    import numpy as np

    from drumflow.physics.particle_air import AirState, drag_force

    air = AirState.at(30.0)
    d = 0.008
    worst, rows = 0.0, {}
    for re in reynolds:
        v = re * air.viscosity / (air.density * d)
        f = float(drag_force(np.array([[0.0, 0.0, v]]), np.zeros((1, 3)), d, air)[0, 2])
        cd = f / (0.5 * air.density * math.pi / 4.0 * d**2 * v**2)
        ref = standard_drag_coefficient(re)
        rows[f"{re:g}"] = {"cd": cd, "cd_standard_curve": ref}
        worst = max(worst, relative_error(cd, ref))
    return Check(
        name="drag_coefficient_standard_curve",
        measured=worst,
        expected=0.0,
        error=worst,
        tolerance=DRAG_TOLERANCE,
        unit="largest relative deviation",
        note="C_d from the coupling's drag force at Re "
        + ", ".join(f"{r:g}" for r in reynolds)
        + " against the standard drag curve",
        reference="Clift, Grace & Weber (1978), Table 5.2",
        details=rows,
    )
