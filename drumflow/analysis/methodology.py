"""The paper's methodology applied to a run directory (Sections 2.2-2.5, Tables 6-8).

Burgos-Florez et al., Processes 2019, 7, 673. From the files a finished ``drumflow run`` leaves
behind, this module computes:

1. the heat-transfer coefficient of every output step, Eqs. 34-41
   (:func:`~drumflow.analysis.heat_transfer.per_step_heat_transfer`), and its time average
   (Table 6);
2. the per-step Nusselt, Reynolds and Prandtl numbers, Eqs. 49-55
   (:func:`~drumflow.analysis.dimensionless.dimensionless_numbers`);
3. the whole cooler as a counter-current exchanger, Eqs. 42-48 (Table 7): the exchange area
   ``A_he`` from the simulated section (Eq. 46 with ``L / l``), then the material outlet
   temperature for the mean ``h`` (:func:`~drumflow.physics.exchanger.solve_outlet_temperature`),
   and, when the case gives the plant's measured outlet temperature, the area the plant needs
   at this ``h`` (the paper's "industry cooler" column);
4. across runs, the ``Nu = a Re^b Pr^c`` fit with its ANOVA, Eq. 56 and Table 8
   (:func:`fit_runs`).

Inputs read: ``DIR/case.toml`` and ``DIR/post/mean_temperature.csv`` (columns ``time_s``,
``mean_temperature_C``, ``particles``, ``falling_mass_kg_in_step``; the falling mass of the step
ending at each row, NaN in the first row). :func:`analyse_run` writes nothing;
:func:`write_methodology` writes ``DIR/post/methodology.json`` and ``DIR/post/steps.csv``.

Falling mass (``m_mf`` in Eqs. 35, 41 and 46). The paper writes it with a bar, "the average NPK
mass that falls during one time step", and Table 6 gives one value per model, measured after the
first second (Section 3.3). The default ``falling_mass="mean"`` does the same: it takes the mean
falling mass flow of the steps that start at or after ``run.mass_flow_start`` and gives every step
that flow times its length. ``falling_mass="per_step"`` uses each step's own crossing mass instead.
That is noisier, because the mass is a whole number of particles, and steps in which no particle
fell are masked, since Eq. 41 then has no area.

The average ``h`` covers every valid step of the simulated time, as the paper says in Section 2.2.
Steps that start before ``run.mass_flow_start`` are included. Only the falling mass is measured
in that window.
"""

from __future__ import annotations

import json
import math
from collections.abc import Iterable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
from numpy.typing import NDArray

from drumflow.analysis.correlation import (
    NusseltCorrelation,
    fit_nusselt_correlation_from_runs,
)
from drumflow.analysis.dimensionless import dimensionless_numbers
from drumflow.analysis.heat_transfer import (
    falling_particle_area,
    per_step_heat_transfer,
)
from drumflow.analysis.methodology_result import (
    FallingMassMode,
    MethodologyResult,
    NusseltConductivity,
    plant_streams,
)
from drumflow.case import Case, load_case
from drumflow.errors import (
    AnalysisInputError,
    MissingRunFileError,
    NoHeatTransferError,
    RunDirectoryError,
)
from drumflow.physics.exchanger import (
    ExchangerResult,
    InfeasibleExchangerError,
    area_for_outlet_temperature,
    exchanger_area_from_section,
    solve_outlet_temperature,
)
from drumflow.readers import reaches_time
from drumflow.rundir import RunDir

__all__ = [
    "MissingRunFileError",
    "NoHeatTransferError",
    "analyse_run",
    "fit_runs",
    "write_methodology",
]

_CSV_COLUMNS = ("time_s", "mean_temperature_C", "particles", "falling_mass_kg_in_step")

# Mask reasons of the per-step table ("" for a valid step).
_NO_CHANGE = "no_temperature_change"
_CROSS = "temperature_cross"
_NO_FALL = "no_falling_mass"

# Tolerance when comparing a step's start time with run.mass_flow_start: output times are
# multiples of the DEM time step (~1e-5 s) written with 10 significant digits, so they can sit a
# few 1e-10 s off the nominal value. 1e-9 s is far below any DEM time step.
_TIME_EPS_S = 1e-9


