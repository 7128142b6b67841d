"""Single-particle verification of the air coupling on the real coupling loop.

* Convective heat transfer: a particle held at rest in uniform air cools; the h it realises,
  m cp ln((T0 - T_air) / (T - T_air)) / (A t), is compared with Ranz-Marshall formed
  independently (:func:`~drumflow.verify.references.ranz_marshall_reference`, CoolProp air),
  at 1 and 3 m/s (particle Re about 500 and 1,500: the drum's slip range).
* Coupling interval: the same particle's temperature drop at one time constant with the air
  updated every N steps against the exact result of that explicit hold (N dt forward-Euler
  steps), N = 10, 100, 1,000 and drumflow's 'auto' choice. Bookkeeping, not a reference: the
  expected drop is formed with drumflow's own h (``ranz_marshall_h``) and its own update
  scheme, so it catches heat applied for a step too many or too few, not a wrong h. The 'auto'
  choice against the continuous lumped solution is a reference (an analytic solution the
  update scheme does not produce).
* Settling in the Schiller-Naumann range: 0.5 and 1.2 mm particles released in still air settle
  at particle Re about 65 and 370; the drag coefficient their terminal speed implies is
  compared with the standard drag curve of Clift, Grace & Weber (not with ``drag_force``).

All run the real coupling loop (LIGGGHTS through its library) on a one-particle deck.
"""

from __future__ import annotations

import json
import math
import time
from pathlib import Path
from typing import Any

import pandas as pd

from drumflow.coupling import driver_command
from drumflow.coupling.interior import InteriorSpec, shell_fix_command
from drumflow.dem.deck import render_deck
from drumflow.dem.thermo import ThermoParser
from drumflow.physics.particle_air import AirState, auto_coupling_interval, ranz_marshall_h
from drumflow.physics.validation import relative_error
from drumflow.runner import Runner
from drumflow.verify.checks import Check
from drumflow.verify.references import (
    DRAG_TOLERANCE,
    ReferenceAir,
    drag_coefficient_from_settling,
    ranz_marshall_reference,
    settling_velocity,
    standard_drag_coefficient,
)

#: The paper's NPK particle of model one.
DIAMETER = 0.008
DENSITY = 1050.0
HEAT_CAPACITY = 1465.38
CONDUCTIVITY = 0.18596
T_AIR = 30.0
T0 = 90.0
#: The coupling loop's air pressure in these scenes, kPa.
PRESSURE_KPA = 101.325
#: Heat-transfer tolerance: the reference's air data (Lemmon & Jacobsen 2004) are stated to
#: about 2% in conductivity, which enters h linearly; the explicit hold adds N dt / (2 tau) =
#: 0.1% (N dt = 0.1 s, tau > 30 s).
H_TOLERANCE = 0.02
#: Thermo output carries 12 significant digits; the drop is ~40 K out of 90: 1e-6 relative
#: leaves four orders of headroom over print round-off yet catches a single step of heat too
#: many or too few in any interval (1 / 4,600 steps = 2e-4).
HOLD_TOLERANCE = 1e-6
#: drumflow's 'auto' coupling interval is chosen to hold the explicit-hold error near 0.1%
#: (:func:`drumflow.physics.particle_air.auto_coupling_interval`).
AUTO_TOLERANCE = 1e-3


def _particle(diameter: float, density: float) -> tuple[float, float]:
    """Mass (kg) and surface area (m2) of a sphere."""
    return density * math.pi / 6.0 * diameter**3, math.pi * diameter**2


def run_single(
    work: Path,
    runner: Runner,
    *,
    air_velocity: tuple[float, float, float],
    gravity: bool,
    held: bool,
    dt: float,
    steps: int,
    interval: int,
    thermo_every: int,
    diameter: float = DIAMETER,
    density: float = DENSITY,
    conductivity: float = CONDUCTIVITY,
    interior: InteriorSpec | None = None,
    heat_capacity: float = HEAT_CAPACITY,
    deck_extra: dict[str, Any] | None = None,
    spec_extra: dict[str, Any] | None = None,
) -> pd.DataFrame:
    """Run the one-particle scene through the coupling loop; return its thermo table.

    ``conductivity`` is the deck's; ``interior`` gives the particle shells
    (``particles.interior = "shells"``), whose conductivity may differ from the deck's (a
    deliberately wrong law, for the test that a check can fail). ``deck_extra`` and
    ``spec_extra`` add to the deck's values and the coupling loop's input (many held particles,
    an air field on a grid, air that warms: :mod:`drumflow.verify.air_heat`).
    """
    work.mkdir(parents=True, exist_ok=True)
    deck = render_deck(
        {
            "diameter": diameter,
            "density": density,
            "conductivity": conductivity,
            "heat_capacity": heat_capacity,
            "dt": dt,
            "gravity": gravity,
            "T0": T0,
            "held": held,
            "thermo_every": thermo_every,
            "shell_fix": shell_fix_command(interior.shells) if interior is not None else "",
            **(deck_extra or {}),
        },
        "single_particle.in.j2",
    )
    (work / "in.single").write_text(deck)
    spec = {
        "deck": "in.single",
        "log": "log.liggghts",
        "total_steps": steps,
        "interval": interval,
        "time_step": dt,
        "omega": 0.0,
        "air_temperature_C": T_AIR,
        "air_pressure_kPa": PRESSURE_KPA,
        "field": {"kind": "uniform", "velocity": list(air_velocity)},
        "coupling_log": "coupling/rank{rank}.{start}.csv",
        "tail": [],
        "interior": interior.to_json() if interior is not None else None,
        **(spec_extra or {}),
    }
    (work / "coupling.json").write_text(json.dumps(spec))
    runner.run("coupling", driver_command(runner.profile, 1), work, work / "driver.out", timeout=600)
    columns = ("step", "time", "atoms", "vz", "T", "cpu")
    parser = ThermoParser(columns=columns)
    for line in (work / "log.liggghts").read_text().splitlines():
        parser(line)
    table = pd.DataFrame(parser.rows, columns=list(columns))
    return table.drop_duplicates("step", keep="last").reset_index(drop=True)


