"""The bed's heat to the air without a solver (drumflow.air.bed_heat and Gunn's law in
drumflow.physics.particle_air): the correlation against hand arithmetic, the exchange rate of
a cell, the zone binning's sums, the particles' means on the cells, and bad input refused."""

from __future__ import annotations

import math
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

from drumflow.air.bed_air import BED_FRACTION, POROUS_FRACTION
from drumflow.air.bed_heat import (
    TURBULENT_PRANDTL,
    bin_heat_sources,
    cell_diffusivity,
    exchange_rate,
    particle_means,
    solve_air_temperature,
    solve_bed_heat,
    superficial_slip,
)
from drumflow.errors import AnalysisInputError
from drumflow.physics.particle_air import AirState, gunn_h, gunn_nusselt


def test_gunn_nusselt_matches_the_formula_worked_by_hand() -> None:
    """eps = 0.4, Re = 100, Pr = 0.7, by hand: Pr^(1/3) = 0.887904, Re^0.2 = 2.511886,
    Re^0.7 = 25.118864; 7 - 4 + 0.8 = 3.8 and 1.33 - 0.96 + 0.192 = 0.562;
    3.8 (1 + 0.7 x 2.511886 x 0.887904) = 9.732670, 0.562 x 25.118864 x 0.887904 = 12.534330:
    Nu = 22.267000. A coefficient 10 % off moves Nu by far more than the 1e-6 allowed."""
    assert float(gunn_nusselt(100.0, 0.7, 0.4)) == pytest.approx(22.267000, rel=1e-6)
    # Vectorised, element by element.
    nu = gunn_nusselt(np.array([100.0, 100.0]), 0.7, np.array([0.4, 0.4]))
    assert nu == pytest.approx([22.267000, 22.267000], rel=1e-6)


def test_gunn_nusselt_limits() -> None:
    """No flow: Nu = 7 - 10 eps + 5 eps^2 (2 for a lone sphere at eps = 1, the still-air
    limit); eps = 0.5 gives 3.25. Outside Gunn's voidage range it is refused."""
    assert float(gunn_nusselt(0.0, 0.7, 1.0)) == pytest.approx(2.0, rel=1e-12)
    assert float(gunn_nusselt(0.0, 0.7, 0.5)) == pytest.approx(3.25, rel=1e-12)
    for eps in (0.3, 1.01, math.nan):
        with pytest.raises(AnalysisInputError, match="voidage"):
            gunn_nusselt(10.0, 0.7, eps)
    with pytest.raises(AnalysisInputError, match="reynolds"):
        gunn_nusselt(-1.0, 0.7, 0.5)


def test_gunn_h_is_nusselt_times_conductivity_over_diameter() -> None:
    air = AirState.at(30.0)
    d, eps, u = 0.008, 0.6, 1.5
    re = air.density * u * d / air.viscosity
    expected = float(gunn_nusselt(re, air.prandtl, eps)) * air.conductivity / d
    assert float(gunn_h(u, eps, d, air)) == pytest.approx(expected, rel=1e-12)


def test_exchange_rate_of_a_cell_by_hand() -> None:
    """Air moving with the particles (no slip: Re = 0): h = (7 - 10 eps + 5 eps^2) k_air / d,
    a_v = 6 phi / d, k = h a_v / (rho c_p); a cell below POROUS_FRACTION takes none. The slip
    is superficial: U - eps v_p (U is the solved, superficial velocity)."""
    air = AirState.at(30.0)
    cp, d = 1007.0, 0.008
    phi = np.array([0.4, 0.4, 0.5 * POROUS_FRACTION])
    v_p = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 0.0]])
    U = (1.0 - phi)[:, None] * v_p  # superficial velocity of air moving with the particles
    h, k = exchange_rate(phi, U, v_p, d, air, cp)
    eps = 0.6
    h0 = (7.0 - 10.0 * eps + 5.0 * eps**2) * air.conductivity / d
    assert h[:2] == pytest.approx([h0, h0], rel=1e-12)
    assert k[:2] == pytest.approx([h0 * 6.0 * 0.4 / d / (air.density * cp)] * 2, rel=1e-12)
    assert k[2] == 0.0
    # With the air at rest and the particles moving at 1 m/s, the slip is 0.6 m/s superficial.
    h2, _ = exchange_rate(phi[:2], np.zeros((2, 3)), v_p[:2], d, air, cp)
    assert h2[1] == pytest.approx(float(gunn_h(0.6, eps, d, air)), rel=1e-12)


