"""The coupling spec: how the air acts on the particles during the DEM run (one-way).

This module is the one owner of the coupling between the air and the DEM stages. The air
stage returns only its field (:class:`~drumflow.air.source.FieldSource`); the pipeline builds the spec with
:func:`build_coupling` (which also chooses the update interval); the DEM stage receives it and
writes the coupling loop's input file with :meth:`CouplingSpec.write_driver_file`, whose keys
:mod:`drumflow.coupling.driver` reads. Neither stage imports the other.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

from drumflow.air.source import FieldSource, mean_axial_velocity
from drumflow.coupling.interior import InteriorSpec
from drumflow.geometry.fluid import fluid_mesh_size
from drumflow.physics.air import ideal_gas_density
from drumflow.physics.particle_air import AirState, auto_coupling_interval, ranz_marshall_h
from drumflow.physics.particle_interior import shells_for_biot

if TYPE_CHECKING:
    from drumflow.case import Case
    from drumflow.runner import LaunchProfile

__all__ = ["COUPLING_FILE", "STOPPED_RECORD", "STOP_REQUEST", "CouplingSpec", "FieldSource",
           "build_coupling", "driver_command", "interior_spec", "largest_biot",
           "loop_heat_options"]

#: The coupling loop's input file, in the DEM working directory.
COUPLING_FILE = "coupling.json"
#: The file, in the DEM working directory, that asks a running loop to stop at its next air
#: update after writing a restart there (spec key ``checkpoint``): the runner writes it when
#: ``drumflow run`` is interrupted, and ``drumflow stop RUN_DIR`` writes it from outside, so that
#: a stop loses at most one update interval instead of everything since the last periodic
#: restart.
STOP_REQUEST = "stop.request"
#: What the loop leaves in its place once it has written that restart: ``{"step", "time_s"}``.
#: Its presence tells the DEM stage that the loop ended on request, not at the end of the run.
STOPPED_RECORD = "stopped.json"
#: The LIGGGHTS library the loop loaded (``/proc/self/maps`` of rank 0), in the DEM working
#: directory: which build ran.
LIBRARY_RECORD = "liggghts_library.txt"
#: Where each rank of the loop writes its log, relative to the DEM working directory.
COUPLING_LOG_PATTERN = "coupling/rank{rank}.{start}.csv"
#: The deck's thermo column ``v_overlap`` (drumflow.dem.thermo) on the rows the loop leaves the
#: contact gather out of (spec key ``overlap_every``): below any overlap.
OVERLAP_NOT_EVALUATED = -1.0
#: The loop's two formulas for that column.
OVERLAP_ON = "variable overlap equal c_overlap_max"
OVERLAP_OFF = f"variable overlap equal {OVERLAP_NOT_EVALUATED:g}"
#: Standard gravity, m/s^2 (the slip bound of the 'auto' interval).
GRAVITY = 9.81


@dataclass(frozen=True)
class CouplingSpec:
    """How the air acts on the particles during the DEM run (one-way).

    Attributes
    ----------
    field
        The driver's field spec (:attr:`FieldSource.field`).
    field_key
        Identifies the field (its hash), for the stage key.
    interval
        DEM steps between air updates.
    temperature_C, pressure_kPa
        The air's state (one-way: the air keeps its inlet temperature).
    omega
        Rotation rate of the frame the field was solved in (0 for a uniform field), rad/s.
    coarse_grain
        ``particles.coarse_grain`` k: each DEM sphere is a parcel of k**3 particles of 1/k its
        diameter, and receives k**3 times the drag and heat of one of them (1: no parcels).
    heat_capacity
        Set (J/(kg K)) when the deck has no heat fix (``run.conduction = false``): the loop
        then advances each particle's temperature by its heat over the interval itself. None:
        LIGGGHTS' conduction fix integrates the heat the loop writes into ``heatSource``.
    interior
        With ``particles.interior = "shells"``: the granules' shells (the deck holds their
        temperatures, the loop advances them); None: lumped particles.
    warming
        With ``air.warming``: the inlet air's density and heat capacity for the air's
        temperature (:mod:`drumflow.air.heat`); None: one-way air at its inlet temperature.
    """

    field: dict[str, Any]
    field_key: str
    interval: int
    temperature_C: float
    pressure_kPa: float
    omega: float
    coarse_grain: float = 1.0
    heat_capacity: float | None = None
    interior: InteriorSpec | None = None
    warming: dict[str, float] | None = None

    @property
    def key(self) -> str:
        """What the DEM stage's result depends on from the coupling."""
        parcels = f":parcels={self.coarse_grain:.12g}" if self.coarse_grain != 1.0 else ""
        # A run whose temperatures the loop integrates has another deck and restart content.
        loop_heat = ":heat=loop" if self.heat_capacity is not None else ""
        shells = f":shells={self.interior.shells}" if self.interior is not None else ""
        warming = ":warming" if self.warming is not None else ""
        return f":air={self.field_key}:every={self.interval}{parcels}{loop_heat}{shells}{warming}"

    def driver_file(self, deck: str, log: str, total_steps: int, time_step: float,
                    tail: list[str], thermo_every: int = 0) -> dict[str, Any]:
        """The coupling loop's input (:func:`drumflow.coupling.driver.run` reads these keys).

        Parameters
        ----------
        deck, log
            The LIGGGHTS deck and LIGGGHTS' own log, relative to the DEM working directory.
        total_steps
            The step the run ends at.
        time_step
            DEM time step, s.
        tail
            LIGGGHTS commands run after the loop (final restart, end of dumps).
        thermo_every
            The deck's thermo step; needed when the loop integrates the temperatures
            (:attr:`heat_capacity` set, see :func:`loop_heat_options`).
        """
        loop_heat = ({} if self.heat_capacity is None
                     else loop_heat_options(self.heat_capacity, thermo_every))
        return {
            "deck": deck,
            "log": log,
            "total_steps": total_steps,
            "interval": self.interval,
            "time_step": time_step,
            "omega": self.omega,
            "air_temperature_C": self.temperature_C,
            "air_pressure_kPa": self.pressure_kPa,
            "field": self.field,
            "coupling_log": COUPLING_LOG_PATTERN,
            "tail": tail,
            "coarse_grain": self.coarse_grain,
            "heat_capacity": None,  # conduction on: LIGGGHTS integrates the temperatures
            **loop_heat,
            "interior": None if self.interior is None else self.interior.to_json(),
            "warming": self.warming,
        }

    def write_driver_file(self, work: Path, deck: str, log: str, total_steps: int,
                          time_step: float, tail: list[str], thermo_every: int = 0) -> Path:
        """Write :meth:`driver_file` to ``work / COUPLING_FILE`` and return its path."""
        path = work / COUPLING_FILE
        path.write_text(json.dumps(self.driver_file(deck, log, total_steps, time_step, tail,
                                                    thermo_every), indent=2))
        return path