def _read_mean_temperature(path: Path) -> pd.DataFrame:
    try:
        table = pd.read_csv(path)
    except (pd.errors.ParserError, pd.errors.EmptyDataError, UnicodeDecodeError) as exc:
        raise RunDirectoryError(f"{path}: not a readable CSV table ({exc})") from None
    missing = [c for c in _CSV_COLUMNS if c not in table.columns]
    if missing:
        raise RunDirectoryError(
            f"{path}: missing column(s) {', '.join(missing)}; expected the header "
            f"{','.join(_CSV_COLUMNS)} (rerun `drumflow post DIR`)"
        )
    if len(table) < 2:
        raise RunDirectoryError(
            f"{path}: {len(table)} row(s); at least two output times are needed for one step"
        )
    for col in ("time_s", "mean_temperature_C"):
        values = pd.to_numeric(table[col], errors="coerce").to_numpy(dtype=np.float64)
        bad = ~np.isfinite(values)
        if bad.any():
            row = int(np.flatnonzero(bad)[0])
            raise RunDirectoryError(
                f"{path}: column {col} has a missing or non-numeric value in data row {row + 1}"
            )
    falling = pd.to_numeric(table["falling_mass_kg_in_step"], errors="coerce").to_numpy(
        dtype=np.float64
    )
    # The first row has no step before it (NaN by design); every later one must be a mass.
    bad = ~np.isfinite(falling[1:]) | (falling[1:] < 0.0)
    if bad.any():
        row = int(np.flatnonzero(bad)[0]) + 2
        raise RunDirectoryError(
            f"{path}: falling_mass_kg_in_step in data row {row} is "
            f"{falling[row - 1]!r}; expected a mass >= 0 kg (only the first row may be empty)"
        )
    return table


def _falling_window(
    t: NDArray[np.float64], start_s: float
) -> tuple[NDArray[np.bool_], list[str]]:
    # Step k runs from t[k] to t[k+1]; it is in the window when it starts at or after start_s.
    in_window = t[:-1] >= start_s - _TIME_EPS_S
    notes: list[str] = []
    if not in_window.any():
        in_window = np.ones(t.size - 1, dtype=bool)
        notes.append(
            f"the run ends ({t[-1]:g} s) before run.mass_flow_start ({start_s:g} s): the mean "
            "falling mass was taken over every step, including the settling of the initial fill"
        )
    return in_window, notes


