"""The validated case: the only place that knows the TOML case-file layout.

A case describes one drum study: the drum and its lifters (flights), the particles, the contact
laws, the air and how long and how finely to run. Units are SI unless the field name says
otherwise (``tilt_deg``, ``rpm``, ``initial_temperature_C``, ``pressure_kPa``).

Every problem in a case file is reported at once, each naming the field, the value and the
allowed range (:class:`drumflow.errors.CaseError`), before any solver starts.
"""

from __future__ import annotations

import hashlib
import json
import math
import tomllib
from pathlib import Path
from typing import Annotated, Any, Literal, TypeVar

from pydantic import BaseModel, ConfigDict, Field, ValidationError, model_validator

from drumflow.errors import CaseError

#: Bulk solids fraction of a settled bed of near-monodisperse spheres, used to turn a fill
#: fraction (share of the drum volume taken by the bed) into a particle count.
BED_SOLIDS_FRACTION = 0.6

#: Particles each MPI process should hold at least ('auto' processes).
PARTICLES_PER_PROCESS = 20_000

Positive = Annotated[float, Field(gt=0)]
PositiveInt = Annotated[int, Field(ge=1)]
Fraction = Annotated[float, Field(ge=0, le=1)]


#: The settings of every input model (drum case, cooler cases, sweep file): one place, so
#: that no case kind is looser than another.
#:
#: * ``extra="forbid"``: a typo such as ``diamter`` must not silently fall back to a default
#:   and produce a different drum than the user meant.
#: * ``strict=True``: a number written as text (``rpm = "5"``) is refused, not converted: TOML
#:   has numbers, so quotes are a mistake (a value pasted from elsewhere, a wrong key) that
#:   the user should see. An integer for a float field (``rpm = 5``) stays accepted.
#: * ``allow_inf_nan=False``: ``inf`` and ``nan`` are valid TOML floats, but no field means
#:   them, and a range check does not catch ``nan`` (every comparison is false).
INPUT_MODEL_CONFIG = ConfigDict(extra="forbid", frozen=True, strict=True, allow_inf_nan=False)


class _Section(BaseModel):
    model_config = INPUT_MODEL_CONFIG


class Drum(_Section):
    """The drum shell (a section of the real cooler's length)."""

    diameter: float = Field(gt=0, le=10, description="inner shell diameter, m")
    length: float = Field(gt=0, le=30, description="simulated section length l along the axis, m")
    tilt_deg: float = Field(1.5, ge=0, lt=30, description="axis tilt below horizontal, degrees")
    rpm: float = Field(gt=0, le=60, description="rotation speed, revolutions per minute")
    facet_size: Positive | Literal["auto"] = Field(
        "auto", description="STL facet edge length, m; 'auto' picks it from drum and particle size"
    )
    ends: Literal["fixed", "rotating", "periodic"] = Field(
        "fixed", description="how the section ends along the axis: 'fixed', two flat planes that "
        "stand still while the shell turns (the paper's closed slice; default); 'rotating', two "
        "end plates that turn with the shell, as a real drum's end walls do; 'periodic', no end "
        "plates, a particle leaving one end comes back at the other (the middle of a long drum)"
    )

    @property
    def radius(self) -> float:
        return 0.5 * self.diameter

    @property
    def omega(self) -> float:
        """Angular speed, rad/s."""
        return self.rpm * 2.0 * math.pi / 60.0

    @property
    def froude(self) -> float:
        """Rotational Froude number omega^2 R / g (1 = centrifuging)."""
        return self.omega**2 * self.radius / 9.81


class Lifters(_Section):
    """Lifters (flights) welded to the shell, one profile for all, evenly spaced.

    The profile is drawn in the drum cross-section: a radial base plate of height
    ``base_height`` from the shell inwards, then (for ``angled`` and ``L``) a lip of length
    ``lip_length`` at the base's tip, bent by ``lip_angle_deg`` from the base towards the
    direction of rotation, so that the lifter holds material as it rises (the paper's
    Figure 2 style). ``L`` means a lip at 90 degrees; ``straight`` has no lip.
    """

    count: int = Field(ge=0, le=64, description="number of lifters around the circumference")
    profile: Literal["straight", "angled", "L"] = "L"
    base_height: float = Field(gt=0, description="radial height of the base plate, m")
    lip_length: float = Field(0.0, ge=0, description="length of the lip, m")
    lip_angle_deg: float = Field(
        90.0, ge=30, le=170, description="angle between base and lip, degrees (L: 90)"
    )
    thickness: float = Field(gt=0, description="plate thickness, m")


