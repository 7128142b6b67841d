"""Reading the results of the drum's OpenFOAM air case: residual history, cell fields,
boundary fluxes, and the :class:`AirSolution` that gathers them.

:mod:`drumflow.air.foam_case` writes the case, :mod:`drumflow.air.foam` runs it.
"""

from __future__ import annotations

import re
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
import pandas as pd
from numpy.typing import NDArray

from drumflow.errors import SolverError

if TYPE_CHECKING:
    pass

#: Callback for progress: (iteration, {field: initial residual}).
IterationCallback = Callable[[int, dict[str, float]], None]


_TIME_RE = re.compile(r"^Time = (\S+)")
_SOLVE_RE = re.compile(
    r"Solving for (\w+), Initial residual = ([^,]+), Final residual = ([^,]+), No Iterations (\d+)"
)
_CONVERGED_RE = re.compile(r"SIMPLE solution converged in (\S+) iterations")


class ResidualParser:
    """Collect the SIMPLE residual history from simpleFoam's output, line by line.

    Only the first solve of a field in an iteration counts, as for OpenFOAM's own
    ``residualControl`` (pressure may be solved again by non-orthogonal correctors).

    Parameters
    ----------
    on_iteration
        Called with (iteration, residuals) when an iteration's residuals are complete.
    """

    def __init__(self, on_iteration: IterationCallback | None = None) -> None:
        self.rows: list[dict[str, float]] = []
        self.converged = False
        self.converged_at: int | None = None
        #: Per field, the iterations whose first solve did no sweep (a field left as it was).
        self.unsolved: dict[str, int] = {}
        self._current: dict[str, float] | None = None
        self._on_iteration = on_iteration

    def _flush(self) -> None:
        row, self._current = self._current, None
        if row is not None and len(row) > 1:
            self.rows.append(row)
            if self._on_iteration is not None:
                try:
                    self._on_iteration(
                        int(row["iteration"]), {k: v for k, v in row.items() if k != "iteration"}
                    )
                except Exception:  # a progress display must never spoil the residual history
                    pass

    def __call__(self, line: str) -> None:
        m = _TIME_RE.match(line)
        if m:
            self._flush()
            try:
                self._current = {"iteration": float(m.group(1))}
            except ValueError:
                self._current = None
            return
        m = _SOLVE_RE.search(line)
        if m and self._current is not None:
            name = m.group(1)
            if name not in self._current:
                self._current[name] = float(m.group(2))
                if int(m.group(4)) == 0:
                    self.unsolved[name] = self.unsolved.get(name, 0) + 1
            return
        m = _CONVERGED_RE.search(line)
        if m:
            self._flush()
            self.converged = True
            try:
                self.converged_at = int(float(m.group(1)))
            except ValueError:
                self.converged_at = None
        elif line.startswith("End"):
            self._flush()

    def finish(self) -> pd.DataFrame:
        """The history as a DataFrame: ``iteration`` then one column per solved field."""
        self._flush()
        df = pd.DataFrame(self.rows)
        if df.empty:
            return pd.DataFrame({"iteration": pd.Series(dtype=int)})
        df["iteration"] = df["iteration"].astype(int)
        return df


def parse_residual_log(text: str) -> pd.DataFrame:
    """Residual history of a simpleFoam log (see :class:`ResidualParser`)."""
    parser = ResidualParser()
    for line in text.splitlines():
        parser(line)
    return parser.finish()


@dataclass
class AirSolution:
    """A finished steady air solution and its checks.

    Mass flows are in kg/s and positive in the flow direction (into the domain at the inlet,
    out of it at the outlet). Velocities are in m/s; ``mean_axial_velocity`` is positive in
    the air's direction of flow, which is -z.
    """

    case_dir: Path
    time_dir: str
    turbulence: str
    converged: bool
    iterations: int
    residual_target: float
    final_residuals: dict[str, float]
    residuals: pd.DataFrame
    residuals_csv: Path
    wall_time_s: float
    solver_wall_time_s: float
    density: float
    kinematic_viscosity: float
    omega: float
    volumetric_flow: float
    inlet_mass_flow: float
    outlet_mass_flow: float
    free_area: float
    mean_axial_velocity: float
    mid_plane_axial_velocity: float | None
    expected_axial_velocity: float
    processes: int
    mesh: dict[str, Any] = field(default_factory=dict)

    @property
    def mass_flow_imbalance(self) -> float:
        """(inlet - outlet) / inlet mass flow."""
        return (self.inlet_mass_flow - self.outlet_mass_flow) / self.inlet_mass_flow

    @property
    def time_path(self) -> Path:
        """The directory of the final fields."""
        return self.case_dir / self.time_dir

    def summary(self) -> dict[str, Any]:
        """Headline numbers as plain JSON types (for the manifest and reports)."""
        return {
            "case_dir": str(self.case_dir),
            "time_dir": self.time_dir,
            "turbulence": self.turbulence,
            "converged": self.converged,
            "iterations": self.iterations,
            "residual_target": self.residual_target,
            "final_residuals": dict(self.final_residuals),
            "wall_time_s": self.wall_time_s,
            "solver_wall_time_s": self.solver_wall_time_s,
            "processes": self.processes,
            "cells": self.mesh.get("cells"),
            "mesh_size_m": self.mesh.get("size_m"),
            "density_kg_m3": self.density,
            "kinematic_viscosity_m2_s": self.kinematic_viscosity,
            "omega_rad_s": self.omega,
            "volumetric_flow_m3_s": self.volumetric_flow,
            "mass_flow_in_kg_s": self.inlet_mass_flow,
            "mass_flow_out_kg_s": self.outlet_mass_flow,
            "mass_flow_imbalance": self.mass_flow_imbalance,
            "free_area_m2": self.free_area,
            "mean_axial_velocity_m_s": self.mean_axial_velocity,
            "mid_plane_axial_velocity_m_s": self.mid_plane_axial_velocity,
            "expected_axial_velocity_m_s": self.expected_axial_velocity,
        }


