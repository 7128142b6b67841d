"""The clinker grate cooler: a cross-flow finite-volume model solved line by line with the
tri-diagonal matrix algorithm, after the IIT Madras / NCL Pune report (Mundhara, Sharma and
Ranade 2005).

- :mod:`~drumflow.coolers.grate.case`: the validated TOML case.
- :mod:`~drumflow.coolers.grate.properties`: clinker, the packed-bed correlation, Ergun, the
  bed top's radiation (the hot air is :mod:`drumflow.physics.air`'s kelvin view).
- :mod:`~drumflow.coolers.grate.fans`: air flow limited by the bed (Ergun against a fan curve).
- :mod:`~drumflow.coolers.grate.tdma`: the tri-diagonal line solver.
- :mod:`~drumflow.coolers.grate.model`: balance cells, boundary conditions, sweeps.
- :mod:`~drumflow.coolers.grate.solution`: the converged fields and headline numbers.
- :mod:`~drumflow.coolers.grate.studies`: parameter and grid studies.
- :mod:`~drumflow.coolers.grate.plots`: the report-style figures and CSV tables.
"""

from drumflow.coolers.grate.case import GrateCase, grate_case_from_dict, load_grate_case
from drumflow.coolers.grate.model import GrateConvergenceError, solve_grate
from drumflow.coolers.grate.solution import GrateSolution
from drumflow.coolers.grate.studies import grid_study, parse_vary, run_sweep
from drumflow.coolers.grate.tdma import tdma

__all__ = [
    "GrateCase",
    "GrateConvergenceError",
    "GrateSolution",
    "grate_case_from_dict",
    "grid_study",
    "load_grate_case",
    "parse_vary",
    "run_sweep",
    "solve_grate",
    "tdma",
]
