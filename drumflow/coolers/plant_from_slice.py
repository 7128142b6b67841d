"""The whole plant from a slice run: what `drumflow plant` (= `drumflow cooler drum`) computes.

A slice run's closures (or a closures file) feed the axial whole-drum model
(:func:`drumflow.coolers.drum.solve_drum`) of the paper's plant, or of the plant with changed
conditions (a what-if). Beside the model's outlets it gathers what a reader weighs them
against: the plant's measured outlets and energy balance (no what-if), the paper's exchanger
(Table 7), a textbook volumetric coefficient, and the outlets over a range of the one closure
no slice measures yet, the air that passes through the curtains. :func:`write_plant_from_slice`
puts it all in a run directory. Library code: it raises and writes files, it never prints.
"""

from __future__ import annotations

import dataclasses
import math
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

from pydantic import BaseModel, ConfigDict

from drumflow.coolers.drum import MAX_CURTAIN_AIR_M3_S_M, DrumModelError

if TYPE_CHECKING:
    from drumflow.analysis.air_closures import AirClosures
    from drumflow.analysis.closures import SliceClosures
    from drumflow.coolers._transport import TransportLaw
    from drumflow.coolers.curtain_air import CurtainAirPoint, NeededCurtainAir
    from drumflow.coolers.drum import DrumOptions, DrumResult
    from drumflow.coolers.plant import PlantSpec
    from drumflow.physics.exchanger import ExchangerResult

__all__ = ["PAPER_TABLE7", "DrumInputs", "PlantFromSlice", "PlantFromSliceFiles",
           "curtain_air_from_slice", "curtain_air_setting", "is_slice_file", "plant_from_slice",
           "plot_curtain_air", "plot_drum", "slice_closures", "write_plant_from_slice"]

#: Table 7 of the paper, model one: its exchanger prediction of the plant.
PAPER_TABLE7 = {"material_outlet_C": 40.90, "air_outlet_C": 69.73}

#: Why the through-curtain air defaults as it does (kept with every result).
CURTAIN_AIR_DEFAULT_NOTE = (
    "default: the closures' own through-curtain air when they carry a periodic slice's air "
    "closures (drumflow plant --curtain-air HEAT.json --save-closures), else 'all': all the air "
    "meets every falling granule, the limit of most contact and the one setting not chosen from "
    "the plant; the through-curtain flow is never fitted to the plant's outlets")

#: Where the textbook volumetric coefficient comes from and how far it was checked.
TEXTBOOK_NOTE = (
    "Ua = 0.5 G^0.67 / D (Btu/(h ft3 F), G lb/(h ft2), D ft), i.e. 237 G^0.67 / D in W/(m3 K) "
    "with G in kg/(s m2), D in m; attributed to McCormick via Perry's (rotary dryers). Checked "
    "only against Coulson & Richardson Vol. 2, Example 16.5 (0.25 kW/(m3 K) form, 5 % above): "
    "a handbook estimate, not a closure")


class DrumInputs(BaseModel):
    """What one `drumflow cooler drum` evaluation depends on (bound to its run directory)."""

    model_config = ConfigDict(extra="forbid", frozen=True)

    source: str
    closures: dict[str, Any]
    plant: dict[str, Any]
    options: dict[str, Any]


def slice_closures(source: Path, start: float | None) -> SliceClosures:
    """The closures of a slice run directory (measured from ``start`` s on), or of a closures
    file.

    Raises
    ------
    DrumModelError
        ``start`` given with a closures file (measured over its own window).
    """
    from drumflow.analysis.closures import extract_closures, load_closures

    if source.is_dir():
        return extract_closures(source, start_s=start)
    if start is not None:
        # A closures file was measured over its own window (its `window_s`); silently ignoring
        # the option would hand back closures the user did not ask for.
        raise DrumModelError(f"--start = {start:g} s: allowed only with a slice run directory "
                             f"as SOURCE; {source} is a closures file (measured over its "
                             "own window_s)")
    return load_closures(source)


