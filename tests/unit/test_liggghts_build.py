"""Which LIGGGHTS runs (issue 35, item 5): the Debian package by default, a build from source
when ``DRUMFLOW_LIGGGHTS_PREFIX`` names one; refused by name when the prefix is not a build;
recorded in the manifest; the arms of an interleaved comparison (builds, physics levels) and
its summary (median of per-repeat ratios)."""

from __future__ import annotations

from pathlib import Path

import pandas as pd
import pytest

from drumflow.bench.interleaved import build_arms, level_arms, library_matches, summarise
from drumflow.errors import SettingsStudyError, SolverNotFoundError
from drumflow.runner import (
    LIBRARY_VARIABLE,
    PREFIX_VARIABLE,
    LaunchProfile,
    LiggghtsBuild,
    liggghts_build,
)


def _fake_build(root: Path, flags: str | None = "g++ 12.2 -O3 -march=native") -> Path:
    (root / "bin").mkdir(parents=True)
    (root / "lib").mkdir()
    (root / "bin" / "liggghts").write_text("")
    (root / "lib" / "libliggghts.so.3").write_text("")
    if flags is not None:
        (root / "build-flags.txt").write_text(flags + "\n")
    return root


def test_debian_package_by_default(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.delenv(PREFIX_VARIABLE, raising=False)
    build = liggghts_build()
    assert build == LiggghtsBuild(None, "liggghts", None, None)
    profile = LaunchProfile()
    assert profile.liggghts == "liggghts" and LIBRARY_VARIABLE not in profile.env
    assert profile.software_versions()["liggghts_build"]["source"] == "debian package"


def test_prefix_selects_the_build_everywhere(monkeypatch: pytest.MonkeyPatch, tmp_path: Path) -> None:
    root = _fake_build(tmp_path / "native")
    monkeypatch.setenv(PREFIX_VARIABLE, str(root))
    profile = LaunchProfile()
    assert profile.liggghts == str(root / "bin" / "liggghts")
    # The coupling loop's processes load the build's library.
    assert profile.env[LIBRARY_VARIABLE] == str(root / "lib" / "libliggghts.so.3")
    assert profile.liggghts_command("in.drum", "log", 2)[3] == str(root / "bin" / "liggghts")
    described = profile.software_versions()["liggghts_build"]
    assert described == {"source": "built from source", "prefix": str(root),
                         "flags": "g++ 12.2 -O3 -march=native"}


def test_a_prefix_that_is_not_a_build_is_refused_by_name(monkeypatch: pytest.MonkeyPatch,
                                                         tmp_path: Path) -> None:
    root = tmp_path / "half"
    (root / "bin").mkdir(parents=True)
    (root / "bin" / "liggghts").write_text("")
    monkeypatch.setenv(PREFIX_VARIABLE, str(root))
    with pytest.raises(SolverNotFoundError) as err:
        LaunchProfile()
    message = str(err.value)
    assert PREFIX_VARIABLE in message and str(root / "lib" / "libliggghts.so.3") in message
    assert str(root / "bin" / "liggghts") not in message.split("(")[1]  # only what is missing
    # On the bench's command line it is bad input (exit 2), named the same way.
    with pytest.raises(SettingsStudyError, match="--builds: .*libliggghts.so.3 missing"):
        build_arms(["debian", str(root)])


def test_build_lists_refused() -> None:
    for names in (["debian"], ["debian", "debian"], ["", "debian"]):
        with pytest.raises(SettingsStudyError, match="two or more different builds"):
            build_arms(names)


def test_library_matches(tmp_path: Path) -> None:
    a = liggghts_build(str(_fake_build(tmp_path / "a")))
    debian = LiggghtsBuild(None, "liggghts", None, None)
    lib_a = str(tmp_path / "a" / "lib" / "libliggghts.so.3")
    link = tmp_path / "link.so"
    link.symlink_to(lib_a)
    assert library_matches(lib_a, a, [debian, a]) and library_matches(str(link), a, [debian, a])
    assert not library_matches("/usr/lib/x86_64-linux-gnu/libliggghts.so.3", a, [debian, a])
    assert library_matches("/usr/lib/x86_64-linux-gnu/libliggghts.so.3", debian, [debian, a])
    assert not library_matches(lib_a, debian, [debian, a]) and not library_matches(None, debian, [debian])


def test_summary_is_the_median_of_neighbouring_ratios() -> None:
    # Repeat 1 ran on a slow stretch for both builds: per-repeat ratios 2.0, 2.0, 2.0 (all
    # neighbours agree) although the walls spread 10-30 s; medians 12 and 6 s, ranges written.
    rows = []
    for repeat, (wall_a, wall_b) in enumerate([(12.0, 6.0), (30.0, 15.0), (10.0, 5.0)]):
        for arm, wall in (("debian", wall_a), ("/opt/x", wall_b)):
            rows.append({"arm": arm, "repeat": repeat, "status": "ok", "coupled_wall_s": wall,
                         "particle_steps_per_s": 1000.0 / wall, "contended": repeat == 1,
                         "python_wall_s": 0.1 * wall, "liggghts_wall_s": 0.9 * wall,
                         "physics_ok": True, "library_ok": True})
    summary = summarise(pd.DataFrame(rows), ["debian", "/opt/x"])
    b = summary["/opt/x"]
    assert b["speedup_vs_first"] == {"median": 2.0, "min": 2.0, "max": 2.0}
    assert b["coupled_wall_s"] == {"median": 6.0, "min": 5.0, "max": 15.0}
    assert summary["debian"]["coupled_wall_s"]["median"] == 12.0
    assert summary["debian"]["speedup_vs_first"]["median"] == 1.0
    assert b["contended_runs"] == 1 and b["runs"] == 3 and b["physics_ok"] and b["library_ok"]
    # The loop's extra time over the first arm's wall: medians 0.6 and 1.2 s of loop, 12 s of wall.
    assert b["loop_cost_vs_first"] == pytest.approx(1.0 + (0.6 - 1.2) / 12.0, rel=1e-12)
    # A ratio of medians would say 12 / 6 = 2 as well here; with an outlier repeat it would not:
    rows[3]["coupled_wall_s"] = 60.0  # repeat 1 of /opt/x on a much slower stretch
    b = summarise(pd.DataFrame(rows), ["debian", "/opt/x"])["/opt/x"]
    assert b["speedup_vs_first"] == {"median": 2.0, "min": 0.5, "max": 2.0}


def test_level_arms_follow_what_the_run_has(tmp_path: Path) -> None:
    both = {"interval": 10, "interior": {"shells": 5}, "warming": {"spacing": 0.05}}
    arms = level_arms(both, tmp_path)
    assert [a.name for a in arms] == ["one-way lumped", "shells", "shells + warming"]
    assert [a.drop for a in arms] == [("interior", "warming"), ("warming",), ()]
    assert not any(a.same_physics for a in arms)
    only_warming = level_arms({"interval": 10, "warming": {}}, tmp_path)
    assert [a.name for a in only_warming] == ["one-way lumped", "warming"]
    with pytest.raises(SettingsStudyError, match="paper's level only"):
        level_arms({"interval": 10}, tmp_path)


def test_levels_of_air_around_the_bed_fly_the_lower_levels_through_the_empty_drum(tmp_path: Path) -> None:
    """A run of air around the bed: its own air is the bed states' phases, the levels below it
    take the empty drum's one-way air the run kept (air/field.npz), and without it the bench
    refuses by name."""
    around = {"interval": 10, "interior": {"shells": 5}, "warming": {"spacing": 0.05},
              "field": {"kind": "phases", "paths": ["x.npz"], "angles": [0.0]}}
    with pytest.raises(SettingsStudyError, match="field.npz"):
        level_arms(around, tmp_path)
    (tmp_path / "air").mkdir()
    (tmp_path / "air" / "field.npz").write_bytes(b"")
    arms = level_arms(around, tmp_path)
    assert [a.name for a in arms] == ["one-way lumped", "shells", "shells + warming", "air around the bed"]
    assert [a.one_way_field for a in arms] == [tmp_path / "air" / "field.npz"] * 3 + [None]
    assert arms[-1].drop == ()


def test_builds_describe_their_flags(tmp_path: Path) -> None:
    arms = build_arms(["debian", str(_fake_build(tmp_path / "n", flags="g++ 12 -O3\nmore"))])
    assert arms[0].description.startswith("the Debian package")
    assert arms[1].description == "g++ 12 -O3" and arms[1].same_physics and arms[1].drop == ()


def test_contention_is_the_cpu_of_other_programs() -> None:
    # A child that spins for 0.4 s of CPU: its time is counted as the run's own (rusage of the
    # waited-for child), and the machine's busy time grew by at least as much.
    import subprocess
    import sys

    from drumflow.bench.interleaved import children_cpu_s
    from drumflow.machine_load import machine_busy_cpu_s

    busy0, own0 = machine_busy_cpu_s(), children_cpu_s()
    subprocess.run([sys.executable, "-c", "import time\nt = time.process_time()\n"
                    "while time.process_time() - t < 0.4: pass"], check=True)
    own = children_cpu_s() - own0
    assert 0.4 <= own < 2.0
    # /proc/stat counts in clock ticks (1/100 s): the machine was busy at least the child's time.
    assert machine_busy_cpu_s() - busy0 >= own - 0.05
