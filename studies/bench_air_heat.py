"""Benchmark: one air update of air that warms (drumflow.air.heat), as it was and as it is.

One update of the coupling loop solves the air's temperature twice: with the particles'
conductance implicit (what the particles see), then with the heat they gave as a source (the
bookkeeping). Until 2026-11-29 both solves were BiCGSTAB preconditioned by an incomplete LU of
the transport alone, each from the inlet temperature ("before"); now the preconditioner is the
grid's lines along the air's flow with the particles' conductance in them, each solve starting
from the last one's field ("now"). Both arms are run here on the same systems, interleaved
A-B-A-B (three rounds of a sequence of updates each), on:

* the curtain scene's duct (Figure 4, parcels of 4 grains: ``duct_air``), with 22,000 parcels
  spread over the curtain (the slit's thickness widening downstream to 0.33 m at the floor, as
  the CFD-DEM run measured) falling 0.29 mm per update (1.5 m/s over 19 steps of 1e-5 s);
* optionally a drum's air field (``--field PATH`` of a run's ``air/field.npz``, at ``--spacing``
  m: the grid the loop would solve on) with a bed in its lower part (particles in the cells
  below 0.4 of the radius, conductance one to ten times the cells' own air capacity flow),
  moving 7.5 mm across the section per update (the shell's speed at 1.5 m, 0.01 s).

The particles are synthetic (placed, not simulated): the systems have the real grids and flows
and the parcels' film conductances, which is what the solver's cost depends on.

``--replay RUN`` adds a run's own air and particles (a run of air around the bed, whose grid is a
few cells long along the axis and whose bed the air goes around): the particles of its snapshots
(``dem/dumps/snap.*.npz``) with the loop's film (Ranz-Marshall at the slip to the run's air),
each snapshot followed by UPDATES updates in which the particles move on at their own velocity
(``interval`` steps of the run per update; their temperatures, which move by 0.1 % of their
excess per update, are held). The bookkeeping's
source is the heat the shells gave in the run, which is not the film's at the implicit solve's
air (the interior advances over the interval): it stands in here as the film's heat times a
factor drawn per particle in [0.95, 1.05] (a few per cent, as between the loop's two solves).
The arms: "one switch" (2026-11-29 to 11-30: a failure of the lines on either system moved both
to the incomplete LU for the rest of the run) against "per system" (now: each system keeps its
own), each from a fresh solver per snapshot.

Writes OUT.json (per arm and grid: median and range of the wall time per update, iterations per
update, the largest difference between the arms' fields) and prints it.

Usage: .venv/bin/python studies/bench_air_heat.py OUT.json [--field PATH --spacing M] [--replay RUN]
"""

from __future__ import annotations

import argparse
import json
import platform
import statistics
import time
from pathlib import Path
from typing import Any

import numpy as np

from drumflow.air.field import AirField
from drumflow.air.heat import AirHeat, coarse_field
from drumflow.physics.particle_air import AirState, ranz_marshall_h
from drumflow.rundir import cpu_model
from drumflow.validate.particle_curtain import curtain_scene, duct_air, load_experiment

UPDATES = 20  # updates per round and arm
ROUNDS = 3


Grid = tuple[AirField, float, np.ndarray, np.ndarray, np.ndarray, np.ndarray]


def _curtain(rng: np.random.Generator) -> Grid:
    case = load_experiment("curtain_fig4")
    scene = curtain_scene(case, 4.0)
    field = duct_air(scene)
    geo = case.geometry
    n = 22_000
    height = rng.uniform(0.0, geo.height, n)
    depth = 1.0 - height / geo.height  # 0 at the slit, 1 at the floor
    half = 0.5 * geo.thickness
    z = rng.uniform(-half, half, n) - 0.33 * depth * rng.uniform(0.0, 1.0, n)
    x = np.column_stack([rng.uniform(0.0, geo.width, n), height, z])
    air = AirState.at(case.gas.inlet_temperature_C, case.gas.pressure_kPa)
    d = scene.parcel_diameter / scene.coarse_grain
    g = ranz_marshall_h(np.full(n, 1.5), np.full(n, d), air) * np.pi * d**2 * scene.coarse_grain**3
    ends = sorted((case.gas.inlet_temperature_C, case.solids.inlet_temperature_C))
    temperature = rng.uniform(ends[0], ends[1], n)
    step = np.array([0.0, -1.5 * 19 * 1e-5, 0.0])
    return field, case.gas.inlet_temperature_C, x, g, temperature, step


