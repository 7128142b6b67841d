"""The air around the bed in the coupled loop: solved at phases of one lifter period.

``drumflow bed-air`` measures the air with one frozen bed as Ergun porosity. This module puts
that air into a run (``air.bed_states``): the coupling loop's particles then feel the air that
goes around the bed and through the curtains only as much as they let it (drag), and, with
``air.warming``, warm that air (heat).

Why phases, and not a re-solve every so often: the air's flow depends on where the bed and the
curtains are, and with n lifters turning at omega that configuration repeats, in the lab,
every lifter period 2 pi / (n omega) (1 s for the paper's 12 lifters at 5 rpm): the bed stays
where gravity holds it while the lifters move on by one spacing. A few bed states of a run of
the same scene, at drum angles spread over one lifter spacing (``drumflow export RUN --state
--time T``), are each solved once (:func:`drumflow.air.bed_air.solve_bed_air`, periodic axial air
at the case's mean velocity: a piece of a long drum), and together stand for the air at every
moment. At drum angle theta the loop takes the state k whose angle is nearest modulo the lifter
spacing alpha, and maps the particles into that state's frame by the drum angle
theta - m alpha, m the whole number of spacings between the two (:func:`nearest_phase`): the
lifters, n-fold symmetric, land exactly where the state's did, and the bed within half the
states' angular spacing of the state's. How many states are enough is a convergence question,
measured (``docs/air-around-the-bed.md``); one state is the frozen-bed limit.

Quasi-steady on purpose: the bed's motion is what the states sample, and the air adapts to a
moved curtain within a transit of the slice (0.03 s at 3 m/s over 0.1 m), far faster than the
lifter period. The particles' drag on the air is the porosity's, Ergun at the cell's voidage
against solids at rest (the stated limitation of :mod:`drumflow.air.bed_air`); the states come
from a run whose bed the air could not move (its drag is a fraction of a per cent of the
granules' weight at these slips), so the air they give is that of the coupled bed too.
"""

from __future__ import annotations

import json
import math
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from drumflow.physics.drum_frame import drum_angle, rotate_to_drum_frame, rotate_to_lab_frame

if TYPE_CHECKING:
    from drumflow.air.bed_air import BedSnapshot
    from drumflow.air.field import AirField
    from drumflow.case import Case
    from drumflow.runner import Runner

__all__ = ["PHASES_RECORD", "BedPhase", "PhaseLockedAir", "lifter_spacing", "nearest_phase",
           "solve_bed_phases"]

#: What the air stage writes beside the phases' fields (their angles, states and measures).
PHASES_RECORD = "bed_phases.json"


def lifter_spacing(lifters: int) -> float | None:
    """The angle between two lifters, rad; None without lifters (every angle is a symmetry)."""
    return 2.0 * math.pi / lifters if lifters > 0 else None


def nearest_phase(angle: float, phases: NDArray[np.float64] | list[float],
                  spacing: float | None) -> tuple[int, float]:
    """The phase nearest ``angle`` modulo ``spacing``, and the drum angle to map by.

    Parameters
    ----------
    angle
        The drum's angle now, rad (:func:`drumflow.physics.drum_frame.drum_angle`).
    phases
        The drum angles of the solved states, rad.
    spacing
        The lifters' angular spacing (:func:`lifter_spacing`); None: any angle is a symmetry.

    Returns
    -------
    index, frame_angle
        The state ``k``, and ``angle - m spacing`` with ``m`` the whole number of spacings that
        brings ``angle`` nearest to the state's (without lifters, the state's angle itself):
        lab points turned by ``-frame_angle`` land in the state's frame.
    """
    theta = np.asarray(phases, dtype=float)
    if len(theta) == 0:
        raise ValueError("no phases")
    if spacing is None:
        return 0, float(theta[0])
    m = np.round((angle - theta) / spacing)
    residual = angle - theta - m * spacing
    k = int(np.argmin(np.abs(residual)))
    return k, float(angle - m[k] * spacing)


