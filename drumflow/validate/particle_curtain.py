"""The falling curtain in a duct (Wardjiman and Rhodes 2009, Figures 3-8) as a CFD-DEM scene.

Sand of 204 um leaves a slit across the whole width of a horizontal duct (0.15 m wide, 0.6 m
high) at 1.3-1.4 m/s and falls through warm air crossing it horizontally at 0.9-1.2 m/s. The
reduced-order curtain model (:mod:`drumflow.coolers.curtain`, ``cases/curtain_fig*.toml``)
holds the fall velocity constant and the curtain vertical; here the same experiments are run
through the slice's own chain: LIGGGHTS moves the grains (fed by ``insert/rate/region`` at the
slit's mass flow and exit speed, taken out at the duct floor by the coupling loop's outlet,
:mod:`drumflow.coupling.outlet`), the coupling loop gives each the Schiller-Naumann drag and the
Ranz-Marshall heat of the air at its place (:mod:`drumflow.coupling.driver`), and the air warms
(``air.warming``, :mod:`drumflow.air.heat`): it crosses the duct in plug flow and each cell
gives the grains in it what it has. The grains fall under gravity and drag (the air pushes the
curtain downstream), so the fall velocity and the curtain's place are results, not inputs.

Frame: the coupling loop's, gravity along -y, the air along -z (towards the outlet at the
smallest z), the duct's width along x (periodic: the curtain spans the width, and the side
walls are left out). Parcels of ``k`` grains (``particles.coarse_grain``'s scaling: drag and
heat of one grain at the parcel's velocity and temperature, times ``k**3``) keep the count in
flight small; the error of that scaling is measured by the ``finer`` scale on one experiment.

What is compared: the heat duty (solids side from the outlet's enthalpy flux; the gas side from
the air's enthalpy), the solids and gas outlet temperatures, the solids' speed and drift at the
duct floor, for each experiment, beside the reduced-order model's with the same air properties
(drumflow's air table at the gas inlet temperature). The measured points of the paper's figures
are not in drumflow's copy of the paper, and its Table 3 (measured duties) is withheld, so the
experiment itself is not in the table: two independent methods for the same experiments.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
import pandas as pd

from drumflow.coupling.outlet import read_outlet_log
from drumflow.validate.errors import ValidationDataError
from drumflow.validate.rolling_drum import SetupChoice

if TYPE_CHECKING:
    from drumflow.coolers.curtain import CurtainCase
    from drumflow.dem.stage import ProgressCallback
    from drumflow.runner import Runner

__all__ = ["EXPERIMENTS", "SCALES", "SETUP", "CurtainScene", "curtain_scene", "duct_air",
           "load_experiment", "run_particle_curtain", "summarise_run"]

#: The paper's six experiments: the reduced-order model's case files (``cases/``).
EXPERIMENTS: tuple[str, ...] = tuple(f"curtain_fig{i}" for i in range(3, 9))
#: 'parcels': every experiment at k = 4 (the comparison); 'short': Figure 3 for 0.5 s (CI: the
#: chain starts and its bookkeeping closes); 'finer': Figure 3 at k = 2.5 (the parcels' error).
SCALES: tuple[str, ...] = ("parcels", "short", "finer")
COARSE_GRAIN = {"parcels": 4.0, "short": 4.0, "finer": 2.5}

#: Set-up values (SI) the paper leaves open, fixed here before any comparison.
YOUNGS_MODULUS = 5.0e6       # Pa: softened sand, the smallest LIGGGHTS takes without soft_particles
POISSON_RATIO = 0.3
RESTITUTION = 0.6
FRICTION = 0.5
UPSTREAM = 0.05              # m of air between the inlet and the curtain's upstream face
DOWNSTREAM = 0.5             # m of air downstream of the slit: the air carries a grain 0.25-0.35 m
AIR_CELL = 0.005             # m: the air's cells along the air and the height
FEED_EVERY = 0.002           # s between two insertions at the slit
SNAPSHOT_EVERY = 0.02        # s between particle snapshots (the profiles over the height)
AVERAGING = 0.25             # s of steady state averaged
SHORT_TIME = 0.5             # s simulated by the 'short' scale: the first grains reach the floor
NEIGHBOUR_SKIN = 0.004       # m: a parcel at 4 m/s crosses half of it in 50 steps of 1e-5 s
NEIGHBOUR_BIN = 0.01         # m

#: Where the reduced-order model's case files are (the repository's ``cases/``).
CASES_DIR = Path(__file__).resolve().parents[2] / "cases"

SETUP: tuple[SetupChoice, ...] = (
    SetupChoice("duct, curtain, sand, flows, inlet temperatures",
                "as cases/curtain_fig3-8.toml (0.15 m x 0.6 m duct, 204 um sand 2640 kg/m³, "
                "753.1 J/(kg K))", "Wardjiman and Rhodes 2009, Section 2, Table 1, figure captions"),
    SetupChoice("feeder exit speed", "solids.fall_velocity of the case (1.35 m/s; 1.3 m/s for "
                "the 10 cm curtain), straight down; the grains then fall under gravity and drag",
                "the paper's 1.3-1.4 m/s feeder exit speeds (high-speed camera)"),
    SetupChoice("air", "plug flow at the case's gas velocity along the duct, warmed by the grains "
                "(air.warming); properties of drumflow's air table at the gas inlet temperature; "
                "no drag of the grains on the air (one-way momentum)",
                "the paper's uniform profile (flow straightener); the solids carry 0.3-0.45 of "
                "the air's mass flow, so two-way momentum would slow the air in the curtain: left "
                "out, stated"),
    SetupChoice("grain-air laws", "Schiller-Naumann drag and Ranz-Marshall heat of one 204 um "
                "grain at its own slip, lumped (Biot 0.16)", "drumflow's slice laws; the curtain's "
                "voidage is above 0.99, so no voidage closure"),
    SetupChoice("contacts", f"Hertz-Mindlin, E = {YOUNGS_MODULUS:g} Pa, nu = {POISSON_RATIO}, "
                f"restitution {RESTITUTION}, friction {FRICTION}; no conduction between grains",
                "not in the paper; a curtain of solids fraction 0.002 barely collides"),
    SetupChoice("side walls", "left out: x periodic across the 0.15 m width",
                "the curtain spans the width (paper, Section 2)"),
    SetupChoice("parcels", "k = 4 grains of diameter (64 grains per parcel) for the comparison; "
                "k = 2.5 on Figure 3 for the scaling's error",
                "drumflow's coarse-graining of the drum runs (particles.coarse_grain)"),
    SetupChoice("averaging", f"the outlet and the air over {AVERAGING} s after 1.2 fall times "
                "(the fall time bounded by the height over the smaller of the exit speed and "
                "the terminal speed)", "drumflow's choice, fixed before any run"),
)


def load_experiment(name: str, cases_dir: Path | None = None) -> CurtainCase:
    """The reduced-order model's case of experiment ``name`` (``curtain_fig3`` ... ``8``).

    Raises
    ------
    ValidationDataError
        Not one of :data:`EXPERIMENTS`, or its case file is missing.
    """
    from drumflow.case import read_toml, validate_model
    from drumflow.coolers.curtain import CurtainCase

    if name not in EXPERIMENTS:
        raise ValidationDataError(f"curtain experiment {name!r}: unknown; allowed: {', '.join(EXPERIMENTS)}")
    path = (cases_dir or CASES_DIR) / f"{name}.toml"
    if not path.is_file():
        raise ValidationDataError(f"{path}: the case file of experiment {name} is missing (the "
                                  "scene reads the reduced-order model's cases from the checkout)")
    return validate_model(CurtainCase, read_toml(path), path)


@dataclass(frozen=True)
class CurtainScene:
    """One experiment as a DEM scene: the duct in the loop's frame and the step plan.

    Lengths in m, times in s; ``z_low``/``z_high`` bound the air's path (the inlet at
    ``z_high``), the slit spans ``slit`` along z; steps are DEM steps.
    """

    case: CurtainCase
    coarse_grain: float
    parcel_diameter: float
    time_step: float
    interval: int
    thermo_every: int
    feed_every: int
    snapshot_every: int
    total_steps: int
    window: tuple[float, float]
    z_low: float
    z_high: float
    slit: tuple[float, float]
    fall_time_bound: float


def curtain_scene(case: CurtainCase, coarse_grain: float, end_time: float | None = None) -> CurtainScene:
    """The scene of ``case`` with parcels of ``coarse_grain`` grains' diameter, run to
    ``end_time`` (default: the fall-time bound times 1.2 plus :data:`AVERAGING`).

    The time step resolves a parcel collision (a tenth of the Hertz contact time at 1 m/s) and
    stays below a fifth of the Rayleigh time; the air update interval is the slice's 'auto'
    rule for the real grain (:func:`~drumflow.physics.particle_air.auto_coupling_interval`).
    """
    from drumflow.dem.timestep import hertz_contact_time, rayleigh_time
    from drumflow.physics.particle_air import AirState, auto_coupling_interval, terminal_velocity

    s, g = case.solids, case.gas
    d = s.diameter * coarse_grain
    dt = min(0.1 * hertz_contact_time(0.5 * d, s.density, YOUNGS_MODULUS, POISSON_RATIO, 1.0),
             0.2 * rayleigh_time(0.5 * d, s.density, YOUNGS_MODULUS, POISSON_RATIO))
    dt = float(f"{dt:.2g}")
    air = AirState.at(g.inlet_temperature_C, g.pressure_kPa)
    feed_every = max(1, round(FEED_EVERY / dt))
    # Snapshots on whole feeds, and a thermo row (on which the loop ends its updates) at every
    # feed: a common divisor of two independently rounded step counts could be 1.
    snapshot_every = feed_every * max(1, round(SNAPSHOT_EVERY / FEED_EVERY))
    thermo_every = feed_every
    settling = terminal_velocity(s.diameter, s.density, air)
    slowest = min(s.fall_velocity, settling)
    fall = case.geometry.height / slowest
    end = end_time if end_time is not None else 1.2 * fall + AVERAGING
    total = round(end / dt)
    # The largest slip: the air's speed plus the faster of the exit and the settling speed (a
    # grain approaches the settling speed from its exit speed).
    interval = auto_coupling_interval(dt, s.diameter, s.density, s.heat_capacity, air,
                                      g.velocity + max(s.fall_velocity, settling), cap=thermo_every)
    half = 0.5 * case.geometry.thickness
    return CurtainScene(case=case, coarse_grain=coarse_grain, parcel_diameter=d, time_step=dt,
                        interval=interval, thermo_every=thermo_every, feed_every=feed_every,
                        snapshot_every=snapshot_every, total_steps=total,
                        window=(min(1.2 * fall, 0.8 * end), end), z_low=-half - DOWNSTREAM,
                        z_high=half + UPSTREAM, slit=(-half, half), fall_time_bound=fall)


def duct_air(scene: CurtainScene) -> Any:
    """Plug flow along -z through the duct: cells of :data:`AIR_CELL` centred in it (two across
    the periodic width), so that the grid's cells tile the duct exactly and the air's volume flow
    is the duct's (width x height x velocity)."""
    from drumflow.air.field import AirField

    geo = scene.case.geometry
    across = 2
    ny = max(2, round(geo.height / AIR_CELL))
    nz = max(2, round((scene.z_high - scene.z_low) / AIR_CELL))
    spacing = np.array([geo.width / across, geo.height / ny, (scene.z_high - scene.z_low) / nz])
    origin = np.array([0.0, 0.0, scene.z_low]) + 0.5 * spacing
    shape = (across, ny, nz)
    velocity = np.zeros((*shape, 3))
    velocity[..., 2] = -scene.case.gas.velocity
    return AirField(origin=origin, spacing=spacing, velocity=velocity, pressure=np.zeros(shape),
                    fluid=np.ones(shape, dtype=bool), omega=0.0, meta={"model": "curtain duct"})


