"""`drumflow verify | bench | profile | answer | ladder`: checks against references, and speed."""

from __future__ import annotations

import json
import time
from pathlib import Path
from typing import Annotated, Any

import typer
from rich import box
from rich.table import Table

from drumflow.cli._common import load_case_file, records
from drumflow.cli._guard import console, err_console

__all__ = ["answer", "bench", "ladder", "profile", "verify"]


def verify(
    quick: Annotated[bool, typer.Option("--quick", help="only what fits in a couple of minutes")] = False,
    out: Annotated[
        Path, typer.Option("--out", "-o", help="where the cases and verification.json go")
    ] = Path("runs/verify"),
) -> None:
    """Run the verification cases (analytic solutions, conservation laws) on the real solvers."""
    from drumflow.readers import output_folder
    from drumflow.verify import run_verification

    output_folder(out)
    table = Table(title="drumflow verify" + (" --quick" if quick else ""))
    for col in ("check", "measured", "expected", "error", "tolerance", ""):
        table.add_column(col, justify="right" if col not in ("check", "") else "left")

    def show(c) -> None:  # type: ignore[no-untyped-def]
        mark = "[green]pass[/]" if c.passed else "[bold red]FAIL[/]"
        err_console.print(f"{mark} {c.name}: error {c.error:.3g} (tolerance {c.tolerance:.3g})",
                          highlight=False)
        table.add_row(c.name, f"{c.measured:.6g} {c.unit}", f"{c.expected:.6g}", f"{c.error:.3g}",
                      f"{c.tolerance:.3g}", mark)

    checks = run_verification(out, quick=quick, on_check=show)
    console.print(table)
    console.print(f"written: {out / 'verification.json'}", highlight=False)
    if not all(c.passed for c in checks):
        raise typer.Exit(1)


def bench(
    case_file: Annotated[Path, typer.Argument(help="reference scene: a case file (TOML)")],
    out: Annotated[Path | None, typer.Option("--out", "-o", help="bench directory")] = None,
    rungs: Annotated[
        str | None, typer.Option("--rungs", help="comma-separated rung names (default: all)")
    ] = None,
    time_s: Annotated[
        float | None,
        typer.Option("--time", min=0.01, help="simulated time per rung, s (default: the case's)"),
    ] = None,
    timeout: Annotated[
        float | None, typer.Option("--timeout", min=1, help="solver time limit per rung, s")
    ] = None,
    list_only: Annotated[bool, typer.Option("--list", help="list the rungs and exit")] = False,
    speed_only: Annotated[
        bool, typer.Option("--speed-only", help="no reference rung: run times only")
    ] = False,
    from_run: Annotated[
        Path | None, typer.Option("--from", help="LIGGGHTS settings side by side from a restart of "
                                  "this coupled run of the case (paper scale: the cascading bed)")
    ] = None,
    steps: Annotated[
        int, typer.Option("--steps", min=1, help="with --from: DEM steps per variant")
    ] = 400,
    restart: Annotated[
        int | None, typer.Option("--restart", min=0, help="with --from: restart step (default: newest)")
    ] = None,
    ranks: Annotated[
        int | None, typer.Option("--np", min=1, help="with --from: MPI ranks (default: the case's)")
    ] = None,
    builds: Annotated[
        str | None, typer.Option("--builds", help="with --from: LIGGGHTS builds side by side, "
                                 "interleaved ('debian' or install prefixes, comma-separated)")
    ] = None,
    levels: Annotated[
        bool, typer.Option("--levels", help="with --from: the run's physics levels side by side, "
                           "interleaved (one-way lumped, shells, air that warms, air around the "
                           "bed): their cost")
    ] = False,
    repeats: Annotated[
        int, typer.Option("--repeats", min=1, max=20, help="with --builds or --levels: runs of each")
    ] = 3,
) -> None:
    """Run time against error: a ladder of settings on one scene -> results.csv and pareto.png.

    With --from RUN_DIR: LIGGGHTS' settings (neighbour skin, rebuild rule, sorting, processor
    grid, the conservative reference) side by side from one restart of that run -> settings.csv;
    with --builds as well: LIGGGHTS builds (the Debian package, a -O3 -march=native build)
    interleaved A-B-A-B from that restart -> builds.csv and builds.json; with --levels: the
    run's physics levels the same way -> levels.csv and levels.json.
    """
    from drumflow.readers import output_folder

    if out is not None:
        output_folder(out)
    case = load_case_file(case_file)
    if from_run is not None:
        if time_s is not None or speed_only:
            raise typer.BadParameter("--time and --speed-only are for the ladder from a fresh "
                                     "start, not with --from", param_hint="--from")
        if builds is not None and levels:
            raise typer.BadParameter("one comparison at a time: --builds or --levels",
                                     param_hint="--levels")
        if builds is not None or levels:
            _bench_arms(case, from_run, out, builds, steps, restart, ranks, repeats, timeout)
            return
        _bench_from_run(case, from_run, out, rungs, steps, restart, ranks, timeout, list_only)
        return
    if builds is not None or levels:
        raise typer.BadParameter("--builds and --levels run from a restart: give --from RUN_DIR",
                                 param_hint="--builds" if builds is not None else "--levels")
    _bench_ladder(case, case_file, out, rungs, time_s, timeout, list_only, speed_only)


