"""The registry of validation scenes: name, source, what is measured, the set-up.

A scene is registered with the citation of its experiment, the observables it compares and
its set-up choices (each with a source), written down before any comparison and never tuned
against the measurement. ``drumflow validate --list`` prints this registry.
"""

from __future__ import annotations

from dataclasses import dataclass

from drumflow.validate import particle_curtain, rolling_drum
from drumflow.validate.errors import ValidationDataError
from drumflow.validate.rolling_drum import SetupChoice


@dataclass(frozen=True)
class Scene:
    """One experiment to compare against.

    Attributes
    ----------
    name
        The name ``drumflow validate NAME`` takes.
    title
        One line: what the scene is.
    source
        The citation of the measurement (and of the copy of the data drumflow ships).
    measures
        The observables compared.
    setup
        The set-up choices, each with its source.
    scales
        The scales it runs at (first: the default).
    """

    name: str
    title: str
    source: str
    measures: tuple[str, ...]
    setup: tuple[SetupChoice, ...]
    scales: tuple[str, ...]


ROLLING_DRUM = Scene(
    name="rolling_drum",
    title="rolling drum measured by radioactive particle tracking: 3 mm glass beads, R = 0.12 m, "
          "11.6 rpm, a third full",
    source="M. Alizadeh, O. Dube, F. Bertrand, J. Chaouki, AIChE J. 59 (2013) 1894-1905; "
           "digitised points from the Lethe project, examples/dem/3d-rotating-drum/data_exp.csv "
           "(github.com/chaos-polymtl/lethe)",
    measures=("velocity parallel to the free surface along the normal line through the axis",
              "surface velocity (largest velocity of the profile)",
              "flowing-layer depth (where the velocity changes sign)",
              "velocity near the wall (deepest measured point, -0.113 m)"),
    setup=rolling_drum.SETUP,
    scales=rolling_drum.SCALES,
)

PARTICLE_CURTAIN = Scene(
    name="particle_curtain",
    title="sand curtain (204 um) falling 0.6 m through warm air crossing a duct at 0.9-1.2 m/s: "
          "the six experiments of Figures 3-8, CFD-DEM beside the reduced-order curtain model",
    source="F. Wardjiman, M. Rhodes, Powder Technology 191 (2009), Figures 3-8 and Section 2 "
           "(../shared/reference/wardjiman-rhodes-2009-curtain.md; its measured points and "
           "Table 3 are not in drumflow's copy)",
    measures=("heat duty, solids and gas sides (W)",
              "solids outlet temperature (mixed, at the duct floor)",
              "gas outlet temperature (mixed, downstream of the curtain)",
              "the curtain's speed and drift at the duct floor; temperature and speed over the height"),
    setup=particle_curtain.SETUP,
    scales=particle_curtain.SCALES,
)

#: Every scene, by name.
SCENES: dict[str, Scene] = {s.name: s for s in (ROLLING_DRUM, PARTICLE_CURTAIN)}


def scene(name: str) -> Scene:
    """The scene called ``name``.

    Raises
    ------
    ValidationDataError
        No scene has that name (the message lists the names).
    """
    try:
        return SCENES[name]
    except KeyError:
        raise ValidationDataError(
            f"validation scene {name!r}: unknown; allowed: {', '.join(sorted(SCENES))}") from None
