"""The reference pages, generated from the code so that they cannot drift from it.

* :func:`case_reference_markdown`: the case-file reference, from the pydantic schema
  (:class:`drumflow.case.Case` and its sections): every key with its type, default, allowed
  range or choices and description, as the validator enforces them.
* :func:`command_reference_markdown`: the command reference, from the typer application
  (``drumflow.cli.app``): every command and sub-command with its help, arguments and options.
* :func:`api_modules`: the public modules of the package, found by walking it (never a hand
  list, so a module that moves or appears gets its page without an edit here).

Plain functions returning Markdown text, so the unit tests call them on a changed copy of the
schema or the CLI without building the site; ``gen_pages.py`` writes their text into the site.
"""

from __future__ import annotations

import importlib
import inspect
import pkgutil
import re
import types
import typing
from collections.abc import Iterator
from typing import Any, Literal, Union

import annotated_types
from pydantic import BaseModel
from pydantic.fields import FieldInfo
from pydantic_core import PydanticUndefined

# --- case-file reference ----------------------------------------------------------------------


def _cell(text: str) -> str:
    """Text fit for one Markdown table cell: no newlines, no bare pipes."""
    return " ".join(text.split()).replace("|", "\\|")


def _literal(value: object) -> str:
    """A value as it is written in a TOML case file."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, str):
        return f'"{value}"'
    if isinstance(value, float):
        return f"{value:g}" if abs(value) < 1e6 or value == 0 else f"{value:.6g}"
    if isinstance(value, int):
        return f"{value:_}".replace("_", ",") if abs(value) >= 10_000 else str(value)
    return str(value)


def _bounds(metadata: list[Any]) -> list[str]:
    """The range a field's constraints allow, one phrase per constraint."""
    out: list[str] = []
    for m in metadata:
        if isinstance(m, FieldInfo):  # Annotated[float, Field(gt=0)] inside a union
            out += _bounds(list(m.metadata))
        elif isinstance(m, annotated_types.Gt):
            out.append(f"> {_literal(m.gt)}")
        elif isinstance(m, annotated_types.Ge):
            out.append(f">= {_literal(m.ge)}")
        elif isinstance(m, annotated_types.Lt):
            out.append(f"< {_literal(m.lt)}")
        elif isinstance(m, annotated_types.Le):
            out.append(f"<= {_literal(m.le)}")
        elif isinstance(m, annotated_types.MinLen):
            out.append(f"length >= {m.min_length}")
        elif isinstance(m, annotated_types.MaxLen):
            out.append(f"length <= {m.max_length}")
        elif getattr(m, "pattern", None):
            out.append(f"matches `{m.pattern}`")
    return out


def _strip_annotated(tp: Any) -> tuple[Any, list[Any]]:
    if typing.get_origin(tp) is typing.Annotated:
        base, *meta = typing.get_args(tp)
        return base, meta
    return tp, []


def _type_name(tp: Any) -> str:
    """A type as the page says it: number, integer, text, or the written type of a table."""
    simple = {float: "number", int: "integer", bool: "true/false", str: "text", Any: "any"}
    if tp in simple:
        return simple[tp]
    if typing.get_origin(tp) is not None or isinstance(tp, types.UnionType):
        return re.sub(r"\b(?:typing|[a-z_]+(?:\.[a-z_]+)+)\.", "", str(tp))
    return getattr(tp, "__name__", str(tp))


