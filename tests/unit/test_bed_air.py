"""The bed's air without a solver (drumflow.air.bed_air): spheres onto mesh cells, the
face-flux counting of the through-flow, and the Ergun coefficients of a zone."""

from __future__ import annotations

import math
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from drumflow.air.bed_air import (
    POROUS_FRACTION,
    categorize,
    deposit_on_cells,
    inflow_into,
    porosity_zones,
    section_flow,
)


def _drum_cells(radius: float, length: float, size: float) -> tuple[np.ndarray, np.ndarray]:
    """Cubes of side ``size`` whose centres lie inside a cylinder about z: a stand-in mesh."""
    n = round(2 * radius / size)
    c = -radius + size * (np.arange(n) + 0.5)
    z = size * (np.arange(round(length / size)) + 0.5)
    X, Y, Z = np.meshgrid(c, c, z, indexing="ij")
    pts = np.column_stack([X.ravel(), Y.ravel(), Z.ravel()])
    pts = pts[np.hypot(pts[:, 0], pts[:, 1]) < radius]
    return pts, np.full(len(pts), size**3)


def test_spheres_inside_the_drum_keep_their_volume_on_the_cells() -> None:
    """Random spheres inside a drum: the grid gets their volume exactly, the mesh cells within
    2 % (the sum of the volumes, computed here by hand, is independent of the code)."""
    radius, length = 0.2, 0.08
    centres, volumes = _drum_cells(radius, length, 0.01)
    rng = np.random.default_rng(5)
    r = np.full(800, 0.004)
    rho = np.sqrt(rng.uniform(0, (radius - 0.01) ** 2, len(r)))
    theta = rng.uniform(0, 2 * math.pi, len(r))
    pos = np.column_stack([rho * np.cos(theta), rho * np.sin(theta),
                           rng.uniform(0.005, length - 0.005, len(r))])
    dep = deposit_on_cells(centres, volumes, pos, r, np.array([-radius, -radius, 0.0]),
                           np.array([radius, radius, length]), 0.02,
                           lambda x, y: np.hypot(x, y) < radius)
    by_hand = len(r) * 4.0 / 3.0 * math.pi * 0.004**3
    assert dep.particles_volume_m3 == pytest.approx(by_hand, rel=1e-12)
    assert dep.grid_volume_m3 + dep.outside_m3 == pytest.approx(by_hand, rel=1e-9)
    assert dep.outside_m3 == 0.0
    assert dep.cells_volume_m3 == pytest.approx(by_hand, rel=0.02)
    assert dep.smoothing_length_m[0] == pytest.approx(dep.spacing_m[0] / math.sqrt(2.0))


def test_a_packed_region_shows_its_packing_fraction() -> None:
    """A simple cubic packing (fraction pi/6, by hand) filling a box: the cells in its middle
    get pi/6 within 2 %; a fraction off by 10 % would not pass."""
    d = 0.004
    centres, volumes = _drum_cells(0.2, 0.08, 0.01)
    s = d * (np.arange(-20, 20) + 0.5)
    zs = d * (np.arange(20) + 0.5)
    X, Y, Z = np.meshgrid(s, s, zs, indexing="ij")
    pos = np.column_stack([X.ravel(), Y.ravel(), Z.ravel()])
    dep = deposit_on_cells(centres, volumes, pos, np.full(len(pos), d / 2),
                           np.array([-0.2, -0.2, 0.0]), np.array([0.2, 0.2, 0.08]), 0.02,
                           lambda x, y: np.hypot(x, y) < 0.2)
    middle = (np.abs(centres[:, 0]) < 0.04) & (np.abs(centres[:, 1]) < 0.04) & (centres[:, 2] < 0.04)
    assert np.mean(dep.fraction[middle]) == pytest.approx(math.pi / 6.0, rel=0.02)
    far = np.hypot(centres[:, 0], centres[:, 1]) > 0.15
    assert np.all(dep.fraction[far] == 0.0)


