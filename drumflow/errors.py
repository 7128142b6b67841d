"""Typed errors of drumflow.

Every error subclasses a builtin so callers that do not know drumflow can still catch it
(``ValueError`` for bad input, ``RuntimeError`` for a solver that failed), and every error
carries the context a user needs to act on it. The CLI turns them into one clear message and
an exit code; library code only raises.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path


class DrumflowError(Exception):
    """Base class of every error drumflow raises on purpose."""


class CaseError(DrumflowError, ValueError):
    """A case file is missing, unreadable or has values outside their allowed range.

    Parameters
    ----------
    problems
        One line per problem, each naming the field, the value and the allowed range.
    source
        The case file the problems were found in, if any.
    """

    def __init__(self, problems: Sequence[str], source: Path | str | None = None) -> None:
        self.problems = list(problems)
        self.source = None if source is None else str(source)
        where = f" in {self.source}" if self.source else ""
        lines = "\n".join(f"  - {p}" for p in self.problems)
        super().__init__(f"invalid case{where}:\n{lines}")


class GeometryError(DrumflowError, ValueError):
    """The drum geometry could not be built or failed its checks (open shell, bad facets)."""


class SweepError(CaseError):
    """A sweep file is invalid, or one of its members is a case the solver would refuse.

    A :class:`CaseError` (so a ``ValueError``: exit code 2), with every problem on its own
    line, each naming the member (when it is about one), the field, the value and the allowed
    range.
    """

    def __init__(self, problems: Sequence[str], source: Path | str | None = None) -> None:
        super().__init__(problems, source)
        where = f" in {self.source}" if self.source else ""
        lines = "\n".join(f"  - {p}" for p in self.problems)
        self.args = (f"invalid sweep{where}:\n{lines}",)

    def __str__(self) -> str:
        return str(self.args[0])


class SettingsStudyError(DrumflowError, ValueError):
    """A run directory cannot be studied by ``drumflow bench --from`` (no restart, no air
    coupling, a deck of another form, a run of another scene, an unknown variant)."""


class SlurmError(DrumflowError, RuntimeError):
    """A SLURM command failed (sbatch refused the job, squeue could not reach the controller)."""


class DrumModelError(DrumflowError, ValueError):
    """The whole-drum model cannot run at these conditions (the message names the quantity)."""


class GrateConvergenceError(DrumflowError, RuntimeError):
    """The grate cooler's sweeps did not reach the case's tolerances (a failed run, exit code 1)."""


class SolverError(DrumflowError, RuntimeError):
    """An external program (LIGGGHTS, an OpenFOAM utility, mpirun) failed.

    Parameters
    ----------
    program
        Short name of the program, e.g. ``"liggghts"``.
    command
        The argument list that was run.
    returncode
        Its exit status (``None`` when it was killed on a timeout).
    log
        The log file holding its full output.
    last_error
        The last line of the log that reports an error, if one was found.
    """

    def __init__(
        self,
        program: str,
        command: Sequence[str],
        returncode: int | None,
        log: Path | None,
        last_error: str | None = None,
        reason: str | None = None,
    ) -> None:
        self.program = program
        self.command = list(command)
        self.returncode = returncode
        self.log = log
        self.last_error = last_error
        self.reason = reason
        head = reason or f"{program} exited with status {returncode}"
        detail = f": {last_error}" if last_error else ""
        where = f" (log: {log})" if log else ""
        super().__init__(f"{head}{detail}{where}")


class SolverTimeoutError(SolverError, TimeoutError):
    """An external program ran past its time limit and was killed with its process group."""


class SolverNotFoundError(SolverError, FileNotFoundError):
    """An external program is not installed (or not on PATH)."""


class LostParticlesError(SolverError):
    """Particles left the domain during a DEM run: a failure, never ignored.

    Attributes
    ----------
    initial
        Particles at the start of the run.
    final
        The last count seen, or ``None`` when LIGGGHTS stopped before printing one (its own
        "Lost atoms: original N current M" message is not trusted: the Debian build of
        LIGGGHTS 3.8 prints wrong numbers there).
    time_s
        Simulated time of the last count seen, if any.
    """

    def __init__(
        self,
        initial: int,
        final: int | None,
        log: Path | None,
        command: Sequence[str] = (),
        time_s: float | None = None,
    ) -> None:
        self.initial = initial
        self.final = final
        self.time_s = time_s
        if final is not None and final < initial:
            what = f"{initial - final} of {initial} particles left the domain"
        else:
            what = f"particles left the domain (of {initial} at the start)"
        when = f" after {time_s:.4g} s simulated" if time_s is not None else ""
        super().__init__("liggghts", command, None, log, reason=what + when)


class UnstableRunError(SolverError):
    """The DEM run went numerically unstable and was stopped (drumflow.dem.stability).

    Attributes
    ----------
    diagnosis
        What broke, when, and the likely cause, in one line.
    step
        The DEM step of the thermo row that broke the bound.
    """

    def __init__(self, diagnosis: str, step: int, log: Path | None, command: Sequence[str] = ()) -> None:
        self.diagnosis = diagnosis
        self.step = step
        super().__init__("liggghts", command, None, log, reason=f"run stopped: {diagnosis}")


class AirNotConvergedError(SolverError):
    """simpleFoam reached ``air.max_iterations`` before every residual fell below the target.

    Attributes
    ----------
    iterations
        SIMPLE iterations run.
    final_residuals
        The last initial residual of each field.
    target
        The residual target that was not reached.
    solution
        The (unconverged) :class:`~drumflow.air.foam_results.AirSolution`, whose files are left
        in place; a caller may
        still decide to use it.
    """

    def __init__(
        self,
        iterations: int,
        final_residuals: dict[str, float],
        target: float,
        log: Path | None,
        # Typed loosely on purpose: the errors are the floor under every stage and import none
        # of them (an AirSolution type here made errors <-> air.foam_results a circle).
        solution: object | None = None,
    ) -> None:
        self.iterations = iterations
        self.final_residuals = dict(final_residuals)
        self.target = target
        self.solution = solution
        worst = max(final_residuals.items(), key=lambda kv: kv[1], default=("?", float("nan")))
        super().__init__(
            "simpleFoam",
            ["simpleFoam"],
            0,
            log,
            reason=(
                f"the air solution did not converge in {iterations} SIMPLE iterations: "
                f"{worst[0]} residual {worst[1]:.3g} > target {target:.3g} "
                "(raise air.max_iterations, coarsen air.mesh_size or relax air.residual_target)"
            ),
        )


class MeshCheckError(SolverError):
    """``checkMesh`` reported failed checks: the mesh would give a wrong or diverging air field."""


class InsertionError(DrumflowError, RuntimeError):
    """Fewer particles could be placed in the drum than the case asks for."""

    def __init__(self, requested: int, placed: int, hint: str = "") -> None:
        self.requested = requested
        self.placed = placed
        msg = f"only {placed} of the requested {requested} particles fit in the drum"
        super().__init__(msg + (f"; {hint}" if hint else ""))


class RunDirectoryError(DrumflowError, ValueError):
    """A run directory is missing what a stage needs, or belongs to a different case."""


class BadFileError(RunDirectoryError):
    """A file drumflow reads is unusable: not UTF-8 text, cut short, empty, not the format it
    should be, or holding a NaN or a word where a number belongs (:mod:`drumflow.readers`).

    A :class:`RunDirectoryError` (so a ``ValueError``: exit code 2) because most such files are
    a run directory's, and the readers that skip a dump still being written catch that class;
    it is raised for input files named on the command line as well.

    Parameters
    ----------
    path
        The file.
    problem
        What is wrong with it and where (line, row, column or field).
    what
        What the file holds, for the message (e.g. ``"the run's manifest"``).

    Attributes
    ----------
    path, problem
        As given.
    """

    def __init__(self, path: Path | str, problem: str, what: str = "") -> None:
        self.path = Path(path)
        self.problem = problem
        held = f" ({what})" if what else ""
        super().__init__(f"{path}{held}: {problem}")


class StartStateError(DrumflowError, ValueError):
    """A start state (``run.start_state``, :mod:`drumflow.dem.state`) that does not fit the case:
    another scene (drum, lifters or particles), another particle count, or a file that is not a
    drumflow start state. Bad input: exit code 2.

    Parameters
    ----------
    path
        The state file.
    problem
        What does not fit, with both values.

    Attributes
    ----------
    field, path, problem
        The case field (``run.start_state``, or ``air.bed_states[k]``) and the arguments.
    """

    field = "run.start_state"

    def __init__(self, path: Path | str, problem: str, field: str = "run.start_state") -> None:
        # The case field: run.start_state, or one of air.bed_states (air around the bed).
        self.field = field
        self.path = Path(path)
        self.problem = problem
        super().__init__(f"{self.field} = {str(path)!r}: {problem}")


class AnalysisInputError(DrumflowError, ValueError):
    """An argument of an analysis function is outside its allowed range.

    It subclasses :class:`ValueError` so callers that do not know drumflow can still catch it,
    and :class:`DrumflowError` so the CLI reports it as a drumflow error.

    Parameters
    ----------
    name
        Name of the argument (as in the function signature, with an index for array items).
    value
        The rejected value (already formatted or any object; it is shown with ``repr``).
    allowed
        Human-readable description of the accepted values, e.g. ``"a finite number > 0"``.
    """

    def __init__(self, name: str, value: object, allowed: str) -> None:
        self.name = name
        self.value = value
        self.allowed = allowed
        super().__init__(f"{name} = {_show(value)} is not allowed: expected {allowed}")


def _show(value: object) -> str:
    # numpy scalars print as np.float64(1.0) with repr; convert to plain Python first so
    # messages read the same whatever the caller passed. Duck-typed so this module stays free
    # of numpy (it is imported by everything).
    item = getattr(value, "item", None)
    if type(value).__module__ == "numpy" and callable(item) and getattr(value, "ndim", 1) == 0:
        value = item()
    if isinstance(value, float):
        return f"{value:.6g}"
    if isinstance(value, str):
        return value
    return repr(value)


class InfeasibleExchangerError(AnalysisInputError):
    """The requested operating point violates the second law (e.g. a temperature cross)."""


class MissingRunFileError(RunDirectoryError):
    """A file the methodology needs is not in the run directory.

    Parameters
    ----------
    path
        The missing file (absolute).
    what
        What the file holds, for the message.

    Attributes
    ----------
    path
        The missing file.
    """

    def __init__(self, path: Path, what: str) -> None:
        self.path = path
        super().__init__(
            f"{path}: missing ({what}); run `drumflow run CASE --out DIR` (or `drumflow post DIR` "
            "if the dumps are there) first"
        )


class NoHeatTransferError(RunDirectoryError):
    """The run cannot give a heat-transfer coefficient (no air, no cooling, no falling mass)."""


class RunTooShortError(RunDirectoryError):
    """A run directory holds less simulated time than an analysis needs.

    Parameters
    ----------
    path
        The file whose last time was read (absolute).
    simulated_time_s
        The simulated time it reaches, s.
    required_s
        The least simulated time the analysis needs, s.
    why
        Where the requirement comes from, for the message (e.g. "run.mass_flow_start + 1 s").

    Attributes
    ----------
    path, simulated_time_s, required_s
        As given.
    """

    def __init__(self, path: Path, simulated_time_s: float, required_s: float, why: str) -> None:
        self.path = path
        self.simulated_time_s = simulated_time_s
        self.required_s = required_s
        super().__init__(
            f"{path}: the run reaches {simulated_time_s:.4g} s of simulated time; allowed: a run "
            f"of at least {required_s:.4g} s ({why}); run it longer (or resume it) and rerun "
            "`drumflow post DIR`"
        )


class RunStoppedError(DrumflowError):
    """A run stopped on request (``drumflow stop``), after writing a restart: interrupted, not
    failed (exit code 130), and resumed by running the same command again.

    Attributes
    ----------
    step, time_s
        Where the restart was written.
    """

    def __init__(self, step: int, time_s: float) -> None:
        self.step = step
        self.time_s = time_s
        super().__init__(f"stopped on request at {time_s:.4g} s (step {step:,}), after writing a "
                         "restart there; run the same command again to resume")


class RenderError(DrumflowError, RuntimeError):
    """The particle picture could not be rendered (no OpenGL, crash, time limit, bad data)."""


#: Exit codes of every drumflow command, computed once from the error's class by :func:`exit_code`.
EXIT_OK = 0
EXIT_FAILED = 1
EXIT_BAD_INPUT = 2
EXIT_INTERRUPTED = 130


def exit_code(exc: BaseException) -> int:
    """The one exit-code rule: bad input 2, a failed run 1, interrupted 130 (Ctrl-C, SIGTERM, a
    run stopped on request).

    Bad input is every drumflow error that is also a ``ValueError`` (a case or sweep file, an
    argument, a run directory); every other drumflow error is a run that failed. Anything
    else is a bug and also maps to 1 (the CLI shows its traceback).
    """
    if isinstance(exc, KeyboardInterrupt | RunStoppedError):
        return EXIT_INTERRUPTED
    if isinstance(exc, DrumflowError) and isinstance(exc, ValueError):
        return EXIT_BAD_INPUT
    return EXIT_FAILED
