"""The house rules of issue 37 that a reader can check by looking: what scripts/ holds, how long
a library file may grow, how long a command function may be, and that every study is listed."""

from __future__ import annotations

import ast
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]

#: What a user runs to install, start and test, the cluster start-up and the optional LIGGGHTS
#: build from source; everything else that is run by hand once is a study (studies/).
SCRIPTS = {"install.sh", "quickstart.sh", "test.sh", "slurm_localhost.sh", "build_liggghts.sh"}

#: A module a newcomer reads in one sitting.
MAX_MODULE_LINES = 600
#: A command function parses, calls the library, prints: more than this holds model work.
MAX_COMMAND_LINES = 80


def test_scripts_holds_only_what_a_user_runs() -> None:
    found = {p.name for p in (ROOT / "scripts").iterdir() if p.is_file()}
    assert found == SCRIPTS


def test_every_study_is_listed_in_its_readme() -> None:
    listing = (ROOT / "studies" / "README.md").read_text()
    studies = sorted(p.name for p in (ROOT / "studies").iterdir()
                     if p.suffix in {".py", ".sh"})
    assert [s for s in studies if f"`{s}`" not in listing] == []


def test_no_library_module_is_over_the_limit() -> None:
    long = {str(p.relative_to(ROOT)): n for p in (ROOT / "drumflow").rglob("*.py")
            if (n := len(p.read_text().splitlines())) > MAX_MODULE_LINES}
    assert long == {}


def test_no_command_function_is_over_the_limit() -> None:
    long = []
    for path in (ROOT / "drumflow" / "cli").rglob("*.py"):
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef):
                assert node.end_lineno is not None
                if node.end_lineno - node.lineno + 1 > MAX_COMMAND_LINES:
                    long.append(f"{path.relative_to(ROOT)}:{node.name}")
    assert long == []
