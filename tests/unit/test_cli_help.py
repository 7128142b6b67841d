"""`drumflow --help` lists the commands as the work goes: one panel per group, in order."""

from __future__ import annotations

import ast
import inspect
from pathlib import Path

from typer.main import get_command
from typer.testing import CliRunner

import drumflow.cli
from drumflow.cli import PANELS, app

#: The panels in the order a user works, and the commands each one holds.
EXPECTED = {
    "A run": ["check", "run", "status", "stop", "post"],
    "Its results": ["report", "paper", "export", "methodology", "exchanger"],
    "Models": ["plant", "predict", "cooler"],
    "Studies": ["sweep", "validate", "bed-air"],
    "Checks and speed": ["verify", "bench", "ladder", "answer", "profile"],
}


def _help() -> str:
    result = CliRunner().invoke(app, ["--help"], env={"COLUMNS": "160"})
    assert result.exit_code == 0, result.output
    return result.output


def test_help_lists_the_panels_in_the_order_of_the_work() -> None:
    text = _help()
    positions = [text.index(f"─ {panel} ─") for panel in EXPECTED]
    assert positions == sorted(positions), positions
    assert tuple(EXPECTED) == PANELS


def test_each_command_is_listed_in_its_panel() -> None:
    text = _help()
    starts = [text.index(f"─ {panel} ─") for panel in EXPECTED] + [len(text)]
    for (panel, names), start, end in zip(EXPECTED.items(), starts, starts[1:], strict=False):
        listed = [line.strip("│ ").split(" ")[0] for line in text[start:end].splitlines()[1:]]
        assert [n for n in listed if n in names] == names, (panel, listed)


def test_every_command_has_a_panel() -> None:
    commands = get_command(app).commands  # type: ignore[attr-defined]
    grouped = {name for names in EXPECTED.values() for name in names}
    assert set(commands) == grouped


def test_the_three_ways_to_the_plant_say_how_they_differ() -> None:
    """`plant` and `cooler drum` are one command; `predict` is another model: each help says so."""
    commands = get_command(app).commands  # type: ignore[attr-defined]
    drum = commands["cooler"].commands["drum"]
    assert inspect.unwrap(commands["plant"].callback) is inspect.unwrap(drum.callback)
    for command in (commands["plant"], drum, commands["predict"]):
        first = (command.help or "").split("\n\n")[0]
        assert "exchanger" in first or "along its axis" in first, first
    assert "along its axis" in (commands["predict"].help or "").split("\n\n")[0]


def test_no_command_function_over_80_lines_and_no_file_over_600() -> None:
    package = Path(drumflow.cli.__file__).parent
    for path in package.rglob("*.py"):
        source = path.read_text()
        assert len(source.splitlines()) <= 600, path
        for node in ast.walk(ast.parse(source)):
            if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef):
                assert node.end_lineno is not None
                length = node.end_lineno - node.lineno + 1
                assert length <= 80, f"{path.name}: {node.name} is {length} lines"
