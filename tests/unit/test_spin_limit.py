"""The spin limit of the DEM step (drumflow.dem.timestep): the stability of velocity Verlet with
a half-step dashpot, and the rotational mode of a bed contact. LIGGGHTS itself:
tests/solver/test_spin_liggghts.py; the shipped spin studies' numbers (no code):
tests/shipped/test_shipped_spin_studies.py."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from drumflow.case import Case, load_case
from drumflow.dem.timestep import (
    SPIN_LIMIT_FRACTION,
    bed_contact_overlap,
    bed_spin_mode,
    choose_time_step,
    spin_mode,
    verlet_damping_limit,
)

ROOT = Path(__file__).resolve().parents[2]


def _spectral_radius(omega_dt: float, zeta: float) -> float:
    """Velocity Verlet on x'' = -w^2 x - 2 zeta w v, the damping taken at the half-step
    velocity (as LAMMPS computes forces between the two half kicks); state (x, v, a), dt = 1."""

    def step(state: np.ndarray) -> np.ndarray:
        x, v, a = state
        v_half = v + 0.5 * a
        x_new = x + v_half
        a_new = -omega_dt**2 * x_new - 2.0 * zeta * omega_dt * v_half
        return np.array([x_new, v_half + 0.5 * a_new, a_new])

    matrix = np.column_stack([step(e) for e in np.eye(3)])
    return float(np.abs(np.linalg.eigvals(matrix)).max())


@pytest.mark.parametrize("zeta", [0.0, 0.3, 0.8, 1.8, 4.0])
def test_the_limit_is_where_the_scheme_stops_damping(zeta: float) -> None:
    limit = verlet_damping_limit(zeta)
    assert _spectral_radius(0.99 * limit, zeta) <= 1.0 + 1e-9
    assert _spectral_radius(1.01 * limit, zeta) > 1.0 + 1e-6


def test_the_undamped_and_overdamped_ends() -> None:
    assert verlet_damping_limit(0.0) == pytest.approx(2.0)
    # Heavily damped: the explicit dashpot's own limit, 1 / zeta (dt < 2 m / c).
    assert verlet_damping_limit(50.0) == pytest.approx(1.0 / 50.0, rel=1e-3)
    with pytest.raises(ValueError, match="damping_ratio"):
        verlet_damping_limit(-0.1)


def test_one_contact_mode_by_hand() -> None:
    """Two 8 mm, 517 kPa spheres at 0.19 r, e = 0.1205: k_t = 8 G* sqrt(R* delta) = 567 N/m,
    the dashpot 0.29 N s/m, lever arm r - delta/2: the numbers the solver test bisected
    (LIGGGHTS' limit between 3.5 and 3.6e-4 s)."""
    r, delta = 0.004, 0.19 * 0.004
    mode = spin_mode(r, 1050.0, 517e3, 0.45, 0.1205, delta, contacts=1)
    mass = 1050.0 * 4.0 / 3.0 * math.pi * r**3
    g_eff = 517e3 / (2 * 1.45) / (2 * 1.55)
    k_t = 8 * g_eff * math.sqrt(0.5 * r * delta)
    assert k_t == pytest.approx(567.2, rel=1e-3)
    arm = r - 0.5 * delta
    assert mode.frequency == pytest.approx(math.sqrt(2 * k_t * arm**2 / (0.4 * mass * r**2)))
    assert 3.5e-4 < mode.time_step_limit < 3.6e-4
    # More contacts: a stiffer, more damped mode and a shorter limit.
    bed = spin_mode(r, 1050.0, 517e3, 0.45, 0.1205, delta)
    assert bed.frequency == pytest.approx(math.sqrt(6) * mode.frequency)
    assert bed.time_step_limit < 0.25 * mode.time_step_limit
    with pytest.raises(ValueError, match="overlap"):
        spin_mode(r, 1050.0, 517e3, 0.45, 0.1205, 0.0)
    with pytest.raises(ValueError, match="restitution"):
        spin_mode(r, 1050.0, 517e3, 0.45, 1.0, delta)


def _contact_step(case: Case) -> Case:
    """The case with ``run.time_step = "contact"``: the step before "auto" knew the spin limit."""
    data = case.model_dump(mode="json")
    data["run"]["time_step"] = "contact"
    return Case.model_validate(data)


def test_the_paper_beds_overlap_and_the_steps() -> None:
    """The bed's weight gives model one's contacts about a fifth of a radius (the stability
    monitor's reading in the full run); the contact step (10 per Hertz contact at the free-fall
    speed, "auto" until the spin limit entered it) is then 1.6 times the bed's spin limit, half
    of it is below, and "auto" is SPIN_LIMIT_FRACTION of the limit at its own step."""
    from drumflow.dem.restitution import calibrate_case

    case = load_case(ROOT / "cases" / "paper_model_one.toml")
    p = case.particles
    overlap = bed_contact_overlap(case)
    assert 0.15 < overlap / p.radius < 0.25
    contact = choose_time_step(_contact_step(case))
    assert contact.bound == "contact" and contact.steps_per_contact == pytest.approx(10.0)
    for factor, low, high in ((1.0, 1.5, 1.7), (0.5, 0.75, 0.9)):
        dt = factor * contact.time_step
        e = calibrate_case(case, dt)["particle_particle"].liggghts_value
        limit = spin_mode(p.radius, p.density, p.youngs_modulus, p.poisson_ratio, e, overlap).time_step_limit
        assert low < dt / limit < high
    auto = choose_time_step(case)
    assert auto.mode == "auto" and auto.bound == "spin"
    limit = bed_spin_mode(case, auto.time_step).time_step_limit
    assert auto.time_step == pytest.approx(SPIN_LIMIT_FRACTION * limit, rel=1e-6)
    assert auto.spin_time_step_limit == pytest.approx(auto.time_step / SPIN_LIMIT_FRACTION, rel=1e-6)
    # Still every contact resolved, and about half the old step (the cost of the fix).
    assert auto.steps_per_contact > 20.0 and 0.45 < auto.time_step / contact.time_step < 0.55


@pytest.mark.parametrize("name", ["paper_model_two.toml", "smoke.toml"])
def test_auto_stays_below_the_spin_limit_and_contact_does_not(name: str) -> None:
    case = load_case(ROOT / "cases" / name)
    auto, contact = choose_time_step(case), choose_time_step(_contact_step(case))
    assert auto.spin_time_step_limit is not None and contact.spin_time_step_limit is not None
    assert auto.time_step <= SPIN_LIMIT_FRACTION * auto.spin_time_step_limit * (1 + 1e-9)
    assert contact.time_step > contact.spin_time_step_limit  # the shipped cases need the cap
    assert contact.mode == "contact" and auto.time_step < contact.time_step


@pytest.mark.parametrize("name", ["paper_model_one.toml", "paper_model_two.toml", "smoke.toml"])
def test_without_the_dashpot_auto_is_the_contact_step_again(name: str) -> None:
    """``contacts.tangential_damping = false``: the bed's spin mode is undamped, its limit the
    spring's ``omega dt = 2`` (:func:`verlet_damping_limit` at zeta 0), more than twice the
    dashpot's, and above the contact step in the shipped cases, so "auto" is the contact step;
    the deck says ``tangential_damping off`` on the pair style (and not on the walls)."""
    from drumflow.dem.deck import deck_context, plan_steps, render_deck

    case = load_case(ROOT / "cases" / name)
    data = case.model_dump(mode="json")
    data["contacts"]["tangential_damping"] = False
    free = Case.model_validate(data)
    choice, contact = choose_time_step(free), choose_time_step(_contact_step(case))
    mode = bed_spin_mode(free, choice.time_step)
    assert mode.damping_ratio == 0.0
    assert choice.spin_time_step_limit == pytest.approx(2.0 / mode.frequency)
    assert choice.spin_time_step_limit > 2.0 * bed_spin_mode(case, choice.time_step).time_step_limit
    assert choice.bound in ("contact", "rayleigh") and choice.time_step == pytest.approx(contact.time_step)
    assert free.hash() != case.hash()
    deck = render_deck(deck_context(free, plan_steps(free, choice)))
    lines = [line for line in deck.splitlines()
             if "tangential_damping off" in line and not line.startswith("#")]
    assert len(lines) == 1 and lines[0].startswith("pair_style"), lines
    damped = render_deck(deck_context(case, plan_steps(case, choose_time_step(case))))
    assert "tangential_damping off" not in damped


def test_a_soft_shallow_bed_keeps_the_contact_step() -> None:
    """Where the spin limit is not the tighter bound, "auto" is the contact step: the cap only
    ever shortens the step. A stiff particle barely overlaps, so its spin mode is slow enough."""
    case = load_case(ROOT / "cases" / "smoke.toml")
    data = case.model_dump(mode="json")
    data["particles"]["youngs_modulus"] = 5.0e9
    data["run"]["rayleigh_fraction"] = 0.05
    stiff = Case.model_validate(data)
    auto = choose_time_step(stiff)
    assert auto.bound == "rayleigh"
    assert auto.time_step == pytest.approx(choose_time_step(_contact_step(stiff)).time_step)