def _type_and_range(annotation: Any, metadata: list[Any]) -> tuple[str, str]:
    """How a field's type reads in the page, and the values it allows.

    The constraints sit on the field (``Field(gt=0)``) or, in a union such as
    ``Positive | Literal["auto"]``, on the member they bound.
    """
    members = (
        list(typing.get_args(annotation))
        if typing.get_origin(annotation) in (Union, types.UnionType)
        else [annotation]
    )
    kinds: list[str] = []
    allowed: list[str] = []
    choices: list[str] = []
    for member in members:
        base, meta = _strip_annotated(member)
        if base is type(None):
            continue  # optional: its default (none) says so
        if typing.get_origin(base) is Literal:
            choices += [_literal(v) for v in typing.get_args(base)]
            continue
        name = _type_name(base)
        kinds.append(name)
        bounds = _bounds(meta or metadata)
        if bounds:
            allowed.append(", ".join(bounds))
    if choices:
        if kinds and not allowed:
            allowed.append(f"any {' or '.join(kinds)}")
        allowed.append(("or " if allowed else "") + ", ".join(choices))
        kinds.append("one of " + ", ".join(choices) if not kinds else ", ".join(choices))
    return " or ".join(kinds), "; ".join(allowed)


def _default(field: FieldInfo) -> str:
    if field.default is PydanticUndefined and field.default_factory is None:
        return "**required**"
    if field.default is None:
        return "none"
    if field.default_factory is not None:
        try:
            made = field.default_factory()  # type: ignore[call-arg]
        except TypeError:  # a factory that needs the other fields
            return "(computed)"
        return f"`{_literal(made)}`" if made in ({}, [], ()) else "(computed)"
    return f"`{_literal(field.default)}`"


def _section_model(annotation: Any) -> type[BaseModel] | None:
    base, _ = _strip_annotated(annotation)
    if inspect.isclass(base) and issubclass(base, BaseModel):
        return base
    return None


def _doc(model: type[BaseModel]) -> str:
    """The model's own docstring (not one inherited from BaseModel), in Markdown."""
    doc = model.__dict__.get("__doc__") or ""
    return inspect.cleandoc(doc).replace("``", "`")


def _sections(model: type[BaseModel], prefix: str = "") -> Iterator[tuple[str, type[BaseModel], str]]:
    """Every table of a case file: (dotted name, model, how it may be left out)."""
    for name, field in model.model_fields.items():
        sub = _section_model(field.annotation)
        if sub is None:
            continue
        key = f"{prefix}{name}"
        presence = "required" if field.is_required() else "optional: leave it out for its defaults"
        yield key, sub, presence
        yield from _sections(sub, f"{key}.")


def _fields_table(model: type[BaseModel]) -> list[str]:
    rows = ["| key | type | default | allowed | meaning |", "|---|---|---|---|---|"]
    for name, field in model.model_fields.items():
        if _section_model(field.annotation) is not None:
            continue
        kind, allowed = _type_and_range(field.annotation, list(field.metadata))
        rows.append(
            f"| `{name}` | {_cell(kind)} | {_cell(_default(field))} | {_cell(allowed)} "
            f"| {_cell(field.description or '')} |"
        )
    return rows if len(rows) > 2 else []


def _model_sections(model: type[BaseModel], level: int) -> list[str]:
    """One input model's top-level keys and tables, headings at ``level``."""
    out: list[str] = []
    h = "#" * level
    top = _fields_table(model)
    if top:
        out += [f"{h} Top level", "", *top, ""]
    for key, sub, presence in _sections(model):
        out += [f"{h} `[{key}]`", "", f"*{presence}*", ""]
        doc = _doc(sub)
        if doc:
            out += [doc, ""]
        out += _fields_table(sub) or ["(only the tables below)"]
        out.append("")
    return out


def _title(model: type[BaseModel]) -> str:
    """"GrateCase" -> "Grate case files"; "Sweep" -> "Sweep files"."""
    words = re.sub(r"(?<=[a-z])(?=[A-Z])", " ", model.__name__).removesuffix(" Case").lower()
    return f"{words.capitalize()} {'case ' if model.__name__.endswith('Case') else ''}files"


