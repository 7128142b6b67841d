"""A synthetic run directory whose per-step h is known (the methodology, report and predict
tests' shared input).

The synthetic run has the smoke case's drum and particles, with air switched on. Its mean
temperature decays towards the air inlet temperature by the same factor ``r`` every step,
``T_k = T_ai + (T_0 - T_ai) r^k``, an exponential in time; the falling mass per step is
constant. The factor comes from the closed-form effectiveness-NTU solution of one
counter-current step with a chosen ``h``, which does not use the LMTD, so recovering ``h``
through Eqs. 34-39 is an independent check. Tests reach the writers through the fixtures of
``tests/unit/conftest.py``; the constants are imported from here.
"""

from __future__ import annotations

import json
import math
import tomllib
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from drumflow.case import case_from_dict, case_to_toml

ROOT = Path(__file__).resolve().parents[2]
SMOKE = ROOT / "cases" / "smoke.toml"

H_TRUE = 60.0  # W/(m2 K), the paper's model-one value
DT = 0.02  # s, the smoke case's dump_interval
N_STEPS = 150  # 3 s, the smoke case's run.time
T0 = 90.0  # deg C
FALLING_PARTICLES = 4  # particles crossing the axis plane per step (constant)
AIR_FLOW = 25.0  # kg/s, the paper's air flow (the plant air flow too)

# The CSV is written as `drumflow post` writes it, with 10 significant digits ("%.10g"), so
# each temperature near 30-90 deg C carries a rounding error of at most 5e-9 K. A step's drop is
# then off by at most 1e-8 K. The smallest drop here is about 0.03 K (see
# test_synthetic_drop_is_large_enough), so h per step is off by at most about 3.3e-7 relative
# (h is proportional to the drop, and the LMTD error is 1e-10 relative). 2e-6 is six times that
# bound. A wrong equation or a wrong falling mass (e.g. the settling steps' mass) moves h by
# percent.
H_RTOL = 2e-6
# Quantities taken from the CSV's falling masses and times carry its 10-digit rounding.
CSV_RTOL = 1e-9


# ----------------------------------------------------------------------- synthetic run dir


def synthetic_case_dict(**sections: dict[str, Any]) -> dict[str, Any]:
    """The smoke case with air (uniform, 25 kg/s); ``sections`` update whole sections."""
    with SMOKE.open("rb") as fh:
        d = tomllib.load(fh)
    d["air"].update(model="uniform", mass_flow=AIR_FLOW)
    for name, values in sections.items():
        d.setdefault(name, {}).update(values)
    return d


def step_decay_ratio(h: float, m_mf: float, dt: float, d: dict[str, Any]) -> float:
    """``(T_{k+1} - T_ai) / (T_k - T_ai)`` of one step with coefficient ``h`` (epsilon-NTU)."""
    p, a = d["particles"], d["air"]
    area = 6.0 * m_mf / (p["density"] * p["diameter"])  # surface of the falling spheres
    c_m = m_mf * p["heat_capacity"] / dt
    c_a = a["mass_flow"] * a.get("heat_capacity", 1005.0)
    c_min, c_max = min(c_m, c_a), max(c_m, c_a)
    ntu = h * area / c_min
    cr = c_min / c_max
    e = math.exp(-ntu * (1.0 - cr))
    eps = (1.0 - e) / (1.0 - cr * e)
    return 1.0 - eps * c_min / c_m  # share of (T - T_ai) left after the step


def _snapshot_text(step: int, n: int, radius: float, length: float, dp: float, seed: int) -> str:
    rng = np.random.default_rng(seed)
    r = (radius - dp) * np.sqrt(rng.uniform(0.0, 1.0, n))
    phi = rng.uniform(np.pi * 1.1, np.pi * 1.9, n)  # the bed lies in the lower half (y < 0)
    x, y = r * np.cos(phi), r * np.sin(phi)
    z = rng.uniform(dp / 2, length - dp / 2, n)
    temp = 80.0 + 10.0 * rng.uniform(0.0, 1.0, n)
    rows = "".join(
        f"{i + 1} {x[i]:.6g} {y[i]:.6g} {z[i]:.6g} 0 0 0 {dp / 2:g} {temp[i]:.6g} \n"
        for i in range(n)
    )
    return (
        f"ITEM: TIMESTEP\n{step}\nITEM: NUMBER OF ATOMS\n{n}\nITEM: BOX BOUNDS ff ff ff\n"
        f"{-radius} {radius}\n{-radius} {radius}\n0 {length}\n"
        f"ITEM: ATOMS id x y z vx vy vz radius f_Temp[0] \n{rows}"
    )


