"""An open scene's outlet in the coupling loop: particles below a level are recorded and removed.

The drum is a closed system: its particles stay, and the DEM stage checks their count. A scene
that is fed and emptied (the particle curtain of :mod:`drumflow.validate.particle_curtain`:
LIGGGHTS' ``insert/rate/region`` feeds it) needs the other end: at every air update the loop
takes every particle below the outlet level (spec key ``outlet``: ``{"region", "level"}``, the
region below ``y = level``: gravity is along -y in the loop's frame, the air along -z), adds its
mass, enthalpy (``m T``), vertical momentum and position along the air to the outlet's log, and
deletes it (``delete_atoms region``, ids not compressed, so the largest id is the number ever
fed). The same row holds the particles still in flight, so that nothing is lost unseen: fed =
out + in flight, by count, is checked from the log (:func:`read_outlet_log`), and LIGGGHTS' own
``thermo_modify lost error`` stops a run that loses a particle anywhere else.

A particle falls below the level between two updates and is taken at the next: its temperature
then holds every interval's heat it received (the loop applies an interval's heat at the
interval's start), so the particles' enthalpy gain is exactly what the log's out and in-flight
sums give.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, TextIO

import numpy as np
import pandas as pd

from drumflow.coupling.crossings import atom_ids
from drumflow.coupling.mpi import allreduce_sum

if TYPE_CHECKING:
    from drumflow.coupling.library import Liggghts

__all__ = ["OUTLET_LOG_COLUMNS", "OUTLET_LOG_PATTERN", "OutletLoop", "read_outlet_log"]

#: Rank 0's outlet log, relative to the DEM working directory.
OUTLET_LOG_PATTERN = "coupling/outlet.{start}.csv"
OUTLET_LOG_COLUMNS = ("time_s", "fed", "in_flight", "in_flight_kg", "in_flight_kgC",
                      "out", "out_kg", "out_kgC", "out_kg_vy", "out_kg_z")


class OutletLoop:
    """The outlet of an open scene, one per MPI rank (rank 0 writes the log).

    Parameters
    ----------
    spec
        ``{"region": the deck's region below the level, "level": y of the level, m}``.
    rank, size
        This process's MPI rank, and the number of ranks.
    start
        The step the loop starts at (names the log).
    """

    def __init__(self, spec: dict[str, object], rank: int, size: int, start: int) -> None:
        self.region = str(spec["region"])
        self.level = float(spec["level"])  # type: ignore[arg-type]
        self.rank, self.size = rank, size
        self._log: TextIO | None = None
        if rank == 0:
            path = Path(OUTLET_LOG_PATTERN.format(start=start))
            path.parent.mkdir(parents=True, exist_ok=True)
            self._log = path.open("w")
            self._log.write(",".join(OUTLET_LOG_COLUMNS) + "\n")
            self._log.flush()

    def take(self, lmp: Liggghts, time_s: float) -> bool:
        """Record and delete the particles below the level; True when any were deleted (the
        next LIGGGHTS run then needs ``pre yes``). Every rank must call it at every update."""
        x = lmp.atom_array("x")
        v = lmp.atom_array("v")
        mass = lmp.atom_vector("rmass")
        temperature = lmp.fix_vector("Temp")
        ids = atom_ids(lmp)
        below = x[:, 1] < self.level
        above = ~below
        local = np.array([
            float(ids.max()) if len(ids) else 0.0,
            float(above.sum()), float(mass[above].sum()), float(np.dot(mass[above], temperature[above])),
            float(below.sum()), float(mass[below].sum()), float(np.dot(mass[below], temperature[below])),
            float(np.dot(mass[below], v[below, 1])), float(np.dot(mass[below], x[below, 2])),
        ])
        # One reduction: the sums, and each rank's largest id in its own slot (the largest id is
        # a maximum, not a sum).
        slots = np.zeros(self.size)
        slots[self.rank] = local[0]
        reduced = allreduce_sum(np.concatenate([local[1:], slots]))
        total, fed = reduced[:8], float(reduced[8:].max())
        if self._log is not None:
            row = (time_s, fed, *total)
            self._log.write(",".join(f"{c:.15g}" for c in row) + "\n")
            self._log.flush()
        if total[3] > 0.5:
            lmp.command(f"delete_atoms region {self.region} compress no")
            return True
        return False

    def close(self) -> None:
        if self._log is not None:
            self._log.close()
            self._log = None


def read_outlet_log(path: Path) -> pd.DataFrame:
    """An outlet log (:data:`OUTLET_LOG_COLUMNS`), by time.

    Raises
    ------
    ValueError
        The file lacks a column of the log.
    """
    table = pd.read_csv(path)
    missing = [c for c in OUTLET_LOG_COLUMNS if c not in table.columns]
    if missing:
        raise ValueError(f"{path}: not an outlet log (columns {', '.join(missing)} missing)")
    return table.sort_values("time_s", kind="stable").reset_index(drop=True)
