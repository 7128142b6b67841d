"""The coupled DEM loop: LIGGGHTS as a library, air acting on particles every N steps.

Run as a child process through :class:`drumflow.runner.Runner`, under ``mpirun``::

    mpirun -np P python -m drumflow.coupling.driver spec.json

Every N DEM steps each MPI rank reads its own particles' positions, velocities and
temperatures (numpy views of LIGGGHTS' memory), samples the air there, and writes the
Schiller-Naumann drag into three per-atom properties that ``fix addforce`` applies at every
step, and the Ranz-Marshall heat into ``heatSource``, which ``heat/gran/conduction`` adds to
each particle's energy balance at every step. Then LIGGGHTS runs N steps. Without conduction
(``run.conduction = false``) the deck has no heat fix: the loop adds each particle's heat over
the N steps to its temperature itself, the sum LIGGGHTS' transport equation would take.

MPI: ``lammps_open_no_mpi`` starts one LIGGGHTS instance on MPI_COMM_WORLD, so P ranks of this
script share one domain-decomposed simulation; drag and convection are per particle, so each
rank only needs its local particles. Each rank writes its own coupling log; post-processing
adds them up.

Interrupts: with the spec key ``checkpoint`` (a restart file pattern), the loop looks for
:data:`~drumflow.coupling.spec.STOP_REQUEST` at every air update; once it is there, every rank
stops at the same update, writes a restart at that step and leaves the loop. The runner writes
that file when ``drumflow run`` is interrupted (Ctrl-C, ``kill`` of its pid) and ``drumflow
stop`` from outside (a SLURM sweep on its time-limit warning), so the run resumes from where it
was stopped, not from its last periodic restart (half a simulated second, about 40 minutes of
paper model one). A signal that reaches mpirun itself ends the ranks at once: mpirun runs in its
own session, so only a signal to the whole job does that.

One-way coupling as in the paper: the air keeps its field and its inlet temperature.

Profile: every coupling-log row ends with the wall seconds this rank spent in Python (air
sampling, drag, heat, crossings, stop rule) and in LIGGGHTS' ``run`` for that interval. About
every :data:`PROFILE_EVERY_STEPS` DEM steps, and at the last interval, the run ends with ``post
yes``: LIGGGHTS then prints its timing breakdown (pair, neighbour, communication, output, fixes
one by one under ``modify_timing on``) into its log, which :mod:`drumflow.bench.profile` reads.
"""

from __future__ import annotations

import ctypes as C
import json
import os
import sys
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Protocol

import numpy as np
from numpy.typing import NDArray

from drumflow.air.bed_phases import PhaseLockedAir
from drumflow.coupling.crossings import CrossingTracker
from drumflow.coupling.interior import (
    INTERIOR_LOG_PATTERN,
    SHELL_FIX,
    UNSET,
    InteriorLoop,
    InteriorSpec,
    granule,
)
from drumflow.coupling.library import Liggghts, loaded_library_path
from drumflow.coupling.mpi import allreduce_sum
from drumflow.coupling.outlet import OutletLoop
from drumflow.coupling.spec import (
    LIBRARY_RECORD,
    OVERLAP_OFF,
    OVERLAP_ON,
    STOP_REQUEST,
    STOPPED_RECORD,
)
from drumflow.coupling.stop import StopMonitor
from drumflow.physics.drum_frame import drum_angle, rotate_to_drum_frame, rotate_to_lab_frame
from drumflow.physics.particle_air import AirState, convective_heat, drag_force, ranz_marshall_h

#: Per-atom properties the deck defines for the drag (``fix addforce`` reads them).
DRAG_FIXES = ("air_fx", "air_fy", "air_fz")
#: The coupling log's columns. The wall times come last, so readers by name of older logs
#: (without them) and of new ones read the same physics columns.
LOG_COLUMNS = ("step", "time_s", "steps", "heat_to_particles_W", "drag_x_N", "drag_y_N", "drag_z_N",
               "particles", "mean_slip_m_s", "python_wall_s", "liggghts_wall_s")
