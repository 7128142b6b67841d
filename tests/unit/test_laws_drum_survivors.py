"""Law tests for the drum model's mutation survivors (issue 36; results/mutation/survivors.md).

The mutmut run of ``drumflow/coolers/drum.py`` (tree of d6ddc82, before the closures scaling
moved to :mod:`drumflow.coolers.drum_closures`) left mutants alive in the closure scaling, the
bed term, the through-curtain branch and the wall loss: the law tests had the bed term off,
took every scaled closure from the result, and had a saturated curtain (where the fall time
does not matter) and no wall loss. Each test here compares with a value that does not come
from the function under test:

* the scaled closures written out from the module notes (hold-up ``W = mdot tau / L``,
  ``G_f = n_c W rpm / 60``, ``H_f`` with the diameter, ``phi = G_f t_f / W``, the axial air
  speed on the ideal-gas density, the segment chord solved here by bisection);
* the lumped drum with the bed on: a counter-current exchanger whose bed conductance is
  ``h(u_axial) x S_bed x L`` exactly (the bed share of the hold-up cancels:
  ``rate pi d^2 h_s S / (n_bed pi d^2) tau (1 - phi) = h_s S L``), epsilon-NTU outlet;
* an unbounded through-curtain flow is the all-air limit (same epsilon-NTU);
* wall loss alone: plug-flow solids losing to ambient, ``exp(-U pi D L / (mdot c_p))``;
* the segment chord at closed-form points (beta = 1/2; theta = 0.8 rad).

The transport law's residence time and the drag-ballistic fall time (``t_f``, the slip) are
other modules' laws; they are taken from the result or from their own functions, as in
``test_laws_drum.py``.
"""

from __future__ import annotations

import dataclasses
import math
import re

import pytest
from support.law_references import counter_current_effectiveness, incropera_air
from test_laws_drum import CLOSURES, PLANT, RESIDENCE_S

from drumflow.coolers import _transport, drum, drum_closures
from drumflow.coolers._fall import fall_kinematics
from drumflow.errors import DrumModelError
from drumflow.physics.particle_air import AirState

LAW = _transport.calibrate(PLANT, RESIDENCE_S)
RHO_300 = 101325.0 / (287.05 * 300.0)  # ideal gas at the 300 K (26.85 C) inlet: 1.176725 kg/m3
BED_PACKING = 0.6  # random loose packing (drumflow.analysis.closures.BED_PACKING, typed again)
# A ten times larger slice bed surface than the shared hand closures: the bed then takes about
# half of the heat, so a 10 % error in the bed term moves the outlet by ~3 %.
BED_CLOSURES = dataclasses.replace(CLOSURES, bed_surface_m2_per_m=2.5)


def _close(value: float, reference: float, rtol: float, what: str) -> None:
    assert math.isfinite(value) and abs(value / reference - 1.0) <= rtol, (
        f"{what}: {value:.8g} vs independent {reference:.8g} "
        f"({value / reference - 1.0:+.3%}, allowed {rtol:.1e})")


def _chord(beta: float) -> float:
    """Chord / diameter of a circular segment holding ``beta`` of the circle: the segment's
    central angle theta solves theta - sin(theta) = 2 pi beta (bisection, written out)."""
    lo, hi = 0.0, 2.0 * math.pi
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        if mid - math.sin(mid) < 2.0 * math.pi * beta:
            lo = mid
        else:
            hi = mid
    return math.sin(0.25 * (lo + hi))


def _ranz_marshall(velocity: float) -> float:
    """h = (2 + 0.6 Re^1/2 Pr^1/3) k / d at 300 K (Incropera Table A.4, typed), W/(m2 K)."""
    _, _, mu, _, k, pr = incropera_air(300.0)
    d = PLANT.particle_diameter_m
    re_ = RHO_300 * velocity * d / mu
    return (2.0 + 0.6 * math.sqrt(re_) * pr ** (1.0 / 3.0)) * k / d


