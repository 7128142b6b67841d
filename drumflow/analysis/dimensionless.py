"""Per-step Nusselt, Reynolds and Prandtl numbers of the particles (Eqs. 49-55).

Method of Burgos-Florez et al., Processes 2019, 7, 673, Section 2.4:

=======  ==========================================================================
Eq. 49   ``Nu = h Dp / k``
Eq. 50   ``T_ma = (T_ai + Ta(t+dt)) / 2``  mean air temperature of the step
Eq. 51   ``Re = v_max Dp / nu(T_ma)``
Eq. 52   ``v_max = V_ai / Vf``
Eq. 53   ``Vf = (V_d - V_m) / V_d``  void factor of the simulated section
Eq. 54   ``V_d = pi (D/2)^2 l``
Eq. 55   ``V_m = 4/3 pi (Dp/2)^3 N``
=======  ==========================================================================

Air properties (``k``, ``nu``, ``Pr``) are interpolated at ``T_ma`` from
:mod:`drumflow.physics.air`. The mean air inlet velocity is, unless given,
``V_ai = mdot_a / (rho_air(T_ai) pi D^2 / 4)``, i.e. the air flow spread over the full drum
cross-section (the paper does not give the inlet area it used).

Which conductivity? Eq. 49 names only ``k``. This module uses the air conductivity at ``T_ma``
by default, as a particle Nusselt number normally does. The paper's own numbers, however, are
reproduced only with the particle conductivity ``k_m = 0.18596`` W/(m K) of its Table 1: with
``h = 60.15`` (8 mm) and ``38.92`` (20 mm), ``h Dp / k_m = 2.588`` and ``4.186``, which is what its
correlation (Eq. 58) gives at the ends of its Re range (3073 and 7686) at ``Pr = 0.7282``, whereas
the air conductivity gives Nu of about 18 and 29. Pass ``conductivity_w_mk=0.18596`` to reproduce
the paper.

Which Reynolds number? drumflow's is Eqs. 51-54 as printed, with the inlet velocity spread over
the whole drum cross-section (above). For the paper's two models that gives 1844 and 4609; the
paper reports 3073 and 7686, 1.667 times more for both models (its Re implies v_max = 6.23 m/s
against V_ai / Vf = 3.74 m/s here). Every Re drumflow computes, fits or compares is this one;
the paper's Re and its Eq. 58 are converted to it once
(:func:`drumflow.analysis.published.reynolds_conversion`,
:func:`drumflow.coolers.prediction.paper_correlation`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from drumflow.physics import air
from drumflow.physics.validation import (
    AnalysisInputError,
    as_float_array,
    check_finite,
    check_positive,
    check_same_length,
    readonly,
)

__all__ = [
    "DimensionlessSteps",
    "dimensionless_numbers",
    "drum_volume",
    "mean_air_inlet_velocity",
    "particle_volume",
    "void_fraction",
]


def drum_volume(drum_diameter_m: float, section_length_m: float) -> float:
    """Volume of the simulated drum section, Eq. 54 (m3).

    Parameters
    ----------
    drum_diameter_m
        Drum diameter D (m).
    section_length_m
        Simulated section length l (m).

    Returns
    -------
    float
        ``pi (D/2)^2 l``.
    """
    d = check_positive("drum_diameter_m", drum_diameter_m)
    length = check_positive("section_length_m", section_length_m)
    return math.pi * (d / 2.0) ** 2 * length


def particle_volume(particle_count: int, particle_diameter_m: float) -> float:
    """Volume of all particles, Eq. 55 (m3).

    Parameters
    ----------
    particle_count
        Number of particles N, >= 1.
    particle_diameter_m
        Particle diameter Dp (m).

    Returns
    -------
    float
        ``4/3 pi (Dp/2)^3 N``.
    """
    n = check_positive("particle_count", particle_count)
    if n != int(n):
        raise AnalysisInputError("particle_count", n, "a whole number >= 1")
    dp = check_positive("particle_diameter_m", particle_diameter_m)
    return 4.0 / 3.0 * math.pi * (dp / 2.0) ** 3 * n


def void_fraction(
    *,
    drum_diameter_m: float,
    section_length_m: float,
    particle_count: int,
    particle_diameter_m: float,
) -> float:
    """Void factor of the simulated section, Eq. 53.

    Parameters
    ----------
    drum_diameter_m
        Drum diameter D (m).
    section_length_m
        Simulated section length l (m).
    particle_count
        Number of particles N in the section.
    particle_diameter_m
        Particle diameter Dp (m).

    Returns
    -------
    float
        ``Vf = (V_d - V_m) / V_d`` in (0, 1).

    Raises
    ------
    AnalysisInputError
        If the particles would fill the whole drum volume (``V_m >= V_d``).

    Examples
    --------
    Model one of the paper (D = 3 m, l = 0.1 m, 467,443 particles of 8 mm):

    >>> round(void_fraction(drum_diameter_m=3.0, section_length_m=0.1,
    ...                     particle_count=467443, particle_diameter_m=0.008), 4)
    0.8227
    """
    v_d = drum_volume(drum_diameter_m, section_length_m)
    v_m = particle_volume(particle_count, particle_diameter_m)
    if v_m >= v_d:
        raise AnalysisInputError(
            "particle_count",
            particle_count,
            f"fewer particles than fill the drum section ({v_m:.4g} m3 of particles "
            f"in {v_d:.4g} m3 of drum)",
        )
    return (v_d - v_m) / v_d


def mean_air_inlet_velocity(
    *, air_mass_flow_kg_s: float, drum_diameter_m: float, air_inlet_temperature_c: float
) -> float:
    """Mean air inlet velocity over the drum cross-section (m/s).

    ``V_ai = mdot_a / (rho_air(T_ai) pi D^2 / 4)``.

    Parameters
    ----------
    air_mass_flow_kg_s
        Air mass flow (kg/s).
    drum_diameter_m
        Drum diameter D (m).
    air_inlet_temperature_c
        Air inlet temperature (deg C), sets the density.

    Returns
    -------
    float
        V_ai (m/s).
    """
    mdot = check_positive("air_mass_flow_kg_s", air_mass_flow_kg_s)
    d = check_positive("drum_diameter_m", drum_diameter_m)
    t_ai = check_finite("air_inlet_temperature_c", air_inlet_temperature_c)
    rho = float(air.density(t_ai, name="air_inlet_temperature_c"))
    return mdot / (rho * math.pi * d**2 / 4.0)


@dataclass(frozen=True)
class DimensionlessSteps:
    """Per-step dimensionless numbers (arrays read-only, one entry per step).

    Attributes
    ----------
    nusselt
        Eq. 49 (-); NaN where ``h`` was NaN (masked step).
    reynolds
        Eq. 51 (-).
    prandtl
        Pr of air at ``T_ma`` (-).
    mean_air_temperature_c
        Eq. 50 (deg C).
    conductivity_w_mk
        Conductivity used in Nu (W/(m K)): air at ``T_ma``, or the constant given.
    kinematic_viscosity_m2_s
        Air kinematic viscosity at ``T_ma`` (m2/s).
    void_fraction
        Eq. 53 (-).
    air_inlet_velocity_m_s
        V_ai (m/s), computed or given.
    max_air_velocity_m_s
        Eq. 52 (m/s).
    particle_diameter_m
        Dp (m).
    valid
        True where Nu is finite.
    """

    nusselt: NDArray[np.float64]
    reynolds: NDArray[np.float64]
    prandtl: NDArray[np.float64]
    mean_air_temperature_c: NDArray[np.float64]
    conductivity_w_mk: NDArray[np.float64]
    kinematic_viscosity_m2_s: NDArray[np.float64]
    void_fraction: float
    air_inlet_velocity_m_s: float
    max_air_velocity_m_s: float
    particle_diameter_m: float
    valid: NDArray[np.bool_]


def dimensionless_numbers(
    h_w_m2k: ArrayLike,
    air_temperature_c: ArrayLike,
    *,
    air_inlet_temperature_c: float,
    particle_diameter_m: float,
    drum_diameter_m: float,
    section_length_m: float,
    particle_count: int,
    air_mass_flow_kg_s: float | None = None,
    air_inlet_velocity_m_s: float | None = None,
    conductivity_w_mk: float | None = None,
) -> DimensionlessSteps:
    """Nusselt, Reynolds and Prandtl numbers of every step, Eqs. 49-55.

    Parameters
    ----------
    h_w_m2k
        Per-step heat-transfer coefficient (W/(m2 K)); NaN marks masked steps and is passed
        through to Nu. Typically ``HeatTransferSteps.h_w_m2k``.
    air_temperature_c
        Per-step air temperature leaving the step, Ta(t+dt) (deg C), same length; typically
        ``HeatTransferSteps.air_temperature_c``.
    air_inlet_temperature_c
        T_ai (deg C).
    particle_diameter_m
        Dp (m).
    drum_diameter_m
        Drum diameter D (m).
    section_length_m
        Simulated section length l (m).
    particle_count
        Number of particles N in the section.
    air_mass_flow_kg_s
        Air mass flow (kg/s), used to compute V_ai when ``air_inlet_velocity_m_s`` is not given.
    air_inlet_velocity_m_s
        Mean air inlet velocity V_ai (m/s), if known; takes the place of ``air_mass_flow_kg_s``.
    conductivity_w_mk
        Conductivity for Nu (W/(m K)). ``None`` (default): air at ``T_ma``. Give the particle
        conductivity (0.18596 in the paper) to reproduce the paper's Nusselt numbers; see the
        module notes.

    Returns
    -------
    DimensionlessSteps

    Raises
    ------
    AnalysisInputError
        For invalid arguments, arrays of different lengths, both or neither of
        ``air_mass_flow_kg_s`` / ``air_inlet_velocity_m_s``, or a mean air temperature outside
        the air-property table.
    """
    h = as_float_array("h_w_m2k", h_w_m2k, allow_nan=True)
    t_air = as_float_array("air_temperature_c", air_temperature_c)
    check_same_length([("h_w_m2k", h), ("air_temperature_c", t_air)])
    t_ai = check_finite("air_inlet_temperature_c", air_inlet_temperature_c)
    dp = check_positive("particle_diameter_m", particle_diameter_m)

    if (air_mass_flow_kg_s is None) == (air_inlet_velocity_m_s is None):
        raise AnalysisInputError(
            "air_mass_flow_kg_s or air_inlet_velocity_m_s",
            "both given" if air_mass_flow_kg_s is not None else "none given",
            "exactly one of them",
        )
    if air_inlet_velocity_m_s is not None:
        v_ai = check_positive("air_inlet_velocity_m_s", air_inlet_velocity_m_s)
    else:
        v_ai = mean_air_inlet_velocity(
            air_mass_flow_kg_s=air_mass_flow_kg_s,  # type: ignore[arg-type]
            drum_diameter_m=drum_diameter_m,
            air_inlet_temperature_c=t_ai,
        )
    vf = void_fraction(
        drum_diameter_m=drum_diameter_m,
        section_length_m=section_length_m,
        particle_count=particle_count,
        particle_diameter_m=dp,
    )
    v_max = v_ai / vf  # Eq. 52

    t_ma = 0.5 * (t_ai + t_air)  # Eq. 50
    nu_air = np.asarray(air.kinematic_viscosity(t_ma, name="mean air temperature T_ma (Eq. 50)"))
    pr = np.asarray(air.prandtl(t_ma, name="mean air temperature T_ma (Eq. 50)"))
    if conductivity_w_mk is None:
        k = np.asarray(air.thermal_conductivity(t_ma, name="mean air temperature T_ma (Eq. 50)"))
    else:
        k = np.full(h.shape, check_positive("conductivity_w_mk", conductivity_w_mk))
    nusselt = h * dp / k  # Eq. 49
    reynolds = v_max * dp / nu_air  # Eq. 51

    return DimensionlessSteps(
        nusselt=readonly(nusselt),
        reynolds=readonly(reynolds),
        prandtl=readonly(pr.astype(np.float64)),
        mean_air_temperature_c=readonly(t_ma),
        conductivity_w_mk=readonly(k.astype(np.float64)),
        kinematic_viscosity_m2_s=readonly(nu_air.astype(np.float64)),
        void_fraction=vf,
        air_inlet_velocity_m_s=v_ai,
        max_air_velocity_m_s=v_max,
        particle_diameter_m=dp,
        valid=readonly(np.isfinite(nusselt)),
    )
