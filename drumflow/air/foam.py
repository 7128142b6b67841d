"""Running the drum's steady air field with OpenFOAM v1912 ``simpleFoam`` and MRF.

:func:`solve_air` meshes (:mod:`drumflow.air.mesh`), writes the case
(:mod:`drumflow.air.foam_case`, where the model, boundary conditions and numerics are
described), runs simpleFoam (serial or decomposed) through the runner, and reads the result
(:mod:`drumflow.air.foam_results`). The writing and reading names are re-exported here.
"""

from __future__ import annotations

import math
import shutil
import time
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING

from drumflow.runner import Runner

if TYPE_CHECKING:
    from drumflow.case import Case

from drumflow.air.foam_case import (
    CMU,
    MIXING_LENGTH_FRACTION,
    TURBULENCE_INTENSITY,
    air_properties_for,
    inlet_turbulence,
    mid_plane_function,
    write_air_case,
    write_control_dict,
    write_decompose_dict,
    write_fv_schemes,
    write_fv_solution,
    write_initial_fields,
    write_mrf,
    write_transport,
)
from drumflow.air.foam_results import (
    AirSolution,
    IterationCallback,
    ResidualParser,
    latest_time,
    parse_residual_log,
    patch_flux,
    read_boundary_values,
    read_cell_fields,
    read_mid_plane,
)
from drumflow.air.mesh import build_air_mesh, foam_check, run_foam
from drumflow.errors import AirNotConvergedError

__all__ = [
    "CMU",
    "MIXING_LENGTH_FRACTION",
    "TURBULENCE_INTENSITY",
    "AirNotConvergedError",
    "AirSolution",
    "IterationCallback",
    "ResidualParser",
    "air_properties_for",
    "inlet_turbulence",
    "latest_time",
    "mid_plane_function",
    "parse_residual_log",
    "patch_flux",
    "read_boundary_values",
    "read_cell_fields",
    "solve_air",
    "write_air_case",
    "write_cell_centres",
    "write_control_dict",
    "write_decompose_dict",
    "write_fv_schemes",
    "write_fv_solution",
    "write_initial_fields",
    "write_mrf",
    "write_transport",
]


def write_cell_centres(runner: Runner, case_dir: Path, timeout: float | None) -> None:
    """Write cell centres and volumes of the latest time (what :func:`read_cell_fields` reads)."""
    run_foam(
        runner,
        "postProcess",
        ["-funcs", "(writeCellCentres writeCellVolumes)", "-latestTime"],
        case_dir,
        timeout=timeout,
        log_name="log.postProcess.cells",
    )


