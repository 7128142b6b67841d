"""The rule for a test whose requirement from outside the test code is missing (a solver, a
program such as Chromium, a Python package such as CoolProp, a SLURM cluster): it is skipped on a
developer's machine and fails under CI (``CI`` set to true, as every CI service does), with a
message naming what is missing: a broken install must not turn a suite into a pass.

Tests say what they need with markers that the hook in ``tests/conftest.py`` reads:
``requires_solver`` (:mod:`support.solvers`), :func:`requires_program` and
:func:`requires_module`. A fixture that finds out later (the SLURM cluster) calls
:func:`missing` itself.
"""

from __future__ import annotations

import importlib
import os
import shutil
from collections.abc import Iterable
from typing import NoReturn

import pytest

#: What each program is, for the message when it is missing.
PROGRAM_NAMES = {
    "chromium": "Chromium (apt-get install -y chromium; scripts/install.sh)",
    "bash": "bash",
}
#: What each Python package is, for the message when it is missing.
MODULE_NAMES = {
    "CoolProp.CoolProp": "CoolProp (a drumflow dependency: pip install -e '.[test]')",
}


def under_ci() -> bool:
    """True when the ``CI`` environment variable says so (``true``, ``1`` or ``yes``)."""
    return os.environ.get("CI", "").strip().lower() in {"true", "1", "yes"}


def missing(what: str, why: str = "not installed") -> NoReturn:
    """Skip the running test because ``what`` is missing, or fail it under CI.

    The skip reads ``"{why}: {what}"``; the failure ``"missing under CI ({why}): {what}"``.
    """
    if under_ci():
        pytest.fail(f"missing under CI ({why}): {what}; a test that needs it cannot be skipped "
                    "there", pytrace=False)
    pytest.skip(f"{why}: {what}")


def requires_program(*programs: str) -> pytest.MarkDecorator:
    """Mark a test (or module) as needing these programs on PATH."""
    return pytest.mark.requires_program(*programs)


def requires_module(*modules: str) -> pytest.MarkDecorator:
    """Mark a test (or module) as needing these Python modules importable (dotted names)."""
    return pytest.mark.requires_module(*modules)


def missing_programs(programs: Iterable[str]) -> list[str]:
    """The programs of ``programs`` not on PATH, sorted."""
    return sorted({p for p in programs if shutil.which(p) is None})


def missing_modules(modules: Iterable[str]) -> list[str]:
    """The modules of ``modules`` that do not import, sorted: not installed, or installed but
    broken (a compiled extension that does not load is as missing as no package)."""
    out = set()
    for name in modules:
        try:
            importlib.import_module(name)
        except ImportError:
            out.add(name)
    return sorted(out)
