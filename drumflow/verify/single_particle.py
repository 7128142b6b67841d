"""Single-particle verification of the air coupling against closed-form solutions.

* Lumped cooling: a particle held at rest in uniform air cools as
  T_air + (T0 - T_air) exp(-t / tau), tau = m cp / (h A), h from Ranz-Marshall at the constant
  slip. Checked at one time constant: the error of the temperature drop must stay below 0.5%.
* Terminal velocity: a particle released in still air reaches the speed where Schiller-Naumann
  drag balances its weight; checked within 1% after five response times.

Both run the real coupling loop (LIGGGHTS through its library) on a one-particle deck.
"""

from __future__ import annotations

import json
import math
import time
from pathlib import Path

import pandas as pd

from drumflow.coupling import driver_command
from drumflow.coupling.physics import AirState, lumped_temperature, ranz_marshall_h, terminal_velocity
from drumflow.dem.deck import render_deck
from drumflow.dem.thermo import ThermoParser
from drumflow.runner import Runner
from drumflow.verify.checks import Check, relative_error

#: The paper's NPK particle of model one.
DIAMETER = 0.008
DENSITY = 1050.0
HEAT_CAPACITY = 1465.38
CONDUCTIVITY = 0.18596
T_AIR = 30.0
T0 = 90.0


def _run_single(
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
) -> pd.DataFrame:
    """Run the one-particle scene through the coupling loop; return its thermo table."""
    work.mkdir(parents=True, exist_ok=True)
    deck = render_deck(
        {
            "diameter": DIAMETER, "density": DENSITY, "conductivity": CONDUCTIVITY,
            "heat_capacity": HEAT_CAPACITY, "dt": dt, "gravity": gravity, "T0": T0,
            "held": held, "thermo_every": thermo_every,
        },
        "single_particle.in.j2",
    )
    (work / "in.single").write_text(deck)
    spec = {
        "deck": "in.single", "log": "log.liggghts", "total_steps": steps, "interval": interval,
        "time_step": dt, "omega": 0.0, "air_temperature_C": T_AIR, "air_pressure_kPa": 101.325,
        "field": {"kind": "uniform", "velocity": list(air_velocity)},
        "coupling_log": "coupling/rank{rank}.{start}.csv", "tail": [],
    }
    (work / "coupling.json").write_text(json.dumps(spec))
    runner.run("coupling", driver_command(runner.profile, 1), work, work / "driver.out", timeout=600)
    columns = ("step", "time", "atoms", "vz", "T", "cpu")
    parser = ThermoParser(columns=columns)
    for line in (work / "log.liggghts").read_text().splitlines():
        parser(line)
    table = pd.DataFrame(parser.rows, columns=list(columns))
    return table.drop_duplicates("step", keep="last").reset_index(drop=True)


def lumped_cooling(work: Path, runner: Runner, interval: int = 10) -> Check:
    """Particle at rest in 1 m/s air: temperature drop at one time constant vs the exact one."""
    t0 = time.perf_counter()
    air = AirState.at(T_AIR)
    speed = 1.0
    h = float(ranz_marshall_h(speed, DIAMETER, air))
    mass = DENSITY * math.pi / 6 * DIAMETER**3
    area = math.pi * DIAMETER**2
    tau = mass * HEAT_CAPACITY / (h * area)
    dt = 0.01  # no contacts: only the heat update's accuracy matters (N dt / 2 tau ~ 0.1%)
    steps = math.ceil(tau / dt)
    table = _run_single(work, runner, air_velocity=(speed, 0.0, 0.0), gravity=False, held=True,
                        dt=dt, steps=steps, interval=interval, thermo_every=steps)
    last = table.iloc[-1]
    t_end = float(last["step"]) * dt
    exact = float(lumped_temperature(t_end, T0, T_AIR, h, mass, HEAT_CAPACITY, area))
    drop_sim, drop_exact = T0 - float(last["T"]), T0 - exact
    return Check(
        name="lumped_cooling_one_time_constant",
        measured=drop_sim, expected=drop_exact, error=relative_error(drop_sim, drop_exact),
        tolerance=0.005, unit="K",
        note=f"8 mm NPK at rest in 1 m/s air at 30 C, h = {h:.2f} W/m2K, tau = {tau:.1f} s, "
             f"coupling every {interval} steps of {dt} s",
        wall_time_s=time.perf_counter() - t0,
        details={"h_W_m2K": h, "tau_s": tau, "T_end_C": float(last["T"]), "T_exact_C": exact},
    )


def terminal_settling(work: Path, runner: Runner, interval: int = 1) -> Check:
    """Particle released in still air: its settling speed against the drag-weight balance."""
    t0 = time.perf_counter()
    air = AirState.at(T_AIR)
    v_t = terminal_velocity(DIAMETER, DENSITY, air)
    # With drag ~ v^2 the approach is v_t tanh(g t / v_t): five response times v_t / g leave
    # 2e-4 of v_t, well inside the 1% tolerance.
    dt = 1e-3
    t_end = 5.0 * v_t / 9.81
    steps = math.ceil(t_end / dt)
    table = _run_single(work, runner, air_velocity=(0.0, 0.0, 0.0), gravity=True, held=False,
                        dt=dt, steps=steps, interval=interval, thermo_every=steps)
    v_sim = -float(table.iloc[-1]["vz"])
    return Check(
        name="terminal_velocity_schiller_naumann",
        measured=v_sim, expected=v_t, error=relative_error(v_sim, v_t), tolerance=0.01,
        unit="m/s",
        note=f"8 mm NPK released in still air, {t_end:.1f} s simulated, drag updated every "
             f"{interval} step(s) of {dt} s",
        wall_time_s=time.perf_counter() - t0,
    )