class Particles(_Section):
    """The granular material, as monodisperse spheres."""

    diameter: float = Field(gt=0, le=0.2, description="sphere diameter, m")
    density: float = Field(gt=0, le=20000, description="solid density, kg/m^3")
    youngs_modulus: float = Field(gt=1e3, le=1e12, description="Young's modulus, Pa")
    youngs_modulus_reference: float | None = Field(
        None, gt=1e3, le=1e12,
        description="the material's real Young's modulus, Pa, when youngs_modulus is softened "
        "for speed: contact conduction areas refer to it (LIGGGHTS area_correction); default: "
        "youngs_modulus",
    )
    poisson_ratio: float = Field(gt=0, lt=0.5, description="Poisson's ratio")
    heat_capacity: float = Field(gt=0, le=1e5, description="specific heat, J/(kg K)")
    conductivity: float = Field(gt=0, le=1e4, description="thermal conductivity, W/(m K)")
    count: int | None = Field(None, ge=1, le=50_000_000, description="number of particles")
    fill_fraction: float | None = Field(
        None, gt=0, le=0.5, description="share of the drum volume taken by the settled bed"
    )
    initial_temperature_C: float = Field(90.0, gt=-100, lt=1500)
    initial_temperature_spread_C: float = Field(
        0.0,
        ge=0,
        lt=1000,
        description="half the particles start this much hotter than the other half "
        "(mean unchanged); 0 = uniform feed. Used by conduction checks.",
    )
    coarse_grain: float = Field(
        1.0, ge=1.0, le=4.0,
        description="opt-in coarse-graining for sweeps: the DEM moves parcels of this many "
        "particle diameters (count divided by its cube, same total mass) while the air's drag "
        "and heat act on each parcel as on the particles it stands for (same per kilogram); "
        "1 = every particle (default). See drumflow.case.Case.dem_case.",
    )
    interior: Literal["lumped", "shells"] = Field(
        "lumped",
        description="heat inside the granule: 'lumped', one temperature per particle (the "
        "paper's Eq. 20, valid for Biot numbers well below 0.1); 'shells', each particle's "
        "radial temperature profile in concentric shells, the air's film acting on the surface "
        "(drumflow.coupling.interior; needs air). The paper's cases stay 'lumped'.",
    )
    interior_shells: int | None = Field(
        None, ge=2, le=40,
        description="shells per particle with interior = 'shells'; default: the fewest whose "
        "temperature drop is within 0.125 % of the exact sphere at the case's largest Biot "
        "number (drumflow.coolers.particle_interior.shells_for_biot)",
    )

    @model_validator(mode="after")
    def _count_or_fill(self) -> Particles:
        if (self.count is None) == (self.fill_fraction is None):
            raise ValueError(
                "particles: give exactly one of 'count' (1 to 50,000,000) or "
                "'fill_fraction' (0 to 0.5)"
            )
        return self

    @property
    def radius(self) -> float:
        return 0.5 * self.diameter

    @property
    def volume(self) -> float:
        return math.pi / 6.0 * self.diameter**3

    @property
    def mass(self) -> float:
        return self.density * self.volume


class Contact(_Section):
    """One contact pair's coefficients (Hertz-Mindlin with rolling resistance)."""

    friction: float = Field(ge=0, le=2, description="static (Coulomb) friction coefficient")
    # LIGGGHTS 3.8 refuses coefficientRestitution <= 0.05.
    restitution: float = Field(gt=0.05, le=1, description="normal coefficient of restitution")
    rolling_friction: float = Field(
        0.05, ge=0, le=1, description="rolling friction coefficient (CDT model)"
    )


class Contacts(_Section):
    particle_particle: Contact
    particle_wall: Contact
    wall_youngs_modulus: float | None = Field(
        None,
        gt=1e3,
        le=1e12,
        description="Young's modulus of shell and lifters, Pa; default: the particles' value, "
        "so that wall contacts are as soft as particle contacts and do not set the time step",
    )
    tangential_damping: bool = Field(
        True,
        description="Hertz-Mindlin's tangential dashpot at particle-particle contacts (the paper's "
        "model has it); false: LIGGGHTS' 'tangential_damping off', which moves the bed's spin "
        "limit out to the tangential spring's own (2.4 times the contact step in the paper "
        "cases), so that 'auto' takes the contact step (README, 'The fast profile'); a change "
        "of the contact model, for sweeps",
    )


