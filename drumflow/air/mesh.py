"""OpenFOAM mesh of the drum's air: gmsh mesh -> ``gmshToFoam`` -> patch types -> ``checkMesh``.

Every OpenFOAM program runs through :class:`drumflow.runner.Runner` (logged, timed out, typed
errors) with ``WM_PROJECT_DIR`` set by the launch profile
(:meth:`drumflow.runner.LaunchProfile.openfoam_env`), because the Debian OpenFOAM v1912 binaries in /usr/bin
find their ``etc/`` files (``controlDict`` defaults, function-object templates) through it.

``gmshToFoam`` makes every physical surface group a plain ``patch``; wall functions and the MRF
treatment of walls need ``wall``, and 2D cases need ``empty``, so :func:`set_patch_types`
rewrites ``constant/polyMesh/boundary`` with foamlib afterwards.
"""

from __future__ import annotations

import re
from collections.abc import Mapping
from pathlib import Path
from typing import TYPE_CHECKING, Any, cast

from drumflow.errors import MeshCheckError, SolverError
from drumflow.runner import Runner

if TYPE_CHECKING:
    from drumflow.case import Case

def foam_check(returncode: int, lines: list[str]) -> str | None:
    """A :class:`Runner` ``check``: OpenFOAM can print ``FOAM FATAL`` and still exit 0."""
    for line in lines:
        if "FOAM FATAL" in line or "FOAM aborting" in line:
            return "OpenFOAM stopped with a fatal error"
    return None


def run_foam(
    runner: Runner,
    program: str,
    args: list[str],
    case_dir: Path,
    timeout: float | None = None,
    on_line: Any = None,
    log_name: str | None = None,
) -> Path:
    """Run an OpenFOAM program in ``case_dir``, logging to ``log.<program>``; return the log."""
    log = case_dir / (log_name or f"log.{program}")
    runner.run(
        program,
        [program, *args],
        cwd=case_dir,
        log=log,
        timeout=timeout,
        on_line=on_line,
        env=runner.profile.openfoam_env(),
        check=foam_check,
    )
    return log


def write_minimal_system(case_dir: Path, application: str = "simpleFoam") -> None:
    """Write placeholder ``system/`` dictionaries that are missing.

    Every OpenFOAM utility reads ``controlDict``, and checkMesh also opens ``fvSchemes`` and
    ``fvSolution``; the solver set-up overwrites all three later.
    """
    from foamlib import FoamFile

    system = case_dir / "system"
    system.mkdir(parents=True, exist_ok=True)
    if not (system / "controlDict").exists():
        with FoamFile(system / "controlDict") as f:
            f["application"] = application
            f["startFrom"] = "startTime"
            f["startTime"] = 0
            f["stopAt"] = "endTime"
            f["endTime"] = 1
            f["deltaT"] = 1
            f["writeControl"] = "timeStep"
            f["writeInterval"] = 1
    placeholders: dict[str, tuple[str, ...]] = {
        "fvSchemes": ("ddtSchemes", "gradSchemes", "divSchemes", "laplacianSchemes",
                      "interpolationSchemes", "snGradSchemes"),
        "fvSolution": ("solvers",),
    }
    for name, sections in placeholders.items():
        if not (system / name).exists():
            with FoamFile(system / name) as f:
                for section in sections:
                    f[section] = {}


def set_patch_types(case_dir: Path, types: Mapping[str, str]) -> dict[str, str]:
    """Set the ``type`` of named patches in ``constant/polyMesh/boundary``.

    ``physicalType`` (written by gmshToFoam) is dropped from a changed patch: it is only a
    hint, and a stale ``patch`` there would contradict the new type for a reader.

    Returns
    -------
    dict
        Patch name -> type after the change, for every patch.

    Raises
    ------
    SolverError
        When a named patch is not in the mesh (e.g. a missing physical group).
    """
    from foamlib import FoamFile

    boundary = FoamFile(case_dir / "constant" / "polyMesh" / "boundary")
    # The boundary file is one list of (name, dictionary) pairs; foamlib types it as a union.
    patches = cast(list[tuple[str, dict[str, Any]]], boundary[None])
    if not isinstance(patches, list):
        raise SolverError("gmshToFoam", [], None, None, reason="unreadable polyMesh/boundary")
    names = {name for name, _ in patches}
    missing = sorted(set(types) - names)
    if missing:
        raise SolverError(
            "gmshToFoam",
            [],
            None,
            None,
            reason=f"the mesh has no patch named {', '.join(missing)} (patches: {sorted(names)})",
        )
    new: list[tuple[str, dict[str, Any]]] = []
    for name, entry in patches:
        entry = dict(entry)
        if name in types and entry.get("type") != types[name]:
            entry["type"] = types[name]
            entry.pop("physicalType", None)
            entry.pop("inGroups", None)
        new.append((name, entry))
    boundary[None] = new
    return {name: str(entry["type"]) for name, entry in new}