def solve_air(
    case: Case,
    workdir: Path,
    runner: Runner | None = None,
    *,
    size: float | None = None,
    processes: int = 1,
    timeout: float | None = 3600.0,
    on_iteration: IterationCallback | None = None,
    prepare: Callable[[Path], None] | None = None,
    periodic: bool = False,
) -> AirSolution:
    """Mesh, set up and solve the drum's steady air field; check mass flow and bulk velocity.

    Parameters
    ----------
    case
        The validated case (drum, lifters, air).
    workdir
        The OpenFOAM case directory to create (an existing one is overwritten file by file;
        old time directories are removed).
    runner
        Starts every OpenFOAM program; default a fresh :class:`Runner`.
    size
        Bulk cell size, m; default ``air.mesh_size``.
    processes
        MPI ranks for simpleFoam (1 = serial; more decomposes with the ``simple`` method).
    timeout
        Limit for each program, s.
    on_iteration
        Progress callback, called with (iteration, initial residuals).
    prepare
        Called with ``workdir`` once the case is written, before the solver starts: to add to
        the case (e.g. the bed's porosity zones of :mod:`drumflow.air.bed_air`).
    periodic
        The slice as a piece of a long drum: its ends coupled and the flow held at the case's
        mean velocity (:mod:`drumflow.air.periodic`) instead of an inlet and an outlet.

    Returns
    -------
    AirSolution
        With the residual history also written to ``workdir/residuals.csv``.

    Raises
    ------
    AirNotConvergedError
        When ``air.max_iterations`` pass before every residual is below ``air.residual_target``.
    drumflow.errors.SolverError
        When any OpenFOAM program fails (its log is named in the message).
    """
    runner = runner or Runner()
    started = time.time()
    workdir = Path(workdir)
    workdir.mkdir(parents=True, exist_ok=True)
    for p in list(workdir.iterdir()):
        # Results of an earlier run would be taken for this run's (latest time, processors).
        if p.is_dir() and (_is_time(p.name) or p.name.startswith("processor")
                           or p.name == "postProcessing"):
            shutil.rmtree(p)
    mesh = build_air_mesh(case, workdir, runner, size=size, timeout=timeout, periodic=periodic)
    inputs = write_air_case(case, workdir, mesh, processes=processes)
    if prepare is not None:
        prepare(workdir)
    if periodic:
        from drumflow.air.periodic import make_periodic

        make_periodic(workdir, case.drum.length, float(inputs["bulk_velocity"]))

    parser = ResidualParser(on_iteration)
    solver_started = time.time()
    if processes > 1:
        run_foam(runner, "decomposePar", ["-force"], workdir, timeout=timeout)
        log = workdir / "log.simpleFoam"
        runner.run(
            "simpleFoam",
            runner.profile.mpi_command(["simpleFoam", "-parallel"], processes),
            cwd=workdir,
            log=log,
            timeout=timeout,
            on_line=parser,
            env=runner.profile.openfoam_env(),
            check=foam_check,
        )
        solver_wall = time.time() - solver_started
        run_foam(runner, "reconstructPar", ["-latestTime"], workdir, timeout=timeout)
        # The reconstructed case holds everything; the per-rank copies would only double
        # the disk use and confuse a later serial run of the same directory.
        for p in workdir.glob("processor*"):
            shutil.rmtree(p)
    else:
        log = run_foam(runner, "simpleFoam", [], workdir, timeout=timeout, on_line=parser)
        solver_wall = time.time() - solver_started
    history = parser.finish()
    csv = workdir / "residuals.csv"
    history.to_csv(csv, index=False)

    time_dir = latest_time(workdir)
    write_cell_centres(runner, workdir, timeout)
    rho = inputs["density"]
    cells = read_cell_fields(workdir, time_dir)
    volume = float(cells["V"].sum())
    mean_uz = float((cells["U"][:, 2] * cells["V"]).sum() / volume)
    mid = read_mid_plane(workdir)
    q_in = -patch_flux(workdir, time_dir, "inlet")
    q_out = patch_flux(workdir, time_dir, "outlet")
    last = history.iloc[-1].to_dict() if len(history) else {}
    final = {k: float(v) for k, v in last.items() if k != "iteration" and not math.isnan(v)}
    iterations = int(last.get("iteration", 0))
    solution = AirSolution(
        case_dir=workdir,
        time_dir=time_dir,
        turbulence=case.air.turbulence,
        converged=parser.converged,
        iterations=iterations,
        residual_target=case.air.residual_target,
        final_residuals=final,
        residuals=history,
        residuals_csv=csv,
        wall_time_s=time.time() - started,
        solver_wall_time_s=solver_wall,
        density=rho,
        kinematic_viscosity=inputs["kinematic_viscosity"],
        omega=case.drum.omega,
        volumetric_flow=inputs["volumetric_flow"],
        inlet_mass_flow=rho * q_in,
        outlet_mass_flow=rho * q_out,
        free_area=float(mesh["area_m2"]),
        mean_axial_velocity=-mean_uz,
        mid_plane_axial_velocity=None if mid is None else -mid,
        expected_axial_velocity=inputs["bulk_velocity"],
        processes=processes,
        mesh={**mesh, **{k: v for k, v in inputs.items() if k.startswith("inlet_")},
              "mesh_volume_m3": volume},
    )
    if not parser.converged:
        raise AirNotConvergedError(
            iterations, final, case.air.residual_target, log, solution=solution
        )
    return solution


def _is_time(name: str) -> bool:
    try:
        float(name)
    except ValueError:
        return False
    return name != "0"
