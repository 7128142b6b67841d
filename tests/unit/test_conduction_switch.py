"""`run.conduction = false` really switches contact conduction off (regression).

In LIGGGHTS 3.8 `fix heat/gran` is registered as another name for heat/gran/conduction, so a
deck that switched to it still conducted: a conduction-off run gave exactly the conduction-on
temperatures. The deck now keeps heat/gran/conduction (it holds the temperatures and adds the
air's heat source) with a zero conductivity, for which LIGGGHTS sets every contact's
conductance to 0. The real-solver half of this regression is
tests/solver/test_liggghts_drum.py::test_conduction_off_keeps_the_spread_and_fails_the_guard.
"""

from __future__ import annotations

import re

import pytest

from drumflow.case import case_from_dict
from drumflow.dem.conduction import liggghts_conductivity
from drumflow.dem.deck import DeckFiles, deck_context, plan_steps, render_deck
from drumflow.dem.timestep import choose_time_step


def _deck(smoke_dict: dict, conduction: bool) -> str:
    smoke_dict["run"]["conduction"] = conduction
    case = case_from_dict(smoke_dict)
    return render_deck(deck_context(case, plan_steps(case, choose_time_step(case)), DeckFiles()))


def _conductivities(deck: str) -> list[float]:
    line = re.search(r"^fix m6 all property/global thermalConductivity peratomtype (.*)$", deck, re.M)
    assert line is not None
    return [float(v) for v in line.group(1).split()]


@pytest.mark.parametrize("conduction", [True, False])
def test_one_heat_fix_whose_conductivity_follows_the_switch(smoke_dict: dict, conduction: bool) -> None:
    deck = _deck(smoke_dict, conduction)
    heat = [ln for ln in deck.splitlines() if re.match(r"fix \S+ all heat/gran", ln)]
    assert heat == ["fix heat all heat/gran/conduction initial_temperature 90.0 contact_area overlap "
                    "area_correction yes"]
    k = liggghts_conductivity(smoke_dict["particles"]["conductivity"]) if conduction else 0.0
    assert _conductivities(deck) == pytest.approx([k, k], rel=1e-8)
