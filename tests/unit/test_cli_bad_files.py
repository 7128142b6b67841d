"""Damaged files, for every reader a command goes through (issue 36, "nothing silent"): exit
code 2, no traceback, and the message names the file and what is wrong with it (not UTF-8,
cut short, empty, NaN or a word where a number belongs, a file where a folder belongs).

Each command runs as a real subprocess (``python -m drumflow.cli``), as in
``test_cli_bad_input.py``. Run-directory fixtures are the shipped results of paper model two
(``results/paper/model_two``) copied into ``tmp_path`` with one file damaged; nothing here needs
a solver. The readers of :mod:`drumflow.readers` are tested directly at the end.
"""

from __future__ import annotations

import gzip
import json
import math
import os
import shutil
import subprocess
import sys
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest

from drumflow.errors import BadFileError

ROOT = Path(__file__).resolve().parents[2]
CASES = ROOT / "cases"
SHIPPED = ROOT / "results" / "paper" / "model_two"
CLOSURES = ROOT / "docs" / "plant" / "smoke_closures.json"
FLUID_BED = CASES / "fluid_bed_npk.toml"
WEATHER = ROOT / "drumflow" / "coolers" / "data" / "salamanca_aemet_1981_2010.csv"

Setup = Callable[[Path], list[str]]


def _drumflow(*args: str, timeout: float = 300) -> subprocess.CompletedProcess[str]:
    # Wide lines: rich would break a long tmp_path inside the file name it must show.
    env = {**os.environ, "COLUMNS": "2000"}
    return subprocess.run([sys.executable, "-m", "drumflow.cli", *args], capture_output=True,
                          text=True, timeout=timeout, check=False, env=env)


def _flat(text: str) -> str:
    # Rich may wrap long lines inside a box: compare with the line breaks and borders removed.
    return " ".join(text.replace("│", " ").split())


def _shipped_copy(tmp: Path, name: str = "model_two") -> Path:
    """The shipped results of model two, pictures left out (nothing here reads them)."""
    target = tmp / name
    shutil.copytree(SHIPPED, target, ignore=shutil.ignore_patterns("*.png", "*.gif"))
    return target


def _cut(path: Path, keep: float = 0.5) -> None:
    """Cut a file to a share of its bytes (a copy interrupted, a disk full)."""
    data = path.read_bytes()
    path.write_bytes(data[: int(len(data) * keep)])


def _cut_lines(path: Path, keep: float = 0.5) -> None:
    """Cut a table at a line boundary: what is left reads as a shorter, valid table."""
    lines = path.read_text().splitlines(keepends=True)
    path.write_text("".join(lines[: int(len(lines) * keep)]))


# ------------------------------------------------------------------ input files (argument)


def _toml_not_utf8(t: Path) -> list[str]:
    path = t / "latin1.toml"
    path.write_bytes(CASES.joinpath("smoke.toml").read_bytes() + "# caf\xe9\n".encode("latin-1"))
    return ["check", str(path)]


def _points_not_utf8(t: Path) -> list[str]:
    path = t / "points.csv"
    path.write_bytes(b"t_ambient_C,rh_pct,t_product_in_C,t_cooled_air_C,t_product_out_C,t_air_out_C\n"
                     b"20,50,60,,30,40\n# \xff\n")
    return ["cooler", "fit", str(FLUID_BED), str(path), "--out", str(t / "fit")]


def _fluid_bed_with_weather(t: Path, weather: bytes) -> list[str]:
    table = t / "weather.csv"
    table.write_bytes(weather)
    case = t / "fluid_bed.toml"
    case.write_text(FLUID_BED.read_text().replace('table = "salamanca"', f'table = "{table}"'))
    return ["cooler", "fluid-bed", str(case), "--month", "1", "--out", str(t / "fb")]


def _weather_not_utf8(t: Path) -> list[str]:
    return _fluid_bed_with_weather(t, WEATHER.read_bytes().replace(b"January", b"Jan\xe9"))


def _weather_nan(t: Path) -> list[str]:
    lines = WEATHER.read_text().splitlines()
    out = []
    for line in lines:
        if line.startswith("1,"):
            cells = line.split(",")
            cells[2] = "nan"  # t_mean_C of January
            line = ",".join(cells)
        out.append(line)
    return _fluid_bed_with_weather(t, ("\n".join(out) + "\n").encode())


