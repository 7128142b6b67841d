"""One exit-code rule for every command (drumflow.errors.exit_code): bad input 2, a failed run 1,
interrupted 130, always with one message and no traceback.

The commands are found by walking the typer application, so a command added later is covered
without editing this file. The failing solver is a real failing program: a directory put first
on PATH whose ``liggghts``, ``mpirun`` and OpenFOAM programs print an error and exit 1 (or, for
the interrupt test, sleep until they are killed). Nothing here imitates a solver's results.
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path
from typing import Any

import pytest
import tomli_w
import typer
from typer.testing import CliRunner

from drumflow.cli import app
from drumflow.errors import (
    EXIT_BAD_INPUT,
    EXIT_FAILED,
    EXIT_INTERRUPTED,
    AirNotConvergedError,
    AnalysisInputError,
    CaseError,
    DrumflowError,
    InsertionError,
    LostParticlesError,
    RenderError,
    RunDirectoryError,
    RunStoppedError,
    SettingsStudyError,
    SolverError,
    SolverTimeoutError,
    exit_code,
)
from drumflow.verify.scenes import tiny_drum_dict

#: Programs the failing-solver directory replaces.
SOLVER_PROGRAMS = ("mpirun", "liggghts", "simpleFoam", "gmshToFoam", "checkMesh", "decomposePar",
                   "reconstructPar", "postProcess", "foamDictionary")


def _leaves(command: Any, path: tuple[str, ...] = ()) -> list[tuple[tuple[str, ...], Any]]:
    if hasattr(command, "commands"):
        out: list[tuple[tuple[str, ...], Any]] = []
        for name, sub in sorted(command.commands.items()):
            out.extend(_leaves(sub, (*path, name)))
        return out
    return [(path, command)]


COMMANDS = _leaves(typer.main.get_command(app))


def _bad_input_args(command: Any, tmp: Path) -> list[str]:
    """Arguments naming files that do not exist, plus plausible values for required options."""
    args: list[str] = []
    for param in command.params:
        if type(param).__name__.endswith("Argument") and param.required:
            args.append(str(tmp / f"missing-{param.name}"))
        elif param.required:
            value = str(tmp / "out.html") if param.name == "out" else "50"
            args += [param.opts[0], value]
    if not args:
        # A command without a file argument (verify): an option it does not know is bad input.
        args = ["--no-such-option"]
    return args


def test_every_command_is_covered() -> None:
    names = {" ".join(path) for path, _ in COMMANDS}
    assert {"check", "run", "post", "exchanger", "predict", "report", "methodology", "verify",
            "bench"} <= names


@pytest.mark.parametrize("path,command", COMMANDS, ids=[" ".join(p) for p, _ in COMMANDS])
def test_bad_input_exits_2_with_a_message(path: tuple[str, ...], command: Any, tmp_path: Path) -> None:
    result = CliRunner().invoke(app, [*path, *_bad_input_args(command, tmp_path)])
    output = result.output + (result.stderr if result.stderr_bytes is not None else "")
    assert result.exit_code == EXIT_BAD_INPUT, output
    assert isinstance(result.exception, SystemExit), repr(result.exception)
    assert "Traceback" not in output
    assert "error" in output.lower()


def test_report_of_a_directory_that_is_not_a_run_writes_nothing(tmp_path: Path) -> None:
    # Regression: `drumflow report DIR --out x.html` wrote a page of notes and exited 0 for a
    # directory that holds no run at all.
    out = tmp_path / "x.html"
    result = CliRunner().invoke(app, ["report", str(tmp_path), "--out", str(out), "--no-3d"])
    assert result.exit_code == EXIT_BAD_INPUT
    assert not out.exists()


@pytest.mark.parametrize(
    "error,code",
    [
        (CaseError(["x = 1: bad"]), EXIT_BAD_INPUT),
        (RunDirectoryError("no run"), EXIT_BAD_INPUT),
        (AnalysisInputError("h", -1.0, "> 0"), EXIT_BAD_INPUT),
        (SolverError("liggghts", ["liggghts"], 1, None), EXIT_FAILED),
        (SolverTimeoutError("liggghts", ["liggghts"], None, None), EXIT_FAILED),
        (LostParticlesError(10, 9, None), EXIT_FAILED),
        (AirNotConvergedError(10, {"p": 0.1}, 1e-4, None), EXIT_FAILED),
        (InsertionError(10, 9), EXIT_FAILED),
        (RenderError("no OpenGL"), EXIT_FAILED),
        (KeyboardInterrupt(), EXIT_INTERRUPTED),
        (RunStoppedError(4160, 0.262), EXIT_INTERRUPTED),  # `drumflow stop`: resumable
        (RuntimeError("a bug"), EXIT_FAILED),
    ],
)
def test_the_rule_follows_the_base_class(error: BaseException, code: int) -> None:
    assert exit_code(error) == code


def test_an_error_in_brackets_is_printed_as_written() -> None:
    # Regression: the guard printed errors as rich markup, so "[particles]" vanished from
    # `drumflow bench --from`'s message naming the case sections that differ.
    import io

    from rich.console import Console

    from drumflow.cli._guard import guard

    buffer = io.StringIO()
    with pytest.raises(typer.Exit) as exit_info, guard(Console(file=buffer, width=200)):
        raise SettingsStudyError("differs in [particles, air]; see [bold]")
    assert exit_info.value.exit_code == EXIT_BAD_INPUT
    assert "differs in [particles, air]; see [bold]" in buffer.getvalue()


def test_a_requested_stop_is_not_printed_as_an_error() -> None:
    # Regression: a member stopped before its SLURM time limit logged "error: stopped on request".
    import io

    from rich.console import Console

    from drumflow.cli._guard import guard

    buffer = io.StringIO()
    with pytest.raises(typer.Exit) as exit_info, guard(Console(file=buffer, width=200)):
        raise RunStoppedError(7840, 0.4937)
    assert exit_info.value.exit_code == EXIT_INTERRUPTED
    assert buffer.getvalue().startswith("stopped on request at 0.4937 s (step 7,840)")


def test_every_error_class_lives_in_errors_py() -> None:
    # Error classes defined elsewhere could not be found (and mapped) in one place.
    import ast

    root = Path(__file__).resolve().parents[2] / "drumflow"
    strays = []
    for path in root.rglob("*.py"):
        if path.name == "errors.py":
            continue
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.ClassDef) and any(
                isinstance(b, ast.Name) and (b.id.endswith("Error") or b.id == "DrumflowError")
                for b in node.bases
            ):
                strays.append(f"{path.relative_to(root)}:{node.name}")
    assert strays == []
    assert issubclass(RenderError, DrumflowError)


# --------------------------------------------------------------------- failing solver


@pytest.fixture()
def failing_solvers(tmp_path: Path) -> dict[str, str]:
    """Environment whose solvers exist on PATH and fail at once, as a broken install does."""
    bin_dir = tmp_path / "failing-bin"
    bin_dir.mkdir()
    for name in SOLVER_PROGRAMS:
        script = bin_dir / name
        script.write_text(f"#!/bin/sh\necho 'ERROR: {name} fails on purpose (exit-code test)'\nexit 1\n")
        script.chmod(0o755)
    cache = tmp_path / "cache"
    return {**os.environ, "PATH": f"{bin_dir}{os.pathsep}{os.environ['PATH']}",
            "DRUMFLOW_CACHE": str(cache), "DRUMFLOW_MPIRUN": str(bin_dir / "mpirun")}


def _tiny_case_file(tmp_path: Path, **overrides: Any) -> Path:
    path = tmp_path / "tiny.toml"
    path.write_text(tomli_w.dumps(tiny_drum_dict(run__time=0.2, run__mass_flow_start=0.1, **overrides)))
    return path


def _drumflow(
    args: list[str],
    env: dict[str, str],
    cwd: Path,
    timeout: float = 300,
) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-m", "drumflow.cli", *args], env=env, cwd=cwd,
                          capture_output=True, text=True, timeout=timeout, check=False)


@pytest.mark.parametrize("command", ["run", "bench"])
def test_failing_solver_exits_1_with_a_message(command: str, tmp_path: Path,
                                               failing_solvers: dict[str, str]) -> None:
    case = _tiny_case_file(tmp_path)
    args = {"run": ["run", str(case), "--out", str(tmp_path / "run")],
            "bench": ["bench", str(case), "--out", str(tmp_path / "bench"), "--rungs", "default",
                      "--speed-only"]}[command]
    proc = _drumflow(args, failing_solvers, tmp_path)
    assert proc.returncode == EXIT_FAILED, proc.stderr[-3000:]
    assert "Traceback" not in proc.stderr
    text = "".join(proc.stderr.split())  # rich wraps long messages at the terminal width
    assert "failsonpurpose" in text or "failedrung" in text, proc.stderr[-3000:]


@pytest.mark.parametrize("signum", [signal.SIGINT, signal.SIGTERM])
def test_interrupted_run_exits_130_and_leaves_no_solver(signum: int, tmp_path: Path,
                                                        failing_solvers: dict[str, str]) -> None:
    # The launcher sleeps instead of failing: Ctrl-C (SIGINT) or a SIGTERM (kill, a batch time
    # limit) arrives while it runs. Regression for SIGTERM: the CLI died at once and left
    # mpirun and its ranks running on.
    launcher = Path(failing_solvers["DRUMFLOW_MPIRUN"])
    marker = tmp_path / "launcher.pid"
    launcher.write_text(f"#!/bin/sh\necho $$ > {marker}\nexec sleep 120\n")
    case = _tiny_case_file(tmp_path)
    # Ctrl-C as a terminal delivers it: SIGINT at its default disposition in the CLI. An ignored
    # SIGINT is inherited across exec, and Python then installs no KeyboardInterrupt handler;
    # in the full CI order (solver tests first) this test twice found the CLI still running 60 s
    # after SIGINT while passing alone, which an ignored SIGINT inherited from the test
    # process would explain. The disposition the test process had is in the failure message.
    inherited = signal.getsignal(signal.SIGINT)
    proc = subprocess.Popen([sys.executable, "-m", "drumflow.cli", "run", str(case), "--out",
                             str(tmp_path / "run")], env=failing_solvers, cwd=tmp_path,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
    try:
        deadline = time.monotonic() + 240
        while not marker.exists() and time.monotonic() < deadline and proc.poll() is None:
            time.sleep(0.2)
        assert marker.exists(), "the DEM stage never started its launcher"
        proc.send_signal(signum)
        try:
            _, err = proc.communicate(timeout=60)
        except subprocess.TimeoutExpired:
            pytest.fail(f"the CLI still ran 60 s after {signal.Signals(signum).name} "
                        f"(SIGINT in the test process: {inherited})")
    finally:
        if proc.poll() is None:
            proc.kill()
    assert proc.returncode == EXIT_INTERRUPTED, (inherited, err[-3000:])
    assert "Traceback" not in err
    assert "resume" in err
    # The runner killed the launcher's process group: the sleeping "solver" is gone.
    pid = int(marker.read_text())
    with pytest.raises(ProcessLookupError):
        os.kill(pid, 0)
