"""Law tests of the air property tables (issue 36): drumflow's air table
(:mod:`drumflow.physics.air`, 200-600 K) and the grate model's high-temperature table
(:mod:`drumflow.coolers.grate.properties`, 250-2000 K).

Independent references:

* the rows of Incropera et al., 6th ed., Table A.4, typed again in
  :mod:`support.law_references` from the book (a transcription check);
* CoolProp's air (Lemmon et al. 2000 equation of state; Lemmon and Jacobsen 2004 viscosity
  and conductivity), a different and newer data set. Measured over 250-1000 K, Incropera's
  rows differ from it by at most 0.06 % in c_p, 1.9 % in mu, 2.0 % in k, 2.6 % in Pr and
  1.4 % in rho (Incropera's density is 1.3 % below p / (R T) throughout). The tolerance is
  3 %: above every measured difference, and a 10 % change of a column cannot hide in it;
* internal consistency of each printed row, Pr = c_p mu / k and nu = mu / rho: the printed
  values have 3-4 significant figures, the measured mismatch is at most 0.07 %; 0.2 % is
  allowed, so a mistyped entry of 10 % (or a slipped digit) fails.

Above 1000 K (the grate's rows to 2000 K) only the internal consistency is checked: there
Incropera's older conductivities and CoolProp's differ by more than the 3 % above.
"""

from __future__ import annotations

import math

import CoolProp.CoolProp as CP
import numpy as np
from support.law_references import INCROPERA_A4_AIR

from drumflow.physics import air as air_properties

ATM = 101325.0
COOLPROP_RTOL = 0.03
ROW_RTOL = 0.002


def _close(value: float, reference: float, rtol: float, what: str) -> None:
    assert math.isfinite(value) and abs(value / reference - 1.0) <= rtol, (
        f"{what}: {value:.6g} vs independent {reference:.6g} "
        f"({value / reference - 1.0:+.3%}, allowed {rtol:.1e})")


def _coolprop(name: str, temperature_k: float) -> float:
    return float(CP.PropsSI(name, "T", temperature_k, "P", ATM, "Air"))


def check_air_table() -> None:
    """drumflow.physics.air against Incropera's rows, CoolProp, and row consistency."""
    for t_k, (rho, cp, mu, nu, k, pr) in INCROPERA_A4_AIR.items():
        t_c = t_k - 273.15
        p = air_properties.air_properties(t_c)
        for what, value, ref in (("rho", p.density, rho), ("c_p", p.specific_heat, cp),
                                 ("mu", p.dynamic_viscosity, mu), ("nu", p.kinematic_viscosity, nu),
                                 ("k", p.thermal_conductivity, k), ("Pr", p.prandtl, pr)):
            _close(value, ref, 1e-9, f"{what} at {t_k:g} K vs Incropera Table A.4")
    # Rows and midpoints from 250 to 600 K against CoolProp.
    for t_k in np.arange(250.0, 600.1, 25.0):
        t_c = float(t_k) - 273.15
        _close(float(air_properties.thermal_conductivity(t_c)), _coolprop("L", t_k),
               COOLPROP_RTOL, f"k at {t_k:g} K vs CoolProp")
        _close(float(air_properties.dynamic_viscosity(t_c)), _coolprop("V", t_k),
               COOLPROP_RTOL, f"mu at {t_k:g} K vs CoolProp")
        _close(float(air_properties.specific_heat(t_c)), _coolprop("C", t_k),
               COOLPROP_RTOL, f"c_p at {t_k:g} K vs CoolProp")
        _close(float(air_properties.density(t_c)), _coolprop("D", t_k),
               COOLPROP_RTOL, f"rho at {t_k:g} K vs CoolProp")
        _close(float(air_properties.prandtl(t_c)), _coolprop("Prandtl", t_k),
               COOLPROP_RTOL, f"Pr at {t_k:g} K vs CoolProp")
        _close(air_properties.ideal_gas_density(t_c), _coolprop("D", t_k), 1e-3,
               f"ideal-gas rho at {t_k:g} K vs CoolProp (air is ideal to 0.05 % at 1 atm)")
    # Every row consistent with itself.
    for t_k in air_properties.TABLE_T_K:
        t_c = float(t_k) - 273.15
        p = air_properties.air_properties(t_c)
        _close(p.specific_heat * p.dynamic_viscosity / p.thermal_conductivity, p.prandtl,
               ROW_RTOL, f"c_p mu / k vs Pr at {t_k:g} K")
        _close(p.dynamic_viscosity / p.density, p.kinematic_viscosity, ROW_RTOL,
               f"mu / rho vs nu at {t_k:g} K")


def check_grate_air_table() -> None:
    """The grate's air table against Incropera's rows, CoolProp (<= 1000 K), consistency."""
    for t_k, (_, cp, mu, _, k, pr) in INCROPERA_A4_AIR.items():
        for what, value, ref in (("c_p", air_properties.air_heat_capacity(t_k), cp),
                                 ("mu", air_properties.air_viscosity(t_k), mu),
                                 ("k", air_properties.air_conductivity(t_k), k),
                                 ("Pr", air_properties.air_prandtl(t_k), pr)):
            _close(float(value), ref, 1e-9, f"grate {what} at {t_k:g} K vs Incropera Table A.4")
    for t_k in np.arange(250.0, 1000.1, 25.0):
        t = float(t_k)
        _close(float(air_properties.air_conductivity(t)), _coolprop("L", t), COOLPROP_RTOL,
               f"grate k at {t:g} K vs CoolProp")
        _close(float(air_properties.air_viscosity(t)), _coolprop("V", t), COOLPROP_RTOL,
               f"grate mu at {t:g} K vs CoolProp")
        _close(float(air_properties.air_heat_capacity(t)), _coolprop("C", t), COOLPROP_RTOL,
               f"grate c_p at {t:g} K vs CoolProp")
        _close(float(air_properties.air_prandtl(t)), _coolprop("Prandtl", t), COOLPROP_RTOL,
               f"grate Pr at {t:g} K vs CoolProp")
    # Enthalpy differences (the grate's energy balance) against CoolProp's: the integral of
    # c_p, which agrees to 0.06 %; 0.3 % allowed.
    for t1, t2 in ((300.0, 500.0), (300.0, 1000.0), (600.0, 900.0)):
        dh = float(air_properties.air_enthalpy(t2) - air_properties.air_enthalpy(t1))
        ref = (float(CP.PropsSI("H", "T", t2, "P", ATM, "Air"))
               - float(CP.PropsSI("H", "T", t1, "P", ATM, "Air")))
        _close(dh, ref, 3e-3, f"grate air enthalpy {t1:g}-{t2:g} K vs CoolProp")
    for t_k in np.arange(250.0, 2000.1, 50.0):
        t = float(t_k)
        cp = float(air_properties.air_heat_capacity(t))
        _close(cp * float(air_properties.air_viscosity(t)) / float(air_properties.air_conductivity(t)),
               float(air_properties.air_prandtl(t)), ROW_RTOL, f"grate c_p mu / k vs Pr at {t:g} K")


def test_air_table_against_incropera_coolprop_and_itself() -> None:
    check_air_table()


def test_grate_air_table_against_incropera_coolprop_and_itself() -> None:
    check_grate_air_table()