def curtain_air_from_slice(path: Path) -> AirClosures:
    """The air closures of a periodic slice (:func:`drumflow.analysis.air_closures.read_air_closures`:
    the ``heat.json`` of ``drumflow bed-air --axial periodic --heat``, the ``split.json`` and the
    mixing bounds beside it). Their through-curtain air is the **saturated flow**, the air per
    metre that would leave at the particles' mean temperature with the heat the slice's air
    took: what the plant model's through-curtain stream stands for (chosen so when the bed-air
    heat was built, before any comparison).

    Raises
    ------
    DrumModelError
        The file missing or unreadable, an entry missing or out of range, an inlet-outlet
        slice (a 0.1 m slice's inlet forces fresh air through the bed: not a piece of a long
        drum), or a flow above :data:`MAX_CURTAIN_AIR_M3_S_M`; the message names the option
        and the file.
    """
    from drumflow.analysis.air_closures import read_air_closures
    from drumflow.errors import BadFileError

    try:
        air = read_air_closures(path)
    except BadFileError as err:
        raise DrumModelError(f"--curtain-air {path}: not a periodic slice's bed-air heat.json "
                             f"with its split.json beside it: {err}") from None
    if air.curtain_air_m3_s_m > MAX_CURTAIN_AIR_M3_S_M:
        raise DrumModelError(f"--curtain-air {path}: saturated_flow_m3_s_m = "
                             f"{air.curtain_air_m3_s_m}: allowed 0 to "
                             f"{MAX_CURTAIN_AIR_M3_S_M:g} m3/s per metre of drum")
    return air


def is_slice_file(value: str) -> bool:
    """Whether a ``--curtain-air`` value names a slice's file (one rule for reading it and
    for recording where the flow came from)."""
    return value.strip().endswith(".json")


def curtain_air_setting(value: str) -> float | None:
    """``--curtain-air``: 'all' (None), a flow in m3/s per metre of drum, or a periodic slice's
    ``heat.json`` (its saturated flow, :func:`curtain_air_from_slice`).

    Raises
    ------
    DrumModelError
        Neither 'all', nor a flow from 0 to :data:`MAX_CURTAIN_AIR_M3_S_M`, nor such a file.
    """
    allowed = (f"allowed 'all', 0 to {MAX_CURTAIN_AIR_M3_S_M:g} m3/s per metre of drum, or a "
               "periodic slice's heat.json")
    if value.strip().lower() == "all":
        return None
    if is_slice_file(value):
        return curtain_air_from_slice(Path(value.strip())).curtain_air_m3_s_m
    try:
        flow = float(value)
    except ValueError:
        raise DrumModelError(f"--curtain-air = {value}: {allowed}") from None
    if not (math.isfinite(flow) and 0.0 <= flow <= MAX_CURTAIN_AIR_M3_S_M):
        raise DrumModelError(f"--curtain-air = {value}: {allowed}")
    return flow


def check_what_if(changes: dict[str, float | None], cells: int, wall_loss: float,
                  closures_start: float | None) -> None:
    """Refuse a what-if outside the drum case's own bounds, naming the option.

    Parameters
    ----------
    changes
        The plant's changed conditions by option name (``--rpm``, ``--air-flow``,
        ``--feed-rate``, ``--particle-diameter``, ``--length``, ``--tilt``; None: unchanged).
    cells, wall_loss, closures_start
        ``--cells``, ``--wall-loss`` (W/(m2 K)) and ``--start`` (s).

    Raises
    ------
    DrumModelError
        The first value out of bounds.
    """
    most = {"--rpm": 60.0, "--air-flow": 1000.0, "--feed-rate": 1000.0, "--particle-diameter": None,
            "--length": 200.0, "--tilt": 30.0}
    for name, value, upper_bound in (("--cells", cells, 5000),
                                     *((n, v, most[n]) for n, v in changes.items())):
        # Upper bounds as the drum case's own (drum.rpm, air.mass_flow, plant.length,
        # drum.tilt_deg; DrumOptions' cells): beyond them the model fails somewhere else and
        # blames another quantity (--length 1e300 was reported as "cells = 40").
        if value is not None and not (value > 0 and (upper_bound is None or value <= upper_bound)):
            upper = "" if upper_bound is None else f" and <= {upper_bound:g}"
            raise DrumModelError(f"{name} = {value:g}: allowed > 0{upper}")
    if not 0 <= wall_loss <= 1000:
        raise DrumModelError(f"--wall-loss = {wall_loss:g}: allowed >= 0 and <= 1000 W/(m2 K)")
    if closures_start is not None and not closures_start >= 0:
        raise DrumModelError(f"--start = {closures_start}: allowed >= 0 s (simulated time)")