def _drum(path: Path, spacing: float, rng: np.random.Generator) -> Grid:
    field = coarse_field(AirField.from_npz(path), spacing)
    probe = AirHeat(field, 30.0, 1.16, 1007.0)
    nodes = probe.nodes_xyz()
    radius = float(np.abs(nodes[:, :2]).max())
    bed = nodes[nodes[:, 1] < -0.4 * radius]
    per_cell = 20
    x = np.repeat(bed, per_cell, axis=0) + rng.uniform(-0.5, 0.5, (len(bed) * per_cell, 3)) * field.spacing
    capacity = 1.16 * 1007.0 * 3.0 * float(field.spacing[0] * field.spacing[1])
    g = rng.uniform(1.0, 10.0, len(x)) * capacity / per_cell
    temperature = rng.uniform(60.0, 90.0, len(x))
    # The bed moves with the shell, about 0.75 m/s at 1.5 m from the axis: 7.5 mm per 0.01 s update.
    return field, 30.0, x, g, temperature, np.array([0.0075, 0.0, 0.0])


def _updates(heat: AirHeat, x: np.ndarray, g: np.ndarray, temperature: np.ndarray,
             step: np.ndarray, before: bool) -> tuple[list[float], list[int], np.ndarray]:
    """UPDATES updates as the loop makes them; the wall time of each and its iterations."""
    if before:
        heat.preconditioner = {"particles": "incomplete LU", "transport": "incomplete LU"}
    walls, iterations = [], []
    field = np.zeros(heat.cells)
    for k in range(UPDATES):
        points = x + k * step
        t0 = time.perf_counter()
        if before:
            heat._last = None  # the old code started every solve from the inlet temperature
        cells = heat.cells_of(points)
        conductance = heat.deposit(cells, g)
        field = heat.solve_with_particles(conductance, heat.deposit(cells, g * temperature))
        first = heat.iterations
        if before:
            heat._last = None
        heat.solve(heat.deposit(cells, g * (temperature - field[cells])))
        walls.append(time.perf_counter() - t0)
        iterations.append(first + heat.iterations)
    return walls, iterations, field


def _arms_summary(arms: dict[str, dict[str, list[float]]]) -> dict[str, Any]:
    """Per arm the median and range of the wall time per update and the median iterations; the
    first arm's median over the second's."""
    out: dict[str, Any] = {}
    for arm, data in arms.items():
        out[arm] = {"median_update_s": statistics.median(data["wall"]),
                    "min_update_s": min(data["wall"]), "max_update_s": max(data["wall"]),
                    "median_iterations_per_update": statistics.median(data["iterations"])}
    first, second = list(arms)
    out["speedup_median"] = out[first]["median_update_s"] / out[second]["median_update_s"]
    return out


def bench(name: str, grid: Grid) -> dict[str, Any]:
    field, inlet, x, g, temperature, step = grid
    arms: dict[str, dict[str, list[float]]] = {"before": {"wall": [], "iterations": []},
                                               "now": {"wall": [], "iterations": []}}
    fields: dict[str, np.ndarray] = {}
    cells = 0
    for _ in range(ROUNDS):
        for arm in ("before", "now"):
            heat = AirHeat(field, inlet, 1.16, 1007.0)
            cells = heat.cells
            walls, iterations, fields[arm] = _updates(heat, x, g, temperature, step, arm == "before")
            arms[arm]["wall"] += walls
            arms[arm]["iterations"] += iterations
    out: dict[str, Any] = {"grid": name, "cells": int(cells),
                           "particles": len(x), "updates_per_round": UPDATES, "rounds": ROUNDS}
    out.update(_arms_summary(arms))
    out["largest_field_difference_K"] = float(np.abs(fields["before"] - fields["now"]).max())
    return out


