"""The fluid-bed cooler's case file, the month weather table and the operating point of a run.

The case (product, unit, air, losses, refrigeration, weather, numerics) is validated like every
drumflow input (:func:`drumflow.case.validate_model`), with a check that the product fluidises
in the ambient air; the weather is the monthly table of the source (AEMET, Salamanca
1981-2010) or a user's CSV; :class:`Conditions` is one operating point: ambient air, product
inlet and river water, in kelvin. The model itself is :mod:`drumflow.coolers.fluid_bed`.
"""

from __future__ import annotations

import csv
import math
from dataclasses import dataclass
from importlib import resources
from pathlib import Path
from typing import Literal

from pydantic import BaseModel, Field, model_validator

from drumflow.case import INPUT_MODEL_CONFIG, read_toml, validate_model
from drumflow.coolers import _fluidization as fl
from drumflow.errors import CaseError

__all__ = ["KELVIN", "Conditions", "FluidBedCase", "MonthWeather", "case_conditions", "check_fluidization",
           "load_fluid_bed_case", "load_weather", "month_conditions"]

KELVIN = 273.15


# == the case ===================================================================================
class _Section(BaseModel):
    # The one input-model config (strict types, finite numbers): drumflow.case.
    model_config = INPUT_MODEL_CONFIG


class SizeDistribution(_Section):
    """Sieve analysis: the mass fraction retained in each class of mean diameter d_i."""

    diameters_mm: list[float] = Field(min_length=1, max_length=50,
                                      description="class mean diameters, mm")
    mass_fractions: list[float] = Field(min_length=1, max_length=50,
                                        description="mass fraction in each class (sum 1)")

    @model_validator(mode="after")
    def _consistent(self) -> SizeDistribution:
        if len(self.diameters_mm) != len(self.mass_fractions):
            raise ValueError("product.size_distribution: diameters_mm and mass_fractions must "
                             "have the same length")
        if any(not (0 < d <= 100) for d in self.diameters_mm):
            raise ValueError("product.size_distribution.diameters_mm: each must be > 0 and <= 100")
        if any(not (0 <= x <= 1) for x in self.mass_fractions):
            raise ValueError("product.size_distribution.mass_fractions: each must be >= 0 and <= 1")
        total = sum(self.mass_fractions)
        if abs(total - 1.0) > 0.01:
            raise ValueError(f"product.size_distribution.mass_fractions sum to {total:.4g}; "
                             "allowed: 1 within 0.01")
        return self

    @property
    def sauter_diameter(self) -> float:
        """d32 = 1 / sum(x_i / d_i) (mass fractions normalised), m."""
        total = sum(self.mass_fractions)
        return 1.0 / sum(x / total / (d * 1e-3) for x, d in zip(self.mass_fractions, self.diameters_mm))


class Product(_Section):
    """The granular product fed to the cooler."""

    mass_flow: float = Field(gt=0, le=200, description="product flow S, kg/s")
    inlet_temperature_C: float = Field(gt=-20, lt=200, description="product inlet temperature, degC")
    sauter_diameter: float | None = Field(None, gt=1e-5, le=0.05, description="Sauter diameter, m")
    size_distribution: SizeDistribution | None = None
    density: float = Field(gt=100, le=10000, description="particle (granule) density, kg/m^3")
    heat_capacity: float = Field(gt=100, le=10000, description="specific heat, J/(kg K)")
    conductivity: float = Field(gt=0.01, le=100, description="thermal conductivity, W/(m K)")
    min_fluidization_voidage: float | None = Field(
        None, ge=0.35, le=0.6, description="voidage at minimum fluidisation (the dense phase); "
        "default: Wen and Yu's 14^(-1/3) = 0.415 for spheres")

    @model_validator(mode="after")
    def _one_size(self) -> Product:
        if (self.sauter_diameter is None) == (self.size_distribution is None):
            raise ValueError("product: give exactly one of 'sauter_diameter' (m) or "
                             "'size_distribution'")
        return self

    @property
    def diameter(self) -> float:
        if self.sauter_diameter is not None:
            return self.sauter_diameter
        assert self.size_distribution is not None
        return self.size_distribution.sauter_diameter


class Unit(_Section):
    """The vibrating deck."""

    length: float = Field(gt=0, le=50, description="deck length, m")
    width: float = Field(gt=0, le=10, description="deck width B, m")
    ambient_fraction: float = Field(0.8, gt=0, lt=1,
                                    description="share of the length fed with ambient air (section B)")
    orifices: int = Field(ge=1, le=10_000_000, description="number of distributor orifices n")
    solids_velocity: float = Field(gt=0, le=5, description="forward velocity v of the solids, m/s")
    vibration_frequency: float = Field(gt=0, le=200, description="deck vibration frequency f, Hz")
    vibration_amplitude: float = Field(gt=0, le=0.05, description="deck vibration amplitude A_f, m")

    @property
    def area(self) -> float:
        return self.length * self.width


class AmbientAir(_Section):
    """Air of section B (always ambient)."""

    velocity: float = Field(gt=0, le=20, description="superficial velocity, m/s")
    temperature_C: float = Field(gt=-40, lt=60, description="ambient temperature, degC")
    relative_humidity: float = Field(ge=0, le=1, description="ambient relative humidity, 0..1")


