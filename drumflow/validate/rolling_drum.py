"""The rolling drum of Alizadeh et al. (2013), measured by radioactive particle tracking.

Glass beads of 3 mm (2500 kg/m³) in a horizontal drum of radius 0.12 m and length 0.36 m at
11.6 rpm, about a third full. Measured: the velocity parallel to the free surface along the line
through the axis normal to it (``data/alizadeh2013_rpt_velocity.csv``, digitised by the Lethe
project; ``data/README.md``). Compared: the surface velocity, the depth of the flowing layer
(where the velocity changes sign) and the velocity near the wall.

Every set-up choice is written down in :data:`SETUP` before any comparison, with its source, and
is never tuned against the measurement.

Geometry of the comparison, in drumflow's drum coordinates (axis on z, the drum turning
counter-clockwise seen from +z, gravity along -y): the bed rises on the +x side, so its free
surface climbs towards +x at the angle ``SURFACE_ANGLE_DEG``. The unit vector down the slope is
``(-cos a, -sin a)``; the upward normal ``(-sin a, cos a)``. A point of the normal line through
the axis is ``s`` times the normal (``s < 0`` below the axis); solid-body rotation moves it at
``omega * s`` down the slope, so the return flow near the shell is negative.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from importlib import resources
from pathlib import Path
from typing import TYPE_CHECKING, Any, Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

from drumflow.validate.errors import ValidationDataError

if TYPE_CHECKING:
    from drumflow.case import Case
    from drumflow.dem.stage import ProgressCallback

#: Scales of the scene: "small" a thin periodic section that runs in minutes (a check of the
#: chain, not the comparison), "section" the affordable comparison (periodic section of
#: SECTION_DIAMETERS diameters), "full" the whole drum with its end walls (the check that the
#: section stands for the middle of the drum).
Scale = Literal["small", "section", "full"]
SCALES: tuple[str, ...] = ("small", "section", "full")

# -- the experiment (Alizadeh et al. 2013; Lethe example examples/dem/3d-rotating-drum) --------
DRUM_RADIUS = 0.12  # m
DRUM_LENGTH = 0.36  # m (Lethe: subdivided_cylinder of half-length 0.18 m)
RPM = 11.6  # 1/min: 1.2147 rad/s (the Lethe post-processing's omega r line)
BEAD_DIAMETER = 0.003  # m
BEAD_DENSITY = 2500.0  # kg/m³
#: Beads in the whole drum (Lethe set-up): about a third full.
FULL_DRUM_BEADS = 226_080
#: The free surface's angle to the horizontal (the paper's value, which the Lethe
#: post-processing fixes) and its signed distance from the axis along the upward normal.
SURFACE_ANGLE_DEG = 27.0
SURFACE_POSITION = -0.03  # m
#: Averaging zone around each point of the line: particles within one bead diameter of it in
#: the cross-section (as the Lethe post-processing), at every axial position of the measured zone.
AVERAGING_RADIUS = BEAD_DIAMETER
#: The whole drum: only the middle |z - L/2| < 0.10 m counts (the Lethe post-processing's
#: cut-off, 0.08 m clear of each end wall).
MIDDLE_HALF_WIDTH = 0.10  # m
#: Points of the simulated profile: from the shell to the surface line.
LINE_POINTS = 100

#: Section lengths in bead diameters (periodic ends). 4 is the shortest section a case allows
#: (particles.diameter at most a quarter of drum.length); 10 is one flowing-layer depth of the
#: experiment (the velocity changes sign about 0.029 m = 9.8 diameters below the surface), so
#: that the layer's largest structures fit the period.
SECTION_DIAMETERS = {"small": 4, "section": 10}
#: Simulated time and the start of the averaging window, s: the bed first turns as a solid
#: until it passes its angle of repose (about 0.4 s at 1.21 rad/s), then settles into rolling;
#: "small" averages its last second, the others the second half of a 6 s run (half a turn).
TIMES = {"small": (2.0, 1.0), "section": (6.0, 3.0), "full": (6.0, 3.0)}
#: Time between the snapshots that are averaged, s.
SNAPSHOT_INTERVAL = {"small": 0.05, "section": 0.05, "full": 0.1}

#: Agreement bands, fixed before any comparison (no uncertainty is given with the digitised
#: points): surface velocity within 20 % (DEM-against-RPT comparisons of rolling drums typically
#: agree to 10-20 % at the surface), the zero crossing of the velocity within two bead
#: diameters, the velocity near the wall within 15 % (it is close to the shell's omega r).
BANDS = {"surface_velocity_m_s": ("relative", 0.20),
         "zero_crossing_position_m": ("absolute", 2 * BEAD_DIAMETER),
         "near_wall_velocity_m_s": ("relative", 0.15)}


@dataclass(frozen=True)
class SetupChoice:
    """One set-up value of a validation scene and where it comes from."""

    item: str
    value: str
    source: str


#: The scene's set-up, written down before any comparison.
SETUP: tuple[SetupChoice, ...] = (
    SetupChoice("drum radius, length", "0.12 m, 0.36 m", "Alizadeh et al. 2013; Lethe example "
                "(subdivided_cylinder 0.12:0.18)"),
    SetupChoice("rotation", "11.6 rpm (1.2147 rad/s), horizontal axis (tilt 0)",
                "Alizadeh et al. 2013; Lethe post-processing omega r = 1.2147 rad/s"),
    SetupChoice("beads", "3 mm glass, 2500 kg/m³, monodisperse", "Alizadeh et al. 2013; Lethe example"),
    SetupChoice("fill", f"{FULL_DRUM_BEADS:,} beads in the whole drum (about a third full); a "
                "section holds the same beads per metre", "Lethe example (number = 226080)"),
    SetupChoice("Young's modulus, Poisson's ratio", "1e7 Pa (particles and walls), 0.24",
                "Lethe example (a softened glass, as DEM practice; not tuned here)"),
    SetupChoice("restitution", "0.97 particle-particle, 0.85 particle-wall", "Lethe example"),
    SetupChoice("friction", "0.3 particle-particle, 0.35 particle-wall", "Lethe example"),
    SetupChoice("rolling friction", "0 (none)", "not given by the paper; the Lethe example sets "
                "none, and smooth glass spheres roll freely; not tuned"),
    SetupChoice("air", "none", "the experiment is in air at rest; 3 mm glass beads at < 0.5 m/s "
                "feel no drag worth modelling"),
    SetupChoice("time step", "drumflow 'auto'", "drumflow.dem.timestep"),
    SetupChoice("initial bed", "a loose random packing (particles.placement = 'random': random "
                "sequential addition at solids fraction 0.3, drumflow.dem.placement) settling as "
                "the drum turns from t = 0",
                "the experiment's beads are poured, not stacked, and drumflow's default lattice is "
                "a crystal of equal spheres; changed before any comparison, not toward the "
                "measurement. (The small slice surged as a block from the lattice and again from "
                "this bed: not the cause; see the validation page)"),
    SetupChoice("end walls", "'small' and 'section': periodic section of 4 and 10 diameters; "
                "'full': end walls turning with the shell (drum.ends = 'rotating'), averaged "
                "over the middle |z - L/2| < 0.10 m", "a lab drum's end plates are fixed to its "
                "shell (assumed; the paper's drum is closed at both ends); the cut-off is the "
                "Lethe post-processing's"),
    SetupChoice("free surface", f"{SURFACE_ANGLE_DEG:g} degrees to the horizontal, "
                f"{-SURFACE_POSITION:g} m from the axis", "Alizadeh et al. 2013 (the Lethe "
                "post-processing fixes the same line)"),
    SetupChoice("averaging", f"particles within {AVERAGING_RADIUS * 1e3:g} mm of each of "
                f"{LINE_POINTS} points of the normal line (cross-section distance, all axial "
                "positions of the measured zone), pooled over the snapshots of the averaging window",
                "Lethe post-processing (distance D = 3 mm)"),
    SetupChoice("averaging window", "small: 1-2 s; section, full: 3-6 s, snapshots every "
                "0.05 s (full: 0.1 s)", "after the bed has settled into rolling"),
    SetupChoice("metrics", "surface velocity = largest velocity of the profile; zero crossing = "
                "first sign change below the surface (linear between points); near-wall "
                "velocity = velocity at the deepest measured point (-0.113 m)", "the issue's three "
                "observables"),
    SetupChoice("agreement bands", "surface velocity 20 %, zero crossing 2 diameters (6 mm), "
                "near-wall velocity 15 %", "fixed before comparing; no uncertainty is given "
                "with the digitised points"),
)


# -- the measured points -------------------------------------------------------------------------


@dataclass(frozen=True)
class Profile:
    """A velocity profile along the normal line: positions (m, negative below the axis, from the
    surface downwards or in any order) and the velocity down the slope (m/s)."""

    position: NDArray[np.float64]
    velocity: NDArray[np.float64]


MEASURED_FILE = "alizadeh2013_rpt_velocity.csv"


def load_measured(path: Path | None = None) -> Profile:
    """The measured profile (``data/alizadeh2013_rpt_velocity.csv``, SI units, down-slope
    velocity positive).

    Raises
    ------
    ValidationDataError
        The file is missing, or is not two columns of finite numbers with the header
        ``normal_position_m,velocity_m_s``.
    """
    if path is None:
        text = resources.files("drumflow.validate").joinpath("data").joinpath(MEASURED_FILE).read_text()
        where = f"drumflow/validate/data/{MEASURED_FILE}"
    else:
        if not path.is_file():
            raise ValidationDataError(f"{path}: not found")
        text = path.read_text()
        where = str(path)
    lines = [ln for ln in text.splitlines() if ln.strip() and not ln.startswith("#")]
    if not lines or lines[0].replace(" ", "") != "normal_position_m,velocity_m_s":
        raise ValidationDataError(f"{where}: header must be 'normal_position_m,velocity_m_s'")
    try:
        table = np.array([[float(v) for v in ln.split(",")] for ln in lines[1:]], dtype=np.float64)
    except ValueError as exc:
        raise ValidationDataError(f"{where}: not a table of numbers ({exc})") from None
    if table.ndim != 2 or table.shape[1] != 2 or len(table) < 3 or not np.isfinite(table).all():
        raise ValidationDataError(f"{where}: expected at least 3 rows of 2 finite numbers")
    return Profile(table[:, 0], table[:, 1])


# -- the profile along the normal line -------------------------------------------------------------


def surface_frame(angle_deg: float) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Unit vectors in the cross-section (x, y): down the slope, and the upward normal."""
    a = math.radians(angle_deg)
    return np.array([-math.cos(a), -math.sin(a)]), np.array([-math.sin(a), math.cos(a)])


