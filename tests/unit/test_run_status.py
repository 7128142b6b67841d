"""`drumflow status`: a run directory's state from the files a run writes (no solver).

The directory here is written by hand in the layout `drumflow run` leaves (manifest, stage
markers, LIGGGHTS logs, the coupling loop's per-update log, restart files), so every number
the status reports is known. The solver side (a finished coupled run) is in
tests/solver/test_coupled_resume_and_report.py.
"""

from __future__ import annotations

import json
import os
import socket
import subprocess
import sys
import time
from pathlib import Path

import pytest
from typer.testing import CliRunner

from drumflow.analysis.run_status import LOG_TAIL_BYTES, RECENT_UPDATES, run_status
from drumflow.case import Case, case_to_toml, load_case
from drumflow.cli import app
from drumflow.dem.stage import clear_stop_request, request_stop
from drumflow.errors import MissingRunFileError, RunDirectoryError
from drumflow.rundir import RunDir

ROOT = Path(__file__).resolve().parents[2]
DT = 1e-4
STEPS_PER_UPDATE = 50


def _thermo(step: int, atoms: int = 3000) -> str:
    return f"{step} {step * DT:.12g} {atoms} 1.5 0.1 85.0 -1 3.2\n"


def _write_run(root: Path, *, last_step: int, update_walls: list[float]) -> Path:
    case = load_case(ROOT / "cases" / "smoke.toml")
    (root / "stages").mkdir(parents=True)
    (root / "case.toml").write_text(case_to_toml(case))
    (root / "manifest.json").write_text(json.dumps({"time_step": {"time_step": DT}}))
    (root / "stages" / "geometry.json").write_text("{}")
    dem = root / "dem"
    (dem / "coupling").mkdir(parents=True)
    (dem / "restart").mkdir()
    # The first attempt's log, then a resumed one whose last row is far from its start: longer
    # than the tail that is read, so only the end of the file is parsed.
    (dem / "log.liggghts").write_text("".join(_thermo(s) for s in range(0, 1000, 100)))
    filler = "Loop time of 1.0 on 2 procs for 50 steps with 3000 atoms\n" * (LOG_TAIL_BYTES // 40)
    (dem / "log.resume-1000.liggghts").write_text(
        _thermo(1000) + filler + _thermo(last_step - 100) + _thermo(last_step, atoms=2999))
    rows = ["step,time_s,steps,heat_to_particles_W,drag_x_N,drag_y_N,drag_z_N,particles,"
            "mean_slip_m_s,python_wall_s,liggghts_wall_s"]
    for i, wall in enumerate(update_walls):
        step = 1000 + i * STEPS_PER_UPDATE
        rows.append(f"{step},{step * DT},{STEPS_PER_UPDATE},-10.0,0,0,0,3000,1.0,0.0,{wall}")
    (dem / "coupling" / "rank0.1000.csv").write_text("\n".join(rows) + "\n")
    (dem / "restart" / "drum.1000.restart").write_bytes(b"r" * 700)
    (dem / "restart" / "drum.2000.restart").write_bytes(b"r" * 300)
    return root


def test_a_running_run(tmp_path: Path) -> None:
    # 30 updates: the first ten slow (the pace has changed since), the last 20 at 2 s per
    # 50 steps of 1e-4 s, i.e. 400 wall s per simulated s.
    walls = [9.0] * 10 + [2.0] * RECENT_UPDATES
    run = _write_run(tmp_path / "run", last_step=2500, update_walls=walls)
    st = run_status(run, now=(run / "dem" / "log.resume-1000.liggghts").stat().st_mtime + 12.0)
    assert st.case == "smoke" and st.target_time_s == 3.0
    assert st.stages_done == ["geometry"] and not st.finished
    assert st.step == 2500 and st.reached_time_s == pytest.approx(0.25)
    assert st.particles == 2999 and st.particles_initial == 3000
    assert st.log_age_s == pytest.approx(12.0)
    assert st.wall_per_simulated_s == pytest.approx(2.0 / (STEPS_PER_UPDATE * DT))
    assert st.eta_s == pytest.approx((3.0 - 0.25) * 400.0)
    assert st.restart_step == 2000 and st.restart_time_s == pytest.approx(0.2)
    assert st.restarts == 2 and st.restart_bytes == 1000
    total = sum(p.stat().st_size for p in run.rglob("*") if p.is_file())
    assert st.output_bytes == total - 1000


def test_a_finished_run_has_no_eta_and_the_cli_prints_it(tmp_path: Path) -> None:
    run = _write_run(tmp_path / "run", last_step=30000, update_walls=[2.0] * 5)
    (run / "stages" / "dem.json").write_text("{}")
    old = (run / "dem" / "log.resume-1000.liggghts").stat().st_mtime - 7200
    for log in (run / "dem").glob("log*"):
        os.utime(log, (old, old))
    st = run_status(run)
    assert st.finished and st.eta_s is None and st.stages_done == ["geometry", "dem"]
    result = CliRunner().invoke(app, ["status", str(run)])
    assert result.exit_code == 0, result.output
    assert "finished" in result.output and "3.000 of 3 s" in result.output
    data = json.loads(CliRunner().invoke(app, ["status", str(run), "--json"]).output)
    assert data["reached_time_s"] == pytest.approx(3.0) and data["restarts"] == 2


def test_the_status_names_the_runs_step_and_what_a_new_run_would_take(tmp_path: Path) -> None:
    """A run keeps its step when resumed (drumflow.dem.stage.kept_time_step); the status says
    so when this drumflow would give a new run of the case another step (here the hand-written
    run's 1e-4 s against the smoke case's spin-limited "auto")."""
    from drumflow.dem.timestep import choose_time_step

    run = _write_run(tmp_path / "run", last_step=2500, update_walls=[2.0] * 5)
    st = run_status(run)
    new = choose_time_step(load_case(ROOT / "cases" / "smoke.toml")).time_step
    assert st.time_step_s == DT and st.new_run_time_step_s == pytest.approx(new)
    result = CliRunner(env={"COLUMNS": "200"}).invoke(app, ["status", str(run)])
    assert result.exit_code == 0, result.output
    assert "0.0001 s; kept on resume: a new run of this case would take" in result.output
    assert f"{new:.3g} s" in result.output


def test_not_a_run_directory(tmp_path: Path) -> None:
    with pytest.raises(MissingRunFileError, match="manifest"):
        run_status(tmp_path)
    result = CliRunner().invoke(app, ["status", str(tmp_path)])
    assert result.exit_code == 2 and "manifest" in result.output


def test_the_recorded_process_decides_running_or_stopped(tmp_path: Path) -> None:
    """Regression: a run killed a minute ago read as running for five minutes (its log was
    young). With the pid `drumflow run` records, a dead process is a stopped run at once and a
    live one is running however quiet its log."""
    run = _write_run(tmp_path / "run", last_step=2500, update_walls=[2.0] * 5)
    manifest = json.loads((run / "manifest.json").read_text())
    dead = subprocess.Popen([sys.executable, "-c", "pass"])
    dead.wait()
    # A live process with "drumflow" on its command line stands in for `drumflow run`; pytest's
    # own pid is alive but another program (a pid reused after a reboot).
    live = subprocess.Popen([sys.executable, "-c", "import time; time.sleep(120)", "drumflow"])
    try:
        for pid, alive in ((dead.pid, False), (os.getpid(), False), (live.pid, True)):
            manifest["process"] = {"pid": pid, "host": socket.gethostname(), "started": 0.0}
            (run / "manifest.json").write_text(json.dumps(manifest))
            young = run_status(run)  # the logs were just written
            quiet = run_status(run, now=time.time() + 3600.0)
            assert young.process_alive is alive and young.running is alive, pid
            assert quiet.running is alive
            assert young.to_dict()["running"] is alive
        result = CliRunner().invoke(app, ["status", str(run)])
        assert "running" in result.output  # the live stand-in
    finally:
        live.kill()
        live.wait()
    # Another host's record cannot be checked here: the log's age decides, as without one.
    manifest["process"] = {"pid": dead.pid, "host": "elsewhere", "started": 0.0}
    (run / "manifest.json").write_text(json.dumps(manifest))
    st = run_status(run)
    assert st.process_alive is None and st.running
    assert not run_status(run, now=time.time() + 3600.0).running


def test_drumflow_stop_refuses_a_run_that_is_not_going(tmp_path: Path) -> None:
    run = _write_run(tmp_path / "run", last_step=2500, update_walls=[2.0] * 5)
    manifest = json.loads((run / "manifest.json").read_text())
    dead = subprocess.Popen([sys.executable, "-c", "pass"])
    dead.wait()
    manifest["process"] = {"pid": dead.pid, "host": socket.gethostname(), "started": 0.0}
    (run / "manifest.json").write_text(json.dumps(manifest))
    result = CliRunner().invoke(app, ["stop", str(run)])
    assert result.exit_code == 2 and "no run is going there (stopped)" in " ".join(result.output.split())
    assert not (run / "dem" / "stop.request").exists()


def test_a_run_without_a_coupling_loop_cannot_be_asked_to_stop(tmp_path: Path) -> None:
    run = _write_run(tmp_path / "run", last_step=2500, update_walls=[2.0] * 5)
    with_air = (run / "case.toml").read_text()
    data = load_case(run / "case.toml").model_dump(mode="json")
    data["air"]["model"] = "none"
    (run / "case.toml").write_text(case_to_toml(Case.model_validate(data)))
    with pytest.raises(RunDirectoryError, match="cannot be asked to stop"):
        request_stop(run)  # no dem/coupling.json and no air: LIGGGHTS alone
    (run / "case.toml").write_text(with_air)
    (run / "dem" / "coupling.json").write_text(json.dumps({"interval": 50}))
    with pytest.raises(RunDirectoryError, match="cannot be asked to stop"):
        request_stop(run)  # a loop without a restart pattern (a study's, a short check's)
    (run / "dem" / "coupling.json").write_text(json.dumps({"checkpoint": "restart/drum.*.restart"}))
    assert request_stop(run) == run / "dem" / "stop.request"
    assert "drumflow stop" in (run / "dem" / "stop.request").read_text()


def test_a_stop_asked_before_the_dem_stage_is_kept_for_it(tmp_path: Path) -> None:
    """Regression: `drumflow stop` during the geometry or air stage was lost (refused for want of
    dem/coupling.json on a new run, removed at the DEM's start on a resumed one). Now the case
    decides, the request stays until the loop's first air update, and only the start of the
    next `drumflow run` attempt removes a stale one."""
    run = tmp_path / "run"
    case = load_case(ROOT / "cases" / "smoke.toml")  # air.model = "cfd"
    (run / "dem").mkdir(parents=True)
    (run / "case.toml").write_text(case_to_toml(case))
    request = request_stop(run)
    assert request == run / "dem" / "stop.request" and request.exists()
    clear_stop_request(RunDir(run))
    assert not request.exists()


def test_a_run_stopped_on_request_says_so(tmp_path: Path) -> None:
    run = _write_run(tmp_path / "run", last_step=2500, update_walls=[2.0] * 5)
    (run / "dem" / "stopped.json").write_text(json.dumps({"step": 2500, "time_s": 0.25}))
    st = run_status(run, now=time.time() + 3600.0)
    assert not st.running and st.stopped_on_request_s == pytest.approx(0.25)
    old = time.time() - 3600.0
    for log in (run / "dem").glob("log*"):
        os.utime(log, (old, old))
    result = CliRunner().invoke(app, ["status", str(run)])
    assert "stopped on request at 0.25 s" in " ".join(result.output.split())


def test_the_status_says_what_else_the_machine_did(tmp_path: Path) -> None:
    # Two attempts of 30 s samples: the first quiet, then 3 contended samples (90 s); the
    # second, an hour later, contended in its last two (60 s). Each attempt's first sample
    # comes 3 s after its start: 153 + 93 s logged.
    run = _write_run(tmp_path / "run", last_step=2500, update_walls=[2.0] * 5)
    t0 = 1.8e9
    rows = [(t0 + 30 * i, o) for i, o in enumerate([0.0, 0.0, 0.5, 1.0, 0.6, 0.0])]
    rows += [(t0 + 3600 + 30 * i, o) for i, o in enumerate([0.0, 0.05, 0.9, 0.7])]
    (run / "dem" / "machine_load.csv").write_text(
        "time_unix,load_1min,busy_cores,run_cores,other_cores\n"
        + "".join(f"{t:.1f},2.5,2.0,{2.0 - o:.3f},{o:.3f}\n" for t, o in rows))
    st = run_status(run)
    assert st.contended_s == pytest.approx(150.0)
    assert st.load_logged_s == pytest.approx(3 + 5 * 30 + 3 + 3 * 30)
    # The last 10 minutes hold the second attempt's four samples.
    assert st.other_cores_recent == pytest.approx((0.0 + 0.05 + 0.9 + 0.7) / 4)
    result = CliRunner().invoke(app, ["status", str(run)])
    assert "0.41 cores over the last 10 min; contended 0:02:30" in result.output, result.output
    # Without a log (a run of an older drumflow) there is no row, and a damaged log is no error.
    (run / "dem" / "machine_load.csv").write_text("nonsense\n")
    assert run_status(run).contended_s is None
