"""Air that warms: the air's temperature with the particles' heat as its source (issue 31).

The one-way air keeps its inlet temperature everywhere, so every particle sees 30 C air however
much heat the air upstream has taken. With ``air.warming = true`` the coupling loop solves the
air's temperature on the air field's own grid (:class:`~drumflow.air.field.AirField`: the
OpenFOAM solution resampled, or plug flow), with the air's own flow, at every air update:

* **Cells and fluxes.** Each fluid node of the grid is a finite volume (a box of the grid
  spacing). The volume flux through a face between two fluid nodes is the mean of their
  velocity components normal to it times the face area; faces towards a wall (a non-fluid node,
  the shell, a lifter) carry nothing; the nodes at z = l take the inlet flux, those at z = 0 the
  outlet's. The resampled velocities are not discretely divergence-free, so the face fluxes are
  projected onto the nearest divergence-free set (least squares: one sparse Poisson solve, the
  inlet fluxes held, the outlet free), once per run. Then the air's enthalpy is conserved to the
  solver's round-off: what the particles give, the air carries out.
* **Transport.** Steady advection with first-order upwind fluxes and the air's molecular
  conduction between neighbouring cells (which only matters where the air stands still), for
  the heat the particles gave over the last interval: quasi-steady, because the air crosses a
  slice in a few hundredths of a second (0.1 m at 3 m/s), while the particles' temperatures move
  by 0.1 % of their excess between updates. The matrix depends only on the flow, so it is
  solved by BiCGSTAB preconditioned by its lines along the drum's axis: the tridiagonal part of
  the matrix in the cells' own order, which holds the advection along the axis (the air's main
  flow) and the particles' conductance exactly, leaving the cross-flow and conduction to the
  iteration. Measured side by side (``studies/bench_air_heat.py``,
  ``results/bench/air_heat/results.json``: one update, both solves, median of 60): on the
  curtain scene's duct with 22,000 parcels 0.015 s against 0.108 s for the incomplete LU of the
  transport from the inlet temperature (which leaves the particles out of the preconditioner),
  on model two's 0.053 m grid (50,800 cells) with a moving bed 0.068 s against 2.31 s (11
  iterations against 79). Should the lines not converge on a system, the incomplete LU of the
  transport takes over for the rest of the run on that system only: the transport alone (the
  bookkeeping's system) has no particles on its diagonal, and where the air stands nearly still
  (inside a bed the air goes around, on a grid of a few cells along the axis) the lines miss
  the cross-flow that then carries the heat; the incomplete LU, built once, takes a few
  iterations from the implicit solve's field, while the implicit solve keeps its lines (in
  model one's first run of air around the bed one switch moved both systems, and every update
  then took some 70 iterations of the incomplete LU: 1.31 s per update against 0.125 s, replayed
  on that run's grid and particles, ``studies/bench_air_heat.py --replay``).
  Each solve starts from the last one's field: the bookkeeping's solve (the heat the particles
  actually gave, as a source) follows the implicit one on the same system when the particles
  are lumped, so it starts converged.
  Density and heat capacity are the inlet air's (a 30 K rise changes the density by 10 %, which
  moves the air's mass flux nowhere: the flux is fixed by the inlet).
* **Particles and cells.** A particle gives its heat to, and sees the air of, the cell of its
  nearest fluid node (the smoothing length is the grid spacing, ``grid_spacing``); a particle
  beside a wall goes to the nearest fluid node. Positions are in the drum's frame, as the
  velocity is sampled (:func:`~drumflow.physics.drum_frame.rotate_to_drum_frame`).

The energy bookkeeping (:meth:`AirHeat.enthalpy_gain`) is the outlet's enthalpy flux against the
inlet's, from the solved field: it equals the source to round-off by conservation, which the
coupling log records per update. The physics check is :mod:`drumflow.verify.air_heat` (a
plug-flow column of particles against the epsilon-NTU solution).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
from numpy.typing import NDArray
from scipy.linalg import lapack
from scipy.sparse.csgraph import connected_components
from scipy.sparse.linalg import LinearOperator, bicgstab, cg, spilu
from scipy.spatial import cKDTree

from drumflow.air.field import AirField

__all__ = ["AIR_CONDUCTIVITY", "AirHeat", "coarse_field"]

#: BiCGSTAB iterations the lines' preconditioner is given before the incomplete LU takes over
#: (an update took 5 on the curtain's grid and 11 on model two's, where the incomplete LU took
#: 79: results/bench/air_heat).
LINE_ITERATIONS = 100

#: Molecular conductivity of air near 30 C, W/(m K) (Incropera Table A.4 at 300 K: 0.0263): it
#: only closes cells the flow does not cross.
AIR_CONDUCTIVITY = 0.0263


def coarse_field(field: AirField, spacing: float) -> AirField:
    """The field on a grid of about ``spacing`` over the same box (no finer than the field's).

    The sampling grid is a quarter of the CFD cell for accurate velocities at the particles;
    the air's temperature needs no finer grid than the CFD's own cells, and a grid 4 times
    coarser along each axis has 64 times fewer cells to solve at every update. Velocities are
    sampled from the field (trilinear), the fluid mask from its nearest node.
    """
    lo = field.origin
    hi = field.origin + field.spacing * (np.array(field.shape) - 1)
    n = np.maximum(2, np.ceil((hi - lo) / max(spacing, float(field.spacing.min())) - 1e-9).astype(int) + 1)
    if np.all(n >= np.array(field.shape)):
        return field
    axes = [np.linspace(lo[i], hi[i], n[i]) for i in range(3)]
    grid = np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, 3)
    velocity = field.sample(grid).reshape(*n, 3)
    nearest = np.rint((grid - lo) / field.spacing).astype(np.intp)
    fluid = field.fluid[nearest[:, 0], nearest[:, 1], nearest[:, 2]].reshape(*n)
    return AirField(origin=lo, spacing=(hi - lo) / (n - 1), velocity=velocity,
                    pressure=np.zeros(tuple(n)), fluid=fluid, omega=field.omega, meta=field.meta)


@dataclass(frozen=True)
class _Faces:
    """Faces of the fluid cells: (a, b) cell indices and the projected volume flux a -> b, m3/s."""

    a: NDArray[np.intp]
    b: NDArray[np.intp]
    flux: NDArray[np.float64]
    conductance: NDArray[np.float64]  # k A / dx, W/K


class AirHeat:
    """The air's temperature on an air field's grid, solved for the particles' heat.

    Parameters
    ----------
    field
        The air field (its grid, fluid mask and velocity; the air flows from z = l to z = 0).
    inlet_temperature_C
        The air's inlet temperature.
    density, heat_capacity
        The inlet air's, kg/m3 and J/(kg K).
    """

    def __init__(self, field: AirField, inlet_temperature_C: float, density: float,
                 heat_capacity: float) -> None:
        for name, value in (("density", density), ("heat_capacity", heat_capacity),
                            ("inlet_temperature_C", inlet_temperature_C)):
            if not math.isfinite(value):
                raise ValueError(f"{name} = {value!r}: must be finite")
        self.field = field
        self.inlet_temperature_C = float(inlet_temperature_C)
        self.rho_cp = float(density) * float(heat_capacity)
        shape = field.shape
        fluid = np.asarray(field.fluid, dtype=bool)
        self._index = np.full(shape, -1, dtype=np.intp)
        self._index[fluid] = np.arange(int(fluid.sum()))
        faces = self._internal_faces(fluid)
        inlet, outlet = self._end_faces(fluid)
        keep = self._reachable(int(fluid.sum()), faces, outlet[0])
        self._keep(keep, faces, inlet, outlet)
        #: The last solve's field (the next one starts from it), its BiCGSTAB iterations and the
        #: preconditioner in use for each system, the particles' implicit one ("particles") and
        #: the transport alone ("transport"): "lines", or "incomplete LU" once the lines have
        #: failed on that system.
        self._last: NDArray[np.float64] | None = None
        self.iterations = 0
        self.preconditioner = {"particles": "lines", "transport": "lines"}

    # -- set-up --------------------------------------------------------------------------
    def nodes_xyz(self) -> NDArray[np.float64]:
        """Coordinates of every fluid node (cell centre), drum frame, m."""
        idx = np.argwhere(self._index >= 0)
        return self.field.origin + idx * self.field.spacing

    def _internal_faces(self, fluid: NDArray[np.bool_]) -> _Faces:
        dx = self.field.spacing
        area = (dx[1] * dx[2], dx[0] * dx[2], dx[0] * dx[1])
        a_all, b_all, f_all, g_all = [], [], [], []
        for axis in range(3):
            lo = [slice(None)] * 3
            hi = [slice(None)] * 3
            lo[axis] = slice(0, -1)
            hi[axis] = slice(1, None)
            both = fluid[tuple(lo)] & fluid[tuple(hi)]
            ua = self.field.velocity[tuple(lo)][..., axis][both]
            ub = self.field.velocity[tuple(hi)][..., axis][both]
            a_all.append(self._index[tuple(lo)][both])
            b_all.append(self._index[tuple(hi)][both])
            f_all.append(0.5 * (ua + ub) * area[axis])
            g_all.append(np.full(int(both.sum()), AIR_CONDUCTIVITY * area[axis] / dx[axis]))
        return _Faces(np.concatenate(a_all), np.concatenate(b_all), np.concatenate(f_all),
                      np.concatenate(g_all))

    def _end_faces(self, fluid: NDArray[np.bool_]
                   ) -> tuple[tuple[NDArray[np.intp], NDArray[np.float64]],
                              tuple[NDArray[np.intp], NDArray[np.float64]]]:
        """(cells, inward volume flux) at z = l (inlet) and (cells, outward flux) at z = 0."""
        dx = self.field.spacing
        area = dx[0] * dx[1]
        top, bottom = fluid[:, :, -1], fluid[:, :, 0]
        inlet_cells = self._index[:, :, -1][top]
        inlet_flux = -self.field.velocity[:, :, -1, 2][top] * area  # air moves towards -z
        outlet_cells = self._index[:, :, 0][bottom]
        outlet_flux = -self.field.velocity[:, :, 0, 2][bottom] * area
        return (inlet_cells, inlet_flux), (outlet_cells, outlet_flux)

    @staticmethod
    def _reachable(n: int, faces: _Faces, outlet_cells: NDArray[np.intp]) -> NDArray[np.bool_]:
        """Cells connected to the outlet through fluid faces: a pocket closed off by walls on
        the grid would make the projection and the transport singular."""
        graph = sp.coo_matrix((np.ones(len(faces.a)), (faces.a, faces.b)), shape=(n, n))
        _, labels = connected_components(graph, directed=False)
        return np.isin(labels, np.unique(labels[outlet_cells]))

    def _keep(self, keep: NDArray[np.bool_], faces: _Faces,
              inlet: tuple[NDArray[np.intp], NDArray[np.float64]],
              outlet: tuple[NDArray[np.intp], NDArray[np.float64]]) -> None:
        renumber = np.full(len(keep), -1, dtype=np.intp)
        renumber[keep] = np.arange(int(keep.sum()))
        flat = self._index.reshape(-1)
        live = flat >= 0
        flat[live] = renumber[flat[live]]
        self.cells = int(keep.sum())
        both = keep[faces.a] & keep[faces.b]
        a, b = renumber[faces.a[both]], renumber[faces.b[both]]
        in_keep = keep[inlet[0]]
        out_keep = keep[outlet[0]]
        self.inlet_cells, inlet_flux = renumber[inlet[0][in_keep]], inlet[1][in_keep]
        self.outlet_cells = renumber[outlet[0][out_keep]]
        flux, outlet_flux = self._project(a, b, faces.flux[both], inlet_flux, outlet[1][out_keep])
        self.inlet_flux, self.outlet_flux = inlet_flux, outlet_flux
        self._faces = _Faces(a, b, flux, faces.conductance[both])
        self._transport = self._matrix()
        # The lines' tridiagonal (offsets -1, 0, +1 in the cells' order, z fastest: an entry
        # there couples two cells of one line along the axis, or is zero); the incomplete LU of
        # the transport only if the lines fail (a complete LU fills in badly on a 3-D grid: a
        # minute for 50,000 cells).
        self._bands = tuple(np.asarray(self._transport.diagonal(k), dtype=float) for k in (-1, 0, 1))
        self._ilu: LinearOperator | None = None
        # Every grid node's cell: its own if it is a kept fluid node, else the nearest one's.
        own = self._index.reshape(-1)
        kept_nodes = np.flatnonzero(own >= 0)
        every = np.argwhere(np.ones(self.field.shape, dtype=bool)) * self.field.spacing
        nearest = cKDTree(every[kept_nodes]).query(every)[1]
        self._node_cell = np.where(own >= 0, own, own[kept_nodes[nearest]])

    def _project(self, a: NDArray[np.intp], b: NDArray[np.intp], flux: NDArray[np.float64],
                 inlet_flux: NDArray[np.float64], outlet_flux: NDArray[np.float64]
                 ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """The nearest fluxes (least squares) with no net flow out of any cell: internal and
        outlet faces corrected by a potential's differences, the inlet's held."""
        n = self.cells
        net = np.zeros(n)  # outflow of each cell, m3/s
        np.add.at(net, a, flux)
        np.add.at(net, b, -flux)
        np.add.at(net, self.inlet_cells, -inlet_flux)
        np.add.at(net, self.outlet_cells, outlet_flux)
        # flux' = flux - (p_b - p_a) on internal faces, outlet' = outlet + p_c (p = 0 outside):
        # the outflow of p is L p with L the graph Laplacian plus the outlet's diagonal.
        ones = np.ones(len(a))
        lap = sp.coo_matrix((np.concatenate([ones, ones, -ones, -ones]),
                             (np.concatenate([a, b, a, b]), np.concatenate([a, b, b, a]))),
                            shape=(n, n)).tocsr()
        lap = lap + sp.coo_matrix((np.ones(len(self.outlet_cells)),
                                   (self.outlet_cells, self.outlet_cells)), shape=(n, n)).tocsr()
        # Symmetric positive definite (the outlet anchors it): conjugate gradients, to a residual
        # far below what the energy bookkeeping resolves (1e-6 of the heat).
        diagonal = lap.diagonal()
        jacobi = LinearOperator((n, n), lambda r: r / diagonal)
        p, info = cg(lap, -net, rtol=1e-13, atol=0.0, maxiter=20 * n, M=jacobi)
        if info != 0:
            raise RuntimeError(f"air heat: the flux projection did not converge ({info})")
        return flux - (p[b] - p[a]), outlet_flux + p[self.outlet_cells]

    def _matrix(self) -> sp.csr_matrix:
        """Steady upwind advection plus conduction, W/K per cell row (times rho cp for flux)."""
        n = self.cells
        f = self._faces
        rc = self.rho_cp
        out_a = rc * np.maximum(f.flux, 0.0)  # a -> b carries a's temperature
        out_b = rc * np.maximum(-f.flux, 0.0)  # b -> a carries b's
        g = f.conductance
        rows = [f.a, f.b, f.a, f.b]
        cols = [f.a, f.b, f.b, f.a]
        vals = [out_a + g, out_b + g, -(out_b + g), -(out_a + g)]
        # Ends. The outlet face carries the cell's temperature whichever way it flows (backflow
        # at z = 0 brings the cell's own air: zero gradient); an inlet face the flow leaves by
        # carries the cell's too, one it enters by brings the inlet temperature (right side).
        rows.append(self.outlet_cells)
        cols.append(self.outlet_cells)
        vals.append(rc * self.outlet_flux)
        rows.append(self.inlet_cells)
        cols.append(self.inlet_cells)
        vals.append(rc * np.maximum(-self.inlet_flux, 0.0))
        # With no net flow out of any cell (the projection), each diagonal equals the sum of
        # its row's off-diagonal magnitudes plus its inflow from the inlet: an M-matrix.
        return sp.coo_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
                             shape=(n, n)).tocsr()

    # -- use -----------------------------------------------------------------------------
    def cells_of(self, points_drum_frame: NDArray[np.float64]) -> NDArray[np.intp]:
        """The cell each point belongs to (its nearest kept fluid node)."""
        g = np.rint((np.asarray(points_drum_frame, float) - self.field.origin) / self.field.spacing)
        shape = np.array(self.field.shape)
        g = np.clip(g, 0, shape - 1).astype(np.intp)
        flat = (g[:, 0] * shape[1] + g[:, 1]) * shape[2] + g[:, 2]
        return np.asarray(self._node_cell[flat], dtype=np.intp)

    def deposit(self, cells: NDArray[np.intp], heat_to_air_W: NDArray[np.float64]) -> NDArray[np.float64]:
        """Each cell's heat source, W, from the heat each particle gave the air."""
        return np.bincount(cells, weights=heat_to_air_W, minlength=self.cells).astype(float)

    def _inlet_rhs(self) -> NDArray[np.float64]:
        rhs = np.zeros(self.cells)
        np.add.at(rhs, self.inlet_cells,
                  self.rho_cp * np.maximum(self.inlet_flux, 0.0) * self.inlet_temperature_C)
        return rhs

    def _lines(self, added_diagonal: NDArray[np.float64] | None) -> LinearOperator:
        """The preconditioner of the lines along the axis, with ``added_diagonal`` (W/K)."""
        lower, diagonal, upper = self._bands
        if added_diagonal is not None:
            diagonal = diagonal + added_diagonal
        dl, d, du, du2, ipiv, info = lapack.dgttrf(lower, diagonal, upper)
        if info != 0:
            raise RuntimeError(f"air heat: a line of cells is singular ({info})")
        return LinearOperator((self.cells, self.cells),
                              lambda r: lapack.dgttrs(dl, d, du, du2, ipiv, r)[0])

    def _incomplete_lu(self) -> LinearOperator:
        if self._ilu is None:
            ilu = spilu(self._transport.tocsc(), drop_tol=1e-5, fill_factor=20)
            self._ilu = LinearOperator((self.cells, self.cells), ilu.solve)
        return self._ilu

    def _solve(self, system: str, matrix: sp.csr_matrix, rhs: NDArray[np.float64],
               added_diagonal: NDArray[np.float64] | None = None) -> NDArray[np.float64]:
        # Relative residual 1e-12: the conservation of the air's enthalpy holds to that. The
        # start is the last solve's field (the same criterion from a closer start: fewer
        # iterations, the same answer to the tolerance), at first the inlet temperature.
        start = self._last if self._last is not None else np.full(self.cells, self.inlet_temperature_C)
        count = [0]

        def counted(_: NDArray[np.float64]) -> None:
            count[0] += 1

        # A start that already solves the system (the lumped particles' bookkeeping) is the
        # answer: no preconditioner is built for it.
        if np.linalg.norm(rhs - matrix @ start) <= 1e-12 * np.linalg.norm(rhs):
            self.iterations = 0
            self._last = np.asarray(start, dtype=float)
            return self._last.copy()
        info = 1
        if self.preconditioner[system] == "lines":
            x, info = bicgstab(matrix, rhs, x0=start, rtol=1e-12, atol=0.0, maxiter=LINE_ITERATIONS,
                               M=self._lines(added_diagonal), callback=counted)
            if info != 0:
                self.preconditioner[system] = "incomplete LU"  # for the rest of the run
        if info != 0:
            x, info = bicgstab(matrix, rhs, x0=start, rtol=1e-12, atol=0.0, maxiter=1000,
                               M=self._incomplete_lu(), callback=counted)
        if info != 0:
            raise RuntimeError(f"air heat: the temperature solve did not converge ({info})")
        self.iterations = count[0]
        self._last = np.asarray(x, dtype=float)
        return self._last.copy()

    def solve(self, source_W: NDArray[np.float64]) -> NDArray[np.float64]:
        """The steady air temperature of each cell, C, for given heat sources, W."""
        return self._solve("transport", self._transport,
                           self._inlet_rhs() + np.asarray(source_W, dtype=float))

    def solve_with_particles(self, conductance_W_K: NDArray[np.float64],
                             weighted_temperature_W: NDArray[np.float64]) -> NDArray[np.float64]:
        """The steady air temperature of each cell, C, with the particles' heat implicit.

        Each cell receives sum_p g_p (T_p - T_cell) from its particles: ``conductance_W_K`` is
        sum_p g_p and ``weighted_temperature_W`` sum_p g_p T_p per cell (all ranks'). Implicit in
        the cell's temperature, so a cell whose particles could heat its air past them (a dense
        bed in slow air: g / (rho cp flux) > 1) cannot overshoot, as a lagged explicit source
        would.
        """
        conductance = np.asarray(conductance_W_K, dtype=float)
        matrix = self._transport + sp.diags(conductance)
        rhs = self._inlet_rhs() + np.asarray(weighted_temperature_W, dtype=float)
        return self._solve("particles", matrix.tocsr(), rhs, conductance)

    def enthalpy_gain(self, temperature_C: NDArray[np.float64]) -> float:
        """What the air carries out of the grid above what it brought in, W (the outlet's
        enthalpy flux minus the inlet's, relative to the inlet temperature)."""
        t_in = self.inlet_temperature_C
        out = self.rho_cp * float(np.sum(self.outlet_flux * (temperature_C[self.outlet_cells] - t_in)))
        back = self.rho_cp * float(np.sum(np.maximum(-self.inlet_flux, 0.0)
                                          * (temperature_C[self.inlet_cells] - t_in)))
        return out + back

    def outlet_temperature(self, temperature_C: NDArray[np.float64]) -> float:
        """The outlet's flow-weighted mean temperature, C."""
        weight = np.maximum(self.outlet_flux, 0.0)
        return float(np.dot(weight, temperature_C[self.outlet_cells]) / weight.sum())

    @property
    def volume_flow(self) -> float:
        """The air's volume flow through the grid, m3/s (the inlet's)."""
        return float(np.sum(self.inlet_flux))
