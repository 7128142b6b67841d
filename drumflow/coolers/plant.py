"""The full-scale drum cooler: one definition of the plant, and the variables a prediction changes.

:class:`PlantSpec` is read by the paper's exchanger scaled by a correlation
(:func:`drumflow.coolers.prediction.predict_plant`) and by the axial whole-drum model
(:mod:`drumflow.coolers.drum`), so both start from the same drum, streams and granules.
:data:`PAPER_PLANT` is the paper's industrial cooler.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

from drumflow.case import Case

__all__ = ["PAPER_PLANT", "OperatingPoint", "PlantSpec"]


@dataclass(frozen=True)
class OperatingPoint:
    """The variables a prediction can change.

    Attributes
    ----------
    rpm
        Drum rotation speed (1/min).
    air_mass_flow_kg_s
        Air mass flow (kg/s).
    feed_rate_kg_s
        Material mass flow (kg/s).
    particle_diameter_m
        Particle diameter (m).
    """

    rpm: float
    air_mass_flow_kg_s: float
    feed_rate_kg_s: float
    particle_diameter_m: float


@dataclass(frozen=True)
class PlantSpec:
    """The full-scale cooler: the one definition of the plant that ``drumflow predict`` (the
    paper's exchanger scaled by a correlation) and ``drumflow cooler drum`` (the axial cell
    model) both use.

    Attributes
    ----------
    diameter_m, length_m, rpm, tilt_deg
        Drum inner diameter and length (m), rotation speed (1/min), axis tilt (degrees).
    feed_rate_kg_s, material_inlet_temperature_c
        Material stream.
    air_mass_flow_kg_s, air_inlet_temperature_c, air_heat_capacity_j_kgk
        Air stream (counter-current).
    particle_diameter_m, particle_density_kg_m3, particle_heat_capacity_j_kgk,
    particle_conductivity_w_mk
        The granules.
    residence_time_s
        Measured mean solids residence time (the transport law's calibration point), or None.
    measured_material_outlet_c, measured_air_outlet_c
        The plant's measured outlets, reported beside predictions, never fitted to.
    """

    diameter_m: float
    length_m: float
    rpm: float
    tilt_deg: float
    feed_rate_kg_s: float
    material_inlet_temperature_c: float
    air_mass_flow_kg_s: float
    air_inlet_temperature_c: float
    particle_diameter_m: float
    particle_density_kg_m3: float
    particle_heat_capacity_j_kgk: float
    particle_conductivity_w_mk: float
    air_heat_capacity_j_kgk: float = 1005.0
    residence_time_s: float | None = None
    measured_material_outlet_c: float | None = None
    measured_air_outlet_c: float | None = None

    @classmethod
    def from_case(cls, case: Case) -> PlantSpec:
        """The plant of a slice case: its drum cross-section and air, ``plant`` section."""
        p = case.particles
        return cls(
            diameter_m=float(case.drum.diameter),
            length_m=float(case.plant.length),
            rpm=float(case.drum.rpm),
            tilt_deg=float(case.drum.tilt_deg),
            feed_rate_kg_s=float(case.plant.material_mass_flow),
            material_inlet_temperature_c=float(case.plant.material_inlet_temperature_C),
            air_mass_flow_kg_s=float(case.air.mass_flow),
            air_inlet_temperature_c=float(case.air.inlet_temperature_C),
            particle_diameter_m=float(p.diameter),
            particle_density_kg_m3=float(p.density),
            particle_heat_capacity_j_kgk=float(p.heat_capacity),
            particle_conductivity_w_mk=float(p.conductivity),
            air_heat_capacity_j_kgk=float(case.air.heat_capacity),
            measured_material_outlet_c=case.plant.material_outlet_temperature_C,
        )

    def operating_point(self) -> OperatingPoint:
        """The variables a prediction can change, at this plant's values."""
        return OperatingPoint(
            rpm=self.rpm,
            air_mass_flow_kg_s=self.air_mass_flow_kg_s,
            feed_rate_kg_s=self.feed_rate_kg_s,
            particle_diameter_m=self.particle_diameter_m,
        )

    def streams(self) -> dict[str, float]:
        """Keyword arguments of the exchanger functions (Eqs. 42-48) for this plant."""
        return {
            "material_mass_flow_kg_s": self.feed_rate_kg_s,
            "material_cp_j_kgk": self.particle_heat_capacity_j_kgk,
            "material_inlet_temperature_c": self.material_inlet_temperature_c,
            "air_mass_flow_kg_s": self.air_mass_flow_kg_s,
            "air_cp_j_kgk": self.air_heat_capacity_j_kgk,
            "air_inlet_temperature_c": self.air_inlet_temperature_c,
        }

    def changed(self, **changes: float | None) -> PlantSpec:
        """A copy with some fields changed (``None`` values keep the current one)."""
        return replace(self, **{k: v for k, v in changes.items() if v is not None})


PAPER_PLANT = PlantSpec(
    diameter_m=3.0,
    length_m=19.0,
    rpm=5.0,
    tilt_deg=1.5,
    feed_rate_kg_s=13.88889,
    material_inlet_temperature_c=90.0,
    air_mass_flow_kg_s=25.0,
    air_inlet_temperature_c=30.0,
    particle_diameter_m=2.7e-3,
    particle_density_kg_m3=1050.0,
    particle_heat_capacity_j_kgk=1465.38,
    particle_conductivity_w_mk=0.18596,
    air_heat_capacity_j_kgk=1005.0,
    residence_time_s=30.0 * 60.0,
    measured_material_outlet_c=46.5,
    measured_air_outlet_c=59.0,
)
"""The paper's industrial cooler (Burgos-Florez et al. 2019, Section 3.1 and Table 1)."""
