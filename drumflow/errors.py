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


class InsertionError(DrumflowError, RuntimeError):
    """Fewer particles could be placed in the drum than the case asks for."""

    def __init__(self, requested: int, placed: int, hint: str = "") -> None:
        self.requested = requested
        self.placed = placed
        msg = f"only {placed} of the requested {requested} particles fit in the drum"
        super().__init__(msg + (f"; {hint}" if hint else ""))


class RunDirectoryError(DrumflowError, ValueError):
    """A run directory is missing what a stage needs, or belongs to a different case."""