#: DEM steps between LIGGGHTS timing breakdowns (``run ... post yes``), roughly; the spec's
#: ``profile_every_steps`` overrides it.
PROFILE_EVERY_STEPS = 200


class VelocityField(Protocol):
    def sample(self, points: NDArray[np.float64]) -> NDArray[np.float64]: ...


@dataclass(frozen=True)
class UniformAir:
    """Plug flow: the same velocity everywhere (also still air, with zero velocity)."""

    velocity: tuple[float, float, float]

    def sample(self, points: NDArray[np.float64]) -> NDArray[np.float64]:
        return np.broadcast_to(np.asarray(self.velocity, float), (len(points), 3))


def air_velocity_at(
    field: VelocityField | PhaseLockedAir,
    x: NDArray[np.float64],
    time_s: float,
    omega: float,
) -> NDArray[np.float64]:
    """Air velocity at lab-frame positions at time t.

    A field solved in the drum's rotating frame (MRF) turns with the drum: a lab position maps
    to the drum frame by a rotation of -omega t, and the sampled (absolute) velocity back by
    +omega t. For a uniform axial field the rotation changes nothing. The air around the bed
    (:class:`~drumflow.air.bed_phases.PhaseLockedAir`) maps by its phase's angle instead.
    """
    if isinstance(field, PhaseLockedAir):
        return field.sample_at(x, time_s)
    if omega == 0.0 or isinstance(field, UniformAir):
        return field.sample(x)
    angle = drum_angle(omega, time_s)
    return rotate_to_lab_frame(field.sample(rotate_to_drum_frame(x, angle)), angle)


def load_field(spec: dict[str, Any]) -> VelocityField | PhaseLockedAir:
    """The air field named by a spec: ``uniform`` (velocity), ``grid`` (an .npz cache) or
    ``phases`` (the air around the bed, one .npz per bed state)."""
    kind = spec["kind"]
    if kind == "phases":
        return PhaseLockedAir.from_spec(spec)
    if kind == "uniform":
        return UniformAir(tuple(spec["velocity"]))
    if kind == "grid":
        from drumflow.air.field import AirField

        return AirField.from_npz(Path(spec["path"]))
    raise ValueError(f"air field kind {kind!r}: expected 'uniform', 'grid' or 'phases'")


def _rank() -> int:
    for var in ("OMPI_COMM_WORLD_RANK", "PMI_RANK", "PMIX_RANK"):
        if var in os.environ:
            return int(os.environ[var])
    return 0


def _size() -> int:
    for var in ("OMPI_COMM_WORLD_SIZE", "PMI_SIZE"):
        if var in os.environ:
            return int(os.environ[var])
    return 1


def _finalize_mpi() -> None:
    # lammps_open_no_mpi called MPI_Init; a rank that exits without MPI_Finalize makes mpirun
    # report a failure. libmpi is loaded globally with libliggghts.
    try:
        C.CDLL(None).MPI_Finalize()
    except (AttributeError, OSError):
        pass


def stop_requested(rank: int, request: Path) -> bool:
    """Whether the stop request exists, the same answer on every rank: rank 0 looks and the
    others take its answer, so no rank runs on alone (which would hang the next collective
    call) when the file appears between two ranks' looks."""
    seen = 1.0 if rank == 0 and request.exists() else 0.0
    return bool(allreduce_sum(np.array([seen]))[0] > 0.5)


def overlap_wanted(step: int, n: int, every: int, total: int) -> bool:
    """Whether the run of ``n`` steps from ``step`` evaluates the overlap column: it reaches a
    multiple of ``every`` (its last thermo row is then one), or it is the run's last."""
    return (step + n) // every > step // every or step + n >= total


def profile_stride(interval: int, every_steps: int = PROFILE_EVERY_STEPS) -> int:
    """Coupling intervals between two timing breakdowns: the whole number of intervals closest to
    ``every_steps`` DEM steps, at least one."""
    return max(1, round(every_steps / max(interval, 1)))


