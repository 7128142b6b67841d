"""What a slice run tells a whole-cooler model: the curtain and bed closures.

A drumflow slice run simulates a short section of a flighted drum. The whole-cooler model
(:mod:`drumflow.coolers.drum`) needs from it only a few numbers per metre of drum, measured
here from the run directory through the same readers ``drumflow post`` uses:

* **falling mass flow per metre** ``G_f`` (kg/(s m)): the paper's Eq. 57 from the crossing
  table (:func:`drumflow.analysis.observables.falling_mass_flow`) divided by the section
  length;
* **airborne fraction** ``phi``: the share of the hold-up in the air, averaged over the
  snapshots after ``run.mass_flow_start``, with the airborne test of
  :func:`drumflow.analysis.air_side.airborne_mask` (falling faster than the shell could carry
  a particle);
* **fall time** ``t_f = phi W / G_f`` (Little's law: the airborne mass is the falling flow
  times the time each particle spends falling; ``W`` is the hold-up per metre);
* **fall height** ``H_f = t_f <v_down>``: the same law for distance (the airborne mass times
  its mean downward speed is the falling flow times the mean drop of one fall);
* **slip velocity** of the airborne particles against the air field (the run's
  ``air/field.npz``, or with ``air.bed_states`` the air around the bed), the speed that enters
  Ranz-Marshall; for ``air.model = "uniform"`` the air is the plug flow of the run, for
  ``"none"`` still air;
* **bed exposed surface** per metre (m^2/m): the length of the bed's top profile in the cross
  section (the highest non-airborne particle below the axis in bins two diameters wide, bins
  within one lifter height of the wall dropped as lifter pockets), times one metre of drum.

Everything is per metre of drum and comes with the slice's own geometry, so the drum model
can scale it to a plant and say how far it extrapolates.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass, fields
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
from numpy.typing import NDArray
from pydantic import BaseModel, ConfigDict, Field, ValidationError, field_validator

from drumflow.analysis.air_closures import AirClosures, validate_air_closures
from drumflow.analysis.air_side import airborne_mask
from drumflow.analysis.observables import falling_mass_flow
from drumflow.case import Case, load_case
from drumflow.errors import BadFileError, RunDirectoryError
from drumflow.readers import field_problems, read_csv, read_json_object
from drumflow.rundir import RunDir

__all__ = ["SliceClosures", "bed_surface_length", "extract_closures", "load_closures"]

FloatArray = NDArray[np.float64]

#: Random loose packing of the bed, for the bed volume of the segment estimate.
BED_PACKING = 0.6


@dataclass(frozen=True)
class SliceClosures:
    """Closures of one slice run, per metre of drum (SI units).

    Attributes
    ----------
    source, case_name
        Run directory (or file) and case name.
    drum_diameter_m, section_length_m, rpm, tilt_deg, lifter_count
        The slice's drum.
    particle_diameter_m, particle_density_kg_m3
        Its particles.
    holdup_kg_per_m
        Solids hold-up per metre of drum.
    solids_volume_fraction
        Solids volume over drum volume.
    air_axial_velocity_m_s
        Mean axial air speed of the slice (0 for still air).
    falling_mass_flow_kg_s_m
        ``G_f``, Eq. 57 per metre.
    airborne_fraction
        ``phi``, mean share of the hold-up in the air.
    fall_time_s, fall_height_m
        Mean duration and drop of one fall (Little's law, module notes).
    airborne_speed_m_s, airborne_downward_speed_m_s
        Mean speed and mean downward speed of airborne particles.
    slip_velocity_m_s
        Mean air-particle slip speed of airborne particles.
    bed_slip_velocity_m_s
        Mean slip speed of the bed particles (what the one-way slice gives every bed particle).
    bed_surface_m2_per_m
        Bed exposed (free-surface) area per metre of drum.
    snapshots
        Snapshots averaged.
    window_s
        Time window of the snapshots and crossings used.
    start_s
        The simulated time from which they were measured (``--start``, or the case's
        ``run.mass_flow_start``); None in files written before it was recorded.
    air
        What a periodic slice's air around the bed measured (through-curtain air with its
        mixing bounds, contact efficiencies; :mod:`drumflow.analysis.air_closures`), once
        attached (``drumflow plant --curtain-air HEAT.json --save-closures``); None before.
    """

    source: str
    case_name: str
    drum_diameter_m: float
    section_length_m: float
    rpm: float
    tilt_deg: float
    lifter_count: int
    particle_diameter_m: float
    particle_density_kg_m3: float
    holdup_kg_per_m: float
    solids_volume_fraction: float
    air_axial_velocity_m_s: float
    falling_mass_flow_kg_s_m: float
    airborne_fraction: float
    fall_time_s: float
    fall_height_m: float
    airborne_speed_m_s: float
    airborne_downward_speed_m_s: float
    slip_velocity_m_s: float
    bed_slip_velocity_m_s: float
    bed_surface_m2_per_m: float
    snapshots: int
    window_s: tuple[float, float]
    start_s: float | None = None
    air: AirClosures | None = None

    @property
    def froude(self) -> float:
        """Rotational Froude number omega^2 R / g of the slice."""
        omega = self.rpm * 2.0 * math.pi / 60.0
        return omega**2 * 0.5 * self.drum_diameter_m / 9.81

    @property
    def cascades_per_revolution(self) -> float:
        """Falls per particle per drum revolution: ``G_f / (W rpm / 60)``."""
        return self.falling_mass_flow_kg_s_m / (self.holdup_kg_per_m * self.rpm / 60.0)

    def to_dict(self) -> dict[str, Any]:
        data = {f.name: getattr(self, f.name) for f in fields(self)}
        data["window_s"] = list(self.window_s)
        data["air"] = None if self.air is None else self.air.model_dump()
        data["froude"] = self.froude
        data["cascades_per_revolution"] = self.cascades_per_revolution
        return data

    @classmethod
    def from_dict(cls, data: dict[str, Any]) -> SliceClosures:
        """Inverse of :meth:`to_dict` (derived entries are ignored)."""
        names = {f for f in cls.__dataclass_fields__}
        missing = sorted(names - set(data) - {"start_s", "air"})
        if missing:
            raise RunDirectoryError(f"closures: missing field(s) {', '.join(missing)}")
        values = {k: data[k] for k in names if k in data}
        values["window_s"] = tuple(values["window_s"])
        if values.get("air") is not None and not isinstance(values["air"], AirClosures):
            values["air"] = validate_air_closures(values["air"], str(data.get("source", "")))
        return cls(**values)

    def write(self, path: Path | str) -> Path:
        """Write the closures as JSON."""
        out = Path(path)
        out.parent.mkdir(parents=True, exist_ok=True)
        out.write_text(json.dumps(self.to_dict(), indent=2) + "\n")
        return out


# Finite numbers only: a NaN closure would pass every comparison of the drum model and end
# in a root finder's error (or a wrong profile) far from the file that held it.
_Positive = Field(gt=0, allow_inf_nan=False)
_NonNegative = Field(ge=0, allow_inf_nan=False)


class ClosuresFile(BaseModel):
    """What a closures JSON file must hold, each field a finite number in its range (strict
    types: a word, a boolean or ``NaN`` where a number belongs is refused by name).

    Derived entries written by :meth:`SliceClosures.to_dict` (``froude``,
    ``cascades_per_revolution``) are ignored: they are recomputed.
    """

    model_config = ConfigDict(strict=True, extra="ignore")

    source: str
    case_name: str
    drum_diameter_m: float = _Positive
    section_length_m: float = _Positive
    rpm: float = _Positive
    tilt_deg: float = Field(ge=0, lt=90, allow_inf_nan=False)
    lifter_count: int = Field(ge=0)
    particle_diameter_m: float = _Positive
    particle_density_kg_m3: float = _Positive
    holdup_kg_per_m: float = _Positive
    solids_volume_fraction: float = Field(gt=0, lt=1, allow_inf_nan=False)
    air_axial_velocity_m_s: float = _NonNegative
    falling_mass_flow_kg_s_m: float = _Positive
    airborne_fraction: float = Field(ge=0, le=1, allow_inf_nan=False)
    fall_time_s: float = _NonNegative
    fall_height_m: float = _NonNegative
    airborne_speed_m_s: float = _NonNegative
    airborne_downward_speed_m_s: float = _NonNegative
    slip_velocity_m_s: float = _NonNegative
    bed_slip_velocity_m_s: float = _NonNegative
    bed_surface_m2_per_m: float = _NonNegative
    snapshots: int = Field(ge=1)
    window_s: list[float] = Field(min_length=2, max_length=2)
    start_s: float | None = Field(default=None, ge=0, allow_inf_nan=False)
    # Files written before the air closures existed have none (or null).
    air: AirClosures | None = None

    @field_validator("window_s")
    @classmethod
    def _ordered_window(cls, value: list[float]) -> list[float]:
        if not all(math.isfinite(v) and v >= 0 for v in value) or value[0] > value[1]:
            raise ValueError("allowed: [start, end], finite times >= 0 s with start <= end")
        return value


def load_closures(path: Path | str) -> SliceClosures:
    """Read closures written by :meth:`SliceClosures.write`, validated by :class:`ClosuresFile`.

    Raises
    ------
    BadFileError
        When the file is missing, not UTF-8, not JSON (or cut short), or a field is missing, not
        a finite number, or outside its range (each problem names the field and its value).
    """
    p = Path(path)
    data = read_json_object(p, "a closures file")
    try:
        ClosuresFile.model_validate(data)
    except ValidationError as exc:
        problems = field_problems(exc, data)
        raise BadFileError(p, "invalid closures:\n" + "\n".join(f"  - {line}" for line in problems),
                           "a closures file") from None
    return SliceClosures.from_dict(data)


def bed_surface_length(x: FloatArray, y: FloatArray, radius: float, bin_width: float,
                       pocket_depth: float) -> float:
    """Length of the bed's top profile in a cross-section, m.

    Parameters
    ----------
    x, y
        Positions of the bed (non-airborne) particles, drum axis at the origin, y up.
    radius
        Drum radius.
    bin_width
        Width of the x bins (two particle diameters).
    pocket_depth
        Bins whose top lies within this distance of the wall are lifter pockets (or the wall
        region the lifters sweep) and are dropped.
    """
    below = y < 0.0
    x, y = x[below], y[below]
    if len(x) == 0:
        return 0.0
    edges = np.arange(-radius, radius + bin_width, bin_width)
    index = np.digitize(x, edges) - 1
    tops = pd.Series(y).groupby(index).max()
    centres = 0.5 * (edges[tops.index.to_numpy()] + edges[tops.index.to_numpy() + 1])
    top = tops.to_numpy()
    keep = np.hypot(centres, top) < radius - pocket_depth
    bins = tops.index.to_numpy()[keep]
    cx, cy = centres[keep], top[keep]
    length = 0.0
    for i in range(1, len(bins)):
        if bins[i] == bins[i - 1] + 1:  # neighbouring bins only: a gap is not surface
            length += math.hypot(cx[i] - cx[i - 1], cy[i] - cy[i - 1])
    return length


def _air_sampler(run_dir: Path, case: Case) -> Any:
    """The air velocity sampler of the run (lab frame), or None for still air."""
    field_path = run_dir / "air" / "field.npz"
    if case.air.model == "cfd" and case.air.bed_states:
        # The air around the bed (air.bed_states): what the loop's particles felt.
        from drumflow.air.bed_phases import PhaseLockedAir

        return PhaseLockedAir.from_run(run_dir / "air", case)
    if case.air.model == "cfd" and field_path.exists():
        from drumflow.air.field import AirField

        return AirField.from_npz(field_path)
    return None


def _uniform_air_velocity(case: Case) -> float:
    """Axial plug-flow speed of the case's air over the drum cross-section, m/s."""
    if case.air.model == "none" or case.air.mass_flow == 0:
        return 0.0
    from drumflow.physics.air import ideal_gas_density

    rho = ideal_gas_density(case.air.inlet_temperature_C, case.air.pressure_kPa)
    return case.air.mass_flow / (rho * math.pi * case.drum.radius**2)


