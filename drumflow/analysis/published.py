"""The numbers Burgos-Florez et al. (Processes 2019, 7, 673) publish, in one place, and the
comparison of a drumflow run with them (formerly ``analysis/paper.py``; "paper" now names only
the report page, :mod:`drumflow.report`, and the ``drumflow paper`` command).

Every value carries the table it comes from, so a comparison row says where its reference
came from. Nothing here is used as an input to a simulation: these are the numbers drumflow's
results are compared with (issue 10: fix the choices first, then compare).
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass
from typing import Any, Literal

import numpy as np
import pandas as pd
from numpy.typing import ArrayLike, NDArray

from drumflow.analysis.air_side import lumped_h
from drumflow.case import Case
from drumflow.physics.validation import AnalysisInputError

Model = Literal["one", "two"]


@dataclass(frozen=True)
class PaperModel:
    """What the paper reports for one of its two simulated sections."""

    name: Model
    particle_diameter_m: float
    section_length_m: float
    particle_count: int
    #: Table 3/4: mean particle temperature at 3.5 s on the chosen mesh (mesh 2), and on the
    #: coarser and finer meshes (mesh 1, mesh 3), deg C.
    mean_temperature_3p5s_C: float
    mean_temperature_3p5s_mesh1_C: float
    mean_temperature_3p5s_mesh3_C: float
    #: Table 5: cells of the chosen air mesh; CFD time step (the observables' step), s.
    air_cells: int
    dt_s: float
    #: Table 6: air mass per step, falling mass per step (kg), falling area A_fp (m2), h.
    air_mass_per_step_kg: float
    falling_mass_per_step_kg: float
    falling_area_m2: float
    h_w_m2k: float
    #: Table 7 (thermodynamic + counter-current exchanger model of the whole plant with this
    #: model's h): material and air outlet temperatures (deg C), thermal power (kW), LMTD, area.
    material_outlet_C: float
    air_outlet_C: float
    thermal_power_kw: float
    lmtd_C: float
    exchanger_area_m2: float


PAPER_MODELS: dict[Model, PaperModel] = {
    "one": PaperModel(
        name="one", particle_diameter_m=0.008, section_length_m=0.1, particle_count=467_443,
        mean_temperature_3p5s_C=83.98, mean_temperature_3p5s_mesh1_C=82.42,
        mean_temperature_3p5s_mesh3_C=84.66, air_cells=146_144, dt_s=0.005,
        air_mass_per_step_kg=0.125, falling_mass_per_step_kg=0.04, falling_area_m2=0.029,
        h_w_m2k=60.15, material_outlet_C=40.90, air_outlet_C=69.73, thermal_power_kw=998.40,
        lmtd_C=15.10, exchanger_area_m2=1099.28,
    ),
    "two": PaperModel(
        name="two", particle_diameter_m=0.020, section_length_m=1.0, particle_count=299_164,
        mean_temperature_3p5s_C=88.41, mean_temperature_3p5s_mesh1_C=86.85,
        mean_temperature_3p5s_mesh3_C=89.04, air_cells=336_351, dt_s=0.010,
        air_mass_per_step_kg=0.250, falling_mass_per_step_kg=0.82, falling_area_m2=0.233,
        h_w_m2k=38.93, material_outlet_C=61.23, air_outlet_C=53.27, thermal_power_kw=584.87,
        lmtd_C=33.90, exchanger_area_m2=443.13,
    ),
}

#: Table 7, industry cooler column (the plant the sections stand for), and Table 1's measured
#: plant outlets.
PLANT_TABLE7 = {"material_outlet_C": 45.00, "air_outlet_C": 66.42, "thermal_power_kw": 915.04,
                "lmtd_C": 18.97, "h_w_m2k": 60.15, "exchanger_area_m2": 802.01}
PLANT_MEASURED = {"material_outlet_C": 46.5, "air_outlet_C": 59.0, "residence_time_min": 30.0,
                  "particle_diameter_m": 0.0027, "feed_kg_s": 13.88889, "air_kg_s": 25.0}

#: Eq. 58 and its validity range (Figure 9): Nu = a Re^b Pr^c, 3073 < Re < 7686; Table 8
#: reports 4,802 observations (the time steps of both models) and adjusted R^2 = 99.8634%.
EQ58 = {"a": 0.0531283, "b": 0.523707, "c": 1.00824, "re_min": 3073.0, "re_max": 7686.0,
        "observations": 4802, "adjusted_r2": 0.998634}


@dataclass(frozen=True)
class ComparisonRow:
    """One published value beside drumflow's, with where it comes from."""

    quantity: str
    source: str
    paper: float
    drumflow: float
    unit: str

    @property
    def difference(self) -> float:
        return self.drumflow - self.paper

    @property
    def relative(self) -> float:
        return self.difference / self.paper if self.paper else math.nan

    def to_dict(self) -> dict[str, Any]:
        return {**asdict(self), "difference": self.difference, "relative": self.relative}