def _closures(t: Path, **changes: object) -> Path:
    data = json.loads(CLOSURES.read_text())
    data.update(changes)
    path = t / "closures.json"
    # allow_nan: the file a buggy writer (json.dumps' default) would leave.
    path.write_text(json.dumps(data, allow_nan=True))
    return path


def _closures_not_utf8(t: Path) -> Path:
    path = t / "closures.json"
    path.write_bytes(CLOSURES.read_bytes().replace(b'"smoke"', b'"sm\xffoke"'))
    return path


# ------------------------------------------------------------------ run directories


def _manifest_cut(t: Path) -> list[str]:
    run = _shipped_copy(t)
    _cut(run / "manifest.json", 0.1)
    return ["status", str(run)]


def _air_heat_empty(t: Path) -> list[str]:
    run = _shipped_copy(t / "from")
    (run / "post" / "air_heat.csv").write_text("")
    return ["paper", "--from", str(t / "from"), "--model", "two", "--out", str(t / "out"), "--no-3d"]


def _summary_cut(t: Path) -> list[str]:
    run = _shipped_copy(t / "from")
    _cut(run / "summary.json", 0.3)
    return ["paper", "--from", str(t / "from"), "--model", "two", "--out", str(t / "out"), "--no-3d"]


def _series_cut(command: str) -> Setup:
    def build(t: Path) -> list[str]:
        run = _shipped_copy(t)
        _cut_lines(run / "post" / "mean_temperature.csv", 0.5)
        if command == "report":
            return ["report", str(run), "--out", str(t / "r.html"), "--no-3d"]
        if command == "paper":
            return ["paper", "--from", str(t), "--model", "two", "--out", str(t / "out"), "--no-3d"]
        return [command, str(run), "--json"]

    return build


def _airborne_run(t: Path, air_model: str = "cfd") -> Path:
    """A synthetic run (tests/support) whose snapshot has airborne particles, so that the
    slice closures can be measured from it; its crossing table only gzipped, as shipped."""
    from support.synthetic_run import synthetic_case_dict, write_synthetic_run

    data = synthetic_case_dict()
    data["air"]["model"] = air_model
    run = write_synthetic_run(t / "run", case_dict=data)
    snap = next((run / "dem" / "dumps").glob("snap.*.txt"))
    lines = snap.read_text().splitlines()
    for i in range(9, 9 + 40):  # 40 of 300 particles falling at 3 m/s
        cells = lines[i].split()
        cells[5] = "-3"
        lines[i] = " ".join(cells) + " "
    snap.write_text("\n".join(lines) + "\n")
    table = run / "post" / "crossings.csv"
    with gzip.open(run / "post" / "crossings.csv.gz", "wb") as fh:
        fh.write(table.read_bytes())
    table.unlink()
    return run


def _air_field_cut(t: Path) -> list[str]:
    run = _airborne_run(t)
    field = run / "air" / "field.npz"
    field.parent.mkdir()
    np.savez_compressed(field, velocity=np.zeros((20, 20, 20, 3)), format_version=np.array(1))
    _cut(field, 0.5)
    return ["plant", str(run), "--json", "--out", str(t / "plant")]


def _a_file(t: Path) -> str:
    path = t / "a_file"
    path.write_text("not a folder\n")
    return str(path)