def _bench_ladder(case: Any, case_file: Path, out: Path | None, rungs: str | None,
                  time_s: float | None, timeout: float | None, list_only: bool,
                  speed_only: bool) -> None:
    """`drumflow bench CASE`: the ladder of settings from a fresh start, each rung run."""
    from drumflow.bench import run_bench
    from drumflow.bench.ladder import ladder, select
    from drumflow.case import case_from_dict

    if time_s is not None:
        data = case.model_dump(mode="json")
        data["run"]["time"] = time_s
        data["run"]["mass_flow_start"] = min(case.run.mass_flow_start, 0.5 * time_s)
        case = case_from_dict(data, source=case_file)
    names = [n.strip() for n in rungs.split(",") if n.strip()] if rungs else None
    try:
        chosen = select(ladder(case), names, speed_only)
    except ValueError as exc:  # an unknown rung name: bad input, exit 2 through click
        raise typer.BadParameter(str(exc), param_hint="--rungs") from None
    if list_only:
        for r in chosen:
            console.print(f"{r.name:18s} {r.group:12s} {r.description}", highlight=False)
        return
    out = out or Path("runs") / "bench" / case.name
    t0 = time.monotonic()

    def on_rung(rung, index: int, total: int, row: dict) -> None:  # type: ignore[no-untyped-def]
        elapsed = time.monotonic() - t0
        eta = elapsed / (index + 1) * (total - index - 1)
        wall = row.get("dem_wall_time_s")
        wall_txt = f"{wall:.1f} s" if isinstance(wall, (int, float)) else "-"
        err_console.print(f"[{index + 1}/{total}] {rung.name}: {row['status'][:120]}, DEM {wall_txt} "
                          f"(elapsed {elapsed / 60:.1f} min, ETA {eta / 60:.1f} min)", highlight=False)

    try:
        result = run_bench(case, out, names, timeout=timeout, on_rung=on_rung, speed_only=speed_only)
    except KeyboardInterrupt:
        err_console.print(f"run the same command again to resume into {out}")
        raise
    cols = [("rung", "rung", "{}"), ("dt/t_R", "fraction_of_rayleigh", "{:.2f}"),
            ("DEM s", "dem_wall_time_s", "{:.1f}"), ("speed-up", "speedup_vs_conservative", "{:.2f}"),
            ("err T", "err_temperature", "{:.2%}"), ("err h", "err_h", "{:.2%}"),
            ("err ṁ", "err_mass_flow", "{:.2%}"), ("front", "pareto", "{}")]
    console.print(_frame_table(f"drumflow bench {case.name} → {out}", result.table, cols))
    console.print(f"written: {result.csv}, {result.json}, {result.plot}", highlight=False)
    failed = [str(r["rung"]) for _, r in result.table.iterrows() if str(r["status"]).startswith("failed")]
    if failed:
        # A rung whose run failed is a failed run (exit 1), even though the table was written.
        err_console.print(f"[bold red]failed rung(s):[/] {', '.join(failed)}", highlight=False)
        raise typer.Exit(1)