@dataclass
class PlantFromSlice:
    """One evaluation of the whole plant from slice closures, with what it is weighed against.

    Attributes
    ----------
    source
        The slice run directory or closures file.
    closures
        The slice closures.
    base, plant
        The paper's plant, and the plant evaluated (``base`` with the what-if's changes).
    law, options
        The transport law (calibrated on the plant's measured residence time) and the model's
        options.
    result, wall_s
        The drum model's result and its wall time.
    warnings
        Extrapolation warnings and the model's own.
    textbook_ua, textbook, exchanger
        The textbook volumetric coefficient (W/(m3 K)) and its exchanger; the paper's exchanger
        (Table 7's h and A_he) with this plant's streams.
    points, needed
        The outlets over the through-curtain air (empty without the sweep), and the flow the
        plant's measured NPK outlet would need (the paper's plant only).
    curtain_air, curtain_air_from
        The through-curtain flow used (None: 'all'); the slice file it came from, if any.
    mixing_bounds
        The outlets at the slice's mixing bounds of the through-curtain air (molecular,
        turbulent: :meth:`drumflow.analysis.air_closures.AirClosures.bounds`), when the flow
        came from a slice that solved them; empty otherwise.
    """

    source: Path
    closures: SliceClosures
    base: PlantSpec
    plant: PlantSpec
    law: TransportLaw
    options: DrumOptions
    result: DrumResult
    wall_s: float
    warnings: list[str]
    textbook_ua: float
    textbook: ExchangerResult
    exchanger: ExchangerResult
    curtain_air: float | None
    curtain_air_from: str | None = None
    mixing_bounds: dict[str, CurtainAirPoint] = field(default_factory=dict)
    points: list[CurtainAirPoint] = field(default_factory=list)
    needed: NeededCurtainAir | None = None

    @property
    def what_if(self) -> bool:
        """Conditions other than the paper's plant (no measured outlets to compare with)."""
        return self.plant != self.base

    def curtain_scales(self) -> dict[str, dict[str, Any]]:
        """The scales of the through-curtain flow, m3/s per metre (what a flow is large beside)."""
        from drumflow.coolers.curtain_air import curtain_air_scales

        return curtain_air_scales(self.plant, self.result.scaled)

    def to_dict(self) -> dict[str, Any]:
        """The whole evaluation as written to ``result.json`` and printed by ``--json``."""
        from drumflow.coolers.plant_balance import measured_balance

        base, what_if = self.base, self.what_if
        return {
            "source": str(self.source),
            "slice": self.closures.to_dict(),
            **self.result.to_dict(),
            "warnings": self.warnings,
            "measured": {"material_outlet_C": base.measured_material_outlet_c,
                         "air_outlet_C": base.measured_air_outlet_c} if not what_if else None,
            "paper_exchanger": {
                "material_outlet_C": self.exchanger.material_outlet_temperature_c,
                "air_outlet_C": self.exchanger.air_outlet_temperature_c,
                "published_table7": PAPER_TABLE7 if not what_if else None,
                "note": "Table 7 model one: h = 60.15 W/(m2 K), A_he = 1099.28 m2, this plant's streams",
            },
            "curtain_air": {
                "setting_m3_s_per_m": self.curtain_air,
                "from_slice": self.curtain_air_from,
                "mixing_bounds": {name: point.to_dict() for name, point in self.mixing_bounds.items()},
                "default_note": CURTAIN_AIR_DEFAULT_NOTE,
                "sweep": [p.to_dict() for p in self.points],
                "needed_for_measured_material_outlet": self.needed.to_dict() if self.needed else None,
                "scales_m3_s_per_m": self.curtain_scales(),
            },
            "plant_balance": measured_balance(base).to_dict() if not what_if else None,
            "textbook_volumetric": {
                "Ua_W_m3K": self.textbook_ua,
                "material_outlet_C": self.textbook.material_outlet_temperature_c,
                "air_outlet_C": self.textbook.air_outlet_temperature_c,
                "note": TEXTBOOK_NOTE,
            },
        }