def mesh_h(model: Model, case: Case) -> dict[str, float]:
    """The paper's h on each of its meshes, W/(m2 K): its mean temperature at 3.5 s (Tables 3-4,
    meshes 1-3) through the lumped solution of ``case`` (the paper model's case file).

    The paper's own h is far from mesh-converged (model one 79 -> 62 -> 55, model two
    79 -> 39 -> 24): the spread any comparison with its Tables 3-6 sits in.
    """
    paper = PAPER_MODELS[model]
    temperatures = {"mesh 1": paper.mean_temperature_3p5s_mesh1_C,
                    "mesh 2": paper.mean_temperature_3p5s_C,
                    "mesh 3": paper.mean_temperature_3p5s_mesh3_C}
    return {mesh: lumped_h(case, t, 3.5) for mesh, t in temperatures.items()}


def temperature_at(times: NDArray[np.float64], temperatures: NDArray[np.float64], t: float) -> float:
    """The mean-temperature series read at time ``t`` (linear interpolation).

    Raises
    ------
    ValueError
        When the series does not reach ``t``.
    """
    times = np.asarray(times, float)
    if len(times) == 0 or times[-1] < t - 1e-9:
        reached = times[-1] if len(times) else 0.0
        raise ValueError(f"the run reaches {reached:.4g} s simulated, not {t:g} s")
    return float(np.interp(t, times, np.asarray(temperatures, float)))


def compare_with_paper(model: Model, methodology: dict[str, Any] | None,
                       mean_temperature_3p5s_C: float | None, *,
                       coupling_h_w_m2k: float | None = None) -> list[ComparisonRow]:
    """drumflow's Tables 3/4, 6 and 7 values beside the paper's, for one model.

    Parameters
    ----------
    model
        ``"one"`` or ``"two"``.
    methodology
        The run's ``methodology.json`` (:meth:`MethodologyResult.to_dict`), or None when the
        run is too short for the methodology (then only the temperature row is given).
    mean_temperature_3p5s_C
        The run's mean particle temperature at 3.5 s, or None when it has not got there.
    coupling_h_w_m2k
        The h the coupling applied over every particle's surface (:func:`coupling_h`), or None.
        It is set beside the paper's Table 6 h because Eq. 39 with Eqs. 35 and 41 is that same
        lumped coefficient (:func:`eq39_as_lumped_h`).

    Raises
    ------
    AnalysisInputError
        If ``model`` is not ``"one"`` or ``"two"``.
    """
    if model not in PAPER_MODELS:
        raise AnalysisInputError("model", model, "'one' or 'two'")
    paper = PAPER_MODELS[model]
    rows: list[ComparisonRow] = []
    if mean_temperature_3p5s_C is not None:
        rows.append(ComparisonRow("mean temperature at 3.5 s", "Table 4 (mesh 2)",
                                  paper.mean_temperature_3p5s_C, mean_temperature_3p5s_C, "°C"))
    if coupling_h_w_m2k is not None:
        rows.append(ComparisonRow("h over every particle's surface (coupling log)",
                                  "Table 6 (Eq. 39 is this lumped h)", paper.h_w_m2k,
                                  coupling_h_w_m2k, "W/(m² K)"))
    if methodology is None:
        return rows
    ht = methodology["heat_transfer"]
    rows += [
        ComparisonRow("time step dt", "Table 6", paper.dt_s, ht["dt_s"], "s"),
        ComparisonRow("air mass per step", "Table 6", paper.air_mass_per_step_kg, ht["air_mass_kg"], "kg"),
        ComparisonRow("falling mass per step", "Table 6", paper.falling_mass_per_step_kg,
                      ht["falling_mass_kg"], "kg"),
        ComparisonRow("falling area A_fp", "Table 6", paper.falling_area_m2, ht["area_fp_m2"], "m²"),
        ComparisonRow("heat-transfer coefficient h", "Table 6", paper.h_w_m2k, ht["h_mean_W_m2K"],
                      "W/(m² K)"),
        ComparisonRow("Nu = h Dp / k_m (particle k)", "Eq. 49 with Table 6's h",
                      paper.h_w_m2k * paper.particle_diameter_m / PAPER_PARTICLE_CONDUCTIVITY,
                      # The run's own Dp (the paper cases' is the paper's).
                      ht["h_mean_W_m2K"] * ht["particle_diameter_mm"] / 1e3 / PAPER_PARTICLE_CONDUCTIVITY,
                      ""),
    ]
    re_mean = (methodology.get("dimensionless") or {}).get("reynolds_mean")
    if re_mean is not None:
        conv = reynolds_conversion()
        rows.append(ComparisonRow("Re in drumflow's definition (Eqs. 51-54)",
                                  f"Figure 9 ({conv.per_model[model]['re_paper']:g}) / {conv.factor:.4f}",
                                  conv.to_drumflow(conv.per_model[model]["re_paper"]), float(re_mean), ""))
    ex = methodology["exchanger"]
    m = ex["model"]
    rows += [
        ComparisonRow("material outlet T_mo", "Table 7", paper.material_outlet_C,
                      m["material_outlet_temperature_c"], "°C"),
        ComparisonRow("air outlet T_ao", "Table 7", paper.air_outlet_C, m["air_outlet_temperature_c"], "°C"),
        ComparisonRow("thermal power Q_m", "Table 7", paper.thermal_power_kw,
                      m["heat_removed_w"] / 1e3, "kW"),
        ComparisonRow("LMTD_he", "Table 7", paper.lmtd_C, m["lmtd_c"], "°C"),
        ComparisonRow("exchange area A_he", "Table 7", paper.exchanger_area_m2, ex["area_he_m2"], "m²"),
    ]
    plant = ex.get("plant")
    if plant is not None:
        rows.append(ComparisonRow("plant area for T_mo = 45 °C", "Table 7 (industry)",
                                  PLANT_TABLE7["exchanger_area_m2"], plant["area_m2"], "m²"))
    return rows


