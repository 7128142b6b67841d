"""What the paper's methodology gives for one run, and the plant streams it is applied to.

:class:`MethodologyResult` holds the per-step table, the time-averaged ``h`` (Table 6), the
dimensionless numbers and the cooler as an exchanger (Table 7) that
:func:`drumflow.analysis.methodology.analyse_run` computes from a run directory;
:func:`plant_streams` gives the exchanger its material and air streams from the case.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any, Literal

import numpy as np
import pandas as pd
from numpy.typing import NDArray

from drumflow._json import json_safe
from drumflow.case import Case
from drumflow.physics.exchanger import ExchangerResult

__all__ = [
    "FallingMassMode",
    "MethodologyResult",
    "NusseltConductivity",
    "exchanger_to_dict",
    "plant_streams",
]

FallingMassMode = Literal["mean", "per_step"]
NusseltConductivity = Literal["air", "particle"]


def plant_streams(
    case: Case,
    *,
    feed_rate_kg_s: float | None = None,
    air_mass_flow_kg_s: float | None = None,
) -> dict[str, float]:
    """Keyword arguments of the exchanger functions for the case's plant (Eqs. 42-48).

    Parameters
    ----------
    case
        The case; its ``plant`` section gives the material stream, ``air`` the air stream and
        ``particles.heat_capacity`` the material specific heat.
    feed_rate_kg_s
        Material mass flow to use instead of ``plant.material_mass_flow``.
    air_mass_flow_kg_s
        Air mass flow to use instead of ``air.mass_flow``.

    Returns
    -------
    dict
        ``material_mass_flow_kg_s``, ``material_cp_j_kgk``, ``material_inlet_temperature_c``,
        ``air_mass_flow_kg_s``, ``air_cp_j_kgk``, ``air_inlet_temperature_c``.
    """
    return {
        "material_mass_flow_kg_s": float(
            case.plant.material_mass_flow if feed_rate_kg_s is None else feed_rate_kg_s
        ),
        "material_cp_j_kgk": float(case.particles.heat_capacity),
        "material_inlet_temperature_c": float(case.plant.material_inlet_temperature_C),
        "air_mass_flow_kg_s": float(
            case.air.mass_flow if air_mass_flow_kg_s is None else air_mass_flow_kg_s
        ),
        "air_cp_j_kgk": float(case.air.heat_capacity),
        "air_inlet_temperature_c": float(case.air.inlet_temperature_C),
    }


@dataclass(frozen=True)
class MethodologyResult:
    """The methodology applied to one run (Tables 6 and 7, the per-step data of Figure 9).

    Attributes
    ----------
    run_dir
        The run directory (absolute).
    case
        The validated case of the run.
    steps
        One row per output step ``t -> t + dt``. Columns: ``time_s`` (end of the step), ``dt_s``,
        ``mean_temperature_C`` (at the end), ``particle_dT_K`` (Eq. 34),
        ``falling_mass_in_step_kg`` (as written by the run), ``falling_mass_kg`` (the ``m_mf``
        used), ``air_mass_kg``, ``heat_J`` (Eq. 35), ``air_dT_K`` (Eq. 36),
        ``air_temperature_C`` (Eq. 37), ``lmtd_K`` (Eq. 38), ``heat_rate_W`` (Eq. 40),
        ``area_fp_m2`` (Eq. 41), ``h_W_m2K`` (Eq. 39), ``valid``, ``mask`` (why a step is not
        valid: ``no_temperature_change``, ``temperature_cross`` or ``no_falling_mass``),
        ``in_mass_flow_window``, ``mean_air_temperature_C`` (Eq. 50), ``reynolds`` (Eq. 51),
        ``prandtl``, ``nusselt`` (Eq. 49), ``conductivity_W_mK``. The dimensionless columns are
        NaN on invalid steps.
    h_mean_w_m2k
        Time average of ``h`` over the valid steps (Table 6).
    falling_mass_mode
        ``"mean"`` or ``"per_step"`` (see the module notes).
    falling_mass_flow_kg_s
        Mean falling mass flow in the window (Eq. 57 from the per-step masses).
    falling_mass_window_s
        ``(start, end)`` of the steps the mean falling mass flow was taken over.
    dt_s
        Mean output step (s), the paper's ``dt``.
    falling_mass_per_step_kg
        ``falling_mass_flow_kg_s * dt_s``, Table 6's ``m_mf``.
    air_mass_per_step_kg
        ``air.mass_flow * dt_s``, Table 6's ``m_a``.
    falling_area_m2
        Eq. 41 for ``falling_mass_per_step_kg``, Table 6's ``A_fp``.
    nusselt_conductivity
        ``"air"`` (air conductivity at ``T_ma``) or ``"particle"`` (``particles.conductivity``,
        what reproduces the paper's Nusselt numbers).
    void_fraction, air_inlet_velocity_m_s, max_air_velocity_m_s
        Eqs. 53, the mean air inlet velocity and Eq. 52.
    exchanger_area_m2
        ``A_he`` of the whole cooler, Eq. 46 with ``L / l``.
    exchanger
        The cooler with ``h_mean`` and ``A_he`` (Table 7, model column): ``T_mo``, ``T_ao``,
        ``Q_m``, ``LMTD_he``, ``Q_he``.
    plant_exchanger
        When ``plant.material_outlet_temperature_C`` is set: the area the plant needs to reach it
        with ``h_mean`` (Table 7, industry column); else None (also None when that temperature is
        infeasible for the streams, with a warning).
    warnings
        Remarks on the analysis (e.g. the falling-mass window fell back to all steps).
    """

    run_dir: Path
    case: Case
    steps: pd.DataFrame
    h_mean_w_m2k: float
    falling_mass_mode: str
    falling_mass_flow_kg_s: float
    falling_mass_window_s: tuple[float, float]
    dt_s: float
    falling_mass_per_step_kg: float
    air_mass_per_step_kg: float
    falling_area_m2: float
    nusselt_conductivity: str
    void_fraction: float
    air_inlet_velocity_m_s: float
    max_air_velocity_m_s: float
    exchanger_area_m2: float
    exchanger: ExchangerResult
    plant_exchanger: ExchangerResult | None
    warnings: tuple[str, ...] = field(default=())

    # -- per-step arrays (NaN on invalid steps), so the result can be fitted directly -------
    @property
    def nusselt(self) -> NDArray[np.float64]:
        """Per-step Nusselt numbers (NaN on invalid steps)."""
        return self.steps["nusselt"].to_numpy(dtype=np.float64)

    @property
    def reynolds(self) -> NDArray[np.float64]:
        """Per-step Reynolds numbers (NaN on invalid steps)."""
        return self.steps["reynolds"].to_numpy(dtype=np.float64)

    @property
    def prandtl(self) -> NDArray[np.float64]:
        """Per-step Prandtl numbers (NaN on invalid steps)."""
        return self.steps["prandtl"].to_numpy(dtype=np.float64)

    @property
    def n_steps(self) -> int:
        """Number of output steps."""
        return int(len(self.steps))

    @property
    def n_valid(self) -> int:
        """Number of steps with a defined ``h``."""
        return int(self.steps["valid"].sum())

    @property
    def masked(self) -> dict[str, int]:
        """Number of invalid steps per reason."""
        counts = self.steps.loc[~self.steps["valid"], "mask"].value_counts()
        return {str(k): int(v) for k, v in counts.items()}

    def _valid_stat(self, column: str, how: str) -> float:
        values = self.steps.loc[self.steps["valid"], column].to_numpy(dtype=np.float64)
        return float(getattr(np, how)(values)) if values.size else math.nan

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready summary (NaN written as ``null``); the per-step table is not included.

        Returns
        -------
        dict
            Sections ``settings``, ``heat_transfer`` (Table 6), ``dimensionless``, ``exchanger``
            (Table 7) and ``warnings``.
        """
        case = self.case
        k_used: float | str = (
            float(case.particles.conductivity)
            if self.nusselt_conductivity == "particle"
            else "air at T_ma"
        )
        data: dict[str, Any] = {
            "run_dir": str(self.run_dir),
            "case": case.name,
            "case_hash": case.hash(),
            "settings": {
                "falling_mass": self.falling_mass_mode,
                "nusselt_conductivity": self.nusselt_conductivity,
                "conductivity_W_mK": k_used,
            },
            "heat_transfer": {
                "particle_diameter_mm": case.particles.diameter * 1e3,
                "dt_s": self.dt_s,
                "air_mass_kg": self.air_mass_per_step_kg,
                "falling_mass_kg": self.falling_mass_per_step_kg,
                "falling_mass_flow_kg_s": self.falling_mass_flow_kg_s,
                "falling_mass_window_s": list(self.falling_mass_window_s),
                "area_fp_m2": self.falling_area_m2,
                "h_mean_W_m2K": self.h_mean_w_m2k,
                "h_std_W_m2K": self._valid_stat("h_W_m2K", "std"),
                "n_steps": self.n_steps,
                "n_valid": self.n_valid,
                "masked": self.masked,
            },
            "dimensionless": {
                "void_fraction": self.void_fraction,
                "air_inlet_velocity_m_s": self.air_inlet_velocity_m_s,
                "max_air_velocity_m_s": self.max_air_velocity_m_s,
                "reynolds_mean": self._valid_stat("reynolds", "mean"),
                "reynolds_min": self._valid_stat("reynolds", "min"),
                "reynolds_max": self._valid_stat("reynolds", "max"),
                "prandtl_mean": self._valid_stat("prandtl", "mean"),
                "nusselt_mean": self._valid_stat("nusselt", "mean"),
            },
            "exchanger": {
                "cooler_length_m": case.plant.length,
                "section_length_m": case.drum.length,
                "area_he_m2": self.exchanger_area_m2,
                "model": exchanger_to_dict(self.exchanger),
                "plant": None
                if self.plant_exchanger is None
                else exchanger_to_dict(self.plant_exchanger),
            },
            "warnings": list(self.warnings),
        }
        return json_safe(data)


def exchanger_to_dict(result: ExchangerResult) -> dict[str, float]:
    """An :class:`~drumflow.physics.exchanger.ExchangerResult` as a flat dict (with the residual)."""
    out = asdict(result)
    out["balance_residual_w"] = result.balance_residual_w
    return out
