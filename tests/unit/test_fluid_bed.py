"""The vibrating fluid-bed cooler: correlations against hand values from their sources, the
shared particle solver, energy closure, the fit's recovery of known parameters, and bad input
refused with the field named (library and command line)."""

from __future__ import annotations

import json
import math
from pathlib import Path

import pytest
from typer.testing import CliRunner

from drumflow.cli import app
from drumflow.coolers import _fluidization as fl
from drumflow.coolers import fluid_bed as fb
from drumflow.coolers.fit import fit_parameters, read_points, synthetic_points, write_points
from drumflow.coolers.particle_interior import SphereConduction
from drumflow.errors import CaseError

CASE = Path(__file__).resolve().parents[2] / "cases" / "fluid_bed_npk.toml"

# A gas with round properties, so the hand values below need no property library.
GAS = fl.HumidAir(temperature=293.15, pressure=101325.0, humidity_ratio=0.0, density=1.2,
                  heat_capacity=1006.0, viscosity=1.8e-5, conductivity=0.026)


def _case(steps: int = 200, **losses: float) -> fb.FluidBedCase:
    case = fb.load_fluid_bed_case(CASE)
    update: dict[str, object] = {"numerics": fb.Numerics(shells=10, steps_per_section=steps)}
    if losses:
        update["losses"] = case.losses.model_copy(update=losses)
    return case.model_copy(update=update)


# -- correlations against hand values -----------------------------------------------------------
def test_wen_yu_minimum_fluidization_by_hand() -> None:
    # d = 1 mm, rho_p = 2500: Ar = 1.2 * 2498.8 * 9.81 * 1e-9 / (1.8e-5)^2 = 90789.73;
    # Re_mf = sqrt(33.7^2 + 0.0408 Ar) - 33.7 = 44.843; u_mf = Re_mf mu / (rho d) = 0.53804 m/s.
    assert fl.archimedes(1e-3, 2500.0, GAS) == pytest.approx(90789.7333, rel=1e-8)
    assert fl.minimum_fluidization_velocity(1e-3, 2500.0, GAS) == pytest.approx(0.538042, rel=1e-5)


def test_haider_levenspiel_terminal_velocity_reaches_stokes_law() -> None:
    # 5 um sphere: Ar = 0.01135, d* = Ar^(1/3) = 0.2248, so the inertial term 0.591 / d*^0.5
    # is 0.591 d*^1.5 / 18 = 0.35 % of the Stokes term 18 / d*^2: u_t is Stokes' law
    # g d^2 (rho_p - rho_g) / (18 mu) divided by 1.0035 (= 0.99651).
    d, rho_p = 5e-6, 2500.0
    stokes = 9.81 * d**2 * (rho_p - GAS.density) / (18 * GAS.viscosity)
    ratio = fl.terminal_velocity(d, rho_p, GAS) / stokes
    assert ratio == pytest.approx(0.99651, abs=2e-5)


def test_rowe_richardson_zaki_exponent_limits() -> None:
    # Rowe (1987): n -> 4.7 as Re_t -> 0 and -> 0.41 / 0.175 = 2.343 as Re_t -> infinity.
    assert fl.richardson_zaki_exponent(10e-6, 2500.0, GAS) == pytest.approx(4.7, abs=0.01)
    assert fl.richardson_zaki_exponent(0.05, 2500.0, GAS) == pytest.approx(0.41 / 0.175, abs=0.02)


def test_darton_bubble_diameter_by_hand() -> None:
    # u - u_mf = 1.5 m/s, h = 0.1 m, A_0 = 4e-4 m^2 (20 mm pitch):
    # 0.54 * 1.5^0.4 * (0.1 + 4 * 0.02)^0.8 / 9.81^0.2 = 0.54 * 1.17608 * 0.25363 / 1.57914 = 0.10200 m.
    assert fl.darton_bubble_diameter(1.5, 0.1, 4e-4) == pytest.approx(0.102027, rel=1e-5)


def test_gunn_nusselt_by_hand() -> None:
    # eps = 0.5, Re = 100, Pr = 0.7: (7 - 5 + 1.25)(1 + 0.7 * 2.51189 * 0.88790)
    # + (1.33 - 1.2 + 0.3) * 25.1189 * 0.88790 = 8.3240 + 9.5903 = 17.9143.
    assert fl.gunn_nusselt(100.0, 0.7, 0.5) == pytest.approx(17.91431, rel=1e-6)
    with pytest.raises(ValueError, match="Gunn"):
        fl.gunn_nusselt(100.0, 0.7, 0.3)


