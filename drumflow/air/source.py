"""The air field as the coupling loop loads it: what the air stage hands on.

Light on purpose (no solver, no stage): the coupling spec (:mod:`drumflow.coupling.spec`) and
the air stage both import it.
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from drumflow.geometry.lifters import free_area
from drumflow.physics.air import ideal_gas_density

if TYPE_CHECKING:
    from drumflow.case import Case

__all__ = ["FieldSource", "mean_axial_velocity", "uniform_field"]


@dataclass(frozen=True)
class FieldSource:
    """The air field a stage produced, as the coupling loop loads it.

    Attributes
    ----------
    field
        ``{"kind": "uniform", "velocity": [ux, uy, uz]}``,
        ``{"kind": "grid", "path": "/abs/path/field.npz"}`` or, the air around the bed,
        ``{"kind": "phases", "paths": [...], "angles": [...], "spacing": ..., "omega": ...}``
        (see :func:`drumflow.coupling.driver.load_field`).
    key
        Identifies the field (a hash), for the DEM stage key.
    omega
        Rotation rate of the frame the field was solved in (0 for a uniform field), rad/s.
    """

    field: dict[str, Any]
    key: str
    omega: float


def uniform_field(case: Case) -> FieldSource:
    """Plug flow at the mean axial velocity mdot / (rho A_free), counter-current (along -z)."""
    from drumflow.rundir import hash_text

    velocity = [0.0, 0.0, -mean_axial_velocity(case)]
    return FieldSource({"kind": "uniform", "velocity": velocity}, hash_text(json.dumps(velocity)), 0.0)


def mean_axial_velocity(case: Case) -> float:
    """Mean axial air speed through the free cross-section, mdot / (rho A_free), m/s."""
    rho = ideal_gas_density(case.air.inlet_temperature_C, case.air.pressure_kPa)
    return case.air.mass_flow / (rho * free_area(case))