def case_reference_markdown(model: type[BaseModel], others: tuple[type[BaseModel], ...] = ()) -> str:
    """The case-file reference page for ``model`` (normally :class:`drumflow.case.Case`).

    One section per TOML table (``[drum]``, ``[contacts.particle_wall]``, ...) in the order of
    the schema, each with the model's docstring and a table of its keys. Only what the schema
    declares goes in: the checks that span keys (a lifter must fit the drum, ...) are in the
    model validators and named in their error messages. ``others`` (the cooler case files, the
    sweep file: :func:`input_models`) follow, each under its own heading.
    """
    out = [
        "# Case-file reference",
        "",
        "<!-- Generated from the pydantic schema by docs/gen/reference.py at build time: "
        "edit the Field descriptions in the code, not this page. -->",
        "",
        f"Generated from `{model.__module__}.{model.__name__}` when the site is built, so it "
        "lists exactly what the validator accepts. A case file is TOML; units are SI unless the "
        "key says otherwise (`tilt_deg`, `rpm`, `..._C`, `..._kPa`). Unknown keys are refused "
        "(a typo must not fall back to a default), and numbers written as text (`rpm = \"5\"`) "
        "are refused. Checks that span several keys (the lifters must fit the drum, the time "
        "step must not exceed the output step, ...) run after these and name the keys they "
        "concern.",
        "",
    ]
    doc = _doc(model)
    if doc:
        out += [doc, ""]
    out += _model_sections(model, 2)
    for other in others:
        out += [f"## {_title(other)}", "", f"`{other.__module__}.{other.__name__}`", ""]
        doc = _doc(other)
        if doc:
            out += [doc, ""]
        out += _model_sections(other, 3)
    return "\n".join(out)


def _nested_types(annotation: Any) -> Iterator[Any]:
    yield annotation
    for arg in typing.get_args(annotation):
        yield from _nested_types(arg)


def input_models(config: Any, package: str = "drumflow") -> list[type[BaseModel]]:
    """The models of the files a user writes (case files, cooler cases, sweep files), found
    by walking the package: every public model with the input models' ``config`` that is not
    a table of another one, in module order."""
    found: list[type[BaseModel]] = []
    for name in api_modules(package, skip=()):
        for obj in vars(importlib.import_module(name)).values():
            if (inspect.isclass(obj) and issubclass(obj, BaseModel) and obj.__module__ == name
                    and not obj.__name__.startswith("_") and obj.model_fields
                    and dict(obj.model_config) == dict(config) and obj not in found):
                found.append(obj)
    tables = {
        t for m in found for f in m.model_fields.values() for t in _nested_types(f.annotation)
        if inspect.isclass(t)
    }
    return [m for m in found if m not in tables]


# --- command reference ------------------------------------------------------------------------


def _param_default(param: Any) -> str:
    default = param.default
    if default is None or callable(default) or getattr(param, "required", False):
        return ""
    if isinstance(default, bool):
        return "" if not default and getattr(param, "is_flag", False) else _literal(default)
    if isinstance(default, list | tuple):
        return ", ".join(str(d) for d in default) if default else ""
    if hasattr(default, "value"):  # an Enum
        default = default.value
    return str(default)


def _context(command: Any, name: str) -> Any:
    # The command's own context class: typer may carry its own copy of click, whose classes
    # are not the installed click's, so nothing here names click's classes.
    return command.context_class(command, info_name=name)


def _subcommands(command: Any, name: str) -> list[tuple[str, Any]]:
    """A group's visible commands in the order its help lists them; none for a command."""
    if not hasattr(command, "list_commands"):
        return []
    ctx = _context(command, name)
    subs = [(n, command.get_command(ctx, n)) for n in command.list_commands(ctx)]
    return [(n, c) for n, c in subs if c is not None and not getattr(c, "hidden", False)]


def _usage(name: str, command: Any) -> str:
    pieces = [name, "[OPTIONS]"]
    for p in command.params:
        if p.param_type_name != "argument":
            continue
        piece = (getattr(p, "metavar", None) or p.name or "").upper()
        piece += "..." if p.nargs == -1 else ""
        pieces.append(piece if p.required else f"[{piece}]")
    if hasattr(command, "list_commands"):
        pieces.append("COMMAND [ARGS]...")
    return " ".join(pieces)