def _frame_table(title: str, frame: Any, cols: list[tuple[str, str, str]], clip: int | None = None,
                 box_style: box.Box = box.HEAVY_HEAD) -> Table:
    """A table of a results frame: one column per (title, key, format); a missing or NaN value
    is blank; each cell cut to ``clip`` characters (a long status)."""
    table = Table(title=title, box=box_style)
    for column, _, _ in cols:
        table.add_column(column)
    for _, r in frame.iterrows():
        cells = []
        for _, key, fmt in cols:
            v = r.get(key)
            cells.append("" if v is None or (isinstance(v, float) and v != v) else fmt.format(v)[:clip])
        table.add_row(*cells)
    return table


def _bench_arms(case: Any, run_dir: Path, out: Path | None, builds: str | None, steps: int,
                restart: int | None, ranks: int | None, repeats: int, timeout: float | None) -> None:
    from drumflow.bench.interleaved import run_arms, speedup_line

    out = out or Path("runs") / "bench" / case.name / ("builds" if builds else "levels")
    ranks = ranks or case.run.processes
    t0 = time.monotonic()

    def on_run(arm: str, repeat: int, index: int, total: int, row: dict[str, Any] | None) -> None:
        elapsed = time.monotonic() - t0
        if row is None:
            err_console.print(f"[{index + 1}/{total}] {arm}, repeat {repeat + 1}: {steps} steps on "
                              f"{ranks} rank(s)... (elapsed {elapsed / 60:.1f} min)", highlight=False)
            return
        eta = elapsed / (index + 1) * (total - index - 1)
        busy = (f" [yellow](other programs took {row['other_programs_cores']:.2f} cores)[/]"
                if row["contended"] else "")
        physics = {True: ", physics ok", False: ", physics CHANGED", None: ""}[row["physics_ok"]]
        err_console.print(f"  {row['particle_steps_per_s']:,.0f} particle-steps/s{physics}{busy} "
                          f"(ETA {eta / 60:.1f} min)", highlight=False)

    result = run_arms(case, run_dir, out, builds=builds.split(",") if builds else None, steps=steps,
                      ranks=ranks, repeats=repeats, restart_step=restart, timeout=timeout or 3600.0,
                      on_run=on_run)
    for name in result.summary:
        console.print(speedup_line(result.summary, name, levels=builds is None), highlight=False)
    console.print(f"written: {result.csv}, {result.json}", highlight=False)


