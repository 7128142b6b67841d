"""The mkdocs-macros module (``module_name`` in mkdocs.yml): gives the pages ``value`` and
``table``, which read the shipped results files when the site is built (docs/gen/doc_numbers.py
says how; docs/contributing/docs.md shows them)."""

from __future__ import annotations

import sys
from pathlib import Path
from typing import Any

# mkdocs-macros loads this file by its path, not as a package: its neighbours come by sys.path.
sys.path.insert(0, str(Path(__file__).resolve().parent))

import doc_numbers  # noqa: E402


def define_env(env: Any) -> None:
    """Register the number macros with mkdocs-macros."""
    env.macro(doc_numbers.value, "value")
    env.macro(doc_numbers.table, "table")