def _command_text(name: str, command: Any, depth: int) -> list[str]:
    """One command's heading, usage, help, arguments and options."""
    heading = "#" * min(depth, 6)
    out = [f"{heading} `{name}`", ""]
    out += ["```", _usage(name, command), "```", ""]
    help_text = inspect.cleandoc(command.help or command.short_help or "")
    if help_text:
        # typer's rich markup marks paragraph breaks with \b; Markdown needs none.
        out += [help_text.replace("\b", "").strip(), ""]
    arguments = [p for p in command.params if p.param_type_name == "argument"]
    options = [p for p in command.params if p.param_type_name == "option" and not p.hidden]
    if arguments:
        out += ["| argument | required | help |", "|---|---|---|"]
        for p in arguments:
            out.append(
                f"| `{(getattr(p, 'metavar', None) or p.name or '').upper()}` "
                f"| {'yes' if p.required else 'no'} | {_cell(getattr(p, 'help', None) or '')} |"
            )
        out.append("")
    if options:
        out += ["| option | default | help |", "|---|---|---|"]
        for p in options:
            flags = ", ".join(f"`{o}`" for o in [*p.opts, *p.secondary_opts])
            default = _param_default(p)
            out.append(
                f"| {flags} | {_cell(f'`{default}`' if default else '')} | {_cell(p.help or '')} |"
            )
        out.append("")
    return out


def _command_section(name: str, command: Any, depth: int) -> list[str]:
    """A command's text, then its sub-commands' one heading level down."""
    out = _command_text(name, command, depth)
    for sub_name, sub in _subcommands(command, name):
        out += _command_section(f"{name} {sub_name}", sub, depth + 1)
    return out


def command_names(command: Any, name: str = "drumflow") -> list[str]:
    """Every command path under ``command`` (``drumflow run``, ``drumflow cooler drum``, ...)."""
    names = [name]
    for sub_name, sub in _subcommands(command, name):
        names += command_names(sub, f"{name} {sub_name}")
    return names


def command_reference_markdown(app: Any, name: str = "drumflow") -> str:
    """The command reference page for a typer application (normally ``drumflow.cli.app``).

    Walks the click commands typer builds: every command in the order ``drumflow --help``
    lists them, its usage line, help, arguments and options with their defaults.
    """
    import typer.main

    command = typer.main.get_command(app)
    out = [
        "# Command reference",
        "",
        "<!-- Generated from the typer application by docs/gen/reference.py at build time: "
        "edit the help texts in drumflow/cli/, not this page. -->",
        "",
        "Generated from the command line itself when the site is built: the same text as "
        f"`{name} COMMAND --help`.",
        "",
    ]
    # The top heading is the page's own; the group's usage and help follow it, then its
    # commands under the help's panels ("A run", "Its results", ...) in the help's order.
    body = _command_text(name, command, 1)[2:]
    panels: dict[str | None, list[tuple[str, Any]]] = {}
    for sub_name, sub in _subcommands(command, name):
        panels.setdefault(getattr(sub, "rich_help_panel", None), []).append((sub_name, sub))
    for panel, subs in panels.items():
        if panel:
            body += [f"## {panel}", ""]
        for sub_name, sub in subs:
            body += _command_section(f"{name} {sub_name}", sub, 3 if panel else 2)
    return "\n".join(out + body)


# --- API reference ----------------------------------------------------------------------------


def api_modules(package: str = "drumflow", skip: tuple[str, ...] = ("cli",)) -> list[str]:
    """The public modules of ``package``, found by walking it: no ``_private`` part, none
    under ``skip`` (the command line has its own reference)."""
    root = importlib.import_module(package)
    names = [package]
    for info in pkgutil.walk_packages(root.__path__, prefix=f"{package}."):
        parts = info.name.split(".")[1:]
        if any(p.startswith("_") for p in parts) or parts[0] in skip:
            continue
        names.append(info.name)
    return sorted(names)
