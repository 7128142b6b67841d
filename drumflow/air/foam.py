"""The steady air field of the drum section with OpenFOAM v1912 ``simpleFoam`` and MRF.

Model (Burgos-Florez et al. 2019, Sections 2.1.2-2.1.3 and 3.4): air as a constant-density
gas, counter-current, realizable k-epsilon (or laminar), solved in the frame that turns with
the drum (the paper's Eq. 27). Here the rotation is a multiple-reference-frame zone covering
the whole fluid (``constant/MRFProperties``) at the drum's omega about +z, the sense in which
LIGGGHTS turns the shell (``rotate ... axis 0 0 1``). OpenFOAM's MRF uses the absolute-velocity
formulation: the lifters and shell are at rest in the rotating frame, their ``noSlip``
condition is replaced by MRF with the wall velocity omega x r, and the ``U`` written out is
the **absolute** (laboratory-frame) velocity at the instant the drum frame and the lab frame
coincide. The flow is steady in the drum frame, so one solution serves every drum angle (see
:mod:`drumflow.air.field`).

Boundary conditions:

- ``inlet`` (z = l): ``flowRateInletVelocity`` with Q = mdot / rho, rho = p / (R_air T) at the
  inlet temperature and pressure; k from 5 % turbulence intensity, epsilon from a mixing
  length 0.07 D_h (D_h: hydraulic diameter of the free cross-section).
- ``outlet`` (z = 0): kinematic pressure 0, ``inletOutlet`` for U, k, epsilon.
- ``walls``: ``noSlip`` (rotating through MRF), standard wall functions.

Inlet and outlet are listed as ``nonRotatingPatches``: MRF would otherwise zero the relative
flux through them (it treats every non-excluded boundary face as a rotating wall) and the air
could not pass. Their normals are along the axis, so omega x r adds no flux there anyway.

Numerics: ``Gauss linear`` gradients (on a 53k-cell lifter drum they reached 1e-4 in 54 SIMPLE
iterations where ``cellLimited`` stalled near 1e-3), bounded ``linearUpwind`` for U, bounded
``upwind`` for k and epsilon (second-order schemes there stalled, see
:func:`write_fv_schemes`), SIMPLEC with ``residualControl`` at ``air.residual_target``. All dictionaries are written with foamlib.
"""

from __future__ import annotations

import math
import re
import shutil
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
import pandas as pd
from numpy.typing import NDArray

from drumflow.air.mesh import build_air_mesh, foam_check, openfoam_env, run_foam
from drumflow.errors import SolverError
from drumflow.runner import Runner

if TYPE_CHECKING:
    from drumflow.case import Case

#: k-epsilon model constant C_mu (standard value) for the inlet epsilon.
CMU = 0.09
#: Inlet turbulence intensity u'/U.
TURBULENCE_INTENSITY = 0.05
#: Inlet mixing length as a fraction of the hydraulic diameter.
MIXING_LENGTH_FRACTION = 0.07

#: Callback for progress: (iteration, {field: initial residual}).
IterationCallback = Callable[[int, dict[str, float]], None]


class AirNotConvergedError(SolverError):
    """simpleFoam reached ``air.max_iterations`` before every residual fell below the target.

    Attributes
    ----------
    iterations
        SIMPLE iterations run.
    final_residuals
        The last initial residual of each field.
    target
        The residual target that was not reached.
    solution
        The (unconverged) :class:`AirSolution`, whose files are left in place; a caller may
        still decide to use it.
    """

    def __init__(
        self,
        iterations: int,
        final_residuals: dict[str, float],
        target: float,
        log: Path | None,
        solution: AirSolution | None = None,
    ) -> None:
        self.iterations = iterations
        self.final_residuals = dict(final_residuals)
        self.target = target
        self.solution = solution
        worst = max(final_residuals.items(), key=lambda kv: kv[1], default=("?", float("nan")))
        super().__init__(
            "simpleFoam",
            ["simpleFoam"],
            0,
            log,
            reason=(
                f"the air solution did not converge in {iterations} SIMPLE iterations: "
                f"{worst[0]} residual {worst[1]:.3g} > target {target:.3g} "
                "(raise air.max_iterations, coarsen air.mesh_size or relax air.residual_target)"
            ),
        )


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


# -- case dictionaries ------------------------------------------------------------------


