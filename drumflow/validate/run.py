"""Run a validation scene and write what it found: ``validation.json``, a CSV per scene and a
plot of the simulated profile over the measured points (``drumflow validate NAME``)."""

from __future__ import annotations

import json
import math
import time
from dataclasses import asdict
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from drumflow._mpl import pyplot
from drumflow.rundir import write_json_atomic
from drumflow.validate.curtain_output import bookkeeping_closes, plot_curtain, write_curtain_csv
from drumflow.validate.errors import ValidationDataError
from drumflow.validate.particle_curtain import run_particle_curtain
from drumflow.validate.rolling_drum import (
    RPM,
    SURFACE_ANGLE_DEG,
    RollingDrumResult,
    run_rolling_drum,
)
from drumflow.validate.scenes import scene

if TYPE_CHECKING:
    from drumflow.dem.stage import ProgressCallback

#: The file every ``drumflow validate`` run adds its scene to.
VALIDATION_JSON = "validation.json"


def _finite(value: Any) -> Any:
    """JSON has no NaN: a missing number is null."""
    if isinstance(value, float) and not math.isfinite(value):
        return None
    if isinstance(value, dict):
        return {k: _finite(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [_finite(v) for v in value]
    return value


def write_profile_csv(path: Path, result: RollingDrumResult) -> None:
    """The simulated profile and the measured points in one table (``source`` says which)."""
    rows = ["source,normal_position_m,velocity_m_s,samples"]
    for s, u, n in zip(result.simulated.position, result.simulated.velocity, result.counts, strict=True):
        rows.append(f"simulated,{s:.6g},{'' if not np.isfinite(u) else f'{u:.6g}'},{int(n)}")
    for s, u in zip(result.measured.position, result.measured.velocity, strict=True):
        rows.append(f"measured,{s:.6g},{u:.6g},")
    path.write_text("\n".join(rows) + "\n")


def plot_profile(path: Path, result: RollingDrumResult, title: str) -> None:
    """Velocity down the slope against the position on the normal line: simulated line,
    measured points, and the solid-body line omega r."""
    plt = pyplot()

    fig, ax = plt.subplots(figsize=(5.5, 5.0), dpi=120)
    s = result.simulated.position
    ax.plot(result.simulated.velocity, s, "-", color="tab:blue", label="drumflow (LIGGGHTS)")
    ax.plot(result.measured.velocity, result.measured.position, "x", color="k",
            label="RPT, Alizadeh et al. 2013")
    omega = 2 * math.pi * RPM / 60
    ax.plot(omega * s, s, "-.", color="0.5", label=r"solid body $\omega r$")
    ax.axvline(0.0, color="0.8", lw=0.8)
    ax.set_xlabel("velocity parallel to the free surface, down-slope positive (m/s)")
    ax.set_ylabel("position on the normal through the axis (m)")
    ax.set_title(title, fontsize=9)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)


def run_validation(name: str, out: Path, scale: str | None = None, timeout: float | None = None,
                   progress: ProgressCallback | None = None) -> dict[str, Any]:
    """Run scene ``name`` at ``scale`` (default: the scene's first) into ``out``; add its record
    to ``out/validation.json``, write ``out/<name>_<scale>.csv`` and ``.png``; return the record.

    Raises
    ------
    ValidationDataError
        An unknown scene or scale.
    SolverError
        The solver failed.
    """
    sc = scene(name)
    scale = scale or sc.scales[0]
    if scale not in sc.scales:
        raise ValidationDataError(f"scale = {scale!r}: unknown for scene {name!r}; allowed: "
                                  f"{', '.join(sc.scales)}")
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    t0 = time.perf_counter()
    stem = f"{name}_{scale}"
    csv, png = out / f"{stem}.csv", out / f"{stem}.png"
    if name == "particle_curtain":
        body = _particle_curtain(out, scale, csv, png, timeout, progress)
    else:
        body = _rolling_drum(out, name, scale, csv, png, timeout, progress)
    record = {"scene": name, "scale": scale, "title": sc.title, "source": sc.source,
              "measures": list(sc.measures), "setup": [asdict(c) for c in sc.setup], **body,
              "csv": csv.name, "plot": png.name, "wall_time_s": time.perf_counter() - t0}
    record = _finite(record)
    path = out / VALIDATION_JSON
    scenes: dict[str, Any] = {}
    if path.is_file():
        try:
            scenes = json.loads(path.read_text()).get("scenes", {})
        except (json.JSONDecodeError, AttributeError):
            scenes = {}  # a file of another shape is replaced, not merged
    scenes[stem] = record
    data: dict[str, Any] = {"scenes": scenes}
    consistency = section_against_full(scenes, "rolling_drum")
    if consistency is not None:
        data["section_against_full"] = consistency
    write_json_atomic(path, data)
    return record


def _rolling_drum(out: Path, name: str, scale: str, csv: Path, png: Path, timeout: float | None,
                  progress: ProgressCallback | None) -> dict[str, Any]:
    """The rolling drum's run, CSV, plot and record entries."""
    result = run_rolling_drum(out / "runs", scale, timeout=timeout, progress=progress)
    write_profile_csv(csv, result)
    case = result.case
    plot_profile(png, result, f"{name} ({scale}): {case.particle_count:,} beads, "
                 f"{case.drum.length:g} m, ends {case.drum.ends}, "
                 f"t = {result.window_s[0]:.2f}-{result.window_s[1]:.2f} s")
    return {
        "case": {"name": case.name, "hash": case.hash(), "particles": case.particle_count,
                 "length_m": case.drum.length, "ends": case.drum.ends},
        "run_dir": str(result.run_dir),
        "averaging_window_s": list(result.window_s),
        "snapshots_averaged": result.snapshots_averaged,
        "comparison": result.comparison,
        "all_within_band": all(m["within_band"] for m in result.comparison.values()),
        "surface_angle_deg": {"simulated": result.surface_angle_deg, "paper": SURFACE_ANGLE_DEG},
    }


def _particle_curtain(out: Path, scale: str, csv: Path, png: Path, timeout: float | None,
                      progress: ProgressCallback | None) -> dict[str, Any]:
    """The curtain's runs, CSV, plot and record entries."""
    records = run_particle_curtain(out / "runs", scale, timeout=timeout, progress=progress)
    write_curtain_csv(csv, records)
    plot_curtain(png, records, scale)
    return {"experiments": records,
            "bookkeeping_closes": all(bookkeeping_closes(r["dem"]["bookkeeping"]) for r in records)}


def section_against_full(scenes: dict[str, Any], name: str) -> dict[str, Any] | None:
    """The periodic section's observables against the whole drum's (its middle), once both are
    in ``validation.json``: the check that the section stands for what the tracking measured.
    Each difference is judged by the scene's own agreement band; None until both ran."""
    section, full = scenes.get(f"{name}_section"), scenes.get(f"{name}_full")
    if section is None or full is None:
        return None
    out: dict[str, Any] = {}
    for key, f in full["comparison"].items():
        a, b = section["comparison"][key]["simulated"], f["simulated"]
        if a is None or b is None:
            out[key] = {"section": a, "full": b, "difference": None, "within_band": False}
            continue
        diff = (a - b) / abs(b) if f["error_kind"] == "relative" else a - b
        out[key] = {"section": a, "full": b, "difference": diff, "error_kind": f["error_kind"],
                    "band": f["band"], "within_band": abs(diff) <= f["band"]}
    return out
