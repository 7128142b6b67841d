"""`drumflow paper`: run the paper's two cases and set every result beside the published one.

Without ``--from`` it runs (or resumes) each model's shipped case, ``cases/paper_model_one.toml``
and ``cases/paper_model_two.toml``, into ``OUT/model_one`` and ``OUT/model_two`` through the same
pipeline as ``drumflow run`` (a finished run is reused), then compares every model directory
that exists. With ``--from DIR`` it only reads: ``DIR/model_one`` and ``DIR/model_two`` may be
run directories or the small results ``studies/ship_paper_run.py`` ships, and the page is
redrawn without any solver. Either way it writes ``OUT/paper.json``, ``OUT/comparison.csv`` and
the HTML page (``--html``, default ``OUT/paper.html``).

Exit codes (:func:`drumflow.errors.exit_code`): 0 written, 1 a run failed, 2 bad input (an
option, a case file, a directory that holds no model), 130 interrupted (rerun to resume).
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Annotated, Any, Optional

import typer
from rich.markup import escape
from rich.table import Table

from drumflow.cli._guard import console, err_console
from drumflow.cli._progress import StageProgress, resume_hint
from drumflow.errors import CaseError, DrumflowError

_MODELS: dict[str, tuple[str, ...]] = {"one": ("one",), "two": ("two",), "both": ("one", "two")}
_CASE_FILES = {"one": "paper_model_one.toml", "two": "paper_model_two.toml"}


def _shipped_case(model: str) -> Path:
    """The shipped case file of a model: ./cases first, then the source tree's cases/."""
    import drumflow

    name = _CASE_FILES[model]
    candidates = [Path("cases") / name, Path(drumflow.__file__).resolve().parents[1] / "cases" / name]
    for path in candidates:
        if path.is_file():
            return path
    raise CaseError([f"--case: the shipped case {name} is in neither "
                     f"{', '.join(str(c.parent) for c in candidates)}; allowed: give --case FILE"])


def _finished(run_dir: Path, case_hash: str) -> bool:
    """A finished run of this case: its DEM stage marker and a summary of the same case."""
    summary = run_dir / "summary.json"
    if not ((run_dir / "stages" / "dem.json").is_file() and summary.is_file()):
        return False
    # A damaged summary is refused by name (BadFileError), not taken for an unfinished run:
    # rerunning would replace what only the finished run knows. Imported here: the CLI's
    # start-up loads no numerical library (drumflow.readers needs numpy).
    from drumflow.readers import read_json_object

    return bool(read_json_object(summary, "the run's summary").get("case_hash") == case_hash)


def _run_model(case_file: Path, out: Path, processes: int | None) -> None:
    from drumflow.case import load_case
    from drumflow.pipeline import run_case

    case = load_case(case_file)
    if processes is not None and processes != case.run.processes:
        # The case run_case will bind (it sets run.processes the same way), for the hash.
        from drumflow.case import Case

        data = case.model_dump(mode="json")
        data["run"]["processes"] = processes
        case = Case.model_validate(data)
    if _finished(out, case.hash()):
        err_console.print(f"{case.name}: finished run reused ({out})", highlight=False)
        return
    err_console.print(f"{case.name}: running into {out} (rerun the same command to resume)",
                      highlight=False)
    try:
        with StageProgress(err_console, prefix=f"{case.name} ") as progress:
            summary = run_case(case, out, processes=processes, progress=progress)
    except KeyboardInterrupt:
        err_console.print(resume_hint(out))
        raise
    if summary.get("status", "ok") != "ok":
        err_console.print(f"[bold red]{case.name}: {summary['status']}[/] (see {out}/summary.json)")
        raise typer.Exit(1)


