"""A run directory as ParaView files: particles, walls and air (``drumflow export --vtk``).

Written into ``OUT`` (default ``RUN_DIR/vtk``):

* ``particles.pvd``: one binary ``.vtu`` per full snapshot (``dem/dumps/snap.*.txt or .npz``), every
  particle a vertex with point data ``id``, ``velocity`` (m/s), ``radius`` (m) and
  ``temperature`` (deg C); the ``.pvd`` collection gives ParaView the simulated times;
* ``walls.pvd``: the walls as LIGGGHTS saw them at each snapshot: part 0 the rotating part of
  the geometry STL (the lifters for a static shell, else the whole wall) turned by the drum
  angle ``omega t`` about +z (counter-clockwise, as ``fix move/mesh ... rotate`` turns it) with
  field data ``drum_angle_rad``; part 1 (static shell only) the shell, written once;
* ``air.vti``: the air on its regular grid (``air/field.npz``; for plug flow the grid
  :meth:`drumflow.air.field.AirField.uniform` builds, carrying the velocity the coupling loop
  applied) with point data ``velocity`` (m/s),
  ``pressure`` (Pa) and ``fluid`` (1 inside the air volume). A CFD field is solved in the
  drum's rotating frame: the file holds it at t = 0, when drum and lab frame coincide (rotate it
  by ``omega t`` about z, ParaView's Transform filter, to lay it over a later snapshot).
  A run with the air around the bed (``air.bed_states``) solved the empty drum (``air.vti``)
  and one field per bed state: ``air_bed_phase_K.vti``, each with field data
  ``phase_angle_rad`` (where the state's lifters stood in the lifter spacing) and the same
  frame; those are the fields the coupling loop applied, the empty drum's is not.

Library code: writes files and returns what it wrote; ``drumflow.cli.export`` prints.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any
from xml.sax.saxutils import quoteattr

import numpy as np

from drumflow.case import load_case
from drumflow.coupling.spec import COUPLING_FILE
from drumflow.dem.dumps import dump_files, read_dump
from drumflow.errors import BadFileError, RunDirectoryError
from drumflow.physics.drum_frame import drum_angle, rotate_about_axis
from drumflow.readers import read_json_object
from drumflow.rundir import RunDir

if TYPE_CHECKING:
    import pyvista as pv

    from drumflow.air.field import AirField
    from drumflow.case import Case

__all__ = ["VtkExport", "export_vtk"]


@dataclass(frozen=True)
class VtkExport:
    """What :func:`export_vtk` wrote (paths relative to ``out``)."""

    out: str
    particles_pvd: str
    walls_pvd: str
    air: str | None
    times_s: list[float]
    particles: list[int]
    bytes_written: int
    snapshot_text_bytes: int
    air_bed_phases: list[str] = field(default_factory=list)

    def as_dict(self) -> dict[str, Any]:
        return asdict(self)


def _write_pvd(path: Path, entries: list[tuple[float, str]], every_time: str | None = None) -> None:
    """A ParaView collection: one data set file per time (part 0), and optionally one file
    shown at every time (part 1)."""
    lines = ['<?xml version="1.0"?>',
             '<VTKFile type="Collection" version="0.1" byte_order="LittleEndian">',
             "  <Collection>"]
    for t, name in entries:
        lines.append(f'    <DataSet timestep="{t:.10g}" group="" part="0" file={quoteattr(name)}/>')
        if every_time:
            lines.append(f'    <DataSet timestep="{t:.10g}" group="" part="1" '
                         f'file={quoteattr(every_time)}/>')
    lines += ["  </Collection>", "</VTKFile>", ""]
    path.write_text("\n".join(lines))


def _walls(rundir: RunDir) -> tuple[pv.PolyData | None, pv.PolyData]:
    """(static part or None, rotating part) of the run's walls, from the geometry stage."""
    import pyvista as pv

    marker = rundir.stages / "geometry.json"
    record = rundir.stage_record("geometry")  # checked: a cut marker is named, not a traceback
    if record is None:
        raise RunDirectoryError(f"{marker}: missing (the geometry stage did not finish)")
    geometry = record.get("result")
    if not isinstance(geometry, dict) or not isinstance(geometry.get("stl"), str):
        raise BadFileError(marker, f"result = {geometry!r}: expected the stage's result with the "
                           "wall file's path (stl)", "the record that the geometry stage finished")

    def read_stl(relative: str) -> pv.PolyData:
        mesh = pv.read(str(rundir.root / relative))
        if not isinstance(mesh, pv.PolyData):
            raise RunDirectoryError(f"{rundir.root / relative}: not a surface mesh")
        return mesh

    shell = read_stl(geometry["stl"])
    if geometry.get("wall_motion") == "static_shell":
        lifters = geometry.get("lifters_stl")
        return shell, read_stl(lifters) if lifters else pv.PolyData()
    return None, shell


