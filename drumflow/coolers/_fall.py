"""A particle's fall from a flight through the drum's air: time, speed and mean film coefficient.

The fall is vertical from rest, with gravity and the Schiller-Naumann drag of the vertical
slip (the slice coupling's drag law, :func:`drumflow.physics.particle_air.schiller_naumann_cd`);
the axial air does not change the vertical motion (it is a small share of the slip in a
cooler: 3 m/s axial against several m/s of fall). The film coefficient along the fall is
Ranz-Marshall on the full slip ``sqrt(v(t)^2 + U^2)`` with ``U`` the axial air speed, and the
curtain model needs its time average, which :func:`fall_kinematics` returns as the slip speed
that gives it (Ranz-Marshall is affine in the square root of the slip).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.integrate import solve_ivp

from drumflow.physics.particle_air import AirState, schiller_naumann_cd

G = 9.81


@dataclass(frozen=True)
class Fall:
    """One fall of height ``height_m``: its duration, mean speeds and effective slip."""

    height_m: float
    time_s: float
    mean_speed_m_s: float
    end_speed_m_s: float
    effective_slip_m_s: float


def fall_kinematics(height_m: float, diameter_m: float, density_kg_m3: float, air: AirState,
                    axial_air_m_s: float) -> Fall:
    """Integrate a fall from rest through ``height_m`` (module notes)."""
    if not (height_m > 0 and diameter_m > 0):
        raise ValueError(f"fall height {height_m!r} m and diameter {diameter_m!r} m must be > 0")
    drag_factor = 3.0 * air.density / (4.0 * density_kg_m3 * diameter_m)

    def rhs(_t: float, state: np.ndarray) -> list[float]:
        v = state[1]
        re = air.density * abs(v) * diameter_m / air.viscosity
        cd = float(schiller_naumann_cd(max(re, 1e-12)))
        accel = G - drag_factor * cd * v * abs(v)
        rms = math.sqrt(math.sqrt(v * v + axial_air_m_s**2))
        return [v, accel, rms]

    def landed(_t: float, state: np.ndarray) -> float:
        return float(state[0] - height_m)

    landed.terminal = True  # type: ignore[attr-defined]
    horizon = 10.0 * math.sqrt(2.0 * height_m / G) + 10.0
    sol = solve_ivp(rhs, (0.0, horizon), [0.0, 0.0, 0.0], events=landed, rtol=1e-9, atol=1e-12,
                    max_step=horizon / 200)
    if not sol.t_events[0].size:
        raise ValueError(f"fall of {height_m} m did not end within {horizon:.3g} s")
    t = float(sol.t_events[0][0])
    end = sol.y_events[0][0]
    mean_root = end[2] / t
    return Fall(height_m=height_m, time_s=t, mean_speed_m_s=height_m / t,
                end_speed_m_s=float(end[1]), effective_slip_m_s=mean_root**2)