def loop_heat_options(heat_capacity: float, thermo_every: int) -> dict[str, Any]:
    """The coupling loop's keys when it integrates the particles' temperatures itself.

    A deck without LIGGGHTS' heat fix (``run.conduction = false``) has only a per-atom
    ``Temp``: the loop adds each particle's heat over an update, ``heat * n * dt / (m * cp)``.
    It must then end an update on every thermo step (``align_every``), so that each
    temperature LIGGGHTS prints or dumps has all its heat and no more. The one place this rule
    lives: the DEM stage and ``drumflow bench --from`` both take it from here.

    Raises
    ------
    ValueError
        ``heat_capacity`` not positive, or ``thermo_every`` not a positive number of steps.
    """
    if not (math.isfinite(heat_capacity) and heat_capacity > 0.0):
        raise ValueError(f"heat_capacity = {heat_capacity!r}: a positive J/(kg K) is needed")
    if thermo_every < 1:
        raise ValueError(f"thermo_every = {thermo_every!r}: the deck's thermo step, at least 1, "
                         "is needed when the coupling loop integrates the temperatures")
    return {"heat_capacity": float(heat_capacity), "align_every": int(thermo_every)}


def coupling_interval(case: Case, time_step: float, dump_every: int) -> int:
    """DEM steps between air updates: the case's, or 'auto' (see
    :func:`~drumflow.physics.particle_air.auto_coupling_interval`), at most one output interval."""
    if case.air.coupling_interval != "auto":
        return int(case.air.coupling_interval)
    state = AirState.at(case.air.inlet_temperature_C, case.air.pressure_kPa)
    # Largest slip: the air speed plus a particle falling across the whole drum.
    max_slip = mean_axial_velocity(case) + math.sqrt(2 * GRAVITY * case.drum.diameter)
    return auto_coupling_interval(
        time_step, case.particles.diameter, case.particles.density,
        case.particles.heat_capacity, state, max_slip, cap=dump_every,
    )