def _hand_closures(closures: object, fall_time: float) -> dict[str, float]:
    """The module notes' scaling laws, written out at the law case (PLANT, tau = 200 s):

    W = 4 * 200 / 6 = 133.3333 kg/m; n_c = 3.4 / (10.56 * 15 / 60) = 1.287879;
    G_f = 1.287879 * 133.3333 * 5 / 60 = 14.30976 kg/(s m); H_f = 0.16 * 3 / 0.4 = 1.2 m;
    cycle = W / G_f = 9.317647 s; u_axial = 8 / (1.176725 * pi * 3^2 / 4) = 0.961877 m/s;
    solids fraction = 133.3333 / 1050 / 7.068583 = 0.01796480; phi = G_f t_f / W (0.05378 at
    t_f = 0.5011 s); bed area = 0.01796480 (1 - phi) / 0.6 = 0.02832; slice bed area
    0.08 * 0.96 / 0.6 = 0.128; S = S_slice * 3 chord(0.02832) / (0.4 chord(0.128)).
    """
    c = closures
    holdup = PLANT.feed_rate_kg_s * RESIDENCE_S / PLANT.length_m
    n_c = c.falling_mass_flow_kg_s_m / (c.holdup_kg_per_m * c.rpm / 60.0)  # type: ignore[attr-defined]
    g_f = n_c * holdup * PLANT.rpm / 60.0
    solids = holdup / PLANT.particle_density_kg_m3 / (math.pi * PLANT.diameter_m**2 / 4.0)
    phi = g_f * fall_time / holdup
    area_plant = solids * (1.0 - phi) / BED_PACKING
    area_slice = c.solids_volume_fraction * (1.0 - c.airborne_fraction) / BED_PACKING  # type: ignore[attr-defined]
    surface = (c.bed_surface_m2_per_m * PLANT.diameter_m * _chord(area_plant)  # type: ignore[attr-defined]
               / (c.drum_diameter_m * _chord(area_slice)))  # type: ignore[attr-defined]
    return {
        "holdup_kg_per_m": holdup,
        "falling_mass_flow_kg_s_m": g_f,
        "fall_height_m": c.fall_height_m * PLANT.diameter_m / c.drum_diameter_m,  # type: ignore[attr-defined]
        "cycle_time_s": holdup / g_f,
        "airborne_fraction": phi,
        "axial_air_velocity_m_s": PLANT.air_mass_flow_kg_s / (RHO_300 * math.pi * PLANT.diameter_m**2 / 4.0),
        "bed_surface_m2_per_m": surface,
    }


def check_scaled_closures() -> None:
    """scale_closures against the laws written out (:func:`_hand_closures`). Closed form on
    both sides except the air density (ideal gas here, the package's table within 1e-6):
    1e-6 allowed, 1e-9 where no property enters."""
    s = drum_closures.scale_closures(PLANT, BED_CLOSURES, LAW)
    hand = _hand_closures(BED_CLOSURES, s.fall_time_s)
    for name, value in hand.items():
        _close(getattr(s, name), value, 1e-6, f"scaled closure {name}")
    # The fall is computed in the inlet air at the axial speed, and the slice's ballistic fall
    # in the same air at the slice's speed (fall_kinematics is its own law, tested apart).
    air = AirState.at(PLANT.air_inlet_temperature_c, 101.325)
    fall = fall_kinematics(1.2, PLANT.particle_diameter_m, PLANT.particle_density_kg_m3, air,
                           hand["axial_air_velocity_m_s"])
    _close(s.fall_time_s, fall.time_s, 1e-6, "plant fall time (inlet air)")
    slice_fall = fall_kinematics(0.16, 8e-3, 1050.0, air, 3.0)
    _close(s.slice_ballistic_fall_time_s, slice_fall.time_s, 1e-6, "slice ballistic fall time")
    assert s.slice_measured_fall_time_s == 0.13
    assert s.slice_airborne_fraction == 0.04


def check_chord_fraction() -> None:
    """Circular segment: a half-full drum has its chord on the diameter (beta = 1/2 -> 1);
    theta = 0.8 rad holds beta = (0.8 - sin 0.8) / (2 pi) = 0.01315295 and has the chord
    sin(0.4) = 0.3894183. 1e-9 (brentq's tolerance)."""
    _close(drum_closures._chord_fraction(0.5), 1.0, 1e-9, "chord of a half-full drum")
    beta = (0.8 - math.sin(0.8)) / (2.0 * math.pi)
    _close(drum_closures._chord_fraction(beta), math.sin(0.4), 1e-9, "chord at theta = 0.8")


def _drop_by_epsilon_ntu(ua: float) -> float:
    c_solids = PLANT.feed_rate_kg_s * PLANT.particle_heat_capacity_j_kgk
    c_air = PLANT.air_mass_flow_kg_s * PLANT.air_heat_capacity_j_kgk
    c_min, c_max = min(c_solids, c_air), max(c_solids, c_air)
    return counter_current_effectiveness(ua / c_min, c_min / c_max) * c_min * 1.0 / c_solids


