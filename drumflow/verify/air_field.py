"""Checks on the OpenFOAM air field.

* Bookkeeping: inlet against outlet mass flow, and the volume-mean axial velocity against
  Q / A. A finite-volume solution conserves mass by construction and any mass-conserving field
  has that mean, so these catch a broken set-up (a wrong patch, a unit slip), not wrong flow.
* Reference: the pressure gradient of a drum without lifters (a pipe) against the smooth-pipe
  friction factor of Petukhov at the same Reynolds number, over the downstream part where the
  flow has developed.
* Decomposition: the air field sampled on radial lines (axial velocity and swirl) from a
  serial and a decomposed solution of the same case must agree to the iteration error the
  residual target leaves (:func:`sampled_profiles`, :func:`profile_difference`); the bulk
  numbers above would agree for any two mass-conserving fields.
"""

from __future__ import annotations

import math
import time
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from drumflow.physics.validation import relative_error
from drumflow.runner import Runner
from drumflow.verify.checks import Check
from drumflow.verify.references import ReferenceAir, petukhov_friction_factor
from drumflow.verify.scenes import tiny_drum

if TYPE_CHECKING:
    from drumflow.air.field import AirField
    from drumflow.case import Case

#: Mass flow in against out: the SIMPLE solution converged to its residual target (1e-4 by
#: default) leaves continuity errors of that order; 0.5% is what the stage itself asks.
MASS_TOLERANCE = 0.005


def air_field_checks(work: Path, runner: Runner) -> list[Check]:
    """OpenFOAM on the tiny drum: mass flow in = out and the bulk axial velocity (bookkeeping)."""
    from drumflow.air.foam import solve_air

    t0 = time.perf_counter()
    case = tiny_drum(air__model="cfd", air__mass_flow=0.1, air__mesh_size=0.02)
    sol = solve_air(case, work, runner)
    wall = time.perf_counter() - t0
    note = f"tiny drum, {sol.mesh.get('cells')} cells, {sol.iterations} SIMPLE iterations"
    return [
        Check(
            name="air_mass_flow_in_equals_out",
            measured=sol.outlet_mass_flow,
            expected=sol.inlet_mass_flow,
            error=relative_error(sol.outlet_mass_flow, sol.inlet_mass_flow),
            tolerance=MASS_TOLERANCE,
            unit="kg/s",
            note="finite volumes conserve mass to the residual target; " + note,
            kind="bookkeeping",
            reference="the solution's own inlet flux",
            wall_time_s=wall,
        ),
        Check(
            name="air_mean_axial_velocity",
            measured=sol.mean_axial_velocity,
            expected=sol.expected_axial_velocity,
            error=relative_error(sol.mean_axial_velocity, sol.expected_axial_velocity),
            tolerance=0.01,
            unit="m/s",
            kind="bookkeeping",
            note="volume-mean axial velocity through the free cross-section against "
            "mdot / (rho A_free), which any mass-conserving field meets; " + note,
            reference="mdot / (rho A_free)",
            wall_time_s=wall,
        ),
    ]


#: The pipe scene: the tiny drum's 0.2 m shell without lifters, 6 diameters long, air at
#: 0.1 kg/s (bulk 2.7 m/s, Re ~ 3.4e4), turning at 1 rpm (wall speed 0.01 m/s, 0.4% of the
#: bulk velocity: a pipe). The first-cell y+ of a 0.025 m mesh is ~100, inside the log layer
#: the wall functions assume.
PIPE_LENGTH = 1.2
PIPE_MESH = 0.025
PIPE_MASS_FLOW = 0.1
#: Where the gradient is fitted, as fractions of the length from the outlet (z = 0): the air
#: enters at z = L, so this is 3-5.4 diameters downstream of the inlet, and stays one cell
#: layer clear of the outlet.
PIPE_WINDOW = (0.1, 0.5)
#: Realizable k-epsilon with standard wall functions reproduces developed smooth-pipe
#: friction within about 10%; the coarse tetrahedral mesh (8 cells across) and a flow only
#: 3-5 diameters from a plug inlet (the turbulent entrance length is 10-40 D) add some
#: percent more. 15% still fails a laminar or unit-slipped solution by a factor.
PIPE_TOLERANCE = 0.15


def pipe_pressure_gradient(z: np.ndarray, p: np.ndarray, volume: np.ndarray, lo: float, hi: float) -> float:
    """-dp/dz, Pa/m, of a volume-weighted straight-line fit of p(z) over lo < z < hi."""
    m = (z > lo) & (z < hi)
    w = np.sqrt(volume[m])
    design = np.column_stack([np.ones(int(m.sum())), z[m]]) * w[:, None]
    coef = np.linalg.lstsq(design, p[m] * w, rcond=None)[0]
    # The air flows towards -z, so the pressure rises with z.
    return float(coef[1])


