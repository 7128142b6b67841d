"""Heat inside the granule through the real coupling loop, against the exact series solution.

One 8 mm NPK granule held at rest in uniform air at 30 C (1 m/s), starting uniform at 90 C, with
``particles.interior = "shells"``: LIGGGHTS integrates its temperature from the heat the loop
hands it, and the loop advances the granule's shells with the film on its surface. Its mean
temperature drop is compared with the exact series solution of a sphere in a fluid at constant h
(Carslaw and Jaeger 1959, sec. 9.4), at Biot numbers 0.1, 1 and 3. The conductivity sets the
Biot number at the air's h, so the flow, the film coefficient and the scene stay the same.

h is drumflow's own Ranz-Marshall value at the particle's slip: its correlation is checked
apart (:func:`drumflow.verify.single_particle.convective_h_check`); here the subject is the
interior and its coupling (the surface temperature driving the film, the heat handed to
LIGGGHTS, the energy the particle keeps).
"""

from __future__ import annotations

import math
import time
from pathlib import Path

import pandas as pd

from drumflow.coupling.interior import InteriorSpec
from drumflow.physics.particle_air import AirState, ranz_marshall_h
from drumflow.physics.particle_interior import (
    Sphere,
    series_mean_temperature,
    shell_drop_error,
    shells_for_biot,
)
from drumflow.physics.validation import relative_error
from drumflow.runner import Runner
from drumflow.verify.checks import Check
from drumflow.verify.single_particle import (
    DENSITY,
    DIAMETER,
    HEAT_CAPACITY,
    PRESSURE_KPA,
    T0,
    T_AIR,
    run_single,
)

#: The held granule is the paper's NPK granule of model one (single_particle's), in 1 m/s air;
#: its conductivity is what the check varies.
AIR_SPEED = 1.0
#: The issue's tolerance on the temperature drop. The shells are chosen to err by at most
#: 0.125 % (:data:`~drumflow.physics.particle_interior.SHELL_TOLERANCE`); Crank-Nicolson in
#: time at a tenth of a second adds < 0.01 %; the thermo print carries 12 digits.
TOLERANCE = 0.005
#: Biot numbers of the check: near lumped, the paper's 8 mm granule (1.7), the 20 mm one (2.6).
BIOTS = (0.1, 1.0, 3.0)
#: Fraction of the initial excess the series solution has removed when the scene stops.
DROP_FRACTION = 1.0 - math.exp(-1.0)


def film_coefficient() -> float:
    """The loop's h for the held granule (Ranz-Marshall at the air speed), W/(m^2 K)."""
    return float(ranz_marshall_h(AIR_SPEED, DIAMETER, AirState.at(T_AIR, PRESSURE_KPA)))


def granule(biot: float) -> Sphere:
    """The granule whose conductivity gives ``biot`` at the loop's h."""
    return Sphere(DIAMETER, film_coefficient() * 0.5 * DIAMETER / biot, DENSITY, HEAT_CAPACITY)


def stop_time(sphere: Sphere, h: float) -> float:
    """When the series solution has removed :data:`DROP_FRACTION` of the excess, s."""
    from scipy.optimize import brentq

    def left(t: float) -> float:
        done = (T0 - float(series_mean_temperature(sphere, h, T0, T_AIR, t)[0])) / (T0 - T_AIR)
        return done - DROP_FRACTION

    hi = 10.0
    while left(hi) < 0:
        hi *= 2.0
    return float(brentq(left, 1e-6, hi, xtol=1e-9))


def run_held_granule(work: Path, runner: Runner, sphere: Sphere, shells: int, duration: float,
                     loop_conductivity: float | None = None, dt: float = 0.01,
                     interval: int = 10) -> tuple[float, float]:
    """Hold the granule in the air for ``duration`` through the coupling loop with shells.

    ``loop_conductivity`` replaces the conductivity the loop's shells use (a wrong law, for the
    test that the check can fail); the reference keeps ``sphere``'s. Returns (simulated time,
    mean temperature at its end).
    """
    steps = math.ceil(duration / dt)
    k = sphere.conductivity if loop_conductivity is None else loop_conductivity
    table = run_single(work, runner, air_velocity=(AIR_SPEED, 0.0, 0.0), gravity=False, held=True,
                       dt=dt, steps=steps, interval=interval, thermo_every=steps,
                       diameter=sphere.diameter, density=sphere.density,
                       conductivity=sphere.conductivity,
                       interior=InteriorSpec(shells, k, sphere.density, sphere.heat_capacity))
    last = table.iloc[-1]
    return float(last["step"]) * dt, float(last["T"])


def interior_series_check(work: Path, runner: Runner, biot: float,
                          loop_conductivity_factor: float = 1.0) -> Check:
    """The held granule's mean-temperature drop at ``biot`` against the series solution.

    ``loop_conductivity_factor`` scales the conductivity the loop uses (1: the true law).
    """
    t0 = time.perf_counter()
    sphere = granule(biot)
    h = film_coefficient()
    shells = shells_for_biot(biot)
    duration = stop_time(sphere, h)
    t_end, T_end = run_held_granule(work, runner, sphere, shells, duration,
                                    loop_conductivity=sphere.conductivity * loop_conductivity_factor)
    exact = T0 - float(series_mean_temperature(sphere, h, T0, T_AIR, t_end)[0])
    drop = T0 - T_end
    # Interior-loop log: the surface-to-centre difference at the last update.
    logs = sorted((work / "coupling").glob("interior_rank*.csv"))
    last = pd.read_csv(logs[-1]).iloc[-1] if logs else None
    return Check(
        name=f"interior_series_bi{biot:g}",
        measured=drop,
        expected=exact,
        error=relative_error(drop, exact),
        tolerance=TOLERANCE,
        unit="K",
        note=(f"8 mm granule, k = {sphere.conductivity:.4g} W/(m K), held in {AIR_SPEED:g} m/s air at "
              f"{T_AIR:g} C (h = {h:.2f} W/(m2 K), Bi = {biot:g}) for {t_end:.1f} s with {shells} shells "
              f"(their own error {shell_drop_error(biot, shells):.2%}), through the coupling loop"),
        reference="exact series solution of a sphere at constant h (Carslaw & Jaeger 1959, sec. 9.4)",
        wall_time_s=time.perf_counter() - t0,
        details={
            "biot": biot,
            "shells": shells,
            "conductivity_W_mK": sphere.conductivity,
            "loop_conductivity_factor": loop_conductivity_factor,
            "h_W_m2K": h,
            "simulated_s": t_end,
            "T_end_C": T_end,
            "centre_minus_surface_K": None if last is None else float(last["max_centre_minus_surface_K"]),
        },
    )
