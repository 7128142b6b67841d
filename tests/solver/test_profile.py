"""The coupled loop's profile and the LIGGGHTS settings study on the real solver (tiny drum).

One short coupled run of the tiny drum with plug-flow air (no OpenFOAM); then `drumflow profile`
on it, and `drumflow bench CASE --from RUN_DIR` (the LIGGGHTS settings study) from its restart
on one rank.
"""

from __future__ import annotations

import json
import math
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from support.solvers import LIGGGHTS, requires_solver

pytestmark = [pytest.mark.solver, pytest.mark.timeout(400), requires_solver(*LIGGGHTS)]

#: LIGGGHTS prints each time and percentage with %g (6 significant digits): a percentage below
#: 100 is off by at most 5e-5, so six categories add up to 100 within 3e-4 (LIGGGHTS' Other is
#: the loop time minus the rest, so before rounding they add up exactly). 1e-3 leaves room and
#: still catches a category lost or counted twice.
ROUNDING = 1e-3


@pytest.fixture(scope="module")
def run(tmp_path_factory: pytest.TempPathFactory) -> Path:
    from drumflow.pipeline import run_case
    from drumflow.verify.scenes import tiny_drum

    case = tiny_drum(air__model="uniform", air__mass_flow=0.1, run__time=0.2, run__mass_flow_start=0.1,
                     run__restart_interval=0.1, run__processes=1)
    out = tmp_path_factory.mktemp("profile") / "run"
    run_case(case, out, timeout=300)
    return out


def test_profile_of_a_coupled_run(run: Path) -> None:
    from drumflow.bench.profile import CATEGORIES, GROUPS, profile_run
    from drumflow.coupling.log import read_coupling

    dt = json.loads((run / "dem" / "coupling.json").read_text())["time_step"]
    coupling = read_coupling(run / "dem" / "coupling", dt)
    # Every update logged both wall times, and both are real time spent.
    assert coupling["python_wall_s"].notna().all() and coupling["liggghts_wall_s"].notna().all()
    assert (coupling["python_wall_s"] > 0).all() and (coupling["liggghts_wall_s"] > 0).all()

    profile = profile_run(run)
    table = profile.intervals
    assert len(table) >= 1
    # The last interval always prints its breakdown.
    assert table["step"].max() == coupling["step"].max() + coupling["steps"].iloc[-1]
    total = sum(table[f"{c}_pct"] for c in CATEGORIES)
    assert (total - 100.0).abs().max() < ROUNDING
    # Under modify_timing every fix is timed: the groups add up to LIGGGHTS' Modfy share.
    groups = sum(table[f"{g}_pct"] for g in GROUPS)
    assert (groups - table["modify_pct"]).abs().max() < ROUNDING
    assert (table["python_wall_s"] + table["liggghts_wall_s"] > 0).all()
    shares = table.filter(like="share_").sum(axis=1)
    assert (shares - 1.0).abs().max() < 1e-3
    assert (table["neighs_per_atom"] > 0).all() and (table["atoms"] == 500).all()
    windows = profile.windows
    assert windows["steps"].sum() == coupling["steps"].sum()
    assert (windows["particle_steps_per_s"] > 0).all()

    proc = subprocess.run([sys.executable, "-m", "drumflow.cli", "profile", str(run), "--window", "0.1"],
                          capture_output=True, text=True, timeout=120, check=False)
    assert proc.returncode == 0, proc.stderr[-2000:]
    written = pd.read_csv(run / "post" / "profile_windows.csv")
    assert len(written) == 2  # 0.2 s in windows of 0.1 s
    assert (run / "post" / "profile.png").stat().st_size > 10_000
    assert len(pd.read_csv(run / "post" / "profile.csv")) == len(table)


def _bench_from(run: Path, case_file: Path, out: Path, *extra: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-m", "drumflow.cli", "bench", str(case_file), "--from", str(run),
                           "--steps", "100", "--np", "1", "--out", str(out), *extra],
                          capture_output=True, text=True, timeout=350, check=False)