def build_coupling(case: Case, source: FieldSource, time_step: float, dump_every: int) -> CouplingSpec:
    """The spec the DEM stage runs with, from the air stage's field and the DEM step plan.

    ``case`` is the user's case (real particles, not :meth:`~drumflow.case.Case.dem_case`): the
    'auto' interval follows the real particles' response to the air, which parcels keep.
    """
    return CouplingSpec(
        field=source.field,
        field_key=source.key,
        interval=coupling_interval(case, time_step, dump_every),
        temperature_C=case.air.inlet_temperature_C,
        pressure_kPa=case.air.pressure_kPa,
        omega=source.omega,
        coarse_grain=case.particles.coarse_grain,
        # The deck leaves out the conduction fix, which also integrates the temperatures, when
        # conduction is off (templates/drum.in.j2); the loop integrates them instead.
        heat_capacity=None if case.run.conduction else case.particles.heat_capacity,
        interior=interior_spec(case),
        warming=({"density": ideal_gas_density(case.air.inlet_temperature_C, case.air.pressure_kPa),
                  "heat_capacity": case.air.heat_capacity,
                  # The air's temperature on the CFD's own cell size (drumflow.air.heat).
                  "spacing": fluid_mesh_size(case)} if case.air.warming else None),
    )


def interior_spec(case: Case) -> InteriorSpec | None:
    """The shells of ``particles.interior = "shells"`` (None for lumped particles).

    Without ``particles.interior_shells`` the count comes from the largest Biot number the case
    can reach: Ranz-Marshall h at the same slip bound as the 'auto' interval (the air speed plus
    a granule falling across the whole drum), on the real granule (parcels keep its profile).
    """
    p = case.particles
    if p.interior != "shells":
        return None
    shells = p.interior_shells if p.interior_shells is not None else shells_for_biot(largest_biot(case))
    return InteriorSpec(shells, p.conductivity, p.density, p.heat_capacity)


def largest_biot(case: Case) -> float:
    """The largest Biot number h R / k of the case's granules: Ranz-Marshall h at the slip bound
    of the 'auto' interval (the air speed plus a fall across the whole drum)."""
    p = case.particles
    state = AirState.at(case.air.inlet_temperature_C, case.air.pressure_kPa)
    max_slip = mean_axial_velocity(case) + math.sqrt(2 * GRAVITY * case.drum.diameter)
    h = float(ranz_marshall_h(max_slip, p.diameter, state))
    return h * 0.5 * p.diameter / p.conductivity


def driver_command(profile: LaunchProfile, processes: int, spec_name: str = COUPLING_FILE) -> list[str]:
    """The command that runs the coupling loop under the MPI launcher."""
    return profile.python_module_command("drumflow.coupling.driver", spec_name, processes=processes)
