"""Impact speeds from snapshots (drumflow.dem.impacts) against hand-built configurations."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from drumflow.case import Case, load_case
from drumflow.dem.collision_speed import impact_velocity
from drumflow.dem.impacts import (
    WALL_EQUIVALENT_SPEED_FACTOR,
    ImpactSample,
    approaching_pairs,
    implied_time_steps,
    pool,
    snapshot_kinematics,
    wall_approaches,
    weighted_quantiles,
)
from drumflow.dem.timestep import choose_time_step
from drumflow.errors import AnalysisInputError

R = 0.01  # particle radius, m (the paper's 20 mm spheres)
D = 2 * R
GAP = 0.1 * D
MATERIAL = {"radius": R, "density": 1050.0, "youngs_modulus": 517e3, "poisson": 0.45}
CASES = Path(__file__).resolve().parents[2] / "cases"


def _pair(gap: float, v_i: np.ndarray, v_j: np.ndarray, direction: np.ndarray,
          origin: np.ndarray | None = None, radii: tuple[float, float] = (R, R)
          ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    n = direction / np.linalg.norm(direction)
    o = np.zeros(3) if origin is None else origin
    x = np.array([o, o + (radii[0] + radii[1] + gap) * n])
    return x, np.array([v_i, v_j], dtype=float), np.array(radii)


def test_head_on_pair_gives_its_closing_speed() -> None:
    n = np.array([1.0, -2.0, 0.5]) / math.sqrt(5.25)
    x, v, r = _pair(0.5 * GAP, 1.3 * n, -2.2 * n, n)
    s = approaching_pairs(x, v, r, GAP)
    assert len(s) == 1
    assert s.speed[0] == pytest.approx(3.5, rel=1e-12)
    assert s.weight[0] == pytest.approx(3.5, rel=1e-12)
    # Unequal radii: the gap is measured between surfaces, not centres.
    x, v, r = _pair(0.5 * GAP, np.zeros(3), -0.7 * n, n, radii=(0.004, 0.012))
    assert approaching_pairs(x, v, r, GAP).speed == pytest.approx([0.7], rel=1e-12)


def test_only_the_normal_part_of_an_oblique_approach_counts() -> None:
    # j comes in at 60 degrees to the line of centres at 2 m/s: normal closing speed 1 m/s.
    n = np.array([0.0, 0.0, 1.0])
    t = np.array([1.0, 0.0, 0.0])
    v_j = -2.0 * (math.cos(math.pi / 3) * n + math.sin(math.pi / 3) * t)
    x, v, r = _pair(0.3 * GAP, np.zeros(3), v_j, n)
    assert approaching_pairs(x, v, r, GAP).speed == pytest.approx([1.0], rel=1e-12)


@pytest.mark.parametrize(
    ("gap", "closing"),
    [(0.5 * GAP, -1.0),  # moving apart
     (1.5 * GAP, 1.0),  # approaching but beyond the window
     (-0.1 * GAP, 1.0)],  # already in contact (overlapping)
)
def test_pairs_outside_the_definition_are_not_counted(gap: float, closing: float) -> None:
    n = np.array([0.0, 1.0, 0.0])
    x, v, r = _pair(gap, np.zeros(3), -closing * n, n)
    assert len(approaching_pairs(x, v, r, GAP)) == 0


def _lattice(spacing: float, k: int = 8) -> np.ndarray:
    g = np.arange(k) * spacing
    return np.array(np.meshgrid(g, g, g, indexing="ij")).reshape(3, -1).T


def test_lattice_in_uniform_motion_or_rigid_rotation_has_no_impacts() -> None:
    x = _lattice(D + 0.5 * GAP)  # every neighbour inside the window
    r = np.full(len(x), R)
    still = np.zeros_like(x)
    assert len(approaching_pairs(x, still + [0.0, 0.0, -1.0], r, GAP)) == 0
    # Solid-body rotation (a bed carried round by the drum): (w x d) . d = 0 for every pair.
    omega = np.array([0.3, -0.2, 0.52])
    assert len(approaching_pairs(x, np.cross(omega, x) + [0.1, 0.0, 0.0], r, GAP)) == 0
    # Sanity of the set-up: a uniform compression makes every neighbour pair approach.
    s = approaching_pairs(x, -0.5 * (x - x.mean(axis=0)), r, GAP)
    assert len(s) == 3 * 7 * 64  # nearest-neighbour bonds of an 8^3 cubic lattice
    assert s.speed == pytest.approx(0.5 * (D + 0.5 * GAP), rel=1e-9)


def test_two_populations_weigh_as_number_times_speed() -> None:
    n1, v1, n2, v2 = 30, 0.2, 5, 3.0
    xs, vs = [], []
    for k in range(n1 + n2):
        x, v, _ = _pair(0.4 * GAP, np.zeros(3), [-(v1 if k < n1 else v2), 0.0, 0.0],
                        np.array([1.0, 0.0, 0.0]), origin=np.array([0.0, 0.1 * k, 0.0]))
        xs.append(x)
        vs.append(v)
    s = approaching_pairs(np.vstack(xs), np.vstack(vs), R, GAP)
    slow = np.isclose(s.speed, v1)
    assert slow.sum() == n1 and (~slow).sum() == n2
    assert s.weight[slow].sum() == pytest.approx(n1 * v1, rel=1e-12)
    assert s.weight[~slow].sum() == pytest.approx(n2 * v2, rel=1e-12)
    share_slow = n1 * v1 / (n1 * v1 + n2 * v2)  # 6 / 21: the slow pairs are 86 % of pairs
    below, above = weighted_quantiles(s.speed, s.weight, [share_slow - 1e-6, share_slow + 1e-6])
    assert below == pytest.approx(v1) and above == pytest.approx(v2)
    assert s.rate == pytest.approx((n1 * v1 + n2 * v2) / GAP, rel=1e-12)


def test_rate_estimate_matches_a_ballistic_stream() -> None:
    # Trains of spheres flying at a fixed target, spacing L, speed u: the true impact rate is
    # u / L. Snapshots at uniformly spread phases of one period must average to it.
    lanes = [(0.4, 5 * D), (2.5, 40 * D)]  # (speed m/s, spacing m)
    rates = np.zeros(len(lanes))
    phases = (np.arange(4000) + 0.5) / 4000
    for li, (u, spacing) in enumerate(lanes):
        k = np.arange(6)
        for ph in phases:
            gaps = (ph + k) * spacing  # target surface to projectile surface, > 0
            x = np.vstack([[0.0, 0.0, 0.0], np.column_stack([-(D + gaps), 0 * k, 0 * k])])
            v = np.vstack([[0.0, 0.0, 0.0], np.column_stack([u + 0 * k, 0 * k, 0 * k])])
            rates[li] += approaching_pairs(x, v, R, GAP).rate / len(phases)
        assert rates[li] == pytest.approx(u / spacing, rel=2e-3)


def test_weighted_quantiles_with_equal_weights_is_the_inverse_cdf() -> None:
    rng = np.random.default_rng(3)
    x = rng.lognormal(size=1001)
    q = np.array([0.05, 0.5, 0.9, 0.99, 1.0])
    got = weighted_quantiles(x, np.ones_like(x), q)
    assert got == pytest.approx(np.quantile(x, q, method="inverted_cdf"), rel=1e-12)
    assert np.all(np.isnan(weighted_quantiles([1.0, 2.0], [0.0, 0.0], [0.5])))
    with pytest.raises(AnalysisInputError, match="q = "):
        weighted_quantiles(x, np.ones_like(x), [0.0])


def test_wall_impacts_count_the_normal_speed_only() -> None:
    big_r, z0, z1 = 1.5, 0.0, 1.0
    x = np.array([
        [0.0, -(big_r - R - 0.5 * GAP), 0.5],  # near the shell bottom, falling onto it
        [big_r - R - 0.5 * GAP, 0.0, 0.5],  # near the shell side, sliding along it
        [0.3, 0.2, z0 + R + 0.2 * GAP],  # near the inlet plate, moving towards it
        [0.3, 0.2, z1 - R - 3.0 * GAP],  # too far from the outlet plate
    ])
    v = np.array([[0.5, -1.2, 0.0], [0.0, 0.785, 0.0], [0.0, 0.0, -0.3], [0.0, 0.0, 2.0]])
    s = wall_approaches(x, v, R, GAP, big_r, z0, z1)
    assert sorted(s.speed) == pytest.approx([0.3, 1.2], rel=1e-12)
    with pytest.raises(AnalysisInputError, match="z_max"):
        wall_approaches(x, v, R, GAP, big_r, z1, z0)


def test_pooling_puts_wall_impacts_on_the_sphere_sphere_scale() -> None:
    a = ImpactSample(np.array([1.0, 2.0]), np.array([1.0, 2.0]), GAP)
    b = ImpactSample(np.array([4.0]), np.array([4.0]), GAP)
    p = pool([a, b], speed_factors=[1.0, WALL_EQUIVALENT_SPEED_FACTOR], instants=1)
    assert list(p.speed) == [1.0, 2.0, 2.0]
    assert list(p.weight) == [1.0, 2.0, 4.0]  # the rate stays the real one
    assert p.rate == pytest.approx(7.0 / GAP)
    assert pool([a, a]).rate == pytest.approx(3.0 / GAP)  # two instants: mean rate
    with pytest.raises(AnalysisInputError, match="gap_max"):
        pool([a, ImpactSample(a.speed, a.weight, 2 * GAP)])


def test_implied_step_scales_as_v_to_minus_one_fifth() -> None:
    dt = implied_time_steps([0.25, 8.0], **MATERIAL)
    assert dt[0] / dt[1] == pytest.approx(2.0, rel=1e-12)  # 32^(1/5)
    # The wall contact by hand: m* = m, R* = r, E* = E / (2 (1 - nu^2)), t = 2.87 (...)^(1/5).
    m = 1050.0 * 4 / 3 * math.pi * R**3
    e_eff = 517e3 / (2 * (1 - 0.45**2))
    t_wall = 2.87 * (m**2 / (R * e_eff**2 * 3.0)) ** 0.2
    got = implied_time_steps([3.0], contact="wall", steps_per_contact=1.0, **MATERIAL)[0]
    assert got == pytest.approx(t_wall, rel=1e-12)
    with pytest.raises(AnalysisInputError, match="speeds"):
        implied_time_steps([0.0], **MATERIAL)


def test_design_speed_gives_back_the_paper_cases_contact_step() -> None:
    """The contact step ("contact", and "auto" before the spin limit) is 10 steps in the
    free-fall contact; "auto" is now shorter, set by the bed's spin limit."""
    data = load_case(CASES / "paper_model_two.toml").model_dump(mode="json")
    data["run"]["time_step"] = "contact"
    case = Case.model_validate(data)
    choice = choose_time_step(case)
    p = case.particles
    dt = implied_time_steps([impact_velocity(case)], p.radius, p.density, p.youngs_modulus,
                            p.poisson_ratio)[0]
    assert choice.steps_per_contact == pytest.approx(10.0) and choice.bound == "contact"
    assert dt == pytest.approx(choice.time_step, rel=1e-12)


