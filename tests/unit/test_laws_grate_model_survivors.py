"""Law tests for the grate model's mutation survivors (issue 36; results/mutation/survivors.md).

The mutmut run of ``drumflow/coolers/grate/model.py`` (tree of d6ddc82, where the clinker
properties, the radiation conductance and :class:`GrateSolution` were still in that module;
they are now in :mod:`drumflow.coolers.grate.properties` and
:mod:`drumflow.coolers.grate.solution`) left mutants alive where the law tests had a grate
1 m wide, one air compartment, a negligible clinker conductivity with no slope, no radiation
value and nothing reading :meth:`GrateSolution.summary`. Each test here compares with a value
that does not come from the function under test:

* the clinker's linear c_p(T) and k(T), their enthalpy, its inverse and the secant c_p,
  worked out by hand (including a c_p slope of 1 J/(kg K2), inside the case's range);
* the bed-top radiation conductance sigma eps_s (1 - eps) dx W by hand, W = 2 m;
* the solver's cell geometry, column air flows (two compartments), freeboard flows, heat duty
  and face conductances (1 - eps) k A / delta with k(T) sloped, by hand;
* the whole solver on a 2 x 2 grid against the report's cell balances (the clinker cell of
  its Eqs. 8-15, the air cell of Eqs. 19-28) written out here as an 8 x 8 linear system, in
  the small-span limit (air in at 299.5 K, clinker at 300.5 K: every film temperature within
  0.5 K of the 300 K row of Incropera's Table A.4, constant clinker c_p), for both the
  report's "outlet" exchange and the "mean" one, with and without conduction, on a 2 m wide
  grate with two air compartments (3 : 1);
* the summary of a solution whose fields are given (not solved), every number by hand.

The packed-bed correlation (Bird, Stewart and Lightfoot, the report's Eqs. 29-31) is written
out again as in ``test_laws_grate.py``.
"""

from __future__ import annotations

import math
import time

import numpy as np
import pytest
from support.law_references import INCROPERA_A4_AIR

from drumflow.coolers.grate import model as grate_model
from drumflow.coolers.grate import properties as grate_props
from drumflow.coolers.grate.case import GrateCase, grate_case_from_dict
from drumflow.coolers.grate.solution import GrateSolution
from drumflow.errors import GrateConvergenceError

_, CP_AIR, MU_AIR, _, _, PR_AIR = INCROPERA_A4_AIR[300.0]
SIGMA = 5.670374419e-8  # Stefan-Boltzmann, W/(m2 K4), CODATA 2018 (typed again)
LENGTH, WIDTH, SPEED = 11.0, 2.0, 0.1
M_S, M_A, CP_S = 33.0, 25.0, 750.0
D_P, POROSITY, RHO_S = 0.02, 0.5, 3150.0
T_AIR, T_CLINKER = 299.5, 300.5
#: Bed height m_s / (rho_s (1 - eps) v_g W) = 33 / (3150 * 0.5 * 0.1 * 2) = 0.1047619 m.
HEIGHT = M_S / (RHO_S * (1.0 - POROSITY) * SPEED * WIDTH)
#: Rounded molar mass and gas constant of the ideal-gas density (as in test_laws_grate.py).
P_ATM, M_AIR, R_GAS = 101325.0, 0.0289644, 8.314462618


def _close(value: float, reference: float, rtol: float, what: str) -> None:
    assert math.isfinite(value) and abs(value / reference - 1.0) <= rtol, (
        f"{what}: {value:.8g} vs independent {reference:.8g} "
        f"({value / reference - 1.0:+.3%}, allowed {rtol:.1e})")