def test_binning_keeps_the_rate_and_the_heat_at_inlet_air() -> None:
    """Zones keep sum k V and sum k theta_p V (the heat at inlet-temperature air) to
    round-off, every source cell is in exactly one zone, cells without a source in none."""
    rng = np.random.default_rng(3)
    n = 5000
    k = np.where(rng.random(n) < 0.3, 0.0, 10 ** rng.uniform(-3, 2, n))
    theta = rng.uniform(20.0, 60.0, n)
    V = rng.uniform(1e-7, 1e-6, n)
    zones = bin_heat_sources(k, theta, V, k_bins=12, t_bins=4)
    assert len(zones.cells) == 48
    held = np.concatenate(zones.cells)
    assert len(held) == len(np.unique(held)) == int(np.sum(k > 0))
    zk, zt = zones.binned()
    assert np.sum(zk * V) == pytest.approx(np.sum(k * V), rel=1e-12)
    assert np.sum(zk * zt * V) == pytest.approx(np.sum(k * theta * V), rel=1e-12)
    assert np.all(zk[k == 0] == 0.0)
    # Binned by log k: a zone's k stays within its cells' range.
    for c, kz in zip(zones.cells, zones.k, strict=True):
        assert k[c].min() <= kz <= k[c].max()


def test_particle_means_on_the_cells() -> None:
    """Two clusters of particles at 50 and 70 degC: cells by each cluster take its
    temperature, a cell far from both the mean over all particles (weighted by volume)."""
    rng = np.random.default_rng(1)
    left = rng.uniform([-0.35, -0.1, 0.0], [-0.25, 0.1, 0.08], (200, 3))
    right = rng.uniform([0.25, -0.1, 0.0], [0.35, 0.1, 0.08], (100, 3))
    positions = np.vstack([left, right])
    temps = np.r_[np.full(200, 50.0), np.full(100, 70.0)]
    radii = np.full(300, 0.004)
    centres = np.array([[-0.3, 0.0, 0.04], [0.3, 0.0, 0.04], [0.0, 0.38, 0.04]])
    out = particle_means(centres, positions, radii, temps, np.array([-0.4, -0.4, 0.0]),
                         np.array([0.4, 0.4, 0.08]), 0.03, periodic_z=True)
    assert out[0] == pytest.approx(50.0)
    assert out[1] == pytest.approx(70.0)
    assert out[2] == pytest.approx((200 * 50.0 + 100 * 70.0) / 300)
    vectors = particle_means(centres, positions, radii, np.ones((300, 3)),
                             np.array([-0.4, -0.4, 0.0]), np.array([0.4, 0.4, 0.08]), 0.03)
    assert vectors.shape == (3, 3) and vectors == pytest.approx(np.ones((3, 3)))


@pytest.mark.parametrize(("kwargs", "name"), [
    ({"diameter": -0.008}, "diameter"),
    ({"diameter": math.nan}, "diameter"),
    ({"fraction": np.array([0.2, 1.0])}, "fraction"),
    ({"fraction": np.array([0.2, math.nan])}, "fraction"),
    ({"particle_velocity": np.array([[0.0, 0.0, math.nan], [0.0, 0.0, 0.0]])},
     "particle_velocity"),
])
def test_bad_exchange_input_is_refused_by_name(kwargs: dict[str, object], name: str) -> None:
    args: dict[str, object] = {"fraction": np.array([0.2, 0.3]), "air_velocity": np.zeros((2, 3)),
                               "particle_velocity": np.zeros((2, 3)), "diameter": 0.008,
                               "air": AirState.at(30.0), "heat_capacity": 1007.0}
    args.update(kwargs)
    with pytest.raises(AnalysisInputError) as err:
        exchange_rate(**args)  # type: ignore[arg-type]
    assert err.value.name == name


