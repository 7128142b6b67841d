"""Damaged files, for the readers test_cli_bad_files.py left (issue 36, "nothing silent"): a
run directory's stage markers, a sweep's state files, the ladder spec, the tables and records
`drumflow answer` and `drumflow profile` read, and the snapshots `drumflow export --vtk` reads.
Each exits 2 with one message naming the file and what is wrong, and no traceback.

Commands run as real subprocesses (``python -m drumflow.cli``), as in
``test_cli_bad_files.py``, whose helpers are reused. Fixtures are copies of shipped results (or
of tests/support's synthetic run) in ``tmp_path`` with one file damaged; nothing here needs a
solver. Readers no command reaches cheaply (SLURM's records, the profile's clock) are tested
directly at the end.
"""

from __future__ import annotations

import gzip
import json
import math
import shutil
from pathlib import Path

import pytest
from test_cli_bad_files import CASES, SHIPPED, Setup, _cut, _shipped_copy, assert_refused

from drumflow.errors import BadFileError

SWEEP = CASES / "sweep_smoke.toml"
LADDER = SHIPPED.parents[1] / "bench" / "paper_model_two_ladder" / "ladder.toml"


# ------------------------------------------------------------------ stage markers


def _marker_status(t: Path) -> list[str]:
    """A finished run whose DEM marker was cut: `drumflow status` said "finished" from the
    marker's name alone."""
    run = _shipped_copy(t)
    (run / "stages").mkdir()
    marker = run / "stages" / "dem.json"
    marker.write_text(json.dumps({"key": "abc", "result": {"steps": 10}, "wall_time_s": 1.0}))
    _cut(marker, 0.5)
    return ["status", str(run)]


def _marker_run(t: Path) -> list[str]:
    """`drumflow run` into a directory of the same case whose geometry marker was cut: it
    ended in a JSONDecodeError traceback."""
    from drumflow.case import case_to_toml, load_case
    from drumflow.rundir import RunDir

    case = load_case(CASES / "smoke.toml")
    rundir = RunDir(t / "run")
    rundir.bind_case(case.canonical_json(), case.hash(), case_to_toml(case), versions={})
    rundir.mark_done("geometry", "key", {"stl": "geometry/walls.stl"}, 1.0)
    _cut(rundir.stages / "geometry.json", 0.4)
    return ["run", str(CASES / "smoke.toml"), "--out", str(rundir.root)]


# ------------------------------------------------------------------ sweeps


def _sweep(t: Path) -> Path:
    from drumflow.sweep.driver import open_sweep

    return open_sweep(SWEEP, t / "sweep").root


def _sweep_summary(damage: str, option: str) -> Setup:
    """A member's summary.json damaged: the member read as "pending" in silence."""

    def build(t: Path) -> list[str]:
        root = _sweep(t)
        summary = root / "members" / "m001" / "summary.json"
        summary.write_text(json.dumps({"case_hash": "x", "status": "ok", "note": "café"},
                                      ensure_ascii=False), encoding="utf-8")
        if damage == "cut":
            _cut(summary, 0.5)
        else:
            summary.write_bytes(summary.read_bytes().replace("é".encode(), b"\xe9"))
        return ["sweep", str(root), option]

    return build


def _sweep_state_cut(t: Path) -> list[str]:
    root = _sweep(t)
    _cut(root / "sweep.json", 0.5)
    return ["sweep", str(SWEEP), "--out", str(root), "--check"]


def _sweep_member_manifest_cut(t: Path) -> list[str]:
    root = _sweep(t)
    manifest = root / "members" / "m002" / "manifest.json"
    manifest.write_text(json.dumps({"case_hash": "abc", "case": {"name": "smoke"}}))
    _cut(manifest, 0.5)
    return ["sweep", str(SWEEP), "--out", str(root), "--check"]


def _sweep_attempts(content: str) -> Setup:
    def build(t: Path) -> list[str]:
        root = _sweep(t)
        (root / "executor").mkdir()
        (root / "executor" / "attempts.json").write_text(content)
        return ["sweep", str(root), "--check"]

    return build


# ------------------------------------------------------------------ ladder, answer


def _ladder_not_utf8(t: Path) -> list[str]:
    spec = t / "ladder.toml"
    text = LADDER.read_text().replace('"../../paper/', f'"{SHIPPED.parents[1]}/paper/')
    spec.write_bytes(text.encode() + "# caf\xe9\n".encode("latin-1"))
    return ["ladder", str(spec), "--out", str(t / "out")]