def test_inflow_counts_only_flux_into_the_target_from_the_source() -> None:
    """Six cells: 0, 2, 5 free; 1, 4 curtain; 3 bed. Fluxes run owner -> neighbour."""
    owner = np.array([0, 1, 2, 1, 3, 4, 4, 0])
    neighbour = np.array([1, 2, 4, 4, 4, 5, 3, 5])
    flux = np.array([2.0, 0.7, -0.3, 5.0, 0.9, -1.5, 0.25, 9.0])
    category = categorize(np.array([0.0, 0.1, 0.001, 0.5, 0.05, 0.0]))
    assert list(category) == [2, 1, 2, 0, 1, 2]
    masks = [category == i for i in range(3)]
    # Into the curtain from free air: face 0 (+2 into 1) and face 5 (-1.5: from 5 into 4);
    # face 1 leaves the curtain, face 2 leaves it (4 -> 2), face 3 is curtain to curtain.
    assert inflow_into(owner, neighbour, flux, masks[1], masks[2]) == pytest.approx(3.5)
    # Into the bed from anything else: face 4 (+0.9 from 3 to 4) leaves it; face 6 (+0.25
    # from 4 into 3) enters.
    assert inflow_into(owner, neighbour, flux, masks[0], ~masks[0]) == pytest.approx(0.25)
    # Boundary faces (owner only, past the internal ones) are not counted.
    assert inflow_into(np.r_[owner, 1], neighbour, np.r_[flux, 100.0], masks[1],
                       masks[2]) == pytest.approx(3.5)


def test_section_flow_splits_the_faces_crossing_the_plane() -> None:
    """Four cells above z = 0.5 (0, 1) and below (2, 3); flow is counted along -z."""
    z = np.array([0.7, 0.8, 0.3, 0.2])
    owner = np.array([0, 1, 2, 0, 2])
    neighbour = np.array([2, 3, 1, 1, 3])
    flux = np.array([1.0, 2.0, -0.5, 7.0, 3.0])  # faces 3, 4 do not cross
    category = np.array([0, 2, 0, 1])  # bed, free, bed, curtain
    out = section_flow(owner, neighbour, flux, z, 0.5, category)
    # Face 0: 1.0 down, bed-bed; face 1: 2.0 down, free-curtain; face 2: owner 2 below,
    # neighbour 1 above, phi -0.5 from 2 to 1 = +0.5 down, bed-free.
    assert out["total"] == pytest.approx(3.5)
    assert out["bed"] == pytest.approx(1.0 + 0.25)
    assert out["free"] == pytest.approx(1.0 + 0.25)
    assert out["curtain"] == pytest.approx(1.0)


def test_thin_curtain_cells_keep_their_own_resistance() -> None:
    """Cells from 0.002 to 0.6 solids: every cell's zone coefficient is within a factor 1.5 of
    its own Ergun d (a zone lumping the curtains with the bed's fringe would be 10^3 off)."""
    fraction = np.geomspace(0.002, 0.6, 3000)
    zones = porosity_zones(fraction, np.ones(len(fraction)), 0.008)
    binned, _ = zones.binned()
    by_hand = 150.0 * fraction**2 / ((1 - fraction) ** 3 * 0.008**2)
    assert np.all(np.abs(np.log(binned / by_hand)) < np.log(1.5))


def test_zone_coefficients_are_ergun_at_the_zone_voidage() -> None:
    """All bed cells at voidage 0.4 with 8 mm granules: d and f by hand from Ergun (1952);
    cells below the porous threshold get no zone."""
    dp = 0.008
    fraction = np.r_[np.full(50, 0.6), np.full(5, 0.5 * POROUS_FRACTION), np.zeros(5)]
    zones = porosity_zones(fraction, np.ones(len(fraction)), dp)
    d_hand = 150.0 * 0.6**2 / (0.4**3 * dp**2)
    f_hand = 2.0 * 1.75 * 0.6 / (0.4**3 * dp)
    cells = np.concatenate(zones.cells)
    assert sorted(cells) == list(range(50))
    assert np.allclose(zones.d, d_hand, rtol=1e-12)
    assert np.allclose(zones.f, f_hand, rtol=1e-12)


