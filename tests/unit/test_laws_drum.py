"""Law tests of the whole-drum model (:mod:`drumflow.coolers.drum`) and of the plant
prediction (:mod:`drumflow.coolers.prediction`), issue 36.

Independent references:

* drum: with lumped particles and the bed term off, every particle exchanges only while it
  falls, at the Ranz-Marshall h of its slip, against air in counter-current plug flow. That
  is a counter-current exchanger with UA = (particles per second) x (pi d^2) x h x (time each
  particle spends falling, tau t_f / t_cycle), whose outlet is the epsilon-NTU formula
  (Incropera Eq. 11.29a). h is worked out by hand from Ranz and Marshall with Incropera's
  Table A.4 row at 300 K (typed in :mod:`support.law_references`) and the ideal-gas density.
  The fall kinematics and the residence time (tau, t_f, t_cycle, the slip) are the closure
  scaling's outputs, taken from the result: they are not the heat-transfer law checked here.
* plant prediction: Re, Nu = a Re^b Pr^c, h = Nu k / Dp, the area of Eq. 46 and the
  counter-current exchanger, all written out from the paper's equations with the table
  properties at the air inlet temperature, and T_mo from epsilon-NTU (not from the
  package's LMTD root finder).

Each ``check_*`` is a plain function (see ``test_law_mutants.py``) that calls the package
through its modules, so that a patched law is the one checked.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from support.law_references import counter_current_effectiveness, incropera_air

from drumflow.analysis.closures import SliceClosures
from drumflow.case import load_case
from drumflow.coolers import _transport, drum
from drumflow.coolers import prediction as predict
from drumflow.coolers.plant import PAPER_PLANT

CASES = Path(__file__).resolve().parents[2] / "cases"

# Closures of the order a 0.4 m slice gives (the same hand-written set as test_drum_model).
CLOSURES = SliceClosures(
    source="hand-written", case_name="hand", drum_diameter_m=0.4, section_length_m=0.08,
    rpm=15.0, tilt_deg=1.5, lifter_count=8, particle_diameter_m=8e-3,
    particle_density_kg_m3=1050.0, holdup_kg_per_m=10.56, solids_volume_fraction=0.08,
    air_axial_velocity_m_s=3.0, falling_mass_flow_kg_s_m=3.4, airborne_fraction=0.04,
    fall_time_s=0.13, fall_height_m=0.16, airborne_speed_m_s=1.3,
    airborne_downward_speed_m_s=1.25, slip_velocity_m_s=3.3, bed_slip_velocity_m_s=3.1,
    bed_surface_m2_per_m=0.25, snapshots=9, window_s=(1.0, 3.0),
)
# Air enters at 300 K (26.85 C), the material 1 K above: the air warms by < 0.5 K, so its
# properties stay at the 300 K row (h moves 2e-5 over that span, measured). The model is
# linear at fixed properties, so the 1 K span loses nothing. A short residence time keeps
# NTU near 0.6, where the outlet is sensitive to h.
PLANT = PAPER_PLANT.changed(length_m=6.0, feed_rate_kg_s=4.0, air_mass_flow_kg_s=8.0,
                                    particle_diameter_m=6e-3, air_inlet_temperature_c=26.85,
                                    material_inlet_temperature_c=27.85)
RESIDENCE_S = 200.0


def _close(value: float, reference: float, rtol: float, what: str) -> None:
    assert math.isfinite(value) and abs(value / reference - 1.0) <= rtol, (
        f"{what}: {value:.8g} vs independent {reference:.8g} "
        f"({value / reference - 1.0:+.3%}, allowed {rtol:.1e})")


def check_drum_counter_current() -> None:
    """The lumped drum without bed exchange against the counter-current epsilon-NTU outlet.

    The cell march converges at second order: the drop is 1.6e-4 from epsilon-NTU on 10
    cells, 3.4e-5 on 20 (used here), 2.3e-6 on 40; h is 1.7e-5 from the hand value (the air
    seen is 0.2 K above the 300 K row). 1e-3 is allowed on both, 100 times below a 10 %
    change of h (which moves the drop by 6 % at this NTU).
    """
    law = _transport.calibrate(PLANT, RESIDENCE_S)
    r = drum.solve_drum(PLANT, CLOSURES, law,
                        drum.DrumOptions(cells=20, lumped_particles=True, bed_exchange=False))
    s = r.scaled
    rho = 101325.0 / (287.05 * 300.0)  # ideal gas, R_air = 8.314462618 / 0.0289647
    _, _, mu, _, k, pr = incropera_air(300.0)
    d = PLANT.particle_diameter_m
    re = rho * s.fall_effective_slip_m_s * d / mu
    h = (2.0 + 0.6 * math.sqrt(re) * pr ** (1.0 / 3.0)) * k / d  # Ranz-Marshall
    _close(r.h_fall_w_m2k, h, 1e-3, "drum fall film coefficient")
    particle_mass = PLANT.particle_density_kg_m3 * math.pi * d**3 / 6.0
    falling_time = s.residence_time_s * s.fall_time_s / s.cycle_time_s
    ua = PLANT.feed_rate_kg_s / particle_mass * math.pi * d**2 * h * falling_time
    c_solids = PLANT.feed_rate_kg_s * PLANT.particle_heat_capacity_j_kgk
    c_air = PLANT.air_mass_flow_kg_s * PLANT.air_heat_capacity_j_kgk
    c_min, c_max = min(c_solids, c_air), max(c_solids, c_air)
    duty = counter_current_effectiveness(ua / c_min, c_min / c_max) * c_min * 1.0
    _close(PLANT.material_inlet_temperature_c - r.material_outlet_c, duty / c_solids, 1e-3,
           "drum solids cooling vs counter-current epsilon-NTU")
    _close(r.air_outlet_c - PLANT.air_inlet_temperature_c, duty / c_air, 1e-3,
           "drum air warming vs counter-current epsilon-NTU")


def check_plant_prediction() -> None:
    """predict_plant at 1.2 x the air flow of the paper's model one, with the paper's Eq. 58
    (its a, b, c in drumflow's Re, particle conductivity in Nu), against the equations
    written out; T_mo from epsilon-NTU. Everything is closed-form on both sides except the
    package's brentq (xtol 1e-12 K): 1e-9 relative, 1e-6 on the temperature drop."""
    case = load_case(CASES / "paper_model_one.toml")
    corr = predict.paper_correlation()
    falling = 0.05  # kg/s in the 0.1 m section
    air_flow = 1.2 * 25.0
    p = predict.predict_plant(corr, case, air_mass_flow=air_flow, falling_mass_flow_kg_s=falling,
                              nusselt_conductivity="particle")
    rho, _, _, nu, _, pr = incropera_air(30.0 + 273.15)
    big_d, section, dp, rho_p, count = 3.0, 0.1, 0.008, 1050.0, 467443
    v_drum = math.pi * big_d**2 / 4.0 * section  # Eq. 54
    v_solids = count * math.pi * dp**3 / 6.0  # Eq. 55
    void = (v_drum - v_solids) / v_drum  # Eq. 53
    v_ai = air_flow / (rho * math.pi * big_d**2 / 4.0)  # Eq. 52
    re = v_ai / void * dp / nu  # Eq. 51
    h = corr.a * re**corr.b * pr**corr.c * 0.18596 / dp  # Eqs. 49, 58
    area = 6.0 * falling * 1.0 / (rho_p * dp) * 19.0 / section  # Eqs. 41, 46
    _close(p.reynolds, re, 1e-9, "plant Re")
    _close(p.h_w_m2k, h, 1e-9, "plant h = Nu k / Dp")
    _close(p.exchanger_area_m2, area, 1e-9, "plant exchange area")
    c_m, c_a = 13.88889 * 1465.38, air_flow * 1005.0
    c_min, c_max = min(c_m, c_a), max(c_m, c_a)
    duty = counter_current_effectiveness(h * area / c_min, c_min / c_max) * c_min * (90.0 - 30.0)
    _close(90.0 - p.exchanger.material_outlet_temperature_c, duty / c_m, 1e-6,
           "plant T_mo vs counter-current epsilon-NTU")


def test_lumped_drum_is_a_counter_current_exchanger() -> None:
    check_drum_counter_current()


def test_plant_prediction_written_out() -> None:
    check_plant_prediction()


# -- issue 34: the air through the curtains ----------------------------------------------------

def check_curtain_lumped_epsilon_ntu() -> None:
    """One curtain pass of lumped particles whose capacity rate dwarfs the air's (Cr -> 0):
    the air leaves at ``T_g + (T_p - T_g)(1 - exp(-NTU))`` whatever the flow arrangement
    (Incropera Eq. 11.35a), ``NTU = n pi d^2 h t_f / (m_c c_p)``. Here NTU = 1, where a 10 %
    error in the air's capacity rate or the particles' conductance moves the rise by 5.8 %;
    the column grid (0.1 NTU each) is within 1e-4 and Cr = 1e-4 within 1e-4: 1e-3 allowed."""
    from drumflow.coolers._curtain_pass import curtain_pass
    from drumflow.physics.particle_interior import Sphere, SphereConduction

    d, rho, cp = 3e-3, 1050.0, 1465.0
    model = SphereConduction(Sphere(d, 1.0e4, rho, cp), shells=4)
    # A weak film (h t_f small) over many particles: the particles carry 1e4 times the air.
    h, t_f, gas = 0.5, 0.1, 10.0  # W/(m2 K), s, W/K
    conductance = gas * 1.0  # NTU = 1
    rate = conductance / (math.pi * d**2 * h * t_f)
    particle_capacity = rate * rho * math.pi * d**3 / 6.0 * cp
    assert gas / particle_capacity < 1.2e-4
    p = curtain_pass(model, h, t_f, rate, gas, rows=5)
    state = np.concatenate([np.full(4, 80.0), [30.0]])
    rise = float(p.gas_out @ state) - 30.0
    _close(rise, 50.0 * (1.0 - math.exp(-1.0)), 1e-3, "curtain air rise vs epsilon-NTU, Cr -> 0")


def check_drum_saturated_curtain_counter_current() -> None:
    """The drum with a thin through-curtain stream (lumped particles, bed off): every curtain
    saturates it (gas NTU ~ 60, remainder e^-60), so the air that crosses a curtain leaves at
    the particles' temperature and the drum is a counter-current exchanger with
    ``UA = rho q_c c_p L`` (rho ideal gas at the 300 K inlet). Then the film coefficient does
    not matter at all, only the air through the curtains: a 10 % error in that flow moves the
    drop by 10 %. The 20-cell march is within 1e-5 at this NTU: 1e-3 allowed."""
    law = _transport.calibrate(PLANT, RESIDENCE_S)
    q_c = 0.01  # m3/s per metre
    r = drum.solve_drum(PLANT, CLOSURES, law,
                        drum.DrumOptions(cells=20, lumped_particles=True, bed_exchange=False,
                                         curtain_air_m3_s_m=q_c))
    assert r.curtain_saturation > 0.999
    rho = 101325.0 / (287.05 * 300.0)
    ua = rho * q_c * PLANT.air_heat_capacity_j_kgk * PLANT.length_m
    c_solids = PLANT.feed_rate_kg_s * PLANT.particle_heat_capacity_j_kgk
    c_air = PLANT.air_mass_flow_kg_s * PLANT.air_heat_capacity_j_kgk
    c_min, c_max = min(c_solids, c_air), max(c_solids, c_air)
    duty = counter_current_effectiveness(ua / c_min, c_min / c_max) * c_min * 1.0
    _close(PLANT.material_inlet_temperature_c - r.material_outlet_c, duty / c_solids, 1e-3,
           "drum solids cooling with a saturated curtain vs epsilon-NTU")
    _close(r.air_outlet_c - PLANT.air_inlet_temperature_c, duty / c_air, 1e-3,
           "drum air warming with a saturated curtain vs epsilon-NTU")


def test_curtain_air_rise_is_epsilon_ntu() -> None:
    check_curtain_lumped_epsilon_ntu()


def test_saturated_curtain_drum_is_a_counter_current_exchanger() -> None:
    check_drum_saturated_curtain_counter_current()


def test_curtain_checks_catch_a_ten_percent_error(monkeypatch: pytest.MonkeyPatch) -> None:
    """Both checks fail when the curtain's air capacity rate is 10 % off."""
    from drumflow.coolers import _curtain_pass

    original = _curtain_pass.element_exchange

    def off(exposure: Any, capacities: Any, temperatures: Any, particle_rate: float,
            gas_inlet_c: float, gas_capacity_rate: float) -> Any:
        return original(exposure, capacities, temperatures, particle_rate, gas_inlet_c,
                        1.1 * gas_capacity_rate)

    monkeypatch.setattr(_curtain_pass, "element_exchange", off)
    with pytest.raises(AssertionError, match="epsilon-NTU"):
        check_curtain_lumped_epsilon_ntu()
    with pytest.raises(AssertionError, match="epsilon-NTU"):
        check_drum_saturated_curtain_counter_current()
