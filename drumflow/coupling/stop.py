"""The 'converged' stop rule inside the coupling loop (``run.stop = "converged"``).

At every coupling update the loop already holds each rank's particles in memory. From them this
module forms, over all MPI ranks (``MPI_Allreduce``, :mod:`drumflow.coupling.mpi`), two time
series over the counting window ``t >= run.mass_flow_start``:

* the air's heat-transfer coefficient on the whole particle surface,
  ``h = -Q / (A (T_mean - T_air))``, with ``Q`` the heat the air gives the particles over the
  update (W), ``A`` their surface and ``T_mean`` their mass-weighted mean temperature: the
  online counterpart of the paper's per-step h (Eqs. 34-41 divide the same heat by the falling
  particles' area instead; the ratio of the two areas is the falling mass flow's business);
* the falling mass flow: particles whose centre went from above the plane ``y = 0`` to on or
  below it since the previous update (:class:`drumflow.coupling.crossings.CrossingTracker`, the
  same test as :func:`drumflow.analysis.observables.crossings_from_rows`, on every particle
  rather than on the dump's band), times the particle mass, per unit time.

Every ``check_every`` steps rank 0 forms both intervals with whole lifter cycles as batches,
after MSER's cut of the start-up (:func:`drumflow.convergence.cycle_means`: the intervals are
the cascading bed's, and no batch mixes phases of the discharge; batch means of 20 equal
batches were up to six times wider, or flagged correlated while the bed formed, and never let
the paper runs stop). The cut is MSER-5 on the samples less their mean profile over a cycle,
up to the next whole cycle (since issue 35: MSER on the cycle means themselves picked the
cycles that strayed and under-covered, 0.91-0.93 for 95 %; ``docs/flow-uncertainty.md``); the
replay's steady flow (:mod:`drumflow.bench.answer`) forms the same interval. The loop then
asks :func:`drumflow.convergence.decide` whether both are narrower than the tolerance and
shares its verdict with a second reduction, so that every rank leaves the loop at the same
step. Rank 0 logs the series to ``coupling/convergence.csv`` (read back on resume) and the
verdict to ``coupling/stop.json``.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any, TextIO

import numpy as np
from numpy.typing import NDArray

from drumflow.convergence import ConvergenceState, MeanInterval, batch_means, cycle_means, decide
from drumflow.coupling.mpi import allreduce_sum

if TYPE_CHECKING:
    from drumflow.case import Case

__all__ = ["STOP_RECORD", "SERIES_RECORD", "StopMonitor", "discharge_cycle", "min_stop_time",
           "rule_inputs", "stop_rule"]

#: The verdict the loop leaves behind, relative to the DEM working directory.
STOP_RECORD = "coupling/stop.json"
#: The online series (one row per coupling update), relative to the DEM working directory.
SERIES_RECORD = "coupling/convergence.csv"
_COLUMNS = "step,time_s,steps,h_W_m2K,crossings,heat_to_particles_W,surface_m2,mean_temperature_C"


def min_stop_time(case: Case) -> float:
    """``run.stop_min_time``, or its 'auto' value: ``mass_flow_start`` plus the longer of 1 s and
    three lifter passing periods (each lifter's discharge is one cycle of the falling flow)."""
    if case.run.stop_min_time != "auto":
        return float(case.run.stop_min_time)
    lifters = max(case.lifters.count, 1)
    passing = 60.0 / (case.drum.rpm * lifters)
    return case.run.mass_flow_start + max(1.0, 3.0 * passing)


def discharge_cycle(case: Case) -> float:
    """Seconds between two lifters' discharges, ``60 / (rpm x lifters)``: the falling flow's
    period (one revolution for a drum without lifters)."""
    return 60.0 / (case.drum.rpm * max(case.lifters.count, 1))


def rule_inputs(case: Case, planned_time_s: float, check_every: int) -> dict[str, Any]:
    """What the monitor needs of a case, whatever its ``run.stop`` (the replay of a fixed run
    asks what the rule would have said). ``case`` is the case the DEM moves: with
    coarse-graining its particle mass is a parcel's, which is what crosses."""
    return {
        "tolerance": case.run.stop_tolerance,
        "min_time_s": min(min_stop_time(case), planned_time_s),
        "window_start_s": case.run.mass_flow_start,
        "check_every": check_every,
        "particle_mass_kg": case.particles.mass,
        "air_temperature_C": case.air.inlet_temperature_C,
        "planned_time_s": planned_time_s,
        "cycle_s": discharge_cycle(case),
    }


def stop_rule(case: Case, planned_time_s: float, check_every: int) -> dict[str, Any] | None:
    """The coupling loop's ``stop`` entry for a case (``None`` for a fixed-time run).

    Parameters
    ----------
    case
        The case.
    planned_time_s
        The simulated time of the step plan (the latest stop).
    check_every
        DEM steps between verdicts (the output step).
    """
    if case.run.stop != "converged":
        return None
    return rule_inputs(case, planned_time_s, check_every)


# -- the monitor ----------------------------------------------------------------------------
@dataclass
class _Series:
    step: list[int] = field(default_factory=list)
    time_s: list[float] = field(default_factory=list)
    steps: list[int] = field(default_factory=list)
    h: list[float] = field(default_factory=list)
    crossings: list[float] = field(default_factory=list)  # NaN: no previous sample (resume)


class StopMonitor:
    """The stop rule's state in one rank of the coupling loop.

    Parameters
    ----------
    rule
        The ``stop`` entry of the loop's input (:func:`stop_rule`).
    work
        The DEM working directory.
    rank
        This process's MPI rank (rank 0 decides and writes).
    time_step
        DEM time step, s.
    start_step
        The step the loop starts at (after a resume: the restart's).
    """

    def __init__(self, rule: dict[str, Any], work: Path, rank: int, time_step: float,
                 start_step: int) -> None:
        self.rule = rule
        self.rank = rank
        self.dt = time_step
        self.series = _Series()
        self.last_check = start_step
        self.verdict: ConvergenceState | None = None
        self.checks = 0
        self.record_path = work / SERIES_RECORD
        self.result_path = work / STOP_RECORD
        self._out: TextIO | None = None
        if rank == 0:
            self._resume(start_step)

    def _resume(self, start_step: int) -> None:
        """Keep the rows of an earlier attempt before the restart step; start the log."""
        kept: list[str] = []
        if self.record_path.exists() and start_step > 0:
            for line in self.record_path.read_text().splitlines()[1:]:
                cells = line.split(",")
                if len(cells) == 8 and int(cells[0]) < start_step:
                    kept.append(line)
                    s = self.series
                    s.step.append(int(cells[0]))
                    s.time_s.append(float(cells[1]))
                    s.steps.append(int(cells[2]))
                    s.h.append(float(cells[3]))
                    s.crossings.append(float(cells[4]))
        self.record_path.parent.mkdir(parents=True, exist_ok=True)
        out = self.record_path.open("w")
        out.write(_COLUMNS + "\n" + "".join(k + "\n" for k in kept))
        out.flush()
        self._out = out

    def observe(self, step: int, steps: int, heat: NDArray[np.float64],
                diameter: NDArray[np.float64], temperature: NDArray[np.float64],
                mass: NDArray[np.float64], crossings: int | None) -> bool:
        """Take the update at ``step`` (held for ``steps`` steps); True when the loop must stop.

        ``crossings``: particles that crossed the axis plane downwards since the previous update
        (:class:`drumflow.coupling.crossings.CrossingTracker`, counted on rank 0; None for the
        first update of an attempt). Every rank must call it at every update (it reduces over
        all ranks).
        """
        local = np.array([float(heat.sum()), float(np.sum(math.pi * diameter**2)),
                          float(np.sum(mass * temperature)), float(mass.sum())])
        total = allreduce_sum(local)
        decide = False
        if self.rank == 0:
            decide = self._take(step, steps, total, crossings)
        # Rank 0's verdict to every rank (the others add 0), so that all leave at one step.
        return bool(allreduce_sum(np.array([1.0 if decide else 0.0]))[0] > 0.5)

    def _take(self, step: int, steps: int, total: NDArray[np.float64],
              crossings: int | None) -> bool:
        heat, surface, mT, m = (float(v) for v in total[:4])
        t_mean = mT / m if m > 0 else math.nan
        dT = t_mean - float(self.rule["air_temperature_C"])
        h = -heat / (surface * dT) if surface > 0 and dT != 0 else math.nan
        count = math.nan if crossings is None else float(crossings)
        s = self.series
        s.step.append(step)
        s.time_s.append(step * self.dt)
        s.steps.append(steps)
        s.h.append(h)
        s.crossings.append(count)
        assert self._out is not None
        self._out.write(f"{step},{step * self.dt:.12g},{steps},{h:.12g},{count:.0f},"
                        f"{heat:.12g},{surface:.12g},{t_mean:.12g}\n")
        self._out.flush()
        if step - self.last_check < int(self.rule["check_every"]):
            return False
        self.last_check = step
        self.checks += 1
        self.verdict = self.state(step * self.dt)
        return self.verdict.converged

    def _samples(self) -> dict[str, tuple[NDArray[np.float64], NDArray[np.float64],
                                          NDArray[np.float64]]]:
        """The two series over the counting window: values, durations (s) and end times (s)."""
        s = self.series
        step = np.asarray(s.step, dtype=float)
        held = np.asarray(s.steps, dtype=float) * self.dt
        t = step * self.dt
        start = float(self.rule["window_start_s"])
        h = np.asarray(s.h)
        # An h sample is held from its update for the update's steps.
        in_h = (t >= start - 1e-9) & np.isfinite(h)
        # Crossing sample k covers (step_{k-1}, step_k]: its duration is the gap to the previous
        # sample, and it belongs to the window when that interval starts inside it.
        gap = np.r_[np.nan, np.diff(step)] * self.dt
        c = np.asarray(s.crossings)
        in_c = (t - gap >= start - 1e-9) & np.isfinite(c) & np.isfinite(gap)
        mass = float(self.rule["particle_mass_kg"])
        return {"h_W_m2K": (h[in_h], held[in_h], t[in_h] + held[in_h]),
                "falling_mass_flow_kg_s": (mass * c[in_c] / gap[in_c], gap[in_c], t[in_c])}

    def windowed(self) -> dict[str, tuple[NDArray[np.float64], NDArray[np.float64]]]:
        """The two series over the counting window, each with its samples' durations, s."""
        return {name: (v, w) for name, (v, w, _) in self._samples().items()}

    def intervals(self) -> dict[str, MeanInterval]:
        """Both intervals on the series so far, each from whole discharge cycles after MSER's
        cut of the start-up on the samples (:func:`drumflow.convergence.cycle_means`,
        ``truncation="samples"``): the cascading bed's h and falling mass flow. Batch means
        where the rule has no ``cycle_s`` (a loop input written before it existed)."""
        samples = self._samples()
        cycle = self.rule.get("cycle_s")
        if cycle is None:
            return {name: batch_means(v, w) for name, (v, w, _) in samples.items()}
        start = float(self.rule["window_start_s"])
        return {name: cycle_means(v, w, ends, float(cycle), start, truncation="samples")
                for name, (v, w, ends) in samples.items()}

    def state(self, time_s: float) -> ConvergenceState:
        return decide(self.intervals(), time_s, float(self.rule["tolerance"]),
                      float(self.rule["min_time_s"]))

    def finish(self, step: int, stopped: bool) -> None:
        """Rank 0 writes the verdict (``coupling/stop.json``); every rank may call it."""
        if self.rank != 0:
            return
        if self._out is not None:
            self._out.close()
        verdict = self.verdict if stopped and self.verdict else self.state(step * self.dt)
        record = {
            "rule": "converged",
            "stopped_early": stopped,
            "step": step,
            "time_s": step * self.dt,
            "planned_time_s": self.rule["planned_time_s"],
            "tolerance": self.rule["tolerance"],
            "min_time_s": self.rule["min_time_s"],
            "window_start_s": self.rule["window_start_s"],
            "checks": self.checks,
            "reason": verdict.reason if stopped else
            f"ran the planned {self.rule['planned_time_s']:g} s; at the end: {verdict.reason}",
            "intervals": {k: v.as_dict() for k, v in verdict.intervals.items()},
        }
        self.result_path.write_text(json.dumps(record, indent=2))