def time_constant(speed: float) -> float:
    """The 8 mm particle's lumped time constant m cp / (h A) in air at ``speed``, s.

    With the reference h: it only sets how long the scene runs.
    """
    mass, area = _particle(DIAMETER, DENSITY)
    return (
        mass
        * HEAT_CAPACITY
        / (ranz_marshall_reference(speed, DIAMETER, ReferenceAir.at(T_AIR, PRESSURE_KPA)) * area)
    )


def _cooling_run(
    work: Path, runner: Runner, speed: float, interval: int, dt: float = 0.01
) -> tuple[float, int]:
    """Hold the 8 mm particle in air at ``speed`` for one time constant; (T_end, steps)."""
    steps = math.ceil(time_constant(speed) / dt)
    table = run_single(
        work,
        runner,
        air_velocity=(speed, 0.0, 0.0),
        gravity=False,
        held=True,
        dt=dt,
        steps=steps,
        interval=interval,
        thermo_every=steps,
    )
    last = table.iloc[-1]
    return float(last["T"]), int(last["step"])


def convective_h_check(work: Path, runner: Runner, speed: float = 1.0, interval: int = 10) -> Check:
    """Particle held in air at ``speed``: the h it realised against Ranz-Marshall formed anew."""
    t0 = time.perf_counter()
    dt = 0.01  # no contacts: only the heat update's accuracy matters
    T_end, steps = _cooling_run(work, runner, speed, interval, dt)
    mass, area = _particle(DIAMETER, DENSITY)
    t_end = steps * dt
    h_sim = mass * HEAT_CAPACITY * math.log((T0 - T_AIR) / (T_end - T_AIR)) / (area * t_end)
    air = ReferenceAir.at(T_AIR, PRESSURE_KPA)
    h_ref = ranz_marshall_reference(speed, DIAMETER, air)
    re = air.density * speed * DIAMETER / air.viscosity
    return Check(
        name=f"convective_h_ranz_marshall_{speed:g}ms",
        measured=h_sim,
        expected=h_ref,
        error=relative_error(h_sim, h_ref),
        tolerance=H_TOLERANCE,
        unit="W/(m2 K)",
        note=f"8 mm NPK held in {speed:g} m/s air at 30 C (Re = {re:.0f}) for one time constant "
        f"({t_end:.1f} s), coupling every {interval} steps of {dt} s; h from the cooling",
        reference="Nu = 2 + 0.6 Re^1/2 Pr^1/3 (Ranz & Marshall 1952) with CoolProp air",
        wall_time_s=time.perf_counter() - t0,
        details={"T_end_C": T_end, "reynolds": re, "reference_air": air.__dict__},
    )


def held_drop(T_start: float, h: float, interval: int, steps: int, dt: float) -> float:
    """Temperature drop after ``steps`` when the heat is re-evaluated every ``interval`` steps.

    Between updates the source h A (T_air - T_k) of the last update is applied unchanged, so
    each interval of n steps is one explicit step of n dt: T_{k+1} = T_k + n dt h A (T_air -
    T_k) / (m cp). The last interval may be shorter, as the driver makes it.
    """
    mass, area = _particle(DIAMETER, DENSITY)
    rate = h * area / (mass * HEAT_CAPACITY)
    T, done = T_start, 0
    while done < steps:
        n = min(interval, steps - done)
        T += n * dt * rate * (T_AIR - T)
        done += n
    return T_start - T


