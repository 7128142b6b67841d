"""Start states: a bed's particles in one small file that outlives the machine it ran on.

A LIGGGHTS restart is 170 MB and more and is never committed, so a long run (hours to reach the
cascading bed of paper model one) was lost twice with its machine. A start state is the part
of a full snapshot that a new run needs to carry on: per particle its id, position, velocity,
spin (angular velocity), radius and temperature; and the simulated time, the drum angle
(omega t) at that time, the hash of the case it came from, the hash of its scene (drum, lifters
and particles sections: what must match for the particles to fit the walls) and the drumflow
version. It is one compressed ``.npz`` (:func:`write_state`, :func:`read_state`), made from a
run's snapshot by :func:`state_from_run` (``drumflow export RUN_DIR --state``); a case starts
from one with ``run.start_state`` (the DEM stage, :func:`data_file_text` and
:func:`temperature_file_text`).

Precision, field by field (the snapshot text is the original: positions with 8 significant
digits, velocities and spins with 6, temperatures with 10):

* positions float64: the snapshot's digits exactly, so no pair of particles overlaps more than
  in the snapshot. float32 would round them by up to 6e-8 m at 1 m (half the text's own step),
  which moves every contact's overlap (Hertz force ~ overlap^1.5); measured on the smoke
  case's bed in ``results/bench/start_state``.
* velocities and spins float32: 7.2 significant digits hold the text's 6 exactly.
* temperature float64: float32 would round 90 degC by 4e-6 K; the text has 1e-7 K.
* radius float64, kept as one value when every particle has it (a monodisperse bed).
* ids int32, kept as the first when they run 1, 2, ..., N.

What a start state does not hold: the contact history (tangential springs, LIGGGHTS' shear
history), which a new run starts at zero, and the temperatures of the particles' interior
shells (``particles.interior = "shells"``), which start at the particle's temperature.
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from drumflow.errors import BadFileError, RunDirectoryError, StartStateError
from drumflow.physics.drum_frame import drum_angle

if TYPE_CHECKING:
    from drumflow.case import Case
    from drumflow.dem.dumps import Snapshot

__all__ = ["STATE_FORMAT", "SCENE_SECTIONS", "StartState", "check_state", "data_file_text",
           "load_bed_states", "load_start_state", "phase_states",
           "scene_hash", "state_from_run", "state_from_snapshot", "read_state",
           "temperature_file_text", "write_state"]

#: Version of the file layout, written into every state.
STATE_FORMAT = 1
#: The case sections a state must share with the case that starts from it.
SCENE_SECTIONS = ("drum", "lifters", "particles")
#: Snapshot columns a state is made of (``T`` is the heat fix's temperature, read_dump's name).
_COLUMNS = ("id", "x", "y", "z", "vx", "vy", "vz", "omegax", "omegay", "omegaz", "radius", "T")


@dataclass(frozen=True)
class StartState:
    """The particles of one instant and what they belong to.

    Attributes
    ----------
    ids
        Particle ids, (n,), ascending.
    positions, velocities, spins
        (n, 3): m, m/s and rad/s (angular velocity), lab frame.
    radii
        (n,), m.
    temperatures_C
        (n,), degC (what LIGGGHTS' heat fix holds).
    time_s
        Simulated time of the state.
    drum_angle_rad
        The drum's angle omega t at ``time_s`` (counter-clockwise about +z, not wrapped).
    step, time_step_s
        The source run's step number and time step (``time_s = step * time_step_s``).
    case_hash, scene_hash
        The source case's hash and the hash of its scene (:func:`scene_hash`).
    drumflow_version
        The drumflow that wrote the state.
    source
        Where it came from (the snapshot file), for the record.
    """

    ids: NDArray[np.int64]
    positions: NDArray[np.float64]
    velocities: NDArray[np.float64]
    spins: NDArray[np.float64]
    radii: NDArray[np.float64]
    temperatures_C: NDArray[np.float64]
    time_s: float
    drum_angle_rad: float
    step: int
    time_step_s: float
    case_hash: str
    scene_hash: str
    drumflow_version: str
    source: str = ""

    def __len__(self) -> int:
        return len(self.ids)


def scene_hash(case: Case) -> str:
    """Hash of what the particles must fit: the drum, lifters and particles sections of what
    the DEM moves (the parcels of a coarse-grained case, :meth:`Case.dem_case`).

    How a granule's inside is modelled (``particles.interior``, ``interior_shells``) is no part
    of where the particles are: a state of a run with shells starts a lumped run, and the
    paper's levels start from one another's beds. The state carries each particle's mean
    temperature, which both levels take.
    """
    dem = case.dem_case()
    # Nor is how the bed was first placed: a state replaces the placement.
    particles = dem.particles.model_copy(update={"interior": "lumped", "interior_shells": None,
                                                 "placement": "lattice"})
    return dem.model_copy(update={"particles": particles}).section_hash(*SCENE_SECTIONS)


def state_from_snapshot(snap: Snapshot, case: Case, time_step: float, source: str = "") -> StartState:
    """The start state of one full snapshot of a run of ``case`` (time step ``time_step``).

    Raises
    ------
    RunDirectoryError
        The snapshot lacks a column (an older deck wrote no spins: omegax omegay omegaz).
    """
    from drumflow import __version__

    missing = [c for c in _COLUMNS if c not in snap.columns]
    if missing:
        raise RunDirectoryError(
            f"{source or 'snapshot'}: lacks column(s) {', '.join(missing)} (snapshots written before "
            "drumflow dumped the spins cannot make a start state; resume the run for one snapshot)")
    c = snap.columns
    t = snap.step * time_step
    return StartState(
        ids=snap.ids,
        positions=np.column_stack([c["x"], c["y"], c["z"]]),
        velocities=np.column_stack([c["vx"], c["vy"], c["vz"]]),
        spins=np.column_stack([c["omegax"], c["omegay"], c["omegaz"]]),
        radii=np.asarray(c["radius"], dtype=np.float64),
        temperatures_C=np.asarray(c["T"], dtype=np.float64),
        time_s=t,
        drum_angle_rad=drum_angle(case.drum.omega, t),
        step=snap.step,
        time_step_s=time_step,
        case_hash=case.hash(),
        scene_hash=scene_hash(case),
        drumflow_version=__version__,
        source=source,
    )


def state_from_run(run_dir: Path, time_s: float | None = None) -> StartState:
    """The start state of a run directory's full snapshot at ``time_s`` (the nearest one), or at
    its newest readable snapshot.

    Raises
    ------
    RunDirectoryError
        Not a run directory, no snapshots, none within half a snapshot interval of ``time_s``,
        or snapshots without spins.
    """
    from drumflow.case import load_case
    from drumflow.dem.dumps import dump_files, dump_step, read_dump
    from drumflow.rundir import RunDir

    run = RunDir.existing(run_dir)
    run.require(run.case_toml)
    case = load_case(run.case_toml)
    record = run.manifest.get("time_step") or {}
    if "time_step" not in record:
        raise RunDirectoryError(f"{run.root}: the manifest has no DEM time step (no DEM run yet)")
    dt = float(record["time_step"])
    files = dump_files(run.dem_dumps, "snap")
    if not files:
        raise RunDirectoryError(f"{run.dem_dumps}: no full snapshots (snap.*.txt or .npz)")
    if time_s is None:
        # The newest may still be being written by a running LIGGGHTS: the newest readable one.
        for path in reversed(files):
            try:
                return state_from_snapshot(read_dump(path), case.dem_case(), dt, str(path))
            except BadFileError:
                continue
            except RunDirectoryError as exc:
                if "lacks column" in str(exc):
                    raise
                continue
        raise RunDirectoryError(f"{run.dem_dumps}: no readable full snapshot")
    times = np.array([dump_step(p) * dt for p in files])
    best = int(np.argmin(np.abs(times - time_s)))
    spacing = float(np.min(np.diff(times))) if len(times) > 1 else math.inf
    if abs(times[best] - time_s) > max(0.5 * spacing, 0.5 * dt) and not (
            len(times) == 1 and abs(times[0] - time_s) <= 0.5 * dt):
        raise RunDirectoryError(
            f"{run.dem_dumps}: no full snapshot at t = {time_s:g} s (snapshots at "
            f"{', '.join(f'{t:g}' for t in times)} s)")
    return state_from_snapshot(read_dump(files[best]), case.dem_case(), dt, str(files[best]))


def phase_states(run_dir: Path, phases: int, start_s: float | None = None) -> list[StartState]:
    """``phases`` start states spread over one lifter period 60 / (rpm lifters), for a case's
    ``air.bed_states``: the snapshots nearest ``start_s + k period / phases`` (default
    ``start_s``: the newest snapshot's time less ``(phases - 1) / phases`` of a period, so the
    last is the newest).

    Raises
    ------
    RunDirectoryError
        A drum without lifters (one state is every phase), ``phases`` outside 1-8, a start
        before the first snapshot, or a time with no snapshot near it (:func:`state_from_run`).
    """
    from drumflow.case import load_case
    from drumflow.dem.dumps import dump_files, dump_step
    from drumflow.rundir import RunDir

    if not 1 <= phases <= 8:
        raise RunDirectoryError(f"--phases = {phases}: allowed 1 to 8 (air.bed_states holds at most 8)")
    run = RunDir.existing(run_dir)
    run.require(run.case_toml)
    case = load_case(run.case_toml)
    if case.lifters.count == 0:
        raise RunDirectoryError(f"{run.root}: a drum without lifters looks the same at every "
                                "angle; one state (--state alone) stands for every phase")
    period = 60.0 / (case.drum.rpm * case.lifters.count)
    dt = float((run.manifest.get("time_step") or {}).get("time_step", math.nan))
    files = dump_files(run.dem_dumps, "snap")
    if not files or not math.isfinite(dt):
        raise RunDirectoryError(f"{run.dem_dumps}: no full snapshots of a DEM run")
    first, newest = dump_step(files[0]) * dt, dump_step(files[-1]) * dt
    start = newest - period * (phases - 1) / phases if start_s is None else start_s
    if start < first - 0.5 * dt:
        raise RunDirectoryError(f"--time = {start:g} s: the first snapshot is at {first:g} s; "
                                f"{phases} phases of the {period:g} s lifter period need "
                                f"snapshots from {start:g} to {start + period * (phases - 1) / phases:g} s")
    return [state_from_run(run_dir, start + k * period / phases) for k in range(phases)]


def write_state(state: StartState, path: Path) -> Path:
    """Write ``state`` as one compressed ``.npz`` (under a temporary name, then renamed, so a
    reader never sees half a file); return the path."""
    n = len(state)
    ids = state.ids
    arrays: dict[str, NDArray[np.generic]] = {
        "format": np.array(STATE_FORMAT, dtype=np.int64),
        "rows": np.array(n, dtype=np.int64),
        "positions": np.asarray(state.positions, dtype=np.float64),
        "velocities": np.asarray(state.velocities, dtype=np.float32),
        "spins": np.asarray(state.spins, dtype=np.float32),
        "temperature_C": np.asarray(state.temperatures_C, dtype=np.float64),
        "time_s": np.array(state.time_s, dtype=np.float64),
        "drum_angle_rad": np.array(state.drum_angle_rad, dtype=np.float64),
        "step": np.array(state.step, dtype=np.int64),
        "time_step_s": np.array(state.time_step_s, dtype=np.float64),
        "case_hash": np.array(state.case_hash),
        "scene_hash": np.array(state.scene_hash),
        "drumflow_version": np.array(state.drumflow_version),
        "source": np.array(state.source),
    }
    if n and np.array_equal(ids, ids[0] + np.arange(n)):
        arrays["first_id"] = np.array(ids[0], dtype=np.int64)
    else:
        arrays["ids"] = ids.astype(np.int32)
    radii = np.asarray(state.radii, dtype=np.float64)
    arrays["radius"] = radii[:1] if n > 1 and np.all(radii == radii[0]) else radii
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    partial = path.with_name(path.name + ".partial")
    with partial.open("wb") as fh:
        np.savez_compressed(fh, **arrays)  # type: ignore[arg-type]
    os.replace(partial, path)
    return path


def read_state(path: Path) -> StartState:
    """Read a start state written by :func:`write_state`.

    Raises
    ------
    StartStateError
        Missing, damaged, or not a drumflow start state (names the file and what is wrong).
    """
    from drumflow.readers import read_npz

    try:
        data = read_npz(path, "start state")
    except BadFileError as exc:
        raise StartStateError(path, exc.problem) from None
    try:
        version = int(data["format"])
        if version > STATE_FORMAT:
            raise ValueError(f"format {version}, newer than this drumflow's {STATE_FORMAT}")
        n = int(data["rows"])
        if "first_id" in data:
            ids = int(data["first_id"]) + np.arange(n, dtype=np.int64)
        else:
            ids = np.asarray(data["ids"], dtype=np.int64)
        radius = np.asarray(data["radius"], dtype=np.float64)
        radii = np.full(n, radius[0]) if radius.shape == (1,) and n != 1 else radius
        state = StartState(
            ids=ids,
            positions=np.asarray(data["positions"], dtype=np.float64).reshape(n, 3),
            velocities=np.asarray(data["velocities"], dtype=np.float64).reshape(n, 3),
            spins=np.asarray(data["spins"], dtype=np.float64).reshape(n, 3),
            radii=radii,
            temperatures_C=np.asarray(data["temperature_C"], dtype=np.float64).reshape(n),
            time_s=float(data["time_s"]),
            drum_angle_rad=float(data["drum_angle_rad"]),
            step=int(data["step"]),
            time_step_s=float(data["time_step_s"]),
            case_hash=str(data["case_hash"]),
            scene_hash=str(data["scene_hash"]),
            drumflow_version=str(data["drumflow_version"]),
            source=str(data["source"]),
        )
    except (KeyError, ValueError, TypeError) as exc:
        raise StartStateError(path, f"not a drumflow start state ({exc})") from None
    if len(state.radii) != n or not np.all(np.isfinite(state.positions)):
        raise StartStateError(path, "not a drumflow start state (columns of unequal length or "
                              "positions that are not finite)")
    return state


def check_state(state: StartState, case: Case, path: Path | str,
                field: str = "run.start_state") -> None:
    """Refuse a state that does not belong to ``case``'s scene (``field``: the case field
    that names it, for the message).

    Raises
    ------
    StartStateError
        Another scene (drum, lifters or particles sections differ from the state's source
        case) or another particle count than the case's.
    """
    want = scene_hash(case)
    if state.scene_hash != want:
        raise StartStateError(
            path, f"made for another scene (its drum, lifters and particles sections hash to "
            f"{state.scene_hash[:12]}, this case's to {want[:12]}; source case "
            f"{state.case_hash[:12]}): start from a state of this scene", field)
    count = case.dem_case().particle_count
    if len(state) != count:
        raise StartStateError(
            path, f"holds {len(state):,} particles, the case {count:,}", field)


def load_start_state(case: Case) -> StartState | None:
    """The case's start state (``run.start_state``), checked against its scene; None without.

    Raises
    ------
    StartStateError
        The file is not a start state, or it is another scene's or holds another particle count.
    """
    if case.run.start_state is None:
        return None
    path = Path(case.run.start_state)
    state = read_state(path)
    check_state(state, case, path)
    if case.run.time <= state.time_s:
        raise StartStateError(
            case.run.start_state, f"the state is at t = {state.time_s:.6g} s, run.time "
            f"= {case.run.time:g} s ends before it: run.time is the end time, counted from 0")
    return state


def load_bed_states(case: Case) -> list[StartState]:
    """The case's bed states for the air around the bed (``air.bed_states``), each checked
    against its scene; empty without.

    Raises
    ------
    StartStateError
        A file that is not a start state, or another scene's, or of another particle count
        (named as ``air.bed_states[k]``).
    """
    states = []
    for k, name in enumerate(case.air.bed_states):
        field = f"air.bed_states[{k}]"
        try:
            state = read_state(Path(name))
        except StartStateError as err:
            raise StartStateError(name, err.problem, field) from None
        check_state(state, case, name, field)
        states.append(state)
    return states


def start_step(state: StartState, time_step: float) -> int:
    """The DEM step a run with ``time_step`` starts at from ``state``: the one nearest its time
    (the state's own step when the time step is the same)."""
    if math.isclose(time_step, state.time_step_s, rel_tol=1e-12):
        return state.step
    return round(state.time_s / time_step)


def data_file_text(state: StartState, case: Case, box: tuple[object, object]) -> str:
    """The LIGGGHTS ``read_data`` file (atom_style granular) of the state's particles: ids,
    diameters, positions (every digit: ``%.17g``), velocities and spins.

    Atom type 1 is the particles, 2 the walls, as :func:`drumflow.dem.placement.write_data_file`.
    """
    lo, hi = (np.asarray(b, dtype=np.float64) for b in box)
    n = len(state)
    header = (
        f"LIGGGHTS data file written by drumflow for case {case.name} from a start state at "
        f"t = {state.time_s:.9g} s\n\n"
        f"{n} atoms\n2 atom types\n\n"
        f"{lo[0]:.9g} {hi[0]:.9g} xlo xhi\n{lo[1]:.9g} {hi[1]:.9g} ylo yhi\n"
        f"{lo[2]:.9g} {hi[2]:.9g} zlo zhi\n\n"
    )
    atoms = np.column_stack([state.ids, np.ones(n), 2.0 * state.radii,
                             np.full(n, case.particles.density), state.positions])
    velocities = np.column_stack([state.ids, state.velocities, state.spins])
    parts = [header, "Atoms\n\n",
             _table(atoms, ["%d", "%d", "%.17g", "%.9g", "%.17g", "%.17g", "%.17g"]),
             "\nVelocities\n\n", _table(velocities, ["%d"] + ["%.9g"] * 6)]
    return "".join(parts)


def temperature_file_text(state: StartState) -> str:
    """The state's temperatures as a LAMMPS ``variable atomfile`` (a count line, then
    ``id value`` lines, every digit), which the deck's ``set ... property/atom Temp`` reads."""
    table = np.column_stack([state.ids, state.temperatures_C])
    return (f"# particle temperatures, degC, of a drumflow start state at t = {state.time_s:.9g} s\n"
            f"{len(state)}\n" + _table(table, ["%d", "%.17g"]))


def _table(rows: NDArray[np.float64], fmt: list[str]) -> str:
    import io

    buf = io.StringIO()
    np.savetxt(buf, rows, fmt=fmt)
    return buf.getvalue()
