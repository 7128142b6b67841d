"""The air velocity field on a regular grid in the drum frame, for fast sampling at particles.

The steady MRF solution (:mod:`drumflow.air.foam`) is steady in the frame that turns with the
drum, so it is resampled **once** from the OpenFOAM cell centres onto a regular grid in that
frame (x, y across the drum, z along the axis, covering the whole drum), and every later query
is a vectorised trilinear interpolation on the grid: no mesh search, no VTK.

Frames and velocities: the grid holds the **absolute** (laboratory-frame) air velocity, with
its components along the drum-frame axes. A particle at lab position ``x`` at time ``t`` sits
at drum-frame position ``R(-omega t) x`` (the drum turns counter-clockwise about +z, as the
LIGGGHTS shell does); the sampled velocity turns back to lab components by ``R(+omega t)``.
:func:`~drumflow.physics.drum_frame.rotate_to_drum_frame`,
:func:`~drumflow.physics.drum_frame.rotate_to_lab_frame` and :meth:`AirField.sample_lab` do this.
The air flows towards -z (it enters at z = l).

Grid nodes that are not in the fluid (inside a lifter plate or outside the shell) take the
value of the nearest fluid cell (:class:`scipy.spatial.cKDTree`), so trilinear interpolation
next to a wall never blends in zeros or garbage, and a particle touching a wall sees the air
just beside it. Fluid nodes get a weighted linear least-squares fit to their nearest cell
centres and inlet/outlet face centres (:func:`~drumflow.air.field_grid.local_linear_fit`:
exact for linear fields, clipped to the neighbours' range so it never overshoots near walls).
The walls' own no-slip values are not used, see :meth:`AirField.from_solution`.
"""

from __future__ import annotations

import hashlib
import json
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from drumflow.air.field_grid import fluid_mask_xy, grid_axes, grid_spacing, local_linear_fit
from drumflow.physics.drum_frame import drum_angle, rotate_to_drum_frame, rotate_to_lab_frame

if TYPE_CHECKING:
    from drumflow.air.foam import AirSolution
    from drumflow.case import Case

#: Version of the resampling and file layout; part of :func:`air_cache_key`, so a changed
#: algorithm never reuses an old cached field.
FIELD_FORMAT_VERSION = 1



# -- frames ----------------------------------------------------------------------------


# -- cache key -------------------------------------------------------------------------


def air_cache_key(case: Case) -> str:
    """SHA-256 of everything the air field depends on.

    Included: the drum (diameter, length, rpm), the lifters, and the air settings. Left out,
    because the air field does not depend on them: the particles and contacts (one-way
    coupling: particles do not act on the air), the run settings, ``drum.facet_size`` and
    ``drum.tilt_deg`` (the DEM wall STL and gravity's direction; the air model has no gravity),
    ``drum.ends`` (the particles' end walls; the air passes the end faces in every case),
    and of the air section ``coupling_interval``, ``pressure_gradient_force``, ``heat_capacity``,
    ``warming`` and ``bed_states`` (they act only on the particle side, on the air's
    temperature, or, the bed states, on fields keyed apart by the air stage; a field option
    added later must be left out too, or every cached field and every run keyed on one is
    recomputed). The resampling version :data:`FIELD_FORMAT_VERSION` is part of
    the key.
    """
    data = case.model_dump(mode="json")
    # drum.ends: what closes the section for the particles (planes, turning plates or a
    # periodic wrap); the air enters and leaves through the end faces in every case.
    drum = {k: v for k, v in data["drum"].items() if k not in ("facet_size", "tilt_deg", "ends")}
    air = {
        k: v
        for k, v in data["air"].items()
        if k not in ("coupling_interval", "pressure_gradient_force", "heat_capacity", "warming",
                     "bed_states")
    }
    key = {
        "version": FIELD_FORMAT_VERSION,
        "drum": drum,
        "lifters": data["lifters"],
        "air": air,
    }
    return hashlib.sha256(json.dumps(key, sort_keys=True).encode()).hexdigest()



