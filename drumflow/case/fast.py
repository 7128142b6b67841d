"""The fast profile (``drumflow run --fast``): settings that keep the answers and halve the cost."""

from __future__ import annotations

import json

from drumflow.case.model import Case

#: The fast profile (``drumflow run --fast``; README, 'The fast profile'): each setting with the
#: measurement that keeps the answers. Without the particles' tangential dashpot the bed has no
#: spin limit below the spring's own, so "auto" takes the contact step (about twice the
#: damped bed's) without the numerical spin that biased the falling mass flow by +5.5 % there:
#: on paper model two's parcels over 17.5 s the cascading flow landed -0.3 % from the resolved
#: spin's (noise +-2.4 %), the heat answers 0.02 %. Conduction between particles moves no
#: heat out of the slice and, with one-way air, changed nothing measurable. The converged stop
#: ends a run once h and the falling mass flow are known to run.stop_tolerance (only with air:
#: it watches the air's h).
FAST_PROFILE: tuple[tuple[str, str, object], ...] = (
    ("contacts", "tangential_damping", False),
    ("run", "conduction", False),
    ("run", "stop", "converged"),
)


def fast_profile(case: Case) -> tuple[Case, list[str]]:
    """The case under :data:`FAST_PROFILE`, named ``<name>_fast`` (its own run directory), and
    what changed, as ``"section.name: old -> new"`` lines (empty if the case already had it).
    The converged stop is left out for a case without air, which it cannot watch."""
    data = case.model_dump(mode="json")
    changed: list[str] = []
    for section, name, value in FAST_PROFILE:
        if (section, name) == ("run", "stop") and case.air.model == "none":
            continue
        old = data[section][name]
        if old != value:
            data[section][name] = value
            changed.append(f"{section}.{name}: {json.dumps(old)} -> {json.dumps(value)}")
    if not changed:
        return case, changed
    if not data["name"].endswith("_fast"):
        data["name"] = f"{data['name']}_fast"
    return Case.model_validate(data), changed