def plant_from_slice(source: Path, *, cells: int = 40, rpm: float | None = None,
                     air_flow: float | None = None, feed_rate: float | None = None,
                     particle_diameter: float | None = None, length: float | None = None,
                     tilt: float | None = None, wall_loss: float = 0.0, lumped: bool = False,
                     curtain_air: str | None = None, sweep: bool = True,
                     closures_start: float | None = None,
                     save_closures: Path | None = None) -> PlantFromSlice:
    """The paper's plant (or a what-if of it) by the axial drum model from a slice's closures.

    Parameters
    ----------
    source
        A slice run directory, or a closures JSON file.
    cells
        Axial cells.
    rpm, air_flow, feed_rate, particle_diameter, length, tilt
        The what-if's changes to the paper's plant (1/min, kg/s, kg/s, m, m, degrees; None:
        the plant's own).
    wall_loss, lumped
        The shell's wall-loss coefficient U_w, W/(m2 K) (0: off); lumped particles (Bi -> 0).
    curtain_air
        Air through the curtains: m3/s per metre of drum, 'all', or a periodic slice's
        ``heat.json`` (its air closures then join the closures, and are saved with them);
        None: the closures' own through-curtain air if they carry one, else 'all'.
    sweep
        Also evaluate the outlets over a range of the through-curtain air.
    closures_start
        With a run directory: measure the closures from this simulated time on, s.
    save_closures
        Also write the slice closures (with the air closures, if any) to this JSON file, once
        the model accepted the inputs (a refused call writes nothing).

    Raises
    ------
    DrumModelError
        An option out of its bounds, or ``closures_start`` with a closures file.
    """
    from drumflow.coolers._transport import calibrate
    from drumflow.coolers.curtain_air import (
        CurtainAirPoint,
        curtain_air_for_outlet,
        sweep_curtain_air,
    )
    from drumflow.coolers.drum import (
        DrumOptions,
        paper_exchanger,
        solve_drum,
        volumetric_coefficient_estimate,
    )
    from drumflow.coolers.drum_closures import extrapolation_warnings
    from drumflow.coolers.plant import PAPER_PLANT

    changes = {"--rpm": rpm, "--air-flow": air_flow, "--feed-rate": feed_rate,
               "--particle-diameter": particle_diameter, "--length": length, "--tilt": tilt}
    check_what_if(changes, cells, wall_loss, closures_start)
    slice_air = (curtain_air_from_slice(Path(curtain_air.strip()))
                 if curtain_air is not None and is_slice_file(curtain_air) else None)
    curtain_flow = (None if curtain_air is None or slice_air is not None
                    else curtain_air_setting(curtain_air))
    if particle_diameter is not None and particle_diameter > 0.05:
        raise DrumModelError(f"--particle-diameter = {particle_diameter}: allowed <= 0.05 m "
                             "(give it in metres)")
    closures = slice_closures(source, closures_start)
    if slice_air is not None:
        # The slice's air closures travel with the closures (--save-closures, result.json).
        closures = dataclasses.replace(closures, air=slice_air)
    elif curtain_air is None:
        slice_air = closures.air
    if slice_air is not None:
        curtain_flow = slice_air.curtain_air_m3_s_m
    base = PAPER_PLANT
    # The transport law's one constant comes from the plant's measured residence time
    # (30 min), never from its outlet temperatures.
    assert base.residence_time_s is not None
    law = calibrate(base, base.residence_time_s)
    plant = base.changed(rpm=rpm, air_mass_flow_kg_s=air_flow, feed_rate_kg_s=feed_rate,
                         particle_diameter_m=particle_diameter, length_m=length, tilt_deg=tilt)
    options = DrumOptions(cells=cells, wall_loss_w_m2k=wall_loss, lumped_particles=lumped,
                          curtain_air_m3_s_m=curtain_flow)
    start = time.perf_counter()
    result = solve_drum(plant, closures, law, options)
    wall = time.perf_counter() - start
    if save_closures is not None:
        # After the model accepted the inputs: a refused command writes nothing.
        closures.write(save_closures)
    ua, textbook = volumetric_coefficient_estimate(plant)
    evaluation = PlantFromSlice(
        source=source, closures=closures, base=base, plant=plant, law=law, options=options,
        result=result, wall_s=wall,
        warnings=extrapolation_warnings(plant, base, closures, result.scaled) + result.warnings,
        textbook_ua=ua, textbook=textbook, exchanger=paper_exchanger(plant), curtain_air=curtain_flow,
        curtain_air_from=None if slice_air is None else slice_air.source,
        mixing_bounds={} if slice_air is None else {
            name: CurtainAirPoint.from_result(solve_drum(
                plant, closures, law, dataclasses.replace(options, curtain_air_m3_s_m=flow)))
            for name, flow in slice_air.bounds().items()})
    # The through-curtain flow is the closure no slice measures yet: show what it changes.
    if sweep:
        evaluation.points = sweep_curtain_air(plant, closures, law, options)
        if not evaluation.what_if and base.measured_material_outlet_c is not None:
            evaluation.needed = curtain_air_for_outlet(plant, closures, law, options,
                                                       base.measured_material_outlet_c,
                                                       evaluation.points)
    return evaluation


