"""Crossings of the axis plane found in the coupling loop, with the particles in memory.

The text crossing dump writes every particle within a band around the plane ``y = 0`` at every
output step, so that :func:`drumflow.analysis.observables.crossings_from_rows` can find the
downward crossings afterwards: about 3 GB for the paper's model one over 17.5 s. The loop holds
every particle at every air update anyway; this module finds the crossings there, by the same
test and the same linear interpolation, and writes only them (``coupling/crossings.csv``:
``time, id, x, z, in_contact``, a few tens of bytes per crossing).

What is falling: a downward crossing of the axis plane is either a granule in free fall (from a
flight, through the curtain) or the bed's own surface rolling across the plane where the bed
reaches it, or granules carried down on a lifter. The loop tells them apart by a physical
criterion, not a geometric cut: whether the particle touches anything at the two air updates
that bracket the crossing, another particle (LIGGGHTS' ``compute touching all contact/atom/gran``:
pairs at or within touching distance, on the pair's own neighbour list) or a wall (the wall
fix's per-atom force, ``store_force yes``: non-zero while in contact with the shell, a lifter or
an end). ``in_contact`` is 0 for a particle touching nothing at both (airborne), 1 otherwise
(the bed, a lifter's load, or a granule colliding in a dense curtain just then), and empty
where the deck has neither (a study from an older run's deck). ``run.crossings = "loop"`` switches the
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

__all__ = ["CONTACT_COMPUTE", "CROSSINGS_RECORD", "CrossingTracker", "atom_ids", "downward_crossings",
           "read_loop_crossings"]

#: The loop's crossing table, relative to the DEM working directory.
CROSSINGS_RECORD = "coupling/crossings.csv"
_HEADER = "time,id,x,z,in_contact"
#: The deck's per-atom contact count and per-atom wall force (drumflow/dem/templates/drum.in.j2).
CONTACT_COMPUTE = "touching"
WALL_FORCE = "force_walls"


def downward_crossings(t0: float, t1: float, ids: NDArray[np.int64], before: NDArray[np.float64],
                       after: NDArray[np.float64], touching_before: NDArray[np.float64] | None = None,
                       touching_after: NDArray[np.float64] | None = None) -> NDArray[np.float64]:
    """Particles that went from above ``y = 0`` to on or below it between two instants.

    Parameters
    ----------
    t0, t1
        The two instants, s.
    ids
        Particle ids, shape (n,).
    before, after
        Positions (n, 3) at ``t0`` and ``t1``; NaN rows mark particles absent at that instant.
    touching_before, touching_after
        Each particle's contact count at ``t0`` and ``t1`` (NaN: unknown); None: not known.

    Returns
    -------
    numpy.ndarray
        Rows ``time, id, x, z, in_contact`` (interpolated linearly in y, as
        :func:`drumflow.analysis.observables.crossings_from_rows` does), sorted by time;
        ``in_contact`` is 1 when the particle touched another at either instant, 0 when at
        neither, NaN when unknown.
    """
    y0, y1 = before[:, 1], after[:, 1]
    with np.errstate(invalid="ignore"):
        hit = np.nonzero((y0 > 0.0) & (y1 <= 0.0))[0]
    frac = y0[hit] / (y0[hit] - y1[hit])
    contact = np.full(len(hit), np.nan)
    if touching_before is not None and touching_after is not None:
        c0, c1 = touching_before[hit], touching_after[hit]
        known = np.isfinite(c0) & np.isfinite(c1)
        contact[known] = ((c0[known] > 0) | (c1[known] > 0)).astype(float)
    rows = np.column_stack([
        t0 + frac * (t1 - t0),
        ids[hit].astype(float),
        before[hit, 0] + frac * (after[hit, 0] - before[hit, 0]),
        before[hit, 2] + frac * (after[hit, 2] - before[hit, 2]),
        contact,
    ])
    return rows[np.argsort(rows[:, 0], kind="stable")]


def read_loop_crossings(path: Path) -> pd.DataFrame:
    """The loop's crossing table (``time, id, x, z, in_contact``), sorted by time.

    A table of a drumflow before the contact column reads with ``in_contact`` NaN (unknown).
    """
    table = pd.read_csv(path, dtype={"time": np.float64, "x": np.float64, "z": np.float64,
                                     "in_contact": np.float64})
    missing = [c for c in ("time", "id", "x", "z") if c not in table.columns]
    if missing:
        raise ValueError(f"{path}: not a crossing table (columns {', '.join(missing)} missing)")
    if "in_contact" not in table.columns:
        table["in_contact"] = np.nan
    table["id"] = table["id"].astype(np.int64)
    table = table[["time", "id", "x", "z", "in_contact"]]
    return table.iloc[np.argsort(table["time"].to_numpy(), kind="stable")].reset_index(drop=True)


def atom_ids(lmp: Liggghts) -> NDArray[np.int64]:
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
        self.previous: tuple[float, NDArray[np.float64], NDArray[np.float64]] | None = None
        self.total = 0
        self.no_contacts = False
        self._out: TextIO | None = None
        if write and rank == 0:
            path = work / CROSSINGS_RECORD
            kept = []
            if path.exists() and start_time > 0:
                lines = path.read_text().splitlines()
                # An earlier attempt of an older drumflow wrote no contact column: unknown there.
                pad = "," if lines and lines[0] != _HEADER else ""
                kept = [ln + pad for ln in lines[1:] if ln and float(ln.split(",", 1)[0]) < start_time]
            path.parent.mkdir(parents=True, exist_ok=True)
            out = path.open("w")
            out.write(_HEADER + "\n" + "".join(k + "\n" for k in kept))
            out.flush()
            self._out = out

    def update(self, lmp: Liggghts, time_s: float) -> int | None:
        """Take the particles at ``time_s``; return the crossings since the last update (rank 0;
        None on the other ranks and at the first update of an attempt). Every rank must call
        it at every update."""
        ids = atom_ids(lmp)
        x = lmp.atom_array("x")
        # One reduction: every rank adds its particles' positions, a presence flag and the
        # contact count (-1: the deck has no contact compute) into id-indexed arrays
        # (particles migrate between ranks; ids do not change).
        local = np.zeros((self.n, 5))
        local[ids - 1, :3] = x
        local[ids - 1, 3] = 1.0
        local[ids - 1, 4] = self._touching(lmp)
        total = allreduce_sum(local.ravel()).reshape(self.n, 5)
        if self.rank != 0:
            return None
        present = total[:, 3] > 0.5
        positions = np.where(present[:, None], total[:, :3], np.nan)
        touching = np.where(present & (total[:, 4] >= 0), total[:, 4], np.nan)
        found = None
        if self.previous is not None:
            t0, before, touching_before = self.previous
            rows = downward_crossings(t0, time_s, self.ids, before, positions, touching_before, touching)
            found = len(rows)
            if self._out is not None and found:
                self._out.write("".join(
                    f"{t:.10g},{int(i)},{px:.8g},{pz:.8g},{'' if c != c else int(c)}\n"
                    for t, i, px, pz, c in rows))
                self._out.flush()
        self.previous = (time_s, positions, touching)
        self.total += found or 0
        return found

    def _touching(self, lmp: Liggghts) -> NDArray[np.float64] | float:
        """This rank's particles' contacts (particles, plus one for a wall), or -1 when the deck
        has neither the contact compute nor the wall force (an older deck)."""
        if self.no_contacts:
            return -1.0
        try:
            touching = lmp.compute_atom_vector(CONTACT_COMPUTE).copy()
        except KeyError:
            touching = None
        try:
            walls = np.linalg.norm(lmp.fix_array(WALL_FORCE, 3), axis=1) > 0.0
        except KeyError:
            walls = None
        if touching is None:
            # Without the particle count a free particle is not known to be free.
            self.no_contacts = True
            return -1.0
        return touching + walls if walls is not None else touching

    def close(self) -> None:
        if self._out is not None:
            self._out.close()
            self._out = None