def _bench_from_run(case: Any, run_dir: Path, out: Path | None, rungs: str | None, steps: int,
                    restart: int | None, ranks: int | None, timeout: float | None,
                    list_only: bool) -> None:
    from drumflow.bench.settings import run_settings_study
    from drumflow.bench.settings_variants import VARIANTS

    if list_only:
        for v in VARIANTS:
            console.print(f"{v.name:22s} {v.description}", highlight=False)
        return
    names = [n.strip() for n in rungs.split(",") if n.strip()] if rungs else None
    out = out or Path("runs") / "bench" / case.name / "settings"
    ranks = ranks or case.run.processes
    t0 = time.monotonic()

    def on_variant(variant, index: int, total: int, row: dict | None) -> None:  # type: ignore[no-untyped-def]
        elapsed = time.monotonic() - t0
        if row is None:
            err_console.print(f"[{index + 1}/{total}] {variant.name}: {steps} steps of the baseline's "
                              f"time from the restart on {ranks} rank(s)... (elapsed {elapsed / 60:.1f} "
                              "min)", highlight=False)
            return
        eta = elapsed / (index + 1) * (total - index - 1)
        err_console.print(f"  {row['particle_steps_per_s']:,.0f} particle-steps/s, physics "
                          f"{'ok' if row['physics_ok'] else 'CHANGED'} (ETA {eta / 60:.1f} min)",
                          highlight=False)

    result = run_settings_study(case, run_dir, out, steps=steps, ranks=ranks, restart_step=restart,
                                only=names, timeout=timeout or 3600.0, on_variant=on_variant)
    cols = [("variant", "variant", "{}"), ("status", "status", "{}"),
            ("wall s", "coupled_wall_s", "{:.1f}"), ("particle-steps/s", "particle_steps_per_s", "{:,.0f}"),
            ("speed-up", "speedup_vs_baseline", "{:.2f}"), ("pair %", "pair_pct", "{:.0f}"),
            ("neigh %", "neigh_pct", "{:.0f}"), ("walls %", "walls_pct", "{:.0f}"),
            ("physics", "physics_ok", "{}")]
    console.print(_frame_table(f"drumflow bench {case.name} --from {run_dir} → {out}", result.table,
                               cols, clip=40, box_style=box.SIMPLE))
    if result.resumed:
        console.print(f"kept from the interrupted study: {', '.join(result.resumed)}", highlight=False)
    console.print(f"written: {result.csv}, {result.json}", highlight=False)
    if result.failed:
        err_console.print(f"[bold red]failed variant(s):[/] {', '.join(result.failed)}", highlight=False)
        raise typer.Exit(1)


def profile(
    run_dir: Annotated[Path, typer.Argument(help="run directory written by `drumflow run`")],
    window: Annotated[
        float, typer.Option("--window", min=1e-6, help="summary window, simulated seconds")
    ] = 0.5,
    out: Annotated[
        Path | None, typer.Option("--out", "-o", help="folder for profile.csv and profile.png "
                                  "(default: RUN_DIR/post)")
    ] = None,
    as_json: Annotated[bool, typer.Option("--json", help="print the windows as JSON")] = False,
) -> None:
    """Where the time goes: LIGGGHTS' timing breakdowns and the coupling loop's wall times."""
    from drumflow.bench.profile import profile_run, write_profile
    from drumflow.readers import output_folder
    from drumflow.rundir import RunDir

    if out is not None:
        output_folder(out)  # checked first: the profile of a long run takes a while
    result = profile_run(run_dir, window_s=window)
    folder = out or RunDir.existing(run_dir).post
    paths = write_profile(result, folder, title=f"{run_dir.name}: where the time goes")
    if as_json:
        console.print_json(json.dumps({"windows": records(result.windows),
                                       "files": {k: str(v) for k, v in paths.items()}}))
        return
    # Comm without the fixes' own communication, which LIGGGHTS also counts in the fixes.
    table = Table(title=f"{run_dir.name}: where the time goes, per {window:g} s simulated "
                  "(% of LIGGGHTS' loop in sampled intervals; comm outside the fixes)")
    cols = [("window (s)", None, ""), ("steps", "steps", "{:,.0f}"), ("pair", "pair_pct", "{:.1f}"),
            ("neigh", "neigh_pct", "{:.1f}"), ("walls", "walls_pct", "{:.1f}"),
            ("conduction", "conduction_pct", "{:.1f}"), ("air drag", "air_drag_pct", "{:.1f}"),
            ("comm", "comm_outside_fixes_pct", "{:.1f}"), ("output", "output_pct", "{:.1f}"),
            ("other", "other_net_pct", "{:.1f}"), ("neighs/atom", "neighs_per_atom", "{:.2f}"),
            ("builds/1000", "neighbor_builds_per_1000_steps", "{:.1f}"),
            ("Python %", "python_share", "{:.1%}"), ("particle-steps/s", "particle_steps_per_s", "{:,.0f}")]
    for title, _, _ in cols:
        table.add_column(title, justify="left" if title.startswith("window") else "right")
    for _, w in result.windows.iterrows():
        cells = [f"{w['window_start_s']:g}-{w['window_end_s']:g}"]
        for _, key, fmt in cols[1:]:
            value = w.get(key)
            cells.append("-" if value is None or value != value else fmt.format(value))
        table.add_row(*cells)
    console.print(table)
    console.print(f"{len(result.intervals)} sampled intervals; written: "
                  + ", ".join(str(p) for p in paths.values()), highlight=False)


