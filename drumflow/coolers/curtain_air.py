"""How much the whole-cooler prediction depends on the air that passes through the curtains.

The drum model (:mod:`drumflow.coolers.drum`) needs one closure no slice run measures yet: the
air that crosses the curtains, ``q_c`` in m^3/s per metre of drum. A dense curtain brings the
air that enters it to the granules' temperature within centimetres, so the heat the falls give
the air is set by ``q_c``, not by the film coefficient. Until a CFD-DEM level with two-way
coupling measures ``q_c`` (never to be fitted to the plant's outlets), this module shows the
prediction over a range of it (:func:`sweep_curtain_air`), the flow that a given NPK outlet
would need (:func:`curtain_air_for_outlet`: a measurement of the miss, not a calibration), and
the physical scales to hold that flow against (:func:`curtain_air_scales`).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, replace
from typing import Any

from scipy.optimize import brentq

from drumflow.analysis.closures import SliceClosures
from drumflow.coolers._fall import fall_kinematics
from drumflow.coolers._transport import TransportLaw
from drumflow.coolers.drum import MAX_CURTAIN_AIR_M3_S_M, DrumOptions, DrumResult, solve_drum
from drumflow.coolers.drum_closures import PlantClosures
from drumflow.coolers.plant import PlantSpec
from drumflow.physics.particle_air import AirState

__all__ = [
    "CURTAIN_AIR_SWEEP_M3_S_M",
    "CurtainAirPoint",
    "NeededCurtainAir",
    "curtain_air_for_outlet",
    "curtain_air_scales",
    "sweep_curtain_air",
]

#: Through-curtain flows of the default sweep, m^3/s per metre: from none (the bed alone) to
#: well past the drum's whole axial air per metre (~1.1 m^3/s per metre for the paper's plant),
#: where the result approaches the all-air limit.
CURTAIN_AIR_SWEEP_M3_S_M: tuple[float, ...] = (0.0, 0.25, 0.5, 1.0, 1.5, 2.0, 3.0, 5.0, 10.0,
                                               30.0)
_G = 9.81
_PRESSURE_KPA = 101.325


@dataclass(frozen=True)
class CurtainAirPoint:
    """The prediction at one through-curtain flow (``None``: all the air meets the curtain)."""

    curtain_air_m3_s_m: float | None
    material_outlet_c: float
    air_outlet_c: float
    heat_curtain_w: float
    heat_bed_w: float
    wall_loss_w: float
    curtain_passes: float | None
    curtain_saturation: float | None

    @classmethod
    def from_result(cls, result: DrumResult) -> CurtainAirPoint:
        streams = result.air_streams()
        return cls(
            curtain_air_m3_s_m=result.options.curtain_air_m3_s_m,
            material_outlet_c=result.material_outlet_c,
            air_outlet_c=result.air_outlet_c,
            heat_curtain_w=result.heat_curtain_w,
            heat_bed_w=result.heat_bed_w,
            wall_loss_w=result.wall_loss_w,
            curtain_passes=streams["curtain_passes"],
            curtain_saturation=streams["curtain_saturation"],
        )

    def to_dict(self) -> dict[str, Any]:
        return {
            "curtain_air_m3_s_per_m": self.curtain_air_m3_s_m,
            "material_outlet_C": self.material_outlet_c,
            "air_outlet_C": self.air_outlet_c,
            "heat_curtain_W": self.heat_curtain_w,
            "heat_bed_W": self.heat_bed_w,
            "wall_loss_W": self.wall_loss_w,
            "curtain_passes": self.curtain_passes,
            "curtain_saturation": self.curtain_saturation,
        }


def sweep_curtain_air(plant: PlantSpec, closures: SliceClosures, law: TransportLaw,
                      options: DrumOptions,
                      flows: Sequence[float | None] = (*CURTAIN_AIR_SWEEP_M3_S_M, None),
                      ) -> list[CurtainAirPoint]:
    """The prediction at each through-curtain flow of ``flows`` (m^3/s per metre; ``None`` for
    all the air), every other option as in ``options``."""
    return [CurtainAirPoint.from_result(
        solve_drum(plant, closures, law, replace(options, curtain_air_m3_s_m=q)))
        for q in flows]


@dataclass(frozen=True)
class NeededCurtainAir:
    """The through-curtain flow that would give a target NPK outlet, or why there is none.

    Attributes
    ----------
    target_material_outlet_c
        The outlet asked for.
    curtain_air_m3_s_m
        The flow that gives it (None when the target is out of the model's reach).
    air_outlet_c
        The model's air outlet at that flow (a check against the measured one).
    reachable_c
        The NPK outlets the model spans: with no through-curtain air (the bed alone) and with
        all the air meeting the curtain.
    reason
        Why there is no flow, when there is none.
    """

    target_material_outlet_c: float
    curtain_air_m3_s_m: float | None
    air_outlet_c: float | None
    reachable_c: tuple[float, float]
    reason: str = ""

    def to_dict(self) -> dict[str, Any]:
        return {
            "target_material_outlet_C": self.target_material_outlet_c,
            "curtain_air_m3_s_per_m": self.curtain_air_m3_s_m,
            "air_outlet_C": self.air_outlet_c,
            "reachable_material_outlet_C": list(self.reachable_c),
            "reason": self.reason,
        }


def curtain_air_for_outlet(plant: PlantSpec, closures: SliceClosures, law: TransportLaw,
                           options: DrumOptions, target_material_outlet_c: float,
                           points: Sequence[CurtainAirPoint] | None = None,
                           tolerance_m3_s_m: float = 1e-3) -> NeededCurtainAir:
    """The through-curtain flow at which the model gives ``target_material_outlet_c``.

    This measures how large the closure would have to be; it is not a calibration (nothing
    else in the model moves, and the flow is reported beside its physical scales). The NPK
    outlet falls monotonically as the flow grows (more air through the curtains, more heat),
    so the root is bracketed from ``points`` (a sweep; one is run when not given).
    """
    pts = list(points) if points is not None else sweep_curtain_air(plant, closures, law,
                                                                     options)
    finite = sorted((p for p in pts if p.curtain_air_m3_s_m is not None),
                    key=lambda p: p.curtain_air_m3_s_m or 0.0)
    limit = [p for p in pts if p.curtain_air_m3_s_m is None]
    bed_alone = (finite[0].material_outlet_c if finite and finite[0].curtain_air_m3_s_m == 0
                 else solve_drum(plant, closures, law,
                                 replace(options, curtain_air_m3_s_m=0.0)).material_outlet_c)
    all_air = (limit[0].material_outlet_c if limit
               else solve_drum(plant, closures, law,
                               replace(options, curtain_air_m3_s_m=None)).material_outlet_c)
    reach = (bed_alone, all_air)
    target = target_material_outlet_c
    if target >= bed_alone:
        return NeededCurtainAir(target, None, None, reach,
                                "the bed alone already cools the NPK below the target")
    if target <= all_air:
        return NeededCurtainAir(target, None, None, reach,
                                "even all the air meeting every granule leaves the NPK above "
                                "the target")
    lo, hi = 0.0, math.nan
    for p in finite:
        q = p.curtain_air_m3_s_m
        assert q is not None
        if p.material_outlet_c > target:
            lo = q
        else:
            hi = q
            break
    if not math.isfinite(hi):
        # Beyond the sweep: double the flow until the outlet is below the target (it tends to
        # the all-air limit, below the target, as the flow grows without bound).
        hi = max(2.0 * lo, 1.0)
        while _outlet(plant, closures, law, options, hi) > target:
            lo, hi = hi, 2.0 * hi
            if hi > MAX_CURTAIN_AIR_M3_S_M:
                return NeededCurtainAir(target, None, None, reach,
                                        f"needs more than {MAX_CURTAIN_AIR_M3_S_M:g} m3/s per "
                                        "metre")

    def miss(q: float) -> float:
        return _outlet(plant, closures, law, options, q) - target

    q = float(brentq(miss, lo, hi, xtol=tolerance_m3_s_m))
    at = solve_drum(plant, closures, law, replace(options, curtain_air_m3_s_m=q))
    return NeededCurtainAir(target, q, at.air_outlet_c, reach)


def _outlet(plant: PlantSpec, closures: SliceClosures, law: TransportLaw, options: DrumOptions,
            q: float) -> float:
    return solve_drum(plant, closures, law,
                      replace(options, curtain_air_m3_s_m=q)).material_outlet_c


def curtain_air_scales(plant: PlantSpec, scaled: PlantClosures) -> dict[str, dict[str, Any]]:
    """Physical scales of the through-curtain flow, m^3/s per metre of drum, each with how it
    is computed. None is a measurement of ``q_c``; they say whether a needed value is
    plausible.

    * ``axial_air_per_metre``: the drum's whole air flow over its length: the flow at which
      every parcel of air crosses one curtain once on its way (more means air circulates
      across the section and through curtains several times).
    * ``curtain_face_at_axial_speed``: air crossing one curtain's face (fall height per metre
      of drum) at the axial air speed: a secondary flow as strong as the main one.
    * ``drag_entrainment``: the air the curtain can set moving by its drag. The impulse the
      particles lose to drag over a fall, ``G_f (g t_f - v_end)`` per metre (N/m, the fall
      kinematics of :mod:`drumflow.coolers._fall`), drives a downward air stream; moving at the
      particles' mean speed ``v`` it carries ``F / (rho v)``. Slower entrained air would be more
      of it, and the still-air drag overstates the force once the air moves: an order of
      magnitude only.
    """
    air = AirState.at(plant.air_inlet_temperature_c, _PRESSURE_KPA)
    axial_m3_s = plant.air_mass_flow_kg_s / air.density
    fall = fall_kinematics(scaled.fall_height_m, plant.particle_diameter_m,
                           plant.particle_density_kg_m3, air, scaled.axial_air_velocity_m_s)
    force = scaled.falling_mass_flow_kg_s_m * max(_G * fall.time_s - fall.end_speed_m_s, 0.0)
    return {
        "axial_air_per_metre": {
            "m3_s_per_m": axial_m3_s / plant.length_m,
            "how": f"axial air {axial_m3_s:.3g} m3/s over the {plant.length_m:g} m drum",
        },
        "curtain_face_at_axial_speed": {
            "m3_s_per_m": scaled.axial_air_velocity_m_s * scaled.fall_height_m,
            "how": f"axial speed {scaled.axial_air_velocity_m_s:.3g} m/s x fall height "
                   f"{scaled.fall_height_m:.3g} m",
        },
        "drag_entrainment": {
            "m3_s_per_m": force / (air.density * fall.mean_speed_m_s),
            "how": f"drag impulse {force:.3g} N/m (falling flow "
                   f"{scaled.falling_mass_flow_kg_s_m:.4g} kg/(s m), g t_f - v_end = "
                   f"{_G * fall.time_s - fall.end_speed_m_s:.3g} m/s) / (rho_air x mean fall "
                   f"speed {fall.mean_speed_m_s:.3g} m/s)",
        },
    }