def test_bad_gap_is_refused() -> None:
    x, v, r = _pair(0.0, np.zeros(3), np.zeros(3), np.array([1.0, 0.0, 0.0]))
    with pytest.raises(AnalysisInputError, match="gap_max = 0"):
        approaching_pairs(x, v, r, 0.0)


def test_a_snapshots_columns_give_the_same_pairs_as_the_arrays() -> None:
    """The snapshot reader's columns (as `drumflow bench --from` and studies/impact_speeds.py
    pass them) stack into the centres, velocities and radii the measurement takes."""
    x, v, r = _pair(0.5 * GAP, np.array([0.3, 0.0, 0.0]), np.array([-0.2, 0.0, 0.0]),
                    np.array([1.0, 0.0, 0.0]))
    columns = {"x": x[:, 0], "y": x[:, 1], "z": x[:, 2], "vx": v[:, 0], "vy": v[:, 1],
               "vz": v[:, 2], "radius": r, "id": np.array([1.0, 2.0])}
    xs, vs, rs = snapshot_kinematics(columns)
    np.testing.assert_array_equal(xs, x)
    np.testing.assert_array_equal(vs, v)
    np.testing.assert_array_equal(rs, r)
    assert approaching_pairs(xs, vs, rs, GAP).speed == pytest.approx([0.5])