def inlet_turbulence(velocity: float, hydraulic_diameter: float) -> tuple[float, float, float]:
    """Inlet k, epsilon and mixing length from the intensity and mixing-length rules.

    k = 1.5 (I U)^2, epsilon = C_mu^0.75 k^1.5 / L_m, L_m = 0.07 D_h.
    """
    k = 1.5 * (TURBULENCE_INTENSITY * velocity) ** 2
    lm = MIXING_LENGTH_FRACTION * hydraulic_diameter
    eps = CMU**0.75 * k**1.5 / lm
    return k, eps, lm


def write_control_dict(
    case_dir: Path,
    end_iteration: int,
    functions: dict[str, Any] | None = None,
) -> None:
    """``system/controlDict`` for a steady run that writes only its final (or converged) state."""
    from foamlib import FoamFile

    path = case_dir / "system" / "controlDict"
    path.unlink(missing_ok=True)
    with FoamFile(path) as f:
        f["application"] = "simpleFoam"
        f["startFrom"] = "startTime"
        f["startTime"] = 0
        f["stopAt"] = "endTime"
        f["endTime"] = int(end_iteration)
        f["deltaT"] = 1
        # Only the last state is kept: simpleFoam writes it when residualControl is met, or at
        # endTime; intermediate writes would only cost disk.
        f["writeControl"] = "timeStep"
        f["writeInterval"] = int(end_iteration)
        f["purgeWrite"] = 0
        f["writeFormat"] = "ascii"
        f["writePrecision"] = 10
        f["timeFormat"] = "general"
        f["timePrecision"] = 8
        f["runTimeModifiable"] = False
        f["functions"] = functions or {}


def write_fv_schemes(case_dir: Path) -> None:
    """``system/fvSchemes`` (see the module docstring for the choices)."""
    from foamlib import FoamFile

    path = case_dir / "system" / "fvSchemes"
    path.unlink(missing_ok=True)
    with FoamFile(path) as f:
        f["ddtSchemes"] = {"default": "steadyState"}
        f["gradSchemes"] = {"default": ("Gauss", "linear")}
        f["divSchemes"] = {
            "default": "none",
            "div(phi,U)": ("bounded", "Gauss", "linearUpwind", "grad(U)"),
            # First order for k and epsilon: on coarse tetrahedra at the thin lifters,
            # limitedLinear and linearUpwind left epsilon bounded below zero every iteration
            # and its residual stalled at 4e-3 to 1e-2; upwind converges monotonically.
            "div(phi,k)": ("bounded", "Gauss", "upwind"),
            "div(phi,epsilon)": ("bounded", "Gauss", "upwind"),
            "div((nuEff*dev2(T(grad(U)))))": ("Gauss", "linear"),
        }
        # Tetrahedra are far from orthogonal at the lifter edges: limit the explicit
        # non-orthogonal correction to keep the pressure equation diagonally dominant.
        f["laplacianSchemes"] = {"default": ("Gauss", "linear", "limited", "corrected", 0.5)}
        f["interpolationSchemes"] = {"default": "linear"}
        f["snGradSchemes"] = {"default": ("limited", "corrected", 0.5)}
        f["wallDist"] = {"method": "meshWave"}


def write_fv_solution(
    case_dir: Path, residual_target: float, fields: list[str], consistent: bool = True
) -> None:
    """``system/fvSolution``: GAMG for p, Gauss-Seidel for the rest, SIMPLEC."""
    from foamlib import FoamFile

    path = case_dir / "system" / "fvSolution"
    path.unlink(missing_ok=True)
    others = "(" + "|".join(f for f in fields if f != "p") + ")"
    with FoamFile(path) as f:
        f["solvers"] = {
            "p": {
                "solver": "GAMG",
                "smoother": "GaussSeidel",
                "tolerance": 1e-7,
                "relTol": 0.05,
            },
            f'"{others}"': {
                "solver": "smoothSolver",
                "smoother": "symGaussSeidel",
                "tolerance": 1e-8,
                "relTol": 0.1,
            },
        }
        f["SIMPLE"] = {
            "nNonOrthogonalCorrectors": 0,
            # SIMPLEC: no pressure under-relaxation needed, converges in far fewer iterations.
            "consistent": consistent,
            "residualControl": {
                "p": residual_target,
                "U": residual_target,
                **({'"(k|epsilon)"': residual_target} if "k" in fields else {}),
            },
        }
        relax = 0.9 if consistent else 0.7
        f["relaxationFactors"] = {
            "fields": {"p": 1.0 if consistent else 0.3},
            "equations": {"U": relax, '".*"': relax},
        }


