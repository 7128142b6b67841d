"""A slice run's closures scaled to the whole drum, and where that scaling stops being trusted.

The slice measured one operating point (rpm, particle size, hold-up, air speed); the axial
model (:mod:`drumflow.coolers.drum`) runs the plant at another. :func:`scale_closures` carries
each closure over by the law that sets it (Froude number, chord of the bed, axial air speed,
the transport law's hold-up) and :func:`extrapolation_warnings` names every condition outside
the range the slice and the transport calibration vouch for.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from scipy.optimize import brentq

from drumflow.analysis.closures import BED_PACKING, SliceClosures
from drumflow.coolers._fall import Fall, fall_kinematics
from drumflow.coolers._transport import TransportLaw
from drumflow.coolers.plant import PlantSpec
from drumflow.errors import DrumModelError
from drumflow.physics.particle_air import AirState

__all__ = ["PRESSURE_KPA", "PlantClosures", "extrapolation_warnings", "scale_closures"]

#: Pressure of the drum's air, kPa (the drum runs at atmospheric pressure).
PRESSURE_KPA = 101.325


@dataclass(frozen=True)
class PlantClosures:
    """The slice closures scaled to the plant (module notes), with the slice checks."""

    residence_time_s: float
    holdup_kg_per_m: float
    cascades_per_revolution: float
    falling_mass_flow_kg_s_m: float
    fall_height_m: float
    fall_time_s: float
    fall_effective_slip_m_s: float
    axial_air_velocity_m_s: float
    airborne_fraction: float
    cycle_time_s: float
    bed_surface_m2_per_m: float
    slice_ballistic_fall_time_s: float
    slice_measured_fall_time_s: float
    slice_airborne_fraction: float


def _chord_fraction(bed_area_fraction: float) -> float:
    """Chord over diameter of a circular segment holding ``bed_area_fraction`` of the circle."""
    beta = min(max(bed_area_fraction, 1e-9), 1.0 - 1e-9)
    theta = brentq(lambda t: t - math.sin(t) - 2.0 * math.pi * beta, 0.0, 2.0 * math.pi)
    return math.sin(0.5 * theta)


def _axial_air_velocity(plant: PlantSpec) -> float:
    rho = AirState.at(plant.air_inlet_temperature_c, PRESSURE_KPA).density
    return plant.air_mass_flow_kg_s / (rho * math.pi * plant.diameter_m**2 / 4.0)


def scale_closures(plant: PlantSpec, closures: SliceClosures, law: TransportLaw) -> PlantClosures:
    """Scale the slice closures to the plant (module notes).

    Raises
    ------
    DrumModelError
        When the scaled falls would take longer than a whole cascade cycle.
    """
    tau = law.residence_time_s(plant)
    holdup = plant.feed_rate_kg_s * tau / plant.length_m
    n_c = closures.cascades_per_revolution
    g_f = n_c * holdup * plant.rpm / 60.0
    height = closures.fall_height_m * plant.diameter_m / closures.drum_diameter_m
    air_in = AirState.at(plant.air_inlet_temperature_c, PRESSURE_KPA)
    u_axial = _axial_air_velocity(plant)
    fall = fall_kinematics(height, plant.particle_diameter_m, plant.particle_density_kg_m3,
                           air_in, u_axial)
    cycle = holdup / g_f
    if fall.time_s >= cycle:
        raise DrumModelError(
            f"rpm = {plant.rpm:g}: a fall ({fall.time_s:.3g} s) would last longer than a cascade "
            f"cycle ({cycle:.3g} s); allowed below {plant.rpm * cycle / fall.time_s:.3g} rpm"
        )
    slice_air = AirState.at(plant.air_inlet_temperature_c, PRESSURE_KPA)
    slice_fall: Fall = fall_kinematics(closures.fall_height_m, closures.particle_diameter_m,
                                       closures.particle_density_kg_m3, slice_air,
                                       closures.air_axial_velocity_m_s)
    # Bed surface: the slice's measured surface, scaled with the segment chord at each drum's
    # bed area (bed = the hold-up not in the air, at random loose packing).
    area_slice = closures.solids_volume_fraction * (1 - closures.airborne_fraction) / BED_PACKING
    solids_fraction = holdup / plant.particle_density_kg_m3 / (math.pi * plant.diameter_m**2 / 4)
    phi = g_f * fall.time_s / holdup
    area_plant = solids_fraction * (1 - phi) / BED_PACKING
    if area_plant >= 1.0:
        raise DrumModelError(
            f"feed_rate_kg_s = {plant.feed_rate_kg_s:g}: the hold-up would fill the drum "
            f"({area_plant:.2f} of its cross-section as bed)"
        )
    bed_surface = (closures.bed_surface_m2_per_m
                   * (plant.diameter_m * _chord_fraction(area_plant))
                   / (closures.drum_diameter_m * _chord_fraction(area_slice)))
    return PlantClosures(
        residence_time_s=tau,
        holdup_kg_per_m=holdup,
        cascades_per_revolution=n_c,
        falling_mass_flow_kg_s_m=g_f,
        fall_height_m=height,
        fall_time_s=fall.time_s,
        fall_effective_slip_m_s=fall.effective_slip_m_s,
        axial_air_velocity_m_s=u_axial,
        airborne_fraction=phi,
        cycle_time_s=cycle,
        bed_surface_m2_per_m=bed_surface,
        slice_ballistic_fall_time_s=slice_fall.time_s,
        slice_measured_fall_time_s=closures.fall_time_s,
        slice_airborne_fraction=closures.airborne_fraction,
    )


def extrapolation_warnings(plant: PlantSpec, base: PlantSpec, closures: SliceClosures,
                           scaled: PlantClosures) -> list[str]:
    """Flag each condition outside the range the slice and the calibration vouch for.

    The slice measured one operating point; the scaling laws are trusted within a factor of
    two of it for what the slice sets (Froude number for rpm, particle diameter, solids volume
    fraction for the feed rate, axial air speed for the air flow), and the transport law's
    calibration within +-50 % of the calibration plant's length and a factor of two of its
    tilt. Outside, the result is an extrapolation and says so.
    """
    out: list[str] = []

    def band(name: str, value: float, ref: float, factor: float, what: str) -> None:
        if ref > 0 and not ref / factor <= value <= ref * factor:
            out.append(f"{name} = {value:.4g}: outside the calibration range "
                       f"[{ref / factor:.4g}, {ref * factor:.4g}] ({what}); extrapolation")

    omega = plant.rpm * 2 * math.pi / 60
    band("Froude number", omega**2 * plant.diameter_m / 2 / 9.81, closures.froude, 2.0,
         f"the slice's Froude number {closures.froude:.3g}, rpm {plant.rpm:g}")
    band("particle_diameter_m", plant.particle_diameter_m, closures.particle_diameter_m, 2.0,
         "the slice's particle diameter")
    solids_fraction = scaled.holdup_kg_per_m / plant.particle_density_kg_m3 / (
        math.pi * plant.diameter_m**2 / 4)
    band("solids volume fraction", solids_fraction, closures.solids_volume_fraction, 2.0,
         f"the slice's hold-up; feed rate {plant.feed_rate_kg_s:g} kg/s")
    if closures.air_axial_velocity_m_s > 0:
        band("axial air velocity (m/s)", scaled.axial_air_velocity_m_s,
             closures.air_axial_velocity_m_s, 2.0,
             f"the slice's air speed; air flow {plant.air_mass_flow_kg_s:g} kg/s")
    band("length_m", plant.length_m, base.length_m, 1.5, "the transport law's calibration plant")
    band("tilt_deg", plant.tilt_deg, base.tilt_deg, 2.0, "the transport law's calibration plant")
    band("rpm", plant.rpm, base.rpm, 2.0, "the transport law's calibration plant")
    return out
