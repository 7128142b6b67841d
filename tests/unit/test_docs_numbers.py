"""Numbers that cannot drift: every ``value``/``table`` macro in the documentation pages resolves
against the shipped results files (the same functions render them when the site is built), and
a page quoting a missing file, key, column or row is caught, naming it."""

from __future__ import annotations

import importlib.util
import json
import sys
from pathlib import Path
from types import ModuleType

import pytest

ROOT = Path(__file__).resolve().parents[2]


def _load(name: str) -> ModuleType:
    spec = importlib.util.spec_from_file_location(f"drumflow_docs_{name}", ROOT / "docs/gen" / f"{name}.py")
    assert spec and spec.loader
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module
    spec.loader.exec_module(module)
    return module


numbers = _load("doc_numbers")


def test_every_number_macro_in_the_pages_resolves_against_the_shipped_files() -> None:
    problems = numbers.check_pages(ROOT / "docs", ROOT)
    assert not problems, "\n".join(str(p) for p in problems)


@pytest.fixture()
def results(tmp_path: Path) -> Path:
    (tmp_path / "r").mkdir()
    summary = {"h": {"mean": 76.54021}, "runs": [{"wall_s": 8893.2}]}
    (tmp_path / "r/summary.json").write_text(json.dumps(summary))
    (tmp_path / "r/runtime.csv").write_text(
        "case,median_s,machine\ngrate,0.390957,x86_64\ncurtain,1.5,x86_64\n"
    )
    return tmp_path


def test_value_reads_json_keys_and_csv_rows(results: Path) -> None:
    assert numbers.value("r/summary.json", "h.mean", ".2f", root=results) == "76.54"
    assert numbers.value("r/summary.json", "runs.0.wall_s", ",.0f", root=results) == "8,893"
    assert numbers.value("r/runtime.csv", "grate.median_s", ".2f", root=results) == "0.39"
    assert numbers.value("r/runtime.csv", "median_s", ".1f", row={"case": "curtain"}, root=results) == "1.5"
    assert numbers.value("r/runtime.csv", "machine", row=-1, root=results) == "x86_64"


def test_table_renders_the_columns_asked_for(results: Path) -> None:
    text = numbers.table("r/runtime.csv", columns=["case", "median_s"], fmt={"median_s": ".2f"},
                         headers=["case", "median (s)"], root=results)
    assert text.splitlines() == [
        "| case | median (s) |", "|---|---|", "| grate | 0.39 |", "| curtain | 1.50 |"
    ]


@pytest.mark.parametrize(
    ("call", "named"),
    [
        ('value("r/missing.json", "h.mean")', "r/missing.json"),
        ('value("r/summary.json", "h.median", ".2f")', "'h.median'"),
        ('value("r/runtime.csv", "median_s")', "say which with row="),
        ('value("r/runtime.csv", "grate.wall_s")', "'wall_s'"),
        ('table("r/runtime.csv", columns=["case", "p95_s"])', "'p95_s'"),
        ('value("r/summary.json", some_variable)', "literals"),
    ],
)
def test_a_page_quoting_what_the_files_lack_is_caught_naming_it(results: Path, call: str, named: str) -> None:
    page = f"# A page\n\nThe grate solve takes\n{{{{ {call} }}}} s.\n"
    problems = numbers.check_page(page, "p.md", results)
    assert len(problems) == 1
    assert problems[0].line == 4 and named in problems[0].error, problems[0]


def test_the_macros_module_gives_the_pages_both_macros(monkeypatch: pytest.MonkeyPatch) -> None:
    registered: dict[str, object] = {}

    class Env:
        def macro(self, fn: object, name: str) -> None:
            registered[name] = fn

    # macros.py puts docs/gen on sys.path (as mkdocs-macros loads it): undo that afterwards.
    monkeypatch.setattr(sys, "path", list(sys.path))
    try:
        _load("macros").define_env(Env())
    finally:
        sys.modules.pop("doc_numbers", None)
    assert set(registered) == {"value", "table"}


def test_raw_blocks_show_the_macros_without_quoting_numbers(results: Path) -> None:
    page = '{% raw %}\n{{ value("r/missing.json", "x") }}\n{% endraw %}\n{{ value("r/nope.json", "x") }}\n'
    problems = numbers.check_page(page, "p.md", results)
    assert [(p.line, "r/nope.json" in p.error) for p in problems] == [(4, True)]


def test_a_value_in_another_unit_is_scaled_before_it_is_formatted(tmp_path: Path) -> None:
    (tmp_path / "r.json").write_text(json.dumps({"duty_W": 156709.4}))
    assert numbers.value("r.json", "duty_W", ".0f", scale=1e-3, root=tmp_path) == "157"
    assert numbers.value("r.json", "duty_W", ",.0f", root=tmp_path) == "156,709"
