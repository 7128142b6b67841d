"""The drumflow command line: the only place that prints or exits.

Each command group has its module: :mod:`~drumflow.cli.run` (a run: check, run, status, stop,
post), :mod:`~drumflow.cli.results`, :mod:`~drumflow.cli.paper` and :mod:`~drumflow.cli.export`
(its results), :mod:`~drumflow.cli.models` and :mod:`~drumflow.cli.cooler` (models of the plant
and of whole coolers), :mod:`~drumflow.cli.studies` (sweeps, validation) and
:mod:`~drumflow.cli.checks` (verification and speed). ``drumflow --help`` lists them in that
order, one panel per group.

Exit codes, one rule for every command (:func:`drumflow.errors.exit_code`, applied by
:func:`drumflow.cli._guard.guard_every_command` below): 0 success, 1 a run failed (solver
error, lost particles), 2 bad input (case file, arguments, run directory), 130 interrupted
(rerun the same command to resume).
"""

from __future__ import annotations

import signal
import sys
from collections.abc import Callable
from typing import Any

import typer

from drumflow.cli import checks, models, results, run, studies
from drumflow.cli._guard import console, err_console, guard_every_command
from drumflow.cli.bed_air import bed_air
from drumflow.cli.cooler import app as cooler_app
from drumflow.cli.cooler.drum import drum as plant
from drumflow.cli.export import export
from drumflow.cli.paper import paper

__all__ = ["PANELS", "app", "console", "err_console", "main"]

#: The help's panels, in the order a user works: a run, what it says, models built on runs,
#: studies of many runs, and the checks and speed measurements behind them.
PANELS = ("A run", "Its results", "Models", "Studies", "Checks and speed")

app = typer.Typer(
    add_completion=False,
    no_args_is_help=True,
    pretty_exceptions_enable=False,
    help="CFD-DEM studies of flighted rotary-drum coolers (LIGGGHTS, OpenFOAM).",
)

_COMMANDS: dict[str, list[tuple[str, Callable[..., Any]]]] = {
    "A run": [("check", run.check), ("run", run.run), ("status", run.status), ("stop", run.stop),
              ("post", run.post)],
    "Its results": [("report", results.report), ("paper", paper), ("export", export),
                    ("methodology", results.methodology), ("exchanger", results.exchanger)],
    "Models": [("plant", plant), ("predict", models.predict)],
    "Studies": [("sweep", studies.sweep), ("validate", studies.validate), ("bed-air", bed_air)],
    "Checks and speed": [("verify", checks.verify), ("bench", checks.bench),
                         ("ladder", checks.ladder), ("answer", checks.answer),
                         ("profile", checks.profile)],
}
for _panel in PANELS:
    if _panel == "Models":
        # `drumflow cooler ...`: the group of whole-cooler models, first among the models.
        app.add_typer(cooler_app, name="cooler", rich_help_panel=_panel)
    for _name, _command in _COMMANDS[_panel]:
        app.command(_name, rich_help_panel=_panel)(_command)

# Last, after every command (and the groups above) is registered: one wrapper for all.
guard_every_command(app)


_interrupts = 0


def _interrupt(signum: int, frame: object) -> None:
    """SIGINT and SIGTERM: say once what happens now, then raise KeyboardInterrupt (a coupled run
    writes a restart at its next air update before it stops; a second interrupt stops at once)."""
    global _interrupts
    _interrupts += 1
    if _interrupts == 1:
        sys.stderr.write(f"\n{signal.Signals(signum).name}: stopping (a run with air first writes a "
                         "restart at its next air update; interrupt again to stop at once)\n")
    raise KeyboardInterrupt


def main() -> None:
    """Console-script entry point."""
    # SIGTERM (`kill`, a SLURM time limit, the end of a login session) ends a command as Ctrl-C
    # does: the runner stops the solver's process group and the run resumes from its restart.
    # Python's default would end the CLI at once and leave mpirun and its ranks running.
    signal.signal(signal.SIGTERM, _interrupt)
    # Python installs its Ctrl-C handler only where SIGINT is not ignored (a background job of
    # a script): an ignored SIGINT stays ignored.
    if signal.getsignal(signal.SIGINT) is signal.default_int_handler:
        signal.signal(signal.SIGINT, _interrupt)
    try:
        app()
    except KeyboardInterrupt:  # Ctrl-C outside a command (while parsing arguments)
        sys.exit(130)
