"""The grate model's hot-air table against an independent source: CoolProp's air (Lemmon et
al. 2000 equation of state, Lemmon and Jacobsen 2004 transport), up to 1300 K.

The table was typed in from Incropera's Table A.4; this check would catch a mistyped row.
Above about 1400 K Incropera's conductivity rises faster than CoolProp's (10% at 1600 K, 20%
at 2000 K, the table's older high-temperature data), so the hottest rows are compared with a
wider bound and the difference is stated rather than hidden.
"""

from __future__ import annotations

from typing import Any

import pytest
from support.requirements import requires_module

from drumflow.physics import air as gp

CoolProp: Any
try:
    import CoolProp.CoolProp as CoolProp
except ImportError:  # the marker below skips the tests, or fails them under CI
    CoolProp = None

# Without CoolProp: skipped on a workstation, failed under CI (support/requirements.py).
pytestmark = requires_module("CoolProp.CoolProp")


@pytest.mark.parametrize("temperature", [300.0, 400.0, 500.0, 700.0, 900.0, 1100.0, 1300.0])
def test_air_table_matches_coolprop_to_1300_k(temperature: float) -> None:
    p = 101325.0
    cp = CoolProp.PropsSI("C", "T", temperature, "P", p, "Air")
    mu = CoolProp.PropsSI("V", "T", temperature, "P", p, "Air")
    k = CoolProp.PropsSI("L", "T", temperature, "P", p, "Air")
    # 4%: the spread between property sources for air below 1300 K (measured: cp 0.07%,
    # mu 3.4%, k 1.9% at worst).
    assert float(gp.air_heat_capacity(temperature)) == pytest.approx(cp, rel=0.01)
    assert float(gp.air_viscosity(temperature)) == pytest.approx(mu, rel=0.04)
    assert float(gp.air_conductivity(temperature)) == pytest.approx(k, rel=0.04)


@pytest.mark.parametrize("temperature", [1600.0, 2000.0])
def test_hottest_rows_stay_near_coolprop(temperature: float) -> None:
    p = 101325.0
    cp = CoolProp.PropsSI("C", "T", temperature, "P", p, "Air")
    k = CoolProp.PropsSI("L", "T", temperature, "P", p, "Air")
    assert float(gp.air_heat_capacity(temperature)) == pytest.approx(cp, rel=0.08)
    assert float(gp.air_conductivity(temperature)) == pytest.approx(k, rel=0.22)
