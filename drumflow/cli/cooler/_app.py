"""The `drumflow cooler` command group: reduced-order models of whole coolers.

Every command here follows the same conventions as `drumflow run`: a validated case file
(every problem names the field, the value and the allowed range), a run directory with a
manifest, ``--json`` for machine-readable output, and the one exit-code rule of
:func:`drumflow.errors.exit_code` applied by :func:`guard`.
"""

from __future__ import annotations

from contextlib import AbstractContextManager

import typer

from drumflow.cli._guard import console, err_console
from drumflow.cli._guard import guard as shared_guard

app = typer.Typer(
    name="cooler",
    no_args_is_help=True,
    pretty_exceptions_enable=False,
    help="Reduced-order models of whole coolers: particle curtain, rotary drum, vibrating "
    "fluid bed with refrigeration, clinker grate cooler (seconds, no solver).",
)
__all__ = ["app", "console", "err_console", "guard"]


def guard() -> AbstractContextManager[None]:
    """Turn drumflow's typed errors and Ctrl-C into one message and the rule's exit code
    (the shared wrapper of every drumflow command, :func:`drumflow.cli._guard.guard`)."""
    return shared_guard(err_console)