def analyse_run(
    run_dir: Path | str,
    *,
    nusselt_conductivity: NusseltConductivity = "air",
    falling_mass: FallingMassMode = "mean",
    until: float | None = None,
) -> MethodologyResult:
    """Apply the paper's methodology to one run directory (Tables 6 and 7, Eqs. 34-55).

    Parameters
    ----------
    run_dir
        A directory written by ``drumflow run`` (needs ``case.toml`` and
        ``post/mean_temperature.csv``).
    nusselt_conductivity
        Conductivity in ``Nu = h Dp / k`` (Eq. 49): ``"air"`` (default, air at ``T_ma``, the usual
        particle Nusselt number) or ``"particle"`` (``particles.conductivity``, which is what
        reproduces the paper's Nusselt numbers; see :mod:`drumflow.analysis.dimensionless`).
    falling_mass
        ``"mean"`` (default, the paper's averaged ``m_mf``) or ``"per_step"``; see the module
        notes.
    until
        If given, analyse only the output times up to this simulated time (s): what a run
        stopped there would report (the falling-mass window then ends there too). Default: the
        whole run. A time past the end of the run means the whole run.

    Returns
    -------
    MethodologyResult

    Raises
    ------
    MissingRunFileError
        If ``case.toml`` or ``post/mean_temperature.csv`` is missing (the message names it).
    NoHeatTransferError
        If the run cannot give ``h``: it had no air (``air.model = "none"`` or no air flow), no
        particle fell in the window, or no step is valid (the mean temperature never changed,
        or every step was a temperature cross), or the mean ``h`` is not positive.
    RunDirectoryError
        If the CSV is malformed or the plant streams are inconsistent (the message names the
        file).
    BadFileError
        If the CSV ends before the simulated time ``summary.json`` records (cut short), or
        ``summary.json`` is damaged.
    drumflow.errors.CaseError
        If ``case.toml`` is not a valid case.
    ValueError
        If ``nusselt_conductivity`` or ``falling_mass`` is not one of the allowed values, or
        ``until`` leaves fewer than two output times (an ``AnalysisInputError``).
    """
    if nusselt_conductivity not in ("air", "particle"):
        raise AnalysisInputError("nusselt_conductivity", nusselt_conductivity, "'air' or 'particle'")
    if falling_mass not in ("mean", "per_step"):
        raise AnalysisInputError("falling_mass", falling_mass, "'mean' or 'per_step'")
    run = _open_run(run_dir)
    case = load_case(run.case_toml)
    _require_air(case, run.case_toml)
    series = _read_series(run.mean_temperature_csv)
    # A series cut short reads as a shorter valid run: its averages would be wrong in silence.
    reaches_time(run.mean_temperature_csv, float(series.t[-1]), run.summary_path)
    if until is not None:
        series = _series_until(series, until)
    window = _falling_window_of(series, case, run.mean_temperature_csv)
    steps = _per_step(case, series, window, falling_mass, run)
    h_mean = _mean_h(steps, series, run.mean_temperature_csv)
    k = case.particles.conductivity if nusselt_conductivity == "particle" else None
    valid = steps.valid
    try:
        numbers = dimensionless_numbers(
            steps.h[valid],
            steps.air_t[valid],
            air_inlet_temperature_c=case.air.inlet_temperature_C,
            particle_diameter_m=case.particles.diameter,
            drum_diameter_m=case.drum.diameter,
            section_length_m=case.drum.length,
            particle_count=case.particle_count,
            air_mass_flow_kg_s=case.air.mass_flow,
            conductivity_w_mk=k,
        )
    except AnalysisInputError as exc:
        raise RunDirectoryError(f"{run.mean_temperature_csv} with {run.case_toml}: {exc}") from exc
    table_out = _steps_table(series, window, steps, numbers)
    dt_mean = float(np.mean(series.dt))
    notes = list(window.notes)
    m_mf, a_fp, a_he, model, plant_result = _exchangers(case, h_mean, window.flow, dt_mean,
                                                        run.case_toml, notes)
    return MethodologyResult(
        run_dir=run.root,
        case=case,
        steps=table_out,
        h_mean_w_m2k=h_mean,
        falling_mass_mode=falling_mass,
        falling_mass_flow_kg_s=window.flow,
        falling_mass_window_s=window.span,
        dt_s=dt_mean,
        falling_mass_per_step_kg=m_mf,
        air_mass_per_step_kg=case.air.mass_flow * dt_mean,
        falling_area_m2=a_fp,
        nusselt_conductivity=nusselt_conductivity,
        void_fraction=numbers.void_fraction,
        air_inlet_velocity_m_s=numbers.air_inlet_velocity_m_s,
        max_air_velocity_m_s=numbers.max_air_velocity_m_s,
        exchanger_area_m2=a_he,
        exchanger=model,
        plant_exchanger=plant_result,
        warnings=tuple(notes),
    )


def _open_run(run_dir: Path | str) -> RunDir:
    """The run directory, with the two files the methodology reads."""
    root = Path(run_dir).resolve()
    if not root.is_dir():
        raise RunDirectoryError(f"{root}: not a directory (expected a `drumflow run` directory)")
    run = RunDir(root, create=False)
    if not run.case_toml.is_file():
        raise MissingRunFileError(run.case_toml, "the validated case of the run")
    if not run.mean_temperature_csv.is_file():
        raise MissingRunFileError(run.mean_temperature_csv,
                                  "mean particle temperature and falling mass per step")
    return run


def _require_air(case: Case, case_path: Path) -> None:
    if case.air.model == "none" or case.air.mass_flow <= 0.0:
        why = (
            "air.model = 'none'"
            if case.air.model == "none"
            else f"air.mass_flow = {case.air.mass_flow:g} kg/s"
        )
        raise NoHeatTransferError(
            f"{case_path}: the run had no air ({why}), so h cannot be measured: without air the "
            "mean particle temperature changes only by conduction between particles, and "
            "Eqs. 34-39 need the air to take the heat. Run the case with air acting on the "
            "particles: air.model = 'uniform' (plug flow) or 'cfd' (OpenFOAM), both available, "
            "and air.mass_flow > 0."
        )