ROOT = Path(__file__).resolve().parents[2]


@pytest.mark.parametrize(("args", "named"), [
    (["cases/paper_model_two.toml", "--state", "results/states/smoke_1.0s.npz"],
     "smoke_1.0s.npz"),
    (["cases/smoke.toml", "--state", "results/states/smoke_1.0s.npz", "--grid-spacing", "-0.1"],
     "--grid-spacing = -0.1"),
    (["cases/smoke.toml", "--state", "results/states/no_such_state.npz"], "no_such_state.npz"),
    (["cases/smoke.toml", "--state", "results/states/smoke_1.0s.npz", "--axial", "cyclic"],
     "--axial = cyclic"),
    (["cases/smoke.toml", "--state", "results/states/smoke_1.0s.npz", "--heat", "--mixing",
      "laminar"], "--mixing = laminar"),
    (["cases/smoke.toml", "--state", "results/states/smoke_1.0s.npz", "--heat-only"],
     "split.json = missing"),
])
def test_bad_input_is_refused_before_any_solver(tmp_path: Path, args: list[str],
                                                named: str) -> None:
    """Exit code 2 and one message naming the file or option, and nothing written."""
    out = tmp_path / "out"
    done = subprocess.run([sys.executable, "-m", "drumflow.cli", "bed-air", *args, "--out",
                           str(out), "--work", str(tmp_path / "work")],
                          cwd=ROOT, capture_output=True, text=True, timeout=120)
    assert done.returncode == 2, done.stderr
    assert named in done.stderr
    assert "Traceback" not in done.stderr
    assert not out.exists() and not (tmp_path / "work").exists()


def test_a_case_without_a_periodic_gradient_is_refused_by_name(tmp_path: Path) -> None:
    """The periodic pressure gradient is read from the solution or the solver log; a case that
    was not periodic has neither, and the error names where it looked."""
    from drumflow.air.periodic import read_pressure_gradient
    from drumflow.errors import SolverError

    (tmp_path / "5").mkdir()
    (tmp_path / "log.simpleFoam").write_text("Time = 5\nSIMPLE solution converged in 5 iterations\n")
    with pytest.raises(SolverError, match="no meanVelocityForce gradient"):
        read_pressure_gradient(tmp_path, "5")
    (tmp_path / "log.simpleFoam").write_text(
        "Pressure gradient source: uncorrected Ubar = 3.05, pressure gradient = 0.25\n"
        "Pressure gradient source: uncorrected Ubar = 3.054, pressure gradient = 0.2007\n")
    assert read_pressure_gradient(tmp_path, "5") == pytest.approx(0.2007)


@pytest.mark.parametrize(("args", "named"), [
    (["--axial", "inlet-outlet"], "split.json = case, --axial, state time, particles"),
    ([], "/bed = no converged bed-air solution"),
])
def test_a_heat_only_rerun_must_match_an_earlier_run(tmp_path: Path, args: list[str],
                                                    named: str) -> None:
    """--heat-only reuses the flow an earlier run left: refused (exit 2, by name, before any
    solver) when the out folder's split.json is of another set-up, or the work folder holds
    no converged bed case."""
    out = tmp_path / "out"
    out.mkdir()
    shutil.copyfile(ROOT / "results/air/bed_air_smoke_1.0s_periodic/split.json",
                    out / "split.json")
    done = subprocess.run([sys.executable, "-m", "drumflow.cli", "bed-air", "cases/smoke.toml",
                           "--state", "results/states/smoke_1.0s.npz", "--heat-only", *args,
                           "--out", str(out), "--work", str(tmp_path / "work")],
                          cwd=ROOT, capture_output=True, text=True, timeout=120)
    assert done.returncode == 2, done.stderr
    assert named in " ".join(done.stderr.split())
    assert "Traceback" not in done.stderr
    assert sorted(p.name for p in out.iterdir()) == ["split.json"]
