"""The methodology on a synthetic run directory whose per-step h is known.

The synthetic run (:func:`support.synthetic_run.write_synthetic_run`, also used by the report
and predict tests through the ``write_synthetic_run`` fixture) has the smoke
case's drum and particles, with air switched on. Its mean temperature decays towards the air
inlet temperature by the same factor ``r`` every step, ``T_k = T_ai + (T_0 - T_ai) r^k``, which
is an exponential in time. The falling mass per step is constant. The factor comes from the
closed-form effectiveness-NTU solution of one counter-current step with a chosen ``h``. That
solution does not use the LMTD, so recovering ``h`` through Eqs. 34-39 is an independent check.
For an exponential decay the recovered ``h`` is the same in every step.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from support.synthetic_run import (
    AIR_FLOW,
    CSV_RTOL,
    DT,
    FALLING_PARTICLES,
    H_RTOL,
    H_TRUE,
    N_STEPS,
    synthetic_case_dict,
    write_synthetic_run,
)

from drumflow.analysis.heat_transfer import falling_particle_area
from drumflow.analysis.methodology import (
    MissingRunFileError,
    NoHeatTransferError,
    analyse_run,
    fit_runs,
    write_methodology,
)
from drumflow.analysis.methodology_result import MethodologyResult, plant_streams
from drumflow.errors import AnalysisInputError, RunDirectoryError
from drumflow.physics import air
from drumflow.physics.exchanger import (
    area_for_outlet_temperature,
    exchanger_area_from_section,
    solve_outlet_temperature,
)


@pytest.fixture()
def run_dir(tmp_path: Path) -> Path:
    return write_synthetic_run(tmp_path / "run", extras=False)


# ------------------------------------------------------------------------- recovering h


def test_synthetic_drop_is_large_enough(run_dir: Path) -> None:
    # The H_RTOL argument needs every per-step drop to be at least 0.03 K.
    table = pd.read_csv(run_dir / "post" / "mean_temperature.csv")
    drops = -np.diff(table["mean_temperature_C"].to_numpy())
    assert drops.min() > 0.03


def test_known_h_is_recovered(run_dir: Path) -> None:
    res = analyse_run(run_dir)
    assert res.n_steps == N_STEPS and res.n_valid == N_STEPS
    np.testing.assert_allclose(res.steps["h_W_m2K"], H_TRUE, rtol=H_RTOL)
    assert res.h_mean_w_m2k == pytest.approx(H_TRUE, rel=H_RTOL)
    # Table 6 quantities come from the CSV's times and falling masses, written with 10
    # significant digits: 1e-9 relative.
    m_mf = FALLING_PARTICLES * res.case.particles.mass
    assert res.falling_mass_per_step_kg == pytest.approx(m_mf, rel=CSV_RTOL)
    assert res.falling_mass_flow_kg_s == pytest.approx(m_mf / DT, rel=CSV_RTOL)
    assert res.dt_s == pytest.approx(DT, rel=CSV_RTOL)
    assert res.air_mass_per_step_kg == pytest.approx(AIR_FLOW * DT, rel=CSV_RTOL)
    assert res.falling_area_m2 == pytest.approx(6.0 * m_mf / (1050.0 * 0.008), rel=CSV_RTOL)
    assert res.warnings == ()


def test_h_hardly_depends_on_the_falling_mass(run_dir: Path) -> None:
    # Eqs. 35, 39 and 41: the heat and the area are both proportional to m_mf, so m_mf cancels
    # from h except through the air warming in the LMTD (Eq. 37). With the plant's 25 kg/s of
    # air that warming is ~1e-4 K on a ~60 K difference. Recompute h from the table with m_mf
    # cancelled: equal within H_RTOL. The falling mass matters for A_he (Table 7), not for h.
    res = analyse_run(run_dir)
    s = res.steps
    rho, dp, cp = 1050.0, 0.008, 1465.38
    h_no_mass = rho * dp * cp * (-s["particle_dT_K"]) / (6.0 * s["dt_s"] * s["lmtd_K"])
    np.testing.assert_allclose(h_no_mass, s["h_W_m2K"], rtol=1e-12)


def test_falling_mass_is_measured_after_mass_flow_start(tmp_path: Path) -> None:
    # The CSV reports 20 particles per step during the first second (settling); the paper
    # measures m_mf after 1 s only, so h must still come out right.
    root = write_synthetic_run(tmp_path / "r", early_falling_particles=20, extras=False)
    res = analyse_run(root)
    assert res.falling_mass_window_s[0] == pytest.approx(1.0, abs=1e-9)
    # m_mf is the in-window mean (4 particles), not the all-steps mean (~9.3): CSV_RTOL.
    m_p = res.case.particles.mass
    assert res.falling_mass_per_step_kg == pytest.approx(FALLING_PARTICLES * m_p, rel=CSV_RTOL)
    assert res.exchanger_area_m2 == pytest.approx(
        6.0 * FALLING_PARTICLES * m_p / (1050.0 * 0.008) * 19.0 / 0.08 / DT, rel=CSV_RTOL
    )
    assert res.h_mean_w_m2k == pytest.approx(H_TRUE, rel=H_RTOL)
    assert bool(res.steps["in_mass_flow_window"].iloc[-1])
    assert not bool(res.steps["in_mass_flow_window"].iloc[0])


def test_per_step_falling_mass(tmp_path: Path) -> None:
    counts = np.tile([3, 0, 5, 4, 6], N_STEPS // 5)
    root = write_synthetic_run(tmp_path / "r", falling_particles=counts, extras=False)
    res = analyse_run(root, falling_mass="per_step")
    no_fall = counts == 0
    assert res.masked == {"no_falling_mass": int(no_fall.sum())}
    assert res.steps["valid"].to_numpy().tolist() == (~no_fall).tolist()
    m_p = res.case.particles.mass
    # Each step's own mass is used (CSV digits: CSV_RTOL); nothing-fell steps carry no area.
    np.testing.assert_allclose(res.steps["falling_mass_kg"], counts * m_p, rtol=CSV_RTOL)
    assert (res.steps["area_fp_m2"][no_fall] == 0.0).all()
    # Same rounding argument as H_RTOL: the smallest drop (3 particles) is 0.024 K, which
    # bounds the error at 4.2e-7, still inside H_RTOL.
    np.testing.assert_allclose(res.steps["h_W_m2K"][~no_fall], H_TRUE, rtol=H_RTOL)
    # The default mode gives every step the mean mass (3.6 particles) and masks the same steps
    # for another reason: the temperature did not change.
    mean_mode = analyse_run(root)
    np.testing.assert_allclose(mean_mode.steps["falling_mass_kg"], 3.6 * m_p, rtol=CSV_RTOL)
    assert mean_mode.masked == {"no_temperature_change": int(no_fall.sum())}


def test_dimensionless_numbers_per_step(run_dir: Path) -> None:
    res = analyse_run(run_dir)
    steps = res.steps
    # Eq. 50: T_ma is the mean of the inlet and the step's outlet air temperature (exact).
    np.testing.assert_allclose(
        steps["mean_air_temperature_C"], 0.5 * (30.0 + steps["air_temperature_C"]), rtol=1e-14
    )
    # Eqs. 51-55 by hand for the first step.
    t_ma = float(steps["mean_air_temperature_C"].iloc[0])
    v_ai = AIR_FLOW / (air.density(30.0) * math.pi * 0.4**2 / 4.0)
    v_d = math.pi * 0.2**2 * 0.08
    vf = (v_d - 3000 * math.pi / 6.0 * 0.008**3) / v_d
    re = v_ai / vf * 0.008 / air.kinematic_viscosity(t_ma)
    # Same formulas, different evaluation order: 1e-12.
    assert float(steps["reynolds"].iloc[0]) == pytest.approx(re, rel=1e-12)
    assert res.void_fraction == pytest.approx(vf, rel=1e-12)
    nu = float(steps["nusselt"].iloc[0])
    assert nu == pytest.approx(
        float(steps["h_W_m2K"].iloc[0]) * 0.008 / air.thermal_conductivity(t_ma), rel=1e-12
    )
    # The particle conductivity reproduces the paper's Nusselt numbers: Nu = h Dp / 0.18596.
    paper = analyse_run(run_dir, nusselt_conductivity="particle")
    np.testing.assert_allclose(paper.nusselt, paper.steps["h_W_m2K"] * 0.008 / 0.18596, rtol=1e-12)


# ------------------------------------------------------------------------------ exchanger


def test_exchanger_consistent_with_exchanger_module(run_dir: Path) -> None:
    res = analyse_run(run_dir)
    case = res.case
    m_mf = FALLING_PARTICLES * case.particles.mass
    a_fp = falling_particle_area(m_mf, 0.008, 1050.0)
    a_he = exchanger_area_from_section(a_fp, cooler_length_m=19.0, section_length_m=0.08, dt_s=DT)
    # Eq. 46 by hand: 6 m_mf / (rho Dp) * (L / l) / dt, from the CSV's 10-digit masses.
    assert res.exchanger_area_m2 == pytest.approx(a_he, rel=CSV_RTOL)
    assert res.exchanger_area_m2 == pytest.approx(
        6.0 * m_mf / (1050.0 * 0.008) * 19.0 / 0.08 / DT, rel=CSV_RTOL
    )
    direct = solve_outlet_temperature(
        h_w_m2k=res.h_mean_w_m2k, area_m2=res.exchanger_area_m2, **plant_streams(case)
    )
    # The same solver on the same inputs: identical up to brentq's xtol (1e-12 K).
    assert res.exchanger.material_outlet_temperature_c == pytest.approx(
        direct.material_outlet_temperature_c, abs=1e-9
    )
    assert res.exchanger.air_outlet_temperature_c == pytest.approx(
        direct.air_outlet_temperature_c, abs=1e-9
    )
    # Plant streams come from the case: 13.88889 kg/s at 90 deg C, air 25 kg/s at 30 deg C.
    assert plant_streams(case) == {
        "material_mass_flow_kg_s": 13.88889, "material_cp_j_kgk": 1465.38,
        "material_inlet_temperature_c": 90.0, "air_mass_flow_kg_s": 25.0,
        "air_cp_j_kgk": 1005.0, "air_inlet_temperature_c": 30.0,
    }
    # Eq. 48 closes: brentq to 1e-12 K on ~1e5 W, so 1e-6 relative is generous.
    assert res.exchanger.heat_exchanged_w == pytest.approx(res.exchanger.heat_removed_w, rel=1e-6)
    assert 30.0 < res.exchanger.material_outlet_temperature_c < 90.0
    assert res.plant_exchanger is None  # the smoke case gives no plant outlet temperature


def test_plant_outlet_temperature_gives_the_required_area(tmp_path: Path) -> None:
    d = synthetic_case_dict(plant={"material_outlet_temperature_C": 85.0})
    res = analyse_run(write_synthetic_run(tmp_path / "r", case_dict=d, extras=False))
    assert res.plant_exchanger is not None
    expected = area_for_outlet_temperature(
        h_w_m2k=res.h_mean_w_m2k, material_outlet_temperature_c=85.0, **plant_streams(res.case)
    )
    # Same function, same inputs: identical up to rounding (1e-12).
    assert res.plant_exchanger.area_m2 == pytest.approx(expected.area_m2, rel=1e-12)


def test_infeasible_plant_outlet_is_a_warning_not_an_error(tmp_path: Path) -> None:
    # 20 deg C is below the 30 deg C air: impossible, reported but the model column stays.
    d = synthetic_case_dict(plant={"material_outlet_temperature_C": 20.0})
    res = analyse_run(write_synthetic_run(tmp_path / "r", case_dict=d, extras=False))
    assert res.plant_exchanger is None
    assert any("material_outlet_temperature_C" in w for w in res.warnings)


# ------------------------------------------------------------------------- JSON and files


def test_write_methodology(run_dir: Path) -> None:
    res = analyse_run(run_dir)
    json_path, csv_path = write_methodology(run_dir, res)
    assert json_path == run_dir.resolve() / "post" / "methodology.json"
    data = json.loads(json_path.read_text())
    assert data["heat_transfer"]["h_mean_W_m2K"] == pytest.approx(res.h_mean_w_m2k, rel=1e-15)
    assert data["heat_transfer"]["n_valid"] == N_STEPS
    assert data["exchanger"]["model"]["material_outlet_temperature_c"] == pytest.approx(
        res.exchanger.material_outlet_temperature_c, rel=1e-15
    )
    assert data["exchanger"]["plant"] is None
    table = pd.read_csv(csv_path)
    assert len(table) == N_STEPS
    # steps.csv uses 10 significant digits: 1e-9 relative.
    np.testing.assert_allclose(table["h_W_m2K"], res.steps["h_W_m2K"], rtol=1e-9)


def test_to_dict_is_strict_json(tmp_path: Path) -> None:
    # A masked step makes NaN statistics possible; the dict must still be valid JSON.
    counts = np.tile([3, 0, 5], N_STEPS // 3)
    root = write_synthetic_run(tmp_path / "r", falling_particles=counts, extras=False)
    res = analyse_run(root, falling_mass="per_step")
    json.dumps(res.to_dict(), allow_nan=False)


# ------------------------------------------------------------------------------ errors


def test_missing_case_file_is_named(run_dir: Path) -> None:
    (run_dir / "case.toml").unlink()
    with pytest.raises(MissingRunFileError, match=r"case\.toml") as info:
        analyse_run(run_dir)
    assert isinstance(info.value, RunDirectoryError) and isinstance(info.value, ValueError)
    assert info.value.path == run_dir.resolve() / "case.toml"


def test_missing_mean_temperature_is_named(run_dir: Path) -> None:
    (run_dir / "post" / "mean_temperature.csv").unlink()
    with pytest.raises(MissingRunFileError, match=r"post/mean_temperature\.csv"):
        analyse_run(run_dir)


def test_missing_column_is_named(run_dir: Path) -> None:
    path = run_dir / "post" / "mean_temperature.csv"
    table = pd.read_csv(path).drop(columns=["falling_mass_kg_in_step"])
    table.to_csv(path, index=False)
    with pytest.raises(RunDirectoryError, match="mean_temperature.csv: missing column.*falling_mass"):
        analyse_run(run_dir)


def test_not_a_directory(tmp_path: Path) -> None:
    with pytest.raises(RunDirectoryError, match="not a directory"):
        analyse_run(tmp_path / "nowhere")


def test_run_without_air_is_a_clear_error(tmp_path: Path) -> None:
    d = synthetic_case_dict(air={"model": "none"})
    root = write_synthetic_run(tmp_path / "r", case_dict=d, constant_temperature=True, extras=False)
    with pytest.raises(NoHeatTransferError, match="the run had no air.*h cannot be measured") as info:
        analyse_run(root)
    assert isinstance(info.value, RunDirectoryError) and isinstance(info.value, ValueError)


def test_constant_temperature_with_air_has_no_valid_step(tmp_path: Path) -> None:
    root = write_synthetic_run(tmp_path / "r", constant_temperature=True, extras=False)
    with pytest.raises(NoHeatTransferError, match="no valid step.*never changed"):
        analyse_run(root)


def test_no_falling_mass_is_a_clear_error(tmp_path: Path) -> None:
    root = write_synthetic_run(tmp_path / "r", falling_particles=0, extras=False)
    with pytest.raises(NoHeatTransferError, match="no particle fell"):
        analyse_run(root)


def test_bad_option_is_rejected(run_dir: Path) -> None:
    with pytest.raises(AnalysisInputError, match="nusselt_conductivity"):
        analyse_run(run_dir, nusselt_conductivity="water")  # type: ignore[arg-type]


# ----------------------------------------------------------------------------- fit_runs


def test_fit_runs_recovers_the_reynolds_exponent(tmp_path: Path) -> None:
    # Two runs at 25 and 50 kg/s of air. Re is proportional to the air flow (same void fraction
    # and nearly the same T_ma), so h2 = h1 * 2^b makes Nu = h Dp / k_particle follow Re^b.
    b_true = 0.5
    r1 = write_synthetic_run(tmp_path / "a", h=H_TRUE, extras=False)
    d2 = synthetic_case_dict(air={"mass_flow": 2 * AIR_FLOW})
    r2 = write_synthetic_run(tmp_path / "b", h=H_TRUE * 2**b_true, case_dict=d2, extras=False)
    corr = fit_runs([r1, r2], nusselt_conductivity="particle")
    # Within a run Re moves only through nu(T_ma), by ~1e-6 relative (the air warms by ~1e-4 K
    # per step), and the recovered h by < 3e-7 relative, so b is determined by the two clusters
    # to about 1e-5. 1e-3 is a safe margin that still rejects b = 0.48 or 0.52.
    assert corr.b == pytest.approx(b_true, abs=1e-3)
    assert corr.n == 2 * N_STEPS
    assert not corr.prandtl_exponent_fitted  # Pr does not vary independently of Re here
    # Results are accepted as they are, without analysing again.
    res = [analyse_run(r, nusselt_conductivity="particle") for r in (r1, r2)]
    assert isinstance(res[0], MethodologyResult)
    assert fit_runs(res).b == pytest.approx(corr.b, rel=1e-12)


def test_fit_on_one_run_says_why_not(run_dir: Path) -> None:
    with pytest.raises(AnalysisInputError, match="spread of ln\\(Re\\)"):
        fit_runs([run_dir])