@dataclass(frozen=True)
class _Series:
    """The run's output steps: times, mean temperature, falling mass per step."""

    t: NDArray[np.float64]
    temp: NDArray[np.float64]
    per_step_mass: NDArray[np.float64]  # per step (one fewer than the times)
    dt: NDArray[np.float64]


def _read_series(csv_path: Path) -> _Series:
    table = _read_mean_temperature(csv_path)
    t = table["time_s"].to_numpy(dtype=np.float64)
    temp = table["mean_temperature_C"].to_numpy(dtype=np.float64)
    per_step_mass = table["falling_mass_kg_in_step"].to_numpy(dtype=np.float64)[1:]
    dt = np.diff(t)
    if np.any(dt <= 0.0):
        row = int(np.flatnonzero(dt <= 0.0)[0]) + 2
        raise RunDirectoryError(f"{csv_path}: time_s is not increasing at data row {row}")
    return _Series(t, temp, per_step_mass, dt)


def _series_until(series: _Series, until: float) -> _Series:
    """The output times up to ``until`` (s), as a run stopped there would have written them."""
    if not math.isfinite(until) or until < series.t[1] - _TIME_EPS_S:
        raise AnalysisInputError(
            "until", until, f"a simulated time >= {series.t[1]:.10g} s (the second output time, "
            f"so that there is one step); the run ends at {series.t[-1]:.10g} s")
    n = int(np.searchsorted(series.t, until + _TIME_EPS_S, side="right"))
    return _Series(series.t[:n], series.temp[:n], series.per_step_mass[: n - 1], series.dt[: n - 1])


@dataclass(frozen=True)
class _Window:
    """The falling-mass window (after ``run.mass_flow_start``) and its mean mass flow."""

    in_window: NDArray[np.bool_]
    span: tuple[float, float]
    flow: float
    notes: tuple[str, ...]


def _falling_window_of(series: _Series, case: Case, csv_path: Path) -> _Window:
    in_window, notes = _falling_window(series.t, case.run.mass_flow_start)
    window_mass = float(series.per_step_mass[in_window].sum())
    window_time = float(series.dt[in_window].sum())
    span = (float(series.t[:-1][in_window][0]), float(series.t[1:][in_window][-1]))
    if window_mass <= 0.0:
        raise NoHeatTransferError(
            f"{csv_path}: no particle fell through the axis plane between {span[0]:g} s and "
            f"{span[1]:g} s (falling_mass_kg_in_step is 0), so the falling-particle area "
            "(Eq. 41) is zero and h cannot be measured; check the lifters and the rotation speed"
        )
    return _Window(in_window, span, window_mass / window_time, tuple(notes))


@dataclass
class _Steps:
    """Eqs. 34-41 per step, with steps that cannot give h masked (and why)."""

    particle_dT: NDArray[np.float64]
    air_mass: NDArray[np.float64]
    used_mass: NDArray[np.float64]
    h: NDArray[np.float64]
    heat: NDArray[np.float64]
    air_dt: NDArray[np.float64]
    air_t: NDArray[np.float64]
    lmtd: NDArray[np.float64]
    rate: NDArray[np.float64]
    area: NDArray[np.float64]
    mask: NDArray[np.object_]

    @property
    def valid(self) -> NDArray[np.bool_]:
        return np.isfinite(self.h)