def _fall_conductance(s: drum_closures.PlantClosures) -> float:
    """rate pi d^2 h_f (tau t_f / t_cycle), as in test_laws_drum (slip from the result)."""
    d = PLANT.particle_diameter_m
    rate = PLANT.feed_rate_kg_s / (PLANT.particle_density_kg_m3 * math.pi * d**3 / 6.0)
    falling_time = s.residence_time_s * s.fall_time_s / s.cycle_time_s
    return rate * math.pi * d**2 * _ranz_marshall(s.fall_effective_slip_m_s) * falling_time


def check_drum_with_bed() -> None:
    """Lumped particles, bed on: UA = fall conductance + h(u_axial) S_bed L, with the axial
    speed and S_bed by hand (0.9619 m/s, h = 53.7 W/(m2 K); S_bed = 11.988 m2/m), the bed
    then about half the heat. 20 cells: within 4e-5 of epsilon-NTU (test_laws_drum); 1e-3
    allowed, against 3 % for a 10 % error in the bed term."""
    r = drum.solve_drum(PLANT, BED_CLOSURES, LAW, drum.DrumOptions(cells=20, lumped_particles=True))
    s = r.scaled
    hand = _hand_closures(BED_CLOSURES, s.fall_time_s)
    h_bed = _ranz_marshall(hand["axial_air_velocity_m_s"])
    _close(r.h_bed_surface_w_m2k, h_bed, 1e-3, "bed-surface film coefficient (axial air)")
    ua_bed = h_bed * hand["bed_surface_m2_per_m"] * PLANT.length_m
    ua_fall = _fall_conductance(s)
    assert 0.3 < ua_bed / (ua_bed + ua_fall) < 0.7
    drop = _drop_by_epsilon_ntu(ua_fall + ua_bed)
    _close(PLANT.material_inlet_temperature_c - r.material_outlet_c, drop, 1e-3,
           "drum with bed: solids cooling vs epsilon-NTU")
    # Each cell's heat split: the bed's share of the heat is its share of the conductance
    # (lumped particles, one temperature difference per cell).
    bed_share = ua_bed / (ua_bed + ua_fall)
    _close(r.heat_bed_w / r.heat_to_air_w, bed_share, 2e-3,
           "bed share of the heat vs its share of the conductance")
    _close(r.curtain_share, 1.0 - bed_share, 2e-3, "curtain share vs its share of the conductance")
    _close(float(r.cell_bed_w.sum()) / r.heat_to_air_w, bed_share, 2e-3, "cells' bed heat")
    _close(float(r.cell_curtain_w.sum()) / r.heat_to_air_w, 1.0 - bed_share, 2e-3,
           "cells' curtain heat")
    # The profile's axis: 21 faces 0.3 m apart from the solids inlet (6 m / 20 cells).
    assert [round(z, 12) for z in r.z_m.tolist()] == [round(0.3 * i, 12) for i in range(21)]
    # The air properties settle (a 1 K span: two or three passes), and nothing is flagged.
    assert r.warnings == [] and 1 <= r.property_iterations < 30


def check_unbounded_curtain_air_is_the_all_air_limit() -> None:
    """A through-curtain flow of 1e4 m3/s per metre (the largest allowed; 6e4 m3/s over the
    drum against 6.8 m3/s axially) leaves each curtain at the cell's air temperature: the
    all-air limit, the epsilon-NTU outlet of test_laws_drum. 1e-3 allowed."""
    r = drum.solve_drum(PLANT, CLOSURES, LAW,
                        drum.DrumOptions(cells=20, lumped_particles=True, bed_exchange=False,
                                         curtain_air_m3_s_m=drum.MAX_CURTAIN_AIR_M3_S_M))
    drop = _drop_by_epsilon_ntu(_fall_conductance(r.scaled))
    _close(PLANT.material_inlet_temperature_c - r.material_outlet_c, drop, 1e-3,
           "unbounded through-curtain air vs the all-air epsilon-NTU outlet")
    _close(r.curtain_air_kg_s_m, RHO_300 * 1.0e4, 1e-6, "through-curtain air, kg/(s m)")


def test_all_air_reports_no_through_curtain_stream() -> None:
    """All the air meets the curtain: an unbounded stream, no saturation (NaN, documented),
    each cell's curtain air is the cell's air."""
    r = drum.solve_drum(PLANT, CLOSURES, LAW, drum.DrumOptions(cells=5, lumped_particles=True))
    assert r.curtain_air_kg_s_m == math.inf
    assert math.isnan(r.curtain_saturation)
    assert len(r.cell_curtain_air_out_c) == 5 and all(
        PLANT.air_inlet_temperature_c <= t <= PLANT.material_inlet_temperature_c
        for t in r.cell_curtain_air_out_c)


