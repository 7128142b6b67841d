"""The benchmark ladder: one reference scene, one setting changed per rung.

Every rung is the scene with one knob turned from drumflow's defaults (or, for the reference
and the conservative rung, several): the time step as a fraction of the Rayleigh time, the
wall representation, Young's modulus softening, particle-size scaling at equal mass, the
coupling interval, MPI processes, the neighbour skin, the output step, conduction, and CFD
against uniform air. The reference is the finest of everything: 5% of the Rayleigh time and
the moving-mesh shell.
"""

from __future__ import annotations

import copy
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

from drumflow.case import FAST_PROFILE, case_from_dict

if TYPE_CHECKING:
    from drumflow.case import Case


@dataclass(frozen=True)
class Rung:
    """One setting of the ladder.

    Attributes
    ----------
    name
        Short identifier (folder name, CSV row).
    group
        The knob it turns (``time_step``, ``walls``, ...).
    description
        One line for the table.
    overrides
        ``"section.field": value`` applied to the scene.
    rayleigh_fraction
        Fixed time step as this fraction of the Rayleigh time (forced past drumflow's limit
        if needed: the ladder measures what lies beyond it).
    size_scale
        Particle diameter times this, count divided by its cube (equal total mass).
    modulus_scale
        Young's modulus times this (softening); the conduction contact area keeps referring
        to the original modulus.
    by_hand
        Run the DEM deck of the ``base`` rung directly with ``mpirun liggghts``, without
        drumflow (the Python and I/O overhead measurement).
    base
        For ``by_hand``: the rung whose deck is run.
    """

    name: str
    group: str
    description: str
    overrides: dict[str, Any] = field(default_factory=dict)
    rayleigh_fraction: float | None = None
    size_scale: float | None = None
    modulus_scale: float | None = None
    by_hand: bool = False
    base: str | None = None


REFERENCE = "reference"
CONSERVATIVE = "conservative"
DEFAULT = "default"
#: Same physics as the default, different round-off (domain decomposition): its differences
#: from the default are the scene's noise floor, what chaos alone changes.
NOISE_FLOOR = "mpi_2"


