"""Regression: loading the CLI must not load the numerical stack.

`drumflow post` on model one took 5.0-5.7 s of which 2.2 s was the command's start-up, most of
it scipy.optimize and scipy.stats pulled in by the cooler commands' module-level imports. Each
command now imports what it computes with when it runs; this test fails if a module-level
import brings them back.
"""

from __future__ import annotations

import subprocess
import sys


def test_importing_the_cli_loads_no_numerical_library() -> None:
    code = (
        "import sys, drumflow.cli\n"
        "print(','.join(m for m in ('numpy', 'scipy', 'pandas', 'matplotlib') if m in sys.modules))"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "", f"drumflow.cli loads {out.stdout.strip()} at start-up"


def test_every_cooler_command_is_still_registered() -> None:
    from typer.main import get_command

    from drumflow.cli import app

    cooler = get_command(app).commands["cooler"]  # type: ignore[attr-defined]
    assert {"curtain", "drum", "fluid-bed", "grate"} <= set(cooler.commands)
