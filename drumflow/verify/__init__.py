"""``drumflow verify``: real small cases checked against independent references.

The stage logic lives in :mod:`drumflow.verify.run`; the checks in :mod:`.single_particle`
(air coupling of one particle), :mod:`.bed` (the tiny drum's bed), :mod:`.air_field` (the
OpenFOAM field), :mod:`.contacts` (LIGGGHTS' contact physics) and :mod:`.references` (the
independent references, and the checks that need no solver).
"""

from __future__ import annotations

from drumflow.verify.checks import Check, summary
from drumflow.verify.run import run_verification

__all__ = ["Check", "run_verification", "summary"]