def test_settings_study_from_the_restart(run: Path, tmp_path: Path) -> None:
    from drumflow.bench.settings_variants import VARIANTS
    from drumflow.dem.thermo import read_thermo

    study = tmp_path / "study"
    out = study / "settings.csv"
    proc = _bench_from(run, run / "case.toml", study)
    assert proc.returncode == 0, proc.stderr[-3000:]
    table = pd.read_csv(out).set_index("variant")
    variants = VARIANTS
    assert list(table.index) == [v.name for v in variants]
    for v in variants:
        row = table.loc[v.name]
        if v.min_ranks > 1:
            assert str(row["status"]).startswith("skipped"), v.name
            continue
        assert row["status"] == "ok", (v.name, row["status"])
        # A time-step variant covers the baseline's simulated time.
        assert row["steps"] == round(100 / v.time_step_factor)
        assert row["particle_steps_per_s"] > 0
        assert abs(sum(row[f"{c}_pct"] for c in ("pair", "neigh", "comm", "output", "modify", "other"))
                   - 100.0) < ROUNDING
        assert bool(row["physics_ok"]), (v.name, row["T_difference_K"], row["ke_relative_difference"])
    # Each variant's setting reached LIGGGHTS' deck.
    deck = (out.parent / "variants" / "skin_x2" / "dem" / "in.drum.resume").read_text()
    base = (out.parent / "variants" / "baseline" / "dem" / "in.drum.resume").read_text()
    assert deck != base and "neighbor        0.008 bin" in deck
    # The overlap compute is dropped from the thermo rows, their columns kept for the readers;
    # every row evaluates it in overlap_every_row (the loop does not switch it off there).
    variants_dir = out.parent / "variants"
    quiet = (variants_dir / "no_overlap" / "dem" / "in.drum.resume").read_text()
    assert "variable overlap equal c_overlap_max" in base and "v_overlap" in base
    assert "variable overlap equal -1" in quiet and "variable overlap equal c_overlap" not in quiet
    specs = {name: json.loads((variants_dir / name / "dem" / "coupling.json").read_text())
             for name in ("baseline", "no_overlap", "overlap_every_row")}
    assert specs["baseline"]["overlap_every"] > 0
    assert "overlap_every" not in specs["no_overlap"] and "overlap_every" not in specs["overlap_every_row"]
    every_row = read_thermo(variants_dir / "overlap_every_row" / "dem")["overlap_max"]
    never = read_thermo(variants_dir / "no_overlap" / "dem")["overlap_max"]
    assert every_row.notna().all() and never.isna().all()
    # The conservative reference: half the step, the shell a rotating mesh, and the air clock
    # continuing from the restart's time (not step x the new step).
    folder = out.parent / "variants" / "conservative" / "dem"
    conservative = (folder / "in.drum.resume").read_text()
    assert "fix spin_shell all move/mesh mesh shell rotate" in conservative
    assert "surface_ang_vel" not in conservative
    dt_base = json.loads((out.parent / "variants" / "baseline" / "dem" / "coupling.json").read_text())
    spec = json.loads((folder / "coupling.json").read_text())
    assert spec["time_step"] == pytest.approx(0.5 * dt_base["time_step"], rel=1e-12)
    start = spec["clock_origin"][0]
    log = pd.read_csv(folder / "coupling" / f"rank0.{start}.csv")  # the times the loop used
    assert log["time_s"].iloc[0] == pytest.approx(start * dt_base["time_step"], rel=1e-9)
    assert spec["interval"] == 2 * dt_base["interval"]  # the same air-update period in time
    # Regression: the deck's thermo clock (step*dt) and the profile put the half-step variant at
    # half the restart's time; both now count from the restart's (step, time).
    thermo = read_thermo(folder)
    rows = thermo[thermo["step"] >= start]
    expected = start * dt_base["time_step"] + (rows["step"] - start) * spec["time_step"]
    assert np.allclose(rows["time"], expected, rtol=1e-9, atol=1e-12)
    from drumflow.bench.profile import profile_run
    loops = profile_run(folder.parent, window_s=math.inf).loops
    assert loops["start_time_s"].min() == pytest.approx(start * dt_base["time_step"], rel=1e-9)
    meta = json.loads(out.with_suffix(".json").read_text())
    assert meta["steps"] == 100 and meta["machine"]["cpus"] >= 1 and meta["resumed"] == []

    # Run again (as after an interrupt): every measured variant is kept, none is rerun.
    before = {p: p.stat().st_mtime_ns for p in study.glob("variants/*/dem/log.liggghts")}
    again = _bench_from(run, run / "case.toml", study)
    assert again.returncode == 0, again.stderr[-3000:]
    measured = [v.name for v in variants if v.min_ranks == 1]
    assert json.loads(out.with_suffix(".json").read_text())["resumed"] == measured
    assert {p: p.stat().st_mtime_ns for p in study.glob("variants/*/dem/log.liggghts")} == before
    assert pd.read_csv(out).set_index("variant")["coupled_wall_s"].equals(table["coupled_wall_s"])


