"""The one error wrapper of every drumflow command.

:func:`guard` turns drumflow's typed errors and Ctrl-C into one message on standard error and
the exit code of :func:`drumflow.errors.exit_code` (bad input 2, a failed run 1, interrupted
130); :func:`guard_every_command` puts it around every command of a typer application,
sub-groups included, so no command can forget it. Anything else is a bug and keeps its
traceback.
"""

from __future__ import annotations

import functools
import os
import sys
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from typing import Any

import typer
from rich.console import Console
from rich.markup import escape

from drumflow.errors import DrumflowError, RunStoppedError, exit_code

__all__ = ["cli_console", "guard", "guard_every_command"]

#: Width of a command's tables off a terminal (a log, a pipe, a batch job's output): rich's
#: default there is 80 columns, which cut the bench and summary tables' columns to "…".
LOG_WIDTH = 200


def cli_console(stderr: bool = False) -> Console:
    """The console a command writes to: the terminal's width on a terminal (or ``COLUMNS``),
    :data:`LOG_WIDTH` columns in a file or pipe."""
    stream = sys.stderr if stderr else sys.stdout
    wide = not os.environ.get("COLUMNS") and not (hasattr(stream, "isatty") and stream.isatty())
    return Console(stderr=stderr, width=LOG_WIDTH if wide else None)


_err_console = cli_console(stderr=True)


@contextmanager
def guard(console: Console | None = None) -> Iterator[None]:
    """Turn drumflow's typed errors and Ctrl-C into one message and the rule's exit code."""
    out = console or _err_console
    try:
        yield
    except RunStoppedError as exc:
        # Asked for (`drumflow stop`, a time limit's warning): an interruption, not an error.
        out.print(escape(str(exc)), highlight=False)
        raise typer.Exit(exit_code(exc)) from None
    except DrumflowError as exc:
        # Escaped: an error's text is plain (a list in brackets, a TOML [section]), not markup.
        out.print(f"[bold red]error:[/] {escape(str(exc))}", highlight=False)
        raise typer.Exit(exit_code(exc)) from None
    except KeyboardInterrupt as exc:
        out.print("interrupted")
        raise typer.Exit(exit_code(exc)) from None


def _guarded(callback: Callable[..., Any]) -> Callable[..., Any]:
    if getattr(callback, "__drumflow_guarded__", False):
        return callback

    @functools.wraps(callback)  # typer reads the wrapped signature (options, arguments)
    def wrapper(*args: Any, **kwargs: Any) -> Any:
        with guard():
            return callback(*args, **kwargs)

    wrapper.__drumflow_guarded__ = True  # type: ignore[attr-defined]
    return wrapper


def guard_every_command(app: typer.Typer) -> None:
    """Wrap every registered command of ``app`` and of its sub-groups in :func:`guard`."""
    for command in app.registered_commands:
        if command.callback is not None:
            command.callback = _guarded(command.callback)
    for group in app.registered_groups:
        if group.typer_instance is not None:
            guard_every_command(group.typer_instance)