class CooledAir(_Section):
    """Air of section C: ambient air, chilled when needed."""

    velocity: float = Field(gt=0, le=20, description="superficial velocity, m/s")
    temperature_C: float | Literal["auto", "off"] = Field(
        "auto", description="'auto': chill only as much as needed to reach the target product "
        "temperature; 'off': ambient air; a number: chilled supply temperature, degC")

    @model_validator(mode="after")
    def _range(self) -> CooledAir:
        t = self.temperature_C
        if not isinstance(t, str) and not (-20 < t < 60):
            raise ValueError(f"air.cooled.temperature_C = {t}: allowed 'auto', 'off' or > -20 and < 60")
        return self


class Air(_Section):
    pressure_kPa: float = Field(101.325, gt=50, lt=200, description="air pressure, kPa")
    ambient: AmbientAir
    cooled: CooledAir


class Losses(_Section):
    """The two fitted parameters (source: 0.30 and 1.17 kW/K)."""

    convective_efficiency: float = Field(gt=0, le=1, description="f_c, multiplies h")
    h_losses_A_kW_per_K: float = Field(ge=0, le=1000, description="hLosses*A of the hood, kW/K")


class Refrigeration(_Section):
    """The chilled-air supply of section C (the source's Figure 5)."""

    refrigerant: Literal["Ammonia", "R134a", "R717", "Propane", "R1234yf"] = "Ammonia"
    target_product_temperature_K: float = Field(
        311.0, gt=250, lt=400, description="product storage limit, K (source: 311 K)")
    river_water_temperature_C: float | None = Field(
        None, gt=0, lt=40, description="condenser water temperature, degC; default: the "
        "month's mean air temperature")
    condenser_approach_K: float = Field(10.0, gt=0, le=40,
                                        description="condensing minus river-water temperature, K")
    air_cooler_approach_K: float = Field(5.0, gt=0, le=30,
                                         description="cooled air minus chilled-water temperature, K")
    chiller_approach_K: float = Field(5.0, gt=0, le=30,
                                      description="chilled water minus evaporating temperature, K")
    min_chilled_water_C: float = Field(4.0, ge=0.5, le=30,
                                       description="lowest chilled-water temperature, degC")
    polytropic_efficiency: float = Field(0.75, gt=0, le=1, description="compressor eta_p")


class Weather(_Section):
    table: str = Field("salamanca", description="'salamanca' (shipped AEMET normals) or a CSV path")
    basis: Literal["mean_max", "mean"] = Field(
        "mean_max", description="monthly air temperature: mean of daily maxima or daily means")


class Numerics(_Section):
    shells: int = Field(10, ge=2, le=200, description="concentric shells of the particle")
    steps_per_section: int = Field(200, ge=10, le=100_000, description="time steps per section")


class FluidBedCase(_Section):
    """A vibrating fluid-bed cooler case (``cases/fluid_bed_npk.toml``)."""

    name: str = Field(min_length=1, max_length=100, pattern=r"^[A-Za-z0-9_.-]+$")
    product: Product
    unit: Unit
    air: Air
    losses: Losses
    refrigeration: Refrigeration = Refrigeration()
    weather: Weather = Weather()
    numerics: Numerics = Numerics()


def load_fluid_bed_case(path: Path | str) -> FluidBedCase:
    """Read and validate a fluid-bed case; then check the bed fluidises in both sections.

    Raises
    ------
    CaseError
        Every problem, naming field, value and allowed range.
    """
    case = validate_model(FluidBedCase, read_toml(path), path)
    check_fluidization(case, source=path)
    return case


def check_fluidization(case: FluidBedCase, source: Path | str | None = None) -> None:
    """Refuse velocities outside u_mf < u < u_t and beds outside Gunn's voidage range."""
    problems = []
    gas = fl.humid_air(case.air.ambient.temperature_C + KELVIN, case.air.pressure_kPa * 1e3,
                       fl.humidity_ratio(case.air.ambient.temperature_C + KELVIN,
                                         case.air.pressure_kPa * 1e3, case.air.ambient.relative_humidity))
    d, rho = case.product.diameter, case.product.density
    group = fl.geldart_group(d, rho, gas.density)
    if group not in fl.BUBBLING_GROUPS:
        problems.append(f"product.sauter_diameter = {d:.4g} m with density {rho:g} kg/m^3 is "
                        f"Geldart group {group}; allowed: groups B and D (bed expansion of "
                        "Johnsson et al. 1991)")
    else:
        u_mf = fl.minimum_fluidization_velocity(d, rho, gas)
        u_t = fl.terminal_velocity(d, rho, gas)
        for name, u in (("ambient", case.air.ambient.velocity), ("cooled", case.air.cooled.velocity)):
            if not u_mf < u < 0.99 * u_t:
                problems.append(f"air.{name}.velocity = {u:g}: allowed: > {u_mf:.3g} (minimum "
                                f"fluidisation) and < {0.99 * u_t:.3g} m/s (0.99 x terminal velocity)")
    if problems:
        raise CaseError(problems, source)