def test_no_air_through_the_curtains_takes_no_curtain_heat() -> None:
    """curtain_air_m3_s_m = 0 (allowed): the falls exchange with no air, only the bed takes
    heat, and the curtain air reported is the cell's (finite)."""
    r = drum.solve_drum(PLANT, CLOSURES, LAW,
                        drum.DrumOptions(cells=5, lumped_particles=True, curtain_air_m3_s_m=0.0))
    assert abs(r.heat_curtain_w) < 1e-9 * r.heat_bed_w  # round-off (6e-11 W of 3e2 W)
    assert all(math.isfinite(t) for t in r.cell_curtain_air_out_c)


def test_saturated_curtain_reports_saturation() -> None:
    """A thin through-curtain stream (0.01 m3/s per metre, gas NTU ~ 60, test_laws_drum):
    the air leaving each curtain is at the particles' temperature. Its approach
    (T_out - T_air) / (T_solids - T_air) is 1 to within the cell's solids-temperature
    variation (lumped, 20 cells), never above 1 (second law): 0.999 to 1.001."""
    r = drum.solve_drum(PLANT, CLOSURES, LAW,
                        drum.DrumOptions(cells=20, lumped_particles=True, bed_exchange=False,
                                         curtain_air_m3_s_m=0.01))
    assert 0.999 < r.curtain_saturation <= 1.001
    solids_cell = 0.5 * (r.solids_c[1:] + r.solids_c[:-1])
    rise = r.cell_curtain_air_out_c - r.air_c[1:]
    span = r.solids_c[0] - r.air_c[-1]
    assert all(abs(x) <= 0.01 * span for x in r.cell_curtain_air_out_c - solids_cell)
    assert all(x > 0 for x in rise)
    _close(r.curtain_air_kg_s_m, RHO_300 * 0.01, 1e-6, "through-curtain air, kg/(s m)")


def test_march_is_second_order() -> None:
    """The cell march (air at the mean of its cell's faces) is second order: 5 cells are
    6.6e-4 from the epsilon-NTU outlet of test_laws_drum (1.6e-4 on 10; a first-order or
    mis-weighted mean is 1.7e-3 off on 5). 1e-3 allowed."""
    r = drum.solve_drum(PLANT, CLOSURES, LAW,
                        drum.DrumOptions(cells=5, lumped_particles=True, bed_exchange=False))
    drop = _drop_by_epsilon_ntu(_fall_conductance(r.scaled))
    _close(PLANT.material_inlet_temperature_c - r.material_outlet_c, drop, 1e-3,
           "5-cell march vs epsilon-NTU")


WALL_PLANT = PLANT.changed(material_inlet_temperature_c=90.0)
NO_FALLS = dataclasses.replace(CLOSURES, falling_mass_flow_kg_s_m=1e-9)


def check_wall_loss_alone(u_wall: float = 0.8, ambient: float = 30.0) -> None:
    """No falls, no bed: plug-flow lumped solids losing U pi D dz (T - T_amb) to ambient:
    T_out = T_amb + (T_in - T_amb) exp(-U pi D L / (mdot c_p)). U = 0.8 W/(m2 K):
    x = 0.8 * pi * 3 * 6 / (4 * 1465.38) = 7.7187e-3, drop = 60 (1 - e^-x) = 0.46136 K.
    The march is explicit in the loss per cell (relative error x / (2 N) = 1e-5 on 400 cells):
    1e-3 allowed, against 10 % for a 10 % error in U."""
    r = drum.solve_drum(WALL_PLANT, NO_FALLS, LAW,
                        drum.DrumOptions(cells=400, shells=2, lumped_particles=True,
                                         bed_exchange=False, wall_loss_w_m2k=u_wall,
                                         ambient_temperature_c=ambient))
    x = u_wall * math.pi * PLANT.diameter_m * PLANT.length_m / (
        PLANT.feed_rate_kg_s * PLANT.particle_heat_capacity_j_kgk)
    drop = (90.0 - ambient) * (1.0 - math.exp(-x))
    _close(90.0 - r.material_outlet_c, drop, 1e-3, "wall loss alone vs exp(-U pi D L / mdot c_p)")
    _close(r.wall_loss_w, PLANT.feed_rate_kg_s * PLANT.particle_heat_capacity_j_kgk * drop, 1e-3,
           "wall loss heat")
    _close(float(r.cell_wall_w.sum()), r.wall_loss_w, 1e-9, "cells' wall loss")


