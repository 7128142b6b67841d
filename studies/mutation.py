"""Mutation testing of the reduced-order cooler models, the coupling laws and the air tables
(issue 36), with mutmut 3. Driven by ``studies/mutation.sh``; see README "Mutation testing".

The work tree is never touched: the tracked files are copied to a scratch directory
(default ``/tmp/drumflow-mutation``), mutmut's configuration is appended to the copy's
``pyproject.toml``, and mutmut makes its ``mutants/`` there. The venv's editable install of
drumflow is shadowed because mutmut puts ``mutants/`` first on ``sys.path``.

    python studies/mutation.py [--modules curtain physics ...] [--max-children 1]

writes ``results/mutation/summary.json`` (killed / total per module, wall time; runs of
other modules are kept) and ``results/mutation/survivors_raw/<module>.md`` (every surviving
mutant's diff); ``results/mutation/survivors.md`` is the hand-written triage of those.
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import subprocess
import sys
import time
from importlib import metadata
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

#: Module -> (source file, unit tests that exercise it). The law tests of issue 36 first.
MODULES: dict[str, tuple[str, list[str]]] = {
    "physics": ("drumflow/physics/particle_air.py",
                ["tests/unit/test_laws_coupling.py", "tests/unit/test_coupling_physics.py"]),
    "air_properties": ("drumflow/physics/air.py",
                       ["tests/unit/test_laws_air_properties.py", "tests/unit/test_air_properties.py",
                        "tests/unit/test_grate_air_properties.py"]),
    # The grate's hot-air table is now physics/air.py's kelvin view ("air_properties" above);
    # grate/properties.py keeps the packed-bed correlation, Ergun, the clinker and radiation.
    "grate_properties": ("drumflow/coolers/grate/properties.py",
                         ["tests/unit/test_laws_grate.py", "tests/unit/test_grate.py"]),
    "curtain": ("drumflow/coolers/curtain.py",
                ["tests/unit/test_laws_curtain.py", "tests/unit/test_curtain.py"]),
    "grate_model": ("drumflow/coolers/grate/model.py",
                    ["tests/unit/test_laws_grate.py", "tests/unit/test_grate.py"]),
    "drum": ("drumflow/coolers/drum.py",
             ["tests/unit/test_laws_drum.py", "tests/unit/test_drum_model.py"]),
    "drum_closures": ("drumflow/coolers/drum_closures.py",
                      ["tests/unit/test_laws_drum.py", "tests/unit/test_drum_model.py"]),
    "predict": ("drumflow/coolers/prediction.py",
                ["tests/unit/test_laws_drum.py", "tests/unit/test_predict.py"]),
    "fluid_bed": ("drumflow/coolers/fluid_bed.py",
                  ["tests/unit/test_laws_fluid_bed.py", "tests/unit/test_fluid_bed.py"]),
    "fluidization": ("drumflow/coolers/_fluidization.py",
                     ["tests/unit/test_laws_fluid_bed.py", "tests/unit/test_fluid_bed.py"]),
    "refrigeration": ("drumflow/coolers/refrigeration.py",
                      ["tests/unit/test_laws_refrigeration.py", "tests/unit/test_refrigeration.py"]),
    "particle_interior": ("drumflow/physics/particle_interior.py",
                          ["tests/unit/test_laws_curtain.py", "tests/unit/test_particle_interior.py",
                           "tests/unit/test_shell_batch.py"]),
}

#: Shipped results the selected tests read (the rest of results/ is not copied).
RESULTS_READ = ("results/paper/model_one/post/closures.json",)

#: mutmut 3 exit codes of a mutant's test run (mutmut/__main__.py, status_by_exit_code).
KILLED, SURVIVED = {1, 3}, {0}
#: No selected test calls the mutated function (mutmut's "no tests"): not run, and not a kill.
NOT_COVERED = 33


def _copy_tree(scratch: Path) -> None:
    files = subprocess.run(["git", "-C", str(ROOT), "ls-files", "-co", "--exclude-standard"],
                           check=True, capture_output=True, text=True).stdout.split("\n")
    if scratch.exists():
        shutil.rmtree(scratch)
    for name in filter(None, files):
        src = ROOT / name
        if src.is_file() and (name in RESULTS_READ
                              or not name.startswith((".venv/", "results/", "runs/"))):
            dst = scratch / name
            dst.parent.mkdir(parents=True, exist_ok=True)
            shutil.copy2(src, dst)


def _configure(scratch: Path, names: list[str], timeout_multiplier: float) -> None:
    sources = [MODULES[n][0] for n in names]
    tests = sorted({t for n in names for t in MODULES[n][1]})
    block = ["", "[tool.mutmut]", 'source_paths = ["drumflow"]',
             "only_mutate = " + json.dumps(sources),
             "pytest_add_cli_args_test_selection = " + json.dumps(tests),
             'pytest_add_cli_args = ["-p", "no:cacheprovider", "-x", "-q"]',
             # Folders (mutmut copies a file only where its folder exists): the scratch copy
             # holds nothing else of results/.
             "also_copy = " + json.dumps(["cases", *sorted({str(Path(f).parent) for f in RESULTS_READ})]),
             "use_git_change_detection = false",
             # A mutant whose tests take longer than this many times the unmutated run is a
             # timeout (not a kill); the grate's slow mutants cost 120-320 CPU s each at 15.
             f"timeout_multiplier = {timeout_multiplier!r}", ""]
    with (scratch / "pyproject.toml").open("a") as fh:
        fh.write("\n".join(block))


def _status(scratch: Path, names: list[str]) -> dict[str, dict[str, list[str]]]:
    """Per module: mutant names by outcome, from mutmut's .meta files."""
    out: dict[str, dict[str, list[str]]] = {}
    for n in names:
        meta = scratch / "mutants" / (MODULES[n][0] + ".meta")
        codes: dict[str, int | None] = {}
        if meta.exists():
            codes = json.loads(meta.read_text()).get("exit_code_by_key", {})
        groups: dict[str, list[str]] = {"killed": [], "survived": [], "not_covered": [], "other": []}
        for key, code in sorted(codes.items()):
            kind = ("killed" if code in KILLED else "survived" if code in SURVIVED
                    else "not_covered" if code == NOT_COVERED else "other")
            groups[kind].append(key)
        out[n] = groups
    return out


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--modules", nargs="+", default=list(MODULES), choices=list(MODULES))
    parser.add_argument("--scratch", type=Path, default=Path("/tmp/drumflow-mutation"))
    parser.add_argument("--max-children", type=int, default=1,
                        help="parallel mutmut workers (default 1: the machine is shared)")
    parser.add_argument("--timeout-multiplier", type=float, default=15.0,
                        help="mutmut's timeout_multiplier (default 15, mutmut's own); recorded in "
                        "the summary, since a timeout is not counted as a kill")
    parser.add_argument("--out", type=Path, default=ROOT / "results" / "mutation")
    parser.add_argument("--report-only", action="store_true",
                        help="summarise the last run in --scratch without running mutmut")
    args = parser.parse_args()
    mutmut = Path(sys.executable).with_name("mutmut")
    wall_file = args.scratch / "wall_time_s"
    if not args.report_only:
        _copy_tree(args.scratch)
        if not args.timeout_multiplier > 0:
            parser.error(f"--timeout-multiplier = {args.timeout_multiplier:g}: must be positive")
        _configure(args.scratch, args.modules, args.timeout_multiplier)
        start = time.perf_counter()
        env = {**os.environ, "PYTHONDONTWRITEBYTECODE": "1"}
        subprocess.run([str(mutmut), "run", "--max-children", str(args.max_children)],
                       cwd=args.scratch, env=env, check=False, stdout=subprocess.DEVNULL)
        wall_file.write_text(f"{time.perf_counter() - start:.1f}")
    wall = float(wall_file.read_text()) if wall_file.exists() else float("nan")
    status = _status(args.scratch, args.modules)
    args.out.mkdir(parents=True, exist_ok=True)
    summary_path = args.out / "summary.json"
    # Runs of different modules add up: keep the modules of earlier runs.
    earlier = json.loads(summary_path.read_text())["modules"] if summary_path.exists() else {}
    summary = {
        "tool": "mutmut " + metadata.version("mutmut"),
        "wall_time_s": round(wall, 1),
        "modules": {n: {"source": MODULES[n][0], "tests": MODULES[n][1],
                        "killed": len(g["killed"]), "survived": len(g["survived"]),
                        "not_covered_by_the_tests": len(g["not_covered"]),
                        "not_run_or_timeout": len(g["other"]),
                        "total": sum(len(v) for v in g.values()),
                        "score": (f"{len(g['killed'])}/{sum(len(v) for v in g.values())}")}
                    for n, g in status.items()},
    }
    this_run: dict[str, dict[str, object]] = summary["modules"]  # type: ignore[assignment]
    for entry in this_run.values():
        entry["wall_time_s_of_run"] = round(wall, 1)
        entry["run_together_with"] = args.modules
        entry["timeout_multiplier"] = args.timeout_multiplier
    summary["modules"] = {**earlier, **this_run}
    summary_path.write_text(json.dumps(summary, indent=2) + "\n")
    raw = args.out / "survivors_raw"
    raw.mkdir(exist_ok=True)
    for n, g in status.items():
        lines = [f"# {n} ({MODULES[n][0]}): {len(g['killed'])} killed of "
                 f"{sum(len(v) for v in g.values())}", "",
                 f"mutmut run of {', '.join(args.modules)}; wall time {wall:.0f} s. Every "
                 "survivor's diff; results/mutation/survivors.md says which matter.", ""]
        for key in g["survived"]:
            diff = subprocess.run([str(mutmut), "show", key], cwd=args.scratch, capture_output=True,
                                  text=True).stdout.strip()
            lines += [f"## {key}", "", "```diff", diff, "```", ""]
        (raw / f"{n}.md").write_text("\n".join(lines) + "\n")
    print(json.dumps(summary, indent=2))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
