"""`run.conduction = false` really switches contact conduction off (regression).

In LIGGGHTS 3.8 `fix heat/gran` is registered as another name for heat/gran/conduction, so a
deck that switched to it still conducted: a conduction-off run gave exactly the conduction-on
temperatures. Then the deck kept heat/gran/conduction with a zero conductivity, which still
visited every contact and integrated every temperature at every step (a quarter to a third of
a paper-scale loop). Now a conduction-off deck has no heat fix at all, only the per-atom
temperature, and the coupling loop integrates it (``heat_capacity`` in its spec). The
real-solver halves: tests/solver/test_liggghts_drum.py::
test_conduction_off_keeps_the_spread_and_fails_the_guard and tests/solver/test_air_coupling.py::
test_conduction_off_loop_integrates_temperatures_across_a_resume.
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


def test_conduction_on_is_one_heat_fix_with_the_paper_conductivity(smoke_dict: dict) -> None:
    deck = _deck(smoke_dict, True)
    heat = [ln for ln in deck.splitlines() if re.match(r"fix \S+ all heat/gran", ln)]
    assert heat == ["fix heat all heat/gran/conduction initial_temperature 90.0 contact_area overlap "
                    "area_correction yes"]
    k = liggghts_conductivity(smoke_dict["particles"]["conductivity"])
    assert _conductivities(deck) == pytest.approx([k, k], rel=1e-8)


def test_conduction_off_has_no_heat_fix_and_the_loop_integrates(smoke_dict: dict) -> None:
    from drumflow.air.source import FieldSource
    from drumflow.coupling.spec import build_coupling

    deck = _deck(smoke_dict, False)
    assert not re.search(r"^fix \S+ all heat/gran", deck, flags=re.M)
    # The temperatures stay, in a per-atom property of the same ID heat/gran/conduction gives
    # its own (snapshots read f_Temp[0]; a restart of either kind fills it).
    assert re.search(r"^fix Temp all property/atom Temp scalar yes no no 90\.?0*$", deck, flags=re.M)
    assert "f_Temp[0]" in deck
    case = case_from_dict(smoke_dict)
    source = FieldSource(field={"kind": "uniform", "velocity": [0.0, 0.0, 1.0]}, key="u", omega=0.0)
    off = build_coupling(case, source, 1e-5, 100)
    assert off.heat_capacity == smoke_dict["particles"]["heat_capacity"]
    assert ":heat=loop" in off.key
    smoke_dict["run"]["conduction"] = True
    on = build_coupling(case_from_dict(smoke_dict), source, 1e-5, 100)
    assert on.heat_capacity is None and ":heat=loop" not in on.key


def test_loop_heat_driver_file_aligns_updates_on_the_thermo_step(smoke_dict: dict) -> None:
    """One owner of the loop-heat keys: the spec writes heat capacity and alignment together,
    and refuses a loop-heat driver without the thermo step (updates would straddle rows)."""
    from drumflow.air.source import FieldSource
    from drumflow.coupling.spec import build_coupling, loop_heat_options

    smoke_dict["run"]["conduction"] = False
    case = case_from_dict(smoke_dict)
    source = FieldSource(field={"kind": "uniform", "velocity": [0.0, 0.0, 1.0]}, key="u", omega=0.0)
    off = build_coupling(case, source, 1e-5, 100)
    driver = off.driver_file("d", "l", 1000, 1e-5, [], thermo_every=200)
    assert driver["align_every"] == 200
    assert driver["heat_capacity"] == smoke_dict["particles"]["heat_capacity"]
    with pytest.raises(ValueError, match="thermo_every"):
        off.driver_file("d", "l", 1000, 1e-5, [])
    with pytest.raises(ValueError, match="heat_capacity"):
        loop_heat_options(0.0, 200)
    smoke_dict["run"]["conduction"] = True
    on = build_coupling(case_from_dict(smoke_dict), source, 1e-5, 100)
    assert "align_every" not in on.driver_file("d", "l", 1000, 1e-5, [])
