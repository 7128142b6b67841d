"""The solved grate cooler: its converged fields and headline numbers, and their export.

:func:`drumflow.coolers.grate.model.solve_grate` returns a :class:`GrateSolution`; the
pictures (:mod:`drumflow.coolers.grate.plots`) and the studies read it.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

from drumflow.coolers.grate.case import GrateCase
from drumflow.coolers.grate.fans import column_pressure_drops, fan_pressure
from drumflow.coolers.grate.properties import ClinkerProperties, radiation_conductance
from drumflow.physics.air import air_enthalpy

__all__ = ["GrateSolution"]

FloatArray = NDArray[np.float64]


@dataclass(frozen=True)
class GrateSolution:
    """The converged fields and headline numbers of one grate-cooler solve.

    Arrays are indexed ``[j, i]``: layer j from the grate (0) to the bed top (m - 1), column
    i from the kiln end (0) to the discharge (n - 1). Temperatures in K, heat in W.
    """

    case: GrateCase
    x: FloatArray
    y: FloatArray
    clinker_temperature: FloatArray
    air_temperature: FloatArray
    freeboard_temperature: FloatArray
    heat_transfer_coefficient: FloatArray
    air_column_flow: FloatArray
    bed_height: float
    sweeps: int
    residual: float
    energy_imbalance: float
    wall_time_s: float
    history: list[tuple[int, float, float]] = field(repr=False, default_factory=list)

    @property
    def clinker(self) -> ClinkerProperties:
        return ClinkerProperties.of(self.case)

    @property
    def caloric_temperature(self) -> FloatArray:
        """Average caloric temperature of the clinker leaving each column, K (the report's
        Figures 11 and 13): the temperature of the layers' mean enthalpy."""
        props = self.clinker
        return props.temperature(props.enthalpy(self.clinker_temperature).mean(axis=0))

    @property
    def clinker_outlet_temperature(self) -> float:
        """Caloric temperature of the clinker leaving the grate, K."""
        return float(self.caloric_temperature[-1])

    @property
    def secondary_air_temperature(self) -> float:
        """Freeboard air leaving at the kiln end, K (the report's air outlet temperature)."""
        return float(self.freeboard_temperature[0])

    @property
    def heat_duty(self) -> float:
        """Heat the clinker would give up cooled to the air inlet temperature, W."""
        props, c = self.clinker, self.case.clinker
        return float(c.mass_flow * (props.enthalpy(c.inlet_temperature)
                                    - props.enthalpy(self.case.air.inlet_temperature)))

    @property
    def clinker_heat_released(self) -> float:
        """Heat the clinker gives up between inlet and outlet, W."""
        props, c = self.clinker, self.case.clinker
        h_out = float(props.enthalpy(self.clinker_temperature[:, -1]).mean())
        return float(c.mass_flow * (float(props.enthalpy(c.inlet_temperature)) - h_out))

    @property
    def heat_recovered(self) -> float:
        """Heat taken up by the air leaving as secondary air, W."""
        a = self.case.air
        return float(a.mass_flow * (air_enthalpy(self.secondary_air_temperature)
                                    - air_enthalpy(a.inlet_temperature)))

    @property
    def efficiency(self) -> float:
        """Recovered heat over the heat duty (share of the clinker's heat above the air inlet
        temperature that reaches the kiln with the secondary air)."""
        return self.heat_recovered / self.heat_duty

    @property
    def radiation_heat(self) -> float:
        """Heat radiated by the bed top to the freeboard, W."""
        case = self.case
        if not case.model.radiation:
            return 0.0
        c_rad = radiation_conductance(case, self.x.size)
        top = self.clinker_temperature[-1]
        return float(np.sum(c_rad * (top**4 - self.freeboard_temperature**4)))

    @property
    def air_flow(self) -> float:
        """Total cooling-air mass flow, kg/s (the operating point with ``air.supply = "fan"``)."""
        return self.case.air.mass_flow

    @property
    def column_pressure_drop(self) -> FloatArray:
        """Ergun pressure drop across the bed of every column, Pa."""
        return column_pressure_drops(self.case, self.air_temperature, self.air_column_flow,
                                     self.bed_height)

    @property
    def bed_pressure_drop(self) -> float:
        """Flow-weighted mean of the columns' bed pressure drops, Pa (what the fan sees)."""
        shares = self.air_column_flow / self.air_column_flow.sum()
        return float(np.sum(shares * self.column_pressure_drop))

    @property
    def fan_pressure(self) -> float | None:
        """Pressure rise of the fan curve at the air flow, Pa (None for a given air flow)."""
        fan = self.case.fan
        if self.case.air.supply != "fan" or fan is None:
            return None
        return fan_pressure(fan, self.air_flow, self.case.air.inlet_temperature)

    def summary(self) -> dict[str, Any]:
        """Headline numbers (JSON-ready)."""
        n, m = self.x.size, self.y.size
        fan_p = self.fan_pressure
        return {
            "air_supply": self.case.air.supply,
            "air_flow_kg_s": self.air_flow,
            "bed_pressure_drop_Pa": self.bed_pressure_drop,
            **({} if fan_p is None else {"fan_pressure_Pa": fan_p}),
            "clinker_outlet_temperature_K": self.clinker_outlet_temperature,
            "secondary_air_temperature_K": self.secondary_air_temperature,
            "heat_recovered_MW": self.heat_recovered / 1e6,
            "heat_duty_MW": self.heat_duty / 1e6,
            "cooler_efficiency": self.efficiency,
            "radiation_heat_MW": self.radiation_heat / 1e6,
            "bed_height_m": self.bed_height,
            "residence_time_s": self.case.cooler.length / self.case.cooler.grate_speed,
            "h_mean_W_m2K": float(self.heat_transfer_coefficient.mean()),
            "top_layer_outlet_K": float(self.clinker_temperature[-1, -1]),
            "bottom_layer_outlet_K": float(self.clinker_temperature[0, -1]),
            "cells": [n, m],
            "sweeps": self.sweeps,
            "residual": self.residual,
            "energy_imbalance": self.energy_imbalance,
            "wall_time_s": self.wall_time_s,
        }
