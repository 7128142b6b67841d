"""The paper's two headline observables from particle dumps.

* Falling mass flow (Section 3.3, Eq. 57): particles crossing the horizontal plane through the
  drum axis (y = 0) downwards, counted after the first second; the mass flow is the particle
  mass times the count over the time between the first and last crossing in the window.
* Mean particle temperature against time (Figures 7 and 8), mass-weighted.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import pandas as pd
from numpy.typing import NDArray


def crossings_from_rows(
    times: NDArray[np.float64],
    frame: NDArray[np.int64],
    ids: NDArray[np.int64],
    x: NDArray[np.float64],
    y: NDArray[np.float64],
    z: NDArray[np.float64],
    plane_y: float = 0.0,
) -> pd.DataFrame:
    """Downward crossings of the plane y = ``plane_y`` between consecutive dumps.

    Parameters
    ----------
    times
        Dump times, shape (n_t,).
    frame, ids, x, y, z
        One row per particle per dump (the dump number, the particle id, its position);
        particles may be missing from some dumps (the crossing dump keeps only a band
        around the plane).

    Returns
    -------
    pandas.DataFrame
        One row per crossing: ``time`` (linear interpolation between the two dumps), ``id``,
        ``x`` and ``z`` at the crossing, sorted by time: the paper's crossing table (Figure 4).

    Notes
    -----
    A crossing counts only between two consecutive dumps that both hold the particle, above
    the plane in the first and on or below it in the second. A particle that crosses down and
    back up within one dump interval is not seen; falling particles cross once.
    """
    order = np.lexsort((frame, ids))
    f, i = frame[order], ids[order]
    yy, xx, zz = y[order] - plane_y, x[order], z[order]
    nxt = slice(1, None)
    cur = slice(None, -1)
    hit = (i[cur] == i[nxt]) & (f[nxt] == f[cur] + 1) & (yy[cur] > 0.0) & (yy[nxt] <= 0.0)
    k = np.nonzero(hit)[0]
    frac = yy[k] / (yy[k] - yy[k + 1])
    t0, t1 = times[f[k]], times[f[k + 1]]
    table = pd.DataFrame(
        {
            "time": t0 + frac * (t1 - t0),
            "id": i[k],
            "x": xx[k] + frac * (xx[k + 1] - xx[k]),
            "z": zz[k] + frac * (zz[k + 1] - zz[k]),
        }
    )
    return table.sort_values("time", kind="stable").reset_index(drop=True)


def find_crossings(
    times: NDArray[np.float64],
    ids: NDArray[np.int64],
    x: NDArray[np.float64],
    y: NDArray[np.float64],
    z: NDArray[np.float64],
    plane_y: float = 0.0,
) -> pd.DataFrame:
    """:func:`crossings_from_rows` for dense (n_t, n_p) arrays; NaN marks an absent particle."""
    n_t, n_p = y.shape
    present = ~np.isnan(y)
    frame = np.broadcast_to(np.arange(n_t)[:, None], (n_t, n_p))[present]
    pid = np.broadcast_to(ids[None, :], (n_t, n_p))[present]
    return crossings_from_rows(times, frame, pid, x[present], y[present], z[present], plane_y)


@dataclass(frozen=True)
class FallingMassFlow:
    """Falling mass flow by the paper's Eq. 57, with its counting window."""

    mass_flow_kg_s: float
    crossings: int
    window_start_s: float
    window_end_s: float
    particle_mass_kg: float
    curtain_mass_flow_kg_s: float  # crossings away from the wall (lifter tip radius inwards)
    #: Split by contact (the crossing table's ``in_contact``: 0 in free flight, 1 touching
    #: another particle); their sum is ``mass_flow_kg_s`` when every crossing is known, NaN
    #: when none is (a band-dump run, or an older table).
    airborne_mass_flow_kg_s: float = math.nan
    bed_mass_flow_kg_s: float = math.nan

    @property
    def window_s(self) -> float:
        return self.window_end_s - self.window_start_s


def falling_mass_flow(
    crossings: pd.DataFrame,
    particle_mass: float,
    start: float = 1.0,
    curtain_radius: float | None = None,
) -> FallingMassFlow:
    """The paper's falling mass flow (Eq. 57) from a crossing table.

    With an ``in_contact`` column known for every crossing of the window, the flow is also
    split into the airborne part (no particle contact at the crossing) and the bed's.

    Parameters
    ----------
    crossings
        Output of :func:`find_crossings`.
    particle_mass
        Mass of one particle, kg.
    start
        Crossings before this time are ignored (the paper: after the first second, when the
        initially placed particles have settled into the lifters).
    curtain_radius
        If given, also the mass flow of crossings with |x| below it (the falling curtain,
        without particles carried down by the lifters along the wall).

    Returns
    -------
    FallingMassFlow
        Zero mass flow when fewer than two crossings fall in the window (no time frame).
    """
    window = crossings[crossings["time"] >= start]
    n = len(window)
    if n < 2:
        t0 = float(window["time"].iloc[0]) if n else start
        return FallingMassFlow(0.0, n, t0, t0, particle_mass, 0.0)
    t0 = float(window["time"].iloc[0])
    t1 = float(window["time"].iloc[-1])
    span = t1 - t0
    flow = n * particle_mass / span if span > 0 else 0.0
    curtain = flow
    if curtain_radius is not None:
        n_curtain = int((window["x"].abs() < curtain_radius).sum())
        curtain = n_curtain * particle_mass / span if span > 0 else 0.0
    airborne = bed = math.nan
    if "in_contact" in window.columns and span > 0:
        contact = window["in_contact"].to_numpy(float)
        if np.isfinite(contact).all():
            airborne = int((contact == 0).sum()) * particle_mass / span
            bed = int((contact > 0).sum()) * particle_mass / span
    return FallingMassFlow(flow, n, t0, t1, particle_mass, curtain, airborne, bed)


def falling_mass_per_interval(
    crossings: pd.DataFrame, times: NDArray[np.float64], particle_mass: float
) -> NDArray[np.float64]:
    """Mass crossing the plane in each interval between consecutive dump times, kg.

    This is the paper's falling mass per output step (m_mf in Eqs. 35 and 41).
    """
    counts, _ = np.histogram(crossings["time"].to_numpy(), bins=times)
    return counts * particle_mass


def mean_temperature(T: NDArray[np.float64], mass: NDArray[np.float64] | float) -> NDArray[np.float64]:
    """Mass-weighted mean temperature per dump, ignoring absent (NaN) particles.

    Parameters
    ----------
    T
        Temperatures, shape (n_t, n_p).
    mass
        Particle masses, shape (n_p,), or one mass for all.
    """
    m = np.broadcast_to(np.asarray(mass, dtype=float), T.shape[1:])
    w = np.where(np.isnan(T), 0.0, m[None, :])
    return np.nansum(T * w, axis=1) / w.sum(axis=1)


def escaped_particles(
    x: NDArray[np.float64], y: NDArray[np.float64], radius: float, particle_radius: float
) -> int:
    """Particles found outside the shell (leaked through the wall mesh) in any dump."""
    r = np.hypot(x, y)
    outside = r > radius + particle_radius  # a particle touching the shell is still inside
    return int(np.any(outside, axis=0).sum())
