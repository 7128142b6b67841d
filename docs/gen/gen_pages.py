"""Write the generated reference pages into the site (run by mkdocs-gen-files at build time).

* ``reference/case-file.md``: from the pydantic schemas (:class:`drumflow.case.Case`, then the
  cooler case files and the sweep file);
* ``reference/commands.md``: from the command line (``drumflow.cli.app``);
* ``reference/api/<module>.md``: one page per public module of drumflow, found by walking the
  package, each rendered by mkdocstrings; ``reference/api/SUMMARY.md`` is their navigation
  (mkdocs-literate-nav).

Nothing here is written into the source tree: the pages exist only in the build.
"""

from __future__ import annotations

import importlib
import sys
from pathlib import Path

import mkdocs_gen_files

# mkdocs-gen-files runs this file by its path: its neighbour module comes by sys.path.
sys.path.insert(0, str(Path(__file__).resolve().parent))

from reference import (  # noqa: E402
    api_modules,
    case_reference_markdown,
    command_reference_markdown,
    input_models,
)

from drumflow.case import INPUT_MODEL_CONFIG, Case  # noqa: E402
from drumflow.cli import app  # noqa: E402

# The drum case first, then every other file a user writes (cooler cases, sweep files), found
# by their shared input-model settings wherever they live.
others = tuple(m for m in input_models(INPUT_MODEL_CONFIG) if m is not Case)
with mkdocs_gen_files.open("reference/case-file.md", "w") as fh:
    fh.write(case_reference_markdown(Case, others))

with mkdocs_gen_files.open("reference/commands.md", "w") as fh:
    fh.write(command_reference_markdown(app))

nav = mkdocs_gen_files.Nav()
for module in api_modules("drumflow"):
    parts = tuple(module.split("."))
    # A package's page is its folder's index, so that its modules' pages sit under it.
    is_package = hasattr(importlib.import_module(module), "__path__")
    page = Path(*parts[1:], "index.md") if is_package else Path(*parts[1:]).with_suffix(".md")
    nav[parts[1:] or parts] = page.as_posix()
    with mkdocs_gen_files.open(f"reference/api/{page.as_posix()}", "w") as fh:
        fh.write(f"# `{module}`\n\n::: {module}\n")
with mkdocs_gen_files.open("reference/api/SUMMARY.md", "w") as fh:
    fh.writelines(nav.build_literate_nav())