# (id, command line builder, texts the message must contain)
ROWS: list[tuple[str, Setup, list[str]]] = [
    ("toml_not_utf8", _toml_not_utf8, ["latin1.toml", "not UTF-8", "0xe9"]),
    ("fit_points_not_utf8", _points_not_utf8, ["points.csv", "not UTF-8", "0xff"]),
    ("weather_not_utf8", _weather_not_utf8, ["weather.csv", "not UTF-8", "0xe9"]),
    ("weather_nan", _weather_nan, ["weather.csv", "data row 1", "t_mean_C = nan", "finite"]),
    ("closures_not_utf8",
     lambda t: ["cooler", "drum", str(_closures_not_utf8(t)), "--out", str(t / "d")],
     ["closures.json", "not UTF-8"]),
    ("plant_closures_not_utf8",
     lambda t: ["plant", str(_closures_not_utf8(t)), "--out", str(t / "d")],
     ["closures.json", "not UTF-8"]),
    ("closures_cut",
     lambda t: (_cut(_closures(t), 0.5), ["cooler", "drum", str(t / "closures.json"),
                                          "--out", str(t / "d")])[1],
     ["closures.json", "not valid JSON", "cut short"]),
    ("closures_nan",
     lambda t: ["cooler", "drum", str(_closures(t, holdup_kg_per_m=math.nan)), "--out", str(t / "d")],
     ["closures.json", "holdup_kg_per_m = nan", "finite"]),
    ("closures_word",
     lambda t: ["cooler", "drum", str(_closures(t, rpm="fast")), "--out", str(t / "d")],
     ["closures.json", "rpm = 'fast'", "number"]),
    # Reported: a hold-up of -10 kg/m was blamed on rpm ("a fall would last longer than a
    # cascade cycle"); the field itself is named now.
    ("closures_negative_holdup",
     lambda t: ["cooler", "drum", str(_closures(t, holdup_kg_per_m=-10)), "--out", str(t / "d")],
     ["closures.json", "holdup_kg_per_m = -10", "greater than 0"]),
    ("manifest_cut", _manifest_cut, ["manifest.json", "not valid JSON", "cut short"]),
    ("air_field_cut", _air_field_cut, ["field.npz", "truncated"]),
    ("paper_air_heat_empty", _air_heat_empty, ["air_heat.csv", "empty"]),
    ("paper_summary_cut", _summary_cut, ["summary.json", "not valid JSON", "cut short"]),
    ("report_series_cut", _series_cut("report"),
     ["mean_temperature.csv", "ends at 8.7", "17.508", "summary.json"]),
    ("methodology_series_cut", _series_cut("methodology"),
     ["mean_temperature.csv", "ends at 8.7", "17.508", "summary.json"]),
    ("paper_series_cut", _series_cut("paper"), ["mean_temperature.csv", "ends at 8.7", "17.508"]),
    ("out_file_run",
     lambda t: ["run", str(CASES / "smoke.toml"), "--out", _a_file(t), "--steps", "1"],
     ["a_file", "not a folder"]),
    ("out_file_cooler_fluid_bed",
     lambda t: ["cooler", "fluid-bed", str(FLUID_BED), "--out", _a_file(t)], ["a_file", "not a folder"]),
    ("out_file_cooler_drum",
     lambda t: ["cooler", "drum", str(CLOSURES), "--out", _a_file(t)], ["a_file", "not a folder"]),
    ("out_file_paper",
     lambda t: ["paper", "--from", str(SHIPPED.parent), "--out", _a_file(t), "--no-3d"],
     ["a_file", "not a folder"]),
    ("out_file_answer", lambda t: ["answer", str(SHIPPED), "--out", _a_file(t)], ["a_file", "not a folder"]),
    ("out_file_profile",
     lambda t: ["profile", str(SHIPPED), "--out", _a_file(t)], ["a_file", "not a folder"]),
    ("out_file_sweep",
     lambda t: ["sweep", str(CASES / "sweep_smoke.toml"), "--out", _a_file(t), "--check"],
     ["a_file", "not a folder"]),
    ("out_file_verify", lambda t: ["verify", "--quick", "--out", _a_file(t)], ["a_file", "not a folder"]),
    ("out_file_bench",
     lambda t: ["bench", str(CASES / "smoke.toml"), "--out", _a_file(t), "--list"],
     ["a_file", "not a folder"]),
    ("out_folder_report",
     lambda t: ["report", str(SHIPPED), "--out", str(t), "--no-3d"], ["an existing folder, not a file"]),
]


def assert_refused(args: list[str], named: list[str]) -> None:
    """The command exits 2 without a traceback, its message naming every piece of ``named``."""
    out = _drumflow(*args)
    text = out.stdout + out.stderr
    assert out.returncode == 2, text
    assert "Traceback" not in text
    flat = _flat(text)
    for piece in named:
        assert piece in flat, (piece, text)


