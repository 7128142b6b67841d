"""Writing the drum's OpenFOAM air case: every dictionary and initial field (foamlib).

:mod:`drumflow.air.foam` runs the case, :mod:`drumflow.air.foam_results` reads what it wrote.

The steady air field of the drum section with OpenFOAM v1912 ``simpleFoam`` and MRF.

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
:func:`write_fv_schemes`), SIMPLEC with ``residualControl`` at ``air.residual_target``. All
dictionaries are written with foamlib.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Any, Literal

if TYPE_CHECKING:
    from drumflow.air.solids_fraction import CellZones, PorosityZones
    from drumflow.case import Case

#: k-epsilon model constant C_mu (standard value) for the inlet epsilon.
CMU = 0.09
#: Inlet turbulence intensity u'/U.
TURBULENCE_INTENSITY = 0.05
#: Inlet mixing length as a fraction of the hydraulic diameter.
MIXING_LENGTH_FRACTION = 0.07

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
                # At least one sweep every iteration. In periodic drums k's normalised initial
                # residual fell to ~5e-9 (below this absolute tolerance) within ~300 iterations,
                # with a near-wall cell at k's bound (1e-15), and k was then never solved again
                # in any cell: model two's bed never converged (2,000 iterations); with one
                # sweep k's residual is ~5e-5 and SIMPLE converges in 1,016.
                "minIter": 1,
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


def write_field(
    case_dir: Path,
    name: str,
    dims: dict[str, int],
    internal: float | list[float],
    boundary: dict[str, dict[str, Any]],
) -> None:
    """Write the initial field ``0/NAME``: its dimensions (``dims`` as foamlib's
    ``DimensionSet`` keywords, e.g. ``{"length": 1, "time": -1}``), a uniform internal value
    and the boundary conditions by patch; an existing file is replaced, not merged."""
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
    write_field(
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
    write_field(
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
    write_field(
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
    write_field(
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
    write_field(
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


# -- porosity zones (drumflow.air.bed_air, drumflow.verify.porous_foam) ----------------

def write_zone_sets(case_dir: Path, zones: CellZones, names: list[str] | None = None,
                    ) -> None:
    """``system/topoSetDict``: one cellZoneSet per zone, from its cell list, named ``names``
    (default the zones' own)."""
    from foamlib import FoamFile

    topo = case_dir / "system" / "topoSetDict"
    topo.unlink(missing_ok=True)
    with FoamFile(topo) as f:
        f["actions"] = [
            {"name": name, "type": "cellZoneSet", "action": "new", "source": "labelToCell",
             "value": [int(c) for c in cells]}
            for name, cells in zip(names or zones.names, zones.cells, strict=True)
        ]


def darcy_forchheimer_coeffs(d: float, f: float) -> dict[str, Any]:
    """The ``DarcyForchheimerCoeffs`` dictionary of isotropic coefficients d (1/m^2), f (1/m)."""
    return {
        "d": [float(d)] * 3,
        "f": [float(f)] * 3,
        "coordinateSystem": {
            "type": "cartesian",
            "origin": [0.0, 0.0, 0.0],
            "coordinateRotation": {"type": "axesRotation", "e1": [1.0, 0.0, 0.0],
                                   "e2": [0.0, 1.0, 0.0]},
        },
    }


def write_porosity(case_dir: Path, zones: PorosityZones,
                   host: Literal["fvOptions", "porosityProperties"]) -> None:
    """``system/topoSetDict`` (the zones' cellZoneSets) and one isotropic DarcyForchheimer
    resistance per zone, where the solver reads it: ``system/fvOptions`` as an
    ``explicitPorositySource`` (stock simpleFoam v1912, the bed-air cases), or
    ``constant/porosityProperties`` (porousSimpleFoam, the verification's porous bed)."""
    from foamlib import FoamFile

    write_zone_sets(case_dir, zones)
    path = case_dir / ("system" if host == "fvOptions" else "constant") / host
    path.unlink(missing_ok=True)
    with FoamFile(path) as f:
        for name, d, fc in zip(zones.names, zones.d, zones.f, strict=True):
            coeffs = darcy_forchheimer_coeffs(float(d), float(fc))
            if host == "fvOptions":
                f[name] = {"type": "explicitPorositySource", "active": True,
                           "explicitPorositySourceCoeffs": {
                               "selectionMode": "cellZone", "cellZone": name,
                               "type": "DarcyForchheimer", "DarcyForchheimerCoeffs": coeffs}}
            else:  # porosityProperties takes the model itself, without selectionMode
                f[name] = {"type": "DarcyForchheimer", "active": True, "cellZone": name,
                           "DarcyForchheimerCoeffs": coeffs}


# -- the whole case ---------------------------------------------------------------------


def air_properties_for(case: Case) -> tuple[float, float]:
    """Air density (ideal gas at inlet p and T) and kinematic viscosity (air table), SI."""
    from drumflow.geometry.fluid import air_density
    from drumflow.physics.air import kinematic_viscosity

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