def _replay_systems(run: Path) -> tuple[AirHeat, list[tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]],
                                         float]:
    """The run's grid of air that warms and, per snapshot, the particles' drum-frame positions,
    velocities, film conductances (W/K, per parcel) and temperatures; the seconds per update."""
    from drumflow.coupling.driver import load_field
    from drumflow.physics.drum_frame import rotate_to_drum_frame

    spec = json.loads((run / "dem" / "coupling.json").read_text())
    field = load_field(spec["field"])
    phases = getattr(field, "fields", None)
    grid = phases[0] if phases else field
    if not isinstance(grid, AirField):
        raise SystemExit(f"--replay {run}: its air is not on a grid")
    warm = spec["warming"]
    heat = AirHeat(coarse_field(grid, float(warm["spacing"])), float(spec["air_temperature_C"]),
                   float(warm["density"]), float(warm["heat_capacity"]))
    air = AirState.at(float(spec["air_temperature_C"]), float(spec["air_pressure_kPa"]))
    k = float(spec["coarse_grain"])
    dt = float(spec["time_step"])
    snaps = sorted((run / "dem" / "dumps").glob("snap.*.npz"))[2::3]  # a few, spread over the run
    systems = []
    for path in snaps:
        z = np.load(path)
        x = np.column_stack([z["c_x"], z["c_y"], z["c_z"]]).astype(float)
        v = np.column_stack([z["c_vx"], z["c_vy"], z["c_vz"]]).astype(float)
        d = 2.0 * z["c_radius"].astype(float) / k
        t = int(z["step"]) * dt
        u = field.sample_at(x, t) if phases else field.sample(x)
        g = ranz_marshall_h(np.linalg.norm(u - v, axis=1), d, air) * np.pi * d**2 * k**3
        angle = field.phase(t)[1] if phases else float(spec["omega"]) * t
        systems.append((rotate_to_drum_frame(x, angle), rotate_to_drum_frame(v, angle), g,
                        z["c_T"].astype(float)))
    return heat, systems, int(spec["interval"]) * dt


def bench_replay(run: Path) -> dict[str, Any]:
    """The two arms on the run's own systems, interleaved per snapshot."""
    heat0, systems, seconds = _replay_systems(run)
    rng = np.random.default_rng(11)
    arms: dict[str, dict[str, list[float]]] = {a: {"wall": [], "iterations": []}
                                               for a in ("one switch", "per system")}
    difference = 0.0
    for x, v, g, temperature in systems:
        factors = rng.uniform(0.95, 1.05, (UPDATES, len(g)))
        fields = {}
        for arm in arms:
            heat = AirHeat(heat0.field, heat0.inlet_temperature_C, heat0.rho_cp, 1.0)
            for k in range(UPDATES):
                t0 = time.perf_counter()
                if arm == "one switch" and "incomplete LU" in heat.preconditioner.values():
                    heat.preconditioner = {"particles": "incomplete LU", "transport": "incomplete LU"}
                cells = heat.cells_of(x + k * seconds * v)
                air = heat.solve_with_particles(heat.deposit(cells, g), heat.deposit(cells, g * temperature))
                first = heat.iterations
                given = g * (temperature - air[cells]) * factors[k]
                fields[arm] = heat.solve(heat.deposit(cells, given))
                arms[arm]["wall"].append(time.perf_counter() - t0)
                arms[arm]["iterations"].append(first + heat.iterations)
        difference = max(difference, float(np.abs(fields["one switch"] - fields["per system"]).max()))
    out: dict[str, Any] = {"grid": f"replay of {run}", "cells": heat0.cells,
                           "particles": len(systems[0][2]), "snapshots": len(systems),
                           "updates_per_snapshot": UPDATES}
    out.update(_arms_summary(arms))
    out["largest_field_difference_K"] = difference
    return out


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("out", type=Path)
    parser.add_argument("--field", type=Path)
    parser.add_argument("--spacing", type=float, default=0.053)
    parser.add_argument("--replay", type=Path, help="a run of air that warms (its dem/ and snapshots)")
    args = parser.parse_args()
    rng = np.random.default_rng(7)
    results = [bench("curtain_fig4 duct, parcels of 4 grains", _curtain(rng))]
    if args.field is not None:
        drum = _drum(args.field, args.spacing, rng)
        results.append(bench(f"drum field {args.field} at {args.spacing} m", drum))
    if args.replay is not None:
        results.append(bench_replay(args.replay))
    record = {"what": "one air update of air that warms (two solves), before and now, interleaved",
              "machine": {"cpu": cpu_model(), "platform": platform.platform()},
              "note": "idle machine required: the arms are interleaved, but a busy core moves both",
              "results": results}
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text(json.dumps(record, indent=1) + "\n")
    print(json.dumps(record, indent=1))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