def line_positions(n: int = LINE_POINTS) -> NDArray[np.float64]:
    """The points of the simulated profile: from the shell up to the surface line, m."""
    return np.linspace(-DRUM_RADIUS, SURFACE_POSITION, n)


def profile_along_normal(x: ArrayLike, y: ArrayLike, vx: ArrayLike, vy: ArrayLike,
                         positions: ArrayLike, angle_deg: float = SURFACE_ANGLE_DEG,
                         radius: float = AVERAGING_RADIUS) -> tuple[NDArray[np.float64], NDArray[np.int64]]:
    """The mean velocity down the slope at each point of the normal line through the axis.

    Parameters
    ----------
    x, y, vx, vy
        Particle positions (m) and velocities (m/s) in the cross-section, any shape (e.g.
        snapshots by particles, all pooled); NaN entries (a lost particle) are left out.
    positions
        Points of the line, signed distance from the axis along the upward normal, m.
    angle_deg
        The free surface's angle to the horizontal, degrees (rising towards +x).
    radius
        Particles within this distance of a point (in the cross-section) are averaged.

    Returns
    -------
    velocity, count
        Mean down-slope velocity at each point (NaN where no particle was near) and the number
        of particle samples averaged.
    """
    xs, ys = (np.asarray(a, dtype=np.float64).ravel() for a in (x, y))
    us, vs = (np.asarray(a, dtype=np.float64).ravel() for a in (vx, vy))
    keep = np.isfinite(xs) & np.isfinite(ys) & np.isfinite(us) & np.isfinite(vs)
    xs, ys, us, vs = xs[keep], ys[keep], us[keep], vs[keep]
    along, normal = surface_frame(angle_deg)
    # Coordinates in the surface frame: distance along the slope from the normal line, and
    # the signed position along the normal.
    p_along = xs * along[0] + ys * along[1]
    p_normal = xs * normal[0] + ys * normal[1]
    u = us * along[0] + vs * along[1]
    pts = np.asarray(positions, dtype=np.float64)
    velocity = np.full(pts.shape, np.nan)
    count = np.zeros(pts.shape, dtype=np.int64)
    near_line = np.abs(p_along) < radius
    p_along, p_normal, u = p_along[near_line], p_normal[near_line], u[near_line]
    for i, s in enumerate(pts):
        hit = p_along**2 + (p_normal - s) ** 2 < radius**2
        count[i] = int(hit.sum())
        if count[i]:
            velocity[i] = float(u[hit].mean())
    return velocity, count