def _air_grid(rundir: RunDir, case: Case) -> pv.ImageData | None:
    """The air field as VTK image data (x fastest), or None without air."""

    from drumflow.air.field import AirField

    if rundir.air_field.exists():
        solved = AirField.from_npz(rundir.air_field)
    elif case.air.model == "uniform":
        # The grid and the air volume of plug flow, carrying the velocity the coupling loop
        # applied (its input file; the case's own value when the run never reached the loop).
        from drumflow.air.source import uniform_field

        solved = AirField.uniform(case)
        spec_file = rundir.dem / COUPLING_FILE
        spec: dict[str, Any] = {}
        if spec_file.exists():
            what = "the coupling loop's input"
            applied = read_json_object(spec_file, what).get("field")
            if not isinstance(applied, dict):
                raise BadFileError(spec_file, f"field = {applied!r}: expected an object (the air "
                                   "the coupling loop applied)", what)
            spec = applied
        velocity = spec.get("velocity") or uniform_field(case).field["velocity"]
        solved.velocity[...] = np.asarray(velocity, dtype=float)
    else:
        return None
    return _field_grid(solved, case)


def _field_grid(air: AirField, case: Case) -> pv.ImageData:
    """One air field as VTK image data (x fastest), in the drum frame at t = 0."""
    import pyvista as pv

    nx, ny, nz = air.shape
    grid = pv.ImageData(dimensions=(nx, ny, nz), spacing=tuple(air.spacing),
                        origin=tuple(air.origin))

    # AirField arrays are C-ordered (x, y, z); VTK points run x fastest (Fortran order).
    grid.point_data["velocity"] = np.column_stack(
        [air.velocity[..., k].ravel(order="F") for k in range(3)])
    grid.point_data["pressure"] = air.pressure.ravel(order="F")
    grid.point_data["fluid"] = air.fluid.astype(np.uint8).ravel(order="F")
    grid.field_data["frame"] = np.array(["drum frame at t = 0 (rotate by omega t about +z)"])
    grid.field_data["model"] = np.array([str(air.meta.get("model", case.air.model))])
    return grid


def _bed_phase_grids(rundir: RunDir, case: Case) -> list[pv.ImageData]:
    """The air around the bed at each of the run's bed states (``air/bed_phase_K.npz``, where
    its record ``air/bed_phases.json`` says each state's lifter angle); empty without."""
    from drumflow.air.bed_phases import PHASES_RECORD
    from drumflow.air.field import AirField

    if not case.air.bed_states or not (rundir.air / PHASES_RECORD).exists():
        return []
    what = "the air stage's record of the bed phases"
    record = read_json_object(rundir.air / PHASES_RECORD, what)
    states = record.get("states")
    if not isinstance(states, list) or len(states) != len(case.air.bed_states):
        raise BadFileError(rundir.air / PHASES_RECORD, f"states = {states!r}: expected one entry per "
                           f"air.bed_states ({len(case.air.bed_states)})", what)
    grids = []
    for k, state in enumerate(states):
        path = rundir.air / f"bed_phase_{k}.npz"
        if not path.exists():
            raise RunDirectoryError(f"{path}: missing (the air stage writes one field per bed "
                                    "state); rerun the case")
        grid = _field_grid(AirField.from_npz(path), case)
        grid.field_data["phase_angle_rad"] = np.array([float(state["angle_rad"])])
        grids.append(grid)
    return grids