def deck_context(scene: CurtainScene) -> dict[str, Any]:
    """The values of ``templates/curtain_duct.in.j2``."""
    case, s, geo = scene.case, scene.case.solids, scene.case.geometry
    exit_speed = s.fall_velocity
    return {
        "name": case.name, "width": geo.width, "height": geo.height,
        # A margin below the outlet no parcel falls through in one update (at 10 m/s).
        "y_low": -max(0.05, 10.0 * scene.interval * scene.time_step),
        "y_high": geo.height + 2 * scene.parcel_diameter,
        "z_low": scene.z_low, "z_high": scene.z_high,
        "skin": NEIGHBOUR_SKIN, "binsize": NEIGHBOUR_BIN,
        "soft_particles": YOUNGS_MODULUS < 5.0e6,
        "youngs_modulus": YOUNGS_MODULUS, "poisson_ratio": POISSON_RATIO,
        "restitution": RESTITUTION, "friction": FRICTION,
        "conductivity": s.conductivity, "heat_capacity": s.heat_capacity,
        "dt": scene.time_step, "solids_inlet_C": s.inlet_temperature_C,
        "density": s.density, "radius": 0.5 * scene.parcel_diameter,
        # The layer the parcels of one insertion fill at the exit speed (at least two parcels
        # deep, so that every parcel fits in it).
        "feed_low": geo.height - max(exit_speed * scene.feed_every * scene.time_step,
                                     2.0 * scene.parcel_diameter),
        "slit_low": scene.slit[0], "slit_high": scene.slit[1],
        "mass_flow": s.mass_flow, "insert_every": scene.feed_every, "exit_speed": exit_speed,
        "snapshot_every": scene.snapshot_every, "snapshot_pattern": "dumps/snap.*.txt",
        "thermo_every": scene.thermo_every,
    }