@pytest.mark.parametrize(("build", "named"), [pytest.param(b, n, id=i) for i, b, n in ROWS])
def test_a_damaged_file_exits_2_naming_it_without_traceback(
    tmp_path: Path, build: Setup, named: list[str]
) -> None:
    assert_refused(build(tmp_path), named)
    # Nothing was written for a refused command.
    assert not (tmp_path / "out" / "paper.html").exists()
    assert not (tmp_path / "r.html").exists()


def test_plant_reads_the_gzipped_crossing_table(tmp_path: Path) -> None:
    """Shipped results hold post/crossings.csv.gz, not post/crossings.csv (reported: `drumflow
    plant` asked for the .csv)."""
    run = _airborne_run(tmp_path, air_model="uniform")
    out = _drumflow("plant", str(run), "--json", "--out", str(tmp_path / "plant"))
    assert out.returncode == 0, out.stdout + out.stderr
    result = json.loads(out.stdout)
    assert result["slice"]["falling_mass_flow_kg_s_m"] > 0
    assert result["slice"]["airborne_fraction"] > 0


def test_plant_on_results_without_snapshots_or_closures_names_what_they_lack(tmp_path: Path) -> None:
    """Shipped results keep the crossing table (gzipped) and the closures `drumflow post`
    measured (post/closures.json), but no snapshot: without that file the closures' airborne
    share, speeds and bed surface cannot be measured, and the refusal says so instead of asking
    for post/crossings.csv. (With it the plant runs: test_plant_from_shipped_results.py.)"""
    results = _shipped_copy(tmp_path)
    (results / "post" / "closures.json").unlink()
    out = _drumflow("plant", str(results), "--json", "--out", str(tmp_path / "plant"))
    text = _flat(out.stdout + out.stderr)
    assert out.returncode == 2, text
    assert "Traceback" not in text
    assert "crossings.csv: missing" not in text
    assert "dem/dumps: no particle snapshot" in text and "no closures.json" in text
    assert "--save-closures" in text


def test_closures_without_airborne_particles_are_refused_before_the_drum_model(tmp_path: Path) -> None:
    """A run whose snapshots hold no airborne particle gives NaN fall speeds: refused naming the
    snapshots and the fields (it ended in a root finder's traceback)."""
    from support.synthetic_run import write_synthetic_run

    run = write_synthetic_run(tmp_path / "run")
    out = _drumflow("plant", str(run), "--out", str(tmp_path / "plant"))
    text = _flat(out.stdout + out.stderr)
    assert out.returncode == 2, text
    assert "Traceback" not in text
    assert "dem/dumps" in text and "airborne_downward_speed_m_s = nan" in text


def test_report_prints_its_notes_on_stderr(tmp_path: Path) -> None:
    """`drumflow report` said only "report written" while its notes were inside the page."""
    run = _shipped_copy(tmp_path)
    out = _drumflow("report", str(run), "--out", str(tmp_path / "r.html"), "--no-3d")
    assert out.returncode == 0, out.stdout + out.stderr
    flat = _flat(out.stderr)
    assert "note:" in flat
    # The one note of a single run: Table 8 needs more than one run to fit its exponent.
    assert "Table 8" in flat


def test_paper_prints_its_notes_on_stderr_with_json(tmp_path: Path) -> None:
    run = _shipped_copy(tmp_path / "from")
    (run / "post" / "air_side.json").unlink()  # a note: the bed and airborne h not available
    out = _drumflow("paper", "--from", str(tmp_path / "from"), "--model", "two", "--out",
                    str(tmp_path / "out"), "--no-3d", "--json")
    assert out.returncode == 0, out.stdout + out.stderr
    assert "air_side.json" in _flat(out.stderr)
    json.loads(out.stdout)  # stdout stays JSON


# ------------------------------------------------------------------ the readers themselves


