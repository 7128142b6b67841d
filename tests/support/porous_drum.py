"""The smoke drum as the air tests solve it, and a drum full of one Ergun zone: shared by
tests/solver/test_bed_air_foam.py and tests/solver/test_bed_heat_foam.py."""

from __future__ import annotations

import copy
import tomllib
from collections.abc import Callable
from pathlib import Path

import numpy as np

from drumflow.air.foam_case import write_fv_solution, write_porosity
from drumflow.air.mesh import run_foam
from drumflow.air.solids_fraction import PorosityZones
from drumflow.case import Case, case_from_dict
from drumflow.runner import Runner
from support.solvers import CASES


def smoke_case(mesh_size: float = 0.03) -> Case:
    """``cases/smoke.toml`` on a coarser air mesh (0.03 m: about 9k tetrahedra)."""
    with (CASES / "smoke.toml").open("rb") as fh:
        d = copy.deepcopy(tomllib.load(fh))
    d["air"]["mesh_size"] = mesh_size
    return case_from_dict(d)


def ergun_by_hand(voidage: float, diameter: float) -> tuple[float, float]:
    """Darcy d (1/m^2) and Forchheimer f (1/m) of Ergun (1952) written out here, independent of
    drumflow's own ErgunLaw: d = 150 (1-eps)^2 / (eps^3 dp^2), f = 2 x 1.75 (1-eps) / (eps^3 dp)."""
    eps, dp = voidage, diameter
    return 150.0 * (1 - eps) ** 2 / (eps**3 * dp**2), 2.0 * 1.75 * (1 - eps) / (eps**3 * dp)


def full_of_porosity(case: Case, runner: Runner, d: float, f: float) -> Callable[[Path], None]:
    """A ``solve_air`` ``prepare`` hook making every cell of the drum one Ergun zone of
    coefficients d, f, solved as the bed case is (plain SIMPLE)."""
    from foamlib import FoamFile

    def prepare(work: Path) -> None:
        n = int(np.asarray(FoamFile(work / "constant/polyMesh/owner")[None]).max()) + 1
        zones = PorosityZones([np.arange(n)], np.array([d]), np.array([f]), np.full(n, d),
                              np.full(n, f))
        write_porosity(work, zones, "fvOptions")
        write_fv_solution(work, case.air.residual_target, ["p", "U", "k", "epsilon"],
                          consistent=False)
        run_foam(runner, "topoSet", [], work, timeout=60)

    return prepare