def answer(
    run_dir: Annotated[Path, typer.Argument(help="run directory after `drumflow post`, or a shipped "
                                            "results folder (case.toml, post/)")],
    tolerance: Annotated[
        float, typer.Option("--tolerance", help="the stop rule's largest relative half-width, and "
                            "how close to the reference counts as settled")
    ] = 0.01,
    every: Annotated[
        float, typer.Option("--every", help="spacing of the replayed end times, simulated seconds")
    ] = 0.1,
    rate: Annotated[
        float | None, typer.Option("--rate", help="particle-steps per wall second for updates "
                                   "without logged wall times (default: the logged ones', else "
                                   "run_record.json)")
    ] = None,
    out: Annotated[
        Path | None, typer.Option("--out", "-o", help="folder for answer.csv, answer.json and "
                                  "answer.png (default: RUN_DIR/post)")
    ] = None,
    as_json: Annotated[bool, typer.Option("--json", help="print answer.json instead of a table")] = False,
) -> None:
    """Time to answer: what a run stopped earlier would report, and when the stop rule fires."""
    from drumflow.bench.answer import replay_answer
    from drumflow.bench.answer_result import QUANTITIES, write_answer
    from drumflow.readers import output_folder
    from drumflow.rundir import RunDir

    if out is not None:
        output_folder(out)  # checked first: the replay of a long run takes a while
    replay = replay_answer(run_dir, tolerance=tolerance, settle_tolerance=tolerance,
                           check_interval_s=every, particle_steps_per_s=rate)
    folder = out or RunDir.existing(run_dir).post
    paths = write_answer(replay, folder, title=f"{run_dir.name}: time to answer")
    summary = replay.to_dict()
    if as_json:
        console.print_json(json.dumps({**summary, "files": {k: str(v) for k, v in paths.items()}}))
        return
    console.print(_answer_table(replay, run_dir.name, tolerance))
    rule = summary["rule"]
    if rule["first_fire_s"] is None:
        console.print(f"stop rule: {rule['reason']}", highlight=False)
    else:
        console.print(f"stop rule: fires at {rule['first_fire_s']:.4g} s (wall "
                      f"{rule['wall_at_first_fire_s'] or float('nan'):,.0f} s): {rule['reason']}",
                      highlight=False)
    for name, (_, label) in QUANTITIES.items():
        when = replay.settled_s[name]
        value = summary["reference"]["values"][name]
        console.print(f"{label} = {value:.6g}: within {tolerance:.0%} from "
                      f"{'never' if when is None else f'{when:.4g} s'}", highlight=False)
    steady = replay.settled_s["steady_mass_flow"]
    ref = summary["reference"]
    console.print(f"falling mass flow of the cascading bed (window from "
                  f"{ref['steady_start_s']:.3g} s, MSER) = {ref['steady_mass_flow_kg_s']:.6g}: within "
                  f"{tolerance:.0%} from {'never' if steady is None else f'{steady:.4g} s'}",
                  highlight=False)
    wall = replay.wall
    console.print(f"wall time: {wall['source']} (rate {wall['particle_steps_per_s'] or float('nan'):,.0f} "
                  f"particle-steps/s from {wall['rate_source']})", highlight=False)
    for note in replay.notes:
        console.print(f"note: {note}", highlight=False)
    console.print("written: " + ", ".join(str(p) for p in paths.values()), highlight=False)