def driver_spec(scene: CurtainScene, field_name: str = "air.npz") -> dict[str, Any]:
    """The coupling loop's input: warming air on the duct's grid (``field_name``, relative to the
    working directory, so a moved run directory keeps its input), the loop integrating the
    grains' temperatures (no heat fix), the outlet at the duct floor."""
    from drumflow.coupling.spec import COUPLING_LOG_PATTERN, loop_heat_options
    from drumflow.physics.air import ideal_gas_density, specific_heat

    g, s = scene.case.gas, scene.case.solids
    return {
        "deck": "in.curtain", "log": "log.liggghts", "total_steps": scene.total_steps,
        "interval": scene.interval, "time_step": scene.time_step, "omega": 0.0,
        "air_temperature_C": g.inlet_temperature_C, "air_pressure_kPa": g.pressure_kPa,
        "field": {"kind": "grid", "path": field_name},
        "coupling_log": COUPLING_LOG_PATTERN, "tail": [],
        "coarse_grain": scene.coarse_grain,
        **loop_heat_options(s.heat_capacity, scene.thermo_every),
        "interior": None,
        "warming": {"density": ideal_gas_density(g.inlet_temperature_C, g.pressure_kPa),
                    "heat_capacity": float(specific_heat(g.inlet_temperature_C))},
        "outlet": {"region": "outlet", "level": 0.0},
    }