@dataclass(frozen=True)
class PlantFromSliceFiles:
    """What :func:`write_plant_from_slice` wrote: the run directory and its files."""

    root: Path
    result: Path
    profile_csv: Path
    profile_png: Path
    curtain_air_csv: Path | None
    curtain_air_png: Path | None


def write_plant_from_slice(evaluation: PlantFromSlice, out: Path | None,
                           force: bool = True) -> PlantFromSliceFiles:
    """Write an evaluation into its run directory (default ``runs/cooler/drum/<slice case>``):
    ``result.json``, the axial profile (CSV, PNG) and, with the sweep, the outlets over the
    through-curtain air (CSV, PNG).

    Raises
    ------
    RunDirectoryError
        ``out`` holds another input and ``force`` is off.
    """
    from drumflow.coolers._rundir import open_cooler_run, write_result

    payload = evaluation.to_dict()
    closures, plant, result = evaluation.closures, evaluation.plant, evaluation.result
    inputs = DrumInputs(source=str(evaluation.source), closures=closures.to_dict(),
                        plant=payload["plant"], options=payload["options"])
    target = out or Path("runs/cooler/drum") / closures.case_name
    rundir = open_cooler_run(target, "drum", inputs, inputs.model_dump_json(indent=2), force=force)
    result_path = write_result(rundir, payload, evaluation.wall_s)
    root = rundir.root
    with (root / "profile.csv").open("w") as fh:
        fh.write("z_m,solids_C,air_C\n")
        for z, s, a in zip(result.z_m, result.solids_c, result.air_c, strict=True):
            fh.write(f"{z:.6g},{s:.6g},{a:.6g}\n")
    title = (f"{plant.diameter_m:g} m x {plant.length_m:g} m, {plant.rpm:g} rpm, "
             f"{plant.feed_rate_kg_s:.4g} kg/s NPK, {plant.air_mass_flow_kg_s:g} kg/s air; "
             f"closures: {closures.case_name}")
    profile_png = plot_drum(result, root / "profile.png", title)
    if not evaluation.points:
        return PlantFromSliceFiles(root, result_path, root / "profile.csv", profile_png, None, None)
    with (root / "curtain_air.csv").open("w") as fh:
        fh.write("curtain_air_m3_s_per_m,material_outlet_C,air_outlet_C,heat_curtain_W,"
                 "heat_bed_W,curtain_passes\n")
        for p in evaluation.points:
            flow = "all" if p.curtain_air_m3_s_m is None else f"{p.curtain_air_m3_s_m:.6g}"
            passes = "" if p.curtain_passes is None else f"{p.curtain_passes:.6g}"
            fh.write(f"{flow},{p.material_outlet_c:.6g},{p.air_outlet_c:.6g},"
                     f"{p.heat_curtain_w:.6g},{p.heat_bed_w:.6g},{passes}\n")
    curtain_png = plot_curtain_air(evaluation.points, plant if evaluation.what_if else evaluation.base,
                                   root / "curtain_air.png", title)
    return PlantFromSliceFiles(root, result_path, root / "profile.csv", profile_png,
                               root / "curtain_air.csv", curtain_png)