# == weather ====================================================================================
@dataclass(frozen=True)
class MonthWeather:
    month: int
    name: str
    t_mean_C: float
    t_max_mean_C: float
    rh_mean_pct: float


#: Allowed values of a weather table's numbers (°C, %): a month outside them is a typing error
#: (and a NaN one would stop CoolProp's humid-air functions with an error of their own).
WEATHER_LIMITS = {"t_mean_C": (-60.0, 60.0), "t_max_mean_C": (-60.0, 70.0), "rh_mean_pct": (0.0, 100.0)}


def load_weather(table: str | Path = "salamanca") -> list[MonthWeather]:
    """The monthly weather table: the shipped AEMET normals or a CSV of the same columns
    (month, name, t_mean_C, t_max_mean_C, rh_mean_pct; '#' lines are comments).

    Raises
    ------
    CaseError
        The file is missing or not UTF-8, a column is missing, or a value is not a finite
        number within :data:`WEATHER_LIMITS` (each problem names the file, row and column).
    """
    from drumflow.errors import BadFileError
    from drumflow.readers import read_text

    if str(table) == "salamanca":
        text = (resources.files("drumflow.coolers") / "data" / "salamanca_aemet_1981_2010.csv").read_text()
    else:
        path = Path(table)
        if not path.is_file():
            raise CaseError([f"weather.table = {table}: file not found"])
        try:
            text = read_text(path, "a weather table")
        except BadFileError as exc:
            raise CaseError([f"weather.table = {table}: {exc.problem}"]) from None
    rows = [line for line in text.splitlines() if line.strip() and not line.startswith("#")]
    reader = csv.DictReader(rows)
    columns = ("month", "name", *WEATHER_LIMITS)
    missing = [c for c in columns if c not in (reader.fieldnames or [])]
    if missing:
        raise CaseError([f"weather.table = {table}: no column(s) {', '.join(missing)}; columns: "
                         "month, name, t_mean_C, t_max_mean_C, rh_mean_pct"])
    out = []
    problems = []
    for i, row in enumerate(reader, start=1):
        where = f"weather.table = {table}, data row {i}"
        try:
            month = int(row["month"] or "")
        except ValueError:
            problems.append(f"{where}, month = {row['month']!r}: allowed a whole number 1 to 12")
            continue
        values: dict[str, float] = {}
        for col, (lo, hi) in WEATHER_LIMITS.items():
            text_value = (row[col] or "").strip()
            try:
                v = float(text_value)
            except ValueError:
                problems.append(f"{where}, {col} = {text_value!r}: not a number")
                continue
            if not (math.isfinite(v) and lo <= v <= hi):
                problems.append(f"{where}, {col} = {text_value}: allowed a finite number >= {lo:g} "
                                f"and <= {hi:g}")
                continue
            values[col] = v
        if len(values) == len(WEATHER_LIMITS):
            out.append(MonthWeather(month, row["name"] or "", values["t_mean_C"],
                                    values["t_max_mean_C"], values["rh_mean_pct"]))
    if problems:
        raise CaseError(problems)
    if sorted(m.month for m in out) != list(range(1, 13)):
        raise CaseError([f"weather.table = {table}: needs months 1 to 12 once each"])
    return sorted(out, key=lambda m: m.month)


# == the operating point ========================================================================
@dataclass(frozen=True)
class Conditions:
    """What changes from one operating point to the next.

    Attributes
    ----------
    ambient_temperature
        K.
    humidity_ratio
        kg/kg dry air of the ambient air.
    product_inlet_temperature
        K.
    river_water_temperature
        K.
    """

    ambient_temperature: float
    humidity_ratio: float
    product_inlet_temperature: float
    river_water_temperature: float


def case_conditions(case: FluidBedCase) -> Conditions:
    """The operating point written in the case's [air.ambient] and [product]."""
    t = case.air.ambient.temperature_C + KELVIN
    p = case.air.pressure_kPa * 1e3
    river = case.refrigeration.river_water_temperature_C
    return Conditions(t, fl.humidity_ratio(t, p, case.air.ambient.relative_humidity),
                      case.product.inlet_temperature_C + KELVIN,
                      (river if river is not None else case.air.ambient.temperature_C) + KELVIN)


def month_conditions(case: FluidBedCase, month: MonthWeather) -> Conditions:
    """A month of the weather table: the temperature of the case's basis, and the humidity
    ratio of the month's mean temperature and mean relative humidity (the absolute humidity
    changes little over a day while the relative humidity follows the temperature)."""
    p = case.air.pressure_kPa * 1e3
    t = (month.t_max_mean_C if case.weather.basis == "mean_max" else month.t_mean_C) + KELVIN
    w = fl.humidity_ratio(month.t_mean_C + KELVIN, p, month.rh_mean_pct / 100.0)
    # Air cannot hold more than saturation at the basis temperature.
    w = min(w, fl.saturation_humidity_ratio(t, p))
    river = case.refrigeration.river_water_temperature_C
    return Conditions(t, w, case.product.inlet_temperature_C + KELVIN,
                      (river if river is not None else month.t_mean_C) + KELVIN)
