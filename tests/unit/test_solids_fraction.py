"""The solids fraction deposited on an air grid, and Ergun's law as OpenFOAM coefficients
(drumflow.air.solids_fraction). No solver."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from drumflow.air.solids_fraction import (
    ERGUN,
    ErgunLaw,
    RectilinearGrid,
    bin_coefficients,
    deposit_solids_fraction,
    slab_sphere_volume,
    smooth_deposition,
    sphere_lattice,
)


def _random_spheres(n: int, box: float, seed: int = 3) -> tuple[np.ndarray, np.ndarray]:
    rng = np.random.default_rng(seed)
    radii = rng.uniform(0.5e-3, 2.5e-3, n)
    centres = rng.uniform(radii[:, None], box - radii[:, None], (n, 3))
    return centres, radii


@pytest.mark.parametrize("resolution", [2, 6])
def test_deposited_volume_sums_to_the_spheres_volume(resolution: int) -> None:
    """Spheres inside a non-uniform grid: the deposit sums to their volume to 1e-9 (relative),
    whatever the sub-sampling resolution."""
    centres, radii = _random_spheres(300, 0.03)
    edges = np.cumsum(np.r_[0.0, np.random.default_rng(1).uniform(1e-3, 4e-3, 12)])
    edges *= 0.03 / edges[-1]
    grid = RectilinearGrid((edges, np.linspace(0, 0.03, 7), np.linspace(0, 0.03, 11)))
    dep = deposit_solids_fraction(grid, centres, radii, resolution=resolution)
    total = 4.0 / 3.0 * math.pi * float(np.sum(radii**3))
    assert dep.outside == 0.0
    assert dep.spheres_volume == pytest.approx(total, rel=1e-12)
    assert abs(dep.volume.sum() - total) / total < 1e-9


def test_periodic_axes_wrap_and_open_axes_report_what_falls_outside() -> None:
    grid = RectilinearGrid.uniform([0, 0, 0], [0.01, 0.01, 0.01], (4, 4, 4), periodic=(True, True, False))
    # One sphere across the x = 0 face (wrapped), one half above the top (cut).
    r = 2e-3
    dep = deposit_solids_fraction(grid, [[0.0, 5e-3, 5e-3], [5e-3, 5e-3, 0.01]], [r, r])
    v = 4.0 / 3.0 * math.pi * r**3
    assert abs(dep.volume.sum() + dep.outside - 2 * v) < 1e-9 * v
    assert dep.outside == pytest.approx(0.5 * v, rel=1e-12)  # the lattice is symmetric
    # The wrapped sphere sits half in the first and half in the last column of cells (the
    # other sphere, at x = 5 mm, reaches neither).
    assert dep.volume[0].sum() == pytest.approx(0.5 * v, rel=1e-12)
    assert dep.volume[-1].sum() == pytest.approx(0.5 * v, rel=1e-12)


def test_sphere_lattice_is_symmetric_so_octants_get_an_eighth() -> None:
    pts = sphere_lattice(6)
    octant = np.all(pts > 0, axis=1).sum()
    assert 8 * octant == len(pts)
    # About the sphere's volume fraction of the cube: the lattice fills the sphere evenly.
    assert len(pts) / (12**3) == pytest.approx(math.pi / 6.0, rel=0.02)


def test_simple_cubic_packing_gives_pi_over_six_in_every_cell() -> None:
    """Spheres of diameter a on a simple cubic lattice of spacing a, centred on the corners of
    cells of side a: every cell holds exactly pi/6 of solids (each takes an eighth of eight
    spheres, which the symmetric sub-sampling splits exactly)."""
    a = 2e-3
    n = 4
    grid = RectilinearGrid.uniform([0, 0, 0], [n * a] * 3, (n, n, n), periodic=(True, True, True))
    idx = np.arange(n) * a  # centres on the cell corners: each sphere is cut into octants
    x, y, z = np.meshgrid(idx, idx, idx, indexing="ij")
    centres = np.column_stack([x.ravel(), y.ravel(), z.ravel()])
    dep = deposit_solids_fraction(grid, centres, 0.5 * a)
    assert np.allclose(dep.fraction, math.pi / 6.0, rtol=1e-12)


def test_random_packed_box_matches_the_exact_slab_volume() -> None:
    """The deposited fraction of horizontal layers against the exact spherical-cap volumes of
    the same slabs: within the sub-sampling error (0.5 % of the solids at resolution 6)."""
    centres, radii = _random_spheres(400, 0.03, seed=11)
    grid = RectilinearGrid.uniform([0, 0, 0], [0.03] * 3, (3, 3, 6))
    dep = deposit_solids_fraction(grid, centres, radii)
    for k in range(6):
        lo, hi = grid.edges[2][k], grid.edges[2][k + 1]
        exact = slab_sphere_volume(centres, radii, lo, hi)
        assert dep.volume[:, :, k].sum() == pytest.approx(exact, rel=0.005), k


def test_slab_volume_of_a_whole_sphere_and_of_a_hemisphere() -> None:
    r = 1e-3
    v = 4.0 / 3.0 * math.pi * r**3
    assert slab_sphere_volume([[0, 0, 0]], r, -1.0, 1.0) == pytest.approx(v, rel=1e-14)
    assert slab_sphere_volume([[0, 0, 0]], r, 0.0, 1.0) == pytest.approx(0.5 * v, rel=1e-14)
    assert slab_sphere_volume([[0, 0, 0]], r, 2 * r, 3 * r) == 0.0


def test_smoothing_conserves_the_volume_and_narrows_the_scatter() -> None:
    centres, radii = _random_spheres(500, 0.03, seed=5)
    grid = RectilinearGrid.uniform([0, 0, 0], [0.03] * 3, (6, 6, 6), periodic=(True, False, False))
    dep = deposit_solids_fraction(grid, centres, radii)
    smooth = smooth_deposition(dep, passes=2)
    assert smooth.volume.sum() == pytest.approx(dep.volume.sum(), rel=1e-12)
    assert smooth.fraction.std() < dep.fraction.std()


def test_ergun_coefficients_reproduce_the_ergun_pressure_gradient() -> None:
    """OpenFOAM's S = -(mu d + rho |U| f / 2) U with the mapped d, f is Ergun's equation
    written out by hand (Ergun 1952), at superficial U."""
    eps, dp, u, rho, mu = 0.41, 4e-3, 0.08, 1.16, 1.87e-5
    d, f = ERGUN.darcy_forchheimer(eps, dp)
    by_hand = 150 * mu * (1 - eps) ** 2 / (eps**3 * dp**2) * u + 1.75 * rho * (1 - eps) / (eps**3 * dp) * u**2
    assert float(mu * d * u + 0.5 * rho * f * u * u) == pytest.approx(by_hand, rel=1e-12)
    assert ERGUN.pressure_gradient(eps, dp, u, rho, mu) == pytest.approx(by_hand, rel=1e-12)
    # A changed law changes its own term only.
    assert ErgunLaw(165.0, 1.75).darcy_forchheimer(eps, dp)[0] == pytest.approx(1.1 * float(d))
    with pytest.raises(ValueError):
        ERGUN.darcy_forchheimer(0.0, dp)


def test_binning_keeps_the_volume_mean_resistance_and_reports_its_spread() -> None:
    rng = np.random.default_rng(2)
    fraction = np.r_[rng.uniform(0.5, 0.65, 400), rng.uniform(0.0, 0.2, 40), np.zeros(60)]
    volumes = rng.uniform(1.0, 2.0, len(fraction)) * 1e-9
    zones = bin_coefficients(fraction, volumes, 4e-3, bins=16)
    binned_d, _ = zones.binned()
    assert np.sum(binned_d * volumes) == pytest.approx(np.sum(zones.cell_d * volumes), rel=1e-12)
    assert sum(len(c) for c in zones.cells) == 440  # the empty cells are plain air
    err = zones.binning_error(volumes)
    assert 0 < err["d_weighted"] < 0.05
    exact = bin_coefficients(fraction, volumes, 4e-3, bins=None)
    assert exact.binning_error(volumes)["d_max"] < 1e-12
    with pytest.raises(ValueError):
        bin_coefficients(np.array([1.0]), np.array([1.0]), 4e-3)


def test_one_porosity_writer_for_both_hosts(tmp_path: Path) -> None:
    """The bed-air cases (fvOptions) and the verification's porous bed (porosityProperties) read
    the same zones and coefficients from one writer (they were twins until 2026-11-28)."""
    from foamlib import FoamFile

    from drumflow.air.foam_case import write_porosity

    zones = bin_coefficients(np.r_[np.full(5, 0.6), np.full(5, 0.3), np.zeros(3)],
                             np.full(13, 1e-9), 4e-3, bins=2)
    for sub in ("system", "constant"):
        (tmp_path / sub).mkdir()
    write_porosity(tmp_path, zones, "fvOptions")
    write_porosity(tmp_path, zones, "porosityProperties")
    options = FoamFile(tmp_path / "system" / "fvOptions")
    props = FoamFile(tmp_path / "constant" / "porosityProperties")
    for name, d, f in zip(zones.names, zones.d, zones.f, strict=True):
        inner = options[name, "explicitPorositySourceCoeffs"]
        assert options[name, "type"] == "explicitPorositySource"
        assert inner["cellZone"] == props[name, "cellZone"] == name
        for coeffs in (inner["DarcyForchheimerCoeffs"], props[name, "DarcyForchheimerCoeffs"]):
            assert list(coeffs["d"]) == pytest.approx([d] * 3)
            assert list(coeffs["f"]) == pytest.approx([f] * 3)
    sets = FoamFile(tmp_path / "system" / "topoSetDict")["actions"]
    assert [a["name"] for a in sets] == zones.names
