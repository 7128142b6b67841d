"""Solids transport along a flighted drum: the Friedman-Marshall residence-time law.

Friedman and Marshall (1949, Chem. Eng. Prog. 45, 482 and 573), as given in Perry's Chemical
Engineers' Handbook (rotary dryers, "retention time"), in their units (ft, rpm, lb/(h ft^2),
minutes)::

    tau = K L / (S N^0.9 D)  +  0.6 B L G / F,    B = 5 Dp^-0.5   (Dp in micrometres)

The first term is Saeman's kinetic transport (a cascade advances the solids by a step set by
the tilt ``S`` = tan(tilt), the drum diameter ``D`` and the speed ``N``); the second is the air
drag, positive for counter-current air, which holds the solids back (``G`` air and ``F``
solids mass velocity over the drum cross-section). The handbook's ``K`` is 0.23; it depends on
the flights, and it is the law's one constant: :func:`calibrate` sets it so that the law gives
a measured residence time (for the paper's plant, its 30 min), and every what-if keeps it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from drumflow.coolers.plant import PlantSpec

#: Perry's value of K (Friedman and Marshall 1949).
HANDBOOK_COEFFICIENT = 0.23
_FT = 0.3048  # m
_LB_H_FT2 = 0.45359237 / 3600.0 / _FT**2  # kg/(s m^2) in one lb/(h ft^2)


@dataclass(frozen=True)
class TransportLaw:
    """The residence-time law with its coefficient and where the coefficient came from."""

    coefficient: float = HANDBOOK_COEFFICIENT
    calibrated_on: str = "handbook value (Perry's, Friedman and Marshall 1949)"

    def terms_min(self, plant: PlantSpec) -> tuple[float, float]:
        """The kinetic and the air-drag terms of the law, minutes."""
        length_ft = plant.length_m / _FT
        diameter_ft = plant.diameter_m / _FT
        slope = math.tan(math.radians(plant.tilt_deg))
        if slope <= 0:
            raise ValueError(f"tilt_deg = {plant.tilt_deg}: the transport law needs a tilt > 0")
        area = math.pi * plant.diameter_m**2 / 4.0
        gas = plant.air_mass_flow_kg_s / area / _LB_H_FT2
        solids = plant.feed_rate_kg_s / area / _LB_H_FT2
        b = 5.0 * (plant.particle_diameter_m * 1e6) ** -0.5
        kinetic = self.coefficient * length_ft / (slope * plant.rpm**0.9 * diameter_ft)
        drag = 0.6 * b * length_ft * gas / solids
        return kinetic, drag

    def residence_time_s(self, plant: PlantSpec) -> float:
        """Mean solids residence time, s (counter-current air)."""
        kinetic, drag = self.terms_min(plant)
        return 60.0 * (kinetic + drag)

    def holdup_kg(self, plant: PlantSpec) -> float:
        """Solids hold-up: feed rate times residence time, kg."""
        return plant.feed_rate_kg_s * self.residence_time_s(plant)


def calibrate(plant: PlantSpec, residence_time_s: float) -> TransportLaw:
    """The law whose coefficient gives ``residence_time_s`` for ``plant``.

    Raises
    ------
    ValueError
        When the air-drag term alone already exceeds the measured time (no positive K).
    """
    unit = TransportLaw(coefficient=1.0)
    kinetic, drag = unit.terms_min(plant)
    target = residence_time_s / 60.0
    if target <= drag:
        raise ValueError(
            f"residence_time_s = {residence_time_s:g}: the air-drag term alone gives "
            f"{60 * drag:.4g} s; allowed above that"
        )
    return TransportLaw(
        coefficient=(target - drag) / kinetic,
        calibrated_on=f"measured residence time {residence_time_s / 60:.4g} min",
    )