#: Written into a scene's directory when its loop finished: the loop's input and the wall time.
DONE_RECORD = "done.json"


def run_scene(scene: CurtainScene, work: Path, runner: Runner, timeout: float | None = None) -> float:
    """Write the deck, the air and the loop's input into ``work`` and run the coupling loop;
    return its wall time, s. A directory whose loop already finished with the same input is
    not run again (its recorded wall time is returned)."""
    import json

    from drumflow.coupling.spec import driver_command
    from drumflow.dem.deck import render_deck

    work.mkdir(parents=True, exist_ok=True)
    deck = render_deck(deck_context(scene), "curtain_duct.in.j2")
    field_path = work / "air.npz"
    spec = json.dumps(driver_spec(scene, field_path.name), indent=1)
    done = work / DONE_RECORD
    if done.is_file():
        record = json.loads(done.read_text())
        if record.get("spec") == spec and record.get("deck") == deck:
            return float(record["wall_time_s"])
    # A fresh start: the logs of an earlier attempt would be read as this one's.
    for old in [*work.glob("coupling/*.csv"), *work.glob("dumps/*.txt"), done]:
        old.unlink(missing_ok=True)
    (work / "dumps").mkdir(exist_ok=True)
    (work / "in.curtain").write_text(deck)
    duct_air(scene).to_npz(field_path)
    (work / "coupling.json").write_text(spec)
    started = time.perf_counter()
    runner.run("coupling", driver_command(runner.profile, 1), work, work / "driver.out", timeout=timeout)
    wall = time.perf_counter() - started
    done.write_text(json.dumps({"spec": spec, "deck": deck, "wall_time_s": wall}))
    return wall


