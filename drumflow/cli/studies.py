"""`drumflow sweep | validate`: studies of many runs. A sweep runs member cases here or on
SLURM, watches them and analyses them; validate runs a scene that experiments measured and
sets the result beside the measurement.

Exit codes (:func:`drumflow.errors.exit_code`): 0 every member done (or the analysis written),
1 a member failed or SLURM failed, 2 bad input (sweep file, member case, arguments), 130
interrupted (rerun the same command to resume). A refused sweep leaves no directory behind.
"""

from __future__ import annotations

import json
import signal
import time
from pathlib import Path
from typing import Annotated, Any, Optional

import typer
from rich.live import Live
from rich.markup import escape
from rich.table import Table

from drumflow.cli._common import records, rough_duration
from drumflow.cli._guard import console, err_console
from drumflow.cli._progress import StageProgress
from drumflow.errors import EXIT_BAD_INPUT, DrumflowError, exit_code

__all__ = ["sweep", "validate"]

_STYLE = {"done": "green", "running": "cyan", "pending": "white", "failed": "bold red",
          "interrupted": "yellow"}


def _table(name: str, rows: list[Any], executor: str) -> Table:
    from drumflow.sweep.spec import format_value, short_axis

    counts: dict[str, int] = {}
    for r in rows:
        counts[r.state] = counts.get(r.state, 0) + 1
    summary = ", ".join(f"{v} {k}" for k, v in sorted(counts.items()))
    table = Table(title=f"sweep {name} ({executor}): {summary}")
    axes = list(rows[0].member.values) if rows else []
    table.add_column("member")
    for axis in axes:
        table.add_column(short_axis(axis), justify="right")
    for col in ("state", "simulated", "ETA", "attempts", "job @ node"):
        table.add_column(col, justify="left" if col in ("state", "job @ node") else "right")
    for r in rows:
        sim = "–" if r.simulated_s is None else f"{r.simulated_s:.2f} / {r.total_s:g} s"
        eta = rough_duration(r.eta_s) if r.state == "running" else ("0 s" if r.state == "done" else "–")
        table.add_row(r.member.id, *[format_value(r.member.values[a]) for a in axes],
                      f"[{_STYLE.get(r.state, 'white')}]{r.state}[/]", sim, eta,
                      str(r.attempts), r.where)
    return table


def sweep(
    target: Annotated[Path, typer.Argument(
        help="sweep file (TOML), or a sweep directory to resume, watch or analyse")],
    out: Annotated[Optional[Path], typer.Option(
        "--out", "-o", help="sweep directory (default runs/sweep/<name>)")] = None,
    executor: Annotated[Optional[str], typer.Option(
        "--executor", "-e", help="'local' or 'slurm' (default: the sweep file's)")] = None,
    max_parallel: Annotated[Optional[int], typer.Option(
        "--max-parallel", min=1,
        help="members at once (local: still at most cores // ranks; slurm: %N)")] = None,
    requeue_failed: Annotated[bool, typer.Option(
        "--requeue-failed", help="run failed members again (from their restarts)")] = False,
    check: Annotated[bool, typer.Option(
        "--check", help="validate and list the members; run nothing")] = False,
    no_wait: Annotated[bool, typer.Option(
        "--no-wait", help="slurm: submit and return; rerun to watch")] = False,
    analyse: Annotated[bool, typer.Option(
        "--analyse", "--analyze",
        help="fit Nu-Re-Pr over the done members and write the report")] = False,
    as_json: Annotated[bool, typer.Option(
        "--json", help="print the final states (or the analysis) as JSON")] = False,
) -> None:
    """Run many cases over operating conditions (rpm, air flow, fill, ...) here or on SLURM."""
    from drumflow.readers import output_folder
    from drumflow.sweep.driver import failure_report, open_sweep, run_sweep
    from drumflow.sweep.spec import SweepError

    if executor not in (None, "local", "slurm"):
        raise SweepError([f"--executor = {executor!r}: allowed: 'local' or 'slurm'"])
    if out is not None:
        output_folder(out)
    sd = open_sweep(target, out)
    if analyse:
        _analyse(sd, as_json)
        return
    if check:
        table = _table(sd.sweep.name, _static_rows(sd), executor or sd.sweep.executor.kind)
        console.print(table)
        console.print(f"{len(sd.members)} members valid; directory {sd.root}", highlight=False)
        return
    try:
        ex = _executor(sd, executor, max_parallel)
    except DrumflowError as exc:
        _forget_refused(sd, exc)
        raise
    # A SIGTERM (a batch system, `kill`) stops the session like Ctrl-C: members resumable.
    signal.signal(signal.SIGTERM, signal.default_int_handler)
    live = Live(console=err_console, refresh_per_second=2, transient=False)
    try:
        with live:
            outcome = run_sweep(
                sd, ex, requeue_failed=requeue_failed, wait=not no_wait,
                on_status=lambda rows: live.update(_table(sd.sweep.name, rows, ex.kind)),
            )
            live.update(_table(sd.sweep.name, outcome.statuses, ex.kind))
    except DrumflowError as exc:
        _forget_refused(sd, exc)
        raise
    if as_json:
        console.print_json(json.dumps([{
            "member": s.member.id, "values": s.member.values, "state": s.state,
            "simulated_s": s.simulated_s, "attempts": s.attempts,
            "job_id": s.attempt.job_id if s.attempt else None,
            "node": s.attempt.node if s.attempt else None,
        } for s in outcome.statuses], default=str))
    if outcome.interrupted:
        err_console.print(f"interrupted: {outcome.message}", highlight=False)
        raise typer.Exit(130)
    for s in outcome.failed:
        err_console.print(f"[bold red]failed:[/] {failure_report(s)}", highlight=False)
    if outcome.failed:
        err_console.print(f"{len(outcome.failed)} member(s) failed; fix the cause, then rerun with "
                          "--requeue-failed (they resume from their restart files)", highlight=False)
        raise typer.Exit(1)
    if no_wait and not outcome.all_done:
        err_console.print(f"submitted; run `drumflow sweep {sd.root}` to watch", highlight=False)
        return
    err_console.print(f"all {len(sd.members)} members done; next: drumflow sweep {sd.root} --analyse",
                      highlight=False)