def _case(*, exchange: str = "mean", conductivity: float = 1e-6, slope: float = 0.0,
          cells: tuple[int, int] = (2, 2), weights: tuple[float, ...] = (3.0, 1.0),
          porosity: float = POROSITY, radiation: bool = False, t_air: float = T_AIR,
          t_clinker: float = T_CLINKER, fan: bool = False) -> GrateCase:
    data: dict[str, object] = {
        "name": "survivors",
        "cooler": {"length": LENGTH, "width": WIDTH, "grate_speed": SPEED},
        "clinker": {"mass_flow": M_S, "inlet_temperature": t_clinker, "particle_diameter": D_P,
                    "sphericity": 1.0, "bed_porosity": porosity, "density": RHO_S,
                    "heat_capacity": CP_S, "heat_capacity_slope": 0.0,
                    "conductivity": conductivity, "conductivity_slope": slope,
                    "emissivity": 0.9},
        "air": {"mass_flow": M_A, "inlet_temperature": t_air, "distribution": list(weights),
                "supply": "fan" if fan else "fixed"},
        "model": {"radiation": radiation},
        "numerics": {"cells_length": cells[0], "cells_height": cells[1], "exchange": exchange},
    }
    if fan:
        data["fan"] = {"shutoff_pressure": 1460.0, "free_delivery": 35.4}
    return grate_case_from_dict(data)


# --- properties --------------------------------------------------------------------------------


def test_clinker_property_laws_by_hand() -> None:
    """c_p = 710 + 0.233 T, k = 1.5 + 0.002 T (T in K):
    k(1000) = 3.5 W/(m K); h(1000) - h(300) = 710 * 700 + 0.1165 * (1000^2 - 300^2) = 603,015
    J/kg, the secant c_p 603,015 / 700 = 861.45 J/(kg K) = c_p(650); the caloric temperature of
    h(1673) = 710 * 1673 + 0.1165 * 1673^2 = 1,513,904.8 J/kg is 1673 K. With c_p slope 1
    (allowed: -2 to 2) and cp0 = 100: h = 100 T + T^2 / 2, h = 600,000 J/kg is T = 1000 K
    (root of T^2 / 2 + 100 T - 6e5 = 0), and with no slope h / cp0. Closed form: 1e-12."""
    props = grate_props.ClinkerProperties(cp0=710.0, cp1=0.233, k0=1.5, k1=0.002)
    _close(float(props.conductivity(1000.0)), 3.5, 1e-12, "k(1000 K)")
    _close(float(props.heat_capacity(1000.0)), 943.0, 1e-12, "c_p(1000 K)")
    _close(float(props.enthalpy(1000.0) - props.enthalpy(300.0)), 603015.0, 1e-12, "h(1000) - h(300)")
    _close(float(props.secant(np.array([1000.0]), np.array([300.0]))[0]), 861.45, 1e-12, "secant c_p")
    _close(float(props.temperature(710.0 * 1673.0 + 0.1165 * 1673.0**2)), 1673.0, 1e-12,
           "caloric temperature (c_p slope 0.233)")
    steep = grate_props.ClinkerProperties(cp0=100.0, cp1=1.0, k0=1.5, k1=0.0)
    _close(float(steep.temperature(600000.0)), 1000.0, 1e-12, "caloric temperature (c_p slope 1)")
    flat = grate_props.ClinkerProperties(cp0=750.0, cp1=0.0, k0=1.5, k1=0.0)
    _close(float(flat.temperature(750.0 * 1234.5)), 1234.5, 1e-12, "caloric temperature (no slope)")
    # The case's fields in their slots.
    case = _case(conductivity=1.5, slope=0.002)
    assert grate_props.ClinkerProperties.of(case) == grate_props.ClinkerProperties(
        cp0=CP_S, cp1=0.0, k0=1.5, k1=0.002)


def test_radiation_conductance_by_hand() -> None:
    """sigma eps_s (1 - eps) dx W of one top cell, eps_s = 0.9, eps = 0.4, dx = 11 / 4 m,
    W = 2 m: 5.670374419e-8 * 0.9 * 0.6 * 2.75 * 2 = 1.684101e-7 W/K4; zero with radiation
    off. Closed form: 1e-12."""
    on = _case(radiation=True, porosity=0.4, cells=(4, 3))
    _close(grate_props.radiation_conductance(on, 4), SIGMA * 0.9 * 0.6 * 2.75 * 2.0, 1e-12,
           "radiation conductance")
    assert abs(SIGMA * 0.9 * 0.6 * 2.75 * 2.0 - 1.684101e-7) < 1e-12
    assert grate_props.radiation_conductance(_case(porosity=0.4, cells=(4, 3)), 4) == 0.0