def coupling_interval_sweep(work: Path, runner: Runner, speed: float = 1.0) -> list[Check]:
    """Air updated every N steps: the drop at one time constant against the exact held result.

    A fixed hold of the heat for N steps is an explicit step of N dt; its exact drop follows
    from :func:`held_drop` with the coupling's own h (its value is the subject of
    :func:`convective_h_check`). Each row also reports the drop's difference from the
    continuous lumped solution, the price of the hold. These rows are ``bookkeeping``: their
    expected value is drumflow's own h through drumflow's own update scheme. The 'auto' row's
    error against the continuous solution (``coupling_interval_auto_error``) stays a
    ``reference``.
    """
    dt = 0.01
    air = AirState.at(T_AIR, PRESSURE_KPA)
    h = float(ranz_marshall_h(speed, DIAMETER, air))
    auto = auto_coupling_interval(dt, DIAMETER, DENSITY, HEAT_CAPACITY, air, speed, cap=10_000)
    mass, area = _particle(DIAMETER, DENSITY)
    checks = []
    for n in sorted({10, 100, 1000, auto}):
        t0 = time.perf_counter()
        T_end, steps = _cooling_run(work / f"n{n}", runner, speed, n, dt)
        drop, exact = T0 - T_end, held_drop(T0, h, n, steps, dt)
        continuous = (T0 - T_AIR) * (1.0 - math.exp(-steps * dt * h * area / (mass * HEAT_CAPACITY)))
        checks.append(
            Check(
                name=f"coupling_interval_{n}_steps",
                measured=drop,
                expected=exact,
                error=relative_error(drop, exact),
                tolerance=HOLD_TOLERANCE,
                unit="K",
                note=f"{n} steps of {dt} s between air updates"
                + (" (the 'auto' choice)" if n == auto else "")
                + f"; drop differs from the continuous solution by {relative_error(drop, continuous):.2%}",
                reference="exact explicit hold: T_{k+1} = T_k + N dt h A (T_air - T_k) / (m cp)",
                # drumflow's own h and update scheme on both sides: bookkeeping (checks.py).
                kind="bookkeeping",
                wall_time_s=time.perf_counter() - t0,
                details={
                    "continuous_drop_K": continuous,
                    "error_against_continuous": relative_error(drop, continuous),
                    "auto": n == auto,
                },
            )
        )
        if n == auto:
            # What the 'auto' rule promises: the hold costs at most 0.1% of the cooling.
            checks.append(
                Check(
                    name="coupling_interval_auto_error",
                    measured=drop,
                    expected=continuous,
                    error=relative_error(drop, continuous),
                    tolerance=AUTO_TOLERANCE,
                    unit="K",
                    note=f"the 'auto' interval ({n} steps of {dt} s): drop at one time constant against "
                    "the continuous lumped solution",
                    reference="exact lumped cooling T_air + (T0 - T_air) exp(-t / tau)",
                    wall_time_s=checks[-1].wall_time_s,
                )
            )
    return checks


#: Particles of the settling checks: particle Re 50-500 in air, where Schiller-Naumann's
#: 24/Re (1 + 0.15 Re^0.687) governs (the drum's slip Re are ~500-1,500).
SETTLING_DIAMETERS = (0.0005, 0.0012)


def settling_check(work: Path, runner: Runner, diameter: float, density: float = DENSITY) -> Check:
    """Particle released in still air: C_d its terminal speed implies against the standard curve."""
    t0 = time.perf_counter()
    air = ReferenceAir.at(T_AIR, PRESSURE_KPA)
    v_ref = settling_velocity(diameter, density, air)
    # Drag grows faster than linearly with speed, so the approach is quicker than
    # exp(-g t / v_t): eight response times v_t / g leave < 3e-4 of v_t.
    dt = 1e-3
    steps = math.ceil(8.0 * v_ref / 9.81 / dt)
    table = run_single(
        work,
        runner,
        air_velocity=(0.0, 0.0, 0.0),
        gravity=True,
        held=False,
        dt=dt,
        steps=steps,
        interval=1,
        thermo_every=steps // 8,
        diameter=diameter,
        density=density,
    )
    v_sim = -float(table.iloc[-1]["vz"])
    v_before = -float(table.iloc[-2]["vz"])
    cd, re = drag_coefficient_from_settling(v_sim, diameter, density, air)
    cd_ref = standard_drag_coefficient(re)
    return Check(
        name=f"settling_drag_re{re:.0f}",
        measured=cd,
        expected=cd_ref,
        error=relative_error(cd, cd_ref),
        tolerance=DRAG_TOLERANCE,
        unit="-",
        note=f"{diameter * 1e3:g} mm sphere of {density:g} kg/m3 released in still air at 30 C, "
        f"{steps * dt:.2f} s, drag every step of {dt} s: settles at {v_sim:.4g} m/s "
        f"(standard curve: {v_ref:.4g} m/s), Re = {re:.0f}",
        reference="standard drag curve, Clift, Grace & Weber (1978) Table 5.2, CoolProp air",
        wall_time_s=time.perf_counter() - t0,
        details={
            "terminal_speed_m_s": v_sim,
            "speed_one_output_earlier_m_s": v_before,
            "standard_curve_speed_m_s": v_ref,
            "reynolds": re,
        },
    )