def _ladder_folder(t: Path) -> list[str]:
    (t / "ladder.toml").mkdir()
    return ["ladder", str(t / "ladder.toml"), "--out", str(t / "out")]


def _answer_crossings_cut(t: Path) -> list[str]:
    """A cut crossings.csv.gz: gzip's EOFError, which click turns into a bare "Aborted."."""
    run = _shipped_copy(t)
    _cut(run / "post" / "crossings.csv.gz", 0.5)
    return ["answer", str(run), "--out", str(t / "out")]


def _answer_air_heat_nan(t: Path) -> list[str]:
    run = _shipped_copy(t)
    table = run / "post" / "air_heat.csv"
    lines = table.read_text().splitlines(keepends=True)
    cells = lines[3].split(",")
    cells[3] = "nan"  # heat_to_particles_W of data row 3
    lines[3] = ",".join(cells)
    table.write_text("".join(lines))
    return ["answer", str(run), "--out", str(t / "out")]


def _answer_run_record_cut(t: Path) -> list[str]:
    """No logged wall times (dem/coupling gone), so the rate comes from run_record.json."""
    run = _shipped_copy(t)
    shutil.rmtree(run / "dem" / "coupling")
    _cut(run / "run_record.json", 0.3)
    return ["answer", str(run), "--out", str(t / "out")]


# ------------------------------------------------------------------ export --vtk


def _export_run(t: Path, damage: str) -> list[str]:
    """The synthetic run (one snapshot) with the geometry stage's marker and walls export
    needs, and one file damaged."""
    import pyvista as pv
    from support.synthetic_run import write_synthetic_run

    run = write_synthetic_run(t / "run")
    (run / "geometry").mkdir(exist_ok=True)
    pv.Cube().triangulate().save(str(run / "geometry" / "walls.stl"))
    (run / "stages").mkdir()
    marker = run / "stages" / "geometry.json"
    marker.write_text(json.dumps({"key": "k", "result": {"stl": "geometry/walls.stl",
                                                         "wall_motion": "rotating"}}))
    snap = next((run / "dem" / "dumps").glob("snap.*.txt"))
    data = snap.read_bytes()
    if damage == "last_row":  # cut inside its last row: the row count still matches
        snap.write_bytes(data[:-20])
    elif damage == "not_utf8":
        lines = data.split(b"\n")
        lines[20] = lines[20].replace(b"0", b"\xe9", 1)
        snap.write_bytes(b"\n".join(lines))
    elif damage == "marker":
        _cut(marker, 0.5)
    return ["export", str(run), "--vtk", "--out", str(t / "vtk")]


# (id, command line builder, texts the message must contain)
ROWS: list[tuple[str, Setup, list[str]]] = [
    ("status_dem_marker_cut", _marker_status,
     ["stages/dem.json", "not valid JSON", "cut short", "delete it", "restart"]),
    ("run_geometry_marker_cut", _marker_run,
     ["stages/geometry.json", "not valid JSON", "cut short", "geometry stage"]),
    ("sweep_check_member_summary_cut", _sweep_summary("cut", "--check"),
     ["members/m001/summary.json", "not valid JSON", "cut short", "drumflow post"]),
    ("sweep_analyse_member_summary_not_utf8", _sweep_summary("latin1", "--analyse"),
     ["members/m001/summary.json", "not UTF-8", "0xe9"]),
    ("sweep_state_cut", _sweep_state_cut, ["sweep.json", "not valid JSON", "cut short"]),
    ("sweep_member_manifest_cut", _sweep_member_manifest_cut,
     ["members/m002/manifest.json", "not valid JSON", "cut short"]),
    ("sweep_attempts_cut", _sweep_attempts('[{"member": "m000", "exec'),
     ["executor/attempts.json", "not valid JSON", "cut short"]),
    ("sweep_attempts_wrong_record", _sweep_attempts('[{"member": "m000", "runner": "local"}]'),
     ["executor/attempts.json", "attempt 1", "runner"]),
    ("ladder_spec_not_utf8", _ladder_not_utf8, ["ladder.toml", "not UTF-8", "0xe9"]),
    ("ladder_spec_folder", _ladder_folder, ["ladder.toml", "a directory, not a file"]),
    ("answer_crossings_cut", _answer_crossings_cut, ["crossings.csv.gz", "truncated"]),
    ("answer_air_heat_nan", _answer_air_heat_nan,
     ["air_heat.csv", "heat_to_particles_W, data row 3", "finite"]),
    ("answer_run_record_cut", _answer_run_record_cut,
     ["run_record.json", "not valid JSON", "cut short"]),
    ("export_snapshot_cut_in_last_row", lambda t: _export_run(t, "last_row"),
     ["snap.", "ends inside a row", "cut short"]),
    ("export_snapshot_not_utf8", lambda t: _export_run(t, "not_utf8"), ["snap.", "not UTF-8"]),
    ("export_geometry_marker_cut", lambda t: _export_run(t, "marker"),
     ["stages/geometry.json", "not valid JSON"]),
]


