"""Bad sizes and bad numbers at the command line (issue 36, "nothing silent"): sizes whose
allowed maxima multiplied into hours, numbers that are not finite or are written as text,
errors that blamed the wrong field, rich's emoji codes, and refused commands that left files
behind.

Each command runs as a real subprocess (``python -m drumflow.cli``), as in
``test_cli_bad_input.py``: exit code 2, no traceback, and the message names the field(s), the
value and the allowed range or limit. A short time limit makes a command that would run for
hours fail fast instead of hanging the suite.
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
CLOSURES = CASES.parent / "docs" / "plant" / "smoke_closures.json"

#: Seconds a refusal may take: every one here is refused before any model runs.
TIME_LIMIT = 60

Setup = Callable[[Path], list[str]]


def _drumflow(args: list[str]) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-m", "drumflow.cli", *args], capture_output=True,
                          text=True, timeout=TIME_LIMIT, check=False)


def _flat(text: str) -> str:
    # Rich may wrap long lines inside a box: compare with the line breaks and borders removed.
    return " ".join(text.replace("│", " ").split())


def _case(tmp_path: Path, name: str, changes: dict[str, Any], stem: str = "") -> Path:
    """A shipped case file with some ``section.field`` (or top-level) values replaced."""
    data = tomllib.loads((CASES / name).read_text())
    for key, value in changes.items():
        node = data
        *parents, last = key.split(".")
        for part in parents:
            node = node.setdefault(part, {})
        node[last] = value
    path = tmp_path / f"{stem or 'bad'}_{name}"
    path.write_text(tomli_w.dumps(data))
    return path


def _sweep(tmp_path: Path, changes: dict[str, Any]) -> Path:
    """The shipped smoke sweep with some top-level tables replaced, its base case beside it."""
    data = tomllib.loads((CASES / "sweep_smoke.toml").read_text())
    data.update(changes)
    (tmp_path / "smoke.toml").write_text((CASES / "smoke.toml").read_text())
    path = tmp_path / "sweep.toml"
    path.write_text(tomli_w.dumps(data))
    return path


def _curtain(t: Path, changes: dict[str, Any]) -> list[str]:
    return ["cooler", "curtain", str(_case(t, "curtain_fig3.toml", changes)), "--out", str(t / "out")]


def _grate(t: Path, changes: dict[str, Any], *more: str) -> list[str]:
    return ["cooler", "grate", str(_case(t, "grate_cooler_report.toml", changes)),
            "--out", str(t / "out"), *more]


def _drum(*more: str) -> Setup:
    return lambda t: ["cooler", "drum", str(CLOSURES), "--out", str(t / "out"), *more]


# (id, command line builder, text the message must contain)
REFUSED: list[tuple[str, Setup, list[str]]] = [
    # -- 1. sizes whose product ran for hours -------------------------------------------------
    (
        "curtain_elements",
        lambda t: _curtain(t, {"numerics.rows": 100_000, "numerics.columns": 1000}),
        ["numerics.rows = 100,000", "numerics.columns = 1,000", "100,000,000 elements",
         "allowed up to 1,000,000"],
    ),
    (
        "curtain_auto_rows",
        lambda t: _curtain(t, {"numerics.columns": 1000, "solids.fall_velocity": 0.01}),
        ["numerics.rows = 'auto'", "1,350,000 rows", "numerics.columns = 1,000",
         "allowed up to 1,000,000"],
    ),
    (
        "grate_cells",
        lambda t: _grate(t, {"numerics.cells_length": 4000, "numerics.cells_height": 2000}),
        ["numerics.cells_length = 4,000", "numerics.cells_height = 2,000", "8,000,000 cells",
         "allowed up to 1,000,000"],
    ),
    (
        "grate_sweep_work",
        lambda t: _grate(t, {"numerics.max_sweeps": 100_000}),
        ["numerics.max_sweeps = 100,000", "10,800 cells", "cell-sweeps",
         "allowed up to 100,000,000", "up to 2,487"],
    ),
    (
        "grate_vary_study",
        lambda t: _grate(t, {"numerics.cells_length": 1000, "numerics.cells_height": 100,
                             "numerics.max_sweeps": 300}, "--vary", "length=5:15:200"),
        ["--vary cooler.length", "200 values", "20,000,000 cells", "allowed up to 10,000,000"],
    ),
    (
        "sweep_axes_product",
        lambda t: ["sweep", str(_sweep(t, {"axes": {
            "drum.rpm": {"start": 5.0, "stop": 15.0, "num": 30},
            "air.mass_flow": {"start": 0.3, "stop": 0.6, "num": 30},
            "run.time": [1.5, 2.0, 2.5, 3.0, 3.5, 4.0]}})), "--check", "--out", str(t / "out")],
        ["drum.rpm (30)", "air.mass_flow (30)", "run.time (6)", "= 5,400 members",
         "allowed up to 5,000"],
    ),
    (
        "sweep_range_step",
        lambda t: ["sweep", str(_sweep(t, {"axes": {
            "drum.rpm": {"start": 5.0, "stop": 15.0, "step": 1e-4},
            "air.mass_flow": [0.3, 0.44]}})), "--check", "--out", str(t / "out")],
        ["axes.drum.rpm", "'step': 0.0001", "100,001 values", "allowed up to 5,000"],
    ),
    # -- 2. the right blame -------------------------------------------------------------------
    ("drum_length", _drum("--length", "1e300"), ["--length = 1e+300", "allowed > 0 and <= 200"]),
    (
        "sweep_empty_directory_with_out",
        lambda t: (t / "empty").mkdir() or ["sweep", str(t / "empty"), "--check", "--out",
                                              str(t / "out")],
        ["empty", "a directory, not a sweep file", "not a sweep directory"],
    ),
    # -- 3. non-finite numbers, options and case fields ----------------------------------------
    ("drum_rpm_inf", _drum("--rpm", "inf"), ["--rpm = inf", "a finite number"]),
    ("drum_rpm_nan", _drum("--rpm", "nan"), ["--rpm = nan", "a finite number"]),
    ("drum_start_nan", _drum("--start", "nan"), ["--start = nan", "a finite number"]),
    (
        "exchanger_h_inf",
        lambda t: ["exchanger", str(CASES / "smoke.toml"), "--h", "inf", "--area", "10"],
        ["--h = inf", "a finite number"],
    ),
    (
        "case_field_nan",
        lambda t: ["run", str(_case(t, "smoke.toml", {"drum.rpm": float("nan")})),
                   "--out", str(t / "out")],
        ["drum.rpm = nan", "not a finite number"],
    ),
    (
        "curtain_field_inf",
        lambda t: _curtain(t, {"solids.heat_capacity": float("inf")}),
        ["solids.heat_capacity = inf", "not a finite number"],
    ),
    (
        "grate_vary_inf",
        lambda t: _grate(t, {}, "--vary", "length=5:inf:3"),
        ["--vary 'length=5:inf:3'", "finite"],
    ),
    # -- 4. numbers written as text, on every case kind ----------------------------------------
    (
        "text_drum_case",
        lambda t: ["check", str(_case(t, "smoke.toml", {"drum.rpm": "5"}))],
        ["drum.rpm = '5'", "text, not a number"],
    ),
    (
        "text_curtain",
        lambda t: _curtain(t, {"solids.mass_flow": "0.04"}),
        ["solids.mass_flow = '0.04'", "text, not a number"],
    ),
    (
        "text_fluid_bed",
        lambda t: ["cooler", "fluid-bed", str(_case(t, "fluid_bed_npk.toml",
                                                     {"product.mass_flow": "13.9"})),
                   "--out", str(t / "out")],
        ["product.mass_flow = '13.9'", "text, not a number"],
    ),
    (
        "text_grate",
        lambda t: _grate(t, {"numerics.cells_length": "120"}),
        ["numerics.cells_length = '120'", "text, not an integer"],
    ),
    (
        "text_sweep",
        lambda t: ["sweep", str(_sweep(t, {"runs": {"processes": "1"}})), "--check",
                   "--out", str(t / "out")],
        ["runs.processes = '1'", "text, not an integer"],
    ),
    # -- 6. refusals after which nothing is left (the time step is checked after the case) -----
    (
        "run_time_step_above_limit",
        lambda t: ["run", str(_case(t, "smoke.toml", {"run.time_step": 0.01})),
                   "--out", str(t / "out")],
        ["run.time_step = 0.01", "stability limit"],
    ),
    (
        "sweep_more_ranks_than_cores",
        lambda t: ["sweep", str(_sweep(t, {"runs": {"processes": 1024}})), "--out", str(t / "out")],
        ["runs.processes = 1024", "allowed: 1 to"],
    ),
]


@pytest.mark.parametrize(("build", "named"), [pytest.param(b, n, id=i) for i, b, n in REFUSED])
def test_refused_with_exit_2_naming_field_value_and_limit_leaving_nothing(
    tmp_path: Path,
    build: Setup,
    named: list[str],
) -> None:
    args = build(tmp_path)
    out = _drumflow(args)
    text = out.stdout + out.stderr
    assert out.returncode == 2, text
    assert "Traceback" not in text
    flat = _flat(text)
    for piece in named:
        assert piece in flat, (piece, text)
    # A refused command leaves nothing behind: no output folder was made.
    assert not (tmp_path / "out").exists(), sorted(p.name for p in (tmp_path / "out").iterdir())


def test_refused_run_leaves_an_existing_folder_unchanged(tmp_path: Path) -> None:
    out_dir = tmp_path / "mine"
    out_dir.mkdir()
    (out_dir / "notes.txt").write_text("keep me")
    case = _case(tmp_path, "smoke.toml", {"run.time_step": 0.01})
    result = _drumflow(["run", str(case), "--out", str(out_dir)])
    assert result.returncode == 2, result.stderr
    assert sorted(p.name for p in out_dir.iterdir()) == ["notes.txt"]


def test_refused_drum_writes_no_closures_file(tmp_path: Path) -> None:
    saved = tmp_path / "closures.json"
    # The model refuses this feed (the hold-up would fill the drum) after the closures load.
    result = _drumflow(["cooler", "drum", str(CLOSURES), "--feed-rate", "1000", "--save-closures",
                        str(saved), "--out", str(tmp_path / "out")])
    assert result.returncode == 2, result.stdout + result.stderr
    assert "feed_rate_kg_s = 1000" in _flat(result.stderr)
    assert not saved.exists() and not (tmp_path / "out").exists()


def test_integers_stay_accepted_for_float_fields(tmp_path: Path) -> None:
    """Strict types refuse text, not an integer where a float is expected (rpm = 15)."""
    from drumflow.case import load_case
    from drumflow.coolers.curtain import CurtainCase
    from drumflow.coolers.fluid_bed_case import load_fluid_bed_case
    from drumflow.coolers.grate.case import load_grate_case
    from drumflow.sweep.spec import load_sweep

    assert load_case(_case(tmp_path, "smoke.toml", {"drum.rpm": 15})).drum.rpm == 15.0
    data = tomllib.loads((CASES / "curtain_fig3.toml").read_text())
    data["solids"]["density"] = 2640
    assert CurtainCase.model_validate(data).solids.density == 2640.0
    bed = load_fluid_bed_case(_case(tmp_path, "fluid_bed_npk.toml", {"product.mass_flow": 14}))
    assert bed.product.mass_flow == 14.0
    grate = load_grate_case(_case(tmp_path, "grate_cooler_report.toml", {"cooler.length": 11}))
    assert grate.cooler.length == 11.0
    sweep, _, members = load_sweep(_sweep(tmp_path, {"axes": {"drum.rpm": [10, 15]}}))
    assert [m.case.drum.rpm for m in members] == [10.0, 15.0]


def test_a_range_on_an_integer_field_gives_integers(tmp_path: Path) -> None:
    """The strict case model takes only integers for lifters.count: a range's whole-number
    values are passed as integers."""
    from drumflow.sweep.spec import load_sweep

    _, _, members = load_sweep(_sweep(tmp_path, {"axes": {
        "lifters.count": {"start": 6, "stop": 8, "num": 2}}}))
    assert [m.case.lifters.count for m in members] == [6, 8]


def test_rich_prints_emoji_codes_as_written(tmp_path: Path) -> None:
    """A path holding ``:smile:`` is printed as typed, not as an emoji."""
    missing = tmp_path / "run:smile:here"
    result = _drumflow(["post", str(missing)])
    assert result.returncode == 2
    assert "run:smile:here" in _flat(result.stdout + result.stderr)
    assert "\N{SMILING FACE WITH OPEN MOUTH AND SMILING EYES}" not in result.stderr


def test_every_cli_console_is_made_without_emoji() -> None:
    """Every command's console comes from cli_console, which turns emoji codes off."""
    import drumflow.cli as cli
    import drumflow.cli.cooler._app as cooler
    import drumflow.cli.studies as studies

    consoles = [cli.console, cli.err_console, cooler.console, cooler.err_console,
                studies.console, studies.err_console]
    for console in consoles:
        assert console._emoji is False
    package = Path(cli.__file__).parent
    made_here = [p.name for p in package.rglob("*.py") if "Console(" in p.read_text()]
    assert made_here == ["_guard.py"], made_here