def plot_drum(result: DrumResult, path: Path, title: str) -> Path:
    """Axial temperature profiles and the heat removed per metre, curtain and bed."""
    from drumflow._mpl import pyplot

    plt = pyplot()

    plant = result.plant
    fig, (ax, bx) = plt.subplots(2, 1, figsize=(7.0, 6.4), dpi=120, sharex=True,
                                 gridspec_kw={"height_ratios": [3, 2]})
    ax.plot(result.z_m, result.solids_c, "-", color="tab:brown", lw=2, label="solids (mean)")
    ax.plot(result.z_m, result.air_c, "--", color="tab:blue", lw=2, label="air")
    if plant.measured_material_outlet_c is not None:
        ax.plot([plant.length_m], [plant.measured_material_outlet_c], "s", color="tab:brown",
                ms=8, mfc="none", label=f"plant, measured NPK out {plant.measured_material_outlet_c:g} °C")
    if plant.measured_air_outlet_c is not None:
        ax.plot([0.0], [plant.measured_air_outlet_c], "o", color="tab:blue", ms=8, mfc="none",
                label=f"plant, measured air out {plant.measured_air_outlet_c:g} °C")
    ax.annotate("solids in →", (0, plant.material_inlet_temperature_c), fontsize=8,
                xytext=(4, -12), textcoords="offset points")
    ax.annotate("← air in", (plant.length_m, plant.air_inlet_temperature_c), fontsize=8,
                xytext=(-40, 6), textcoords="offset points")
    ax.set_ylabel("temperature (°C)")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8, loc="upper right")
    ax.set_title(title, fontsize=10)
    dz = plant.length_m / len(result.cell_curtain_w)
    centres = 0.5 * (result.z_m[1:] + result.z_m[:-1])
    bx.plot(centres, result.cell_curtain_w / dz / 1e3, "-", color="tab:orange", label="curtain")
    bx.plot(centres, result.cell_bed_w / dz / 1e3, "-", color="tab:green", label="bed surface")
    if result.wall_loss_w > 0:
        bx.plot(centres, result.cell_wall_w / dz / 1e3, "-", color="tab:gray", label="wall loss")
    bx.set_xlabel("distance from the solids inlet (m)")
    bx.set_ylabel("heat removed (kW/m)")
    bx.grid(alpha=0.3)
    bx.legend(fontsize=8)
    bx.set_xlim(-0.02 * plant.length_m, 1.02 * plant.length_m)  # keep the outlet markers whole
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)
    return path


def plot_curtain_air(points: list[CurtainAirPoint], plant: PlantSpec, path: Path,
                     title: str) -> Path:
    """NPK and air outlets over the through-curtain flow, with the all-air limit and the
    plant's measured outlets."""
    from drumflow._mpl import pyplot

    plt = pyplot()

    finite = [p for p in points if p.curtain_air_m3_s_m is not None]
    limit = [p for p in points if p.curtain_air_m3_s_m is None]
    q = [p.curtain_air_m3_s_m or 0.0 for p in finite]
    fig, ax = plt.subplots(figsize=(7.0, 4.6), dpi=120)
    ax.plot(q, [p.material_outlet_c for p in finite], "o-", color="tab:brown", label="NPK out")
    ax.plot(q, [p.air_outlet_c for p in finite], "s--", color="tab:blue", label="air out")
    for p in limit:
        ax.axhline(p.material_outlet_c, color="tab:brown", lw=0.8, ls=":",
                   label=f"all air meets the curtain: NPK {p.material_outlet_c:.1f} °C")
        ax.axhline(p.air_outlet_c, color="tab:blue", lw=0.8, ls=":",
                   label=f"all air meets the curtain: air {p.air_outlet_c:.1f} °C")
    if plant.measured_material_outlet_c is not None:
        ax.axhspan(plant.measured_material_outlet_c - 3, plant.measured_material_outlet_c + 3,
                   color="tab:brown", alpha=0.12,
                   label=f"plant NPK out {plant.measured_material_outlet_c:g} ± 3 °C")
    if plant.measured_air_outlet_c is not None:
        ax.axhline(plant.measured_air_outlet_c, color="tab:blue", lw=1.5, alpha=0.4,
                   label=f"plant air out {plant.measured_air_outlet_c:g} °C (a check)")
    ax.set_xlabel("air through the curtains (m³/s per metre of drum)")
    ax.set_ylabel("outlet temperature (°C)")
    ax.set_xscale("symlog", linthresh=1.0)
    ax.set_xlim(left=0.0)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7, loc="center right")
    ax.set_title(title, fontsize=9)
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)
    return path