def extract_closures(run_dir: Path | str, start_s: float | None = None) -> SliceClosures:
    """Measure the slice closures of a finished run (module notes).

    Parameters
    ----------
    run_dir
        A ``drumflow run`` directory with ``case.toml``, ``post/crossings.csv`` and the
        snapshots ``dem/dumps/snap.*.txt or .npz``.
    start_s
        Ignore data before this time; default ``run.mass_flow_start``.

    Raises
    ------
    RunDirectoryError
        When a file is missing or the run has no falling particles or no snapshot in the window.
    """
    # Reading a run's snapshots needs the DEM stage's reader; imported here so that the coolers,
    # which only load a closures file, never load a simulation stage.
    from drumflow.dem.dumps import dump_files, read_dump

    run = RunDir.existing(run_dir)
    root = run.root
    case_file = run.case_toml
    # The run's own table, or the gzipped copy shipped results hold (post/crossings.csv.gz).
    crossings_file = run.crossings_table
    for f, what in ((case_file, "the case"), (crossings_file, "the crossing table")):
        if not f.exists():
            raise RunDirectoryError(f"{f}: missing ({what}); run `drumflow run CASE --out "
                                    f"{root}` (or `drumflow post {root}`) first")
    snaps = [f for f in dump_files(run.dem_dumps, "snap")]
    case = load_case(case_file)
    start = case.run.mass_flow_start if start_s is None else float(start_s)
    if not snaps:
        # Checked before the crossing table is read (seconds for a paper run): shipped results
        # keep no snapshots, and the airborne share, speeds and bed surface need them; they keep
        # the closures `drumflow post` measured from them instead.
        return _recorded_closures(run, start_s)
    length = case.drum.length
    # What the DEM moved: under coarse-graining each crossing and each snapshot row is a parcel
    # of k**3 particles (counted with the particles' mass, the flow came out k**3 too small).
    parcels = case.dem_case()
    mass = parcels.particles.mass
    crossings = read_csv(crossings_file, "the crossing table", columns=("time", "id", "x", "z"),
                         finite=("time", "x", "z"))
    flow = falling_mass_flow(crossings, mass, start=start)
    if flow.mass_flow_kg_s <= 0:
        raise RunDirectoryError(f"{crossings_file}: no particle fell after {start:g} s")
    time_step = run.manifest.get("time_step", {}).get("time_step")
    if time_step is None:
        raise RunDirectoryError(f"{run.manifest_path}: no DEM time step recorded")
    sampler = _air_sampler(root, case)
    u_plug = _uniform_air_velocity(case)
    airborne_shares: list[float] = []
    speeds: list[float] = []
    downs: list[float] = []
    slips: list[float] = []
    bed_slips: list[float] = []
    beds: list[float] = []
    times: list[float] = []
    for path in snaps:
        snap = read_dump(path)
        t = snap.step * float(time_step)
        if t < start - 1e-9 or len(snap) == 0:
            continue
        c = snap.columns
        velocity = np.column_stack([c["vx"], c["vy"], c["vz"]])
        falling = airborne_mask(case, velocity)
        weights = c["radius"] ** 3
        airborne_shares.append(float(weights[falling].sum() / weights.sum()))
        if sampler is not None:
            points = np.column_stack([c["x"], c["y"], c["z"]])
            air = sampler.sample_lab(points, t)
        else:
            air = np.zeros_like(velocity)
            air[:, 2] = -u_plug  # drumflow's air flows towards -z
        slip = np.linalg.norm(air - velocity, axis=1)
        if falling.any():
            speeds.append(float(np.linalg.norm(velocity[falling], axis=1).mean()))
            downs.append(float(-velocity[falling, 1].mean()))
            slips.append(float(slip[falling].mean()))
        bed_slips.append(float(slip[~falling].mean()) if (~falling).any() else math.nan)
        beds.append(bed_surface_length(c["x"][~falling], c["y"][~falling], case.drum.radius,
                                       2.0 * parcels.particles.diameter, case.lifters.base_height))
        times.append(t)
    if not times:
        raise RunDirectoryError(f"{root / 'dem' / 'dumps'}: no snapshot after {start:g} s")
    holdup = case.particle_mass_total / length
    g_f = flow.mass_flow_kg_s / length
    phi = float(np.mean(airborne_shares))
    fall_time = phi * holdup / g_f
    down = float(np.mean(downs)) if downs else math.nan
    drum_volume = math.pi * case.drum.radius**2 * length
    closures = SliceClosures(
        source=str(root),
        case_name=case.name,
        drum_diameter_m=float(case.drum.diameter),
        section_length_m=float(length),
        rpm=float(case.drum.rpm),
        tilt_deg=float(case.drum.tilt_deg),
        lifter_count=int(case.lifters.count),
        particle_diameter_m=float(case.particles.diameter),
        particle_density_kg_m3=float(case.particles.density),
        holdup_kg_per_m=float(holdup),
        solids_volume_fraction=float(case.particle_count * case.particles.volume / drum_volume),
        air_axial_velocity_m_s=float(u_plug),
        falling_mass_flow_kg_s_m=float(g_f),
        airborne_fraction=phi,
        fall_time_s=float(fall_time),
        fall_height_m=float(fall_time * down),
        airborne_speed_m_s=float(np.mean(speeds)) if speeds else math.nan,
        airborne_downward_speed_m_s=down,
        slip_velocity_m_s=float(np.mean(slips)) if slips else math.nan,
        bed_slip_velocity_m_s=float(np.nanmean(bed_slips)),
        bed_surface_m2_per_m=float(np.mean(beds)),
        snapshots=len(times),
        window_s=(float(min(times[0], flow.window_start_s)), float(max(times[-1], flow.window_end_s))),
        start_s=start,
    )
    # The same check as a closures file's: a NaN (no airborne particle in any snapshot) would
    # otherwise stop the drum model far from its cause, or be saved with --save-closures.
    data = closures.to_dict()
    try:
        ClosuresFile.model_validate(data)
    except ValidationError as exc:
        lines = "\n".join(f"  - {line}" for line in field_problems(exc, data))
        raise RunDirectoryError(
            f"{run.dem_dumps}: the closures of its {len(times)} snapshot(s) after {start:g} s are "
            f"not usable (a NaN: no airborne particle in any of them?):\n{lines}") from None
    return closures


def _recorded_closures(run: RunDir, start_s: float | None) -> SliceClosures:
    """The closures ``drumflow post`` recorded (``post/closures.json``) of a run directory
    without snapshots (shipped results), if they were measured from the time asked for."""
    path = run.closures_json
    if not path.is_file():
        raise RunDirectoryError(
            f"{run.dem_dumps}: no particle snapshot (snap.*.txt or .npz) and no {path.name} in "
            f"{run.post}: the closures need the run's snapshots (shipped results keep the "
            "closures `drumflow post` measured instead): give the run directory itself, or a "
            "closures JSON file saved from it with --save-closures")
    closures = load_closures(path)
    if start_s is not None and (closures.start_s is None or abs(closures.start_s - start_s) > 1e-9):
        recorded = "an unrecorded time" if closures.start_s is None else f"{closures.start_s:g} s"
        raise RunDirectoryError(
            f"--start = {start_s:g} s: {run.root} keeps no snapshots, only the closures in "
            f"{path} measured from {recorded}; leave --start out to use them, or give the run "
            "directory with its snapshots")
    return closures
