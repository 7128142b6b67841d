"""Numbers that cannot drift: the pages quote measured numbers through two macros that read
the shipped results files when the site is built, and this module both renders them and checks
every page's macros without a build.

``{{ value("results/paper/model_two/summary.json", "h_W_m2K", ".1f") }}``
    One number (or text) from a JSON file (a dotted key path, list indices as numbers:
    ``"runs.0.wall_s"``) or from a CSV file: a column (``"h_W_m2K"``) of its only row, or
    ``"ROW.column"`` for the row whose first column reads ``ROW`` (``"default.h_W_m2K"``), or a
    column with ``row=`` the row index or a ``{"column": value}`` match that must pick exactly
    one row.
``{{ table("docs/grate/runtime.csv", columns=["case", "median_s"], fmt=".2f") }}``
    A Markdown table of a CSV file (or a JSON list of records), its columns in the order given,
    numbers formatted by ``fmt`` (one format for all, or ``{"column": format}``), optionally
    ``headers=["case", "median (s)"]`` and ``where={"column": value}``.

Paths are relative to the repository root. A missing file, key, column or row raises
:class:`NumberSourceError` naming it, which fails ``mkdocs build`` (the macros plugin is set to
stop on errors) and :func:`check_pages` (run by a unit test without a build).

Named ``doc_numbers`` and not ``numbers``: the generation scripts put this folder on
``sys.path``, where a ``numbers.py`` would hide the standard library's module of that name.
"""

from __future__ import annotations

import ast
import csv
import json
import re
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path
from typing import Any

#: The repository root: results paths in the pages are relative to it.
REPO_ROOT = Path(__file__).resolve().parents[2]

#: A call of one of the number macros in a page: ``{{ value(...) }}`` or ``{{ table(...) }}``.
MACRO_CALL = re.compile(r"\{\{-?\s*(value|table)\s*\((.*?)\)\s*-?\}\}", re.DOTALL)


#: A Jinja raw block: what it holds is shown, not rendered, so it quotes no number.
RAW_BLOCK = re.compile(r"\{%-?\s*raw\s*-?%\}.*?\{%-?\s*endraw\s*-?%\}", re.DOTALL)


class NumberSourceError(LookupError):
    """A page quotes a file, key, column or row that the shipped results do not have."""


@lru_cache(maxsize=256)
def _read_json(path: Path) -> Any:
    return json.loads(path.read_text(encoding="utf-8"))


@lru_cache(maxsize=256)
def _read_csv(path: Path) -> tuple[dict[str, str], ...]:
    with path.open(newline="", encoding="utf-8") as fh:
        return tuple(csv.DictReader(fh))


def _path(file: str, root: Path) -> Path:
    path = (root / file).resolve()
    if not path.is_file():
        raise NumberSourceError(f"{file}: no such results file (paths are from the repository root)")
    return path


def _json_key(data: Any, key: str, file: str) -> Any:
    node = data
    for part in key.split(".") if key else []:
        if isinstance(node, Mapping) and part in node:
            node = node[part]
        elif isinstance(node, Sequence) and not isinstance(node, str) and part.lstrip("-").isdigit():
            try:
                node = node[int(part)]
            except IndexError:
                raise NumberSourceError(f"{file}: key {key!r}: index {part} out of range") from None
        else:
            raise NumberSourceError(f"{file}: no key {key!r} (missing part {part!r})")
    return node


def _number(text: str) -> Any:
    """A CSV cell as a number when it reads as one, else the text."""
    try:
        return int(text)
    except ValueError:
        pass
    try:
        return float(text)
    except ValueError:
        return text


def _matches(row: Mapping[str, Any], where: Mapping[str, Any]) -> bool:
    return all(str(row.get(k)) == str(v) or _number(str(row.get(k))) == v for k, v in where.items())


def _records(file: str, root: Path) -> list[dict[str, Any]]:
    path = _path(file, root)
    if path.suffix == ".csv":
        return [{k: _number(v) for k, v in row.items()} for row in _read_csv(path)]
    data = _read_json(path)
    if not (isinstance(data, list) and all(isinstance(r, Mapping) for r in data)):
        raise NumberSourceError(f"{file}: a table needs a CSV file or a JSON list of records")
    return [dict(r) for r in data]


def _format(value: Any, fmt: str | None, scale: float = 1.0) -> str:
    if fmt is None or isinstance(value, str | bool) or value is None:
        return str(value)
    # ``scale`` turns the file's unit into the page's (W -> kW: 1e-3); a number is never rounded
    # by hand on a page.
    return format(value * scale if scale != 1.0 else value, fmt)