def zero_crossing(profile: Profile) -> float:
    """The first position below the surface where the velocity changes sign (linear between
    the two points around it), m; NaN if it never does."""
    order = np.argsort(-profile.position)  # from the surface down
    s, u = profile.position[order], profile.velocity[order]
    ok = np.isfinite(u)
    s, u = s[ok], u[ok]
    for i in range(len(u) - 1):
        if u[i] > 0 >= u[i + 1]:
            return float(s[i] + u[i] / (u[i] - u[i + 1]) * (s[i + 1] - s[i]))
    return float("nan")


def value_at(profile: Profile, position: float) -> float:
    """The profile's velocity at ``position`` (linear between points), NaN outside it."""
    ok = np.isfinite(profile.velocity)
    s, u = profile.position[ok], profile.velocity[ok]
    if len(s) < 2 or not (s.min() <= position <= s.max()):
        return float("nan")
    order = np.argsort(s)
    return float(np.interp(position, s[order], u[order]))


def metrics(profile: Profile, near_wall_position: float) -> dict[str, float]:
    """The three observables of a profile: surface velocity (its largest velocity), the zero
    crossing, and the velocity at ``near_wall_position``."""
    u = profile.velocity[np.isfinite(profile.velocity)]
    return {
        "surface_velocity_m_s": float(u.max()) if len(u) else float("nan"),
        "zero_crossing_position_m": zero_crossing(profile),
        "near_wall_velocity_m_s": value_at(profile, near_wall_position),
    }