def test_scaled_closures_written_out() -> None:
    check_scaled_closures()


def test_chord_fraction_closed_form() -> None:
    check_chord_fraction()


def test_drum_with_bed_is_a_counter_current_exchanger() -> None:
    check_drum_with_bed()


def test_unbounded_curtain_air_is_the_all_air_limit() -> None:
    check_unbounded_curtain_air_is_the_all_air_limit()


def test_wall_loss_alone_is_exponential() -> None:
    check_wall_loss_alone()


def test_shells_option_is_used() -> None:
    """The shell count converges the interior (Bi ~ 1 for 6 mm at h ~ 90): 2 shells are
    further from 60 than 30 are. With the option ignored all three would be equal."""
    def outlet(shells: int) -> float:
        return drum.solve_drum(PLANT, CLOSURES, LAW, drum.DrumOptions(cells=10, shells=shells)
                               ).material_outlet_c
    fine = outlet(60)
    assert abs(outlet(2) - fine) > 10.0 * abs(outlet(30) - fine)


def test_equal_inlets_are_refused() -> None:
    with pytest.raises(DrumModelError, match="material_inlet_temperature_c"):
        drum.solve_drum(PLANT.changed(material_inlet_temperature_c=26.85), CLOSURES, LAW,
                        drum.DrumOptions(cells=5))


def test_too_fast_rotation_names_the_limit() -> None:
    """A fall longer than a cascade cycle is refused with the rpm below which it is not:
    cycle = W / G_f = 60 / (n_c rpm), so the limit is 60 / (n_c t_f), t_f the fall time
    (independent of rpm: it depends on the fall height and the axial air)."""
    plant = PLANT.changed(rpm=200.0)
    air = AirState.at(PLANT.air_inlet_temperature_c, 101.325)
    u_axial = PLANT.air_mass_flow_kg_s / (RHO_300 * math.pi * PLANT.diameter_m**2 / 4.0)
    t_f = fall_kinematics(1.2, PLANT.particle_diameter_m, PLANT.particle_density_kg_m3, air,
                          u_axial).time_s
    n_c = 3.4 / (10.56 * 15.0 / 60.0)
    with pytest.raises(DrumModelError, match=r"rpm = 200") as err:
        drum_closures.scale_closures(plant, CLOSURES, LAW)
    found = re.search(r"allowed below ([0-9.eE+-]+) rpm", str(err.value))
    assert found is not None, str(err.value)
    _close(float(found.group(1)), 60.0 / (n_c * t_f), 2e-3, "rpm limit in the message")


def test_hold_up_filling_the_drum_is_refused() -> None:
    """A bed filling 1.42 of the cross-section is refused (feed 200 kg/s through 6 m for
    200 s: W = 6,666.7 kg/m, 6,666.7 / 1050 / 7.0686 / 0.6 = 1.497, times 1 - phi = 0.946)."""
    plant = PLANT.changed(feed_rate_kg_s=200.0)
    law = _transport.calibrate(plant, RESIDENCE_S)
    with pytest.raises(DrumModelError, match="fill the drum"):
        drum_closures.scale_closures(plant, CLOSURES, law)


@pytest.mark.parametrize("kwargs", [
    {"cells": 1}, {"cells": 5000}, {"shells": 2}, {"shells": 200}, {"curtain_rows": 1},
    {"curtain_rows": 50}, {"curtain_air_m3_s_m": 0.0}, {"curtain_air_m3_s_m": 1.0e4},
])
def test_options_accept_their_documented_ends(kwargs: dict[str, float]) -> None:
    drum.DrumOptions(**kwargs)  # type: ignore[arg-type]


@pytest.mark.parametrize(("kwargs", "field"), [
    ({"cells": 5001}, "cells"), ({"shells": 201}, "shells"), ({"curtain_rows": 51}, "curtain_rows"),
    ({"wall_loss_w_m2k": math.inf}, "wall_loss_w_m2k"), ({"curtain_air_m3_s_m": -1.0}, "curtain_air"),
    ({"curtain_air_m3_s_m": 1.0001e4}, "curtain_air"),
])
def test_options_refuse_beyond_their_ends(kwargs: dict[str, float], field: str) -> None:
    with pytest.raises(DrumModelError, match=field):
        drum.DrumOptions(**kwargs)  # type: ignore[arg-type]
