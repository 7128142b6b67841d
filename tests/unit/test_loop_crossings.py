"""Crossings found in the coupling loop (drumflow.coupling.crossings) against the dump route
(drumflow.analysis.observables.crossings_from_rows): the same test and interpolation, so the
same table from the same positions."""

from __future__ import annotations

from pathlib import Path

import numpy as np

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
    np.testing.assert_allclose(loop[order], expected, rtol=0, atol=1e-12)
    # Written and read back as the loop writes it (10 and 8 significant digits).
    path = tmp_path / "crossings.csv"
    path.write_text("time,id,x,z\n" + "".join(f"{t:.10g},{int(i)},{x:.8g},{z:.8g}\n"
                                              for t, i, x, z in loop))
    back = read_loop_crossings(path)
    assert sorted(back[:, 1].astype(int)) == sorted(loop[:, 1].astype(int))
    np.testing.assert_allclose(np.sort(back[:, 0]), np.sort(loop[:, 0]), rtol=1e-9)
    assert read_loop_crossings(_empty(tmp_path)).shape == (0, 4)


def _empty(tmp_path: Path) -> Path:
    path = tmp_path / "empty.csv"
    path.write_text("time,id,x,z\n")
    return path