def compare(simulated: Profile, measured: Profile) -> dict[str, dict[str, Any]]:
    """Each observable, simulated against measured, with its error and agreement band."""
    wall = float(measured.position.min())
    sim, exp = metrics(simulated, wall), metrics(measured, wall)
    out: dict[str, dict[str, Any]] = {}
    for name, (kind, band) in BANDS.items():
        s, e = sim[name], exp[name]
        error = (s - e) / abs(e) if kind == "relative" else s - e
        out[name] = {"simulated": s, "measured": e, "error": error,
                     "error_kind": kind, "band": band,
                     "within_band": bool(np.isfinite(error) and abs(error) <= band)}
    out["zero_crossing_position_m"]["depth_below_surface_m"] = {
        "simulated": SURFACE_POSITION - sim["zero_crossing_position_m"],
        "measured": SURFACE_POSITION - exp["zero_crossing_position_m"]}
    out["near_wall_velocity_m_s"]["position_m"] = wall
    out["near_wall_velocity_m_s"]["solid_body_m_s"] = 2 * math.pi * RPM / 60 * wall
    return out


def surface_angle(x: ArrayLike, y: ArrayLike, bins: int = 12) -> float:
    """The free surface's angle to the horizontal, degrees, from the highest particle in each
    of ``bins`` columns across the middle 1.2 radii of the drum (a diagnostic: the comparison
    line stays the paper's); NaN with too few columns."""
    xs, ys = np.asarray(x, dtype=np.float64).ravel(), np.asarray(y, dtype=np.float64).ravel()
    ok = np.isfinite(xs) & np.isfinite(ys)
    xs, ys = xs[ok], ys[ok]
    edges = np.linspace(-0.6 * DRUM_RADIUS, 0.6 * DRUM_RADIUS, bins + 1)
    cx, top = [], []
    for lo, hi in zip(edges[:-1], edges[1:], strict=True):
        inside = (xs >= lo) & (xs < hi)
        if inside.sum() >= 3:
            cx.append(0.5 * (lo + hi))
            top.append(float(np.quantile(ys[inside], 0.98)))
    if len(cx) < 4:
        return float("nan")
    slope = np.polyfit(cx, top, 1)[0]
    return math.degrees(math.atan(slope))


# -- the case ----------------------------------------------------------------------------------------


def section_length(scale: str) -> float:
    """The simulated length along the axis, m."""
    if scale == "full":
        return DRUM_LENGTH
    return SECTION_DIAMETERS[scale] * BEAD_DIAMETER