# --- the solver's grid -------------------------------------------------------------------------


def test_air_columns_follow_the_compartments() -> None:
    """Equal-length compartments, kiln end first, a column in the compartment holding its
    centre: 4 columns under [3, 1] are [3, 3, 1, 1] / 8 of the air; 6 columns under [1, 2, 3]
    are [1, 1, 2, 2, 3, 3] / 12; the given total replaces the case's. Exact: 1e-12."""
    flows = grate_model._air_column_flow(_case(cells=(4, 2)), 4)
    np.testing.assert_allclose(flows, [9.375, 9.375, 3.125, 3.125], rtol=1e-12)
    flows = grate_model._air_column_flow(_case(cells=(6, 2), weights=(1.0, 2.0, 3.0)), 6, 24.0)
    np.testing.assert_allclose(flows, [2.0, 2.0, 4.0, 4.0, 6.0, 6.0], rtol=1e-12)


def test_grid_geometry_and_flows_by_hand() -> None:
    """3 x 2 cells on the 11 m x 2 m grate, air [3, 1] (the column centres at 1/6, 1/2 and 5/6
    of the length fall in compartments 0, 1, 1):
    dx = 11 / 3 m, dy = 0.1047619 / 2 m, cell volume dx dy W = 0.3841270 m3; columns
    [3, 1, 1] / 5 * 25 = [15, 5, 5] kg/s; flux M_i / (dx W) = [2.045455, 0.681818, 0.681818]
    kg/(m2 s); freeboard flow towards the kiln end [25, 10, 5] kg/s; layer flow 33 / 2 kg/s;
    heat duty m_s c_p (T_in - T_air) = 33 * 750 * 1 = 24,750 W. Exact: 1e-12."""
    grid = grate_model._Grid(_case(cells=(3, 2)))
    dx, dy = LENGTH / 3.0, HEIGHT / 2.0
    _close(grid.volume, dx * dy * WIDTH, 1e-12, "cell volume")
    assert abs(grid.volume - 0.3841270) < 1e-7
    np.testing.assert_allclose(grid.column_flow, [15.0, 5.0, 5.0], rtol=1e-12)
    np.testing.assert_allclose(grid.mass_flux, np.array([15.0, 5.0, 5.0]) / (dx * WIDTH), rtol=1e-12)
    np.testing.assert_allclose(grid.freeboard_flow, [25.0, 10.0, 5.0], rtol=1e-12)
    _close(grid.layer_flow, 16.5, 1e-12, "layer flow")
    _close(grid.duty, M_S * CP_S * (T_CLINKER - T_AIR), 1e-9, "heat duty (normalises the residuals)")
    assert grid.theta == 0.5
    assert grate_model._Grid(_case(cells=(3, 2), exchange="outlet")).theta == 0.0


def test_face_conductances_by_hand() -> None:
    """(1 - eps) k A / delta with k = 1.5 + 0.002 T at the faces' arithmetic mean, eps = 0.4,
    3 x 3 cells: dx = 11 / 3 m, dy = H / 3 with H = 33 / (3150 * 0.6 * 0.1 * 2) = 0.0873016 m.
    Between the bottom-left cells at 1000 K and 900 K: 0.6 * (3.5 + 3.3) / 2 = 2.04 W/(m K),
    times dy W / dx = 0.0158730 m: 0.0323810 W/K; between 1000 K and 950 K above it:
    0.6 * 3.45 = 2.07 W/(m K) times dx W / dy = 252.0 m: 521.64 W/K. Closed form: 1e-12."""
    grid = grate_model._Grid(_case(conductivity=1.5, slope=0.002, porosity=0.4, cells=(3, 3)))
    ts = np.array([[1000.0, 900.0, 700.0], [950.0, 820.0, 640.0], [905.0, 780.0, 600.0]])
    kb = 0.6 * (1.5 + 0.002 * ts)
    height = M_S / (RHO_S * 0.6 * SPEED * WIDTH)
    dx, dy = LENGTH / 3.0, height / 3.0
    east_west = np.array([[0.5 * (kb[j, i] + kb[j, i + 1]) * dy * WIDTH / dx for i in range(2)]
                          for j in range(3)])
    north_south = np.array([[0.5 * (kb[j, i] + kb[j + 1, i]) * dx * WIDTH / dy for i in range(3)]
                            for j in range(2)])
    assert abs(east_west[0, 0] - 0.0323810) < 1e-7 and abs(north_south[0, 0] - 521.64) < 1e-2
    dxf, dyf = grid.conduction(ts)
    np.testing.assert_allclose(dxf, east_west, rtol=1e-12)
    np.testing.assert_allclose(dyf, north_south, rtol=1e-12)