def pipe_friction_check(work: Path, runner: Runner) -> Check:
    """A drum without lifters: the CFD's pressure gradient against Petukhov's friction factor."""
    from drumflow.air.foam import read_cell_fields, solve_air

    t0 = time.perf_counter()
    case = tiny_drum(
        lifters__count=0,
        drum__length=PIPE_LENGTH,
        drum__rpm=1.0,
        air__model="cfd",
        air__mass_flow=PIPE_MASS_FLOW,
        air__mesh_size=PIPE_MESH,
    )
    sol = solve_air(case, work, runner, timeout=1200)
    cells = read_cell_fields(sol.case_dir, sol.time_dir)
    gradient = pipe_pressure_gradient(
        cells["C"][:, 2],
        cells["p"] * sol.density,
        cells["V"],
        PIPE_WINDOW[0] * PIPE_LENGTH,
        PIPE_WINDOW[1] * PIPE_LENGTH,
    )
    air = ReferenceAir.at(case.air.inlet_temperature_C, case.air.pressure_kPa)
    diameter = case.drum.diameter
    bulk = case.air.mass_flow / (air.density * math.pi / 4.0 * diameter**2)
    re = air.density * bulk * diameter / air.viscosity
    f = petukhov_friction_factor(re)
    expected = f * air.density * bulk**2 / (2.0 * diameter)
    return Check(
        name="pipe_friction_pressure_gradient",
        measured=gradient,
        expected=expected,
        error=relative_error(gradient, expected),
        tolerance=PIPE_TOLERANCE,
        unit="Pa/m",
        note=f"0.2 m drum without lifters, {PIPE_LENGTH:g} m long, {case.air.mass_flow:g} kg/s "
        f"(Re = {re:.3g}), {sol.mesh.get('cells')} cells, {sol.turbulence}; -dp/dz fitted "
        f"over {PIPE_WINDOW[0] * PIPE_LENGTH:g}-{PIPE_WINDOW[1] * PIPE_LENGTH:g} m from the outlet",
        reference="Petukhov (1970) smooth-pipe friction factor (Incropera Eq. 8.21), CoolProp air",
        wall_time_s=time.perf_counter() - t0,
        details={
            "reynolds": re,
            "friction_factor": f,
            "bulk_velocity_m_s": bulk,
            "friction_factor_cfd": gradient * 2.0 * diameter / (air.density * bulk**2),
        },
    )


#: Two converged SIMPLE solutions of one case on different decompositions differ by their
#: iteration errors. The run stops when every normalised initial residual is below the
#: residual target (1e-4); with the outer iteration contracting at a rate rho of about 0.99
#: per iteration (under-relaxed SIMPLE), the remaining error is about residual / (1 - rho),
#: i.e. ~1% of the velocity scale. So the RMS difference of the sampled velocity may be 1% of
#: the mean speed; single points in slowly converging recirculation behind the lifters may
#: differ by a few times that, so the largest difference may be 5%. A field from a wrong
#: decomposition (a processor patch not coupled, a swirl lost on one rank) misses these by far.
PROFILE_RMS_TOLERANCE = 0.01
PROFILE_MAX_TOLERANCE = 0.05


def sampled_profiles(
    field: AirField,
    case: Case,
    radii: int = 12,
    angles: int = 24,
    planes: tuple[float, ...] = (0.25, 0.5, 0.75),
) -> dict[str, np.ndarray]:
    """The air field on radial lines of a few cross-sections, in the drum frame.

    Parameters
    ----------
    field
        The air field (drum-frame grid).
    case
        Its case (drum radius and length, the lifters that take points out of the air).
    radii, angles
        Points per radial line (from 0.1 R to 0.95 R) and radial lines per cross-section.
    planes
        Cross-sections as fractions of the drum length.

    Returns
    -------
    dict
        ``points`` (n, 3), m; ``velocity`` (n, 3), m/s; ``axial`` (-u_z, the air's direction)
        and ``swirl`` (u_theta, counter-clockwise about +z), m/s; points inside the lifters
        are left out.
    """
    from drumflow.air.field_grid import fluid_mask_xy

    R, L = case.drum.radius, case.drum.length
    r, theta, z = np.meshgrid(
        np.linspace(0.1 * R, 0.95 * R, radii),
        np.linspace(0.0, 2.0 * np.pi, angles, endpoint=False),
        np.asarray(planes) * L,
        indexing="ij",
    )
    x, y = r * np.cos(theta), r * np.sin(theta)
    keep = fluid_mask_xy(case, x, y)
    points = np.column_stack([x[keep], y[keep], z[keep]])
    u = field.sample(points)
    th = theta[keep]
    return {
        "points": points,
        "velocity": u,
        "axial": -u[:, 2],
        "swirl": -np.sin(th) * u[:, 0] + np.cos(th) * u[:, 1],
    }


def profile_difference(a: dict[str, np.ndarray], b: dict[str, np.ndarray]) -> dict[str, float]:
    """Largest and RMS differences of two :func:`sampled_profiles`, relative to ``a``'s mean speed.

    Returns
    -------
    dict
        ``mean_speed_m_s``; ``velocity_max``/``velocity_rms`` (the vector difference),
        ``axial_max``/``axial_rms`` and ``swirl_max``/``swirl_rms``, each divided by the mean
        speed.
    """
    if a["points"].shape != b["points"].shape or not np.allclose(a["points"], b["points"]):
        raise ValueError("the profiles were sampled at different points")
    speed = float(np.linalg.norm(a["velocity"], axis=1).mean())
    out = {"mean_speed_m_s": speed}
    diffs = {
        "velocity": np.linalg.norm(a["velocity"] - b["velocity"], axis=1),
        "axial": np.abs(a["axial"] - b["axial"]),
        "swirl": np.abs(a["swirl"] - b["swirl"]),
    }
    for name, d in diffs.items():
        out[f"{name}_max"] = float(d.max()) / speed
        out[f"{name}_rms"] = float(np.sqrt(np.mean(d**2))) / speed
    return out