def _answer_table(replay: Any, name: str, tolerance: float) -> Table:
    """The replay's table: what a run stopped at each t reports, against the reference."""
    table = Table(title=f"{name}: what a run stopped at t reports (Δ: against "
                  f"{replay.reference_time_s:.4g} s; rule: widest interval, fires at ±{tolerance:.0%})",
                  box=box.SIMPLE, padding=(0, 1))
    cols = [("t s", "time_s", "{:.2f}"), ("T3.5 °C", "temperature_C", "{:.3f}"),
            ("Δ", "rel_temperature", "{:+.2%}"), ("ṁ kg/s", "mass_flow_kg_s", "{:.2f}"),
            ("Δ", "rel_mass_flow", "{:+.1%}"), ("h W/m²K", "h_W_m2K", "{:.2f}"),
            ("Δ", "rel_h", "{:+.2%}"), ("rule ±", "converged", "{}"), ("wall s", "wall_s", "{:,.0f}")]
    for title, _, _ in cols:
        table.add_column(title, justify="right")
    for _, row in replay.table.iterrows():
        cells = []
        for _, key, fmt in cols:
            value = row[key]
            if key == "converged":
                # The wider of the two intervals the rule compares with the tolerance.
                widest = max(row["monitor_h_rel_half_width"], row["monitor_mass_flow_rel_half_width"])
                cells.append("fires" if value else "-" if widest != widest else f"{widest:.1%}")
            else:
                cells.append("-" if value is None or value != value else fmt.format(value))
        table.add_row(*cells)
    return table


def ladder(
    spec: Annotated[Path, typer.Argument(help="ladder spec (TOML): the rungs' runs, how each "
                                         "stops, the reference")],
    out: Annotated[
        Path | None, typer.Option("--out", "-o", help="folder for ladder.csv, ladder.json and "
                                  "ladder.png (default: the spec's folder)")
    ] = None,
    as_json: Annotated[bool, typer.Option("--json", help="print ladder.json instead of a table")] = False,
) -> None:
    """Time-to-answer ladder: wall time and errors of several runs of a scene against one
    reference run (runs are replayed, not rerun)."""
    from drumflow.bench.time_to_answer import (
        LADDER_QUANTITIES,
        answer_ladder,
        load_ladder_spec,
        write_ladder,
    )
    from drumflow.readers import output_folder

    if out is not None:
        output_folder(out)
    result = answer_ladder(load_ladder_spec(spec))
    paths = write_ladder(result, out or spec.parent)
    if as_json:
        console.print_json(json.dumps({**result.to_dict(),
                                       "files": {k: str(v) for k, v in paths.items()}}))
        return
    answers = result.spec.answers
    table = Table(title=f"{result.spec.title} (errors against '{result.spec.reference}'; "
                  f"answer known within ±{result.spec.tolerance:.0%})", box=box.SIMPLE,
                  padding=(0, 1))
    for title in ("rung", "stop", "at s", "wall h", "contended", "faster",
                  *(f"Δ {LADDER_QUANTITIES[q].short}" for q in answers), "known"):
        table.add_column(title, justify="left" if title in ("rung", "stop") else "right")
    for _, row in result.table.iterrows():
        wall = row["wall_s"]
        cells = [row["rung"], row["stop"],
                 "never" if row["stop_time_s"] != row["stop_time_s"] else f"{row['stop_time_s']:.3g}",
                 "-" if wall != wall else f"{wall / 3600:.2f}{'*' if row['wall_estimated'] else ''}",
                 "-" if row["contended_share"] != row["contended_share"]
                 else f"{row['contended_share']:.0%}",
                 "-" if row["speedup"] != row["speedup"] else f"{row['speedup']:.2f}×",
                 *(f"{row[f'error_{q}']:+.2%}" for q in answers),
                 "yes" if row["within_tolerance"] else "no"]
        table.add_row(*cells)
    console.print(table)
    floor = ", ".join(f"{q} ±{result.noise_floor[q]:.2%}" for q in answers)
    console.print(f"noise floor (the reference's half-widths): {floor}; "
                  "* wall time estimated (scaled or partly from a rate); contended: the share "
                  "of the run's logged wall time other programs took a core's tenth or more "
                  "(- no load log), a speed result only near 0 %", highlight=False)
    for _, row in result.table.iterrows():
        console.print(f"{row['rung']}: {row['note']}", highlight=False)
    console.print("written: " + ", ".join(str(p) for p in paths.values()), highlight=False)