# --- the whole solver on 2 x 2 cells ------------------------------------------------------------


def _packed_bed_h(mass_flux: float) -> float:
    """Re = d G0 / ((1 - eps) mu psi), j_H = 2.19 Re^-2/3 + 0.78 Re^-0.381,
    h = j_H c_p G0 Pr^-2/3, Incropera's 300 K row (as in test_laws_grate.py)."""
    re = D_P * mass_flux / ((1.0 - POROSITY) * MU_AIR)
    return (2.19 * re ** (-2.0 / 3.0) + 0.78 * re ** (-0.381)) * CP_AIR * mass_flux * PR_AIR ** (-2.0 / 3.0)


def _cells_by_hand(theta: float, conductivity: float) -> tuple[np.ndarray, np.ndarray]:
    """The report's balances of a 2 x 2 grid (layers j from the grate, columns i from the kiln
    end), constant properties, written out as a linear system for the 4 clinker and 4 air
    temperatures:

    clinker  F c_s (T_W - T_P) + sum G (T_nb - T_P) - U_i (T_s,ex - T_a,ex) = 0,
    air      M_i c_a (T_S - T_P) + U_i (T_s,ex - T_a,ex) = 0,

    T_s,ex = theta T_W + (1 - theta) T_P (clinker from the west; T_in at the kiln end),
    T_a,ex = theta T_S + (1 - theta) T_P (air from below; T_air at the grate); theta = 0 is
    the report's outlet form, 1/2 the mean. F = 33 / 2 kg/s; M = [18.75, 6.25] kg/s (weights
    3 : 1); U_i = a h(G_i) dx dy W, a = 6 * 0.5 / 0.02 = 150 1/m, dx dy W = 5.5 * 0.0523810
    * 2 = 0.576190 m3, G_i = M_i / (5.5 * 2) = [1.704545, 0.568182] kg/(m2 s), h = [93.60,
    51.12] W/(m2 K), U = [8,090, 4,418] W/K; conductances G = (1 - eps) k dy W / dx
    east-west, (1 - eps) k dx W / dy north-south (105.0 k W/K).
    """
    n = m = 2
    dx, dy = LENGTH / n, HEIGHT / m
    flows = [0.75 * M_A, 0.25 * M_A]
    u = [150.0 * _packed_bed_h(f / (dx * WIDTH)) * dx * dy * WIDTH for f in flows]
    g_x = (1.0 - POROSITY) * conductivity * dy * WIDTH / dx
    g_y = (1.0 - POROSITY) * conductivity * dx * WIDTH / dy
    f_s = M_S / m * CP_S
    cells = n * m
    a = np.zeros((2 * cells, 2 * cells))
    b = np.zeros(2 * cells)

    def k(j: int, i: int) -> int:
        return j * n + i

    for j in range(m):
        for i in range(n):
            rs, ra = k(j, i), cells + k(j, i)
            f_a = flows[i] * CP_AIR
            a[rs, k(j, i)] += f_s + (1.0 - theta) * u[i]
            a[rs, cells + k(j, i)] -= (1.0 - theta) * u[i]
            a[ra, cells + k(j, i)] += f_a + (1.0 - theta) * u[i]
            a[ra, k(j, i)] -= (1.0 - theta) * u[i]
            if i == 0:  # clinker from the kiln
                b[rs] += (f_s - theta * u[i]) * T_CLINKER
                b[ra] += theta * u[i] * T_CLINKER
            else:
                a[rs, k(j, i - 1)] -= f_s - theta * u[i]
                a[ra, k(j, i - 1)] -= theta * u[i]
            if j == 0:  # air from below the grate
                b[rs] += theta * u[i] * T_AIR
                b[ra] += (f_a - theta * u[i]) * T_AIR
            else:
                a[rs, cells + k(j - 1, i)] -= theta * u[i]
                a[ra, cells + k(j - 1, i)] -= f_a - theta * u[i]
            for jj, ii, g in ((j, i - 1, g_x), (j, i + 1, g_x), (j - 1, i, g_y), (j + 1, i, g_y)):
                if 0 <= jj < m and 0 <= ii < n:
                    a[rs, k(j, i)] += g
                    a[rs, k(jj, ii)] -= g
    x = np.linalg.solve(a, b)
    return x[:cells].reshape(m, n), x[cells:].reshape(m, n)