def rolling_drum_case(scale: str = "small") -> Case:
    """The scene's drumflow case at ``scale`` ("small", "section" or "full"), from :data:`SETUP`.

    Raises
    ------
    ValidationDataError
        An unknown scale (naming the allowed ones).
    """
    from drumflow.case import case_from_dict

    if scale not in SCALES:
        raise ValidationDataError(f"scale = {scale!r}: unknown; allowed: {', '.join(SCALES)}")
    length = section_length(scale)
    beads = round(FULL_DRUM_BEADS * length / DRUM_LENGTH)
    time, _ = TIMES[scale]
    contact = {"restitution": 0.97, "friction": 0.3, "rolling_friction": 0.0}
    data: dict[str, Any] = {
        "name": f"rolling_drum_alizadeh2013_{scale}",
        "description": "Alizadeh et al. 2013 rolling drum (RPT): 3 mm glass beads, R = 0.12 m, "
                       f"11.6 rpm, {beads:,} beads in {length:g} m",
        "drum": {"diameter": 2 * DRUM_RADIUS, "length": length, "tilt_deg": 0.0, "rpm": RPM,
                 "ends": "rotating" if scale == "full" else "periodic"},
        # A plain cylinder: no lifters (the profile's plates are placeholders the case needs).
        "lifters": {"count": 0, "profile": "straight", "base_height": 0.01, "lip_length": 0.0,
                    "thickness": 0.002},
        "particles": {"diameter": BEAD_DIAMETER, "density": BEAD_DENSITY, "youngs_modulus": 1.0e7,
                      "poisson_ratio": 0.24, "heat_capacity": 840.0, "conductivity": 1.0,
                      "count": beads, "initial_temperature_C": 20.0, "placement": "random"},
        "contacts": {"particle_particle": contact,
                     "particle_wall": {"restitution": 0.85, "friction": 0.35, "rolling_friction": 0.0},
                     "wall_youngs_modulus": 1.0e7},
        "air": {"model": "none"},
        "run": {"time": time, "dump_interval": 0.01, "snapshot_interval": SNAPSHOT_INTERVAL[scale],
                "mass_flow_start": TIMES[scale][1], "restart_interval": 0.5,
                "conduction": False},
    }
    return case_from_dict(data)


@dataclass(frozen=True)
class RollingDrumResult:
    """The simulated profile, the comparison and what the run was."""

    simulated: Profile
    counts: NDArray[np.int64]
    measured: Profile
    comparison: dict[str, dict[str, Any]]
    surface_angle_deg: float
    snapshots_averaged: int
    window_s: tuple[float, float]
    run_dir: Path
    case: Case


#: What :func:`profile_from_run` returns: the profile, the samples per point, the surface angle
#: (degrees), the snapshots averaged and the averaging window (s).
RunProfile = tuple[Profile, NDArray[np.int64], float, int, tuple[float, float]]


def profile_from_run(run_dir: Path, case: Case, start: float,
                     middle_half_width: float | None = None) -> RunProfile:
    """The simulated profile from a finished run's snapshots at ``t >= start``.

    ``middle_half_width``: only particles with ``|z - L/2|`` below it count (the whole drum).
    Returns the profile, the samples per point, the surface angle, the snapshots used and the
    averaging window.

    Raises
    ------
    ValidationDataError
        No snapshot in the window.
    """
    from drumflow.dem.dumps import read_series
    from drumflow.rundir import RunDir

    rundir = RunDir.existing(run_dir)
    ts = float(rundir.manifest["time_step"]["time_step"])
    series = read_series(rundir.dem_dumps, ts, columns=("x", "y", "z", "vx", "vy"))
    use = series.times >= start - 1e-9
    if not use.any():
        raise ValidationDataError(f"{run_dir}: no snapshot at t >= {start:g} s "
                                  f"(last at {series.times[-1]:.3g} s)")
    x, y, z = series["x"][use], series["y"][use], series["z"][use]
    vx, vy = series["vx"][use], series["vy"][use]
    if middle_half_width is not None:
        outside = np.abs(z - 0.5 * case.drum.length) >= middle_half_width
        x = np.where(outside, np.nan, x)
    pos = line_positions()
    u, counts = profile_along_normal(x, y, vx, vy, pos)
    window = (float(series.times[use][0]), float(series.times[use][-1]))
    return Profile(pos, u), counts, surface_angle(x, y), int(use.sum()), window


def run_rolling_drum(out: Path, scale: str = "small", timeout: float | None = None,
                     progress: ProgressCallback | None = None) -> RollingDrumResult:
    """Run the scene at ``scale`` into ``out/<case name>`` (or reuse a finished run) and compare.

    Raises
    ------
    ValidationDataError
        An unknown scale, or a run without snapshots in the averaging window.
    SolverError
        LIGGGHTS failed.
    """
    from drumflow.pipeline import run_case

    case = rolling_drum_case(scale)
    run_dir = Path(out) / case.name
    run_case(case, run_dir, timeout=timeout, progress=progress)
    _, start = TIMES[scale]
    middle = MIDDLE_HALF_WIDTH if scale == "full" else None
    simulated, counts, angle, n, window = profile_from_run(run_dir, case, start, middle)
    measured = load_measured()
    return RollingDrumResult(simulated, counts, measured, compare(simulated, measured), angle, n,
                             window, run_dir, case)
