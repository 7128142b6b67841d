"""The generated reference pages follow the code: a key added to the case schema shows up in
the case-file reference with its default and range, every command of ``drumflow --help`` has its
section in the command reference, and every public module gets an API page."""

from __future__ import annotations

import importlib.util
import re
import sys
from pathlib import Path
from types import ModuleType

import typer.main
from pydantic import Field, create_model
from typer.testing import CliRunner

from drumflow.case import Case, Drum

ROOT = Path(__file__).resolve().parents[2]


def _load(name: str) -> ModuleType:
    """A docs/gen module by its path (docs/gen is not a package; a unique name keeps it apart
    from anything else on sys.path)."""
    spec = importlib.util.spec_from_file_location(f"drumflow_docs_{name}", ROOT / "docs/gen" / f"{name}.py")
    assert spec and spec.loader
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module
    spec.loader.exec_module(module)
    return module


reference = _load("reference")


def test_a_field_added_to_a_copy_of_the_schema_appears_with_default_and_range() -> None:
    WiderDrum = create_model(
        "Drum",
        __base__=Drum,
        shell_emissivity=(float, Field(0.85, ge=0.05, lt=1, description="radiating shell, a new key")),
    )
    WiderCase = create_model("Case", __base__=Case, drum=(WiderDrum, ...))
    page = reference.case_reference_markdown(WiderCase)
    row = next(line for line in page.splitlines() if line.startswith("| `shell_emissivity`"))
    assert "`0.85`" in row
    assert ">= 0.05, < 1" in row
    assert "radiating shell, a new key" in row
    # It sits in the [drum] table, not elsewhere.
    drum = page.split("## `[drum]`")[1].split("\n## ")[0]
    assert "`shell_emissivity`" in drum
    assert "`shell_emissivity`" not in reference.case_reference_markdown(Case)


def test_every_key_of_every_table_is_in_the_case_reference() -> None:
    page = reference.case_reference_markdown(Case)
    for key, model, _ in reference._sections(Case):
        section = page.split(f"## `[{key}]`\n")[1].split("\n## ")[0]
        for name, field in model.model_fields.items():
            if reference._section_model(field.annotation) is None:
                assert f"| `{name}` |" in section, f"[{key}] {name}"
    assert "| `rpm` | number | **required** | > 0, <= 60 |" in page
    assert '| `facet_size` | number or "auto" | `"auto"` | > 0; or "auto" |' in page
    assert "## `[contacts.particle_wall]`" in page


def _help_commands(args: list[str]) -> list[str]:
    result = CliRunner().invoke(_app(), [*args, "--help"], env={"COLUMNS": "160"})
    assert result.exit_code == 0, result.output
    # The panel rows: "│ check        Validate a case file ..." (continuation rows are indented).
    return re.findall(r"^│ ([a-z][a-z-]*)\s{2,}\S", result.output, re.M)


def _app() -> typer.Typer:
    from drumflow.cli import app

    return app


def test_every_command_of_drumflow_help_is_in_the_command_reference() -> None:
    page = reference.command_reference_markdown(_app())
    commands = _help_commands([])
    assert {"run", "check", "sweep", "cooler"} <= set(commands) and len(commands) >= 10  # parsed
    for command in commands:
        assert f"`drumflow {command}`\n" in page, command
    for sub in _help_commands(["cooler"]):
        assert f"`drumflow cooler {sub}`\n" in page, sub
    names = reference.command_names(typer.main.get_command(_app()))
    assert set(names) >= {f"drumflow {c}" for c in commands}


def test_options_appear_with_their_defaults() -> None:
    page = reference.command_reference_markdown(_app())
    stop = page.split("`drumflow stop`\n")[1].split("\n### ")[0]
    assert "`--timeout`" in stop and "`600.0`" in stop
    assert "| `RUN_DIR` | yes |" in stop


def test_api_pages_cover_the_public_modules_found_by_walking_the_package() -> None:
    modules = reference.api_modules("drumflow")
    assert "drumflow.case" in modules and "drumflow.errors" in modules
    assert not [m for m in modules if m.startswith("drumflow.cli")]
    assert not [m for m in modules if any(p.startswith("_") for p in m.split("."))]
    on_disk = {
        ".".join(p.relative_to(ROOT).with_suffix("").parts).removesuffix(".__init__")
        for p in (ROOT / "drumflow").rglob("*.py")
    }
    public = {m for m in on_disk if not any(p.startswith("_") for p in m.split("."))
              and not m.startswith("drumflow.cli")}
    assert public - {"drumflow.__main__"} <= set(modules)


def test_the_other_input_files_are_found_by_walking_the_package() -> None:
    from drumflow.case import INPUT_MODEL_CONFIG

    models = reference.input_models(INPUT_MODEL_CONFIG)
    names = {m.__name__ for m in models}
    assert {"Case", "GrateCase", "CurtainCase", "Sweep"} <= names
    assert "Drum" not in names  # a table of a case, not a file
    page = reference.case_reference_markdown(Case, tuple(m for m in models if m is not Case))
    assert "## Grate case files" in page and "## Sweep files" in page
