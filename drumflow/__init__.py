"""drumflow: CFD-DEM studies of flighted rotary-drum coolers.

The pipeline reads like the package: :mod:`drumflow.case` (validated case file) ->
:mod:`drumflow.geometry` (gmsh: walls, fluid mesh) -> :mod:`drumflow.dem` (LIGGGHTS) ->
:mod:`drumflow.air` (OpenFOAM air field) -> :mod:`drumflow.analysis` (observables, the paper's
heat-transfer methodology) -> :mod:`drumflow.report` (plots, HTML). Every external program is
started through :mod:`drumflow.runner`; every run writes into a :mod:`drumflow.rundir`.
"""

from drumflow.case import Case, case_from_dict, load_case
from drumflow.errors import (
    CaseError,
    DrumflowError,
    GeometryError,
    InsertionError,
    LostParticlesError,
    RunDirectoryError,
    SolverError,
    SolverNotFoundError,
    SolverTimeoutError,
    UnstableRunError,
)
from drumflow.pipeline import post_run, run_case

__version__ = "0.1.0"

__all__ = [
    "Case",
    "CaseError",
    "DrumflowError",
    "GeometryError",
    "InsertionError",
    "LostParticlesError",
    "RunDirectoryError",
    "SolverError",
    "SolverNotFoundError",
    "SolverTimeoutError",
    "UnstableRunError",
    "case_from_dict",
    "load_case",
    "post_run",
    "run_case",
]