def ladder(case: Case) -> list[Rung]:
    """The rungs for a scene, reference first."""
    d = case.particles.diameter
    rungs = [
        Rung(REFERENCE, "reference", "5% of the Rayleigh time, moving-mesh shell (finest)",
             {"run.wall_motion": "moving_mesh"}, rayleigh_fraction=0.05),
        Rung(CONSERVATIVE, "conservative", "10% of the Rayleigh time, moving-mesh shell",
             {"run.wall_motion": "moving_mesh"}, rayleigh_fraction=0.10),
        Rung(DEFAULT, "default", "drumflow's defaults"),
    ]
    for f in (0.10, 0.20, 0.30, 0.40):
        rungs.append(Rung(f"dt_{round(f * 100)}pct", "time_step",
                          f"time step {f:.0%} of the Rayleigh time (static shell)", rayleigh_fraction=f))
    # The rule "auto" was until it respected the bed's spin limit, and the two ways back to its
    # step: without the tangential dashpot (no spin limit below the spring's), and the whole
    # fast profile (README, 'The fast profile'; at the case's fixed time, so that its errors
    # are those of the settings, not of where the converged stop fired).
    rungs.append(Rung("contact", "time_step", "time step 'contact': 10 steps per contact, "
                      "without the spin limit", {"run.time_step": "contact"}))
    rungs.append(Rung("no_tangential_damping", "contacts", "no tangential dashpot between "
                      "particles ('auto' then takes the contact step)",
                      {"contacts.tangential_damping": False}))
    rungs.append(Rung("fast", "profile", "the fast profile's settings (no tangential dashpot, no "
                      "conduction) at the fixed time",
                      {f"{section}.{name}": value for section, name, value in FAST_PROFILE
                       if (section, name) != ("run", "stop")}))
    rungs.append(Rung("moving_mesh", "walls", "moving-mesh shell at the default time step",
                      {"run.wall_motion": "moving_mesh"}))
    for s in (0.5, 0.2):
        rungs.append(Rung(f"E_x{s:g}", "modulus", f"Young's modulus x {s:g} (softened)", modulus_scale=s))
    for s in (1.25, 1.5):
        rungs.append(Rung(f"size_x{s:g}", "size", f"particles {s:g} x larger, same total mass",
                          size_scale=s))
    if case.air.model != "none":
        for n in (10, 100):
            rungs.append(Rung(f"coupling_{n}", "coupling", f"air updated every {n} steps",
                              {"air.coupling_interval": n}))
    rungs.append(Rung(NOISE_FLOOR, "mpi", "2 MPI processes", {"run.processes": 2}))
    for k in (0.25, 1.0):
        rungs.append(Rung(f"skin_{k:g}d", "skin", f"neighbour skin {k:g} particle diameters",
                          {"run.neighbor_skin": k * d}))
    dump = case.run.dump_interval
    for k in (0.5, 2.0):
        rungs.append(Rung(f"dump_x{k:g}", "output", f"output step {k * dump:g} s",
                          {"run.dump_interval": k * dump}))
    rungs.append(Rung("no_conduction", "conduction", "particle-particle conduction off",
                      {"run.conduction": False}))
    if case.air.model == "cfd":
        rungs.append(Rung("uniform_air", "air", "uniform plug-flow air instead of the CFD field",
                          {"air.model": "uniform"}))
    # The Python and I/O overhead: drumflow's DEM stage against the same deck by hand. The
    # comparison needs an uncoupled deck (with air, the coupling loop is physics, not overhead).
    rungs.append(Rung("no_air", "overhead", "default without air, run by drumflow",
                      {"air.model": "none"}))
    rungs.append(Rung("no_air_by_hand", "overhead", "the same deck run by hand (mpirun liggghts)",
                      by_hand=True, base="no_air"))
    return rungs


def apply_rung(case: Case, rung: Rung) -> Case:
    """The scene with the rung's settings (validated: a refused rung raises CaseError)."""
    from drumflow.dem.timestep import rayleigh_time

    data = copy.deepcopy(case.model_dump(mode="json"))
    data["name"] = f"{case.name}-{rung.name}"[:80]
    for key, value in rung.overrides.items():
        section, name = key.split(".")
        data[section][name] = value
    p = data["particles"]
    if rung.modulus_scale is not None:
        p["youngs_modulus"] = case.particles.youngs_modulus * rung.modulus_scale
        p["youngs_modulus_reference"] = (case.particles.youngs_modulus_reference
                                         or case.particles.youngs_modulus)
    if rung.size_scale is not None:
        s = rung.size_scale
        p["diameter"] = case.particles.diameter * s
        if case.particles.count is not None:
            # Equal total mass: the paper's own trick for affordable particle counts.
            p["count"] = max(1, round(case.particles.count / s**3))
    if rung.rayleigh_fraction is not None:
        t_r = rayleigh_time(0.5 * p["diameter"], p["density"], p["youngs_modulus"], p["poisson_ratio"])
        data["run"]["time_step"] = rung.rayleigh_fraction * t_r
        data["run"]["force_time_step"] = True
    return case_from_dict(data)


def select(rungs: list[Rung], names: list[str] | None, speed_only: bool = False) -> list[Rung]:
    """Only the named rungs (plus the reference, which every error needs, unless
    ``speed_only``, and a by-hand rung's base)."""
    if not names:
        return [r for r in rungs if not (speed_only and r.name == REFERENCE)]
    known = {r.name for r in rungs}
    unknown = [n for n in names if n not in known]
    if unknown:
        raise ValueError(f"unknown rung(s) {', '.join(unknown)}; known: {', '.join(sorted(known))}")
    wanted = set(names) if speed_only else set(names) | {REFERENCE}
    wanted |= {r.base for r in rungs if r.name in wanted and r.base}
    return [r for r in rungs if r.name in wanted]
