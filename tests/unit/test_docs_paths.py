"""Every repository path the README and the documentation pages name in code style exists
(issue 37, item 7): a module that moves, a study that is renamed or a results file that is
dropped fails here, naming the page, the line and the path, instead of leaving a newcomer a
dead pointer.

What counts as a path: a token inside backticks (inline code, or a line of a fenced code block)
that starts with ``drumflow/``, ``scripts/``, ``studies/``, ``results/``, ``docs/``, ``cases/``
or ``tests/``. Trailing punctuation (``.,;:)``) is dropped, and a trailing ``/`` names a folder.

Skipped, because they name a family of paths rather than one file:

- placeholders and patterns: tokens holding ``<`` or ``>`` (``drumflow/coolers/<name>.py``),
  ``*`` (``docs/*.md``), ``{`` or ``}`` (``docs/grate/{a,b}.csv``), ``$`` or ``%``;
- tokens holding an upper-case placeholder word used by the pages for a run directory or a
  file the reader chooses: ``RUN_DIR``, ``RUN``, ``DIR``, ``OUT``, ``STEP``, ``NAME``, ``CASE``,
  ``SPEC``, ``FILE``, ``HALF``, ``OLD``;
- paths under ``runs/`` or ``site/`` (what a run or a build writes; they do not start with the
  prefixes above, so they are never collected).

The generation scripts' folder ``docs/gen/`` is not a page and is not read.
"""

from __future__ import annotations

import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]

#: Where a code-styled path may start.
PREFIXES = ("drumflow/", "scripts/", "studies/", "results/", "docs/", "cases/", "tests/")

#: Characters that make a token a pattern or placeholder rather than one path.
PLACEHOLDER_CHARS = set("<>*{}$%")

#: Upper-case words the pages use for paths the reader chooses.
PLACEHOLDER_WORDS = re.compile(
    r"(?<![A-Za-z])(RUN_DIR|RUN|DIR|OUT|STEP|NAME|CASE|SPEC|FILE|HALF|OLD)(?![a-z])")

INLINE_CODE = re.compile(r"`([^`\n]+)`")
FENCE = re.compile(r"^\s*(```|~~~)")


def pages() -> list[Path]:
    """README.md and every Markdown page under docs/ (not the generation scripts' folder)."""
    found = [ROOT / "README.md"]
    found += sorted(p for p in (ROOT / "docs").rglob("*.md")
                    if "gen" not in p.relative_to(ROOT / "docs").parts)
    return found


def _tokens(code: str) -> list[str]:
    out = []
    for raw in code.split():
        token = raw.strip("'\"").rstrip(".,;:)").lstrip("(")
        if token.startswith(PREFIXES):
            out.append(token)
    return out


def code_paths(text: str) -> list[tuple[int, str]]:
    """(line, path) for every code-styled repository path in a page's text."""
    found: list[tuple[int, str]] = []
    in_fence = False
    for number, line in enumerate(text.splitlines(), 1):
        if FENCE.match(line):
            in_fence = not in_fence
            continue
        if in_fence:
            found += [(number, t) for t in _tokens(line)]
            continue
        for m in INLINE_CODE.finditer(line):
            found += [(number, t) for t in _tokens(m.group(1))]
    return found


def is_placeholder(path: str) -> bool:
    """A pattern or a path with a placeholder in it: names no single file (see the docstring)."""
    return bool(PLACEHOLDER_CHARS & set(path)) or bool(PLACEHOLDER_WORDS.search(path))


def missing_paths(page: Path, root: Path = ROOT) -> list[str]:
    """The code-styled paths of one page that do not exist under ``root``."""
    rel = page.relative_to(root).as_posix() if page.is_relative_to(root) else page.name
    return [f"{rel}:{line}: `{path}` does not exist"
            for line, path in code_paths(page.read_text(encoding="utf-8"))
            if not is_placeholder(path) and not (root / path.rstrip("/")).exists()]


@pytest.mark.parametrize("page", pages(), ids=lambda p: p.relative_to(ROOT).as_posix())
def test_every_path_a_page_names_exists(page: Path) -> None:
    missing = missing_paths(page)
    assert not missing, ("\n".join(missing)
                         + "\n(moved? name its new home; a pattern? see this test's docstring)")


def test_the_pages_name_paths_at_all() -> None:
    """The extraction finds what the pages hold (so an empty pass cannot hide a broken regex)."""
    named = [p for page in pages() for _, p in code_paths(page.read_text(encoding="utf-8"))]
    assert len(named) > 50
    assert any(n.startswith("results/paper/") for n in named)


def test_a_missing_path_is_caught_and_placeholders_are_not(tmp_path: Path) -> None:
    (tmp_path / "drumflow").mkdir()
    (tmp_path / "drumflow/here.py").write_text("")
    page = tmp_path / "page.md"
    page.write_text(
        "See `drumflow/here.py` and `drumflow/gone.py`, `drumflow/coolers/<name>.py`, `docs/*.md`,\n"
        "`drumflow cooler drum RUN_DIR --save-closures results/x/OUT.json`.\n"
        "```console\n$ python studies/missing_study.py runs/a\n```\n",
        encoding="utf-8")
    missing = missing_paths(page, tmp_path)
    assert missing == ["page.md:1: `drumflow/gone.py` does not exist",
                       "page.md:4: `studies/missing_study.py` does not exist"]
