"""A case's hash must not move when drumflow gains an option.

The hash names a run directory's case: ``drumflow run`` resumes a directory whose hash matches
and refuses (or, with ``--force``, restarts) one whose hash does not. When
``particles.coarse_grain`` arrived, every case's canonical JSON gained a field, and the paper
run of model two (hours in, at 6 s of 17.5) was refused on resume. Regression test: the hash
of a fixed case text is pinned to the value the code gave before that option existed (the
same at commits c86fda7~1 and 39fa6b3, twenty commits apart), so a new option that changes it
fails here, naming the fix (``drumflow.case._ADDED_LATER``).
"""

from __future__ import annotations

import json

from drumflow.case import Case, case_from_dict, read_toml
from drumflow.case.model import _ADDED_LATER

#: The smoke case as it stood (all sections explicit, no later option set).
CASE_TEXT = """
name = "pinned"
description = "hash stability fixture"

[drum]
diameter = 0.4
length = 0.08
tilt_deg = 1.5
rpm = 15.0

[lifters]
count = 8
profile = "L"
base_height = 0.04
lip_length = 0.02
lip_angle_deg = 90.0
thickness = 0.004

[particles]
diameter = 0.008
density = 1050.0
youngs_modulus = 5.0e6
poisson_ratio = 0.45
heat_capacity = 1465.38
conductivity = 0.18596
count = 3000
initial_temperature_C = 90.0

[contacts.particle_particle]
friction = 0.4
restitution = 0.1
rolling_friction = 0.05

[contacts.particle_wall]
friction = 0.2
restitution = 0.3
rolling_friction = 0.05

[air]
model = "cfd"
mesh_size = 0.02
mass_flow = 0.44
inlet_temperature_C = 30.0
pressure_kPa = 101.3

[run]
time = 3.0
time_step = "auto"
rayleigh_fraction = 0.2
dump_interval = 0.02
snapshot_interval = 0.25
mass_flow_start = 1.0
processes = 1
"""

#: ``Case.hash()`` of CASE_TEXT before ``particles.coarse_grain`` existed.
PINNED_HASH = "0bb4a0184745b9d3bdf4f2a2562fd5c0d98bba00754037bea4d7b27bed17b4a2"


def _case(tmp_path) -> Case:  # type: ignore[no-untyped-def]
    path = tmp_path / "pinned.toml"
    path.write_text(CASE_TEXT)
    return case_from_dict(read_toml(path), source=path)


def test_a_new_option_at_its_default_keeps_old_runs_hash(tmp_path) -> None:  # type: ignore[no-untyped-def]
    got = _case(tmp_path).hash()
    assert got == PINNED_HASH, (
        "Case.hash() moved for a case that sets no new option: old run directories would "
        "refuse to resume. List the new option with its old-behaviour value in "
        "drumflow.case._ADDED_LATER."
    )


def test_every_option_added_later_is_left_out_only_at_its_default(tmp_path) -> None:  # type: ignore[no-untyped-def]
    case = _case(tmp_path)
    canonical = json.loads(case.canonical_json())
    for section, name, old_behaviour in _ADDED_LATER:
        default = Case.model_fields[section].annotation.model_fields[name].default  # type: ignore[union-attr]
        assert default == old_behaviour, f"{section}.{name}: default {default!r} is not the old behaviour"
        assert name not in canonical[section]
    # Set away from the old behaviour, the option is part of the hash.
    data = case.model_dump(mode="json")
    data["particles"]["coarse_grain"] = 1.2
    assert Case.model_validate(data).hash() != case.hash()