def write_transport(case_dir: Path, nu: float, turbulence: str) -> None:
    """``constant/transportProperties`` and ``constant/turbulenceProperties``."""
    from foamlib import FoamFile

    for name in ("transportProperties", "turbulenceProperties"):
        (case_dir / "constant" / name).unlink(missing_ok=True)
    with FoamFile(case_dir / "constant" / "transportProperties") as f:
        f["transportModel"] = "Newtonian"
        f["nu"] = FoamFile.Dimensioned(nu, FoamFile.DimensionSet(length=2, time=-1), "nu")
    with FoamFile(case_dir / "constant" / "turbulenceProperties") as f:
        if turbulence == "laminar":
            f["simulationType"] = "laminar"
        else:
            f["simulationType"] = "RAS"
            f["RAS"] = {"RASModel": turbulence, "turbulence": True, "printCoeffs": True}


def write_mrf(
    case_dir: Path,
    omega: float,
    non_rotating: list[str],
    cell_zone: str = "fluid",
) -> None:
    """``constant/MRFProperties``: the whole fluid zone turning at ``omega`` about +z."""
    from foamlib import FoamFile

    path = case_dir / "constant" / "MRFProperties"
    path.unlink(missing_ok=True)
    with FoamFile(path) as f:
        f["MRF1"] = {
            "cellZone": cell_zone,
            "active": True,
            "nonRotatingPatches": list(non_rotating),
            "origin": [0.0, 0.0, 0.0],
            "axis": [0.0, 0.0, 1.0],
            "omega": float(omega),
        }


def _field(
    case_dir: Path,
    name: str,
    dims: dict[str, int],
    internal: float | list[float],
    boundary: dict[str, dict[str, Any]],
) -> None:
    from foamlib import FoamFieldFile, FoamFile

    path = case_dir / "0" / name
    path.parent.mkdir(parents=True, exist_ok=True)
    path.unlink(missing_ok=True)
    with FoamFieldFile(path) as f:
        f.dimensions = FoamFile.DimensionSet(**dims)
        f.internal_field = internal
        f.boundary_field = boundary


def write_initial_fields(
    case_dir: Path,
    flow_rate: float,
    bulk_velocity: float,
    hydraulic_diameter: float,
    turbulence: str,
) -> dict[str, float]:
    """The ``0/`` fields U, p (and k, epsilon, nut for k-epsilon).

    The interior starts at the plug-flow velocity (0, 0, -U_bulk): closer to the answer than
    rest, so SIMPLE spends its iterations on the swirl and the lifter wakes.

    Returns
    -------
    dict
        The inlet ``k``, ``epsilon`` and ``mixing_length`` (0 for laminar).
    """
    zero = [0.0, 0.0, 0.0]
    _field(
        case_dir,
        "U",
        {"length": 1, "time": -1},
        [0.0, 0.0, -bulk_velocity],
        {
            "inlet": {
                "type": "flowRateInletVelocity",
                "volumetricFlowRate": ("constant", float(flow_rate)),
                "value": [0.0, 0.0, -bulk_velocity],
            },
            "outlet": {"type": "inletOutlet", "inletValue": zero, "value": zero},
            "walls": {"type": "noSlip"},
        },
    )
    _field(
        case_dir,
        "p",
        {"length": 2, "time": -2},
        0.0,
        {
            "inlet": {"type": "zeroGradient"},
            "outlet": {"type": "fixedValue", "value": 0.0},
            "walls": {"type": "zeroGradient"},
        },
    )
    if turbulence == "laminar":
        return {"k": 0.0, "epsilon": 0.0, "mixing_length": 0.0}
    k, eps, lm = inlet_turbulence(bulk_velocity, hydraulic_diameter)
    _field(
        case_dir,
        "k",
        {"length": 2, "time": -2},
        k,
        {
            "inlet": {
                "type": "turbulentIntensityKineticEnergyInlet",
                "intensity": TURBULENCE_INTENSITY,
                "value": k,
            },
            "outlet": {"type": "inletOutlet", "inletValue": k, "value": k},
            "walls": {"type": "kqRWallFunction", "value": k},
        },
    )
    _field(
        case_dir,
        "epsilon",
        {"length": 2, "time": -3},
        eps,
        {
            "inlet": {
                "type": "turbulentMixingLengthDissipationRateInlet",
                "mixingLength": lm,
                "value": eps,
            },
            "outlet": {"type": "inletOutlet", "inletValue": eps, "value": eps},
            "walls": {"type": "epsilonWallFunction", "value": eps},
        },
    )
    _field(
        case_dir,
        "nut",
        {"length": 2, "time": -1},
        0.0,
        {
            "inlet": {"type": "calculated", "value": 0.0},
            "outlet": {"type": "calculated", "value": 0.0},
            "walls": {"type": "nutkWallFunction", "value": 0.0},
        },
    )
    return {"k": k, "epsilon": eps, "mixing_length": lm}


