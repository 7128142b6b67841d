"""The whole case: its sections checked together (the drum fits its lifters and particles), its
derived counts, the view the DEM moves (coarse-grained parcels), and its hashes.

A hash names a run's inputs; options added after runs had been made are left out at their old
value (:data:`_ADDED_LATER`) so that those runs keep their hashes.
"""

from __future__ import annotations

import hashlib
import json
import math
from pathlib import Path

from pydantic import Field, model_validator

from drumflow.case.lifter_shape import lifter_gap
from drumflow.case.sections import (
    BED_SOLIDS_FRACTION,
    PARTICLES_PER_PROCESS,
    Air,
    Contacts,
    Drum,
    Lifters,
    Particles,
    Plant,
    Run,
    _Section,
)


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
        if self.air.bed_states and self.air.model != "cfd":
            problems.append(
                f"air.bed_states: {len(self.air.bed_states)} state(s) with air.model = "
                f"'{self.air.model}': the air around the bed is solved by OpenFOAM; allowed with "
                "air.model = 'cfd', or no bed states"
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
        if state is not None:
            # The state by its content, not its path: the path is resolved against the case
            # file, so it names the checkout's place, and a moved checkout must keep its runs.
            data["run"]["start_state"] = _by_content(state)
        if data["air"].get("bed_states"):
            data["air"]["bed_states"] = [_by_content(s) for s in data["air"]["bed_states"]]
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


def _by_content(path: str) -> str:
    """A state file by its content's hash (as run.start_state), its path if it is missing."""
    return ("sha256:" + hashlib.sha256(Path(path).read_bytes()).hexdigest()
            if Path(path).is_file() else path)


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
    ("particles", "placement", "lattice"),
    ("air", "bed_states", []),
)

#: The options of :data:`_ADDED_LATER` that came after section hashes (geometry cache, start
#: states) were first stored: :meth:`Case.section_hash` leaves them out at their old value. The
#: earlier ones were always part of those hashes, so leaving them out would change them.
_ADDED_AFTER_SECTION_HASHES: tuple[tuple[str, str, object], ...] = (
    ("drum", "ends", "fixed"),
    ("particles", "placement", "lattice"),
)
