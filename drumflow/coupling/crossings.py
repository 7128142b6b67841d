"""Crossings of the axis plane found in the coupling loop, with the particles in memory.

The text crossing dump writes every particle within a band around the plane ``y = 0`` at every
output step, so that :func:`drumflow.analysis.observables.crossings_from_rows` can find the
downward crossings afterwards: about 3 GB for the paper's model one over 17.5 s. The loop holds
every particle at every air update anyway; this module finds the crossings there, by the same
test and the same linear interpolation, and writes only them (``coupling/crossings.csv``:
``time, id, x, z``, a few tens of bytes per crossing). ``run.crossings = "loop"`` switches the
dump off; the 'converged' stop rule (:mod:`drumflow.coupling.stop`) counts the same crossings.

The loop samples at every air update, at most one output step apart, so it sees every
crossing the dump sees (and, with updates more frequent than output steps, the rare particle
that crosses down and back up within one output step).
"""

from __future__ import annotations

import ctypes as C
from pathlib import Path
from typing import TYPE_CHECKING, TextIO

import numpy as np
import pandas as pd
from numpy.typing import NDArray

from drumflow.coupling.mpi import allreduce_sum

if TYPE_CHECKING:
    from drumflow.coupling.library import Liggghts

__all__ = ["CROSSINGS_RECORD", "CrossingTracker", "downward_crossings", "read_loop_crossings"]

#: The loop's crossing table, relative to the DEM working directory.
CROSSINGS_RECORD = "coupling/crossings.csv"
_HEADER = "time,id,x,z"


def downward_crossings(t0: float, t1: float, ids: NDArray[np.int64], before: NDArray[np.float64],
                       after: NDArray[np.float64]) -> NDArray[np.float64]:
    """Particles that went from above ``y = 0`` to on or below it between two instants.

    Parameters
    ----------
    t0, t1
        The two instants, s.
    ids
        Particle ids, shape (n,).
    before, after
        Positions (n, 3) at ``t0`` and ``t1``; NaN rows mark particles absent at that instant.

    Returns
    -------
    numpy.ndarray
        Rows ``time, id, x, z`` (interpolated linearly in y, as
        :func:`drumflow.analysis.observables.crossings_from_rows` does), sorted by time.
    """
    y0, y1 = before[:, 1], after[:, 1]
    with np.errstate(invalid="ignore"):
        hit = np.nonzero((y0 > 0.0) & (y1 <= 0.0))[0]
    frac = y0[hit] / (y0[hit] - y1[hit])
    rows = np.column_stack([
        t0 + frac * (t1 - t0),
        ids[hit].astype(float),
        before[hit, 0] + frac * (after[hit, 0] - before[hit, 0]),
        before[hit, 2] + frac * (after[hit, 2] - before[hit, 2]),
    ])
    return rows[np.argsort(rows[:, 0], kind="stable")]


def read_loop_crossings(path: Path) -> NDArray[np.float64]:
    """The loop's crossing table as an (n, 4) array ``time, id, x, z`` (sorted by time)."""
    table = pd.read_csv(path, dtype=np.float64).to_numpy().reshape(-1, 4)
    return table[np.argsort(table[:, 0], kind="stable")]


def _atom_ids(lmp: Liggghts) -> NDArray[np.int64]:
    """This rank's particle ids (LIGGGHTS 3.8 ``tagint`` is a 32-bit int)."""
    n = lmp.nlocal
    if n == 0:
        return np.empty(0, dtype=np.int64)
    ptr = lmp._lib.lammps_extract_atom(lmp._handle, b"id")
    if not ptr:
        raise KeyError("LIGGGHTS has no per-atom ids")
    return np.ctypeslib.as_array(C.cast(ptr, C.POINTER(C.c_int32)), shape=(n,)).astype(np.int64)


class CrossingTracker:
    """Downward crossings of ``y = 0`` between consecutive air updates, over all MPI ranks.

    Parameters
    ----------
    particles
        Particles in the run (ids 1..particles).
    work
        The DEM working directory.
    rank
        This process's MPI rank (rank 0 counts and writes).
    write
        Write the crossing table (``run.crossings = "loop"``); else only count them.
    start_time
        Simulated time the loop starts at; rows an earlier attempt wrote from then on are
        dropped (the resumed run finds them again).
    """

    def __init__(self, particles: int, work: Path, rank: int, write: bool, start_time: float) -> None:
        self.n = particles
        self.rank = rank
        self.ids = np.arange(1, particles + 1, dtype=np.int64)
        self.previous: tuple[float, NDArray[np.float64]] | None = None
        self.total = 0
        self._out: TextIO | None = None
        if write and rank == 0:
            path = work / CROSSINGS_RECORD
            kept = []
            if path.exists() and start_time > 0:
                kept = [ln for ln in path.read_text().splitlines()[1:]
                        if ln and float(ln.split(",", 1)[0]) < start_time]
            path.parent.mkdir(parents=True, exist_ok=True)
            out = path.open("w")
            out.write(_HEADER + "\n" + "".join(k + "\n" for k in kept))
            out.flush()
            self._out = out

    def update(self, lmp: Liggghts, time_s: float) -> int | None:
        """Take the particles at ``time_s``; return the crossings since the last update (rank 0;
        None on the other ranks and at the first update of an attempt). Every rank must call
        it at every update."""
        ids = _atom_ids(lmp)
        x = lmp.atom_array("x")
        # One reduction: every rank adds its particles' positions and a presence flag into
        # id-indexed arrays (particles migrate between ranks; ids do not change).
        local = np.zeros((self.n, 4))
        local[ids - 1, :3] = x
        local[ids - 1, 3] = 1.0
        total = allreduce_sum(local.ravel()).reshape(self.n, 4)
        if self.rank != 0:
            return None
        positions = np.where(total[:, 3:4] > 0.5, total[:, :3], np.nan)
        found = None
        if self.previous is not None:
            t0, before = self.previous
            rows = downward_crossings(t0, time_s, self.ids, before, positions)
            found = len(rows)
            if self._out is not None and found:
                self._out.write("".join(f"{t:.10g},{int(i)},{px:.8g},{pz:.8g}\n"
                                        for t, i, px, pz in rows))
                self._out.flush()
        self.previous = (time_s, positions)
        self.total += found or 0
        return found

    def close(self) -> None:
        if self._out is not None:
            self._out.close()
            self._out = None
