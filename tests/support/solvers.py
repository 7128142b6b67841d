"""What solver tests need to say which programs they run, and the small cases they run.

A test that needs an external program says so with ``@requires_solver("liggghts", "mpirun")``
(or as a module's ``pytestmark``); the hook in ``tests/conftest.py`` skips it when a program is
missing on a developer's machine and fails it under CI (``CI`` set to true, as every CI service
does): a broken install must not turn the solver suite into a pass. The rule is
:mod:`support.requirements`, shared with the Chromium, CoolProp and SLURM tests.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest

from support.requirements import under_ci as under_ci  # re-exported for older imports

ROOT = Path(__file__).resolve().parents[2]
CASES = ROOT / "cases"

#: What each program is, for the message when it is missing.
SOLVER_NAMES = {
    "liggghts": "LIGGGHTS (scripts/install.sh)",
    "mpirun": "an MPI launcher (scripts/install.sh)",
    "simpleFoam": "OpenFOAM (simpleFoam; scripts/install.sh)",
}
LIGGGHTS = ("liggghts", "mpirun")
OPENFOAM = ("simpleFoam",)


def requires_solver(*programs: str) -> pytest.MarkDecorator:
    """Mark a test (or module) as needing these programs on PATH."""
    return pytest.mark.requires_solver(*programs)


def tiny_case_dict(**overrides: Any) -> dict[str, Any]:
    """A very small drum for real-solver tests: 0.2 m, 6 lifters, 500 particles of 8 mm."""
    from drumflow.verify.scenes import tiny_drum_dict

    return tiny_drum_dict(**overrides)