def write_synthetic_run(
    root: Path,
    *,
    h: float = H_TRUE,
    case_dict: dict[str, Any] | None = None,
    falling_particles: int | np.ndarray = FALLING_PARTICLES,
    early_falling_particles: int | None = None,
    constant_temperature: bool = False,
    extras: bool = True,
) -> Path:
    """Write a run directory like `drumflow run` does, with a known h.

    Parameters
    ----------
    root
        Directory to create.
    h
        Heat-transfer coefficient the temperature series is built from.
    case_dict
        Case as nested dicts (default :func:`synthetic_case_dict`).
    falling_particles
        Particles falling per step: a constant or one count per step (a step with 0 keeps the
        temperature, as Eq. 35 then gives no heat).
    early_falling_particles
        If given, the CSV reports this count for the steps before ``run.mass_flow_start`` while
        the temperatures still follow ``falling_particles`` (settling noise the paper excludes).
    constant_temperature
        Keep the mean temperature at T0 (a run without air).
    extras
        Also write crossings.csv, the PNG plots, a snapshot, manifest and summary.
    """
    from drumflow.analysis.observables import falling_mass_flow
    from drumflow.report.plots import plot_crossings, plot_mean_temperature

    d = case_dict or synthetic_case_dict()
    case = case_from_dict(d)
    m_p = case.particles.mass
    counts = np.broadcast_to(np.asarray(falling_particles), (N_STEPS,)).astype(int)
    times = np.arange(N_STEPS + 1) * DT
    t_ai = case.air.inlet_temperature_C
    temps = [T0]
    for k in range(N_STEPS):
        if constant_temperature or counts[k] == 0:
            temps.append(temps[-1])
        else:
            r = step_decay_ratio(h, counts[k] * m_p, DT, d)
            temps.append(t_ai + (temps[-1] - t_ai) * r)
    temps_arr = np.array(temps)
    reported = counts.astype(float)
    if early_falling_particles is not None:
        reported[times[:-1] < case.run.mass_flow_start - 1e-9] = early_falling_particles
    falling = np.r_[np.nan, reported * m_p]

    post = root / "post"
    post.mkdir(parents=True)
    (root / "case.toml").write_text(case_to_toml(case))
    # Same writer and format as drumflow.pipeline.post_run.
    np.savetxt(
        post / "mean_temperature.csv",
        np.column_stack([times, temps_arr, np.full(times.size, case.particle_count), falling]),
        delimiter=",",
        header="time_s,mean_temperature_C,particles,falling_mass_kg_in_step",
        comments="",
        fmt="%.10g",
    )
    if not extras:
        return root
    rng = np.random.default_rng(7)
    rows = []
    for k in range(N_STEPS):
        for j in range(int(reported[k])):
            rows.append((times[k] + (j + 0.5) * DT / max(reported[k], 1), 1000 * k + j,
                         rng.uniform(-0.15, 0.15), rng.uniform(0.0, case.drum.length)))
    crossings = pd.DataFrame(rows, columns=["time", "id", "x", "z"])
    crossings.to_csv(post / "crossings.csv", index=False, float_format="%.6g")
    flow = falling_mass_flow(crossings, m_p, start=case.run.mass_flow_start,
                             curtain_radius=case.drum.radius - case.lifters.base_height)
    plot_mean_temperature(times, temps_arr, post / "mean_temperature.png", f"{case.name} synthetic")
    plot_crossings(crossings, flow, case.drum.length, post / "crossings.png", f"{case.name} synthetic")
    time_step = 1.0e-5
    dumps = root / "dem" / "dumps"
    dumps.mkdir(parents=True)
    last = round(times[-1] / time_step)
    (dumps / f"snap.{last}.txt").write_text(
        _snapshot_text(last, 300, case.drum.radius, case.drum.length, case.particles.diameter, 3)
    )
    manifest = {
        "case": case.model_dump(mode="json"),
        "case_hash": case.hash(),
        "versions": {"python": "3.11", "liggghts": None, "openfoam": None,
                     "packages": {"numpy": np.__version__}},
        "commands": [{"program": "liggghts", "command": ["lmp", "-in", "in.drum"],
                      "returncode": 0, "wall_time_s": 12.5}],
        "stages": {"dem": {"key": "abc", "wall_time_s": 12.5}},
        "time_step": {"time_step": time_step, "rayleigh_time": 5e-5, "hertz_time": 4e-4,
                      "fraction_of_rayleigh": 0.2},
    }
    (root / "manifest.json").write_text(json.dumps(manifest, indent=2))
    summary = {
        "case": case.name,
        "particles_initial": case.particle_count,
        "particles_final": case.particle_count,
        "mean_temperature_C": float(temps_arr[-1]),
        "falling_mass_flow_kg_s": flow.mass_flow_kg_s,
        "curtain_mass_flow_kg_s": flow.curtain_mass_flow_kg_s,
        "wall_time_s": 12.5,
    }
    (root / "summary.json").write_text(json.dumps(summary, indent=2))
    return root


