"""Heat inside the granule in the coupling loop: each particle's radial temperature profile.

With ``particles.interior = "shells"`` every DEM sphere carries the shell temperatures of its
granule (a parcel: of one of its k**3 granules) in the per-atom vector ``shellT`` of the deck,
which LIGGGHTS migrates with the atom between MPI ranks and writes into its restarts. At each
air update the loop

1. gives the outer shell whatever LIGGGHTS added to the particle's temperature since the last
   update beyond the air's heat (contact conduction enters through the surface),
2. advances every profile over the coming interval with the Ranz-Marshall h of the particle's
   slip and the air's temperature (:class:`~drumflow.physics.particle_interior.ShellBatch`,
   Crank-Nicolson, the film acting on the surface temperature), and
3. hands LIGGGHTS the heat that advance gave the air as a constant ``heatSource`` over the
   interval, so LIGGGHTS' ``Temp`` (the particle's enthalpy, its mean temperature) arrives
   where the profile's mean does: the energy bookkeeping of the lumped loop is unchanged.

Contact conduction in LIGGGHTS still uses ``Temp`` (one temperature per particle): the mean, not
the surface. The shells need no stability limit of their own (Crank-Nicolson); they sub-step
when an interval is longer than a quarter of a shell's diffusion time, to keep its accuracy.

A new particle (a fresh deck, an inserted one) has the sentinel :data:`UNSET` in ``shellT`` and
starts uniform at its ``Temp``.
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from drumflow.physics.particle_interior import ShellBatch

#: The deck's per-atom vector of shell temperatures.
SHELL_FIX = "shellT"
#: Its default value: below any temperature, so the loop can tell a profile it never set.
UNSET = -1.0e9
#: The interior log's columns (one file per rank and start, beside the coupling log).
INTERIOR_COLUMNS = ("step", "time_s", "particles", "mean_surface_C", "mean_centre_C",
                    "mean_C", "max_centre_minus_surface_K", "max_biot", "interior_wall_s")
INTERIOR_LOG_PATTERN = "coupling/interior_rank{rank}.{start}.csv"


def shell_fix_command(shells: int) -> str:
    """The deck's ``fix property/atom`` holding ``shells`` temperatures per particle."""
    defaults = " ".join([f"{UNSET:g}"] * shells)
    return f"fix {SHELL_FIX} all property/atom {SHELL_FIX} vector yes no no {defaults}"


@dataclass(frozen=True)
class InteriorSpec:
    """The coupling spec's ``interior`` entry.

    Attributes
    ----------
    shells
        Shells per granule.
    conductivity
        The granules' thermal conductivity, W/(m K).
    density, heat_capacity
        kg/m^3 and J/(kg K): the diffusivity k / (rho cp), and the capacity of a granule from
        its mass.
    """

    shells: int
    conductivity: float
    density: float
    heat_capacity: float

    def to_json(self) -> dict[str, Any]:
        return {"shells": self.shells, "conductivity": self.conductivity, "density": self.density,
                "heat_capacity": self.heat_capacity}

    @classmethod
    def from_json(cls, data: dict[str, Any]) -> InteriorSpec:
        return cls(int(data["shells"]), float(data["conductivity"]), float(data["density"]),
                   float(data["heat_capacity"]))


class InteriorLoop:
    """The coupling loop's interior: one per rank (its particles only)."""

    def __init__(self, spec: InteriorSpec, log_path: Path) -> None:
        self.spec = spec
        self._wall = 0.0
        self.batch = ShellBatch(spec.shells, spec.conductivity,
                                spec.conductivity / (spec.density * spec.heat_capacity))
        log_path.parent.mkdir(parents=True, exist_ok=True)
        self._log = log_path.open("w")
        self._log.write(",".join(INTERIOR_COLUMNS) + "\n")

    def advance(self, shells: NDArray[np.float64], temperature: NDArray[np.float64],
                h: NDArray[np.float64], air_temperature: NDArray[np.float64] | float,
                diameter: NDArray[np.float64], mass: NDArray[np.float64], duration: float
                ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """The profiles at the end of the coming interval and the heat to each granule, W
        (negative when it cools), constant over the interval.

        Nothing is written: the loop commits the profiles (:meth:`commit`) only once it is
        sure to apply the heat, so a restart written instead (a stop request) holds profiles
        and temperatures of the same instant.

        Parameters
        ----------
        shells
            (n, shells) view of ``shellT`` (read only here).
        temperature
            Each particle's ``Temp`` now: its mean temperature as LIGGGHTS integrated it.
        h
            Film coefficient of each granule, W/(m^2 K).
        diameter, mass
            Of one granule (a parcel's sphere diameter and mass divided by k and k**3).
        duration
            The interval, s.
        """
        if len(temperature) == 0:
            return np.zeros((0, self.spec.shells)), np.zeros(0)
        started = time.perf_counter()
        start = np.array(shells, dtype=float)
        unset = start[:, 0] <= 0.5 * UNSET
        start[unset] = temperature[unset, None]
        # What LIGGGHTS added beyond the air's heat since the last update: contact conduction.
        self.batch.add_surface_heat(start, temperature - self.batch.mean(start))
        capacity = mass * self.spec.heat_capacity
        new, given = self.batch.advance(start, h, air_temperature, 0.5 * diameter, capacity, duration)
        # What the interior costs this rank per update (the coupling log's python_wall_s holds it
        # with the rest of the loop's Python): the measure of this level's price.
        self._wall = time.perf_counter() - started
        return new, -given / duration

    def commit(self, shells: NDArray[np.float64], new: NDArray[np.float64], h: NDArray[np.float64],
               air_temperature: NDArray[np.float64] | float, diameter: NDArray[np.float64],
               step: int, time_s: float) -> None:
        """Write the advanced profiles into LIGGGHTS' memory and log this update."""
        if len(new) == 0:
            return
        started = time.perf_counter()
        shells[:] = new
        self._wall += time.perf_counter() - started
        self._record(new, h, air_temperature, 0.5 * diameter, step, time_s)

    def _record(self, shells: NDArray[np.float64], h: NDArray[np.float64],
                air_temperature: NDArray[np.float64] | float, radius: NDArray[np.float64],
                step: int, time_s: float) -> None:
        surface = self.batch.surface_temperature(shells, h, radius, air_temperature)
        centre = shells[:, 0]
        biot = h * radius / self.spec.conductivity
        row = (step, time_s, len(shells), float(surface.mean()), float(centre.mean()),
               float(self.batch.mean(shells).mean()), float(np.max(centre - surface)),
               float(biot.max()), self._wall)
        self._log.write(",".join(f"{v:.12g}" for v in row) + "\n")
        self._log.flush()

    def close(self) -> None:
        self._log.close()


def granule(sphere_diameter: NDArray[np.float64], sphere_mass: NDArray[np.float64],
            coarse_grain: float) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Diameter and mass of one granule of each DEM sphere (a parcel holds k**3 of 1/k size)."""
    if coarse_grain == 1.0:
        return sphere_diameter, sphere_mass
    return sphere_diameter / coarse_grain, sphere_mass / coarse_grain**3