def test_vibration_numbers_by_hand() -> None:
    # 16 Hz, 2.5 mm: Gamma = 0.0025 (2 pi 16)^2 / 9.81 = 2.5756;
    # Re_v = 1.2 * 0.0025 * 2 pi 16 * 0.0027 / 1.8e-5 = 45.239.
    assert fl.vibration_intensity(0.0025, 16.0) == pytest.approx(2.575554, rel=1e-6)
    assert fl.vibration_reynolds(0.0025, 16.0, 0.0027, GAS) == pytest.approx(45.23893, rel=1e-6)


def test_geldart_groups_of_textbook_powders() -> None:
    # Kunii and Levenspiel (1991) Fig. 3.8: FCC catalyst 60 um/1400 is A, 150 um sand is B,
    # 3 mm granules of 1750 kg/m^3 are D.
    assert fl.geldart_group(60e-6, 1400.0, 1.2) == "A"
    assert fl.geldart_group(150e-6, 2650.0, 1.2) == "B"
    assert fl.geldart_group(3e-3, 1750.0, 1.2) == "D"


def test_bed_state_holds_the_solids_and_balances_the_gas() -> None:
    bed = fl.bed_state(2.0, GAS, 1e-3, 2500.0, solids_flow=5.0, solids_velocity=0.1, width=1.0,
                       orifice_area=4e-4)
    # Eq. 20: H (1 - eps) v B rho_p = S, to the solver's tolerance.
    assert bed.bed_height * (1 - bed.voidage) * 0.1 * 1.0 * 2500.0 == pytest.approx(5.0, rel=1e-9)
    # Gas balance: bubbles carry psi (u - u_mf), the dense phase the rest.
    psi = fl.VISIBLE_BUBBLE_FLOW_RATIO[bed.geldart]
    carried = (psi * (2.0 - bed.min_fluidization_velocity)
               + (1 - bed.bubble_fraction) * bed.dense_phase_velocity)
    assert carried == pytest.approx(2.0, rel=1e-9)
    assert bed.min_fluidization_velocity < 2.0 < bed.terminal_velocity


def test_sauter_diameter_of_a_sieve_analysis() -> None:
    # d32 = 1 / (0.5/2 + 0.5/4) mm = 2.6667 mm.
    dist = fb.SizeDistribution(diameters_mm=[2.0, 4.0], mass_fractions=[0.5, 0.5])
    assert dist.sauter_diameter == pytest.approx(2.0 / 0.75 * 1e-3, rel=1e-12)


# -- the unit -----------------------------------------------------------------------------------
def test_unit_uses_the_shared_particle_solver(monkeypatch: pytest.MonkeyPatch) -> None:
    calls = {"n": 0}
    original = SphereConduction.step

    def counting(self: SphereConduction, *args: object, **kwargs: object) -> object:
        calls["n"] += 1
        return original(self, *args, **kwargs)  # type: ignore[arg-type]

    monkeypatch.setattr(SphereConduction, "step", counting)
    case = _case(steps=20)
    fb.run_unit(case, fb.case_conditions(case))
    assert calls["n"] == 2 * 20  # every time step of both sections goes through it


@pytest.mark.parametrize("cooled", [None, 290.0])
def test_energy_balance_closes(cooled: float | None) -> None:
    case = _case(steps=50)
    r = fb.run_unit(case, fb.case_conditions(case), cooled_air_temperature=cooled)
    # Product enthalpy drop = air enthalpy gain at the measuring point + hood loss; the shell
    # solver and the slice balance conserve energy to round-off, so 1e-9 is generous.
    assert r.closure < 1e-9
    assert r.loss_heat > 0
    assert r.air_measured_temperature < r.air_mixed_temperature


def test_outlet_converges_with_time_steps() -> None:
    case = fb.load_fluid_bed_case(CASE)
    cond = fb.case_conditions(case)
    fine_numerics = fb.Numerics(shells=20, steps_per_section=2000)
    fine = fb.run_unit(case.model_copy(update={"numerics": fine_numerics}), cond)
    coarse = fb.run_unit(case, cond)
    # The shipped numerics (10 shells, 200 steps) are within 0.01 K of 20 shells / 2000 steps
    # (measured 0.004 K), well under a thermocouple's 0.3 K.
    assert abs(coarse.product_outlet_temperature - fine.product_outlet_temperature) < 0.01


def test_losses_do_not_touch_the_product() -> None:
    # The hood loses heat from the air after it left the bed: the product outlet does not
    # depend on hLosses A, the measured air does (which is what makes the fit well posed).
    case = _case(steps=30)
    cond = fb.case_conditions(case)
    a = fb.run_unit(case, cond, losses_conductance=0.0)
    b = fb.run_unit(case, cond, losses_conductance=5000.0)
    assert a.product_outlet_temperature == b.product_outlet_temperature
    assert b.air_measured_temperature < a.air_measured_temperature


