"""The README stays what a newcomer needs on a few screens (issue 37): at most 250 lines, and it
keeps the two commands that install and run drumflow on a fresh machine, exactly as
scripts/ has them. The rest of the documentation lives in the site under docs/."""

from __future__ import annotations

from pathlib import Path

README = Path(__file__).resolve().parents[2] / "README.md"
ROOT = README.parent

#: The two commands a newcomer runs, as the README's "Two commands" section gives them.
TWO_COMMANDS = ("bash scripts/quickstart.sh", "bash scripts/test.sh")

MAX_LINES = 250


def test_readme_is_at_most_250_lines() -> None:
    lines = README.read_text(encoding="utf-8").splitlines()
    assert len(lines) <= MAX_LINES, (
        f"README.md has {len(lines)} lines (at most {MAX_LINES}): move the detail into a page "
        "under docs/ and point to it")


def test_readme_gives_the_two_commands_and_they_exist() -> None:
    text = README.read_text(encoding="utf-8")
    for command in TWO_COMMANDS:
        assert command in text, f"README.md lost the command {command!r}"
        script = ROOT / command.split()[1]
        assert script.is_file(), f"{command!r}: {script} does not exist"


def test_readme_says_where_the_documentation_is() -> None:
    text = README.read_text(encoding="utf-8")
    assert "mkdocs serve" in text and "mkdocs build" in text
    for page in ("docs/getting-started.md", "docs/paper.md", "docs/benchmarks.md"):
        assert page in text, f"README.md does not point to {page}"
        assert (ROOT / page).is_file(), f"README.md points to {page}, which does not exist"