def value(file: str, key: str, fmt: str | None = None, *, row: int | Mapping[str, Any] | None = None,
          scale: float = 1.0, root: Path = REPO_ROOT) -> str:
    """One number from a shipped results file, times ``scale`` (a unit change, e.g. 1e-3 for W to
    kW), formatted by ``fmt`` (``".2f"``, ``",.0f"``)."""
    if file.endswith(".csv"):
        rows = _records(file, root)
        if row is None and rows and key not in rows[0] and "." in key:
            # "default.h_W_m2K": the row whose first column reads "default", its column h_W_m2K.
            label, key = key.split(".", 1)
            row = {next(iter(rows[0])): label}
        if row is None:
            if len(rows) != 1:
                raise NumberSourceError(f"{file}: {len(rows)} rows; say which with row=")
            picked = rows[0]
        elif isinstance(row, int):
            if not -len(rows) <= row < len(rows):
                raise NumberSourceError(f"{file}: row {row} out of range ({len(rows)} rows)")
            picked = rows[row]
        else:
            found = [r for r in rows if _matches(r, row)]
            if len(found) != 1:
                raise NumberSourceError(f"{file}: {len(found)} rows match {dict(row)} (need one)")
            picked = found[0]
        if key not in picked:
            raise NumberSourceError(f"{file}: no column {key!r}")
        return _format(picked[key], fmt, scale)
    return _format(_json_key(_read_json(_path(file, root)), key, file), fmt, scale)


def table(file: str, columns: Sequence[str] | None = None, fmt: str | Mapping[str, str] | None = None,
          *, headers: Sequence[str] | None = None, where: Mapping[str, Any] | None = None,
          root: Path = REPO_ROOT) -> str:
    """A Markdown table of a shipped CSV file (or JSON list of records)."""
    rows = _records(file, root)
    if where:
        rows = [r for r in rows if _matches(r, where)]
        if not rows:
            raise NumberSourceError(f"{file}: no row matches {dict(where)}")
    cols = list(columns) if columns else list(rows[0]) if rows else []
    for c in cols:
        if rows and c not in rows[0]:
            raise NumberSourceError(f"{file}: no column {c!r}")
    names = list(headers) if headers else cols
    if len(names) != len(cols):
        raise NumberSourceError(f"{file}: {len(names)} headers for {len(cols)} columns")

    def cell(r: Mapping[str, Any], c: str) -> str:
        f = fmt.get(c) if isinstance(fmt, Mapping) else fmt
        return _format(r[c], f).replace("|", "\\|")

    lines = ["| " + " | ".join(names) + " |", "|" + "---|" * len(cols)]
    lines += ["| " + " | ".join(cell(r, c) for c in cols) + " |" for r in rows]
    return "\n".join(lines)


MACROS: dict[str, Callable[..., str]] = {"value": value, "table": table}


@dataclass(frozen=True)
class Problem:
    """One macro call in a page that does not resolve."""

    page: str
    line: int
    call: str
    error: str

    def __str__(self) -> str:
        return f"{self.page}:{self.line}: {self.call}: {self.error}"


def _arguments(text: str) -> tuple[list[Any], dict[str, Any]]:
    """The literal arguments of a macro call (a Jinja call with literal arguments reads as
    Python)."""
    call = ast.parse(f"f({text})", mode="eval").body
    assert isinstance(call, ast.Call)
    args = [ast.literal_eval(a) for a in call.args]
    kwargs = {k.arg: ast.literal_eval(k.value) for k in call.keywords if k.arg}
    return args, kwargs


def check_page(text: str, page: str = "<page>", root: Path = REPO_ROOT) -> list[Problem]:
    """Every number macro in one page's text that does not resolve against the shipped files."""
    # Raw blocks (examples of the macros' source) become blank lines: line numbers stay right.
    text = RAW_BLOCK.sub(lambda m: "\n" * m.group(0).count("\n"), text)
    problems: list[Problem] = []
    for m in MACRO_CALL.finditer(text):
        line = text.count("\n", 0, m.start()) + 1
        call = " ".join(m.group(0).split())
        try:
            args, kwargs = _arguments(m.group(2))
        except (SyntaxError, ValueError) as exc:
            problems.append(Problem(page, line, call, f"arguments must be literals ({exc})"))
            continue
        try:
            MACROS[m.group(1)](*args, root=root, **kwargs)
        except NumberSourceError as exc:
            problems.append(Problem(page, line, call, str(exc)))
        except (TypeError, ValueError) as exc:  # wrong arguments, a format that does not fit
            problems.append(Problem(page, line, call, f"{type(exc).__name__}: {exc}"))
    return problems


def check_pages(docs_dir: Path = REPO_ROOT / "docs", root: Path = REPO_ROOT) -> list[Problem]:
    """Every number macro of every Markdown page under ``docs_dir`` that does not resolve."""
    problems: list[Problem] = []
    for page in sorted(docs_dir.rglob("*.md")):
        rel = page.relative_to(docs_dir).as_posix()
        problems += check_page(page.read_text(encoding="utf-8"), rel, root)
    return problems


def macro_calls(docs_dir: Path = REPO_ROOT / "docs") -> int:
    """How many number macros the pages under ``docs_dir`` hold."""
    return sum(len(MACRO_CALL.findall(RAW_BLOCK.sub("", p.read_text(encoding="utf-8"))))
               for p in docs_dir.rglob("*.md"))