def _per_step(case: Case, series: _Series, window: _Window, falling_mass: FallingMassMode,
              run: RunDir) -> _Steps:
    n = series.dt.size
    streams = {
        "material_cp_j_kgk": case.particles.heat_capacity,
        "air_mass_flow_kg_s": case.air.mass_flow,
        "air_cp_j_kgk": case.air.heat_capacity,
        "air_inlet_temperature_c": case.air.inlet_temperature_C,
    }
    dp, rho = case.particles.diameter, case.particles.density
    no_fall = np.zeros(n, dtype=bool)
    try:
        if falling_mass == "mean":
            used_mass = window.flow * series.dt
            steps = per_step_heat_transfer(
                series.t, series.temp, particle_diameter_m=dp, particle_density_kg_m3=rho,
                falling_mass_flow_kg_s=window.flow, **streams,
            )
        else:
            no_fall = series.per_step_mass <= 0.0
            # per_step_heat_transfer needs a positive mass everywhere; steps where nothing fell
            # get a placeholder and are masked below (Eq. 41 gives them no area).
            placeholder = np.where(no_fall, 1.0, series.per_step_mass)
            used_mass = np.where(no_fall, 0.0, series.per_step_mass)
            steps = per_step_heat_transfer(
                series.t, series.temp, particle_diameter_m=dp, particle_density_kg_m3=rho,
                falling_mass_kg=placeholder, **streams,
            )
    except AnalysisInputError as exc:
        raise RunDirectoryError(f"{run.mean_temperature_csv} with {run.case_toml}: {exc}") from exc

    out = _Steps(
        particle_dT=np.asarray(steps.particle_dT_c),
        air_mass=np.asarray(steps.air_mass_kg),
        used_mass=used_mass,
        h=np.array(steps.h_w_m2k, dtype=np.float64),
        heat=np.array(steps.heat_j, dtype=np.float64),
        air_dt=np.array(steps.air_dT_c, dtype=np.float64),
        air_t=np.array(steps.air_temperature_c, dtype=np.float64),
        lmtd=np.array(steps.lmtd_c, dtype=np.float64),
        rate=np.array(steps.heat_rate_w, dtype=np.float64),
        area=np.array(steps.area_m2, dtype=np.float64),
        mask=np.full(n, "", dtype=object),
    )
    out.mask[steps.particle_dT_c == 0.0] = _NO_CHANGE
    out.mask[(out.mask == "") & ~np.isfinite(steps.lmtd_c)] = _CROSS
    if no_fall.any():
        # Eq. 35 with m_mf = 0: no heat reaches the air and there is no area; h is undefined.
        out.heat[no_fall] = 0.0
        out.air_dt[no_fall] = 0.0
        out.air_t[no_fall] = case.air.inlet_temperature_C
        out.rate[no_fall] = 0.0
        out.area[no_fall] = 0.0
        out.lmtd[no_fall] = np.nan
        out.h[no_fall] = np.nan
        out.mask[no_fall] = _NO_FALL
    return out


def _mean_h(steps: _Steps, series: _Series, csv_path: Path) -> float:
    """The time average of h over the valid steps (the paper's h)."""
    valid = steps.valid
    n, n_valid = valid.size, int(valid.sum())
    if n_valid == 0:
        counts = {r: int((steps.mask == r).sum()) for r in (_NO_CHANGE, _CROSS, _NO_FALL)}
        if counts[_NO_CHANGE] == n:
            why = (
                f"the mean particle temperature never changed ({series.temp[0]:g} deg C "
                "throughout): the air took no heat"
            )
        else:
            why = ", ".join(f"{v} step(s) {k.replace('_', ' ')}" for k, v in counts.items() if v)
        raise NoHeatTransferError(f"{csv_path}: no valid step of {n}, so h cannot be measured: {why}")
    dt = series.dt
    h_mean = float(np.sum(steps.h[valid] * dt[valid]) / np.sum(dt[valid]))
    if not h_mean > 0.0:
        raise NoHeatTransferError(
            f"{csv_path}: the mean h over {n_valid} valid step(s) is {h_mean:.4g} W/(m2 K), not "
            "positive: the particles did not cool on average, so the cooler model cannot be "
            "applied"
        )
    return h_mean


def _steps_table(series: _Series, window: _Window, steps: _Steps, numbers: Any) -> pd.DataFrame:
    """The per-step table (``post/steps.csv``)."""
    valid = steps.valid

    def scatter(values: NDArray[np.float64]) -> NDArray[np.float64]:
        out = np.full(valid.size, np.nan)
        out[valid] = values
        return out

    return pd.DataFrame(
        {
            "time_s": series.t[1:],
            "dt_s": series.dt,
            "mean_temperature_C": series.temp[1:],
            "particle_dT_K": steps.particle_dT,
            "falling_mass_in_step_kg": series.per_step_mass,
            "falling_mass_kg": steps.used_mass,
            "air_mass_kg": steps.air_mass,
            "heat_J": steps.heat,
            "air_dT_K": steps.air_dt,
            "air_temperature_C": steps.air_t,
            "lmtd_K": steps.lmtd,
            "heat_rate_W": steps.rate,
            "area_fp_m2": steps.area,
            "h_W_m2K": steps.h,
            "valid": valid,
            "mask": steps.mask.astype(str),
            "in_mass_flow_window": window.in_window,
            "mean_air_temperature_C": scatter(numbers.mean_air_temperature_c),
            "reynolds": scatter(numbers.reynolds),
            "prandtl": scatter(numbers.prandtl),
            "nusselt": scatter(numbers.nusselt),
            "conductivity_W_mK": scatter(numbers.conductivity_w_mk),
        }
    )


