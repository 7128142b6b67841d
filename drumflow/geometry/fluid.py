"""The fluid (air) volume of the drum section as a tetrahedral gmsh mesh for OpenFOAM.

The fluid is the same cross-section as the DEM walls (shell disk minus the lifter plates,
:func:`drumflow.geometry.drum._build_cross_section`) extruded along +z over the section length
``l``. The air is counter-current: the drum axis runs from the feed end z = 0 to the material
outlet z = l, and the air enters at z = l and leaves at z = 0, so the physical groups are

========  =====================================================
inlet     the end face z = l (air in)
outlet    the end face z = 0 (air out)
walls     the shell and every lifter face
fluid     the volume
========  =====================================================

The file is ASCII msh 2.2, the only format OpenFOAM v1912's ``gmshToFoam`` reads.

Boundary layers: the paper meshed the 3 m drum with 0.03 m trimmed cells and 5 prism layers
(0.009 m thick, stretching 1.5). gmsh's 3D boundary-layer extrusion does not work reliably on
the lifters' sharp, re-entrant edges (folded or missing prisms at the lifter tips), so this mesh
has **no prism layers**. Instead the cell size falls towards the walls: a gmsh ``Distance``
field on the wall surfaces drives a ``Threshold`` field from ``wall_size`` (half the bulk size
by default) on the walls to the bulk size one bulk cell away. The air model then uses wall
functions (k-epsilon), which want the first cell centre in the log layer rather than resolved
viscous sublayers, so a moderately fine, isotropic near-wall tetrahedral layer is adequate.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Any

from drumflow.errors import GeometryError
from drumflow.physics.air import ideal_gas_density

if TYPE_CHECKING:
    from drumflow.case import Case

#: Near-wall cell size as a fraction of the bulk size (see the module docstring).
WALL_SIZE_FRACTION = 0.5



def _area_and_perimeter(surface: int) -> tuple[float, float]:
    """Area and perimeter of a synchronised OCC plane surface in the current gmsh model."""
    import gmsh

    area = gmsh.model.occ.getMass(2, surface)
    curves = gmsh.model.getBoundary([(2, surface)], oriented=False)
    perimeter = sum(gmsh.model.occ.getMass(1, abs(tag)) for _, tag in curves)
    return area, perimeter

def fluid_mesh_size(case: Case) -> float:
    """The bulk fluid cell size, m: ``air.mesh_size``, or drum diameter / 20 for ``"auto"``."""
    if case.air.mesh_size == "auto":
        return case.drum.diameter / 20.0
    return float(case.air.mesh_size)


def cross_section_properties(case: Case) -> dict[str, float]:
    """Area, wetted perimeter and hydraulic diameter of the free (air) cross-section.

    Computed by gmsh's OCC kernel on the same boolean cross-section as the meshes, so the
    plug-flow velocity of the uniform air model and the CFD's bulk velocity use one area.

    Returns
    -------
    dict
        ``area_m2``, ``perimeter_m`` and ``hydraulic_diameter_m`` (4 A / P).
    """
    import gmsh

    from drumflow.geometry.drum import _build_cross_section, _Gmsh

    with _Gmsh():
        gmsh.model.add("section")
        surface = _build_cross_section(gmsh.model, case)
        gmsh.model.occ.synchronize()
        area, perimeter = _area_and_perimeter(surface)
    return {
        "area_m2": float(area),
        "perimeter_m": float(perimeter),
        "hydraulic_diameter_m": float(4.0 * area / perimeter),
    }


def write_fluid_mesh(case: Case, path: Path, size: float | None = None,
                     periodic: bool = False) -> dict[str, Any]:
    """Mesh the fluid volume of the section with tetrahedra and write it as ASCII msh 2.2.

    Parameters
    ----------
    case
        The validated case (drum, lifters, ``air.mesh_size``).
    path
        The ``.msh`` file to write (parent folders are created).
    size
        Bulk cell size, m; default :func:`fluid_mesh_size`. The walls get
        ``WALL_SIZE_FRACTION * size``.
    periodic
        Mesh the inlet face as a copy of the outlet face moved by the section length (gmsh
        ``setPeriodic``), so that the two can be coupled face to face
        (:mod:`drumflow.air.periodic`).

    Returns
    -------
    dict
        ``cells`` (tetrahedra), ``nodes``, ``size_m`` (bulk), ``wall_size_m``,
        ``volume_m3`` (of the fluid, from the geometry), ``area_m2``, ``perimeter_m`` and
        ``hydraulic_diameter_m`` of the free cross-section, and the face counts of the
        ``inlet``, ``outlet`` and ``walls`` groups.

    Raises
    ------
    GeometryError
        When gmsh cannot split the boundary into inlet, outlet and walls or produces no
        tetrahedra.
    """
    import gmsh

    from drumflow.geometry.drum import _build_cross_section, _Gmsh

    size = fluid_mesh_size(case) if size is None else float(size)
    if not size > 0:
        raise GeometryError(f"fluid mesh size must be positive, got {size}")
    wall_size = WALL_SIZE_FRACTION * size
    length = case.drum.length
    tol = 1e-6 * max(length, 1.0)
    path.parent.mkdir(parents=True, exist_ok=True)
    with _Gmsh():
        gmsh.model.add("fluid")
        surface = _build_cross_section(gmsh.model, case)
        gmsh.model.occ.synchronize()
        area, perimeter = _area_and_perimeter(surface)
        out = gmsh.model.occ.extrude([(2, surface)], 0.0, 0.0, length)
        gmsh.model.occ.synchronize()
        volumes = [tag for dim, tag in out if dim == 3]
        if len(volumes) != 1:
            raise GeometryError(f"extruding the cross-section gave {len(volumes)} volumes, not 1")
        groups: dict[str, list[int]] = {"inlet": [], "outlet": [], "walls": []}
        for _, tag in gmsh.model.getEntities(2):
            _, _, zmin, _, _, zmax = gmsh.model.getBoundingBox(2, tag)
            if zmin > length - tol:
                groups["inlet"].append(tag)  # z = l: the counter-current air enters here
            elif zmax < tol:
                groups["outlet"].append(tag)
            else:
                groups["walls"].append(tag)
        if not all(groups.values()):
            empty = [k for k, v in groups.items() if not v]
            raise GeometryError(f"fluid mesh: no surfaces found for {', '.join(empty)}")
        for name, tags in groups.items():
            gmsh.model.addPhysicalGroup(2, tags, name=name)
        gmsh.model.addPhysicalGroup(3, volumes, name="fluid")
        if periodic:
            # The inlet (z = l) takes the outlet's (z = 0) surface mesh, moved by l along z.
            shift = [1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0, length,
                     0.0, 0.0, 0.0, 1.0]
            gmsh.model.mesh.setPeriodic(2, groups["inlet"], groups["outlet"], shift)

        # Finer cells at the walls through a distance field (no prism layers, see above).
        mf = gmsh.model.mesh.field
        dist = mf.add("Distance")
        mf.setNumbers(dist, "SurfacesList", groups["walls"])
        mf.setNumber(dist, "Sampling", 40)
        thr = mf.add("Threshold")
        mf.setNumber(thr, "InField", dist)
        mf.setNumber(thr, "SizeMin", wall_size)
        mf.setNumber(thr, "SizeMax", size)
        mf.setNumber(thr, "DistMin", 0.0)
        mf.setNumber(thr, "DistMax", size)
        mf.setAsBackgroundMesh(thr)
        # The field alone sets sizes: boundary-point sizes and curvature would otherwise
        # propagate the lifters' 4 mm thickness far into the volume.
        gmsh.option.setNumber("Mesh.MeshSizeExtendFromBoundary", 0)
        gmsh.option.setNumber("Mesh.MeshSizeFromPoints", 0)
        gmsh.option.setNumber("Mesh.MeshSizeFromCurvature", 0)
        gmsh.option.setNumber("Mesh.MeshSizeMax", size)
        gmsh.option.setNumber("Mesh.MeshSizeMin", min(wall_size, case.lifters.thickness))
        gmsh.option.setNumber("Mesh.Algorithm", 6)  # Frontal-Delaunay surfaces
        gmsh.option.setNumber("Mesh.Algorithm3D", 1)  # Delaunay volumes: robust and fast
        gmsh.option.setNumber("Mesh.Optimize", 1)  # remove slivers (checkMesh skewness)
        # Netgen's optimiser halves the worst skewness and aspect ratio next to the lifters
        # (on the 0.4 m smoke drum at 0.03 m: skewness 2.0 -> 1.2, aspect ratio 17 -> 9).
        gmsh.option.setNumber("Mesh.OptimizeNetgen", 1)
        gmsh.option.setNumber("Mesh.MshFileVersion", 2.2)
        gmsh.option.setNumber("Mesh.Binary", 0)  # gmshToFoam reads ASCII only
        gmsh.option.setNumber("Mesh.SaveAll", 0)  # only the physical groups
        gmsh.model.mesh.generate(3)
        counts: dict[str, int] = {}
        for name, tags in (*groups.items(), ("fluid", volumes)):
            dim = 3 if name == "fluid" else 2
            n = 0
            for tag in tags:
                etypes, elem_tags, _ = gmsh.model.mesh.getElements(dim, tag)
                n += sum(len(t) for t in elem_tags)
            counts[name] = n
        node_tags, _, _ = gmsh.model.mesh.getNodes()
        if counts["fluid"] == 0:
            raise GeometryError("gmsh produced no tetrahedra for the fluid volume")
        gmsh.write(str(path))
    return {
        "cells": counts["fluid"],
        "nodes": int(len(node_tags)),
        "size_m": size,
        "wall_size_m": wall_size,
        "volume_m3": float(area * length),
        "area_m2": float(area),
        "perimeter_m": float(perimeter),
        "hydraulic_diameter_m": float(4.0 * area / perimeter),
        "inlet_faces": counts["inlet"],
        "outlet_faces": counts["outlet"],
        "wall_faces": counts["walls"],
        "path": str(path),
    }


def bulk_velocity(case: Case, area: float | None = None) -> float:
    """Mean axial air speed through the free cross-section, mdot / (rho A), m/s.

    ``rho`` is the ideal-gas density at the inlet temperature and pressure
    (:func:`air_density`); ``area`` defaults to :func:`cross_section_properties`.
    """
    if area is None:
        area = cross_section_properties(case)["area_m2"]
    return case.air.mass_flow / (air_density(case) * area)


def air_density(case: Case) -> float:
    """Ideal-gas air density at the inlet, rho = p / (R_air T), kg/m^3.

    The air is treated as incompressible at this density (the paper: "constant density gas").
    """
    return ideal_gas_density(case.air.inlet_temperature_C, case.air.pressure_kPa)