@dataclass
class PhaseLockedAir:
    """The air of each solved bed state, and which one stands for the drum's angle now.

    Attributes
    ----------
    fields
        One grid field per state (absolute velocity, in the state's drum frame).
    angles
        The states' drum angles, rad.
    spacing
        The lifters' spacing, rad (None without lifters).
    omega
        The drum's angular speed, rad/s.
    """

    fields: list[AirField]
    angles: list[float]
    spacing: float | None
    omega: float

    def phase(self, time_s: float) -> tuple[int, float]:
        """The state standing for ``time_s`` and the drum angle to map the particles by."""
        return nearest_phase(drum_angle(self.omega, time_s), self.angles, self.spacing)

    def sample_at(self, x: NDArray[np.float64], time_s: float) -> NDArray[np.float64]:
        """The absolute air velocity at lab-frame points ``x`` at ``time_s``, lab components."""
        k, angle = self.phase(time_s)
        return rotate_to_lab_frame(self.fields[k].sample(rotate_to_drum_frame(x, angle)), angle)

    def sample_lab(self, x: NDArray[np.float64], time_s: float) -> NDArray[np.float64]:
        """:meth:`sample_at`, under the name :class:`~drumflow.air.field.AirField` gives it (the
        run's readers sample either)."""
        return self.sample_at(x, time_s)

    @classmethod
    def from_run(cls, air_dir: Path, case: Case) -> PhaseLockedAir:
        """The phases a run's air stage wrote into ``air_dir`` (its :data:`PHASES_RECORD` and
        ``bed_phase_<k>.npz``).

        Raises
        ------
        drumflow.errors.BadFileError
            The record or a field missing, cut short or not what it should be.
        """
        from drumflow.air.field import AirField
        from drumflow.readers import read_json_object

        record = read_json_object(air_dir / PHASES_RECORD, "the run's bed phases record")
        angles = [float(s["angle_rad"]) for s in record["states"]]
        return cls([AirField.from_npz(air_dir / f"bed_phase_{k}.npz") for k in range(len(angles))],
                   angles, lifter_spacing(case.lifters.count), case.drum.omega)

    @classmethod
    def from_spec(cls, spec: dict[str, Any]) -> PhaseLockedAir:
        """From the coupling spec's field entry ``{"kind": "phases", "paths", "angles",
        "spacing", "omega"}`` (written by the air stage)."""
        from drumflow.air.field import AirField

        return cls([AirField.from_npz(Path(p)) for p in spec["paths"]],
                   [float(a) for a in spec["angles"]],
                   None if spec["spacing"] is None else float(spec["spacing"]),
                   float(spec["omega"]))


@dataclass(frozen=True)
class BedPhase:
    """One solved state: its field file, its drum angle, and what ``bed-air`` measured."""

    path: Path
    angle_rad: float
    time_s: float
    source: str
    measures: dict[str, Any]
    #: This state's solve (the first also solved the empty drum every state starts from).
    wall_time_s: float = math.nan

    def record(self) -> dict[str, Any]:
        """The entry of :data:`PHASES_RECORD` for this state."""
        return {"path": str(self.path), "angle_rad": self.angle_rad, "time_s": self.time_s,
                "source": self.source, "split": self.measures, "wall_time_s": self.wall_time_s}


def solve_bed_phases(case: Case, states: list[BedSnapshot], workdir: Path, out: Path,
                     runner: Runner, *, processes: int = 1, timeout: float | None = 7200.0,
                     on_phase: Callable[[int, int], None] | None = None) -> list[BedPhase]:
    """Solve the air around each state's bed (periodic axial air), resample each onto the
    grid the loop samples, write ``out/bed_phase_<k>.npz`` and :data:`PHASES_RECORD`.

    The empty drum is solved once and every bed case starts from it. ``on_phase(done, total)``
    is called as each state's air is written (a progress bar: each takes minutes at paper
    scale).

    Raises
    ------
    drumflow.errors.SolverError
        An OpenFOAM program failed or did not converge.
    """
    from drumflow.air.bed_air import solve_bed_air
    from drumflow.air.field import AirField

    out.mkdir(parents=True, exist_ok=True)
    started = time.perf_counter()
    empty = None
    phases: list[BedPhase] = []
    for k, state in enumerate(states):
        phase_started = time.perf_counter()
        result = solve_bed_air(case, state, workdir / f"phase_{k}", runner, processes=processes,
                               timeout=timeout, axial="periodic", empty=empty)
        empty = result.empty_solution
        assert result.bed_solution is not None
        path = out / f"bed_phase_{k}.npz"
        AirField.from_solution(result.bed_solution, case).to_npz(path)
        phases.append(BedPhase(path, float(state.drum_angle_rad), float(state.time_s),
                               state.source, result.as_dict(), time.perf_counter() - phase_started))
        if on_phase is not None:
            on_phase(k + 1, len(states))
    record = {"states": [p.record() for p in phases],
              "spacing_rad": lifter_spacing(case.lifters.count),
              "wall_time_s": time.perf_counter() - started}
    (out / PHASES_RECORD).write_text(json.dumps(record, indent=2, default=float) + "\n")
    return phases