def air_load(air_velocity: NDArray[np.float64], velocity: NDArray[np.float64],
             temperature: NDArray[np.float64], sphere_diameter: NDArray[np.float64],
             coarse_grain: float, air: AirState
             ) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """Drag (N, (n, 3)) and heat (W) on each DEM sphere, and the particle diameter behind them.

    Without coarse-graining (``coarse_grain`` 1) a sphere is a particle. With ``k > 1`` each
    sphere is a parcel of ``k**3`` particles of ``1/k`` its diameter: its drag and heat are
    those of one such particle at the parcel's velocity and temperature, ``k**3`` times, so that
    per kilogram (acceleration, heating rate) they are the particles' (``Case.dem_case``).
    """
    d = sphere_diameter / coarse_grain
    force = drag_force(air_velocity, velocity, d, air)
    heat = convective_heat(air_velocity, velocity, temperature, d, air)
    if coarse_grain != 1.0:
        per_parcel = coarse_grain**3
        force *= per_parcel
        heat *= per_parcel
    return force, heat, d


#: Rank 0's log of the air's temperature (air.warming), beside the coupling logs.
AIR_LOG_PATTERN = "coupling/air.{start}.csv"
AIR_LOG_COLUMNS = ("step", "time_s", "steps", "heat_to_air_W", "air_enthalpy_gain_W",
                   "outlet_C", "max_C", "wall_s", "phase", "heat_if_fresh_W")


class _AirWarming:
    """The coupling loop's air that warms (:mod:`drumflow.air.heat`), one per rank: every rank
    holds the same grid and solves the same system from the heat summed over all ranks."""

    def __init__(self, spec: dict[str, Any], field: VelocityField | PhaseLockedAir, rank: int,
                 start: int) -> None:
        from drumflow.air.field import AirField
        from drumflow.air.heat import AirHeat, coarse_field

        # The air around the bed: one air per bed state, each on its own flow; the one of the
        # drum's phase is solved at each update (its last field is the next solve's start).
        self.phases = field if isinstance(field, PhaseLockedAir) else None
        fields = self.phases.fields if self.phases is not None else [field]
        if not all(isinstance(f, AirField) for f in fields):
            raise ValueError("air.warming needs the air field on a grid (spec field kind 'grid')")
        warm = spec["warming"]
        self.heats = [AirHeat(coarse_field(f, float(warm["spacing"])) if warm.get("spacing") else f,
                              float(spec["air_temperature_C"]), float(warm["density"]),
                              float(warm["heat_capacity"]))
                      for f in fields if isinstance(f, AirField)]
        self.phase = 0
        self._fresh = 0.0
        self.heat = self.heats[0]
        self.omega = float(spec["omega"])
        self.rank = rank
        self.cells = np.zeros(0, dtype=np.intp)
        self._wall = 0.0
        self._log = None
        if rank == 0:
            path = Path(AIR_LOG_PATTERN.format(start=start))
            path.parent.mkdir(parents=True, exist_ok=True)
            self._log = path.open("w")
            self._log.write(",".join(AIR_LOG_COLUMNS) + "\n")

    def air_at(self, x: NDArray[np.float64], time_s: float, conductance: NDArray[np.float64],
               temperature: NDArray[np.float64]) -> NDArray[np.float64]:
        """The air temperature each particle sees over the coming interval, C.

        ``conductance`` (W/K) and ``temperature`` (C) are each DEM sphere's film conductance to
        the air and the temperature behind it (the surface node)."""
        started = time.perf_counter()
        if self.phases is not None:
            self.phase, angle = self.phases.phase(time_s)
            self.heat = self.heats[self.phase]
        else:
            angle = drum_angle(self.omega, time_s)
        points = rotate_to_drum_frame(x, angle) if self.omega else x
        self.cells = self.heat.cells_of(points)
        g = allreduce_sum(self.heat.deposit(self.cells, conductance))
        gt = allreduce_sum(self.heat.deposit(self.cells, conductance * temperature))
        # The heat if every particle met air at the inlet temperature through the same film:
        # the contact efficiency's denominator (heat_to_air_W over it).
        self._fresh = float(gt.sum() - g.sum() * self.heat.inlet_temperature_C)
        cell_temperature = self.heat.solve_with_particles(g, gt)
        self._wall = time.perf_counter() - started
        return np.asarray(cell_temperature[self.cells], dtype=float)

    def record(self, heat_to_particles: NDArray[np.float64], step: int, time_s: float, n: int) -> None:
        """Log the interval: the heat the air received from every rank's particles and what the
        air carries out for it (equal by conservation), its outlet and largest temperature."""
        started = time.perf_counter()
        source = allreduce_sum(self.heat.deposit(self.cells, -np.asarray(heat_to_particles)))
        solved = self.heat.solve(source)
        self._wall += time.perf_counter() - started
        if self._log is not None:
            row = (step, time_s, n, float(source.sum()), self.heat.enthalpy_gain(solved),
                   self.heat.outlet_temperature(solved), float(solved.max()), self._wall,
                   self.phase, self._fresh)
            self._log.write(",".join(f"{v:.12g}" for v in row) + "\n")
            self._log.flush()

    def close(self) -> None:
        if self._log is not None:
            self._log.close()