def check_two_by_two(exchange: str, conductivity: float) -> None:
    """The solver's clinker and air temperatures on 2 x 2 cells against the written-out
    balances. The film temperatures sit within 0.5 K of the 300 K row: measured 4e-5 of the
    1 K span apart. 3e-4 of the span allowed, against 1.4e-3 to 2e-3 of it for a 10 % error
    in the vertical conduction (k = 50 W/(m K)), 1.5e-2 to 2.8e-2 for 10 % in h, and about
    0.1 between the two exchange forms. The freeboard mixes the columns' top air (constant c_p over
    0.5 K): the discharge-end cell holds only its own column's air, the kiln end 3 : 1."""
    sol = grate_model.solve_grate(_case(exchange=exchange, conductivity=conductivity))
    theta = 0.5 if exchange == "mean" else 0.0
    ts, ta = _cells_by_hand(theta, conductivity)
    span = T_CLINKER - T_AIR
    what = f"{exchange} exchange, k = {conductivity:g}"
    np.testing.assert_allclose((sol.clinker_temperature - T_AIR) / span, (ts - T_AIR) / span,
                               rtol=0.0, atol=3e-4, err_msg=f"clinker cells, {what}")
    np.testing.assert_allclose((sol.air_temperature - T_AIR) / span, (ta - T_AIR) / span,
                               rtol=0.0, atol=3e-4, err_msg=f"air cells, {what}")
    tfb = sol.freeboard_temperature
    assert abs(tfb[1] - sol.air_temperature[1, 1]) < 1e-9 * span, f"discharge-end freeboard, {what}"
    mix = 0.75 * ta[1, 0] + 0.25 * ta[1, 1]
    assert abs(tfb[0] - mix) < 3e-4 * span, f"secondary air {tfb[0]} vs mixed {mix}, {what}"
    np.testing.assert_allclose(sol.air_column_flow, [18.75, 6.25], rtol=1e-12)
    # Cell centres: 2.75 and 8.25 m along, H / 4 and 3 H / 4 up.
    np.testing.assert_allclose(sol.x, [2.75, 8.25], rtol=1e-12)
    np.testing.assert_allclose(sol.y, [0.25 * HEIGHT, 0.75 * HEIGHT], rtol=1e-12)
    _close(sol.bed_height, HEIGHT, 1e-12, "bed height")


def test_two_by_two_grid_mean_exchange() -> None:
    check_two_by_two("mean", 1e-6)


def test_two_by_two_grid_outlet_exchange() -> None:
    check_two_by_two("outlet", 1e-6)


def test_two_by_two_grid_with_conduction() -> None:
    check_two_by_two("mean", 50.0)


def test_two_by_two_grid_outlet_exchange_with_conduction() -> None:
    check_two_by_two("outlet", 50.0)