class Air(_Section):
    """The cooling air (counter-current). Used by the air field and the exchanger model."""

    model: Literal["none", "uniform", "cfd"] = Field(
        "none", description="'none': no air (conduction only); 'uniform': plug flow; 'cfd': OpenFOAM"
    )
    mass_flow: float = Field(25.0, ge=0, le=1000, description="air mass flow, kg/s")
    inlet_temperature_C: float = Field(30.0, gt=-60, lt=500)
    pressure_kPa: float = Field(101.3, gt=10, lt=1000)
    heat_capacity: float = Field(1005.0, gt=0, description="air specific heat, J/(kg K)")
    mesh_size: Positive | Literal["auto"] = Field(
        "auto", description="fluid mesh cell size, m; 'auto' = drum diameter / 20"
    )
    turbulence: Literal["realizableKE", "laminar"] = Field(
        "realizableKE", description="RANS model of the air (the paper: realizable k-epsilon)"
    )
    residual_target: float = Field(
        1e-4, gt=0, lt=1, description="steady solver stops when all initial residuals fall below"
    )
    max_iterations: int = Field(2000, ge=10, le=100_000, description="SIMPLE iteration limit")
    coupling_interval: PositiveInt | Literal["auto"] = Field(
        "auto", description="DEM steps between air-on-particle updates; 'auto' from the N-sweep"
    )
    pressure_gradient_force: bool = Field(
        False, description="add the pressure-gradient force of Eq. 4 to the drag"
    )
    warming: bool = Field(
        False, description="air that warms (two-way heat): the coupling loop solves the air's "
        "temperature on the air field's grid with the particles' heat as its source, and each "
        "particle sees the air of its cell (drumflow.air.heat); false: the paper's one-way air "
        "at the inlet temperature everywhere",
    )


class Run(_Section):
    """How long and how finely to simulate."""

    time: float = Field(gt=0, le=3600, description="simulated time, s")
    time_step: Positive | Literal["auto", "contact"] = Field(
        "auto", description="DEM time step, s, or 'auto': the largest that resolves the fastest "
        "contact in 10 steps, stays below run.rayleigh_fraction of the Rayleigh time and below 0.8 "
        "of the bed's spin limit; 'contact': the same without the spin limit (faster for beds of "
        "soft, deeply overlapping particles; their spin is then numerical, README 'The spin limit')")
    rayleigh_fraction: float = Field(
        0.2, gt=0, le=0.5, description="'auto' time step as a fraction of the Rayleigh time"
    )
    dump_interval: float = Field(
        0.02,
        gt=0,
        description="output step of the observables, s: mean temperature and the crossing dump "
        "(particles near the axis plane) are written this often (the paper's dt, Table 5)",
    )
    snapshot_interval: float = Field(
        0.5, gt=0, description="time between full particle snapshots (pictures, checks), s"
    )
    mass_flow_start: float = Field(
        1.0, ge=0, description="start of the falling-mass-flow window, s (paper: after 1 s)"
    )
    processes: Annotated[int, Field(ge=1, le=1024)] | Literal["auto"] = Field(
        "auto", description="MPI processes, or 'auto': serial below "
        "2 x PARTICLES_PER_PROCESS particles, else one per PARTICLES_PER_PROCESS up to the cores"
    )
    seed: int = Field(5_489_317, ge=1, lt=2**31, description="random seed for insertion")
    restart_interval: float = Field(
        0.5, gt=0, description="time between restart files (resume after an interrupt), s"
    )
    neighbor_skin: Positive | Literal["auto"] = Field(
        "auto", description="neighbour-list skin, m; 'auto' = 0.5 particle diameters"
    )
    conduction: bool = Field(
        True, description="particle-particle heat conduction (paper Eq. 24); off: the particles "
        "exchange heat with the air only"
    )
    force_time_step: bool = Field(
        False, description="run a fixed time_step above the stability limit anyway (stress tests)"
    )
    restitution_correction: bool = Field(
        True, description="give LIGGGHTS the restitution that the time step realises as the "
        "case's (drumflow.dem.restitution); off: pass the coefficients through"
    )
    wall_motion: Literal["auto", "moving_mesh", "static_shell"] = Field(
        "auto", description="'moving_mesh': shell and lifters rotate as one mesh; "
        "'static_shell': the cylinder stays put with a surface velocity, only the lifters move; "
        "'auto': static_shell"
    )
    stop: Literal["fixed", "converged"] = Field(
        "fixed", description="'fixed': run for run.time; 'converged': end as soon as the air's "
        "heat-transfer coefficient and the falling mass flow are both known to run.stop_tolerance "
        "(95% intervals over whole lifter cycles after the start-up, drumflow.convergence), at the "
        "latest at run.time"
    )
    stop_tolerance: float = Field(
        0.01, gt=0, le=0.5, description="'converged' stop: largest relative half-width of the "
        "95% intervals of h and of the falling mass flow"
    )
    stop_min_time: Positive | Literal["auto"] = Field(
        "auto", description="'converged' stop: never before this simulated time, s; 'auto' = "
        "mass_flow_start + the longer of 1 s and three lifter passing periods"
    )
    crossings: Literal["dump", "loop"] = Field(
        "dump", description="how the axis-plane crossings are found: 'dump': LIGGGHTS writes the "
        "particles near the plane at every output step (text, about 3 GB for the paper's model "
        "one); 'loop': the air coupling loop finds them in memory and writes only the crossings "
        "(dem/coupling/crossings.csv; needs air)"
    )
    start_state: str | None = Field(
        None, min_length=1, description="start the DEM from this start state (.npz, written by "
        "`drumflow export RUN_DIR --state`) instead of the lattice placement: its particles, "
        "velocities, spins, radii and temperatures at its simulated time and drum angle; a path "
        "relative to the case file; its scene (drum, lifters, particles) and particle count must "
        "be this case's"
    )


