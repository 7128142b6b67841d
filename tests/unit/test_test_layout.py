"""The test tree itself: pytest imports test modules by basename (no packages), so two test files
with one name in different folders stop the whole run at collection."""

from __future__ import annotations

import ast
from collections import Counter
from pathlib import Path


def test_no_two_test_files_share_a_name() -> None:
    # Regression: tests/unit/test_profile.py beside tests/solver/test_profile.py failed CI at
    # collection ("import file mismatch") although each passed when run on its own.
    root = Path(__file__).resolve().parents[1]
    names = Counter(p.name for p in root.rglob("test_*.py"))
    assert [name for name, n in names.items() if n > 1] == []


def _imports(tree: ast.Module) -> set[str]:
    found = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            found |= {a.name.split(".")[0] for a in node.names}
        elif isinstance(node, ast.ImportFrom) and node.module:
            found.add(node.module.split(".")[0])
    return found


def test_shipped_file_tests_run_no_code_and_are_marked() -> None:
    """tests/shipped: tests that only read shipped files (issue 36). They import neither
    drumflow nor the test helpers (which run drumflow), carry the ``shipped`` marker, and
    the marker is used nowhere else."""
    root = Path(__file__).resolve().parents[1]
    shipped = sorted((root / "shipped").glob("test_*.py"))
    assert shipped
    for path in shipped:
        text = path.read_text()
        assert {"drumflow", "support", "scripts"}.isdisjoint(_imports(ast.parse(text))), path.name
        assert "pytestmark = pytest.mark.shipped" in text, path.name
    elsewhere = [p.name for p in root.rglob("*.py") if p.parent.name != "shipped"
                 and p != Path(__file__).resolve() and "pytest.mark.shipped" in p.read_text()]
    assert elsewhere == []