def test_source_qualitative_results() -> None:
    """f_c = 0.30, hLosses A = 1.17 kW/K (the case), Salamanca mean daily maxima: the
    source finds ambient air enough except June-August and a nearly flat particle."""
    case = _case(steps=50)
    year = {m.month: op for m, op in fb.operate_year(case)}
    for month in (1, 2, 3, 4, 5, 10, 11, 12):
        assert not year[month].cooling_needed, month
    assert year[7].cooling_needed and year[7].target_met
    # Flat radial profile at the outlet: centre to surface shell within 2.5 K while the
    # product cooled by ~10 K (Bi = f_c h R / k ~ 0.5).
    unit = year[7].unit
    assert unit.radial_temperature[0] - unit.radial_temperature[-1] < 2.5
    assert year[7].cycle is not None and year[7].cycle.cop < year[7].cycle.carnot_cop


# -- fitting ------------------------------------------------------------------------------------
def test_fit_recovers_known_parameters(tmp_path: Path) -> None:
    case = _case(steps=30)
    points = synthetic_points(case, 16, convective_efficiency=0.30, losses_conductance=1170.0,
                              noise=0.2, seed=7)
    path = tmp_path / "points.csv"
    write_points(path, points, header="synthetic")
    result = fit_parameters(case, read_points(path), initial=(0.6, 3000.0))
    assert result.success
    lo, hi = result.ci_convective_efficiency
    assert lo < 0.30 < hi
    lo, hi = result.ci_losses_conductance
    assert lo < 1170.0 < hi
    # The residuals are the noise that was added (0.2 K) within sampling error.
    assert 0.1 < result.residual_std < 0.35


# -- bad input ----------------------------------------------------------------------------------
def _write_case(tmp_path: Path, old: str, new: str) -> Path:
    text = CASE.read_text()
    assert old in text
    path = tmp_path / "bad.toml"
    path.write_text(text.replace(old, new))
    return path


def test_bad_case_value_names_the_field(tmp_path: Path) -> None:
    path = _write_case(tmp_path, "convective_efficiency = 0.30", "convective_efficiency = 1.5")
    with pytest.raises(CaseError, match=r"losses\.convective_efficiency.*1\.5"):
        fb.load_fluid_bed_case(path)


def test_velocity_below_minimum_fluidization_is_refused(tmp_path: Path) -> None:
    path = _write_case(tmp_path, "velocity = 5.0", "velocity = 0.5")
    with pytest.raises(CaseError, match=r"air\.ambient\.velocity = 0\.5.*minimum"):
        fb.load_fluid_bed_case(path)


def test_cli_bad_case_exit_code_2_without_traceback(tmp_path: Path) -> None:
    path = _write_case(tmp_path, "ambient_fraction = 0.8", "ambient_fraction = 1.2")
    res = CliRunner().invoke(app, ["cooler", "fluid-bed", str(path), "--out", str(tmp_path / "run")])
    assert res.exit_code == 2
    assert "unit.ambient_fraction" in res.output
    assert "Traceback" not in res.output


def test_cli_bad_data_exit_code_2(tmp_path: Path) -> None:
    data = tmp_path / "points.csv"
    data.write_text("t_ambient_C,rh_pct,t_product_in_C,t_cooled_air_C,t_product_out_C,t_air_out_C\n"
                    "20,150,46,,35,30\n")
    res = CliRunner().invoke(app, ["cooler", "fit", str(CASE), str(data), "--out", str(tmp_path / "run")])
    assert res.exit_code == 2
    assert "rh_pct" in res.output and "Traceback" not in res.output


def test_cli_month_run_writes_the_run_directory(tmp_path: Path) -> None:
    out = tmp_path / "run"
    res = CliRunner().invoke(app, ["cooler", "fluid-bed", str(CASE), "--month", "1",
                                   "--out", str(out), "--json"])
    assert res.exit_code == 0, res.output
    for name in ("manifest.json", "result.json", "profile.png", "radial_outlet.png", "profile.csv"):
        assert (out / name).is_file(), name
    result = json.loads((out / "result.json").read_text())
    assert math.isfinite(result["product_outlet_K"]) and result["energy_closure"] < 1e-9


def test_weather_table_has_twelve_months() -> None:
    months = fb.load_weather("salamanca")
    assert [m.month for m in months] == list(range(1, 13))
    assert all(m.t_max_mean_C > m.t_mean_C for m in months)