def test_bad_sources_and_temperatures_are_refused_by_name(tmp_path: Path) -> None:
    V = np.ones(3)
    with pytest.raises(AnalysisInputError) as err:
        bin_heat_sources(np.array([1.0, 1.0, 1.0]), np.array([1.0, math.nan, 1.0]), V)
    assert err.value.name == "theta_p"
    with pytest.raises(AnalysisInputError) as err:
        bin_heat_sources(np.array([1.0, -1.0, 1.0]), np.ones(3), V)
    assert err.value.name == "k"
    # A NaN particle temperature is refused before any case is read.
    state = SimpleNamespace(temperatures_C=np.array([60.0, math.nan]),
                            velocities=np.zeros((2, 3)), radii=np.full(2, 0.004))
    with pytest.raises(AnalysisInputError) as err:
        solve_bed_heat(SimpleNamespace(), state, SimpleNamespace(), SimpleNamespace(),  # type: ignore[arg-type]
                       tmp_path)
    assert err.value.name == "temperatures_C"


def test_local_diffusivity_by_hand() -> None:
    """Three cells: free air (phi 0), a curtain (0.05) and the bed (0.55), nu_t 1e-3 m^2/s
    in each, nu = 1.6e-5, Pr = 0.71, d = 8 mm, superficial slip 0.2 m/s. Outside the bed
    D = 2.253521e-5 + 1.176471e-3 = 1.199006e-3; in the bed the k-epsilon nu_t is not used:
    D = 0.45 x 1.6e-5 / 0.71 + 0.1 x 0.2 x 0.008 = 1.014085e-5 + 1.6e-4 = 1.701408e-4
    (Yagi & Kunii's 0.1: a coefficient 10 % off moves it by 9.4 %, far past 1e-6)."""
    assert BED_FRACTION < 0.55 and TURBULENT_PRANDTL == 0.85
    d = cell_diffusivity(np.full(3, 1e-3), np.array([0.0, 0.05, 0.55]), np.full(3, 0.2),
                         0.008, 1.6e-5, 0.71)
    assert d == pytest.approx([1.199006e-3, 1.199006e-3, 1.701408e-4], rel=1e-6)
    with pytest.raises(AnalysisInputError) as err:
        cell_diffusivity(np.array([1e-3, -1e-3]), np.zeros(2), np.zeros(2), 0.008, 1.6e-5, 0.71)
    assert err.value.name == "nut"


def test_superficial_slip_by_hand() -> None:
    """U = (0, 0, 1) superficial, v_p = (0, 0, 2) at phi = 0.4: U - 0.6 v_p = (0, 0, -0.2)."""
    slip = superficial_slip(np.array([0.4]), np.array([[0.0, 0.0, 1.0]]),
                            np.array([[0.0, 0.0, 2.0]]))
    assert slip == pytest.approx([0.2], rel=1e-12)


@pytest.mark.parametrize(("diffusivity", "value"), [
    (-1e-3, -1e-3), (math.nan, None), (np.array([1e-3, math.inf, 1e-3]), math.inf),
    (np.full(2, 1e-3), "(2,) values"),
])
def test_bad_diffusivity_is_refused_before_any_solver(tmp_path: Path, diffusivity: object,
                                                      value: object) -> None:
    """One value or one per cell, finite and >= 0; refused by name before the case is
    copied (the bed case here does not even exist)."""
    zones = bin_heat_sources(np.ones(3), np.ones(3), np.ones(3))
    with pytest.raises(AnalysisInputError) as err:
        solve_air_temperature(tmp_path / "bed", "5", tmp_path / "heat", zones,
                              diffusivity, SimpleNamespace())  # type: ignore[arg-type]
    assert err.value.name == "diffusivity"
    if value is not None:
        assert err.value.value == value
    assert not (tmp_path / "heat").exists()


def test_a_heat_only_rerun_without_a_converged_bed_is_refused(tmp_path: Path) -> None:
    """``result=None`` reuses the work folder's bed case; without a converged simpleFoam log
    there the error names the folder."""
    state = SimpleNamespace(temperatures_C=np.array([60.0]), velocities=np.zeros((1, 3)),
                            radii=np.full(1, 0.004))
    (tmp_path / "bed").mkdir()
    (tmp_path / "bed" / "log.simpleFoam").write_text("Time = 1\nTime = 2\nEnd\n")
    with pytest.raises(AnalysisInputError) as err:
        solve_bed_heat(None, state, SimpleNamespace(), SimpleNamespace(),  # type: ignore[arg-type]
                       tmp_path)
    assert err.value.name == str(tmp_path / "bed")