# -- reading results --------------------------------------------------------------------


def latest_time(case_dir: Path) -> str:
    """Name of the latest time directory (other than 0) of a reconstructed case."""
    best: tuple[float, str] | None = None
    for p in case_dir.iterdir():
        if not p.is_dir():
            continue
        try:
            t = float(p.name)
        except ValueError:
            continue
        if best is None or t > best[0]:
            best = (t, p.name)
    if best is None or best[0] == 0.0:
        raise SolverError("simpleFoam", [], None, None, reason=f"no result time in {case_dir}")
    return best[1]


def _internal(path: Path) -> NDArray[np.float64]:
    from foamlib import FoamFieldFile

    value = FoamFieldFile(path).internal_field
    return np.asarray(value, dtype=float)


def read_cell_fields(case_dir: Path, time_dir: str) -> dict[str, NDArray[np.float64]]:
    """Cell centres ``C`` (n, 3), volumes ``V`` (n,), ``U`` (n, 3) and kinematic ``p`` (n,).

    ``C`` and ``V`` must have been written by ``postProcess -funcs
    '(writeCellCentres writeCellVolumes)'`` (as :func:`solve_air` does).
    """
    t = case_dir / time_dir
    C = _internal(t / "C").reshape(-1, 3)
    n = len(C)
    out: dict[str, NDArray[np.float64]] = {"C": C}
    for name, shape in (("V", (n,)), ("U", (n, 3)), ("p", (n,))):
        # A uniform field comes back as one value: spread it over the cells.
        out[name] = np.broadcast_to(_internal(t / name), shape).copy()
    return out


def read_boundary_values(
    case_dir: Path,
    time_dir: str,
    omega: float,
    patches: tuple[str, ...] = ("inlet", "outlet"),
    moving_walls: tuple[str, ...] = ("walls",),
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Boundary face centres (m, 3) of some patches and their absolute air velocity (m, 3).

    Patches that store a ``value`` for U (inlet, outlet) give it; a ``noSlip`` patch named in
    ``moving_walls`` turns with the MRF zone, so its absolute velocity is omega e_z x r (MRF
    sets it at every iteration, but ``noSlip`` does not write it); other ``noSlip`` patches
    are at rest.

    Parameters
    ----------
    patches
        The patches to read. The default, the end faces only, is what the grid resampling
        uses: see :meth:`drumflow.air.field.AirField.from_solution` for why walls are left out.
    """
    from foamlib import FoamFieldFile

    t = case_dir / time_dir
    # foamlib's value types are wide unions; these are dictionaries of patch dictionaries.
    centres: Any = FoamFieldFile(t / "C").boundary_field
    velocity: Any = FoamFieldFile(t / "U").boundary_field
    pts: list[NDArray[np.float64]] = []
    vel: list[NDArray[np.float64]] = []
    for name in patches:
        entry = centres.get(name)
        if entry is None or "value" not in entry:
            continue  # no such patch, or an empty one
        c = np.asarray(entry["value"], dtype=float).reshape(-1, 3)
        u_entry = velocity.get(name, {})
        if name in moving_walls:
            u = np.column_stack([-omega * c[:, 1], omega * c[:, 0], np.zeros(len(c))])
        elif "value" in u_entry:
            u = np.broadcast_to(np.asarray(u_entry["value"], dtype=float), c.shape).copy()
        elif u_entry.get("type") == "noSlip":
            u = np.zeros_like(c)
        else:
            continue
        pts.append(c)
        vel.append(u.reshape(-1, 3))
    if not pts:
        return np.zeros((0, 3)), np.zeros((0, 3))
    return np.concatenate(pts), np.concatenate(vel)


def patch_flux(case_dir: Path, time_dir: str, patch: str) -> float:
    """Sum of the face fluxes ``phi`` (m^3/s, positive out of the domain) over a patch."""
    from foamlib import FoamFieldFile

    boundary: Any = FoamFieldFile(case_dir / time_dir / "phi").boundary_field
    value = boundary[patch]["value"]
    return float(np.sum(np.asarray(value, dtype=float)))


def read_mid_plane(case_dir: Path) -> float | None:
    """Last area-averaged U_z on the mid plane from the function object output, if any."""
    files = sorted((case_dir / "postProcessing" / "midPlane").glob("*/surfaceFieldValue*.dat"))
    if not files:
        return None
    last: float | None = None
    for path in files:
        for line in path.read_text(errors="replace").splitlines():
            if line.startswith("#") or not line.strip():
                continue
            nums = re.findall(r"[-+]?\d*\.?\d+(?:[eE][-+]?\d+)?", line.replace("(", " "))
            if len(nums) >= 4:
                last = float(nums[3])
    return last


