"""Air properties: Incropera & DeWitt Table A.4 nodes, linear interpolation, range errors."""

from __future__ import annotations

import numpy as np
import pytest

from drumflow.errors import AnalysisInputError
from drumflow.physics import air

# Rows of Incropera & DeWitt, Fundamentals of Heat and Mass Transfer, Table A.4 (air, 1 atm),
# typed in again here (not imported) so a wrong value in the module is caught:
# T (K), rho (kg/m3), cp (kJ/kg K), mu*1e7 (N s/m2), nu*1e6 (m2/s), k*1e3 (W/m K), Pr
ROWS = [
    (250.0, 1.3947, 1.006, 159.6, 11.44, 22.3, 0.720),
    (300.0, 1.1614, 1.007, 184.6, 15.89, 26.3, 0.707),
    (350.0, 0.9950, 1.009, 208.2, 20.92, 30.0, 0.700),
    (400.0, 0.8711, 1.014, 230.1, 26.41, 33.8, 0.690),
    (450.0, 0.7740, 1.021, 250.7, 32.39, 37.3, 0.686),
    (500.0, 0.6964, 1.030, 270.1, 38.79, 40.7, 0.684),
]


@pytest.mark.parametrize("row", ROWS, ids=lambda r: f"{r[0]:.0f}K")
def test_table_nodes_are_returned_exactly(row: tuple[float, ...]) -> None:
    t_k, rho, cp, mu, nu, k, pr = row
    t_c = t_k - 273.15
    # At a node linear interpolation returns the tabulated value; 1e-12 only absorbs the
    # K -> deg C -> K round trip of the node position.
    assert air.density(t_c) == pytest.approx(rho, rel=1e-12)
    assert air.specific_heat(t_c) == pytest.approx(cp * 1e3, rel=1e-12)
    assert air.dynamic_viscosity(t_c) == pytest.approx(mu * 1e-7, rel=1e-12)
    assert air.kinematic_viscosity(t_c) == pytest.approx(nu * 1e-6, rel=1e-12)
    assert air.thermal_conductivity(t_c) == pytest.approx(k * 1e-3, rel=1e-12)
    assert air.prandtl(t_c) == pytest.approx(pr, rel=1e-12)


def test_midpoint_is_the_average_of_neighbouring_rows() -> None:
    t_c = 325.0 - 273.15  # halfway between the 300 K and 350 K rows
    # Linear interpolation at a midpoint is exact arithmetic on table values: 1e-12.
    assert air.prandtl(t_c) == pytest.approx((0.707 + 0.700) / 2, rel=1e-12)
    assert air.kinematic_viscosity(t_c) == pytest.approx((15.89 + 20.92) / 2 * 1e-6, rel=1e-12)
    assert air.thermal_conductivity(t_c) == pytest.approx((26.3 + 30.0) / 2 * 1e-3, rel=1e-12)
    assert air.density(t_c) == pytest.approx((1.1614 + 0.9950) / 2, rel=1e-12)


def test_paper_air_inlet_temperature() -> None:
    # 30 deg C = 303.15 K lies 3.15/50 of the way from 300 K to 350 K.
    frac = 3.15 / 50.0
    # Exact linear-interpolation arithmetic: 1e-12.
    assert air.prandtl(30.0) == pytest.approx(0.707 + frac * (0.700 - 0.707), rel=1e-12)
    assert air.specific_heat(30.0) == pytest.approx(1007.0 + frac * 2.0, rel=1e-12)


def test_arrays_in_arrays_out_and_scalars_stay_floats() -> None:
    temps = np.array([0.0, 30.0, 60.0, 90.0])
    out = air.prandtl(temps)
    assert isinstance(out, np.ndarray) and out.shape == temps.shape
    # Pr decreases monotonically between 250 K and 450 K in the table.
    assert np.all(np.diff(out) < 0)
    assert isinstance(air.prandtl(30.0), float)


def test_columns_are_mutually_consistent() -> None:
    # At the nodes nu = mu / rho and Pr = mu cp / k hold up to the table's 3-4 significant
    # figures; 0.5 % would catch swapped or mis-scaled columns. (Between nodes each column is
    # interpolated on its own, so the ratios drift by up to ~1.2 %, which is expected.)
    for t_k in air.TABLE_T_K:
        p = air.air_properties(float(t_k) - 273.15)
        assert p.kinematic_viscosity == pytest.approx(p.dynamic_viscosity / p.density, rel=0.005)
        assert p.prandtl == pytest.approx(
            p.dynamic_viscosity * p.specific_heat / p.thermal_conductivity, rel=0.005
        )


@pytest.mark.parametrize("bad", [-80.0, 330.0, float("nan")])
def test_outside_table_raises_with_name_value_and_range(bad: float) -> None:
    with pytest.raises(AnalysisInputError) as info:
        air.prandtl(bad)
    msg = str(info.value)
    assert "temperature_c" in msg
    assert "-73.15" in msg and "326.85" in msg
    assert isinstance(info.value, ValueError)


def test_array_with_one_bad_value_raises_and_custom_name() -> None:
    with pytest.raises(AnalysisInputError, match=r"T_ma = 400"):
        air.kinematic_viscosity(np.array([30.0, 400.0]), name="T_ma")


def test_table_cannot_be_modified_through_the_module() -> None:
    with pytest.raises(ValueError):
        air.TABLE["prandtl"][0] = 1.0


@pytest.mark.parametrize("t_k", [250.0, 300.0, 350.0, 400.0])
def test_ideal_gas_density_agrees_with_the_table_at_one_atmosphere(t_k: float) -> None:
    # The table's densities are measured values of real air; the ideal gas with R = 287.05
    # J/(kg K) differs from them by under 1.5 % between 250 and 400 K (compressibility and the
    # table's rounding), so 1.5 % is the honest bound for this independent comparison.
    rho = air.ideal_gas_density(t_k - 273.15, 101.325)
    assert rho == pytest.approx(air.density(t_k - 273.15), rel=0.015)


def test_ideal_gas_density_is_proportional_to_pressure() -> None:
    # rho = p / (R T): doubling p doubles rho exactly (floating point only).
    assert air.ideal_gas_density(30.0, 202.65) == pytest.approx(
        2.0 * air.ideal_gas_density(30.0, 101.325), rel=1e-14
    )