def _print(runs: list[Any], paths: dict[str, Path]) -> None:
    for run in runs:
        table = Table(title=f"model {run.model}: {run.root}")
        for col in ("quantity", "paper", "drumflow", "difference", "relative", "unit"):
            table.add_column(col, justify="left" if col in ("quantity", "unit") else "right")
        for r in run.rows:
            table.add_row(r.quantity, f"{r.paper:.5g}", f"{r.drumflow:.5g}", f"{r.difference:+.4g}",
                          f"{r.relative:+.1%}" if r.relative == r.relative else "–", r.unit)
        console.print(table)
        sim, target = run.record.get("simulated_time_s"), run.record.get("target_time_s")
        if sim is not None:
            console.print(f"simulated {sim:.4g} of {target} s", highlight=False)
    console.print(f"written: {paths['json']}, {paths['csv']}, {paths['html']}", highlight=False)


def paper(
    model: Annotated[str, typer.Option("--model", help="'one', 'two' or 'both'")] = "both",
    out: Annotated[Path, typer.Option("--out", "-o", help="folder of the runs and the outputs")] = Path(
        "runs/paper"),
    np_: Annotated[Optional[int], typer.Option("--np", min=1, help="MPI processes per run")] = None,
    from_: Annotated[Optional[Path], typer.Option(
        "--from", help="read DIR/model_one, DIR/model_two (runs or shipped results); no solver")] = None,
    html: Annotated[Optional[Path], typer.Option("--html", help="the page (default OUT/paper.html)")] = None,
    case_file: Annotated[Optional[Path], typer.Option(
        "--case", help="run this case file instead of the shipped one (one --model only)")] = None,
    render_3d: Annotated[bool, typer.Option(
        "--3d/--no-3d", help="render the last snapshot of a run (Figure 6)")] = True,
    as_json: Annotated[bool, typer.Option("--json", help="print the comparison as JSON")] = False,
) -> None:
    """The paper's two cases: run them (or read them) and compare with Tables 3-8, Figures 4, 6-9."""
    from drumflow.readers import output_folder
    from drumflow.report.paper_page import write_paper
    from drumflow.report.paper_results import (
        MODEL_DIRS,
        collect_paper_run,
        find_model_dirs,
        needs_post,
    )

    output_folder(out)  # before any run: a file there would fail only after hours
    if model not in _MODELS:
        raise typer.BadParameter(f"{model!r}; allowed: 'one', 'two' or 'both'", param_hint="--model")
    models = _MODELS[model]
    if case_file is not None and len(models) != 1:
        raise typer.BadParameter("--case runs one model: give --model one or --model two",
                                 param_hint="--case")
    if from_ is not None and case_file is not None:
        raise typer.BadParameter("--from reads results and runs nothing: give --from or --case",
                                 param_hint="--from")
    if from_ is None:
        # Read every case before the first run starts: a bad case file fails in seconds.
        files = {m: case_file if case_file is not None else _shipped_case(m) for m in models}
        from drumflow.case import load_case

        for path in files.values():
            load_case(path)
        for m in models:
            _run_model(files[m], out / MODEL_DIRS[m], np_)  # type: ignore[index]
    root = from_ if from_ is not None else out
    dirs = find_model_dirs(root, models)  # type: ignore[arg-type]
    runs = []
    for m, path in dirs.items():
        try:
            if needs_post(path):
                from drumflow.pipeline import post_run

                post_run(path)
                err_console.print(f"model {m}: post-processed {path} (its dumps were newer)",
                                  highlight=False)
        except DrumflowError as exc:  # e.g. a dump still being written by a live run
            err_console.print(f"[yellow]note:[/] model {m}: not post-processed: {escape(str(exc))}",
                              highlight=False)
        runs.append(collect_paper_run(path, m, render_3d=render_3d))
    source = f"--from {root}" if from_ is not None else f"runs in {root}"
    paths = write_paper(runs, out, html, source=source)
    # On stderr, with --json too: the page and paper.json hold them, "written" alone would not.
    for run in runs:
        for note in run.notes:
            err_console.print(f"[yellow]note:[/] model {run.model}: {escape(note)}", highlight=False)
    if as_json:
        from drumflow._json import json_safe

        console.print_json(json.dumps(json_safe({
            **{k: str(v) for k, v in paths.items()},
            "models": {r.model: {"path": str(r.root), "kind": r.kind, "record": r.record,
                                 "comparison": [row.to_dict() for row in r.rows], "notes": r.notes}
                       for r in runs},
        }), default=str))
        return
    _print(runs, paths)
