"""The sections of a case file (drum, lifters, particles, contacts, air, run, plant) and the one
configuration every drumflow input model shares.

Units are SI unless the field name says otherwise (``tilt_deg``, ``rpm``,
``initial_temperature_C``, ``pressure_kPa``).
"""

from __future__ import annotations

import math
from typing import Annotated, Literal

from pydantic import BaseModel, ConfigDict, Field, model_validator

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
    placement: Literal["lattice", "random"] = Field(
        "lattice",
        description="initial bed: 'lattice', a face-centred-cubic lattice filled from the bottom "
        "(settles by a fraction of a diameter; the default); 'random', a loose random packing "
        "(random sequential addition, solids fraction about 0.3, seeded by run.seed) that "
        "settles into a random bed, as a poured bed of equal beads lies; a lattice of equal "
        "spheres is a crystal, which a drum without lifters does not break up quickly "
        "(drumflow.dem.placement)",
    )
    interior_shells: int | None = Field(
        None, ge=2, le=40,
        description="shells per particle with interior = 'shells'; default: the fewest whose "
        "temperature drop is within 0.125 % of the exact sphere at the case's largest Biot "
        "number (drumflow.physics.particle_interior.shells_for_biot)",
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
    bed_states: list[str] = Field(
        [], max_length=8, description="air around the bed (issue 32): bed "
        "states of this scene (.npz, `drumflow export RUN_DIR --state --time T`) at drum angles "
        "spread over one lifter spacing; the air stage solves the air with each state's bed as "
        "Ergun porosity and periodic axial air (a piece of a long drum), and the coupling loop "
        "uses the state nearest the drum's angle modulo the lifter spacing "
        "(drumflow.air.bed_phases); paths relative to the case file; needs air.model = 'cfd'; "
        "empty: the air of the empty drum",
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