def export_vtk(run_dir: Path | str, out: Path | str | None = None) -> VtkExport:
    """Write a run's snapshots, walls and air field as ParaView files.

    Parameters
    ----------
    run_dir
        A directory written by ``drumflow run``.
    out
        Output folder (created); default ``RUN_DIR/vtk``.

    Raises
    ------
    RunDirectoryError
        When the run directory lacks the case, the time step, the geometry or the snapshots.
    BadFileError
        A snapshot, the geometry stage's marker or the coupling input is damaged (cut short,
        not UTF-8, a word where a number belongs).
    """
    import pyvista as pv

    rundir = RunDir.existing(run_dir)
    rundir.require(rundir.case_toml, rundir.dem_dumps)
    case = load_case(rundir.case_toml)
    ts = rundir.manifest.get("time_step", {}).get("time_step")
    if ts is None:
        raise RunDirectoryError(f"{rundir.root}/manifest.json: no DEM time step recorded; rerun the case")
    files = dump_files(rundir.dem_dumps, "snap")
    if not files:
        raise RunDirectoryError(f"{rundir.dem_dumps}: no snapshots (snap.*.txt or .npz)")
    target = Path(out) if out is not None else rundir.root / "vtk"
    (target / "particles").mkdir(parents=True, exist_ok=True)
    (target / "walls").mkdir(parents=True, exist_ok=True)
    static, moving = _walls(rundir)
    static_name = None
    if static is not None:
        # The static shell once; the collection shows it at every time as part 1.
        static_name = "walls/shell.vtp"
        static.save(str(target / static_name), binary=True)
    particle_entries: list[tuple[float, str]] = []
    wall_entries: list[tuple[float, str]] = []
    counts: list[int] = []
    written = 0
    for path in files:
        snap = read_dump(path)
        t = snap.step * float(ts)
        c = snap.columns
        cloud = pv.PolyData(np.column_stack([c["x"], c["y"], c["z"]]))
        cloud.point_data["id"] = snap.ids
        cloud.point_data["velocity"] = np.column_stack([c["vx"], c["vy"], c["vz"]])
        cloud.point_data["radius"] = c["radius"]
        cloud.point_data["temperature"] = c["T"]
        name = f"particles/particles_{snap.step:010d}.vtu"
        cloud.cast_to_unstructured_grid().save(str(target / name), binary=True)
        particle_entries.append((t, name))
        counts.append(len(snap))
        turned = moving.copy()
        turned.points = rotate_about_axis(np.asarray(moving.points), drum_angle(case.drum.omega, t))
        turned.field_data["drum_angle_rad"] = np.array([drum_angle(case.drum.omega, t)])
        wname = f"walls/moving_{snap.step:010d}.vtp"
        turned.save(str(target / wname), binary=True)
        wall_entries.append((t, wname))
        written += (target / name).stat().st_size + (target / wname).stat().st_size
    _write_pvd(target / "particles.pvd", particle_entries)
    _write_pvd(target / "walls.pvd", wall_entries, static_name)
    written += (target / static_name).stat().st_size if static_name else 0
    air_name = None
    grid = _air_grid(rundir, case)
    if grid is not None:
        air_name = "air.vti"
        grid.save(str(target / air_name), binary=True)
        written += (target / air_name).stat().st_size
    phases = _bed_phase_grids(rundir, case)
    for k, phase in enumerate(phases):
        phase.save(str(target / f"air_bed_phase_{k}.vti"), binary=True)
        written += (target / f"air_bed_phase_{k}.vti").stat().st_size
    return VtkExport(
        air_bed_phases=[f"air_bed_phase_{k}.vti" for k in range(len(phases))],
        out=str(target),
        particles_pvd="particles.pvd",
        walls_pvd="walls.pvd",
        air=air_name,
        times_s=[t for t, _ in particle_entries],
        particles=counts,
        bytes_written=written,
        snapshot_text_bytes=sum(p.stat().st_size for p in files),
    )
