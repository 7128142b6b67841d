"""The validated case: the only place that knows the TOML case-file layout.

A case describes one drum study: the drum and its lifters (flights), the particles, the contact
laws, the air and how long and how finely to run. Units are SI unless the field name says
otherwise (``tilt_deg``, ``rpm``, ``initial_temperature_C``, ``pressure_kPa``).

Every problem in a case file is reported at once, each naming the field, the value and the
allowed range (:class:`drumflow.errors.CaseError`), before any solver starts.

=================  ==========================================================================
``sections``       the case file's sections and the configuration every input model shares
``model``          :class:`Case`: the sections checked together, derived counts, hashes
``lifter_shape``   the lifters' plates, shared by the case's gap check and the geometry stage
``loading``        reading TOML, validating any input model with every problem named
``fast``           the fast profile (``drumflow run --fast``)
=================  ==========================================================================

The public names are re-exported here: ``from drumflow.case import load_case, Case`` is the
way in.
"""

from drumflow.case.fast import FAST_PROFILE, fast_profile
from drumflow.case.loading import case_from_dict, case_to_toml, load_case, read_toml, validate_model
from drumflow.case.model import Case
from drumflow.case.sections import (
    BED_SOLIDS_FRACTION,
    INPUT_MODEL_CONFIG,
    PARTICLES_PER_PROCESS,
    Air,
    Contact,
    Contacts,
    Drum,
    Fraction,
    Lifters,
    Particles,
    Plant,
    Positive,
    PositiveInt,
    Run,
)

__all__ = [
    "BED_SOLIDS_FRACTION",
    "FAST_PROFILE",
    "INPUT_MODEL_CONFIG",
    "PARTICLES_PER_PROCESS",
    "Air",
    "Case",
    "Contact",
    "Contacts",
    "Drum",
    "Fraction",
    "Lifters",
    "Particles",
    "Plant",
    "Positive",
    "PositiveInt",
    "Run",
    "case_from_dict",
    "case_to_toml",
    "fast_profile",
    "load_case",
    "read_toml",
    "validate_model",
]