class Plant(_Section):
    """The full-scale cooler the section stands for (exchanger model, predictions)."""

    length: float = Field(19.0, gt=0, le=200, description="cooler length L, m")
    material_mass_flow: float = Field(13.88889, gt=0, description="feed rate, kg/s")
    material_inlet_temperature_C: float = Field(90.0, gt=-60, lt=1500)
    material_outlet_temperature_C: float | None = Field(None, gt=-60, lt=1500)


class Case(_Section):
    """A complete drumflow case."""

    name: str = Field(min_length=1, max_length=80, pattern=r"^[A-Za-z0-9_.-]+$")
    description: str = ""
    drum: Drum
    lifters: Lifters
    particles: Particles
    contacts: Contacts
    air: Air = Air()
    run: Run
    plant: Plant = Plant()

    @model_validator(mode="after")
    def _geometry_fits(self) -> Case:
        problems: list[str] = []
        R = self.drum.radius
        d = self.particles.diameter
        lf = self.lifters
        if lf.base_height >= 0.5 * R:
            problems.append(
                f"lifters.base_height = {lf.base_height} m: must be below half the drum "
                f"radius ({0.5 * R:g} m)"
            )
        if lf.profile == "straight" and lf.lip_length > 0:
            problems.append(
                f"lifters.lip_length = {lf.lip_length} m: a 'straight' lifter has no lip (use 0)"
            )
        if lf.profile != "straight" and lf.lip_length <= 0:
            problems.append(
                f"lifters.lip_length = {lf.lip_length} m: an '{lf.profile}' lifter needs a lip "
                "longer than 0"
            )
        if lf.profile == "L" and abs(lf.lip_angle_deg - 90.0) > 1e-9:
            problems.append(
                f"lifters.lip_angle_deg = {lf.lip_angle_deg}: an 'L' lifter has a 90 degree lip "
                "(use profile 'angled' for other angles)"
            )
        if lf.thickness >= lf.base_height:
            problems.append(
                f"lifters.thickness = {lf.thickness} m: must be below base_height "
                f"({lf.base_height} m)"
            )
        if lf.count > 0:
            # Free arc between neighbouring lifters at the tip radius: particles must fit
            # through it, or they jam and the DEM run only measures a blocked drum.
            from drumflow.geometry.lifters import lifter_gap

            gap = lifter_gap(R, lf)
            if gap < 3.0 * d:
                problems.append(
                    f"particles.diameter = {d} m: the gap between lifters is {gap:.4g} m and "
                    f"must be at least 3 particle diameters ({3 * d:.4g} m); use fewer or "
                    "smaller lifters or smaller particles"
                )
        if d > 0.25 * self.drum.length:
            problems.append(
                f"particles.diameter = {d} m: must be at most a quarter of drum.length "
                f"({0.25 * self.drum.length:g} m) so that the section holds several layers"
            )
        parcel = self.particles.coarse_grain * d
        if self.particles.coarse_grain > 1.0 and (
                parcel > 0.25 * self.drum.length or (lf.count > 0 and gap < 3.0 * parcel)):
            limit = 0.25 * self.drum.length if lf.count == 0 else min(0.25 * self.drum.length, gap / 3.0)
            problems.append(
                f"particles.coarse_grain = {self.particles.coarse_grain}: parcels of {parcel:.4g} m "
                f"must fit the section and pass between the lifters (at most {limit:.4g} m, i.e. "
                f"coarse_grain up to {limit / d:.3g})"
            )
        if self.particles.count is not None and problems == []:
            solids = self.particles.count * self.particles.volume
            drum_volume = math.pi * R**2 * self.drum.length
            if solids > 0.35 * drum_volume:
                problems.append(
                    f"particles.count = {self.particles.count}: the solids would take "
                    f"{solids / drum_volume:.0%} of the drum volume; allowed up to 35% "
                    f"(at most {int(0.35 * drum_volume / self.particles.volume)} particles)"
                )
        if self.drum.froude >= 1.0:
            problems.append(
                f"drum.rpm = {self.drum.rpm}: Froude number {self.drum.froude:.2f} >= 1, the bed "
                f"centrifuges; allowed below {60 / (2 * math.pi) * math.sqrt(9.81 / R):.1f} rpm"
            )
        if isinstance(self.run.time_step, float) and self.run.time_step > self.run.dump_interval:
            problems.append(
                f"run.time_step = {self.run.time_step} s: must not exceed run.dump_interval "
                f"({self.run.dump_interval} s)"
            )
        if self.run.snapshot_interval < self.run.dump_interval:
            problems.append(
                f"run.snapshot_interval = {self.run.snapshot_interval} s: must be at least "
                f"run.dump_interval ({self.run.dump_interval} s)"
            )
        if self.run.dump_interval > 0.5 * self.run.time:
            problems.append(
                f"run.dump_interval = {self.run.dump_interval} s: must be at most half of "
                f"run.time ({0.5 * self.run.time:g} s)"
            )
        if self.run.mass_flow_start >= self.run.time:
            problems.append(
                f"run.mass_flow_start = {self.run.mass_flow_start} s: must be below run.time "
                f"({self.run.time} s)"
            )
        if self.run.stop == "converged" and self.air.model == "none":
            problems.append(
                "run.stop = 'converged': needs air (the stop rule watches the air's heat-transfer "
                "coefficient); allowed with air.model = 'uniform' or 'cfd', else run.stop = 'fixed'"
            )
        if self.air.warming and self.air.model == "none":
            problems.append(
                "air.warming = true: needs air (the coupling loop solves its temperature); "
                "allowed with air.model = 'uniform' or 'cfd'"
            )
        if self.particles.interior == "shells" and self.air.model == "none":
            problems.append(
                "particles.interior = 'shells': needs air (the coupling loop advances the shells "
                "with the air's film); allowed with air.model = 'uniform' or 'cfd', else "
                "particles.interior = 'lumped'"
            )
        if self.run.crossings == "loop" and self.air.model == "none":
            problems.append(
                "run.crossings = 'loop': needs air (the coupling loop finds them); allowed with "
                "air.model = 'uniform' or 'cfd', else run.crossings = 'dump'"
            )
        if self.run.stop_min_time != "auto" and not (
                self.run.mass_flow_start < self.run.stop_min_time <= self.run.time):
            problems.append(
                f"run.stop_min_time = {self.run.stop_min_time} s: must be above "
                f"run.mass_flow_start ({self.run.mass_flow_start} s) and at most run.time "
                f"({self.run.time} s)"
            )
        if self.drum.ends == "periodic" and self.air.model != "none":
            # Not checked: the air enters and leaves through the section's end faces while the
            # particles wrap around them, and the coupling loop was not run against it.
            problems.append(
                f"drum.ends = 'periodic': not with air.model = '{self.air.model}' (the air's "
                "inlet and outlet are the end faces the particles would wrap through); allowed "
                "with air.model = 'none', or drum.ends = 'fixed' or 'rotating'"
            )
        size = self.air.mesh_size
        if size != "auto" and size > self.drum.diameter:
            # A cell larger than the drum cannot resolve it (gmsh would make a handful of
            # degenerate cells, or none): refuse it before any mesher runs.
            problems.append(
                f"air.mesh_size = {size:g} m: must be at most the drum diameter "
                f"({self.drum.diameter:g} m)"
            )
        if problems:
            raise ValueError("\n".join(problems))
        return self

    # -- derived quantities --------------------------------------------------------------
    @property
    def particle_count(self) -> int:
        """The number of particles, from ``count`` or from ``fill_fraction``."""
        if self.particles.count is not None:
            return self.particles.count
        assert self.particles.fill_fraction is not None
        drum_volume = math.pi * self.drum.radius**2 * self.drum.length
        solids = self.particles.fill_fraction * drum_volume * BED_SOLIDS_FRACTION
        return max(1, round(solids / self.particles.volume))

    def processes(self, cores: int) -> int:
        """MPI processes for the run on a machine with ``cores`` cores: ``run.processes``, or
        the 'auto' choice.

        'auto' keeps at least :data:`PARTICLES_PER_PROCESS` particles on each process: with
        fewer, halo exchange outweighs the split (measured here: 3,000 particles on 2 ranks
        ran only 1.12 times faster, a 500-particle drum slower than serial). The core count
        comes from the launch profile (:meth:`drumflow.runner.LaunchProfile.processes_for`), so
        the case model itself never looks at the machine.
        """
        if self.run.processes != "auto":
            return int(self.run.processes)
        return max(1, min(cores, self.particle_count // PARTICLES_PER_PROCESS))

    @property
    def particle_mass_total(self) -> float:
        return self.particle_count * self.particles.mass

    def dem_case(self) -> Case:
        """The case the DEM moves: itself, or with ``particles.coarse_grain = k > 1`` its parcels.

        Parcels are spheres ``k`` times the particle diameter, ``count / k**3`` of them (same
        total mass; a ``fill_fraction`` case keeps its fraction), with the particles' material
        and contacts, and ``coarse_grain = 1`` (the view is an ordinary case of larger
        particles: geometry, time step, deck, placement and the DEM's counts follow from it).
        What keeps the physics per kilogram is the coupling loop: it computes the air's drag and
        heat for a particle of the real diameter at the parcel's velocity and temperature and
        gives the parcel ``k**3`` times that (:class:`drumflow.coupling.spec.CouplingSpec`
        ``coarse_grain``), so acceleration and heating rate are the particles'. Not kept: the
        contact mechanics (a parcel's collisions are those of a larger sphere: the bed's
        packing in the lifters, the curtain's density) and contact conduction per kilogram,
        which is what the error measurement of the fast-and-accurate bench is for.
        """
        k = self.particles.coarse_grain
        if k == 1.0:
            return self
        data = self.model_dump(mode="json")
        p = data["particles"]
        p["diameter"] = self.particles.diameter * k
        p["coarse_grain"] = 1.0
        if self.particles.count is not None:
            p["count"] = max(1, round(self.particles.count / k**3))
        return Case.model_validate(data)

    def canonical_json(self) -> str:
        """The case as canonical JSON (sorted keys), the basis of its hash.

        Options added after runs had been made are left out while they hold the value that
        reproduces the old behaviour (:data:`_ADDED_LATER`), so that those runs keep their
        hash, their run directories and their caches; a fixed-time run also leaves out the
        'converged' rule's tolerances, which do nothing then.
        """
        data = self.model_dump(mode="json")
        for section, name, old_behaviour in _ADDED_LATER:
            if data[section].get(name) == old_behaviour:
                del data[section][name]
        if "stop" not in data["run"]:
            for name in ("stop_tolerance", "stop_min_time"):
                del data["run"][name]
        state = data["run"].get("start_state")
        if state is not None and Path(state).is_file():
            # The state by its content, not its path: the path is resolved against the case
            # file, so it names the checkout's place, and a moved checkout must keep its runs.
            data["run"]["start_state"] = "sha256:" + hashlib.sha256(Path(state).read_bytes()).hexdigest()
        return json.dumps(data, sort_keys=True, separators=(",", ":"))

    def hash(self) -> str:
        """SHA-256 of the canonical case, identifying a run's inputs."""
        return hashlib.sha256(self.canonical_json().encode()).hexdigest()

    def section_hash(self, *sections: str) -> str:
        """Hash of some sections only, e.g. ``("drum", "lifters")`` for the geometry cache.

        Options of :data:`_ADDED_AFTER_SECTION_HASHES` at their old value are left out, so
        that a geometry cache or a start state made before the option existed keeps its hash.
        """
        data = self.model_dump(mode="json")
        for section, name, old_behaviour in _ADDED_AFTER_SECTION_HASHES:
            if section in sections and data[section].get(name) == old_behaviour:
                del data[section][name]
        sub = {s: data[s] for s in sections}
        return hashlib.sha256(json.dumps(sub, sort_keys=True).encode()).hexdigest()


#: Options that came after the first runs, each with the value that does what the code did
#: before it existed: ``Case.canonical_json`` leaves them out at that value. Without this, a
#: new option resets every run directory at ``drumflow run`` (a paper run of hours refused
#: to resume when ``particles.coarse_grain`` arrived). Add each new option here.
_ADDED_LATER: tuple[tuple[str, str, object], ...] = (
    ("run", "stop", "fixed"),
    ("run", "crossings", "dump"),
    ("particles", "coarse_grain", 1.0),
    ("contacts", "tangential_damping", True),
    ("particles", "interior", "lumped"),
    ("particles", "interior_shells", None),
    ("air", "warming", False),
    ("run", "start_state", None),
    ("drum", "ends", "fixed"),
)

#: The options of :data:`_ADDED_LATER` that came after section hashes (geometry cache, start
#: states) were first stored: :meth:`Case.section_hash` leaves them out at their old value. The
#: earlier ones were always part of those hashes, so leaving them out would change them.
_ADDED_AFTER_SECTION_HASHES: tuple[tuple[str, str, object], ...] = (
    ("drum", "ends", "fixed"),
)


def _format_error(err: dict[str, Any], loc: str) -> list[str]:
    msg: str = err.get("msg", "")
    value = err.get("input")
    etype = err.get("type", "")
    if etype == "value_error":
        # Our own model validators already name field, value and range, one per line.
        text = msg.removeprefix("Value error, ")
        return [line for line in text.splitlines() if line]
    if etype == "missing":
        return [f"{loc}: missing (required)"]
    if etype == "extra_forbidden":
        return [f"{loc} = {value!r}: unknown field (check the spelling)"]
    if etype in _TYPES and isinstance(value, str):
        # Strict input models (INPUT_MODEL_CONFIG): say what to write instead of the text.
        return [f"{loc} = {value!r}: text, not {_TYPES[etype]}; write the value without quotes"]
    if etype == "finite_number":
        return [f"{loc} = {value!r}: not a finite number; allowed: a finite number (not inf or nan)"]
    ctx = err.get("ctx") or {}
    bounds = [f"{word} {ctx[key]}" for key, word in _BOUNDS if key in ctx]
    allowed = f"; allowed: {' and '.join(bounds)}" if bounds else ""
    return [f"{loc} = {value!r}: {msg[:1].lower()}{msg[1:]}{allowed}"]


#: pydantic's type errors of the strict models and the type each one expects.
_TYPES = {"float_type": "a number", "int_type": "an integer", "bool_type": "true or false"}


_BOUNDS = (("gt", ">"), ("ge", ">="), ("lt", "<"), ("le", "<="))


def _clean_loc(err: dict[str, Any]) -> str:
    # pydantic appends the union member tag ("float", "literal['auto']") to the location.
    parts = [str(p) for p in err.get("loc", ())]
    return ".".join(
        p for p in parts
        if p not in {"float", "int"} and not p.startswith(("literal[", "constrained-"))
    )


def _merge_problems(errors: list[dict[str, Any]]) -> list[str]:
    """One line per mistake: a union field (float | "auto") fails once per member."""
    grouped: dict[str, list[dict[str, Any]]] = {}
    for err in errors:
        grouped.setdefault(_clean_loc(err), []).append(err)
    lines: list[str] = []
    for loc, errs in grouped.items():
        if len(errs) > 1 and all(e.get("type") != "value_error" for e in errs):
            # "must be > 0 or 'auto'": each member's own message and bounds, joined.
            parts = []
            for e in errs:
                text = _format_error(e, loc)[0].split(": ", 1)[-1]
                parts.append(text)
            lines.append(f"{loc} = {errs[0].get('input')!r}: " + " or ".join(sorted(set(parts))))
            continue
        for err in errs:
            lines.extend(_format_error(err, loc))
    return lines


_Model = TypeVar("_Model", bound=BaseModel)


def validate_model(model: type[_Model], data: dict[str, Any],
                   source: Path | str | None = None) -> _Model:
    """Validate nested dictionaries into any drumflow input model (drum case, cooler case,
    sweep file), with every problem named by field, value and allowed range.

    Raises
    ------
    CaseError
        Listing every problem.
    """
    try:
        return model.model_validate(data)
    except ValidationError as exc:
        raise CaseError(_merge_problems([dict(e) for e in exc.errors()]), source) from None


def read_toml(path: Path | str) -> dict[str, Any]:
    """Read a TOML input file.

    Raises
    ------
    CaseError
        When the file is missing or is not valid TOML.
    """
    from drumflow.errors import BadFileError
    from drumflow.readers import read_text

    path = Path(path)
    if not path.is_file():
        raise CaseError([f"case file {path}: not found"], path)
    try:
        text = read_text(path, "a TOML file")
    except BadFileError as exc:
        # A CaseError like every other problem of an input file; the message names the file.
        raise CaseError([exc.problem], path) from None
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise CaseError([f"not valid TOML: {exc}"], path) from None


def case_from_dict(data: dict[str, Any], source: Path | str | None = None) -> Case:
    """Validate a case given as nested dictionaries.

    Raises
    ------
    CaseError
        Listing every problem, each with field, value and allowed range.
    """
    return validate_model(Case, data, source)


def load_case(path: Path | str) -> Case:
    """Read and validate a TOML case file.

    Raises
    ------
    CaseError
        When the file is missing, is not valid TOML, or has invalid values.
    """
    data = read_toml(path)
    run = data.get("run")
    if isinstance(run, dict) and isinstance(run.get("start_state"), str):
        # Relative to the case file, as written; the case holds it resolved, so that the copy
        # of the case in a run directory still names the same file.
        state = Path(run["start_state"]).expanduser()
        if not state.is_absolute():
            run["start_state"] = str((Path(path).resolve().parent / state).resolve())
    return case_from_dict(data, source=path)


#: The fast profile (``drumflow run --fast``; README, 'The fast profile'): each setting with the
#: measurement that keeps the answers. Without the particles' tangential dashpot the bed has no
#: spin limit below the spring's own, so "auto" takes the contact step (about twice the
#: damped bed's) without the numerical spin that biased the falling mass flow by +5.5 % there:
#: on paper model two's parcels over 17.5 s the cascading flow landed -0.3 % from the resolved
#: spin's (noise +-2.4 %), the heat answers 0.02 %. Conduction between particles moves no
#: heat out of the slice and, with one-way air, changed nothing measurable. The converged stop
#: ends a run once h and the falling mass flow are known to run.stop_tolerance (only with air:
#: it watches the air's h).
FAST_PROFILE: tuple[tuple[str, str, object], ...] = (
    ("contacts", "tangential_damping", False),
    ("run", "conduction", False),
    ("run", "stop", "converged"),
)


def fast_profile(case: Case) -> tuple[Case, list[str]]:
    """The case under :data:`FAST_PROFILE`, named ``<name>_fast`` (its own run directory), and
    what changed, as ``"section.name: old -> new"`` lines (empty if the case already had it).
    The converged stop is left out for a case without air, which it cannot watch."""
    data = case.model_dump(mode="json")
    changed: list[str] = []
    for section, name, value in FAST_PROFILE:
        if (section, name) == ("run", "stop") and case.air.model == "none":
            continue
        old = data[section][name]
        if old != value:
            data[section][name] = value
            changed.append(f"{section}.{name}: {json.dumps(old)} -> {json.dumps(value)}")
    if not changed:
        return case, changed
    if not data["name"].endswith("_fast"):
        data["name"] = f"{data['name']}_fast"
    return Case.model_validate(data), changed


def case_to_toml(case: Case) -> str:
    """Write a case back as TOML (used for the copy kept in each run directory)."""
    import tomli_w

    data = case.model_dump(mode="json", exclude_none=True)
    return tomli_w.dumps(data)