def import_gmsh_mesh(
    msh: Path,
    case_dir: Path,
    runner: Runner,
    patch_types: Mapping[str, str],
    timeout: float | None = 600,
) -> dict[str, str]:
    """Convert an ASCII msh 2.2 file into ``case_dir/constant/polyMesh`` and fix patch types.

    Returns the patch types after the fix (see :func:`set_patch_types`).
    """
    write_minimal_system(case_dir)
    run_foam(runner, "gmshToFoam", [str(msh.resolve())], case_dir, timeout=timeout)
    return set_patch_types(case_dir, patch_types)


_CHECK_PATTERNS: dict[str, re.Pattern[str]] = {
    "cells": re.compile(r"^\s*cells:\s+(\d+)"),
    "faces": re.compile(r"^\s*faces:\s+(\d+)"),
    "points": re.compile(r"^\s*points:\s+(\d+)"),
    "max_non_orthogonality": re.compile(r"Mesh non-orthogonality Max:\s*([-+]?\d*\.?\d+(?:[eE][-+]?\d+)?)"),
    "max_skewness": re.compile(r"Max skewness\s*=\s*([-+]?\d*\.?\d+(?:[eE][-+]?\d+)?)"),
    "max_aspect_ratio": re.compile(r"Max aspect ratio\s*=\s*([-+]?\d*\.?\d+(?:[eE][-+]?\d+)?)"),
    "min_volume": re.compile(r"Min volume\s*=\s*([-+]?\d*\.?\d+(?:[eE][-+]?\d+)?)"),
    "total_volume": re.compile(r"Total volume\s*=\s*([-+]?\d*\.?\d+(?:[eE][-+]?\d+)?)"),
}


def parse_check_mesh(text: str) -> dict[str, Any]:
    """The headline numbers of a ``checkMesh`` log, and whether it ended with ``Mesh OK.``."""
    out: dict[str, Any] = {}
    for line in text.splitlines():
        for key, pat in _CHECK_PATTERNS.items():
            if key not in out:
                m = pat.search(line)
                if m:
                    value = m.group(1)
                    out[key] = int(value) if key in ("cells", "faces", "points") else float(value)
    failed = re.search(r"Failed (\d+) mesh checks", text)
    out["failed_checks"] = int(failed.group(1)) if failed else 0
    out["ok"] = "Mesh OK." in text and not failed
    return out


def check_mesh(case_dir: Path, runner: Runner, timeout: float | None = 600) -> dict[str, Any]:
    """Run ``checkMesh`` and return its numbers.

    Raises
    ------
    MeshCheckError
        When checkMesh reports failed checks (it exits 0 even then).
    """
    log = run_foam(runner, "checkMesh", [], case_dir, timeout=timeout)
    text = log.read_text(errors="replace")
    info = parse_check_mesh(text)
    if not info["ok"]:
        failures = [ln.strip() for ln in text.splitlines() if ln.lstrip().startswith("***")]
        raise MeshCheckError(
            "checkMesh",
            ["checkMesh"],
            0,
            log,
            failures[-1] if failures else None,
            reason=f"checkMesh failed {info['failed_checks']} mesh checks",
        )
    return info


def build_air_mesh(
    case: Case,
    case_dir: Path,
    runner: Runner,
    size: float | None = None,
    timeout: float | None = 600,
    periodic: bool = False,
) -> dict[str, Any]:
    """Mesh the drum's fluid with gmsh and turn it into a checked OpenFOAM polyMesh.

    Parameters
    ----------
    case
        The validated case.
    case_dir
        The OpenFOAM case directory (created).
    runner
        Starts gmshToFoam and checkMesh.
    size
        Bulk cell size, m; default ``air.mesh_size`` ('auto' = D/20).
    periodic
        End faces meshed alike, to be coupled (:mod:`drumflow.air.periodic`).

    Returns
    -------
    dict
        The gmsh statistics of :func:`drumflow.geometry.fluid.write_fluid_mesh`, plus
        ``patches`` (name -> type) and ``check`` (the checkMesh numbers).
    """
    from drumflow.geometry.fluid import write_fluid_mesh

    case_dir.mkdir(parents=True, exist_ok=True)
    msh = case_dir / "fluid.msh"
    info = write_fluid_mesh(case, msh, size=size, periodic=periodic)
    info["patches"] = import_gmsh_mesh(msh, case_dir, runner, {"walls": "wall"}, timeout=timeout)
    info["check"] = check_mesh(case_dir, runner, timeout=timeout)
    return info