def test_coupling_log_cut_short_is_refused_by_post(tmp_path: Path) -> None:
    """`drumflow post` read a coupling log cut at a line boundary as a shorter run, and said
    status "ok" with an energy-balance error of 0.96; its strict read names the file."""
    from drumflow.coupling.log import read_coupling

    header = "step,time_s,steps,heat_to_particles_W,drag_x_N,drag_y_N,drag_z_N,particles\n"
    dt = 1e-4

    def rows(last: int) -> str:
        return "".join(f"{s},{s * dt},100,-2.0,0,0,0,3\n" for s in range(0, last + 1, 100))

    (tmp_path / "rank0.0.csv").write_text(header + rows(900))
    (tmp_path / "rank1.0.csv").write_text(header + rows(400))  # cut after 5 of 10 updates
    assert len(read_coupling(tmp_path, dt)) == 10  # the lenient read of a live run
    with pytest.raises(BadFileError, match=r"rank1\.0\.csv.*end at 0\.05 s, before 0\.1 s"):
        read_coupling(tmp_path, dt, covers_s=0.1)
    (tmp_path / "rank1.0.csv").write_text(header + rows(900) + "1000,0.1,100,-2.0,0,")
    with pytest.raises(BadFileError, match=r"rank1\.0\.csv.*drag_y_N, data row 11"):
        read_coupling(tmp_path, dt, covers_s=0.1)
    (tmp_path / "rank1.0.csv").write_text(header + rows(900))
    assert len(read_coupling(tmp_path, dt, covers_s=0.1)) == 10


def test_read_text_and_json(tmp_path: Path) -> None:
    from drumflow.readers import read_json, read_json_object, read_text

    path = tmp_path / "f.json"
    path.write_bytes(b'{"a": "\xe9"}')
    with pytest.raises(BadFileError, match=r"f\.json.*not UTF-8 text: byte 0xe9 at offset 7 \(line 1\)"):
        read_text(path)
    path.write_text("")
    with pytest.raises(BadFileError, match="empty"):
        read_json(path)
    path.write_text('{"a": [1, 2')
    with pytest.raises(BadFileError, match="cut short"):
        read_json(path)
    path.write_text("[1]")
    with pytest.raises(BadFileError, match="expected an object"):
        read_json_object(path)
    with pytest.raises(BadFileError, match="no such file"):
        read_text(tmp_path / "missing.json")


def test_read_csv(tmp_path: Path) -> None:
    from drumflow.readers import read_csv

    path = tmp_path / "t.csv"
    path.write_text("")
    with pytest.raises(BadFileError, match="empty"):
        read_csv(path)
    path.write_text("a,b\n1,2\n3,x\n")
    with pytest.raises(BadFileError, match=r"column b, data row 2 \(line 3\): 'x' is not a finite"):
        read_csv(path, finite=("a", "b"))
    with pytest.raises(BadFileError, match="no column"):
        read_csv(path, columns=("c",))
    with pytest.raises(BadFileError, match="2 data row"):
        read_csv(path, min_rows=3)
    packed = tmp_path / "t.csv.gz"
    with gzip.open(packed, "wb") as fh:
        fh.write(b"a,b\n" + b"1,2\n" * 5000)
    assert len(read_csv(packed, finite=("a", "b"))) == 5000
    _cut(packed, 0.5)
    with pytest.raises(BadFileError, match=r"t\.csv\.gz.*truncated"):
        read_csv(packed)


def test_read_npz(tmp_path: Path) -> None:
    from drumflow.readers import read_npz

    path = tmp_path / "a.npz"
    np.savez_compressed(path, x=np.arange(1000.0))
    assert read_npz(path)["x"].sum() == pytest.approx(499500.0)
    _cut(path, 0.5)
    with pytest.raises(BadFileError, match=r"a\.npz.*truncated"):
        read_npz(path)
    np.save(tmp_path / "b.npy", np.arange(3))
    with pytest.raises(BadFileError, match="not a .npz archive"):
        read_npz(tmp_path / "b.npy")


def test_reaches_time(tmp_path: Path) -> None:
    from drumflow.readers import reaches_time

    summary = tmp_path / "summary.json"
    series = tmp_path / "series.csv"
    reaches_time(series, 1.0, summary)  # no summary: a run not post-processed yet
    summary.write_text(json.dumps({"simulated_time_s": 2.0}))
    reaches_time(series, 2.0, summary)
    with pytest.raises(BadFileError, match=r"series\.csv: ends at 1 s, before the 2 s"):
        reaches_time(series, 1.0, summary)
