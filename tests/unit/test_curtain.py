"""Curtain model (Wardjiman and Rhodes 2009): energy closure, limits, grid convergence, and the
exposure matrices against the shared solver's own ``advance``."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from drumflow.case import read_toml, validate_model
from drumflow.coolers._propagator import apply, exposure_matrix
from drumflow.coolers.curtain import CurtainCase, solve_curtain
from drumflow.errors import CaseError
from drumflow.physics.particle_interior import Sphere, SphereConduction

CASES = Path(__file__).resolve().parents[2] / "cases"


def _case(fig: int = 3, **changes: dict[str, object]) -> CurtainCase:
    data = read_toml(CASES / f"curtain_fig{fig}.toml")
    for section, values in changes.items():
        data[section] = {**data.get(section, {}), **values}
    return validate_model(CurtainCase, data, f"fig{fig}")


def test_exposure_matrix_is_the_solvers_advance() -> None:
    model = SphereConduction(Sphere(2.7e-3, 0.186, 1050.0, 1465.0), shells=12)
    rng = np.random.default_rng(1)
    start = 40.0 + 50.0 * rng.random(12)
    expected, _ = model.advance(start, 80.0, 30.0, 3.7)
    got = apply(exposure_matrix(model, 80.0, 3.7), start, 30.0)
    # Same steps, same arithmetic up to association: round-off of ~100 products of O(1) terms.
    assert np.max(np.abs(got - expected)) < 1e-10


@pytest.mark.parametrize("fig", [3, 4, 5, 6, 7, 8])
def test_energy_closes_for_every_experiment(fig: int) -> None:
    result = solve_curtain(_case(fig))
    # Each element's heat is the particles' enthalpy change and the gas takes exactly it.
    assert abs(result.energy_residual) < 1e-9
    assert result.heat_to_solids_w > 0  # hot gas heats cold sand
    case = _case(fig)
    assert case.solids.inlet_temperature_C < result.solids_outlet_C < case.gas.inlet_temperature_C


def test_no_gas_flow_no_heat() -> None:
    result = solve_curtain(_case(3, gas={"velocity": 0.0}, numerics={"rows": 40}))
    assert result.heat_to_solids_w == 0.0
    assert result.solids_outlet_C == pytest.approx(15.8, abs=1e-12)


def test_auto_rows_need_gas_flow() -> None:
    with pytest.raises(CaseError, match="numerics.rows"):
        _case(3, gas={"velocity": 0.0})


def test_infinite_h_lumped_particles_reach_the_mixing_temperature_in_one_row() -> None:
    # Very conductive particles (Bi -> 0) with an infinite film: in the first element the
    # particles and the gas leave at one temperature, the mixing temperature of the mean-gas
    # balance: C_p (T - T_si) = 2 C_g (T_gi - T).
    case = _case(3, solids={"conductivity": 1.0e4}, numerics={"rows": 50, "columns": 1})
    result = solve_curtain(case, h_w_m2k=math.inf)
    c_p = result.solids_capacity_rate_w_k
    c_g = result.gas_capacity_rate_w_k / result.rows
    t_si, t_gi = case.solids.inlet_temperature_C, case.gas.inlet_temperature_C
    mixing = (c_p * t_si + 2 * c_g * t_gi) / (c_p + 2 * c_g)
    # Conduction time of the sand grain R^2/(pi^2 alpha) ~ 1e-6 s at k = 1e4, against 12 ms
    # per row: the particle is uniform to round-off.
    assert result.solids_profile_C[0] == pytest.approx(mixing, abs=1e-6)
    assert abs(result.energy_residual) < 1e-9


def test_one_row_at_the_lumped_rate() -> None:
    # One element, conductive particles (Bi -> 0): they follow the lumped solution
    # exp(-6 h t / (rho c d)) towards the gas temperature they see, the mean of the element's
    # gas inlet and outlet.
    case = _case(3, solids={"conductivity": 1.0e4}, numerics={"rows": 1, "columns": 1},
                 gas={"velocity": 50.0})
    h = 300.0
    result = solve_curtain(case, h_w_m2k=h)
    s = case.solids
    t = case.geometry.height / s.fall_velocity
    seen = 0.5 * (case.gas.inlet_temperature_C + result.gas_outlet_C)
    lumped = seen + (s.inlet_temperature_C - seen) * math.exp(
        -6 * h * t / (s.density * s.heat_capacity * s.diameter))
    # k = 1e4 leaves Bi = 3e-6, whose interior resistance slows the rate by that share:
    # ~1e-5 K on the 22 K change; the Crank-Nicolson time error is far smaller.
    assert result.solids_outlet_C == pytest.approx(lumped, abs=2e-5)


def test_columns_converge() -> None:
    coarse = solve_curtain(_case(3, numerics={"columns": 10}))
    fine = solve_curtain(_case(3, numerics={"columns": 20}))
    # The mean-gas scheme is second order: 10 -> 20 columns moves the outlets by < 0.05 K.
    assert abs(coarse.solids_outlet_C - fine.solids_outlet_C) < 0.05
    assert abs(coarse.gas_outlet_C - fine.gas_outlet_C) < 0.05


def test_overloaded_curtain_is_rejected() -> None:
    with pytest.raises(CaseError, match="solids.mass_flow"):
        _case(3, solids={"mass_flow": 50.0})