def _one(work: Path, pattern: str) -> Path:
    files = sorted(work.glob(pattern))
    if len(files) != 1:
        raise ValidationDataError(f"{work}: expected one {pattern}, found {len(files)} (a run "
                                  "that was interrupted and resumed is not read here)")
    return files[0]


def _snapshots(work: Path, scene: CurtainScene) -> pd.DataFrame:
    """The parcels of every snapshot in the averaging window, one table."""
    frames = []
    for path in sorted((work / "dumps").glob("snap.*.txt")):
        t = int(path.name.split(".")[1]) * scene.time_step
        if t < scene.window[0] - 1e-9:
            continue
        table = pd.read_csv(path, skiprows=9, sep=r"\s+", header=None,
                            names=["id", "x", "y", "z", "vx", "vy", "vz", "T"])
        frames.append(table)
    return pd.concat(frames) if frames else pd.DataFrame(columns=["id", "x", "y", "z", "vx", "vy", "vz", "T"])


def summarise_run(work: Path, scene: CurtainScene, bins: int = 12) -> dict[str, Any]:
    """What a finished scene found: outlet and gas temperatures, duties, the curtain's speed and
    drift, the profiles over the height, and the bookkeeping (fed = out + in flight; the grains'
    enthalpy gain = the heat the loop gave them)."""
    s, geo = scene.case.solids, scene.case.geometry
    cp, t_in = s.heat_capacity, s.inlet_temperature_C
    # The outlet log through its reader, which refuses a file without the log's columns.
    outlet = read_outlet_log(_one(work, "coupling/outlet.*.csv"))
    heat = pd.read_csv(_one(work, "coupling/rank0.*.csv"))
    air = pd.read_csv(_one(work, "coupling/air.*.csv"))
    last = outlet.iloc[-1]
    out_n = float(outlet["out"].sum())
    given = float((heat["heat_to_particles_W"] * heat["steps"]).sum() * scene.time_step)
    gained = cp * (float(outlet["out_kgC"].sum()) - t_in * float(outlet["out_kg"].sum())
                   + float(last["in_flight_kgC"]) - t_in * float(last["in_flight_kg"]))
    t0, t1 = scene.window
    win = outlet[(outlet["time_s"] > t0) & (outlet["time_s"] <= t1 + 1e-12)]
    # The window's outflow is what the takes after t0 found: from the last take at or before t0.
    before = outlet["time_s"][outlet["time_s"] <= t0]
    span = float(win["time_s"].iloc[-1] - before.iloc[-1]) if len(win) and len(before) else math.nan
    kg, kgc = float(win["out_kg"].sum()), float(win["out_kgC"].sum())
    air_win = air[(air["time_s"] >= t0) & (air["time_s"] <= t1)]
    result: dict[str, Any] = {
        "solids_outlet_C": kgc / kg if kg > 0 else math.nan,
        "solids_flow_out_kg_s": kg / span if span > 0 else math.nan,
        "heat_duty_W": cp * (kgc - t_in * kg) / span if span > 0 else math.nan,
        "gas_side_duty_W": -float(air_win["air_enthalpy_gain_W"].mean()) if len(air_win) else math.nan,
        "gas_outlet_C": float(air_win["outlet_C"].mean()) if len(air_win) else math.nan,
        "outlet_speed_m_s": -float(win["out_kg_vy"].sum()) / kg if kg > 0 else math.nan,
        "outlet_drift_m": -float(win["out_kg_z"].sum()) / kg if kg > 0 else math.nan,
        "parcels_in_flight": float(win["in_flight"].mean()) if len(win) else math.nan,
        "window_s": [t0, t1],
        "bookkeeping": {
            "fed": float(last["fed"]), "out": out_n, "in_flight": float(last["in_flight"]),
            "count_residual": float(last["fed"]) - out_n - float(last["in_flight"]),
            "heat_given_J": given, "enthalpy_gained_J": gained,
            "energy_residual": (gained - given) / max(abs(given), 1e-30),
            "air_heat_balance": float((air["heat_to_air_W"] - air["air_enthalpy_gain_W"]).abs().max()
                                      / max(float(air["heat_to_air_W"].abs().max()), 1e-30)),
        },
    }
    snaps = _snapshots(work, scene)
    edges = np.linspace(0.0, geo.height, bins + 1)
    which = np.digitize(snaps["y"].to_numpy(), edges) - 1
    rows = []
    for b in range(bins):
        sel = snaps[which == b]
        rows.append({"depth_m": geo.height - 0.5 * (edges[b] + edges[b + 1]), "parcels": len(sel),
                     "solids_C": float(sel["T"].mean()) if len(sel) else math.nan,
                     "speed_m_s": -float(sel["vy"].mean()) if len(sel) else math.nan,
                     "drift_m": -float(sel["z"].mean()) if len(sel) else math.nan})
    result["profile"] = sorted(rows, key=lambda r: r["depth_m"])
    return result