def test_sweep_count_and_limit() -> None:
    """The reported sweep count is the number of sweeps made (one history row each, numbered
    from 1), and numerics.max_sweeps bounds them: the same solve with max_sweeps equal to that
    count converges to the same field, one fewer is refused naming the option. The reported
    residual and energy imbalance are below the case's tolerances (1e-9, the stopping rule),
    and the wall time is within the time measured around the call."""
    start = time.perf_counter()
    sol = grate_model.solve_grate(_case())
    elapsed = time.perf_counter() - start
    assert 0.0 < sol.wall_time_s <= elapsed
    assert 0.0 <= sol.residual < 1e-9 and 0.0 <= sol.energy_imbalance < 1e-9
    assert sol.sweeps == len(sol.history) >= 2
    assert [row[0] for row in sol.history] == list(range(1, sol.sweeps + 1))
    data = _case().model_dump()
    data["numerics"]["max_sweeps"] = sol.sweeps
    again = grate_model.solve_grate(grate_case_from_dict(data))
    np.testing.assert_array_equal(again.clinker_temperature, sol.clinker_temperature)
    data["numerics"]["max_sweeps"] = sol.sweeps - 1
    with pytest.raises(GrateConvergenceError, match="max_sweeps"):
        grate_model.solve_grate(grate_case_from_dict(data))


# --- the summary -------------------------------------------------------------------------------

#: The headline numbers' names (the CLI's table and the run's result.json read them).
SUMMARY_KEYS = {
    "air_supply", "air_flow_kg_s", "bed_pressure_drop_Pa", "clinker_outlet_temperature_K",
    "secondary_air_temperature_K", "heat_recovered_MW", "heat_duty_MW", "cooler_efficiency",
    "radiation_heat_MW", "bed_height_m", "residence_time_s", "h_mean_W_m2K", "top_layer_outlet_K",
    "bottom_layer_outlet_K", "cells", "sweeps", "residual", "energy_imbalance", "wall_time_s",
}
TS_GIVEN = np.array([[390.0, 380.0, 370.0, 360.0], [395.0, 385.0, 375.0, 365.0],
                     [398.0, 388.0, 378.0, 368.0]])
TFB_GIVEN = np.array([302.0, 301.0, 300.5, 300.2])
H_GIVEN = np.array([[100.0, 110.0, 120.0, 130.0], [101.0, 111.0, 121.0, 131.0],
                    [102.0, 112.0, 122.0, 132.0]])


def _given_solution(fan: bool) -> GrateSolution:
    """Fields given, not solved: 4 x 3 cells, clinker in at 400 K, air in at 300 K and 300 K
    throughout the bed, radiation on (eps_s = 0.9, eps = 0.5)."""
    case = _case(cells=(4, 3), weights=(1.0,), radiation=True, t_air=300.0, t_clinker=400.0,
                 fan=fan)
    return GrateSolution(
        case=case, x=np.array([1.375, 4.125, 6.875, 9.625]), y=HEIGHT * np.array([1, 3, 5]) / 6.0,
        clinker_temperature=TS_GIVEN, air_temperature=np.full((3, 4), 300.0),
        freeboard_temperature=TFB_GIVEN, heat_transfer_coefficient=H_GIVEN,
        air_column_flow=np.full(4, M_A / 4.0), bed_height=HEIGHT, sweeps=7, residual=3e-10,
        energy_imbalance=2e-11, wall_time_s=0.25)