def _forget_refused(sd: Any, exc: BaseException) -> None:
    """A refused session (bad input: the executor cannot run these members here) leaves
    nothing behind: the sweep directory it made is removed, if no member was started in it.
    A directory the user already had is never touched."""
    import shutil

    if sd.created and exit_code(exc) == EXIT_BAD_INPUT and not sd.ledger.attempts:
        shutil.rmtree(sd.root, ignore_errors=True)


def _static_rows(sd: Any) -> list[Any]:
    from drumflow.sweep.driver import statuses

    return statuses(sd)


def _executor(sd: Any, kind: str | None, max_parallel: int | None) -> Any:
    from drumflow.sweep.local import LocalExecutor
    from drumflow.sweep.slurm import SlurmExecutor

    spec = sd.sweep.executor
    kind = kind or spec.kind
    if kind == "local":
        local = spec.local if max_parallel is None else spec.local.model_copy(
            update={"max_parallel": max_parallel})
        return LocalExecutor(sd.root, local, sd.sweep.runs)
    settings = spec.slurm if max_parallel is None else spec.slurm.model_copy(
        update={"max_parallel": max_parallel})
    return SlurmExecutor(sd.root, settings, sd.sweep.runs, sd.sweep.name, len(sd.members))


def _analyse(sd: Any, as_json: bool) -> None:
    from drumflow.report.page_parts import fmt as _fmt
    from drumflow.sweep.analyse import (
        analyse_sweep,
        correlation_to_dict,
        write_sweep_report,
    )

    t0 = time.monotonic()
    analysis = analyse_sweep(sd)
    page = write_sweep_report(analysis)
    if as_json:
        console.print_json(json.dumps({
            "report": str(page), "member_fit": correlation_to_dict(analysis.member_fit),
            "step_fit": correlation_to_dict(analysis.step_fit),
            "members": records(analysis.table),
        }, default=float))
        return
    fits = Table(title=f"sweep {sd.sweep.name}: Nu = a Re^b Pr^c")
    for col in ("fit", "points", "a", "b (95 %)", "c", "adj. R²"):
        fits.add_column(col, justify="left" if col == "fit" else "right")
    for name, f, err in (
        ("member means (honest)", analysis.member_fit, analysis.member_fit_error),
        ("all steps (paper's; too narrow)", analysis.step_fit, analysis.step_fit_error),
    ):
        if f is None:
            fits.add_row(name, "–", f"not possible: {err}", "", "", "")
        else:
            fits.add_row(name, str(f.n), _fmt(f.a, 4),
                         f"{f.b:.3g} [{f.ci_b[0]:.3g}, {f.ci_b[1]:.3g}]",
                         _fmt(f.c, 4) + ("" if f.prandtl_exponent_fitted else " (held)"),
                         _fmt(f.adjusted_r_squared, 4))
    console.print(fits)
    t = analysis.table
    if len(t):
        members = Table(title="members")
        cols = ["member", *[a for a in sd.sweep.axes if a in t.columns], "h_mean_W_m2K",
                "reynolds_mean", "falling_mass_flow_kg_s", "plant_material_outlet_C",
                "fit_material_outlet_C"]
        cols = [c for c in cols if c in t.columns]
        for c in cols:
            members.add_column(c.replace("_", " "), justify="right")
        for _, row in t.iterrows():
            members.add_row(*[_fmt(row[c], 4) for c in cols])
        console.print(members)
    for m in analysis.members:
        if m.result is None:
            err_console.print(f"[yellow]not analysed:[/] {m.member.id}: {m.why_not}", highlight=False)
    console.print(f"report: {page} ({time.monotonic() - t0:.1f} s)", highlight=False)