def reduced_order(case: CurtainCase) -> dict[str, Any]:
    """The reduced-order model's answer for ``case`` with drumflow's air table (the DEM's air)."""
    from drumflow.coolers.curtain import solve_curtain

    same_air = case.model_copy(update={"gas": case.gas.model_copy(update={"properties": "incropera"})})
    r = solve_curtain(same_air)
    return {"heat_duty_W": r.heat_to_solids_w, "solids_outlet_C": r.solids_outlet_C,
            "gas_outlet_C": r.gas_outlet_C, "outlet_speed_m_s": case.solids.fall_velocity,
            "outlet_drift_m": 0.0, "fall_time_s": r.fall_time_s,
            "profile": {"depth_m": r.depth_m.tolist(), "solids_C": r.solids_profile_C.tolist()}}


def experiments_for(scale: str) -> tuple[str, ...]:
    """The experiments a scale runs."""
    return EXPERIMENTS if scale == "parcels" else ("curtain_fig3",)


def run_particle_curtain(out: Path, scale: str = "parcels", timeout: float | None = None,
                         progress: ProgressCallback | None = None,
                         runner: Runner | None = None) -> list[dict[str, Any]]:
    """Run the scale's experiments into ``out/<experiment>_<scale>`` and return one record each:
    the DEM's answer, the reduced-order model's, their differences and the bookkeeping.

    Raises
    ------
    ValidationDataError
        An unknown scale, or a case file missing.
    SolverError
        The coupling loop (LIGGGHTS) failed.
    """
    from drumflow.runner import Runner as _Runner

    if scale not in SCALES:
        raise ValidationDataError(f"scale = {scale!r}: unknown for scene particle_curtain; "
                                  f"allowed: {', '.join(SCALES)}")
    runner = runner or _Runner()
    records = []
    names = experiments_for(scale)
    for i, name in enumerate(names):
        if progress is not None:
            progress(f"curtain {name}", float(i), float(len(names)))
        case = load_experiment(name)
        scene = curtain_scene(case, COARSE_GRAIN[scale], SHORT_TIME if scale == "short" else None)
        work = Path(out) / f"{name}_{scale}"
        wall = run_scene(scene, work, runner, timeout)
        dem = summarise_run(work, scene)
        rom = reduced_order(case)
        diff = {k: dem[k] - rom[k] for k in ("heat_duty_W", "solids_outlet_C", "gas_outlet_C",
                                               "outlet_speed_m_s", "outlet_drift_m")}
        records.append({"experiment": name, "source": case.source, "coarse_grain": scene.coarse_grain,
                        "time_step_s": scene.time_step, "air_update_steps": scene.interval,
                        "simulated_s": scene.total_steps * scene.time_step, "run_dir": str(work),
                        "dem": dem, "reduced_order": rom, "dem_minus_reduced_order": diff,
                        "wall_time_s": wall})
    if progress is not None:
        progress("curtain", float(len(names)), float(len(names)))
    return records