def _exchangers(
    case: Case, h_mean: float, flow: float, dt_mean: float, case_path: Path, notes: list[str]
) -> tuple[float, float, float, ExchangerResult, ExchangerResult | None]:
    """The section's falling mass and area, the plant's exchanger area (Eqs. 41, 47-48), the
    cooler model at that area, and the area for the plant's outlet temperature if given."""
    m_mf = flow * dt_mean
    a_fp = float(falling_particle_area(m_mf, case.particles.diameter, case.particles.density))
    a_he = exchanger_area_from_section(
        a_fp, cooler_length_m=case.plant.length, section_length_m=case.drum.length, dt_s=dt_mean
    )
    plant = plant_streams(case)
    try:
        model = solve_outlet_temperature(h_w_m2k=h_mean, area_m2=a_he, **plant)
    except AnalysisInputError as exc:
        raise RunDirectoryError(f"{case_path}: the plant streams do not make a cooler: {exc}") from exc
    plant_result: ExchangerResult | None = None
    if case.plant.material_outlet_temperature_C is not None:
        try:
            plant_result = area_for_outlet_temperature(
                h_w_m2k=h_mean,
                material_outlet_temperature_c=case.plant.material_outlet_temperature_C,
                **plant,
            )
        except InfeasibleExchangerError as exc:
            notes.append(f"plant.material_outlet_temperature_C: {exc}")
    return m_mf, a_fp, a_he, model, plant_result


def write_methodology(run_dir: Path | str, result: MethodologyResult) -> tuple[Path, Path]:
    """Write ``post/methodology.json`` and ``post/steps.csv`` into the run directory.

    Parameters
    ----------
    run_dir
        The run directory (its ``post/`` folder is created if missing).
    result
        The result of :func:`analyse_run` for this directory.

    Returns
    -------
    tuple of pathlib.Path
        The JSON file and the CSV file.
    """
    run = RunDir(run_dir, create=False)
    json_path, csv_path = run.methodology_json, run.steps_csv
    json_path.parent.mkdir(parents=True, exist_ok=True)
    json_path.write_text(json.dumps(result.to_dict(), indent=2, allow_nan=False) + "\n")
    result.steps.to_csv(csv_path, index=False, float_format="%.10g")
    return json_path, csv_path


def fit_runs(
    run_dirs: Iterable[Path | str | MethodologyResult],
    *,
    nusselt_conductivity: NusseltConductivity = "air",
    falling_mass: FallingMassMode = "mean",
    **fit_kwargs: Any,
) -> NusseltCorrelation:
    """Fit ``Nu = a Re^b Pr^c`` (Eq. 56, Table 8) to the valid steps of several runs.

    Parameters
    ----------
    run_dirs
        Run directories, or results of :func:`analyse_run` (not analysed again; then the two
        options below are not used for them).
    nusselt_conductivity, falling_mass
        Passed to :func:`analyse_run` for the directories.
    **fit_kwargs
        Passed to :func:`~drumflow.analysis.correlation.fit_nusselt_correlation`.
        ``drop_nonpositive`` defaults to True here: a step in which the mean temperature rose
        has a negative ``h`` (it is kept in the paper's average) but cannot enter a power law.

    Returns
    -------
    NusseltCorrelation

    Raises
    ------
    AnalysisInputError
        If there is no run, or the data cannot identify the exponents (e.g. one run only: Re then
        varies only through the air viscosity; combine runs with different particle diameters or
        air flows).
    RunDirectoryError
        If a directory cannot be analysed (see :func:`analyse_run`).
    """
    results = [
        r
        if isinstance(r, MethodologyResult)
        else analyse_run(r, nusselt_conductivity=nusselt_conductivity, falling_mass=falling_mass)
        for r in run_dirs
    ]
    fit_kwargs.setdefault("drop_nonpositive", True)
    return fit_nusselt_correlation_from_runs(
        [(r.nusselt, r.reynolds, r.prandtl) for r in results], **fit_kwargs
    )
