"""`drumflow export RUN_DIR --vtk | --animation | --state`: a run directory as ParaView files,
as an animated GIF of the section coloured by temperature (Figure 6 in motion), or one full
snapshot as a start state (a small file to commit, which a case starts from with
``run.start_state``; :mod:`drumflow.dem.state`).

Exit codes (:func:`drumflow.errors.exit_code`): 0 written, 2 bad input (no format chosen, not a
run directory, missing snapshots or geometry, snapshots without spins).
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Annotated, Optional

import typer
from rich.table import Table

from drumflow.cli._guard import console
from drumflow.errors import RunDirectoryError


def export(
    run_dir: Annotated[Path, typer.Argument(help="run directory written by `drumflow run`")],
    vtk: Annotated[bool, typer.Option(
        "--vtk", help="particles (.vtu + .pvd), walls at each snapshot's drum angle, air (.vti)")] = False,
    animation: Annotated[bool, typer.Option(
        "--animation", help="the section coloured by temperature at every snapshot, as a GIF "
        "(RUN_DIR/post/section_temperature.gif unless --out)")] = False,
    speed: Annotated[float, typer.Option(
        "--seconds-per-simulated-second", min=0.01, max=100.0,
        help="--animation: playback seconds per simulated second")] = 1.0,
    state: Annotated[bool, typer.Option(
        "--state", help="one full snapshot as a start state (.npz; RUN_DIR/state_T.npz unless "
        "--out), for a case's run.start_state")] = False,
    time_s: Annotated[Optional[float], typer.Option(
        "--time", min=0.0, help="--state: the snapshot at this simulated time, s (default: the "
        "newest); with --phases the first phase's")] = None,
    phases: Annotated[Optional[int], typer.Option(
        "--phases", min=1, max=8, help="--state: this many states spread over one lifter "
        "period (the last the newest snapshot unless --time), into the --out folder (default "
        "RUN_DIR), for a case's air.bed_states")] = None,
    out: Annotated[Optional[Path], typer.Option(
        "--out", "-o", help="output folder (--vtk, default RUN_DIR/vtk) or file (--animation: "
        "GIF, --state: .npz)")] = None,
    as_json: Annotated[bool, typer.Option("--json", help="print what was written as JSON")] = False,
) -> None:
    """Write a run's snapshots, walls and air field for ParaView, its section animation, or a
    start state."""
    from drumflow.readers import output_file, output_folder
    from drumflow.report.vtk import export_vtk

    if vtk + animation + state != 1:
        raise RunDirectoryError("choose one export format: --vtk, --animation or --state")
    if time_s is not None and not state:
        raise RunDirectoryError("--time is for --state (the snapshot to make the state of)")
    if phases is not None and not state:
        raise RunDirectoryError("--phases is for --state (states over a lifter period)")
    if phases is not None:
        _phase_states(run_dir, phases, time_s, out, as_json)
        return
    if out is not None:
        # --vtk writes a folder of files, --animation and --state one file.
        (output_folder if vtk else output_file)(out)
    if state:
        _state(run_dir, time_s, out, as_json)
        return
    if animation:
        _animation(run_dir, out, speed, as_json)
        return
    result = export_vtk(run_dir, out)
    if as_json:
        console.print_json(json.dumps(result.as_dict()))
        return
    table = Table(title=f"{run_dir} → {result.out}", show_header=False)
    times = result.times_s
    table.add_row("particles", f"{result.particles_pvd}: {len(times)} snapshots, "
                  f"t = {times[0]:.3g}-{times[-1]:.3g} s, {max(result.particles):,} particles")
    table.add_row("walls", f"{result.walls_pvd}: turned by the drum angle at each snapshot")
    table.add_row("air", result.air or "none (the run has no air)")
    if result.air_bed_phases:
        table.add_row("air around the bed", f"{', '.join(result.air_bed_phases)}: the fields the "
                      "loop applied, one per bed state (air.vti is the empty drum's)")
    table.add_row("size", f"{result.bytes_written / 1e6:.2f} MB binary "
                  f"(text snapshots: {result.snapshot_text_bytes / 1e6:.2f} MB)")
    console.print(table)
    console.print(f"open in ParaView: paraview {Path(result.out) / result.particles_pvd} "
                  f"{Path(result.out) / result.walls_pvd}", highlight=False)


def _state(run_dir: Path, time_s: float | None, out: Path | None, as_json: bool) -> None:
    from drumflow.dem.state import state_from_run, write_state

    start = state_from_run(run_dir, time_s)
    path = write_state(start, out if out is not None else run_dir / f"state_{start.time_s:.4g}s.npz")
    size = path.stat().st_size
    record = {"path": str(path), "bytes": size, "particles": len(start), "time_s": start.time_s,
              "drum_angle_rad": start.drum_angle_rad, "case_hash": start.case_hash,
              "scene_hash": start.scene_hash, "source": start.source,
              "drumflow_version": start.drumflow_version}
    if as_json:
        console.print_json(json.dumps(record))
        return
    console.print(f"{path}: {len(start):,} particles at t = {start.time_s:.6g} s (drum angle "
                  f"{start.drum_angle_rad:.6g} rad), {size / 1e6:.3f} MB "
                  f"({size / max(len(start), 1):.1f} bytes per particle); start a case from it "
                  "with run.start_state", highlight=False)


def _phase_states(run_dir: Path, phases: int, time_s: float | None, out: Path | None,
                  as_json: bool) -> None:
    import math

    from drumflow.air.bed_phases import lifter_spacing
    from drumflow.case import load_case
    from drumflow.dem.state import phase_states, write_state
    from drumflow.readers import output_folder
    from drumflow.rundir import RunDir

    folder = output_folder(out) if out is not None else run_dir
    states = phase_states(run_dir, phases, time_s)
    folder.mkdir(parents=True, exist_ok=True)
    paths = [write_state(s, folder / f"state_{s.time_s:.4g}s.npz") for s in states]
    # Where each landed in the lifter period (the snapshots' spacing rounds the targets).
    spacing = lifter_spacing(load_case(RunDir.existing(run_dir).case_toml).lifters.count)
    assert spacing is not None  # phase_states refused a drum without lifters
    offsets = [math.degrees((s.drum_angle_rad - states[0].drum_angle_rad) % spacing) for s in states]
    records = [{"path": str(p), "time_s": s.time_s, "drum_angle_rad": s.drum_angle_rad,
                "phase_deg": o, "target_phase_deg": math.degrees(spacing) * k / phases}
               for k, (p, s, o) in enumerate(zip(paths, states, offsets, strict=True))]
    if as_json:
        console.print_json(json.dumps(records))
        return
    for r in records:
        console.print(f"{r['path']}: t = {r['time_s']:.6g} s, {r['phase_deg']:.1f} degrees into the "
                      f"{math.degrees(spacing):g}-degree lifter spacing (target "
                      f"{r['target_phase_deg']:.1f})", highlight=False)
    listed = ", ".join(f'"{p}"' for p in paths)
    console.print(f"for the case file:\n[air]\nbed_states = [{listed}]", highlight=False)


def _animation(run_dir: Path, out: Path | None, speed: float, as_json: bool) -> None:
    from drumflow.case import load_case
    from drumflow.report.animation import render_animation
    from drumflow.rundir import RunDir

    run = RunDir.existing(run_dir)
    result = render_animation(run, load_case(run.case_toml), out, seconds_per_simulated_second=speed)
    if as_json:
        console.print_json(json.dumps(result.as_dict()))
        return
    times = result.times_s
    console.print(f"{result.path}: {result.frames} frames, t = {times[0]:.3g}-{times[-1]:.3g} s at "
                  f"{result.fps:.3g} frames/s, colour scale {result.temperature_range_C[0]:.2f}-"
                  f"{result.temperature_range_C[1]:.2f} °C", highlight=False)
    if result.skipped:
        console.print(f"[yellow]unreadable snapshots skipped: {', '.join(result.skipped)}[/yellow]")