# --------------------------------------------------------------------- Reynolds definition

#: The air temperature of the paper's plant (Table 1), at which the definitions are compared:
#: every step's T_ma (Eq. 50) is within hundredths of a kelvin of it.
PAPER_AIR_INLET_C = 30.0
#: Figure 9: the Prandtl number the paper's correlation is drawn at (its air-property table;
#: drumflow's table gives 0.7066 at 30 deg C).
PAPER_PRANDTL = 0.7282
#: Table 1: NPK conductivity, the k that reproduces the paper's Nusselt numbers (Eq. 49).
PAPER_PARTICLE_CONDUCTIVITY = 0.18596
#: Drum diameter and air mass flow of both models (Table 1).
PAPER_DRUM_DIAMETER_M = 3.0
PAPER_AIR_MASS_FLOW_KG_S = 25.0


@dataclass(frozen=True)
class ReynoldsConversion:
    """The paper's Reynolds number against drumflow's, for the paper's own two cases.

    drumflow computes Re with Eqs. 51-54 as printed: the mean inlet velocity over the whole drum
    cross-section at the inlet density, divided by the void factor of the section
    (:func:`drumflow.analysis.dimensionless.dimensionless_numbers`). For the paper's two models
    that gives about 1844 and 4609, where the paper reports 3073 and 7686 (the ends of Eq. 58's
    range, one cluster per model in Figure 9). Both ratios are the same to 0.05 %, so the two
    differ by a definition (the velocity put into Eq. 51; the paper calls v_max "the maximum air
    velocity throughout the drum" and does not give the inlet area), not by physics. The paper's
    numbers imply v_max of about 6.23 m/s in both models, against drumflow's V_ai / Vf = 3.74 m/s.

    Attributes
    ----------
    factor
        ``Re_paper / Re_drumflow``: the mean of the two models' ratios.
    factor_spread
        Relative difference between the two models' ratios (how well one factor fits both).
    prandtl_factor
        ``Pr_paper / Pr_drumflow`` at 30 deg C (0.7282 from the paper's property table, 0.7066
        from drumflow's).
    per_model
        For each model: ``re_paper``, ``re_drumflow``, ``ratio``, ``v_ai_m_s`` (drumflow's mean
        inlet velocity), ``void_fraction``, ``v_max_drumflow_m_s`` (Eq. 52),
        ``v_max_paper_implied_m_s`` (Eq. 51 solved for v_max with the paper's Re),
        ``prandtl_drumflow``.
    """

    factor: float
    factor_spread: float
    prandtl_factor: float
    per_model: dict[str, dict[str, float]]

    def to_drumflow(self, reynolds_paper: float) -> float:
        """A Reynolds number of the paper's definition in drumflow's."""
        return reynolds_paper / self.factor

    def to_paper(self, reynolds_drumflow: float) -> float:
        """A Reynolds number of drumflow's definition in the paper's."""
        return reynolds_drumflow * self.factor

    def to_dict(self) -> dict[str, Any]:
        return asdict(self)