def _summary_by_hand() -> dict[str, float]:
    """Fields of :func:`_given_solution`, by hand:

    heat duty 33 * 750 * (400 - 300) = 2.475 MW; heat recovered 25 * 1007.04 * 2 = 50,352 W
    (Incropera: c_p 1007 at 300 K, 1009 at 350 K, so 1007.04 mean over 300-302 K): 0.050352
    MW; efficiency 0.0203442; clinker outlet (constant c_p: the layers' mean) (360 + 365 +
    368) / 3 = 364.3333 K; top layer 368 K, bottom 360 K; secondary air 302 K; radiation
    sigma 0.9 * 0.5 * 2.75 * 2 * sum(top^4 - T_fb^4) with top [398, 388, 378, 368] K; bed
    pressure drop H * Ergun at 300 K, G = 25 / 22 kg/(m2 s); residence 11 / 0.1 = 110 s;
    mean h 116 W/(m2 K).
    """
    c_rad = SIGMA * 0.9 * 0.5 * 2.75 * 2.0
    top = TS_GIVEN[-1]
    rho = P_ATM * M_AIR / (R_GAS * 300.0)
    u = M_A / (LENGTH * WIDTH) / rho
    ergun = (150.0 * MU_AIR * (1.0 - POROSITY) ** 2 * u / (POROSITY**3 * D_P**2)
             + 1.75 * rho * (1.0 - POROSITY) * u * u / (POROSITY**3 * D_P))
    duty = M_S * CP_S * 100.0
    recovered = M_A * 1007.04 * 2.0
    return {
        "air_flow_kg_s": M_A, "bed_pressure_drop_Pa": HEIGHT * ergun,
        "clinker_outlet_temperature_K": (360.0 + 365.0 + 368.0) / 3.0,
        "secondary_air_temperature_K": 302.0, "heat_recovered_MW": recovered / 1e6,
        "heat_duty_MW": duty / 1e6, "cooler_efficiency": recovered / duty,
        "radiation_heat_MW": c_rad * float(np.sum(top**4 - TFB_GIVEN**4)) / 1e6,
        "bed_height_m": HEIGHT, "residence_time_s": 110.0, "h_mean_W_m2K": 116.0,
        "top_layer_outlet_K": 368.0, "bottom_layer_outlet_K": 360.0,
    }


def test_summary_by_hand() -> None:
    """Every headline number of a solution with given fields. 1e-4 where the air's enthalpy or
    Ergun's density enters (c_p interpolated between table rows; the ideal gas), 1e-12 where
    the numbers are copied or closed form; the unit conversions exactly (1 MW = 1e6 W)."""
    sol = _given_solution(fan=False)
    s = sol.summary()
    assert set(s) == SUMMARY_KEYS
    for name, value in _summary_by_hand().items():
        _close(float(s[name]), value, 1e-4, f"summary {name}")
    for name in ("clinker_outlet_temperature_K", "top_layer_outlet_K", "bottom_layer_outlet_K",
                 "residence_time_s", "heat_duty_MW", "h_mean_W_m2K"):
        _close(float(s[name]), _summary_by_hand()[name], 1e-12, f"summary {name} (exact)")
    assert s["air_supply"] == "fixed"
    assert s["cells"] == [4, 3]
    assert (s["sweeps"], s["residual"], s["energy_imbalance"], s["wall_time_s"]) == (7, 3e-10, 2e-11, 0.25)
    for name, watts in (("heat_recovered_MW", sol.heat_recovered), ("heat_duty_MW", sol.heat_duty),
                        ("radiation_heat_MW", sol.radiation_heat)):
        assert abs(s[name] * 1e6 / watts - 1.0) < 1e-14, name


def test_summary_reports_the_fan_pressure() -> None:
    """With air.supply = "fan" the fan curve's pressure at the air flow is reported:
    rho(300 K) = 101325 * 0.0289644 / (8.314462618 * 300) = 1.1765915 kg/m3,
    Q = 25 / 1.1765915 = 21.24782 m3/s, p = 1460 [1 - (21.24782 / 35.4)^2] = 934.013 Pa.
    Ideal gas written out: 1e-9."""
    s = _given_solution(fan=True).summary()
    assert set(s) == SUMMARY_KEYS | {"fan_pressure_Pa"}
    rho = P_ATM * M_AIR / (R_GAS * 300.0)
    p = 1460.0 * (1.0 - (M_A / rho / 35.4) ** 2)
    assert abs(p - 934.013) < 1e-3
    _close(float(s["fan_pressure_Pa"]), p, 1e-9, "fan pressure in the summary")
    assert s["air_supply"] == "fan"
