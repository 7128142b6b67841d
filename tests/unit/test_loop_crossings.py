"""Crossings found in the coupling loop (drumflow.coupling.crossings) against the dump route
(drumflow.analysis.observables.crossings_from_rows): the same test and interpolation, so the
same table from the same positions."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from drumflow.analysis.observables import crossings_from_rows
from drumflow.coupling.crossings import downward_crossings, read_loop_crossings


def test_loop_crossings_equal_the_dump_route(tmp_path: Path) -> None:
    rng = np.random.default_rng(3)
    n_t, n_p = 40, 300
    times = np.linspace(0.0, 0.39, n_t)
    ids = np.arange(1, n_p + 1)
    # Particles falling through the plane at random speeds and phases, some rising.
    y0 = rng.uniform(-0.1, 0.1, n_p)
    vy = rng.uniform(-1.0, 0.5, n_p)
    pos = np.empty((n_t, n_p, 3))
    pos[:, :, 0] = rng.uniform(-0.1, 0.1, n_p) + 0.05 * times[:, None]
    pos[:, :, 1] = y0 + vy * times[:, None] - 4.9 * times[:, None] ** 2
    pos[:, :, 2] = rng.uniform(0, 0.05, n_p)
    # Some particles absent from some instants (a band dump, or a lost particle).
    absent = rng.random((n_t, n_p)) < 0.05
    pos[absent] = np.nan
    rows = []
    for k in range(1, n_t):
        rows.append(downward_crossings(times[k - 1], times[k], ids, pos[k - 1], pos[k]))
    loop = np.concatenate(rows)
    present = ~absent
    frame = np.broadcast_to(np.arange(n_t)[:, None], (n_t, n_p))[present]
    pid = np.broadcast_to(ids[None, :], (n_t, n_p))[present]
    dump = crossings_from_rows(times, frame, pid, pos[:, :, 0][present], pos[:, :, 1][present],
                               pos[:, :, 2][present])
    assert len(loop) == len(dump) > 50
    order = np.lexsort((loop[:, 1], loop[:, 0]))
    expected = dump.sort_values(["time", "id"]).to_numpy()
    np.testing.assert_allclose(loop[order][:, :4], expected, rtol=0, atol=1e-12)
    assert np.isnan(loop[:, 4]).all()  # no contact counts given: unknown
    # Written and read back as the loop writes it (10 and 8 significant digits).
    path = tmp_path / "crossings.csv"
    path.write_text("time,id,x,z\n" + "".join(f"{t:.10g},{int(i)},{x:.8g},{z:.8g}\n"
                                              for t, i, x, z, _ in loop))
    back = read_loop_crossings(path)
    assert sorted(back["id"]) == sorted(loop[:, 1].astype(int))
    np.testing.assert_allclose(back["time"], np.sort(loop[:, 0]), rtol=1e-9)
    # A table of a drumflow before the contact column: contacts unknown.
    assert back["in_contact"].isna().all()
    assert read_loop_crossings(_empty(tmp_path)).shape == (0, 5)


def test_a_crossing_is_airborne_only_without_contact_at_both_updates() -> None:
    ids = np.arange(1, 5)
    before = np.array([[0.0, 0.1, 0.0], [0.2, 0.1, 0.0], [0.4, 0.1, 0.0], [0.6, 0.1, 0.0]])
    after = before - [0.0, 0.2, 0.0]  # all four cross at mid-interval
    touching_before = np.array([0.0, 2.0, 0.0, np.nan])
    touching_after = np.array([0.0, 0.0, 1.0, 0.0])
    rows = downward_crossings(1.0, 1.1, ids, before, after, touching_before, touching_after)
    by_id = {int(r[1]): r[4] for r in rows}
    assert by_id[1] == 0.0  # free at both updates: airborne
    assert by_id[2] == 1.0 and by_id[3] == 1.0  # touching at either: the bed
    assert np.isnan(by_id[4])  # unknown at one update: unknown
    np.testing.assert_allclose(rows[:, 0], 1.05)


def test_the_falling_flow_splits_by_contact() -> None:
    from drumflow.analysis.observables import falling_mass_flow

    # 11 crossings over 1.0-2.0 s (one before the window): 3 airborne, 7 in the bed.
    times = [0.5, *np.linspace(1.0, 2.0, 10)]
    contact = [0.0, 0, 1, 1, 0, 1, 1, 1, 0, 1, 1]
    table = pd.DataFrame({"time": times, "id": range(11), "x": 0.0, "z": 0.0, "in_contact": contact})
    flow = falling_mass_flow(table, 0.5, start=1.0)
    assert flow.mass_flow_kg_s == pytest.approx(10 * 0.5 / 1.0)
    assert flow.airborne_mass_flow_kg_s == pytest.approx(3 * 0.5)
    assert flow.bed_mass_flow_kg_s == pytest.approx(7 * 0.5)
    # One unknown crossing in the window: no split (never a split of part of the crossings).
    table.loc[5, "in_contact"] = np.nan
    assert math.isnan(falling_mass_flow(table, 0.5, start=1.0).airborne_mass_flow_kg_s)
    # A table without the column (the band dump's route).
    assert math.isnan(falling_mass_flow(table.drop(columns="in_contact"), 0.5).bed_mass_flow_kg_s)


def test_post_keeps_the_contact_column_only_where_it_is_known(tmp_path: Path) -> None:
    from drumflow.pipeline import write_crossings_csv

    table = pd.DataFrame({"time": [1.0, 2.0], "id": [3, 4], "x": [0.1, 0.2], "z": [0.0, 0.0],
                          "in_contact": [0.0, np.nan]})
    write_crossings_csv(tmp_path / "a.csv", table)
    assert (tmp_path / "a.csv").read_text() == "time,id,x,z,in_contact\n1,3,0.1,0,0\n2,4,0.2,0,\n"
    write_crossings_csv(tmp_path / "b.csv", table.assign(in_contact=np.nan))
    assert (tmp_path / "b.csv").read_text().splitlines()[0] == "time,id,x,z"


def _empty(tmp_path: Path) -> Path:
    path = tmp_path / "empty.csv"
    path.write_text("time,id,x,z\n")
    return path