def reynolds_conversion() -> ReynoldsConversion:
    """Compare drumflow's Re (Eqs. 51-55 as printed) with the paper's, for both paper models.

    Uses only published inputs (Table 1: D, the air flow and T_ai; each model's Dp, l and N) and
    the published Re at the ends of Eq. 58's range; nothing is fitted.
    """
    from drumflow.analysis.dimensionless import dimensionless_numbers
    from drumflow.physics import air as air

    nu = float(air.kinematic_viscosity(PAPER_AIR_INLET_C))
    per_model: dict[str, dict[str, float]] = {}
    for model, re_paper in (("one", EQ58["re_min"]), ("two", EQ58["re_max"])):
        p = PAPER_MODELS[model]  # type: ignore[index]
        # T_a(t + dt) = T_ai: T_ma = T_ai, the limit the paper's steps are within 0.05 K of.
        steps = dimensionless_numbers(
            [p.h_w_m2k], [PAPER_AIR_INLET_C], air_inlet_temperature_c=PAPER_AIR_INLET_C,
            particle_diameter_m=p.particle_diameter_m, drum_diameter_m=PAPER_DRUM_DIAMETER_M,
            section_length_m=p.section_length_m, particle_count=p.particle_count,
            air_mass_flow_kg_s=PAPER_AIR_MASS_FLOW_KG_S,
        )
        re_df = float(steps.reynolds[0])
        per_model[model] = {
            "re_paper": float(re_paper),
            "re_drumflow": re_df,
            "ratio": float(re_paper) / re_df,
            "v_ai_m_s": steps.air_inlet_velocity_m_s,
            "void_fraction": steps.void_fraction,
            "v_max_drumflow_m_s": steps.max_air_velocity_m_s,
            "v_max_paper_implied_m_s": float(re_paper) * nu / p.particle_diameter_m,
            "prandtl_drumflow": float(steps.prandtl[0]),
        }
    ratios = [v["ratio"] for v in per_model.values()]
    factor = float(np.mean(ratios))
    return ReynoldsConversion(
        factor=factor,
        factor_spread=float(abs(ratios[1] - ratios[0]) / factor),
        prandtl_factor=PAPER_PRANDTL / per_model["one"]["prandtl_drumflow"],
        per_model=per_model,
    )


# ---------------------------------------------------------------- h from the coupling log


@dataclass(frozen=True)
class CouplingH:
    """The heat-transfer coefficient the coupling applied, read back from its log.

    ``h(t) = Q(t) / (N pi Dp^2 (T_mean(t) - T_air))``: the heat the air removed at each coupling
    update over the surface of every particle and the mean particle-air temperature difference.
    This is what the one-way air does in drumflow (and in the paper's CFD): it acts on every
    particle, in the bed as in the curtain.

    Attributes
    ----------
    h_run_w_m2k
        Over the run: the heat removed divided by the time integral of ``A (T_mean - T_air)``.
    h_mean_w_m2k
        Time average of the per-update ``h``.
    surface_m2
        ``N pi Dp^2``: the surface of all particles.
    heat_removed_j
        Heat the air removed over the logged updates.
    updates
        Number of coupling updates used.
    time_s
        Simulated time covered by the log.
    """

    h_run_w_m2k: float
    h_mean_w_m2k: float
    surface_m2: float
    heat_removed_j: float
    updates: int
    time_s: float
    series: pd.DataFrame

    def to_dict(self) -> dict[str, Any]:
        return {"h_run_W_m2K": self.h_run_w_m2k, "h_mean_W_m2K": self.h_mean_w_m2k,
                "surface_m2": self.surface_m2, "heat_removed_J": self.heat_removed_j,
                "updates": self.updates, "time_s": self.time_s}