def mid_plane_function(z: float) -> dict[str, Any]:
    """A ``surfaceFieldValue`` function object: area average of U on the plane z = const.

    It runs every iteration (a cutting plane through a few ten thousand cells is cheap) and
    gives an independent check of the bulk velocity next to the volume average.
    """
    return {
        "type": "surfaceFieldValue",
        "libs": ['"libfieldFunctionObjects.so"'],
        "writeControl": "timeStep",
        "writeInterval": 1,
        "log": False,
        "writeFields": False,
        "regionType": "sampledSurface",
        "name": "midPlane",
        "sampledSurfaceDict": {
            "type": "cuttingPlane",
            "planeType": "pointAndNormal",
            "pointAndNormalDict": {"point": [0.0, 0.0, float(z)], "normal": [0.0, 0.0, 1.0]},
            "interpolate": False,
        },
        "operation": "areaAverage",
        "fields": ["U"],
    }


def write_decompose_dict(case_dir: Path, processes: int, axis: int = 0) -> None:
    """``system/decomposeParDict`` with the ``simple`` method (scotch is a stub in this build)."""
    from foamlib import FoamFile

    n = [1, 1, 1]
    n[axis] = processes
    path = case_dir / "system" / "decomposeParDict"
    path.unlink(missing_ok=True)
    with FoamFile(path) as f:
        f["numberOfSubdomains"] = processes
        f["method"] = "simple"
        f["coeffs"] = {"n": n, "delta": 0.001}


# -- reading results --------------------------------------------------------------------


def write_cell_centres(runner: Runner, case_dir: Path, timeout: float | None) -> None:
    """Write cell centres and volumes of the latest time (what :func:`read_cell_fields` reads)."""
    run_foam(
        runner,
        "postProcess",
        ["-funcs", "(writeCellCentres writeCellVolumes)", "-latestTime"],
        case_dir,
        timeout=timeout,
        log_name="log.postProcess.cells",
    )


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


def _read_mid_plane(case_dir: Path) -> float | None:
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


# -- the stage --------------------------------------------------------------------------


def air_properties_for(case: Case) -> tuple[float, float]:
    """Air density (ideal gas at inlet p and T) and kinematic viscosity (air table), SI."""
    from drumflow.analysis.air_properties import kinematic_viscosity
    from drumflow.geometry.fluid import air_density

    return air_density(case), float(kinematic_viscosity(case.air.inlet_temperature_C))


def write_air_case(
    case: Case, case_dir: Path, mesh: dict[str, Any], processes: int = 1
) -> dict[str, Any]:
    """Write every dictionary and initial field of the drum's air case (mesh already in place).

    Returns
    -------
    dict
        The physical inputs: density, nu, flow rate, bulk velocity, inlet k and epsilon.
    """
    rho, nu = air_properties_for(case)
    flow = case.air.mass_flow / rho
    bulk = flow / mesh["area_m2"]
    turbulence = case.air.turbulence
    fields = ["p", "U"] + ([] if turbulence == "laminar" else ["k", "epsilon"])
    write_control_dict(
        case_dir,
        case.air.max_iterations,
        functions={"midPlane": mid_plane_function(0.5 * case.drum.length)},
    )
    write_fv_schemes(case_dir)
    write_fv_solution(case_dir, case.air.residual_target, fields)
    write_transport(case_dir, nu, turbulence)
    write_mrf(case_dir, case.drum.omega, ["inlet", "outlet"])
    inlet = write_initial_fields(case_dir, flow, bulk, mesh["hydraulic_diameter_m"], turbulence)
    if processes > 1:
        # Cut across the axis for short sections, along it for long ones: the cut with the
        # smaller interface.
        axis = 2 if case.drum.length > case.drum.diameter else 0
        write_decompose_dict(case_dir, processes, axis)
    return {
        "density": rho,
        "kinematic_viscosity": nu,
        "volumetric_flow": flow,
        "bulk_velocity": bulk,
        "inlet_k": inlet["k"],
        "inlet_epsilon": inlet["epsilon"],
        "mixing_length": inlet["mixing_length"],
    }


