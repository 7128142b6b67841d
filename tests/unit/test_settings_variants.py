"""The settings study's deck edits (drumflow.bench.settings_variants.apply_variant) that need no solver;
tests/solver/test_profile.py runs every variant through LIGGGHTS."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from drumflow.bench.settings_variants import VARIANTS, apply_variant
from drumflow.case import Case, load_case
from drumflow.dem.collision_speed import typical_impact_velocity
from drumflow.dem.restitution import calibrate_case, mean_realised_restitution, pair_properties
from drumflow.dem.stage import plan_run
from drumflow.errors import SettingsStudyError

ROOT = Path(__file__).resolve().parents[2]


def _deck(time_step: float, e_pp: float, e_pw: float) -> str:
    return (f"timestep        {time_step:.12g}\n"
            f"fix m3 all property/global coefficientRestitution peratomtypepair 2 {e_pp:.6g} {e_pw:.6g} "
            f"{e_pw:.6g} {e_pw:.6g}\n")


def _coefficients(deck: str) -> tuple[float, float]:
    m = re.search(r"coefficientRestitution peratomtypepair 2 (\S+) (\S+) \S+ \S+", deck)
    assert m is not None
    return float(m.group(1)), float(m.group(2))


@pytest.mark.parametrize("name", ["half_step", "conservative"])
def test_a_time_step_variant_gets_the_restitution_a_run_at_its_step_has(name: str) -> None:
    """Regression: the half-step variants kept the baseline's calibrated coefficients, which at
    20 steps per contact realise e_pp 0.111 instead of the case's 0.1 (paper model one), so the
    'conservative reference' was a more elastic bed than a run at that step."""
    case = load_case(ROOT / "cases" / "paper_model_one.toml")
    _, plan = plan_run(case)
    base = calibrate_case(case, plan.time_step)
    deck = _deck(plan.time_step, base["particle_particle"].liggghts_value,
                 base["particle_wall"].liggghts_value)
    variant = next(v for v in VARIANTS if v.name == name)
    if variant.moving_shell:
        deck += ("fix shell all mesh/surface file shell.stl type 2 surface_ang_vel origin 0 0 0 "
                 "axis 0 0 1 omega 0.5236\nfix walls all wall/gran model hertz mesh n_meshes 1 "
                 "meshes shell\n")
    e_pp, e_pw = _coefficients(apply_variant(deck, variant, 2, case))
    half = 0.5 * plan.time_step
    speed = typical_impact_velocity(case)
    for given, name_, wall in ((e_pp, "particle_particle", False), (e_pw, "particle_wall", True)):
        target = getattr(case.contacts, name_).restitution
        m, r, e = pair_properties(case, wall)
        # What LIGGGHTS' discrete contact realises at the variant's step is the case's value
        # (to the 6 digits the deck carries), and not what the baseline's coefficient gives.
        assert mean_realised_restitution(given, half, m, r, e, speed) == pytest.approx(target, rel=1e-4)
        stale = base[name_].liggghts_value
        assert abs(mean_realised_restitution(stale, half, m, r, e, speed) - target) > 0.005 * target


def test_a_variant_with_the_baseline_step_keeps_the_coefficients() -> None:
    case = load_case(ROOT / "cases" / "paper_model_one.toml")
    deck = _deck(1.2e-4, 0.1205, 0.313)
    skin = next(v for v in VARIANTS if v.name == "skin_x2")
    edited = apply_variant(deck + "neighbor        0.004 bin\n", skin, 2, case)
    assert _coefficients(edited) == (0.1205, 0.313)


def test_the_calibration_is_exact_at_the_typical_speed_and_too_elastic_below_it() -> None:
    """The table in docs/benchmarks.md (model one, "The calibration speed"): calibrated at half
    the free-fall speed, the contact step (10 steps per free-fall contact; "auto" before the
    spin limit) realises e_pp = 0.1 there but 0.1105 at the bed's median impact (0.14 m/s),
    half of it 0.1049. If the calibration speed changes, this and docs/benchmarks.md change
    together."""
    data = load_case(ROOT / "cases" / "paper_model_one.toml").model_dump(mode="json")
    data["run"]["time_step"] = "contact"
    case = Case.model_validate(data)
    _, plan = plan_run(case)
    m, r, e = pair_properties(case, False)
    speed = typical_impact_velocity(case)
    assert speed == pytest.approx(0.5 * (2 * 9.81 * case.drum.diameter) ** 0.5, rel=1e-3)
    for factor, at_median in ((1.0, 0.1105), (0.5, 0.1049)):
        dt = factor * plan.time_step
        given = calibrate_case(case, dt)["particle_particle"].liggghts_value
        assert mean_realised_restitution(given, dt, m, r, e, speed) == pytest.approx(0.1, rel=1e-4)
        assert mean_realised_restitution(given, dt, m, r, e, 0.14) == pytest.approx(at_median, abs=5e-4)


def test_a_bed_restitution_variant_is_exact_at_the_bed_speed() -> None:
    case = load_case(ROOT / "cases" / "paper_model_one.toml")
    _, plan = plan_run(case)
    base = calibrate_case(case, plan.time_step)
    deck = _deck(plan.time_step, base["particle_particle"].liggghts_value,
                 base["particle_wall"].liggghts_value)
    m, r, e = pair_properties(case, False)
    for name, dt in (("bed_restitution", plan.time_step),
                     ("half_step_bed_restitution", 0.5 * plan.time_step)):
        variant = next(v for v in VARIANTS if v.name == name)
        with pytest.raises(SettingsStudyError, match="no measured impact speed"):
            apply_variant(deck, variant, 2, case)
        e_pp, _ = _coefficients(apply_variant(deck, variant, 2, case, bed_speed=0.14))
        assert mean_realised_restitution(e_pp, dt, m, r, e, 0.14) == pytest.approx(0.1, rel=1e-4)


def test_the_tangential_damping_diagnostic_edits_the_pair_style_only() -> None:
    case = load_case(ROOT / "cases" / "paper_model_one.toml")
    walls = ("fix walls all wall/gran model hertz tangential history rolling_friction cdt mesh "
             "n_meshes 1 meshes shell\n")
    deck = (_deck(1.2e-4, 0.1205, 0.313)
            + "pair_style      gran model hertz tangential history rolling_friction cdt\n" + walls)
    variant = next(v for v in VARIANTS if v.name == "no_tangential_damping")
    edited = apply_variant(deck, variant, 2, case)
    assert ("pair_style      gran model hertz tangential history rolling_friction cdt "
            "tangential_damping off\n") in edited
    assert walls in edited and _coefficients(edited) == (0.1205, 0.313)
    with pytest.raises(SettingsStudyError, match="pair_style"):
        apply_variant(_deck(1.2e-4, 0.1205, 0.313), variant, 2, case)


def test_a_rendered_baseline_deck_is_the_parcels_at_the_runs_time_step(tmp_path: Path) -> None:
    """Regression: the bench rendered a coarse-grained run's deck from the particles' case, so
    model one's parcels of 2 ran at half the run's time step (5.78e-5 s for 1.156e-4 s) and the
    loop gave them twice the DEM's time of heat per update. The deck is the DEM's case (the
    parcels: their time step, their snapshot stride) at the step the loop's input names."""
    from drumflow.bench.settings import baseline_deck
    from drumflow.case import case_to_toml
    from drumflow.geometry.stage import build_geometry
    from drumflow.rundir import RunDir
    from drumflow.verify.scenes import tiny_drum

    case = tiny_drum(air__model="uniform", air__mass_flow=0.1, particles__coarse_grain=1.5)
    run = RunDir(tmp_path / "run")
    run.bind_case(case.canonical_json(), case.hash(), case_to_toml(case))
    build_geometry(case.dem_case(), run)
    choice, plan = plan_run(case.dem_case())
    assert plan_run(case)[0].time_step < 0.7 * choice.time_step  # the particles' step is shorter
    driver = {"field": {"kind": "uniform", "velocity": [0.0, 0.0, -1.0]}, "interval": 10,
              "air_temperature_C": 30.0, "air_pressure_kPa": 101.3, "omega": 1.0,
              "coarse_grain": 1.5, "time_step": choice.time_step}
    deck, source = baseline_deck(run, 100, 1, tmp_path / "scratch", driver)
    steps = [float(m) for m in re.findall(r"^timestep\s+(\S+)\s*$", deck, flags=re.M)]
    assert steps == [pytest.approx(choice.time_step, rel=1e-9)]
    assert re.search(rf"^dump\s+snap\s+all\s+custom\s+{plan.snapshot_every}\s", deck, flags=re.M)
    assert "the run's time step" in source
