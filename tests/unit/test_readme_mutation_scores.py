"""The README's mutation-score table is the shipped results file's (issue 36: the README gives
the score per module; issue 37: a number in the documentation cannot differ from its file)."""

from __future__ import annotations

import json
import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]


def _readme_rows() -> dict[str, tuple[str, str]]:
    rows = {}
    for line in (ROOT / "README.md").read_text().splitlines():
        m = re.fullmatch(r"\| (\w+) \| `([^`]+)` \| (.+) \|", line)
        if m:
            rows[m.group(1)] = (m.group(2), m.group(3))
    return rows


def test_every_module_of_the_results_file_is_in_the_readme_with_its_score() -> None:
    modules = json.loads((ROOT / "results" / "mutation" / "summary.json").read_text())["modules"]
    rows = _readme_rows()
    assert set(rows) == set(modules)
    assert {k: rows[k][1] for k in modules} == {k: v["score"] for k, v in modules.items()}


def test_the_files_the_table_names_exist() -> None:
    assert [f for f, _ in _readme_rows().values() if not (ROOT / f).is_file()] == []
