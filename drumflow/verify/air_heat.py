"""Air that warms through the real coupling loop, against the epsilon-NTU solution.

A column of held particles fills a square duct in plug flow (``air.warming``): every cell of the
air's grid holds one 2 mm particle at 90 C, with a heat capacity so large that the particles
stay at 90 C over the scene, and air enters at 30 C. The air warms along the duct as a stream
passing a surface at constant temperature: an exchanger with a capacity ratio of zero, whose
effectiveness is epsilon = 1 - exp(-NTU), NTU = (sum of the particles' h A) / (m_dot c_p)
(Incropera et al., 7th ed., Eq. 11.35a). The air's outlet temperature in the loop's air log is
compared with T_in + epsilon (T_p - T_in).

h is drumflow's own Ranz-Marshall value at the particles' slip (the correlation has its own
check); the subject here is the air's side: the flux projection, the upwind transport, the
deposition of each particle's heat into its cell and the air temperature it sees back. The
grid's cells along the duct (101) make the discrete exchanger differ from the continuous one by
NTU^2 / (2 N) on the exponent: 0.3 % of the temperature rise at NTU 1.1, inside the 1 %
tolerance, while a 10 % error in the heat the particles give moves the rise by 6 %.
"""

from __future__ import annotations

import math
import time
from pathlib import Path

import numpy as np
import pandas as pd

from drumflow.air.field import AirField
from drumflow.physics.air import ideal_gas_density
from drumflow.physics.particle_air import AirState, ranz_marshall_h
from drumflow.physics.validation import relative_error
from drumflow.runner import Runner
from drumflow.verify.checks import Check
from drumflow.verify.single_particle import PRESSURE_KPA, T0, T_AIR, run_single

#: The duct: nodes across (x, y), spacing across, nodes along and their spacing, m.
ACROSS, ACROSS_SPACING = 4, 0.01
ALONG, ALONG_SPACING = 101, 0.003
#: The particles and the air.
DIAMETER = 0.002
DENSITY = 1050.0
#: Large enough that a particle's temperature moves by under 1e-4 of its excess over the scene.
HEAT_CAPACITY = 1.0e7
AIR_SPEED = 1.0
AIR_HEAT_CAPACITY = 1007.0
#: Tolerance on the outlet's temperature rise (the discretisation's 0.3 %, three times over).
TOLERANCE = 0.01
DURATION_S = 0.05


def duct_field() -> AirField:
    """Plug flow towards -z through a square duct, every node fluid."""
    shape = (ACROSS, ACROSS, ALONG)
    velocity = np.zeros((*shape, 3))
    velocity[..., 2] = -AIR_SPEED
    spacing = np.array([ACROSS_SPACING, ACROSS_SPACING, ALONG_SPACING])
    return AirField(origin=np.zeros(3), spacing=spacing, velocity=velocity, pressure=np.zeros(shape),
                    fluid=np.ones(shape, dtype=bool), omega=0.0, meta={"model": "duct"})


def expected_rise(h_factor: float = 1.0) -> tuple[float, float]:
    """(NTU, the air's temperature rise) of the epsilon-NTU solution, h times ``h_factor``."""
    air = AirState.at(T_AIR, PRESSURE_KPA)
    h = float(ranz_marshall_h(AIR_SPEED, DIAMETER, air)) * h_factor
    particles = ACROSS * ACROSS * ALONG
    rho = ideal_gas_density(T_AIR, PRESSURE_KPA)
    # The duct's flow: every column of cells carries its face's share (the grid's end faces).
    flow = AIR_SPEED * ACROSS_SPACING**2 * ACROSS * ACROSS
    ntu = particles * h * math.pi * DIAMETER**2 / (rho * AIR_HEAT_CAPACITY * flow)
    return ntu, (T0 - T_AIR) * (1.0 - math.exp(-ntu))


def air_heat_check(work: Path, runner: Runner, h_factor: float = 1.0) -> Check:
    """The duct's outlet temperature rise against epsilon-NTU.

    ``h_factor`` scales the h of the reference (1: the law the loop applies; 1.1 or 0.9: the
    check must then fail, which the tests show).
    """
    t0 = time.perf_counter()
    work.mkdir(parents=True, exist_ok=True)
    field = duct_field()
    field.to_npz(work / "duct.npz")
    axes = field.axes()
    positions = [(float(x), float(y), float(z)) for x in axes[0] for y in axes[1] for z in axes[2]]
    dt = 1e-3
    steps = round(DURATION_S / dt)
    box = [-0.005, ACROSS_SPACING * (ACROSS - 1) + 0.005, -0.005, ACROSS_SPACING * (ACROSS - 1) + 0.005,
           -0.005, ALONG_SPACING * (ALONG - 1) + 0.005]
    run_single(work, runner, air_velocity=(0.0, 0.0, -AIR_SPEED), gravity=False, held=True, dt=dt,
               steps=steps, interval=10, thermo_every=steps, diameter=DIAMETER, density=DENSITY,
               heat_capacity=HEAT_CAPACITY,
               deck_extra={"positions": positions, "box": box},
               spec_extra={"field": {"kind": "grid", "path": str(work / "duct.npz")},
                           "warming": {"density": ideal_gas_density(T_AIR, PRESSURE_KPA),
                                       "heat_capacity": AIR_HEAT_CAPACITY}})
    log = pd.read_csv(next((work / "coupling").glob("air.*.csv")))
    last = log.iloc[-1]
    rise = float(last["outlet_C"]) - T_AIR
    ntu, exact = expected_rise(h_factor)
    return Check(
        name="air_warming_epsilon_ntu" + ("" if h_factor == 1.0 else f"_h_x{h_factor:g}"),
        measured=rise,
        expected=exact,
        error=relative_error(rise, exact),
        tolerance=TOLERANCE,
        unit="K",
        note=(f"{ACROSS * ACROSS * ALONG} held {DIAMETER * 1e3:g} mm particles at {T0:g} C, one in each "
              f"cell of a {ACROSS}x{ACROSS}x{ALONG} grid, plug flow at {AIR_SPEED:g} m/s from {T_AIR:g} C "
              f"(NTU = {ntu:.3f}); the air's outlet temperature through the coupling loop with "
              "air.warming"),
        reference="epsilon = 1 - exp(-NTU), a stream past a surface at constant temperature "
                  "(Incropera et al. 2011, Eq. 11.35a)",
        wall_time_s=time.perf_counter() - t0,
        details={"ntu": ntu, "outlet_C": float(last["outlet_C"]), "h_factor": h_factor,
                 "air_enthalpy_gain_W": float(last["air_enthalpy_gain_W"]),
                 "heat_to_air_W": float(last["heat_to_air_W"]),
                 # The heat taken over the heat with inlet air at every particle: epsilon / NTU
                 # for a stream past a surface at one temperature.
                 "contact_efficiency": float(last["heat_to_air_W"]) / float(last["heat_if_fresh_W"]),
                 "contact_efficiency_exact": (1.0 - math.exp(-ntu)) / ntu},
    )