@pytest.mark.parametrize(("build", "named"), [pytest.param(b, n, id=i) for i, b, n in ROWS])
def test_a_damaged_file_exits_2_naming_it_without_traceback(
    tmp_path: Path, build: Setup, named: list[str]
) -> None:
    assert_refused(build(tmp_path), named)
    # Nothing was written for a refused command.
    assert not (tmp_path / "out").exists()
    assert not (tmp_path / "vtk" / "particles.pvd").exists()


# ------------------------------------------------------------------ the readers themselves


def test_stage_markers_are_written_whole_and_read_checked(tmp_path: Path) -> None:
    from drumflow.rundir import RunDir

    rundir = RunDir(tmp_path / "run")
    rundir.mark_done("dem", "k1", {"steps": 5}, 2.0)
    assert [p.name for p in rundir.stages.iterdir()] == ["dem.json"]  # no temporary left
    assert rundir.stage_done("dem", "k1") is not None
    assert rundir.finished_key("dem") == "k1"
    assert rundir.finished_stages() == ["dem"]
    assert rundir.stage_record("geometry") is None  # no marker: not finished
    marker = rundir.stages / "dem.json"
    marker.write_text(json.dumps({"key": "k1"}))  # a hand edit lost the result
    assert rundir.finished_key("dem") == "k1"
    assert rundir.stage_done("dem", "k2") is None  # another input: not this stage's result
    with pytest.raises(BadFileError, match=r"dem\.json.*result = None.*delete it"):
        rundir.stage_done("dem", "k1")  # skipping the stage would return nothing
    marker.write_text("")
    with pytest.raises(BadFileError, match=r"dem\.json.*empty"):
        rundir.finished_key("dem")


def test_a_member_summary_is_done_missing_or_refused(tmp_path: Path) -> None:
    from drumflow.sweep.driver import member_done

    assert not member_done(tmp_path, "h")  # no summary: not done
    (tmp_path / "summary.json").write_text(json.dumps({"case_hash": "h", "status": "ok"}))
    assert member_done(tmp_path, "h")
    (tmp_path / "summary.json").write_text("[1, 2]")
    with pytest.raises(BadFileError, match="expected an object"):
        member_done(tmp_path, "h")


def _slurm(root: Path):  # type: ignore[no-untyped-def]
    from drumflow.sweep.run_settings import Runs, SlurmSettings
    from drumflow.sweep.slurm import SlurmExecutor

    return SlurmExecutor(root, SlurmSettings(), Runs(processes=2), "demo", 3)


@pytest.mark.parametrize(("content", "message"), [
    ('{"job_id": "12_1", "node": "n1", "exit_co', "cut short"),
    ('{"job_id": "12_1", "exit_code": "fine"}', "exit_code = 'fine'"),
    ("", "empty"),
])
def test_a_damaged_slurm_end_record_is_refused(tmp_path: Path, content: str, message: str) -> None:
    """A task's end record that does not read was taken as "no record": the attempt settled
    as failed (or an exit 130, a stop to resume, was missed) on a guess."""
    from drumflow.sweep.executor import Attempt

    ex = _slurm(tmp_path)
    record = tmp_path / "members" / "m001" / "slurm-12_1.json"
    record.parent.mkdir(parents=True)
    record.write_text(content)
    attempt = Attempt(member="m001", executor="slurm", state="running", job_id="12_1")
    with pytest.raises(BadFileError, match=rf"slurm-12_1\.json.*{message}"):
        ex._settle(attempt, None)
    record.unlink()  # no record at all: SLURM forgot the task and it wrote none (killed)
    ex._settle(attempt, None)
    assert attempt.state == "failed"


def test_damaged_slurm_submissions_are_refused(tmp_path: Path) -> None:
    ex = _slurm(tmp_path)
    path = tmp_path / "slurm" / "submissions.json"
    assert ex._submissions(path) == []
    path.parent.mkdir()
    path.write_text('{"array_job_id": "12"}')
    with pytest.raises(BadFileError, match=r"submissions\.json.*expected a list"):
        ex._submissions(path)
    path.write_text('[{"array_job_id": "12", "mem')
    with pytest.raises(BadFileError, match="cut short"):
        ex._submissions(path)