def run(spec_path: Path) -> int:
    """Run the coupled loop described by a JSON spec (written by
    :meth:`drumflow.coupling.spec.CouplingSpec.write_driver_file`)."""
    spec = json.loads(spec_path.read_text())
    work = spec_path.parent
    os.chdir(work)
    rank = _rank()
    air = AirState.at(spec["air_temperature_C"], spec["air_pressure_kPa"])
    field = load_field(spec["field"])
    omega = float(spec["omega"])
    dt = float(spec["time_step"])
    total = int(spec["total_steps"])
    # The simulated time is origin + (step - origin step) * dt. A run that keeps one time step
    # throughout has the origin (0, 0); a run continued from a restart with another time step
    # (the settings study's time-step variants) gives the restart's step and time, so that the
    # air field stands at the drum angle of the restart, not at step * new dt.
    origin_step, origin_time = (int(spec.get("clock_origin", [0, 0.0])[0]),
                                float(spec.get("clock_origin", [0, 0.0])[1]))
    if (origin_step, origin_time) != (0, 0.0) and spec.get("stop"):
        raise ValueError("clock_origin with a stop rule: the stop rule's clock is step * dt")

    def clock(at_step: int) -> float:
        return origin_time + (at_step - origin_step) * dt

    coarse_grain = float(spec.get("coarse_grain", 1.0))
    heat_capacity = spec.get("heat_capacity")
    # Updates end on multiples of this step (0: every `interval` steps from the start).
    align = int(spec.get("align_every", 0))
    # The thermo rows' overlap column gathers every contact; with `overlap_every` it is
    # evaluated only in the runs that reach a multiple of it (and the last), -1 elsewhere.
    overlap_every = int(spec.get("overlap_every", 0))
    overlap_on = True  # the deck's own formula

    interval = int(spec["interval"])
    stride = profile_stride(interval, int(spec.get("profile_every_steps", PROFILE_EVERY_STEPS)))
    lmp = Liggghts(["-log", spec["log"], "-echo", "none"])
    if rank == 0:
        # Which LIGGGHTS build ran (Debian's or one built from source): benchmarks read it.
        (work / LIBRARY_RECORD).write_text(f"{loaded_library_path()}\n")
    lmp.file(Path(spec["deck"]))
    # Time every fix on its own, so the breakdown splits LIGGGHTS' "Modify" share into walls,
    # conduction, air drag and integration (a clock read around each fix call: negligible
    # against a time step of a bed).
    lmp.command("modify_timing on")
    step = int(C.cast(lmp._lib.lammps_extract_global(lmp._handle, b"ntimestep"), C.POINTER(C.c_int64))[0])
    start = step
    log_path = Path(spec["coupling_log"].format(rank=rank, start=start))
    log_path.parent.mkdir(parents=True, exist_ok=True)
    rows: list[tuple[float, ...]] = []
    # run.stop = "converged": leave the loop once h and the falling mass flow are known well
    # enough (drumflow.coupling.stop); absent for a fixed-time run, which is unchanged.
    monitor = StopMonitor(spec["stop"], work, rank, dt, start) if spec.get("stop") else None
    # run.crossings = "loop": find the axis-plane crossings here, with the particles in memory,
    # instead of LIGGGHTS' band dump (drumflow.coupling.crossings); the stop rule counts them.
    record_crossings = spec.get("crossings") == "loop"
    if record_crossings:
        lmp.command("undump cross")
    tracker = (CrossingTracker(int(spec["particles"]), work, rank, record_crossings, clock(start))
               if monitor is not None or record_crossings else None)
    # air.warming: the air's temperature, solved on the field's grid (drumflow.air.heat).
    warming = _AirWarming(spec, field, rank, start) if spec.get("warming") else None
    # particles.interior = "shells": each particle's radial profile (drumflow.coupling.interior).
    interior = (InteriorLoop(InteriorSpec.from_json(spec["interior"]),
                             Path(INTERIOR_LOG_PATTERN.format(rank=rank, start=start)))
                if spec.get("interior") else None)
    # An open scene (spec key ``outlet``): particles below the outlet level are recorded and
    # removed at every update (drumflow.coupling.outlet); a closed drum has none.
    outlet = OutletLoop(spec["outlet"], rank, _size(), start) if spec.get("outlet") else None
    stopped = False
    # A restart pattern lets an interrupt end the loop with a restart at the current step
    # (module docstring); without one (studies, verification scenes) the loop never looks.
    checkpoint = spec.get("checkpoint")
    request = work / STOP_REQUEST
    checkpointed = False
    updates = 0
    with log_path.open("w") as out:
        out.write(",".join(LOG_COLUMNS) + "\n")
        while step < total:
            started = time.perf_counter()
            # Before the arrays are read: a deletion reorders them.
            removed = outlet.take(lmp, clock(step)) if outlet is not None else False
            n = min(interval, total - step)
            if align > 0:
                n = min(n, align - step % align)
            x = lmp.atom_array("x")
            v = lmp.atom_array("v")
            T = lmp.fix_vector("Temp")
            u = air_velocity_at(field, x, clock(step), omega)
            force, heat, d = air_load(u, v, T, 2.0 * lmp.atom_vector("radius"), coarse_grain, air)
            # The film coefficient, where a level needs it apart from the heat (the lumped
            # one-way loop has it inside air_load).
            h = (ranz_marshall_h(np.linalg.norm(u - v, axis=1), d, air)
                 if warming is not None or interior is not None else np.zeros(0))
            air_temperature: NDArray[np.float64] | float = air.temperature_C
            if warming is not None:
                # Each particle sees the air of its cell, solved with this interval's heat
                # implicit in it (drumflow.air.heat), from the particle's surface: the outer
                # shell through its half-shell and the film, or the lumped particle's film.
                if interior is not None:
                    g = interior.batch.surface_conductance(h, 0.5 * d)
                    node = lmp.fix_array(SHELL_FIX, interior.spec.shells)[:, -1].copy()
                    unset = node <= 0.5 * UNSET
                    node[unset] = T[unset]
                else:
                    g, node = h * np.pi * d**2, np.asarray(T, dtype=float)
                air_temperature = warming.air_at(x, clock(step), g * coarse_grain**3, node)
                if interior is None:
                    heat = g * coarse_grain**3 * (air_temperature - T)
            if interior is not None:
                # The heat from each granule's surface, not its mean: the interior's advance.
                mass = granule(d * coarse_grain, lmp.atom_vector("rmass"), coarse_grain)[1]
                profiles, heat = interior.advance(lmp.fix_array(SHELL_FIX, interior.spec.shells),
                                                  T, h, air_temperature, d, mass, n * dt)
                heat = heat * coarse_grain**3
            found = tracker.update(lmp, clock(step)) if tracker is not None else None
            # After the crossings up to this step are recorded (a resume from this step keeps
            # them), before this update's heat is applied or logged (the resumed attempt
            # applies it): the restart and the logs then describe the same instant.
            if checkpoint and stop_requested(rank, request):
                lmp.command(f"write_restart {checkpoint}")
                if rank == 0:
                    (work / STOPPED_RECORD).write_text(json.dumps({"step": step, "time_s": clock(step)}))
                    request.unlink(missing_ok=True)
                checkpointed = True
                break
            # The monitor's surface is the particles' (k**3 spheres of diameter d per parcel).
            if monitor is not None and monitor.observe(step, n, heat, d * coarse_grain**1.5, T,
                                                       lmp.atom_vector("rmass"), found):
                # Before this update's heat is applied or logged: the heat log stays exactly
                # what LIGGGHTS received.
                stopped = True
                break
            for axis, name in enumerate(DRAG_FIXES):
                lmp.fix_vector(name)[:] = force[:, axis]
            if interior is not None:
                interior.commit(lmp.fix_array(SHELL_FIX, interior.spec.shells), profiles, h,
                                air_temperature, d, step, clock(step))
            if warming is not None:
                warming.record(heat, step, clock(step), n)
            if heat_capacity is None:
                lmp.fix_vector("heatSource")[:] = heat
            else:
                # No heat fix: the interval's heat enters now, held constant over the n steps as
                # heatSource would be. Nothing reads a temperature before the next update (no
                # conduction; `align_every` puts every thermo row, dump and restart on an update
                # step), so every temperature seen is the one LIGGGHTS would have integrated.
                T += heat * (n * dt) / (lmp.atom_vector("rmass") * float(heat_capacity))
            slip = float(np.linalg.norm(u - v, axis=1).mean()) if len(v) else 0.0
            row = (step, clock(step), n, float(heat.sum()), *map(float, force.sum(axis=0)), len(v), slip)
            python_wall = time.perf_counter() - started
            # The row without its last column, flushed before the run: an interrupted run is
            # resumed from a restart file, and the heat applied before that restart must survive
            # a SIGTERM (which ends Python without flushing its buffers), or the resumed energy
            # balance misses it. A row cut there lacks only LIGGGHTS' wall time (read as NaN).
            out.write(",".join(f"{c:.12g}" for c in (*row, python_wall)))
            out.flush()
            rows.append(row)
            updates += 1
            # `pre no`: nothing but per-atom values changed since the last run, so LIGGGHTS
            # need not rebuild neighbour lists or re-initialise the fixes (the loop's cost).
            # `post yes` every `stride` updates and at the end: the timing breakdown.
            post = "yes" if updates % stride == 0 or step + n >= total else "no"
            if overlap_every > 0:
                wanted = overlap_wanted(step, n, overlap_every, total)
                if wanted != overlap_on:
                    lmp.command(OVERLAP_ON if wanted else OVERLAP_OFF)
                    overlap_on = wanted
            ran = time.perf_counter()
            # `pre yes` after a deletion: LIGGGHTS must rebuild what refers to the atoms.
            lmp.command(f"run {n} pre {'yes' if removed else 'no'} post {post}")
            out.write(f",{time.perf_counter() - ran:.6g}\n")
            out.flush()
            step += n
    if interior is not None:
        interior.close()
    if warming is not None:
        warming.close()
    if outlet is not None:
        if not checkpointed:
            # The particles that fell below the level in the last interval.
            outlet.take(lmp, clock(step))
        outlet.close()
    if checkpointed:
        # Not finished: no closing commands (final snapshot, end restart), no stop verdict.
        if tracker is not None:
            tracker.close()
        lmp.close()
        _finalize_mpi()
        return 0
    if tracker is not None:
        if not stopped:
            # The crossings of the last interval, up to the final step.
            tracker.update(lmp, clock(step))
        tracker.close()
    if monitor is not None:
        monitor.finish(step, stopped)
    for command in spec.get("tail", []):
        lmp.command(command)
    lmp.close()
    _finalize_mpi()
    return 0


def main() -> None:
    if len(sys.argv) != 2:
        sys.stderr.write("usage: python -m drumflow.coupling.driver SPEC.json\n")
        raise SystemExit(2)
    raise SystemExit(run(Path(sys.argv[1])))


if __name__ == "__main__":
    main()