def test_settings_study_refuses_another_scene(run: Path, tmp_path: Path) -> None:
    # A case with other particles is another scene: one message naming the section, exit 2,
    # before any solver starts.
    text = (run / "case.toml").read_text()
    other = tmp_path / "other.toml"
    head, particles = text.split("[particles]", 1)
    particles = re.sub(r"(?m)^diameter\s*=\s*([0-9.e-]+)",
                       lambda m: f"diameter = {float(m.group(1)) * 1.1:.6g}", particles, count=1)
    other.write_text(f"{head}[particles]{particles}")
    assert other.read_text() != text
    proc = _bench_from(run, other, tmp_path / "study")
    assert proc.returncode == 2, proc.stderr
    assert "another scene" in proc.stderr and "particles" in proc.stderr
    assert "Traceback" not in proc.stderr
    assert not (tmp_path / "study" / "variants").exists()


def _copied_build(root: Path) -> Path:
    """A 'build from source' that is a copy of the Debian package's library, under another
    path: the comparison's machinery on the real solver without compiling LIGGGHTS."""
    import ctypes.util
    import os
    import shutil

    found = next((p for p in ("/usr/lib/x86_64-linux-gnu/libliggghts.so.3",
                              ctypes.util.find_library("liggghts") or "") if p and os.path.isfile(p)), None)
    assert found is not None, "the Debian package's libliggghts.so.3 (apt libliggghts3)"
    (root / "lib").mkdir(parents=True)
    (root / "bin").mkdir()
    shutil.copy2(found, root / "lib" / "libliggghts.so.3")
    liggghts = shutil.which("liggghts")
    assert liggghts is not None
    (root / "bin" / "liggghts").symlink_to(liggghts)
    (root / "build-flags.txt").write_text("a copy of the Debian package's library (test)\n")
    return root


def test_builds_side_by_side_interleaved(run: Path, tmp_path: Path) -> None:
    # Two builds, two repeats: the runs alternate A-B-A-B, each loaded the library it was given
    # (read back from the loop's own /proc/self/maps), and the same library gives the same
    # end state to the last digit on one rank, so the physics check passes with no slack used.
    copy = _copied_build(tmp_path / "copy")
    study = tmp_path / "builds"
    proc = _bench_from(run, run / "case.toml", study, "--builds", f"debian,{copy}", "--repeats", "2")
    assert proc.returncode == 0, proc.stderr[-3000:]
    table = pd.read_csv(study / "builds.csv")
    assert list(table["arm"]) == ["debian", str(copy), "debian", str(copy)]
    assert list(table["repeat"]) == [0, 0, 1, 1]
    assert table["library_ok"].all(), table[["arm", "library"]]
    assert table.loc[table["arm"] == str(copy), "library"].eq(str(copy / "lib" / "libliggghts.so.3")).all()
    assert not table.loc[table["arm"] == "debian", "library"].str.startswith(str(copy)).any()
    assert (table["steps"] == 100).all() and (table["particle_steps_per_s"] > 0).all()
    assert table["T_end_C"].nunique() == 1 and table["kinetic_energy_J"].nunique() == 1
    meta = json.loads((study / "builds.json").read_text())
    assert meta["arms"][str(copy)]["build"]["flags"].startswith("a copy of the Debian")
    assert meta["arms"]["debian"]["build"]["source"] == "debian package"
    assert table["physics_ok"].all()
    speedup = meta["summary"][str(copy)]["speedup_vs_first"]
    assert speedup["min"] <= speedup["median"] <= speedup["max"] and speedup["median"] > 0
    assert f"{str(copy)}: " in proc.stdout and "x the first arm's speed" in proc.stdout