def solve_air(
    case: Case,
    workdir: Path,
    runner: Runner | None = None,
    *,
    size: float | None = None,
    processes: int = 1,
    timeout: float | None = 3600.0,
    on_iteration: IterationCallback | None = None,
) -> AirSolution:
    """Mesh, set up and solve the drum's steady air field; check mass flow and bulk velocity.

    Parameters
    ----------
    case
        The validated case (drum, lifters, air).
    workdir
        The OpenFOAM case directory to create (an existing one is overwritten file by file;
        old time directories are removed).
    runner
        Starts every OpenFOAM program; default a fresh :class:`Runner`.
    size
        Bulk cell size, m; default ``air.mesh_size``.
    processes
        MPI ranks for simpleFoam (1 = serial; more decomposes with the ``simple`` method).
    timeout
        Limit for each program, s.
    on_iteration
        Progress callback, called with (iteration, initial residuals).

    Returns
    -------
    AirSolution
        With the residual history also written to ``workdir/residuals.csv``.

    Raises
    ------
    AirNotConvergedError
        When ``air.max_iterations`` pass before every residual is below ``air.residual_target``.
    drumflow.errors.SolverError
        When any OpenFOAM program fails (its log is named in the message).
    """
    runner = runner or Runner()
    started = time.time()
    workdir = Path(workdir)
    workdir.mkdir(parents=True, exist_ok=True)
    for p in list(workdir.iterdir()):
        # Results of an earlier run would be taken for this run's (latest time, processors).
        if p.is_dir() and (_is_time(p.name) or p.name.startswith("processor")
                           or p.name == "postProcessing"):
            shutil.rmtree(p)
    mesh = build_air_mesh(case, workdir, runner, size=size, timeout=timeout)
    inputs = write_air_case(case, workdir, mesh, processes=processes)

    parser = ResidualParser(on_iteration)
    solver_started = time.time()
    if processes > 1:
        run_foam(runner, "decomposePar", ["-force"], workdir, timeout=timeout)
        log = workdir / "log.simpleFoam"
        runner.run(
            "simpleFoam",
            runner.profile.mpi_command(["simpleFoam", "-parallel"], processes),
            cwd=workdir,
            log=log,
            timeout=timeout,
            on_line=parser,
            env=openfoam_env(),
            check=foam_check,
        )
        solver_wall = time.time() - solver_started
        run_foam(runner, "reconstructPar", ["-latestTime"], workdir, timeout=timeout)
        # The reconstructed case holds everything; the per-rank copies would only double
        # the disk use and confuse a later serial run of the same directory.
        for p in workdir.glob("processor*"):
            shutil.rmtree(p)
    else:
        log = run_foam(runner, "simpleFoam", [], workdir, timeout=timeout, on_line=parser)
        solver_wall = time.time() - solver_started
    history = parser.finish()
    csv = workdir / "residuals.csv"
    history.to_csv(csv, index=False)

    time_dir = latest_time(workdir)
    write_cell_centres(runner, workdir, timeout)
    rho = inputs["density"]
    cells = read_cell_fields(workdir, time_dir)
    volume = float(cells["V"].sum())
    mean_uz = float((cells["U"][:, 2] * cells["V"]).sum() / volume)
    mid = _read_mid_plane(workdir)
    q_in = -patch_flux(workdir, time_dir, "inlet")
    q_out = patch_flux(workdir, time_dir, "outlet")
    last = history.iloc[-1].to_dict() if len(history) else {}
    final = {k: float(v) for k, v in last.items() if k != "iteration" and not math.isnan(v)}
    iterations = int(last.get("iteration", 0))
    solution = AirSolution(
        case_dir=workdir,
        time_dir=time_dir,
        turbulence=case.air.turbulence,
        converged=parser.converged,
        iterations=iterations,
        residual_target=case.air.residual_target,
        final_residuals=final,
        residuals=history,
        residuals_csv=csv,
        wall_time_s=time.time() - started,
        solver_wall_time_s=solver_wall,
        density=rho,
        kinematic_viscosity=inputs["kinematic_viscosity"],
        omega=case.drum.omega,
        volumetric_flow=inputs["volumetric_flow"],
        inlet_mass_flow=rho * q_in,
        outlet_mass_flow=rho * q_out,
        free_area=float(mesh["area_m2"]),
        mean_axial_velocity=-mean_uz,
        mid_plane_axial_velocity=None if mid is None else -mid,
        expected_axial_velocity=inputs["bulk_velocity"],
        processes=processes,
        mesh={**mesh, **{k: v for k, v in inputs.items() if k.startswith("inlet_")},
              "mesh_volume_m3": volume},
    )
    if not parser.converged:
        raise AirNotConvergedError(
            iterations, final, case.air.residual_target, log, solution=solution
        )
    return solution


def _is_time(name: str) -> bool:
    try:
        float(name)
    except ValueError:
        return False
    return name != "0"
