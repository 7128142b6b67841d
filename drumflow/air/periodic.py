"""Periodic axial air: the slice as a piece of a long drum, not a box with an inlet and an outlet.

Where the question is the plant (how much air goes round the bed and through the curtains), the
slice stands for any metre of a long cooler: the air that leaves its air-outlet end (z = 0) is
the air that enters the next slice's air-inlet end (z = l). With an inlet and an outlet the air
enters the slice as a plug over the whole cross-section and has only the slice's length to turn
aside (model one's 0.1 m slice: not at all); periodic, it is the flow developed along the drum.

How, with stock OpenFOAM v1912 (no compiled code):

- The fluid mesh's two end faces are meshed alike (gmsh ``setPeriodic``,
  :func:`drumflow.geometry.fluid.write_fluid_mesh` with ``periodic=True``) and coupled as a
  ``cyclicAMI`` pair translated by the section length. AMI rather than ``cyclic``: ``cyclic``
  needs the faces of the two patches in matching order, which gmshToFoam does not give and
  ``createPatch`` would have to sort; on conformal faces AMI's weights are exact.
- The flow is held at the plant's mean velocity by ``meanVelocityForce`` on every cell: the
  volume mean of U_z over a prism of constant cross-section equals the volume flow over the
  free area, so ``Ubar`` = (0, 0, -Q/A) sets the same flow as the inlet-outlet case's inlet.
  Its uniform pressure gradient (kinematic, m/s^2) is what pushes the air along one metre of the
  drum: :func:`read_pressure_gradient` reads it from ``<time>/uniform/``.
- With every boundary closed or coupled, the pressure needs a reference (``pRefCell``).
"""

from __future__ import annotations

import re
from pathlib import Path
from typing import Any, cast

from drumflow.errors import SolverError

__all__ = ["MOMENTUM_SOURCE", "PAIR", "make_periodic", "read_pressure_gradient"]

#: The patch pair made periodic: the air-inlet end (z = l) and the air-outlet end (z = 0).
PAIR = ("inlet", "outlet")
#: The name of the ``meanVelocityForce`` entry in ``system/fvOptions``.
MOMENTUM_SOURCE = "axialFlow"


def couple_patches(case_dir: Path, length: float) -> None:
    """Make the mesh's ``inlet`` and ``outlet`` patches one ``cyclicAMI`` pair, translated by
    ``length`` (m) along z, in ``constant/polyMesh/boundary``."""
    from foamlib import FoamFile

    boundary = FoamFile(case_dir / "constant" / "polyMesh" / "boundary")
    patches = cast(list[tuple[str, dict[str, Any]]], boundary[None])
    names = {name for name, _ in patches}
    if not set(PAIR) <= names:
        raise SolverError("gmshToFoam", [], None, None,
                          reason=f"periodic air needs patches {PAIR}; the mesh has {sorted(names)}")
    # separationVector: from this patch to its neighbour (the inlet end lies at z = l).
    separation = {"inlet": [0.0, 0.0, -float(length)], "outlet": [0.0, 0.0, float(length)]}
    new: list[tuple[str, dict[str, Any]]] = []
    for name, entry in patches:
        if name in separation:
            entry = {k: v for k, v in dict(entry).items()
                     if k in ("nFaces", "startFace")}
            entry.update({"type": "cyclicAMI", "inGroups": ["cyclicAMI"],
                          "neighbourPatch": PAIR[1] if name == PAIR[0] else PAIR[0],
                          "transform": "translational",
                          "separationVector": separation[name]})
        new.append((name, entry))
    boundary[None] = new


def make_periodic(case_dir: Path, length: float, bulk_velocity: float) -> None:
    """Turn a written drum air case (:func:`drumflow.air.foam_case.write_air_case`) periodic
    along its axis at the mean axial velocity ``bulk_velocity`` (m/s, along -z).

    The mesh's end patches are coupled (:func:`couple_patches`), every ``0/`` field's end
    conditions become ``cyclicAMI``, ``system/fvOptions`` gains the ``meanVelocityForce``
    :data:`MOMENTUM_SOURCE` (other entries, e.g. a bed's porosity, are kept), and
    ``system/fvSolution`` a pressure reference. Call it after everything else is written.
    """
    from foamlib import FoamFieldFile, FoamFile

    if not bulk_velocity > 0.0:
        raise ValueError(f"bulk_velocity must be > 0 m/s, got {bulk_velocity}")
    couple_patches(case_dir, length)
    for path in sorted((case_dir / "0").iterdir()):
        if not path.is_file():
            continue
        with FoamFieldFile(path) as f:
            boundary = cast(dict[str, Any], f.boundary_field)
            for name in PAIR:
                if name in boundary:
                    f[("boundaryField", name)] = {"type": "cyclicAMI"}
    with FoamFile(case_dir / "system" / "fvOptions") as f:
        f[MOMENTUM_SOURCE] = {
            "type": "meanVelocityForce",
            "active": True,
            "meanVelocityForceCoeffs": {
                "selectionMode": "all",
                "fields": ["U"],
                "Ubar": [0.0, 0.0, -float(bulk_velocity)],
            },
        }
    with FoamFile(case_dir / "system" / "fvSolution") as f:
        f[("SIMPLE", "pRefCell")] = 0
        f[("SIMPLE", "pRefValue")] = 0.0


_GRADIENT_RE = re.compile(r"pressure gradient = ([-+]?\d*\.?\d+(?:[eE][-+]?\d+)?)")


def read_pressure_gradient(case_dir: Path, time_dir: str) -> float:
    """The kinematic pressure gradient (m/s^2) that ``meanVelocityForce`` applied along -z in
    the solution ``time_dir``: from ``<time>/uniform/axialFlowProperties``, else the last value
    in ``log.simpleFoam``. Multiplied by the density it is the pressure drop per metre, Pa/m.

    Raises
    ------
    SolverError
        When neither holds the gradient (the case was not periodic).
    """
    from foamlib import FoamFile

    props = case_dir / time_dir / "uniform" / f"{MOMENTUM_SOURCE}Properties"
    if props.exists():
        return float(cast(float, FoamFile(props)["gradient"]))
    log = case_dir / "log.simpleFoam"
    found = _GRADIENT_RE.findall(log.read_text(errors="replace")) if log.exists() else []
    if not found:
        raise SolverError("simpleFoam", [], None, log if log.exists() else None,
                          reason=f"no meanVelocityForce gradient in {props} or {log}")
    return float(found[-1])
