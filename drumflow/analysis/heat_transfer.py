"""Per-time-step heat-transfer coefficient between falling particles and air (Eqs. 34-41).

Method of Burgos-Florez et al., Processes 2019, 7, 673, Section 2.2. For every step
``t -> t + dt`` of a CFD-DEM run the mean particle temperature drop is turned into heat, that
heat is given to the air passing during the step, and the step is treated as a small
counter-current heat exchanger whose area is the surface of the particles falling from the
flights during the step:

=======  =====================================================================================
Eq. 34   ``dT = T(t+dt) - T(t)``  (mean particle temperature change; negative when cooling)
Eq. 35   ``Qm = m_mf * cp_m * (-dT)``  heat given to the air during the step (J)
Eq. 36   ``dTa = Qm / (m_a * cp_a)``  with ``m_a = mdot_a * dt``
Eq. 37   ``Ta = T_ai + dTa``  air temperature leaving the step
Eq. 38   ``LMTD = (dA - dB) / ln(dA / dB)``, ``dA = T(t) - Ta``, ``dB = T(t+dt) - T_ai``
Eq. 40   ``dQ/dt = Qm / dt``  (W)
Eq. 41   ``A_fp = 4 pi (Dp/2)^2 / m_p * m_mf``  with ``m_p = rho pi Dp^3 / 6``
Eq. 39   ``h = (dQ/dt) / (A_fp * LMTD)``
=======  =====================================================================================

Sign convention. The paper writes Eq. 35 as ``m_mf cp_m dT`` and then adds ``Qm / (m_a cp_a)`` to
the air inlet temperature, which only makes sense if ``Qm`` is the heat *given to the air*
(positive when the particles cool). This module uses that reading: ``Qm``, ``dTa``, ``dQ/dt`` and
``h`` are positive for a cooling step. A step in which the mean particle temperature rises
(numerical noise) gives a negative ``h``; it is kept, because the paper averages every step of the
simulated time, and the caller can filter on ``h > 0`` if needed.

Masked steps. ``h`` is set to NaN (and the step marked invalid) when

* ``dT == 0``: no heat was exchanged, the step carries no information on ``h`` (typically a
  repeated output sample), and counting it as ``h = 0`` would bias the mean downwards;
* the log argument of Eq. 38 is zero or negative, i.e. ``dA <= 0`` or ``dB <= 0``: the air would
  leave the step hotter than the particles entering it, or the particles are already at or below
  the air inlet temperature (a temperature cross), and the counter-current model does not apply.

When ``dA == dB`` the LMTD is its limit, the common difference, and the step is valid.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from drumflow.physics.exchanger import log_mean_temperature_difference
from drumflow.physics.validation import (
    AnalysisInputError,
    as_float_array,
    check_finite,
    check_positive,
    check_same_length,
    exactly_one,
    readonly,
)

__all__ = [
    "HeatTransferSteps",
    "falling_particle_area",
    "particle_mass",
    "per_step_heat_transfer",
]



def particle_mass(particle_diameter_m: float, particle_density_kg_m3: float) -> float:
    """Mass of one spherical particle, ``m_p = rho pi Dp^3 / 6`` (kg).

    Parameters
    ----------
    particle_diameter_m
        Particle diameter Dp (m), > 0.
    particle_density_kg_m3
        Particle density rho (kg/m3), > 0.

    Returns
    -------
    float
        m_p (kg).
    """
    d = check_positive("particle_diameter_m", particle_diameter_m)
    rho = check_positive("particle_density_kg_m3", particle_density_kg_m3)
    return rho * math.pi * d**3 / 6.0


def falling_particle_area(
    falling_mass_kg: ArrayLike,
    particle_diameter_m: float,
    particle_density_kg_m3: float,
) -> float | NDArray[np.float64]:
    """Surface of the particles falling during one step, Eq. 41 (m2).

    ``A_fp = 4 pi (Dp/2)^2 / m_p * m_mf``: the number of falling particles ``m_mf / m_p`` times the
    surface of one sphere. (It simplifies to ``6 m_mf / (rho Dp)``; the paper's form is kept for
    traceability.)

    Parameters
    ----------
    falling_mass_kg
        Mass of particles falling during the step, m_mf (kg), scalar or array, > 0.
    particle_diameter_m
        Particle diameter Dp (m), > 0.
    particle_density_kg_m3
        Particle density (kg/m3), > 0.

    Returns
    -------
    float or numpy.ndarray
        A_fp (m2); a float for scalar input.

    Examples
    --------
    Table 6 of the paper, model one (0.04 kg of 8 mm particles at 1050 kg/m3):

    >>> round(falling_particle_area(0.04, 0.008, 1050.0), 3)
    0.029
    """
    m_p = particle_mass(particle_diameter_m, particle_density_kg_m3)
    sphere_area = 4.0 * math.pi * (float(particle_diameter_m) / 2.0) ** 2
    if np.ndim(falling_mass_kg) == 0:
        return sphere_area / m_p * check_positive("falling_mass_kg", falling_mass_kg)
    m_mf = as_float_array("falling_mass_kg", falling_mass_kg, positive=True)
    return sphere_area / m_p * m_mf


@dataclass(frozen=True)
class HeatTransferSteps:
    """Per-step results of the heat-transfer model (one entry per step ``t -> t + dt``).

    All arrays have ``n_steps = len(times) - 1`` entries and are read-only.

    Attributes
    ----------
    time_s
        End time ``t + dt`` of each step (s).
    dt_s
        Step length (s).
    particle_dT_c
        Eq. 34, ``T(t+dt) - T(t)`` (K); negative when the particles cool.
    falling_mass_kg
        m_mf, mass falling during the step (kg).
    air_mass_kg
        m_a = mdot_a * dt, air mass passing during the step (kg).
    heat_j
        Eq. 35, heat given to the air during the step (J); positive when the particles cool.
    air_dT_c
        Eq. 36, air temperature rise (K).
    air_temperature_c
        Eq. 37, air temperature leaving the step (deg C).
    lmtd_c
        Eq. 38 (K); NaN where the log argument is zero or negative.
    heat_rate_w
        Eq. 40, ``Qm / dt`` (W).
    area_m2
        Eq. 41, A_fp (m2).
    h_w_m2k
        Eq. 39, heat-transfer coefficient (W/(m2 K)); NaN on masked steps.
    valid
        True where ``h`` is defined (see the module notes on masking).
    h_mean_w_m2k
        Time average of ``h`` over the valid steps, ``sum(h dt) / sum(dt)`` (equal to the plain mean
        for a constant dt); NaN if no step is valid.
    n_valid, n_steps
        Number of valid steps and of all steps.
    masked_no_change
        Steps masked because ``dT == 0``.
    masked_cross
        Steps masked because the LMTD log argument was zero or negative (temperature cross).
    """

    time_s: NDArray[np.float64]
    dt_s: NDArray[np.float64]
    particle_dT_c: NDArray[np.float64]
    falling_mass_kg: NDArray[np.float64]
    air_mass_kg: NDArray[np.float64]
    heat_j: NDArray[np.float64]
    air_dT_c: NDArray[np.float64]
    air_temperature_c: NDArray[np.float64]
    lmtd_c: NDArray[np.float64]
    heat_rate_w: NDArray[np.float64]
    area_m2: NDArray[np.float64]
    h_w_m2k: NDArray[np.float64]
    valid: NDArray[np.bool_]
    h_mean_w_m2k: float
    n_valid: int
    n_steps: int
    masked_no_change: int
    masked_cross: int


def per_step_heat_transfer(
    times_s: ArrayLike,
    mean_particle_temperature_c: ArrayLike,
    *,
    particle_diameter_m: float,
    particle_density_kg_m3: float,
    material_cp_j_kgk: float,
    air_mass_flow_kg_s: float,
    air_cp_j_kgk: float,
    air_inlet_temperature_c: float,
    falling_mass_kg: ArrayLike | None = None,
    falling_mass_flow_kg_s: ArrayLike | None = None,
) -> HeatTransferSteps:
    """Heat-transfer coefficient of every simulation step, Eqs. 34-41.

    Parameters
    ----------
    times_s
        Output times (s), strictly increasing, at least two. The step length may vary.
    mean_particle_temperature_c
        Mean particle temperature at each time (deg C), same length as ``times_s``.
    particle_diameter_m
        Particle diameter Dp (m).
    particle_density_kg_m3
        Particle density (kg/m3).
    material_cp_j_kgk
        Particle specific heat cp_m (J/(kg K)).
    air_mass_flow_kg_s
        Air mass flow mdot_a (kg/s); the air mass per step is ``mdot_a * dt``.
    air_cp_j_kgk
        Air specific heat cp_a (J/(kg K)).
    air_inlet_temperature_c
        Air inlet temperature T_ai (deg C).
    falling_mass_kg
        Mass falling from the flights during one step, m_mf (kg): a scalar (same every step) or
        one value per step. Give this or ``falling_mass_flow_kg_s``, not both.
    falling_mass_flow_kg_s
        Falling mass flow (kg/s, Eq. 57 of the paper); the mass per step is ``flow * dt``.

    Returns
    -------
    HeatTransferSteps
        Per-step arrays, the time-averaged ``h`` and the number of valid steps.

    Raises
    ------
    AnalysisInputError
        If an argument is missing, non-finite, non-positive where it must be positive, of the
        wrong length, or if the times are not strictly increasing.

    Notes
    -----
    Table 6 of the paper: model one (dt = 0.005 s, m_mf = 0.04 kg, Dp = 8 mm, rho = 1050 kg/m3,
    mdot_a = 25 kg/s) has A_fp = 0.029 m2 and m_a = 0.125 kg per step; model two (dt = 0.01 s,
    m_mf = 0.82 kg, Dp = 20 mm) has A_fp = 0.233 m2 and m_a = 0.25 kg.
    """
    t = as_float_array("times_s", times_s, min_size=2)
    temp = as_float_array("mean_particle_temperature_c", mean_particle_temperature_c, min_size=2)
    check_same_length([("times_s", t), ("mean_particle_temperature_c", temp)])
    dt = np.diff(t)
    if np.any(dt <= 0.0):
        i = int(np.flatnonzero(dt <= 0.0)[0]) + 1
        raise AnalysisInputError(
            f"times_s[{i}]",
            float(t[i]),
            f"a time > times_s[{i - 1}] = {t[i - 1]:g} (strictly increasing)",
        )
    n_steps = dt.size

    d_p = check_positive("particle_diameter_m", particle_diameter_m)
    rho_p = check_positive("particle_density_kg_m3", particle_density_kg_m3)
    cp_m = check_positive("material_cp_j_kgk", material_cp_j_kgk)
    mdot_a = check_positive("air_mass_flow_kg_s", air_mass_flow_kg_s)
    cp_a = check_positive("air_cp_j_kgk", air_cp_j_kgk)
    t_ai = check_finite("air_inlet_temperature_c", air_inlet_temperature_c)

    which = exactly_one(
        falling_mass_kg=falling_mass_kg, falling_mass_flow_kg_s=falling_mass_flow_kg_s
    )
    given = falling_mass_kg if which == "falling_mass_kg" else falling_mass_flow_kg_s
    per = as_float_array(which, given, positive=True)  # type: ignore[arg-type]
    if per.size not in (1, n_steps):
        raise AnalysisInputError(
            which, f"{per.size} values", f"a scalar or {n_steps} values (one per step)"
        )
    m_mf = np.broadcast_to(per, (n_steps,)).astype(np.float64)
    if which == "falling_mass_flow_kg_s":
        m_mf = m_mf * dt

    m_a = mdot_a * dt
    d_temp = temp[1:] - temp[:-1]  # Eq. 34
    heat = -m_mf * cp_m * d_temp  # Eq. 35, heat given to the air (> 0 when particles cool)
    air_dt = heat / (m_a * cp_a)  # Eq. 36
    air_t = t_ai + air_dt  # Eq. 37
    # End A: hot particles enter (mean T at t) and warmed air leaves; end B: particles leave
    # (mean T at t+dt) and inlet air enters.
    delta_a = temp[:-1] - air_t
    delta_b = temp[1:] - t_ai
    lmtd = np.asarray(log_mean_temperature_difference(delta_a, delta_b), dtype=np.float64)
    lmtd = lmtd.reshape(n_steps)  # Eq. 38
    rate = heat / dt  # Eq. 40
    area = np.asarray(falling_particle_area(m_mf, d_p, rho_p), dtype=np.float64).reshape(n_steps)
    no_change = d_temp == 0.0
    cross = ~np.isfinite(lmtd)
    with np.errstate(divide="ignore", invalid="ignore"):
        h = rate / (area * lmtd)  # Eq. 39
    h[no_change | cross] = np.nan
    valid = np.isfinite(h)
    n_valid = int(valid.sum())
    if n_valid:
        h_mean = float(np.sum(h[valid] * dt[valid]) / np.sum(dt[valid]))
    else:
        h_mean = math.nan

    return HeatTransferSteps(
        time_s=readonly(t[1:].copy()),
        dt_s=readonly(dt),
        particle_dT_c=readonly(d_temp),
        falling_mass_kg=readonly(m_mf),
        air_mass_kg=readonly(m_a),
        heat_j=readonly(heat),
        air_dT_c=readonly(air_dt),
        air_temperature_c=readonly(air_t),
        lmtd_c=readonly(lmtd),
        heat_rate_w=readonly(rate),
        area_m2=readonly(area),
        h_w_m2k=readonly(h),
        valid=readonly(valid),
        h_mean_w_m2k=h_mean,
        n_valid=n_valid,
        n_steps=n_steps,
        masked_no_change=int(no_change.sum()),
        masked_cross=int((cross & ~no_change).sum()),
    )
