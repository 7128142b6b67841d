"""Bad input at the command line, for every command: exit code 2, no traceback, and the
message names what was wrong (the field and its value, the option, or the path).

Each command runs as a real subprocess (``python -m drumflow.cli``) so that what a user sees
on the terminal is what is asserted. Nothing here needs a solver: the input is refused before
anything runs.
"""

from __future__ import annotations

import subprocess
import sys
import tomllib
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest
import tomli_w

CASES = Path(__file__).resolve().parents[2] / "cases"

Setup = Callable[[Path], list[str]]


def _bad_case(tmp_path: Path, name: str, section: str, field: str, value: Any) -> Path:
    """A shipped case file with one field set to a bad value."""
    data = tomllib.loads((CASES / name).read_text())
    data[section][field] = value
    path = tmp_path / f"bad_{name}"
    path.write_text(tomli_w.dumps(data))
    return path


def _smoke_bad(tmp_path: Path) -> str:
    return str(_bad_case(tmp_path, "smoke.toml", "drum", "rpm", -5.0))


def _bad_sweep(tmp_path: Path) -> str:
    data = tomllib.loads((CASES / "sweep_smoke.toml").read_text())
    data["axes"]["drum.rpm"] = [10.0, -15.0]
    path = tmp_path / "bad_sweep.toml"
    path.write_text(tomli_w.dumps(data))
    # The sweep's base case is named relative to the sweep file.
    (tmp_path / "smoke.toml").write_text((CASES / "smoke.toml").read_text())
    return str(path)


SMOKE = str(CASES / "smoke.toml")
CLOSURES = CASES.parent / "docs" / "plant" / "smoke_closures.json"

# (id, command line builder, text the message must contain)
CASES_BAD: list[tuple[str, Setup, list[str]]] = [
    ("run", lambda t: ["run", _smoke_bad(t), "--out", str(t / "run")], ["drum.rpm = -5"]),
    ("bench", lambda t: ["bench", _smoke_bad(t), "--out", str(t / "bench")], ["drum.rpm = -5"]),
    ("post", lambda t: ["post", str(t / "missing_run")], ["missing_run"]),
    ("methodology", lambda t: ["methodology", str(t / "missing_run")], ["missing_run"]),
    ("predict", lambda t: ["predict", str(t / "missing_run"), "--rpm", "10"], ["missing_run"]),
    ("report", lambda t: ["report", str(t / "missing_run"), "--out", str(t / "r.html")], ["missing_run"]),
    ("exchanger_neither", lambda t: ["exchanger", SMOKE, "--h", "40"], ["--area", "--outlet-temperature"]),
    (
        "exchanger_both",
        lambda t: ["exchanger", SMOKE, "--h", "40", "--area", "10", "--outlet-temperature", "40"],
        ["--area", "--outlet-temperature"],
    ),
    ("exchanger_negative_h", lambda t: ["exchanger", SMOKE, "--h", "-40", "--area", "10"], ["h", "-40"]),
    ("sweep", lambda t: ["sweep", _bad_sweep(t), "--check"], ["drum.rpm", "-15"]),
    ("sweep_missing_file", lambda t: ["sweep", str(t / "nope.toml")], ["nope.toml"]),
    (
        "cooler_fluid_bed",
        lambda t: [
            "cooler",
            "fluid-bed",
            str(_bad_case(t, "fluid_bed_npk.toml", "product", "mass_flow", -1.0)),
        ],
        ["product.mass_flow", "-1"],
    ),
    (
        "cooler_grate",
        lambda t: [
            "cooler",
            "grate",
            str(_bad_case(t, "grate_cooler_report.toml", "cooler", "length", -11.0)),
        ],
        ["cooler.length", "-11"],
    ),
    (
        "cooler_curtain",
        lambda t: [
            "cooler",
            "curtain",
            str(_bad_case(t, "curtain_fig3.toml", "solids", "mass_flow", -0.04)),
            "--out", str(t / "curtain"),
        ],
        ["solids.mass_flow", "-0.04"],
    ),
    (
        "cooler_drum",
        lambda t: ["cooler", "drum", str(CLOSURES), "--rpm", "-5", "--out", str(t / "drum")],
        ["--rpm", "-5"],
    ),
    (
        "cooler_drum_negative_start",
        lambda t: ["cooler", "drum", str(CLOSURES), "--start", "-1", "--out", str(t / "drum")],
        ["--start", "-1", ">= 0"],
    ),
    (
        # A closures file was measured over its own window: --start cannot re-measure it.
        "cooler_drum_start_on_a_closures_file",
        lambda t: ["cooler", "drum", str(CLOSURES), "--start", "3", "--out", str(t / "drum")],
        ["--start", "run directory", "window_s"],
    ),
]


def _cooler_commands() -> set[str]:
    from drumflow.cli.cooler._app import app

    return {c.name or (c.callback.__name__ if c.callback else "") for c in app.registered_commands}


@pytest.mark.parametrize(("build", "named"), [pytest.param(b, n, id=i) for i, b, n in CASES_BAD])
def test_bad_input_exits_2_naming_the_field_without_traceback(
    tmp_path: Path,
    build: Setup,
    named: list[str],
) -> None:
    args = build(tmp_path)
    if args[0] == "cooler" and args[1] not in _cooler_commands():
        pytest.fail(f"drumflow cooler {args[1]} is gone: update this test")
    out = subprocess.run(
        [sys.executable, "-m", "drumflow.cli", *args],
        capture_output=True,
        text=True,
        timeout=120,
        check=False,
    )
    text = out.stdout + out.stderr
    assert out.returncode == 2, text
    assert "Traceback" not in text
    # Rich may wrap long lines inside a box: compare with the line breaks and borders removed.
    flat = " ".join(text.replace("│", " ").split())
    for piece in named:
        assert piece in flat, (piece, text)
    # Nothing was run: no run directory was started for a refused case.
    assert not (tmp_path / "run" / "dem").exists()


def test_every_cooler_command_is_covered() -> None:
    """A new ``drumflow cooler`` command must get its bad-input row above."""
    covered = {
        args_id.split("_", 1)[1].replace("_", "-")
        for args_id, *_ in CASES_BAD
        if args_id.startswith("cooler_")
    }
    # 'fit' takes a case and a data file; its case is the fluid-bed one, refused the same way.
    missing = _cooler_commands() - covered - {"fit"}
    assert not missing, f"no bad-input test for: drumflow cooler {', '.join(sorted(missing))}"
