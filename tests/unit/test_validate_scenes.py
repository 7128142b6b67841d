"""The validation scenes (drumflow.validate): registry, measured data, the profile along the
normal line (on a field whose answer is known), the comparison, the scene's cases; and the
case's drum.ends option (hash rule, refused combinations, deck)."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from drumflow.case import case_from_dict
from drumflow.errors import CaseError
from drumflow.validate import SCENES, ValidationDataError, scene
from drumflow.validate.rolling_drum import (
    BEAD_DIAMETER,
    DRUM_RADIUS,
    FULL_DRUM_BEADS,
    RPM,
    SETUP,
    SURFACE_ANGLE_DEG,
    SURFACE_POSITION,
    Profile,
    compare,
    line_positions,
    load_measured,
    profile_along_normal,
    rolling_drum_case,
    surface_angle,
    surface_frame,
    zero_crossing,
)
from drumflow.verify.scenes import tiny_drum, tiny_drum_dict

OMEGA = 2 * math.pi * RPM / 60


def test_registry_names_source_measures_and_setup() -> None:
    sc = scene("rolling_drum")
    assert SCENES["rolling_drum"] is sc
    assert "Alizadeh" in sc.source and "AIChE J. 59 (2013)" in sc.source and "lethe" in sc.source.lower()
    assert any("changes sign" in m for m in sc.measures)
    assert sc.scales[0] == "small" and "full" in sc.scales
    # Every set-up choice names where it comes from.
    assert all(c.item and c.value and c.source for c in SETUP)


def test_unknown_scene_is_refused_naming_the_allowed() -> None:
    with pytest.raises(ValidationDataError, match="'nope'.*allowed: particle_curtain, rolling_drum"):
        scene("nope")


def test_measured_points_are_in_metres_and_metres_per_second() -> None:
    m = load_measured()
    assert len(m.position) == 36
    # Positions on the normal line between the shell (-0.12 m) and about the free surface
    # (-0.03 m; one digitised point lies 2 mm above it): metres, not millimetres.
    assert m.position.min() > -DRUM_RADIUS and m.position.max() < -0.025
    # Down-slope positive: fast at the surface, the shell's return flow (-omega r) at the wall.
    bottom = np.argmin(m.position)
    assert m.velocity.max() == pytest.approx(0.348, abs=1e-3)
    assert m.position[np.argmax(m.velocity)] == pytest.approx(-0.0303, abs=1e-4)
    assert m.velocity[bottom] == pytest.approx(OMEGA * m.position[bottom], rel=0.05)
    assert np.abs(m.velocity).max() < 0.5
    # The flowing layer: the velocity changes sign about 0.0594 m from the axis.
    assert zero_crossing(m) == pytest.approx(-0.0594, abs=5e-4)


def test_a_broken_data_file_is_refused(tmp_path: Path) -> None:
    bad = tmp_path / "bad.csv"
    bad.write_text("velocity,position\n1,2\n")
    with pytest.raises(ValidationDataError, match="header"):
        load_measured(bad)
    with pytest.raises(ValidationDataError, match="not found"):
        load_measured(tmp_path / "missing.csv")


def _solid_body_bed(omega: float, n: int = 40_000, seed: int = 3) -> tuple[np.ndarray, ...]:
    """Particles filling the drum below the free surface line, turning as a solid body
    counter-clockwise about +z at ``omega``: v = omega z x r."""
    rng = np.random.default_rng(seed)
    r = DRUM_RADIUS * np.sqrt(rng.random(n))
    phi = 2 * math.pi * rng.random(n)
    x, y = r * np.cos(phi), r * np.sin(phi)
    _, normal = surface_frame(SURFACE_ANGLE_DEG)
    below = x * normal[0] + y * normal[1] < SURFACE_POSITION
    x, y = x[below], y[below]
    return x, y, -omega * y, omega * x


def test_profile_of_a_solid_body_rotation_is_omega_r() -> None:
    """Analytic answer: a point s on the normal line moves at omega s down the slope."""
    x, y, vx, vy = _solid_body_bed(OMEGA)
    s = line_positions()
    u, count = profile_along_normal(x, y, vx, vy, s)
    inside = count > 0
    assert inside.mean() > 0.95
    # Averaging over a disk of one diameter around each point is exact for a linear field
    # (the disk's mean equals its centre's value) up to the sampling.
    assert np.allclose(u[inside], OMEGA * s[inside], rtol=0.02, atol=2e-3)


def test_profile_tells_a_ten_percent_faster_rotation_apart() -> None:
    x, y, vx, vy = _solid_body_bed(1.1 * OMEGA)
    s = line_positions()
    u, count = profile_along_normal(x, y, vx, vy, s)
    inside = count > 0
    deep = inside & (s < -0.06)
    # Against the true omega the profile is off by 10 %: a 2 % check must fail.
    assert not np.allclose(u[deep], OMEGA * s[deep], rtol=0.02, atol=2e-3)
    assert np.median(u[deep] / (OMEGA * s[deep])) == pytest.approx(1.1, abs=0.01)


def test_nan_particles_are_left_out_and_an_empty_zone_is_nan() -> None:
    u, count = profile_along_normal([np.nan, 0.5], [0.0, 0.5], [1.0, 1.0], [0.0, 0.0], [-0.05])
    assert count[0] == 0 and np.isnan(u[0])


def test_comparison_of_the_measurement_with_itself_is_exact() -> None:
    m = load_measured()
    result = compare(m, m)
    for name, entry in result.items():
        assert entry["error"] == pytest.approx(0.0, abs=1e-12), name
        assert entry["within_band"]
    depth = result["zero_crossing_position_m"]["depth_below_surface_m"]["measured"]
    assert depth == pytest.approx(0.0294, abs=5e-4)


def test_comparison_sees_a_solid_body_profile_as_far_off() -> None:
    """A bed that only turns (no flowing layer) has no positive surface velocity to speak of."""
    m = load_measured()
    s = line_positions()
    result = compare(Profile(s, OMEGA * s), m)
    assert not result["surface_velocity_m_s"]["within_band"]
    assert np.isnan(result["zero_crossing_position_m"]["simulated"])
    assert result["near_wall_velocity_m_s"]["within_band"]  # the wall does move at omega r


def test_zero_crossing_of_a_linear_profile() -> None:
    s = np.linspace(-0.12, -0.03, 50)
    assert zero_crossing(Profile(s, 10.0 * (s + 0.06))) == pytest.approx(-0.06, abs=1e-12)


def test_surface_angle_of_a_tilted_flat_bed() -> None:
    rng = np.random.default_rng(1)
    x = rng.uniform(-0.1, 0.1, 20_000)
    y = rng.uniform(-0.12, 0.0, 20_000)
    keep = y < np.tan(math.radians(27.0)) * x - 0.03
    assert surface_angle(x[keep], y[keep]) == pytest.approx(27.0, abs=1.5)


def test_scene_cases_follow_the_setup() -> None:
    small = rolling_drum_case("small")
    assert small.drum.ends == "periodic" and small.air.model == "none"
    assert small.drum.length == pytest.approx(4 * BEAD_DIAMETER)
    assert small.lifters.count == 0 and small.drum.tilt_deg == 0.0
    assert small.drum.omega == pytest.approx(1.2147, abs=1e-4)
    assert small.particle_count == round(FULL_DRUM_BEADS * 4 * BEAD_DIAMETER / 0.36)
    full = rolling_drum_case("full")
    assert full.particle_count == FULL_DRUM_BEADS and full.drum.ends == "rotating"
    assert full.drum.length == pytest.approx(0.36)
    with pytest.raises(ValidationDataError, match="scale = 'huge'"):
        rolling_drum_case("huge")


# -- drum.ends ------------------------------------------------------------------------------------


def test_ends_default_keeps_the_case_and_section_hashes() -> None:
    case = tiny_drum()
    explicit = tiny_drum(drum__ends="fixed")
    assert case.hash() == explicit.hash()
    assert "ends" not in case.canonical_json()
    assert case.section_hash("drum", "lifters") == explicit.section_hash("drum", "lifters")
    for ends in ("rotating", "periodic"):
        other = tiny_drum(drum__ends=ends)
        assert other.hash() != case.hash()
        assert other.section_hash("drum", "lifters") != case.section_hash("drum", "lifters")


def test_ends_do_not_change_the_air_cache_key() -> None:
    from drumflow.air.field import air_cache_key

    base = tiny_drum(air__model="uniform")
    assert air_cache_key(base) == air_cache_key(tiny_drum(air__model="uniform", drum__ends="rotating"))


def test_unknown_ends_and_periodic_with_air_are_refused_by_name() -> None:
    with pytest.raises(CaseError, match="drum.ends"):
        case_from_dict(tiny_drum_dict(drum__ends="open"))
    with pytest.raises(CaseError, match="drum.ends = 'periodic': not with air.model = 'uniform'"):
        case_from_dict(tiny_drum_dict(drum__ends="periodic", air__model="uniform"))


def test_deck_of_each_end_option() -> None:
    from drumflow.dem.deck import DeckFiles, deck_context, plan_steps, render_deck
    from drumflow.dem.timestep import choose_time_step
    from drumflow.errors import GeometryError
    from drumflow.geometry.drum import simulation_box

    def deck(ends: str, files: DeckFiles) -> str:
        case = tiny_drum(drum__ends=ends)
        return render_deck(deck_context(case, plan_steps(case, choose_time_step(case)), files))

    fixed = deck("fixed", DeckFiles())
    assert "boundary        f f f" in fixed and fixed.count("zplane") == 2
    rotating = deck("rotating", DeckFiles(ends_stl_file="../geometry/ends.stl"))
    assert "zplane" not in rotating
    assert "fix ends all mesh/surface file ../geometry/ends.stl type 2 surface_ang_vel" in rotating
    assert "meshes shell ends" in rotating
    periodic = deck("periodic", DeckFiles())
    assert "boundary        f f p" in periodic and "zplane" not in periodic and "fix ends" not in periodic
    with pytest.raises(GeometryError, match="end plates"):
        deck("rotating", DeckFiles())
    box = simulation_box(tiny_drum(drum__ends="periodic"))
    assert box.lo[2] == 0.0 and box.hi[2] == pytest.approx(0.048)


def test_section_is_judged_against_the_full_drum_once_both_ran() -> None:
    from drumflow.validate.run import section_against_full

    def rec(surface: float, crossing: float) -> dict:
        return {"comparison": {
            "surface_velocity_m_s": {"simulated": surface, "error_kind": "relative", "band": 0.2},
            "zero_crossing_position_m": {"simulated": crossing, "error_kind": "absolute", "band": 0.006}}}

    assert section_against_full({"rolling_drum_section": rec(0.3, -0.06)}, "rolling_drum") is None
    out = section_against_full({"rolling_drum_section": rec(0.3, -0.06),
                                "rolling_drum_full": rec(0.32, -0.07)}, "rolling_drum")
    assert out is not None
    assert out["surface_velocity_m_s"]["within_band"]
    assert out["zero_crossing_position_m"]["difference"] == pytest.approx(0.01)
    assert not out["zero_crossing_position_m"]["within_band"]
