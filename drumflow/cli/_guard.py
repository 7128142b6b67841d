"""The one error wrapper of every drumflow command.

:func:`guard` turns drumflow's typed errors and Ctrl-C into one message on standard error and
the exit code of :func:`drumflow.errors.exit_code` (bad input 2, a failed run 1, interrupted
130); :func:`guard_every_command` puts it around every command of a typer application,
sub-groups included, so no command can forget it. Anything else is a bug and keeps its
traceback.
"""

from __future__ import annotations

import functools
import inspect
import math
import os
import sys
import typing
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from typing import Any

import typer
from rich.console import Console
from rich.markup import escape

from drumflow.errors import DrumflowError, RunStoppedError, exit_code

__all__ = ["cli_console", "console", "err_console", "guard", "guard_every_command"]

#: Width of a command's tables off a terminal (a log, a pipe, a batch job's output): rich's
#: default there is 80 columns, which cut the bench and summary tables' columns to "…".
LOG_WIDTH = 200


def cli_console(stderr: bool = False) -> Console:
    """The console a command writes to: the terminal's width on a terminal (or ``COLUMNS``),
    :data:`LOG_WIDTH` columns in a file or pipe."""
    stream = sys.stderr if stderr else sys.stdout
    wide = not os.environ.get("COLUMNS") and not (hasattr(stream, "isatty") and stream.isatty())
    # emoji=False: rich turns ":name:" into an emoji, so a path, a value or an error message
    # holding such text (a time like 12:30:00, a file "a:smile:b") would print altered.
    return Console(stderr=stderr, width=LOG_WIDTH if wide else None, emoji=False)


#: The two consoles every command prints to: results on standard output, notes, progress and
#: errors on standard error (one pair for the whole command line).
console = cli_console()
err_console = cli_console(stderr=True)


@contextmanager
def guard(console: Console | None = None) -> Iterator[None]:
    """Turn drumflow's typed errors and Ctrl-C into one message and the rule's exit code."""
    out = console or err_console
    try:
        yield
    except RunStoppedError as exc:
        # Asked for (`drumflow stop`, a time limit's warning): an interruption, not an error.
        out.print(escape(str(exc)), highlight=False, soft_wrap=True)
        raise typer.Exit(exit_code(exc)) from None
    except DrumflowError as exc:
        # Escaped: an error's text is plain (a list in brackets, a TOML [section]), not markup.
        # soft_wrap: no line breaks of rich's own inside the message (at COLUMNS=80 it broke
        # "another scene" across two lines, depending on the length of the path before it), so
        # a message can be searched, and a terminal still wraps it for the eye.
        out.print(f"[bold red]error:[/] {escape(str(exc))}", highlight=False, soft_wrap=True)
        raise typer.Exit(exit_code(exc)) from None
    except KeyboardInterrupt as exc:
        out.print("interrupted")
        raise typer.Exit(exit_code(exc)) from None


def option_names(callback: Callable[..., Any]) -> dict[str, str]:
    """The command-line name of each parameter of a typer command (``closures_start`` ->
    ``--start``), from its ``typer.Option`` declarations; parameters without one keep their
    Python name, with dashes."""
    try:
        hints = typing.get_type_hints(callback, include_extras=True)
    except Exception:  # a name only imported for type checking: fall back to the plain names
        hints = {}
    names: dict[str, str] = {}
    for name in inspect.signature(callback).parameters:
        names[name] = "--" + name.rstrip("_").replace("_", "-")
        for meta in getattr(hints.get(name), "__metadata__", ()):
            # In an Annotated typer.Option("--start", ...) the name arrives as its "default".
            given = [*(getattr(meta, "param_decls", None) or ()), getattr(meta, "default", None)]
            decls = [d for d in given if isinstance(d, str) and d.startswith("--")]
            if decls:
                names[name] = decls[0]
            elif type(meta).__name__ == "ArgumentInfo":
                names[name] = name.upper()
    return names


def refuse_non_finite(values: dict[str, Any], names: dict[str, str]) -> None:
    """Refuse ``inf`` and ``nan`` in every number option of a command, before it runs.

    click reads "inf" and "nan" as floats, and a ``min=`` check lets ``nan`` pass where an
    option has none; no option of drumflow means them, so they are bad input here, once for
    every command, rather than a wrong message deep in a model ("allowed below nan rpm").

    Raises
    ------
    AnalysisInputError
        Naming the option (as typed on the command line), its value and what is allowed.
    """
    from drumflow.errors import AnalysisInputError

    for key, value in values.items():
        items = value if isinstance(value, list | tuple) else [value]
        for item in items:
            if isinstance(item, float) and not math.isfinite(item):
                raise AnalysisInputError(names.get(key, key), item, "a finite number (not inf or nan)")


def _guarded(callback: Callable[..., Any]) -> Callable[..., Any]:
    if getattr(callback, "__drumflow_guarded__", False):
        return callback

    names = option_names(callback)

    @functools.wraps(callback)  # typer reads the wrapped signature (options, arguments)
    def wrapper(*args: Any, **kwargs: Any) -> Any:
        with guard():
            refuse_non_finite(kwargs, names)
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
