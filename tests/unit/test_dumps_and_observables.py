"""Dump parsing and the paper's observables on data whose answer is known."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from drumflow.analysis.observables import (
    escaped_particles,
    falling_mass_flow,
    falling_mass_per_interval,
    find_crossings,
    mean_temperature,
)
from drumflow.dem.dumps import read_dump, read_rows, read_series
from drumflow.errors import RunDirectoryError

DUMP = """ITEM: TIMESTEP
{step}
ITEM: NUMBER OF ATOMS
{n}
ITEM: BOX BOUNDS ff ff ff
-0.2 0.2
-0.2 0.2
0 0.1
ITEM: ATOMS id x y z vx vy vz radius f_Temp[0]
{rows}"""


def _write(folder: Path, step: int, rows: list[tuple], prefix: str = "snap") -> None:
    body = "".join(" ".join(str(v) for v in r) + " \n" for r in rows)
    (folder / f"{prefix}.{step:010d}.txt").write_text(DUMP.format(step=step, n=len(rows), rows=body))


def test_read_hand_written_dump(tmp_path: Path) -> None:
    _write(tmp_path, 100, [(2, 0.1, 0.2, 0.3, 0, 0, -1, 0.004, 80.5),
                           (1, -0.1, 0.0, 0.05, 0, 0, 0, 0.004, 90.0)])
    snap = read_dump(tmp_path / "snap.0000000100.txt")
    assert snap.step == 100
    assert snap.ids.tolist() == [1, 2]  # sorted by id
    assert snap.columns["T"].tolist() == [90.0, 80.5]
    assert snap.columns["vz"].tolist() == [0.0, -1.0]


def test_truncated_dump_is_an_error(tmp_path: Path) -> None:
    p = tmp_path / "snap.0000000001.txt"
    p.write_text(DUMP.format(step=1, n=3, rows="1 0 0 0 0 0 0 0.004 90 \n"))
    with pytest.raises(RunDirectoryError, match="header says 3 particles"):
        read_dump(p)


def test_series_marks_lost_particles_nan(tmp_path: Path) -> None:
    _write(tmp_path, 0, [(1, 0, 0.1, 0, 0, 0, 0, 0.004, 90), (2, 0, 0.1, 0, 0, 0, 0, 0.004, 70)])
    _write(tmp_path, 10, [(2, 0, -0.1, 0, 0, 0, 0, 0.004, 71)])
    s = read_series(tmp_path, time_step=0.001)
    assert s.counts.tolist() == [2, 1]
    assert np.isnan(s["T"][1, 0]) and s["T"][1, 1] == 71
    assert s.times.tolist() == [0.0, 0.01]


def test_series_of_equal_counts_but_other_ids_keeps_the_union(tmp_path: Path) -> None:
    """The shortcut for dumps with the same ids must not take two dumps of equal length whose
    ids differ (one particle lost, another inserted)."""
    _write(tmp_path, 0, [(1, 0, 0.1, 0, 0, 0, 0, 0.004, 90), (2, 0, 0.1, 0, 0, 0, 0, 0.004, 70)])
    _write(tmp_path, 10, [(1, 0, 0.1, 0, 0, 0, 0, 0.004, 89), (3, 0, 0.1, 0, 0, 0, 0, 0.004, 60)])
    _write(tmp_path, 20, [(1, 0, 0.1, 0, 0, 0, 0, 0.004, 88), (3, 0, 0.1, 0, 0, 0, 0, 0.004, 59)])
    s = read_series(tmp_path, time_step=0.001)
    assert s.ids.tolist() == [1, 2, 3]
    assert s["T"][:, 0].tolist() == [90, 89, 88]
    assert np.isnan(s["T"][1:, 1]).all() and np.isnan(s["T"][0, 2]) and s["T"][2, 2] == 59


def test_crossings_of_free_fall() -> None:
    # 50 particles released from y = 0.1 at known times fall freely; each crosses y = 0 once
    # at t_release + sqrt(2 * 0.1 / g). Dumps every 2 ms: interpolation error is below
    # (g dt^2 / 8) / v, about 3 microseconds here, so 1e-4 s is a safe tolerance.
    g, dt = 9.81, 0.002
    times = np.arange(0, 1.0 + dt / 2, dt)
    release = np.linspace(0.05, 0.8, 50)
    tau = times[:, None] - release[None, :]
    y = np.where(tau > 0, 0.1 - 0.5 * g * tau**2, 0.1)
    x = np.zeros_like(y)
    z = np.tile(np.linspace(0.0, 0.1, 50), (len(times), 1))
    ids = np.arange(1, 51)
    table = find_crossings(times, ids, x, y, z)
    assert len(table) == 50
    expected = np.sort(release + np.sqrt(2 * 0.1 / g))
    assert np.allclose(table["time"], expected, atol=1e-4)
    assert np.allclose(np.sort(table["z"]), np.linspace(0, 0.1, 50))
    # Upward motion is not counted: reverse time.
    assert len(find_crossings(times, ids, x, y[::-1], z)) == 0


def test_falling_mass_flow_eq57() -> None:
    t = np.array([0.5, 1.0, 1.5, 2.0, 3.0])
    table = pd.DataFrame({"time": t, "id": np.arange(5), "x": [0, 0, 0.19, 0, 0], "z": 0.0})
    flow = falling_mass_flow(table, particle_mass=0.002, start=1.0, curtain_radius=0.1)
    # Four crossings from 1.0 s to 3.0 s: 4 * 2 g / 2 s = 4 g/s; one of them is near the wall.
    assert flow.crossings == 4
    assert flow.mass_flow_kg_s == pytest.approx(0.004)
    assert flow.curtain_mass_flow_kg_s == pytest.approx(0.003)
    per = falling_mass_per_interval(table, np.array([0.0, 1.25, 2.5, 3.5]), 0.002)
    assert per.tolist() == pytest.approx([0.004, 0.004, 0.002])
    assert falling_mass_flow(table.iloc[:1], 0.002).mass_flow_kg_s == 0.0


def test_mean_temperature_is_mass_weighted() -> None:
    T = np.array([[10.0, 20.0], [np.nan, 30.0]])
    m = np.array([1.0, 3.0])
    assert mean_temperature(T, m).tolist() == pytest.approx([17.5, 30.0])


def test_escaped_particles() -> None:
    x = np.array([[0.0, 0.0, 0.3], [0.0, 0.0, 0.3]])
    y = np.array([[0.0, 0.199, 0.0], [0.0, 0.25, 0.0]])
    assert escaped_particles(x, y, radius=0.2, particle_radius=0.004) == 2


def test_crossings_from_band_dumps(tmp_path: Path) -> None:
    """Particles enter and leave the band: a crossing needs both sides in consecutive dumps."""
    row = lambda i, y, z=0.05: (i, 0.0, y, z, 0, 0, 0, 0.004, 90)  # noqa: E731
    _write(tmp_path, 0, [row(1, 0.03), row(2, 0.02)], "cross")
    _write(tmp_path, 10, [row(1, -0.01), row(3, 0.01)], "cross")  # 1 crosses; 2 left the band
    _write(tmp_path, 20, [row(2, -0.02), row(3, -0.03, 0.07)], "cross")  # 2 skipped a dump
    rows = read_rows(tmp_path, time_step=0.001, prefix="cross")
    from drumflow.analysis.observables import crossings_from_rows

    table = crossings_from_rows(rows.times, rows.frame, rows.ids, rows["x"], rows["y"], rows["z"])
    assert table["id"].tolist() == [1, 3]
    # Particle 1: y 0.03 -> -0.01 over 0.01 s crosses at 3/4 of the interval.
    assert table["time"].tolist() == pytest.approx([0.0075, 0.0125])
    assert table["z"].iloc[1] == pytest.approx(0.05 + 0.25 * 0.02)


# ----------------------------------------------------------------------- packed snapshots


def test_packed_snapshot_reads_back_what_the_text_held(tmp_path: Path) -> None:
    from drumflow.dem.dumps import dump_files, pack_dumps

    rng = np.random.default_rng(3)
    n = 500
    rows = [(int(i), *np.round(rng.uniform(-1.5, 1.5, 6), 7), 0.004, round(float(t), 6))
            for i, t in zip(rng.permutation(n) + 1, rng.uniform(30.0, 90.0, n), strict=True)]
    for step in (0, 50, 100):
        _write(tmp_path, step, rows)
    text = {p.name: read_dump(p) for p in dump_files(tmp_path)}
    series_text = read_series(tmp_path, time_step=0.01)
    # During a run the newest dump may be being written: it stays text.
    packed = pack_dumps(tmp_path, keep_newest=1)
    assert [p.name for p in packed] == ["snap.0000000000.npz", "snap.0000000050.npz"]
    assert [p.name for p in dump_files(tmp_path)] == [
        "snap.0000000000.npz", "snap.0000000050.npz", "snap.0000000100.txt"]
    pack_dumps(tmp_path)
    assert sorted(p.name for p in tmp_path.iterdir()) == [
        "snap.0000000000.npz", "snap.0000000050.npz", "snap.0000000100.npz"]
    for name, before in text.items():
        after = read_dump(tmp_path / name.replace(".txt", ".npz"))
        assert after.step == before.step and list(after.columns) == list(before.columns)
        assert np.array_equal(after.ids, before.ids)
        # Temperatures: every digit; positions, velocities, radius: float32, 6e-8 relative
        # (the text's 8 digits are 1e-7 m at 1.5 m).
        assert np.array_equal(after.columns["T"], before.columns["T"])
        for c in ("x", "y", "z", "vx", "vy", "vz", "radius"):
            np.testing.assert_allclose(after.columns[c], before.columns[c], rtol=6e-8, atol=0)
    series = read_series(tmp_path, time_step=0.01)
    assert np.array_equal(series.steps, series_text.steps)
    assert np.array_equal(series["T"], series_text["T"])


def test_what_does_not_vary_is_packed_once(tmp_path: Path) -> None:
    """One radius for every particle and ids 1..N are kept as one value each; ids with a gap (a
    particle lost) and varying columns in full; both read back as they were."""
    from drumflow.dem.dumps import pack_dump

    n = 400
    rng = np.random.default_rng(5)
    xyz = np.round(rng.uniform(-1.0, 1.0, (n, 3)), 7)
    whole = [(i + 1, *xyz[i], 0.0, 0.0, 0.0, 0.004, 90.0) for i in range(n)]
    gap = [r for r in whole if r[0] != 17]
    _write(tmp_path, 0, whole)
    _write(tmp_path, 10, gap)
    before = {s: read_dump(tmp_path / f"snap.{s:010d}.txt") for s in (0, 10)}
    packed = {s: pack_dump(tmp_path / f"snap.{s:010d}.txt") for s in (0, 10)}
    with np.load(packed[0]) as data:
        assert data["c_radius"].shape == (1,) and data["c_T"].shape == (1,) and "c_id" not in data
        assert data["c_x"].shape == (n,)
    with np.load(packed[10]) as data:
        assert data["c_id"].shape == (n - 1,) and data["c_radius"].shape == (1,)
    for s, path in packed.items():
        after = read_dump(path)
        assert np.array_equal(after.ids, before[s].ids) and len(after) == len(before[s])
        for c in ("radius", "T", "vx"):
            assert np.array_equal(after.columns[c], before[s].columns[c].astype(np.float32))
    # 400 ids (int32) and radii (float32) are 3.2 kB less than in full.
    assert packed[0].stat().st_size < packed[10].stat().st_size - 1500


def test_snapshots_packed_before_the_elision_still_read(tmp_path: Path) -> None:
    # Regression guard: runs packed by earlier drumflow (shipped, or a long run resumed on new
    # code) keep their files; those have every column in full and no row count.
    old = tmp_path / "snap.0000000020.npz"
    np.savez(old, step=np.array(20), names=np.array(["id", "x", "radius"]),
             c_id=np.array([1, 2, 3], dtype=np.int32), c_x=np.array([0.1, 0.2, 0.3], dtype=np.float32),
             c_radius=np.array([0.004] * 3, dtype=np.float32))
    snap = read_dump(old)
    assert snap.step == 20 and snap.ids.tolist() == [1, 2, 3]
    assert snap.columns["radius"].tolist() == pytest.approx([0.004] * 3)


def test_a_partial_pack_is_ignored_and_a_bad_one_named(tmp_path: Path) -> None:
    from drumflow.dem.dumps import dump_files

    _write(tmp_path, 10, [(1, 0, 0.1, 0, 0, 0, 0, 0.004, 90)])
    # A run stopped while packing leaves the temporary file: the text is still the dump.
    (tmp_path / "snap.0000000010.npz.partial").write_bytes(b"half")
    assert [p.name for p in dump_files(tmp_path)] == ["snap.0000000010.txt"]
    bad = tmp_path / "snap.0000000020.npz"
    bad.write_bytes(b"not a zip")
    with pytest.raises(RunDirectoryError, match="not a packed drumflow snapshot"):
        read_dump(bad)


def test_a_dump_cut_short_stays_text_and_the_others_are_packed(tmp_path: Path) -> None:
    from drumflow.dem.dumps import pack_dumps

    _write(tmp_path, 10, [(1, 0, 0.1, 0, 0, 0, 0, 0.004, 90)])
    (tmp_path / "snap.0000000020.txt").write_text(DUMP.format(step=20, n=3, rows="1 0 0 0 0 0 0 0.004 90 \n"))
    _write(tmp_path, 30, [(1, 0, 0.1, 0, 0, 0, 0, 0.004, 80)])
    with pytest.raises(RunDirectoryError, match="header says 3 particles"):
        pack_dumps(tmp_path)
    # During a run, housekeeping skips it: the run goes on, and post names the file later.
    packed = pack_dumps(tmp_path, skip_unreadable=True)
    assert [p.name for p in packed] == ["snap.0000000030.npz"]
    assert (tmp_path / "snap.0000000020.txt").exists()


def test_a_newest_snapshot_cut_short_is_left_out_only_when_asked(tmp_path: Path) -> None:
    _write(tmp_path, 0, [(1, 0, 0.1, 0, 0, 0, 0, 0.004, 90), (2, 0, 0.1, 0, 0, 0, 0, 0.004, 70)])
    (tmp_path / "snap.0000000010.txt").write_text(
        DUMP.format(step=10, n=2, rows="1 0 0.1 0 0 0 0 0.004 89 \n"))  # LIGGGHTS mid-write
    with pytest.raises(RunDirectoryError, match="header says 2 particles"):
        read_series(tmp_path, time_step=0.001)
    s = read_series(tmp_path, time_step=0.001, skip_partial_newest=True)
    assert s.steps.tolist() == [0] and [p.name for p in s.skipped] == ["snap.0000000010.txt"]


def test_crossings_csv_is_the_pandas_text(tmp_path: Path) -> None:
    """post/crossings.csv is written row by row for speed; its text is what pandas' to_csv with
    %.6g gave (readers and shipped results unchanged)."""
    import pandas as pd

    from drumflow.pipeline import write_crossings_csv

    rng = np.random.default_rng(3)
    n = 1000
    frame = pd.DataFrame({"time": rng.uniform(0, 17.5, n), "id": rng.integers(1, 467_443, n),
                          "x": rng.uniform(-1.5, 1.5, n), "z": rng.uniform(0, 0.1, n)})
    frame.loc[0, "x"], frame.loc[1, "z"], frame.loc[2, "time"] = 1e-7, -0.0, 123456789.0
    write_crossings_csv(tmp_path / "a.csv", frame)
    frame.to_csv(tmp_path / "b.csv", index=False, float_format="%.6g")
    assert (tmp_path / "a.csv").read_text() == (tmp_path / "b.csv").read_text()