def validate(
    name: Annotated[str | None, typer.Argument(help="scene to run (see --list)")] = None,
    list_only: Annotated[bool, typer.Option("--list", help="name each scene, its source and what "
                                            "it measures, and exit")] = False,
    out: Annotated[
        Path, typer.Option("--out", "-o", help="where the runs, validation.json, CSVs and plots go")
    ] = Path("runs/validate"),
    scale: Annotated[
        str | None, typer.Option("--scale", help="the scene's scale (--list names them; default the "
                                 "first): rolling_drum small|section|full, particle_curtain "
                                 "parcels|short|finer")
    ] = None,
    timeout: Annotated[float | None, typer.Option("--timeout", min=1, help="solver time limit, s")] = None,
) -> None:
    """Compare with experiments: run a validation scene and write validation.json, a CSV and a plot."""
    from drumflow.readers import output_folder
    from drumflow.validate import SCENES

    if list_only or name is None:
        for sc in SCENES.values():
            console.print(f"[bold]{sc.name}[/]: {escape(sc.title)}", highlight=False)
            console.print(f"  source: {escape(sc.source)}", highlight=False)
            for m in sc.measures:
                console.print(f"  measures: {escape(m)}", highlight=False)
            console.print(f"  scales: {', '.join(sc.scales)} (default {sc.scales[0]})", highlight=False)
        if name is None and not list_only:
            raise typer.BadParameter("give a scene name, or --list", param_hint="NAME")
        return
    from drumflow.validate.run import run_validation

    output_folder(out)
    with StageProgress(err_console) as progress:
        record = run_validation(name, out, scale, timeout=timeout, progress=progress)
    if "experiments" in record:
        console.print(_curtain_table(record))
    else:
        console.print(_profile_table(record))
    console.print(f"written: {out / 'validation.json'}, {out / record['csv']}, {out / record['plot']}",
                  highlight=False)


def _num(v: Any) -> str:
    return "n/a" if v is None else f"{v:.4g}"


def _profile_table(record: dict[str, Any]) -> Table:
    """The rolling drum's observables against the measured ones."""
    table = Table(title=f"drumflow validate {record['scene']} ({record['scale']})")
    for col in ("observable", "simulated", "measured", "error", "band", ""):
        table.add_column(col, justify="right" if col not in ("observable", "") else "left")
    for key, m in record["comparison"].items():
        err = m["error"]
        err_text = "n/a" if err is None else (f"{100 * err:+.1f} %" if m["error_kind"] == "relative"
                                              else f"{1e3 * err:+.1f} mm")
        band = f"{100 * m['band']:g} %" if m["error_kind"] == "relative" else f"{1e3 * m['band']:g} mm"
        table.add_row(key, _num(m["simulated"]), _num(m["measured"]), err_text, band,
                      "[green]within[/]" if m["within_band"] else "[bold red]outside[/]")
    return table


def _curtain_table(record: dict[str, Any]) -> Table:
    """The curtain's experiments: the DEM's answer beside the reduced-order model's."""
    table = Table(title=f"drumflow validate {record['scene']} ({record['scale']}): CFD-DEM / "
                  "reduced-order model")
    for col in ("experiment", "duty W", "solids out °C", "gas out °C", "speed at floor m/s",
                "drift m", "bookkeeping", "wall s"):
        table.add_column(col, justify="left" if col == "experiment" else "right")
    for r in record["experiments"]:
        dem, rom = r["dem"], r["reduced_order"]

        def pair(key: str, dem: dict[str, Any] = dem, rom: dict[str, Any] = rom) -> str:
            return f"{_num(dem[key])} / {_num(rom[key])}"
        book = dem["bookkeeping"]
        closes = (f"{int(book['fed']):,} fed, {int(book['count_residual'])} missing, "
                  f"energy {book['energy_residual']:.1e}")
        table.add_row(r["experiment"], pair("heat_duty_W"), pair("solids_outlet_C"),
                      pair("gas_outlet_C"), pair("outlet_speed_m_s"), pair("outlet_drift_m"), closes,
                      f"{r['wall_time_s']:.0f}")
    return table