def test_the_profile_clock_names_a_damaged_coupling_input(tmp_path: Path) -> None:
    from drumflow.bench.profile import _clock
    from drumflow.rundir import RunDir

    rundir = RunDir(tmp_path / "run")
    spec = rundir.dem / "coupling.json"
    spec.parent.mkdir()
    spec.write_text(json.dumps({"time_step": 1e-5, "clock_origin": [100, 0.001]}))
    assert _clock(rundir) == (1e-5, (100, 0.001))
    _cut(spec, 0.5)
    with pytest.raises(BadFileError, match=r"coupling\.json.*cut short"):
        _clock(rundir)
    spec.write_text(json.dumps({"time_step": 1e-5, "clock_origin": ["start", 0]}))
    with pytest.raises(BadFileError, match=r"coupling\.json.*clock_origin = \['start', 0\]"):
        _clock(rundir)


def test_a_nan_wall_time_in_the_run_record_is_refused(tmp_path: Path) -> None:
    """A NaN is truthy: it passed the "has a wall time" test and made every estimated wall
    time NaN."""
    import pandas as pd

    from drumflow.bench.answer_wall import rate_from_record as _rate_from_record
    from drumflow.rundir import RunDir

    rundir = RunDir(tmp_path / "run")
    (rundir.root / "run_record.json").write_text(
        json.dumps({"dem_wall_time_s": math.nan, "simulated_time_s": 2.0}))
    updates = pd.DataFrame({"time_s": [0.0, 1.0], "particles": [10, 10], "steps": [100, 100]})
    with pytest.raises(BadFileError, match=r"run_record\.json.*dem_wall_time_s = nan"):
        _rate_from_record(rundir, updates)
    (rundir.root / "run_record.json").write_text(
        json.dumps({"dem_wall_time_s": 10.0, "simulated_time_s": 2.0}))
    rate, _ = _rate_from_record(rundir, updates)
    assert rate == pytest.approx(2000 / 10.0)


def test_a_dump_cut_inside_its_header_or_last_row(tmp_path: Path) -> None:
    from drumflow.dem.dumps import read_dump

    path = tmp_path / "snap.1.txt"
    head = ("ITEM: TIMESTEP\n1\nITEM: NUMBER OF ATOMS\n2\nITEM: BOX BOUNDS ff ff ff\n"
            "-1 1\n-1 1\n0 1\nITEM: ATOMS id x y z\n")
    path.write_text(head + "1 0.1 0.2 0.3 \n2 0.4 0.5 0.6 \n")
    assert read_dump(path).columns["z"].tolist() == [0.3, 0.6]
    path.write_text(head + "1 0.1 0.2 0.3 \n2 0.4 0.5 0.")
    with pytest.raises(BadFileError, match="ends inside a row"):
        read_dump(path)
    path.write_text(head[:40])
    with pytest.raises(BadFileError, match="ends inside its 9-line header"):
        read_dump(path)
    path.write_text(head + "1 0.1 0.2 0.3 \n2 0.4 x 0.6 \n")
    with pytest.raises(BadFileError, match="not a table of numbers"):
        read_dump(path)


def test_a_gzipped_crossing_table_still_reads(tmp_path: Path) -> None:
    """The answer replay's strict read keeps reading what shipped results hold."""
    from drumflow.readers import read_csv

    table = tmp_path / "crossings.csv.gz"
    with gzip.open(table, "wb") as fh:
        fh.write(b"time,id,x,z\n1.0,1,0.1,0.2\n")
    assert len(read_csv(table, columns=("time",), finite=("time",))) == 1


def test_a_damaged_summary_of_a_finished_paper_run_is_refused(tmp_path: Path) -> None:
    """Regression: `drumflow paper` took a run whose summary.json was cut short for an
    unfinished one and ran the model again over it, without a word."""
    from drumflow.cli.paper import _finished

    run = tmp_path / "model_two"
    (run / "stages").mkdir(parents=True)
    (run / "stages" / "dem.json").write_text("{}")
    summary = run / "summary.json"
    summary.write_text(json.dumps({"case_hash": "abc", "simulated_time_s": 17.5}))
    assert _finished(run, "abc") and not _finished(run, "other")
    _cut(summary, 0.5)
    with pytest.raises(BadFileError, match="summary.json.*cut short"):
        _finished(run, "abc")
