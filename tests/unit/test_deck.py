"""Deck rendering: the physics values land in the LIGGGHTS commands."""

from __future__ import annotations

import math

import jinja2
import pytest

from drumflow.case import case_from_dict
from drumflow.dem.deck import (
    DeckFiles,
    deck_context,
    gravity_vector,
    plan_steps,
    render_deck,
)
from drumflow.dem.timestep import choose_time_step


def _deck(d: dict, **kw) -> str:
    case = case_from_dict(d)
    plan = plan_steps(case, choose_time_step(case))
    return render_deck(deck_context(case, plan, DeckFiles(), **kw))


def test_deck_has_the_models(smoke_dict: dict) -> None:
    deck = _deck(smoke_dict)
    assert "pair_style      gran model hertz tangential history rolling_friction cdt" in deck
    assert "heat/gran/conduction initial_temperature 90" in deck
    assert "fix spin all move/mesh mesh shell rotate origin 0. 0. 0. axis 0. 0. 1. period 4" in deck
    assert "coefficientFriction peratomtypepair 2 0.4 0.2 0.2 0.2" in deck
    # The corrected coefficients (drumflow.dem.restitution): above the case's 0.1 and 0.3.
    e = deck.split("coefficientRestitution peratomtypepair 2 ")[1].split("\n")[0].split()
    assert 0.1 < float(e[0]) < 0.15 and 0.3 < float(e[1]) < 0.33 and e[1] == e[2] == e[3]
    assert "thermo_modify   lost warn" in deck
    assert "soft_particles" not in deck  # 5 MPa is not soft
    assert "read_data       particles.data" in deck
    assert "{{" not in deck and "{%" not in deck


def test_restitution_passed_through_when_correction_is_off(smoke_dict: dict) -> None:
    smoke_dict["run"]["restitution_correction"] = False
    assert "coefficientRestitution peratomtypepair 2 0.1 0.3 0.3 0.3" in _deck(smoke_dict)


def test_static_shell_deck_moves_only_the_lifters(smoke_dict: dict) -> None:
    case = case_from_dict(smoke_dict)
    plan = plan_steps(case, choose_time_step(case))
    files = DeckFiles(stl_file="../geometry/shell.stl", lifters_stl_file="../geometry/lifters.stl",
                      static_shell=True)
    deck = render_deck(deck_context(case, plan, files))
    omega = 15.0 * 2.0 * math.pi / 60.0
    assert f"shell.stl type 2 surface_ang_vel origin 0. 0. 0. axis 0. 0. 1. omega {omega:.9g}" in deck
    assert "meshes shell lifters" in deck
    assert "move/mesh mesh lifters rotate" in deck and "move/mesh mesh shell" not in deck


def test_soft_particles_and_resume(smoke_dict: dict) -> None:
    smoke_dict["particles"]["youngs_modulus"] = 517e3
    deck = _deck(smoke_dict, resume_from="restart/drum.100.restart")
    assert "soft_particles  yes" in deck
    assert "read_restart    restart/drum.100.restart" in deck
    assert "read_data" not in deck


def test_gravity_tilt() -> None:
    g = gravity_vector(1.5)
    assert g[2] == pytest.approx(math.sin(math.radians(1.5)))
    assert math.hypot(*g) == pytest.approx(1.0)


def test_strict_undefined(smoke_dict: dict) -> None:
    case = case_from_dict(smoke_dict)
    plan = plan_steps(case, choose_time_step(case))
    ctx = deck_context(case, plan)
    del ctx["period"]
    with pytest.raises(jinja2.UndefinedError):
        render_deck(ctx)


def test_step_plan_rounds_intervals(smoke_dict: dict) -> None:
    """The output step is a whole number of equal thermo intervals of at most
    CHECK_EVERY_STEPS: the nearest whole number of steps, rounded up by fewer steps than it has
    parts (the smoke case's 571 steps of 0.02 s, a prime, become 6 x 96: 0.9 % longer)."""
    from drumflow.dem.stability import CHECK_EVERY_STEPS

    case = case_from_dict(smoke_dict)
    choice = choose_time_step(case)
    plan = plan_steps(case, choice)
    assert plan.steps * plan.time_step >= case.run.time
    raw = round(case.run.dump_interval / plan.time_step)
    parts = plan.dump_every // plan.thermo_every
    assert plan.dump_every == parts * plan.thermo_every and plan.thermo_every <= CHECK_EVERY_STEPS
    assert raw <= plan.dump_every < raw + parts and parts == math.ceil(raw / CHECK_EVERY_STEPS)


@pytest.mark.parametrize("name", ["paper_model_one.toml", "paper_model_two.toml"])
def test_the_paper_cases_output_at_the_papers_time_step(name: str) -> None:
    """Table 5's 0.005 s and 0.01 s, to half a DEM step: the methodology's time steps."""
    from support.solvers import CASES

    from drumflow.case import load_case

    case = load_case(CASES / name)
    plan = plan_steps(case, choose_time_step(case))
    assert abs(plan.dump_interval - case.run.dump_interval) <= 0.5 * plan.time_step


@pytest.mark.parametrize(("case_file", "ranks", "grid"), [
    # Paper model two (1 m of 20 mm particles, 25 diameters per rank at 2 ranks): along the axis,
    # where the settings study measured 1.61 times the rate of the split across x.
    ("paper_model_two.toml", 2, "1 1 2"),
    ("paper_model_two.toml", 4, "1 1 4"),
    # Paper model one (6.25 diameters per rank at 2 ranks): along the axis, 1.30 times the
    # rate across x from its cascading 1.5 s restart; at 4 ranks (3.1 diameters) across.
    ("paper_model_one.toml", 2, "1 1 2"),
    ("paper_model_one.toml", 4, "4 1 1"),
    # The smoke drum (5 diameters per rank at 2 ranks): across the drum, as before.
    ("smoke.toml", 2, "2 1 1"),
    ("smoke.toml", 1, "1 1 1"),
])
def test_processor_grid_along_the_axis_only_for_thick_sections(case_file: str, ranks: int, grid: str) -> None:
    from support.solvers import CASES

    from drumflow.case import load_case
    from drumflow.dem.deck import processors_grid

    assert processors_grid(load_case(CASES / case_file), ranks) == grid