@dataclass
class AirField:
    """Air velocity (and pressure) on a regular drum-frame grid, with trilinear sampling.

    Attributes
    ----------
    origin
        The grid's lowest corner (x, y, z), m.
    spacing
        Node spacing along x, y, z, m.
    velocity
        (nx, ny, nz, 3) absolute air velocity, drum-frame components, m/s.
    pressure
        (nx, ny, nz) static gauge pressure relative to the outlet, Pa (zeros for plug flow).
    fluid
        (nx, ny, nz) True at nodes inside the air volume.
    omega
        The drum's angular speed, rad/s (the frame rotation for :meth:`sample_lab`).
    meta
        Provenance: model, cache key, the CFD summary, the resampling statistics.
    """

    origin: NDArray[np.float64]
    spacing: NDArray[np.float64]
    velocity: NDArray[np.float64]
    pressure: NDArray[np.float64]
    fluid: NDArray[np.bool_]
    omega: float
    meta: dict[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        self.origin = np.asarray(self.origin, dtype=float).reshape(3)
        self.spacing = np.asarray(self.spacing, dtype=float).reshape(3)
        self.velocity = np.ascontiguousarray(self.velocity, dtype=float)
        if self.velocity.ndim != 4 or self.velocity.shape[3] != 3:
            raise ValueError(f"velocity must be (nx, ny, nz, 3), got {self.velocity.shape}")
        if min(self.velocity.shape[:3]) < 2:
            raise ValueError("the grid needs at least 2 nodes along each axis")
        self.pressure = np.ascontiguousarray(self.pressure, dtype=float)
        self.fluid = np.asarray(self.fluid, dtype=bool)
        self._prepare()

    def _prepare(self) -> None:
        # Sampling state: a flat (N, 3) view, the index strides of a C-ordered grid and the
        # largest valid lower-corner index per axis.
        nx, ny, nz = self.velocity.shape[:3]
        self._flat = self.velocity.reshape(-1, 3)
        self._pflat = self.pressure.reshape(-1)
        self._shape = np.array([nx, ny, nz])
        self._strides = (ny * nz, nz, 1)
        self._inv = 1.0 / self.spacing
        self._max_base = self._shape - 2

    @property
    def shape(self) -> tuple[int, int, int]:
        """Nodes along x, y, z."""
        nx, ny, nz = self.velocity.shape[:3]
        return (int(nx), int(ny), int(nz))

    def axes(self) -> list[NDArray[np.float64]]:
        """The node coordinates along x, y and z."""
        return [self.origin[i] + self.spacing[i] * np.arange(n) for i, n in enumerate(self.shape)]

    # -- sampling ----------------------------------------------------------------------
    def _corners(
        self, points: NDArray[np.float64]
    ) -> tuple[NDArray[np.intp], NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
        p = np.asarray(points, dtype=float)
        if p.ndim != 2 or p.shape[1] != 3:
            raise ValueError(f"points must be (n, 3), got {p.shape}")
        g = p - self.origin
        g *= self._inv
        # Points outside the grid take the value at its faces (constant extrapolation).
        np.clip(g, 0.0, self._shape - 1, out=g)
        i = g.astype(np.intp)
        np.minimum(i, self._max_base, out=i)
        g -= i  # now the fractions within the cell
        sx, sy, _ = self._strides
        base = i[:, 0] * sx
        base += i[:, 1] * sy
        base += i[:, 2]
        return base, g[:, 0:1], g[:, 1:2], g[:, 2:3]

    def sample(self, points: NDArray[np.float64]) -> NDArray[np.float64]:
        """Trilinear air velocity at (n, 3) drum-frame points, m/s, shape (n, 3).

        Exact for a field linear in x, y, z. Points outside the grid are clamped to it.
        """
        base, fx, fy, fz = self._corners(points)
        v = self._flat
        sx, sy, _ = self._strides

        # np.take along axis 0 is several times faster than fancy indexing v[base] for
        # (N, 3) rows; the 8 corner gathers dominate the cost.
        def lerp_z(b: NDArray[np.intp]) -> NDArray[np.float64]:
            lo = np.take(v, b, axis=0)
            hi = np.take(v, b + 1, axis=0)
            hi -= lo
            hi *= fz
            lo += hi
            return lo

        c0 = lerp_z(base)
        c1 = lerp_z(base + sy)
        c1 -= c0
        c1 *= fy
        c0 += c1
        base += sx
        d0 = lerp_z(base)
        d1 = lerp_z(base + sy)
        d1 -= d0
        d1 *= fy
        d0 += d1
        d0 -= c0
        d0 *= fx
        c0 += d0
        return c0

    def sample_pressure(self, points: NDArray[np.float64]) -> NDArray[np.float64]:
        """Trilinear gauge pressure at (n, 3) drum-frame points, Pa, shape (n,)."""
        base, fx, fy, fz = self._corners(points)
        p = self._pflat
        sx, sy, _ = self._strides
        fx, fy, fz = fx[:, 0], fy[:, 0], fz[:, 0]

        def lerp_z(b: NDArray[np.intp]) -> NDArray[np.float64]:
            a = p[b]
            return a + fz * (p[b + 1] - a)

        c0 = lerp_z(base)
        c0 = c0 + fy * (lerp_z(base + sy) - c0)
        c1 = lerp_z(base + sx)
        c1 = c1 + fy * (lerp_z(base + sx + sy) - c1)
        return c0 + fx * (c1 - c0)

    def sample_lab(self, points: NDArray[np.float64], time_s: float) -> NDArray[np.float64]:
        """Air velocity in lab components at (n, 3) lab-frame points at time ``time_s``."""
        angle = drum_angle(self.omega, time_s)
        return rotate_to_lab_frame(self.sample(rotate_to_drum_frame(points, angle)), angle)

    def mean_axial_velocity(self) -> float:
        """Mean of -U_z over the fluid nodes, m/s (positive in the air's flow direction)."""
        return float(-self.velocity[..., 2][self.fluid].mean())

    # -- constructors ------------------------------------------------------------------
    @classmethod
    def from_cells(
        cls,
        centres: NDArray[np.float64],
        velocity: NDArray[np.float64],
        case: Case,
        pressure: NDArray[np.float64] | None = None,
        spacing: float | None = None,
        meta: dict[str, Any] | None = None,
        boundary_points: NDArray[np.float64] | None = None,
        boundary_velocity: NDArray[np.float64] | None = None,
    ) -> AirField:
        """Resample cell-centred data onto the drum grid (see the module docstring).

        Parameters
        ----------
        centres
            (n, 3) cell centres in the drum frame, m.
        velocity
            (n, 3) cell velocities (absolute), m/s.
        case
            The case (drum size, lifters, omega).
        pressure
            (n,) cell pressures, Pa; zeros when omitted.
        spacing
            Grid spacing, m; default :func:`grid_spacing`.
        meta
            Extra provenance for :attr:`meta`.
        boundary_points, boundary_velocity
            Optional (m, 3) boundary face centres and their velocities, added to the support
            of the fit (their pressure is that of the nearest cell).
        """
        from scipy.spatial import cKDTree

        t0 = time.perf_counter()
        centres = np.asarray(centres, dtype=float)
        velocity = np.asarray(velocity, dtype=float)
        n = len(centres)
        p_cells = np.zeros(n) if pressure is None else np.asarray(pressure, dtype=float)
        h = grid_spacing(case) if spacing is None else float(spacing)
        axes, lo, step = grid_axes(case, h)
        X, Y = np.meshgrid(axes[0], axes[1], indexing="ij")
        mask2d = fluid_mask_xy(case, X, Y)
        nx, ny, nz = len(axes[0]), len(axes[1]), len(axes[2])
        fluid = np.broadcast_to(mask2d[:, :, None], (nx, ny, nz)).copy()
        G = np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, 3)
        values = np.column_stack([velocity, p_cells])
        tree = cKDTree(centres)
        support, support_values = centres, values
        if boundary_points is not None and len(boundary_points):
            bp = np.asarray(boundary_points, dtype=float)
            bv = np.asarray(boundary_velocity, dtype=float)
            _, near = tree.query(bp)
            support = np.concatenate([centres, bp])
            support_values = np.concatenate([values, np.column_stack([bv, p_cells[near]])])
        out = np.empty((len(G), 4))
        flat_fluid = fluid.reshape(-1)
        out[flat_fluid] = local_linear_fit(
            support, support_values, G[flat_fluid], tree=cKDTree(support)
        )
        # Solid and outside nodes: nearest fluid cell (cell centres only: a face's value is
        # not "the air beside it").
        solid = ~flat_fluid
        _, nearest = tree.query(G[solid])
        out[solid] = values[nearest]
        info = {
            "model": "cfd",
            "cells": int(n),
            "grid_nodes": int(len(G)),
            "fluid_nodes": int(flat_fluid.sum()),
            "resample_s": time.perf_counter() - t0,
            "key": air_cache_key(case),
        }
        info.update(meta or {})
        return cls(
            origin=lo,
            spacing=step,
            velocity=out[:, :3].reshape(nx, ny, nz, 3),
            pressure=out[:, 3].reshape(nx, ny, nz),
            fluid=fluid,
            omega=case.drum.omega,
            meta=info,
        )

    @classmethod
    def from_solution(
        cls, solution: AirSolution, case: Case, spacing: float | None = None
    ) -> AirField:
        """The grid field of a finished OpenFOAM solution (:func:`drumflow.air.foam.solve_air`).

        The support points are the cell centres and the inlet and outlet face centres (so the
        end planes z = 0 and z = l are interpolated, not extrapolated). The
        walls' no-slip values are left out on purpose: with wall functions the first cell's
        velocity holds through the log layer, so blending linearly from it to the wall's
        velocity would slow the air wrongly within a cell of every wall (on the smoke drum
        the grid's mean axial velocity fell by 2 % that way); near walls the fit extrapolates
        from the cells, bounded by their values. The kinematic pressure of simpleFoam is turned into Pa with
        the solution's density.
        """
        from drumflow.air.foam import read_boundary_values, read_cell_fields

        cells = read_cell_fields(solution.case_dir, solution.time_dir)
        bp, bv = read_boundary_values(solution.case_dir, solution.time_dir, solution.omega)
        return cls.from_cells(
            cells["C"],
            cells["U"],
            case,
            pressure=cells["p"] * solution.density,
            spacing=spacing,
            meta={"solution": solution.summary()},
            boundary_points=bp,
            boundary_velocity=bv,
        )

    @classmethod
    def uniform(cls, case: Case, spacing: float | None = None) -> AirField:
        """Plug flow at the mean axial speed mdot / (rho A_free) towards -z (no CFD).

        ``rho`` is the ideal-gas density at the inlet (:func:`drumflow.geometry.fluid.air_density`)
        and ``A_free`` the free cross-section (shell disk minus lifters).
        """
        from drumflow.geometry.fluid import air_density, cross_section_properties

        area = cross_section_properties(case)["area_m2"]
        rho = air_density(case)
        u = case.air.mass_flow / (rho * area)
        h = grid_spacing(case) if spacing is None else float(spacing)
        axes, lo, step = grid_axes(case, h)
        X, Y = np.meshgrid(axes[0], axes[1], indexing="ij")
        nx, ny, nz = len(axes[0]), len(axes[1]), len(axes[2])
        fluid = np.broadcast_to(fluid_mask_xy(case, X, Y)[:, :, None], (nx, ny, nz)).copy()
        velocity = np.zeros((nx, ny, nz, 3))
        velocity[..., 2] = -u
        return cls(
            origin=lo,
            spacing=step,
            velocity=velocity,
            pressure=np.zeros((nx, ny, nz)),
            fluid=fluid,
            omega=case.drum.omega,
            meta={
                "model": "uniform",
                "density_kg_m3": rho,
                "free_area_m2": area,
                "mean_axial_velocity_m_s": u,
                "key": air_cache_key(case),
            },
        )

    # -- cache files -------------------------------------------------------------------
    def to_npz(self, path: Path) -> None:
        """Write the field to a compressed ``.npz`` (no pickles: safe to load)."""
        path = Path(path)
        path.parent.mkdir(parents=True, exist_ok=True)
        tmp = path.with_name(path.name + ".tmp.npz")
        np.savez_compressed(
            tmp,
            format_version=np.array(FIELD_FORMAT_VERSION),
            origin=self.origin,
            spacing=self.spacing,
            velocity=self.velocity,
            pressure=self.pressure,
            fluid=self.fluid,
            omega=np.array(self.omega),
            meta=np.array(json.dumps(self.meta, default=str)),
        )
        # Atomic replace: a reader (another run sharing the cache) never sees half a file.
        tmp.replace(path)

    @classmethod
    def from_npz(cls, path: Path) -> AirField:
        """Read a field written by :meth:`to_npz`.

        Raises
        ------
        BadFileError
            When the file is missing, cut short or not an air field (a missing array named),
            or was written by another :data:`FIELD_FORMAT_VERSION`.
        """
        from drumflow.errors import BadFileError
        from drumflow.readers import read_npz

        what = "the run's air field"
        z = read_npz(path, what)
        missing = [k for k in ("format_version", "origin", "spacing", "velocity", "pressure",
                               "fluid", "omega", "meta") if k not in z]
        if missing:
            raise BadFileError(path, f"not an air field: no array(s) {', '.join(missing)}", what)
        version = int(z["format_version"])
        if version != FIELD_FORMAT_VERSION:
            raise BadFileError(path, f"air field format {version}, this drumflow reads "
                               f"{FIELD_FORMAT_VERSION}; delete the file to recompute it", what)
        try:
            meta = json.loads(str(z["meta"]))
        except json.JSONDecodeError as exc:
            raise BadFileError(path, f"its meta entry is not JSON ({exc.msg})", what) from None
        return cls(
            origin=z["origin"],
            spacing=z["spacing"],
            velocity=z["velocity"],
            pressure=z["pressure"],
            fluid=z["fluid"],
            omega=float(z["omega"]),
            meta=meta,
        )
