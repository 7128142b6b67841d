"""The sweep file: expansion into members, and refusal of bad files before anything runs."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path
from typing import Any

import pytest
import tomli_w

from drumflow.case import load_case
from drumflow.errors import exit_code
from drumflow.sweep.run_settings import time_limit_seconds
from drumflow.sweep.spec import SweepError, load_sweep

ROOT = Path(__file__).resolve().parents[2]


def _write(tmp_path: Path, sweep: dict[str, Any]) -> Path:
    (tmp_path / "smoke.toml").write_bytes((ROOT / "cases" / "smoke.toml").read_bytes())
    path = tmp_path / "sweep.toml"
    path.write_text(tomli_w.dumps({"name": "s", "base": "smoke.toml", **sweep}))
    return path


def test_shipped_sweep_expands_to_the_full_factorial() -> None:
    sweep, _, members = load_sweep(ROOT / "cases" / "sweep_smoke.toml")
    assert [m.id for m in members] == ["m000", "m001", "m002", "m003"]
    combos = {(m.case.drum.rpm, m.case.air.mass_flow) for m in members}
    assert combos == {(10.0, 0.3), (10.0, 0.44), (15.0, 0.3), (15.0, 0.44)}
    for m in members:
        assert m.case.run.time == 1.5  # override
        assert m.case.run.processes == sweep.runs.processes
        assert m.case.name == f"smoke-{m.id}"
    assert len({m.hash for m in members}) == 4


def test_member_case_round_trips_through_its_toml(tmp_path: Path) -> None:
    # The member's directory is bound to its hash: the case.toml written for `drumflow run`
    # must load back to the very same case.
    _, _, members = load_sweep(ROOT / "cases" / "sweep_smoke.toml")
    for m in members:
        path = tmp_path / f"{m.id}.toml"
        path.write_text(m.case_toml)
        assert load_case(path).hash() == m.hash


def test_ranges_section_axes_and_nested_tables(tmp_path: Path) -> None:
    path = _write(tmp_path, {
        "axes": {
            "drum": {"rpm": {"start": 10.0, "stop": 20.0, "num": 3}},
            "lifters": [{"profile": "straight", "lip_length": 0.0}, {"profile": "L", "lip_length": 0.02}],
        },
    })
    _, _, members = load_sweep(path)
    assert len(members) == 6
    assert sorted({m.case.drum.rpm for m in members}) == [10.0, 15.0, 20.0]
    assert {(m.case.lifters.profile, m.case.lifters.lip_length) for m in members} == {
        ("straight", 0.0), ("L", 0.02)}
    # A section axis merges: the other lifter fields stay the base case's.
    assert all(m.case.lifters.count == 8 for m in members)


def test_step_range_includes_its_stop(tmp_path: Path) -> None:
    path = _write(tmp_path, {"axes": {"air.mass_flow": {"start": 0.1, "stop": 0.3, "step": 0.1}}})
    _, _, members = load_sweep(path)
    assert [round(m.case.air.mass_flow, 12) for m in members] == [0.1, 0.2, 0.3]


def test_latin_hypercube_is_seeded_stratified_and_rounds_integer_fields(tmp_path: Path) -> None:
    sweep = {
        "axes": {"drum.rpm": {"start": 8.0, "stop": 16.0}, "lifters.count": {"start": 4, "stop": 8},
                 "air.mass_flow": [0.2, 0.3, 0.4, 0.5]},
        "design": {"kind": "latin_hypercube", "samples": 8, "seed": 7},
    }
    _, _, a = load_sweep(_write(tmp_path, sweep))
    _, _, b = load_sweep(_write(tmp_path, sweep))
    assert [m.hash for m in a] == [m.hash for m in b]  # same seed, same members
    rpm = sorted(m.case.drum.rpm for m in a)
    # Latin hypercube: exactly one sample in each of the 8 equal strata of [8, 16].
    assert [int((r - 8.0) // 1.0) for r in rpm] == list(range(8))
    assert all(isinstance(m.case.lifters.count, int) and 4 <= m.case.lifters.count <= 8 for m in a)
    # A list axis: each of the 4 levels taken by exactly 2 of the 8 members.
    flows = [m.case.air.mass_flow for m in a]
    assert sorted(flows.count(v) for v in (0.2, 0.3, 0.4, 0.5)) == [2, 2, 2, 2]
    sweep["design"]["seed"] = 8
    _, _, c = load_sweep(_write(tmp_path, sweep))
    assert [m.hash for m in c] != [m.hash for m in a]


@pytest.mark.parametrize(
    ("sweep", "expected"),
    [
        ({"axes": {"drum.rmp": [10.0, 12.0]}}, "axes.drum.rmp: unknown case field"),
        ({"axes": {"drumm.rpm": [10.0]}}, "axes.drumm.rpm: unknown case field"),
        ({"axes": {"drum.rpm": []}}, "axes.drum.rpm = []: empty list"),
        ({"axes": {"drum.rpm": {"start": 20.0, "stop": 10.0, "num": 3}}}, "the range is empty"),
        ({"axes": {"drum.rpm": {"start": 10.0, "stop": 20.0}}}, "needs num or step"),
        ({"axes": {}}, "axes = {}"),
        ({"axes": {"drum.rpm": [10.0]}, "overrides": {"run.tiem": 1.0}}, "overrides.run.tiem"),
        ({"axes": {"lifters": [{"profile": "L", "lip_lenght": 0.02}]}}, "axes.lifters.lip_lenght"),
        ({"axes": {"drum.rpm": [10.0]}, "design": {"kind": "latin_hypercube"}}, "design.samples"),
        ({"axes": {"drum.rpm": [10.0]}, "runs": {"processes": 0}}, "runs.processes = 0"),
        ({"axes": {"drum.rpm": [10.0]}, "executor": {"slurm": {"time_limit": "00:04:00"}}},
         "stop_before_limit = 300 s is not below time_limit = '00:04:00' (240 s)"),
    ],
)
def test_bad_sweep_files_are_refused_naming_the_field(tmp_path: Path, sweep: dict[str, Any],
                                                      expected: str) -> None:
    with pytest.raises(SweepError) as err:
        load_sweep(_write(tmp_path, sweep))
    assert expected in str(err.value), str(err.value)
    assert exit_code(err.value) == 2


def test_member_the_case_would_refuse_is_named_with_its_values(tmp_path: Path) -> None:
    # 90 rpm makes the 0.4 m drum centrifuge (Froude > 1); -0.1 kg/s is below the air bound.
    path = _write(tmp_path, {"axes": {"drum.rpm": [15.0, 90.0], "air.mass_flow": [0.3, -0.1]}})
    with pytest.raises(SweepError) as err:
        load_sweep(path)
    text = str(err.value)
    assert "member m001 (drum.rpm = 15, air.mass_flow = -0.1): air.mass_flow = -0.1" in text
    assert "member m002 (drum.rpm = 90, air.mass_flow = 0.3): drum.rpm = 90.0" in text
    assert "m000" not in text  # the valid member is not blamed


def test_cli_refuses_a_bad_sweep_with_exit_2_and_no_traceback(tmp_path: Path) -> None:
    path = _write(tmp_path, {"axes": {"drum.rpm": [15.0, 90.0]}})
    proc = subprocess.run([sys.executable, "-m", "drumflow.cli", "sweep", str(path), "--out",
                           str(tmp_path / "out")], capture_output=True, text=True, timeout=120)
    assert proc.returncode == 2, proc.stderr
    assert "member m001" in proc.stderr and "drum.rpm" in proc.stderr
    assert "Traceback" not in proc.stderr
    assert not (tmp_path / "out").exists()  # nothing written, nothing submitted


@pytest.mark.parametrize(("limit", "seconds"), [("30", 1800), ("05:30", 330), ("02:00:00", 7200),
                                                ("1-00:00:00", 86400), ("1-2", 93600),
                                                ("1-02:30", 95400)])
def test_slurm_time_limits_in_seconds(limit: str, seconds: int) -> None:
    # sbatch --time: "minutes", "minutes:seconds", "hours:minutes:seconds", "days-hours",
    # "days-hours:minutes", "days-hours:minutes:seconds".
    assert time_limit_seconds(limit) == seconds
