"""Real OpenFOAM v1912 runs of the smoke drum's air, empty and with the shipped 1 s bed state
as Ergun porosity (drumflow.air.bed_air). No mocks.

The smoke drum on a 0.03 m mesh (about 9k tetrahedra): each solve takes a few seconds on one
core (about a minute in all on a loaded 2-core machine).
"""

from __future__ import annotations

import copy
import json
import tomllib
from pathlib import Path

import numpy as np
import pytest
from support.solvers import CASES, OPENFOAM, requires_solver

from drumflow.air.bed_air import (
    BedAirResult,
    solve_bed_air,
    write_bed_air,
    write_porosity_options,
)
from drumflow.air.foam import read_cell_fields, solve_air
from drumflow.air.foam_case import air_properties_for, write_fv_solution
from drumflow.air.mesh import run_foam
from drumflow.air.solids_fraction import PorosityZones
from drumflow.case import Case, case_from_dict
from drumflow.dem.state import check_state, read_state
from drumflow.runner import Runner

pytestmark = [
    pytest.mark.solver,
    requires_solver(*OPENFOAM, "topoSet"),
]

STATE = Path(__file__).resolve().parents[2] / "results" / "states" / "smoke_1.0s.npz"


def _smoke() -> Case:
    with (CASES / "smoke.toml").open("rb") as fh:
        d = copy.deepcopy(tomllib.load(fh))
    d["air"]["mesh_size"] = 0.03
    return case_from_dict(d)


@pytest.fixture(scope="module")
def smoke_bed_air(tmp_path_factory: pytest.TempPathFactory,
                  ) -> tuple[BedAirResult, list[Path]]:
    case = _smoke()
    state = read_state(STATE)
    check_state(state, case, STATE)
    work = tmp_path_factory.mktemp("bed_air")
    result = solve_bed_air(case, state, work / "openfoam", Runner(), timeout=150)
    return result, write_bed_air(result, work / "out")


@pytest.mark.timeout(180)
def test_the_bed_holds_back_the_air_and_the_flow_is_conserved(
        smoke_bed_air: tuple[BedAirResult, list[Path]]) -> None:
    result, _ = smoke_bed_air
    empty, bed = result.empty.axial_flow_m3_s, result.bed.axial_flow_m3_s
    # Both solutions carry the inlet's flow through the mid section (continuity, face fluxes).
    assert bed["total"] == pytest.approx(empty["total"], rel=0.005)
    assert empty["total"] == pytest.approx(result.empty.inlet_flow_m3_s, rel=0.005)
    # The bed cells pass well under their empty-drum share: the air goes round the bed.
    assert result.category_cells["bed"] > 0
    assert bed["bed"] < 0.75 * empty["bed"]
    assert bed["free"] > empty["free"]
    # Pushing the air round and through the bed costs pressure.
    assert result.bed.pressure_drop_Pa > result.empty.pressure_drop_Pa > 0.0
    # The smoke bed lies inside the drum: the cells get the particles' volume within 2 %.
    assert result.deposit["outside_m3"] == 0.0
    assert result.deposit["cells_over_particles"] == pytest.approx(1.0, abs=0.02)


@pytest.mark.timeout(180)
def test_the_outputs_are_written(smoke_bed_air: tuple[BedAirResult, list[Path]]) -> None:
    result, paths = smoke_bed_air
    assert [p.name for p in paths] == ["split.json", "split.csv", "cross_section.png"]
    data = json.loads(paths[0].read_text())
    assert data["bed"]["pressure_drop_Pa"] == pytest.approx(result.bed.pressure_drop_Pa)
    lines = paths[1].read_text().splitlines()
    assert lines[0] == "solution,quantity,part,value,unit"
    assert len(lines) == 1 + len(result.rows())
    assert paths[2].stat().st_size > 10_000


@pytest.mark.timeout(180)
def test_a_drum_full_of_porosity_meets_ergun_drag(tmp_path: Path) -> None:
    """Every cell one zone at voidage 0.45 with 8 mm granules (d and f by hand from Ergun
    1952), written and solved as the bed case is: in the slice's middle half the fitted
    pressure gradient equals the drag per volume of Ergun's law at the solved cell velocities
    within 5 % (what is left is wall shear and swirl); a law 10 % off on either side fails."""
    from foamlib import FoamFile

    case, runner = _smoke(), Runner()
    eps, dp = 0.45, 0.008
    d = 150.0 * (1 - eps) ** 2 / (eps**3 * dp**2)
    f = 2.0 * 1.75 * (1 - eps) / (eps**3 * dp)

    def prepare(work: Path) -> None:
        n = int(np.asarray(FoamFile(work / "constant/polyMesh/owner")[None]).max()) + 1
        zones = PorosityZones([np.arange(n)], np.array([d]), np.array([f]), np.full(n, d),
                              np.full(n, f))
        write_porosity_options(work, zones)
        write_fv_solution(work, case.air.residual_target, ["p", "U", "k", "epsilon"],
                          consistent=False)
        run_foam(runner, "topoSet", [], work, timeout=60)

    solution = solve_air(case, tmp_path / "full", runner, timeout=150, prepare=prepare)
    cells = read_cell_fields(solution.case_dir, solution.time_dir)
    rho, nu = air_properties_for(case)
    z, U, V = cells["C"][:, 2], cells["U"], cells["V"]
    middle = (z > 0.25 * case.drum.length) & (z < 0.75 * case.drum.length)
    gradient = np.polyfit(z[middle], rho * cells["p"][middle], 1)[0]  # dp/dz > 0: flow to -z
    drag = (rho * nu * d + 0.5 * rho * f * np.linalg.norm(U, axis=1)) * -U[:, 2]
    expected = float(np.sum((drag * V)[middle]) / np.sum(V[middle]))
    assert gradient == pytest.approx(expected, rel=0.05)
