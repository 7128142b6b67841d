"""A run keeps the time step it started with (drumflow.dem.stage.kept_time_step): when
``drumflow run`` resumes or reuses it, not when it starts afresh. Regression: "auto" came to
respect the spin limit, and a run started before would have resumed at the new step, i.e. with
another air-update interval, another stage key, a fresh start and its restarts deleted.
tests/solver/test_coupled_resume_and_report.py resumes a real run across such a change."""

from __future__ import annotations

import json
from dataclasses import replace
from pathlib import Path

from drumflow.dem.stage import kept_time_step, plan_run
from drumflow.dem.timestep import choose_time_step
from drumflow.rundir import RunDir
from drumflow.verify.scenes import tiny_drum

CASE = tiny_drum()


def _run_dir(tmp_path: Path, key_suffix: str = ":air=abc:every=42", restart: bool = True,
             case_hash: str | None = None) -> RunDir:
    rundir = RunDir(tmp_path / "run")
    started = replace(choose_time_step(CASE), time_step=1.25e-5)  # what an older drumflow chose
    rundir.record("time_step", started.as_dict())
    rundir.record("dem_key", (case_hash or CASE.hash()) + key_suffix)
    rundir.dem_restart.mkdir(parents=True, exist_ok=True)
    if restart:
        (rundir.dem_restart / "drum.800.restart").write_bytes(b"")
    return rundir


def test_a_run_with_a_restart_keeps_its_step(tmp_path: Path) -> None:
    kept = kept_time_step(CASE, _run_dir(tmp_path))
    assert kept is not None and kept.time_step == 1.25e-5
    assert kept.time_step != choose_time_step(CASE).time_step
    # The plan follows the kept step: the same number of steps to the case's end.
    _, plan = plan_run(CASE, None, kept)
    assert plan.time_step == 1.25e-5 and plan.steps == round(CASE.run.time / 1.25e-5)


def test_a_finished_run_keeps_its_step(tmp_path: Path) -> None:
    rundir = _run_dir(tmp_path, restart=False)
    rundir.stages.mkdir(parents=True, exist_ok=True)
    (rundir.stages / "dem.json").write_text(json.dumps({"key": CASE.hash() + ":air=abc:every=42"}))
    kept = kept_time_step(CASE, rundir)
    assert kept is not None and kept.time_step == 1.25e-5


def test_an_older_record_without_the_new_fields_is_read(tmp_path: Path) -> None:
    rundir = _run_dir(tmp_path)
    record = dict(rundir.manifest["time_step"])
    del record["bound"], record["spin_time_step_limit"]
    rundir.record("time_step", {**record, "a_field_of_the_future": 1})
    kept = kept_time_step(CASE, rundir)
    assert kept is not None and kept.bound is None and kept.time_step == 1.25e-5


def test_no_step_is_kept_where_the_run_starts_afresh(tmp_path: Path) -> None:
    # Nothing to resume from and the stage not finished.
    assert kept_time_step(CASE, _run_dir(tmp_path / "a", restart=False)) is None
    # Another case ran there.
    assert kept_time_step(CASE, _run_dir(tmp_path / "b", case_hash="0" * 64)) is None
    # A short start-up run (never resumed), asked for or recorded.
    assert kept_time_step(CASE, _run_dir(tmp_path / "c"), steps=40) is None
    assert kept_time_step(CASE, _run_dir(tmp_path / "d", key_suffix=":steps=40")) is None
    # A new directory.
    assert kept_time_step(CASE, RunDir(tmp_path / "e")) is None


def test_a_kept_step_of_the_older_auto_is_recorded_as_the_contact_rule() -> None:
    """Regression: model one's long run, started when "auto" was the contact rule, recorded on
    resume the spin-limited "auto" skip ("not measured") though it runs the contact step. Its
    skips now name the rule its step follows today."""
    from drumflow.pipeline import kept_step_rule
    from drumflow.skips import skips

    data = CASE.model_dump(mode="json")
    data["run"]["time_step"] = "contact"
    contact = choose_time_step(type(CASE).model_validate(data))
    older_auto = replace(contact, mode="auto", bound=None, spin_time_step_limit=None)
    assert kept_step_rule(CASE, older_auto) == "contact"
    assert kept_step_rule(CASE, replace(older_auto, time_step=0.7 * contact.time_step)) == "auto"
    entries = [e["skip"] for e in skips(CASE, kept_step_rule(CASE, older_auto), False, "static_shell", 1)]
    assert any(e.startswith("time step 'contact'") for e in entries)
    assert not any(e.startswith("time step 'auto'") for e in entries)