def test_builds_refused_by_name_before_any_run(run: Path, tmp_path: Path) -> None:
    # A prefix that is not a build, and a single build: exit 2, one message, nothing run.
    empty = tmp_path / "not-a-build"
    empty.mkdir()
    proc = _bench_from(run, run / "case.toml", tmp_path / "b1", "--builds", f"debian,{empty}")
    assert proc.returncode == 2, proc.stderr
    assert str(empty / "lib" / "libliggghts.so.3") in proc.stderr and "Traceback" not in proc.stderr
    assert not (tmp_path / "b1" / "runs").exists()
    proc = _bench_from(run, run / "case.toml", tmp_path / "b2", "--builds", "debian")
    assert proc.returncode == 2 and "two or more different builds" in proc.stderr, proc.stderr


def test_levels_side_by_side_interleaved(tmp_path: Path) -> None:
    # The cost of the physics levels (issue 31): from one restart of a run with shells and air
    # that warms, the loop runs at each level in turn, A-B-C-A-B-C; each level's parts reach
    # the loop's input or are left out of it, and each level logs what it runs (the interior
    # log for shells, the air's temperature for warming).
    from drumflow.pipeline import run_case
    from drumflow.verify.scenes import tiny_drum

    case = tiny_drum(air__model="uniform", air__mass_flow=0.1, air__warming=True,
                     particles__interior="shells", run__time=0.2, run__mass_flow_start=0.1,
                     run__restart_interval=0.1, run__processes=1)
    run = tmp_path / "run"
    run_case(case, run, timeout=300)
    study = tmp_path / "levels"
    proc = _bench_from(run, run / "case.toml", study, "--levels", "--repeats", "2")
    assert proc.returncode == 0, proc.stderr[-3000:]
    table = pd.read_csv(study / "levels.csv")
    names = ["one-way lumped", "shells", "shells + warming"]
    assert list(table["arm"]) == names * 2 and list(table["repeat"]) == [0, 0, 0, 1, 1, 1]
    assert table["physics_ok"].isna().all()  # levels change the physics on purpose
    runs = sorted((study / "runs").iterdir())
    specs = [json.loads((r / "dem" / "coupling.json").read_text()) for r in runs[:3]]
    assert ["interior" in s for s in specs] == [False, True, True]
    assert ["warming" in s for s in specs] == [False, False, True]
    assert not list((runs[0] / "dem" / "coupling").glob("interior_rank*"))
    assert list((runs[1] / "dem" / "coupling").glob("interior_rank*"))
    # The same level gives the same end state in both repeats (one rank, same input) and the
    # levels differ from one another (shells cool the mean more slowly at Bi > 0.1).
    t_end = table.groupby("arm")["T_end_C"]
    assert (t_end.nunique() == 1).all()
    assert t_end.first()["shells"] != t_end.first()["one-way lumped"]
    meta = json.loads((study / "levels.json").read_text())
    assert meta["kind"] == "levels" and meta["arms"]["one-way lumped"]["left_out_of_the_loop"] == [
        "interior", "warming"]
    assert "cost" in proc.stdout
