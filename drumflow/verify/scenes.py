"""Small scenes for verification and tests: a tiny drum that runs in seconds."""

from __future__ import annotations

import copy
from typing import Any

from drumflow.case import Case, case_from_dict

_TINY: dict[str, Any] = {
    "name": "tiny",
    "description": "0.2 m drum, 6 L-lifters, 500 particles of 8 mm",
    "drum": {"diameter": 0.2, "length": 0.048, "tilt_deg": 1.5, "rpm": 30.0},
    "lifters": {"count": 6, "profile": "L", "base_height": 0.025, "lip_length": 0.012,
                "lip_angle_deg": 90.0, "thickness": 0.003},
    "particles": {"diameter": 0.008, "density": 1050.0, "youngs_modulus": 5.0e6,
                  "poisson_ratio": 0.45, "heat_capacity": 1465.38, "conductivity": 0.18596,
                  "count": 500, "initial_temperature_C": 90.0},
    "contacts": {
        "particle_particle": {"friction": 0.4, "restitution": 0.1, "rolling_friction": 0.05},
        "particle_wall": {"friction": 0.2, "restitution": 0.3, "rolling_friction": 0.05},
    },
    "air": {"model": "none", "mass_flow": 0.1, "inlet_temperature_C": 30.0},
    "run": {"time": 1.2, "dump_interval": 0.01, "snapshot_interval": 0.1,
            "mass_flow_start": 0.6, "restart_interval": 0.2},
}


def tiny_drum_dict(**overrides: Any) -> dict[str, Any]:
    """The tiny drum as nested dictionaries; ``section__field=value`` overrides a value."""
    data = copy.deepcopy(_TINY)
    for key, value in overrides.items():
        section, name = key.split("__")
        data[section][name] = value
    return data


def tiny_drum(**overrides: Any) -> Case:
    """The tiny drum as a validated case."""
    return case_from_dict(tiny_drum_dict(**overrides))
