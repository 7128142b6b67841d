"""drumflow: CFD-DEM studies of flighted rotary-drum coolers.

The pipeline reads like the package: :mod:`drumflow.case` (validated case file) ->
:mod:`drumflow.geometry` (gmsh: walls, fluid mesh) -> :mod:`drumflow.air` (OpenFOAM air field)
-> :mod:`drumflow.coupling` (how the air acts on the particles) -> :mod:`drumflow.dem`
(LIGGGHTS) -> :mod:`drumflow.analysis` (observables, the paper's heat-transfer methodology) ->
:mod:`drumflow.report` (plots, HTML). Each stage has one entry point, ``<stage>.stage.run``.
Every external program is started through :mod:`drumflow.runner`; every run writes into a
:mod:`drumflow.rundir`.

Importing this package is light: the names below are loaded on first use (module
``__getattr__``), so importing a small module such as :mod:`drumflow.physics.particle_interior`
does not load pandas or the pipeline.
"""

from __future__ import annotations

from importlib import import_module
from typing import TYPE_CHECKING, Any

__version__ = "0.1.0"

#: Public name -> the module that defines it (loaded on first access).
_LAZY = {
    "Case": "drumflow.case",
    "case_from_dict": "drumflow.case",
    "load_case": "drumflow.case",
    "CaseError": "drumflow.errors",
    "DrumflowError": "drumflow.errors",
    "GeometryError": "drumflow.errors",
    "InsertionError": "drumflow.errors",
    "LostParticlesError": "drumflow.errors",
    "RunDirectoryError": "drumflow.errors",
    "SolverError": "drumflow.errors",
    "SolverNotFoundError": "drumflow.errors",
    "SolverTimeoutError": "drumflow.errors",
    "UnstableRunError": "drumflow.errors",
    "post_run": "drumflow.pipeline",
    "run_case": "drumflow.pipeline",
}

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

if TYPE_CHECKING:
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


def __getattr__(name: str) -> Any:
    module = _LAZY.get(name)
    if module is None:
        raise AttributeError(f"module 'drumflow' has no attribute {name!r}")
    value = getattr(import_module(module), name)
    globals()[name] = value  # later lookups skip this function
    return value


def __dir__() -> list[str]:
    return sorted({*globals(), *_LAZY})