def coupling_h(case: Case, air_heat: pd.DataFrame, mean_temperature: pd.DataFrame) -> CouplingH:
    """``h`` over all particle surface from the coupling log (``post/air_heat.csv``).

    Parameters
    ----------
    case
        The run's case (particle count and diameter, air inlet temperature: the one-way air
        stays at its inlet temperature).
    air_heat
        ``post/air_heat.csv``: ``time_s``, ``steps``, ``heat_to_particles_W`` and
        ``heat_removed_J`` (cumulative) per coupling update.
    mean_temperature
        ``post/mean_temperature.csv``: ``time_s``, ``mean_temperature_C``.

    Raises
    ------
    AnalysisInputError
        If a column is missing, the log is empty, or the particles never differ from the air.
    """
    for name, table, cols in (
        ("air_heat", air_heat, ("step", "time_s", "steps", "heat_to_particles_W", "heat_removed_J")),
        ("mean_temperature", mean_temperature, ("time_s", "mean_temperature_C")),
    ):
        missing = [c for c in cols if c not in table.columns]
        if missing:
            raise AnalysisInputError(name, f"columns {list(table.columns)}",
                                     f"a table with the column(s) {', '.join(missing)}")
    step = air_heat["step"].to_numpy(float)
    t = air_heat["time_s"].to_numpy(float)
    if not (step > 0).any():
        raise AnalysisInputError("air_heat", f"{len(air_heat)} row(s)",
                                 "coupling updates past the first DEM step")
    dt_dem = float(np.median(t[step > 0] / step[step > 0]))
    # Each update's heat is applied for `steps` DEM steps (drumflow.coupling.log).
    held = air_heat["steps"].to_numpy(float) * dt_dem
    q = -air_heat["heat_to_particles_W"].to_numpy(float)  # heat given to the air, W
    t_mean = np.interp(t, mean_temperature["time_s"].to_numpy(float),
                       mean_temperature["mean_temperature_C"].to_numpy(float))
    excess = t_mean - case.air.inlet_temperature_C
    area = case.particle_count * math.pi * case.particles.diameter**2
    ok = np.abs(excess) > 1e-9
    if not ok.any():
        raise AnalysisInputError("mean_temperature", "the air temperature throughout",
                                 "particles hotter (or colder) than the air at some update")
    h = np.full(t.shape, np.nan)
    h[ok] = q[ok] / (area * excess[ok])
    h_run = float(np.sum(q[ok] * held[ok]) / np.sum(area * excess[ok] * held[ok]))
    h_mean = float(np.sum(h[ok] * held[ok]) / np.sum(held[ok]))
    series = pd.DataFrame({"time_s": t, "heat_to_air_W": q, "mean_temperature_C": t_mean,
                           "h_W_m2K": h})
    return CouplingH(h_run_w_m2k=h_run, h_mean_w_m2k=h_mean, surface_m2=area,
                     heat_removed_j=float(np.sum(q * held)), updates=int(ok.sum()),
                     time_s=float(t[-1] + held[-1]), series=series)


def eq39_as_lumped_h(particle_density_kg_m3: float, particle_diameter_m: float,
                     particle_cp_j_kgk: float, cooling_rate_k_s: ArrayLike,
                     lmtd_k: ArrayLike) -> float | NDArray[np.float64]:
    """Eq. 39 with Eqs. 35, 40 and 41 put in: the falling mass cancels.

    ``h = (m_mf cp (-dT) / dt) / ((6 m_mf / (rho Dp)) LMTD) = rho Dp cp (-dT/dt) / (6 LMTD)``:
    the lumped coefficient that cools every particle of the section at the rate of the mean
    temperature. (m_mf still enters the LMTD through the air's warming, Eq. 36, hundredths of
    a kelvin against tens.)

    Parameters
    ----------
    particle_density_kg_m3, particle_diameter_m, particle_cp_j_kgk
        rho, Dp and cp of the particles.
    cooling_rate_k_s
        ``-dT/dt`` of the mean particle temperature (K/s), scalar or per step.
    lmtd_k
        Eq. 38 (K), same shape.

    Returns
    -------
    float or numpy.ndarray
        h (W/(m2 K)); a float for scalar inputs.
    """
    out = (particle_density_kg_m3 * particle_diameter_m * particle_cp_j_kgk
           * np.asarray(cooling_rate_k_s, float) / (6.0 * np.asarray(lmtd_k, float)))
    return float(out) if np.ndim(out) == 0 else out
