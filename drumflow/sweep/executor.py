"""What every executor does, and the records it keeps in the sweep directory.

An executor runs members (``drumflow run`` of each member's case into its run directory) and
reports what became of each attempt. Two implementations: :class:`~drumflow.sweep.local.
LocalExecutor` (a bounded pool on this machine) and :class:`~drumflow.sweep.slurm.
SlurmExecutor` (one SLURM job array). Neither decides whether a member is *done*: that is
read from the member's run directory (:func:`drumflow.sweep.driver.member_done`), so a
finished member is never run again, whichever executor ran it.

Every attempt is one :class:`Attempt` in ``DIR/executor/attempts.json``: the executor, the
job id (SLURM ``<array job>_<task>``, or the local process id), the node, the times, the final
state, the exit code and the log file. The file is the sweep's provenance of where and how each
member ran.
"""

from __future__ import annotations

import json
import time
from abc import ABC, abstractmethod
from collections.abc import Sequence
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any, Literal

from drumflow.errors import BadFileError
from drumflow.readers import read_json
from drumflow.sweep.spec import Member

__all__ = ["ATTEMPTS_FILE", "Attempt", "AttemptState", "Executor", "Ledger", "log_tail"]

#: Where the attempts are recorded, relative to the sweep directory.
ATTEMPTS_FILE = "executor/attempts.json"

#: ``pending``: submitted, not started; ``running``; ``completed``: exit code 0 (the member is
#: done if its run directory says so); ``failed``: non-zero exit, cancelled, timed out, node
#: failure; ``interrupted``: stopped before it finished by the user (Ctrl-C) or, under SLURM,
#: after writing a restart before its time limit (exit 130); resumed on rerun.
AttemptState = Literal["pending", "running", "completed", "failed", "interrupted"]

#: States after which an attempt will not change any more.
FINAL_STATES: frozenset[str] = frozenset({"completed", "failed", "interrupted"})


@dataclass
class Attempt:
    """One run (or try) of one member.

    Attributes
    ----------
    member
        The member id (``m000``).
    executor
        ``"local"`` or ``"slurm"``.
    state
        See :data:`AttemptState`.
    job_id
        SLURM ``<array job id>_<task id>``, or ``pid <n>`` locally; None until known.
    node
        Host the member ran on.
    submitted, started, ended
        Unix times.
    exit_code
        The member's exit code (``drumflow run``: 1 failed, 2 bad input, 130 interrupted), or
        the scheduler's (``"0:15"`` = killed by signal 15) when only it is known.
    reason
        The scheduler's state word or reason (``CANCELLED``, ``TIMEOUT``...), or a note.
    log
        The file holding what the member printed.
    """

    member: str
    executor: str
    state: str = "pending"
    job_id: str | None = None
    node: str | None = None
    submitted: float = field(default_factory=time.time)
    started: float | None = None
    ended: float | None = None
    exit_code: str | None = None
    reason: str | None = None
    log: str | None = None

    @property
    def final(self) -> bool:
        return self.state in FINAL_STATES


class Ledger:
    """The attempts of a sweep directory (``executor/attempts.json``), newest last."""

    def __init__(self, root: Path) -> None:
        self.path = root / ATTEMPTS_FILE
        self.attempts: list[Attempt] = []
        if self.path.exists():
            self.attempts = self._read(self.path)

    @staticmethod
    def _read(path: Path) -> list[Attempt]:
        """The attempts of ``path``, each checked (it is saved whole: one that does not read
        was damaged, and a session guessing would run members again or lose their history).

        Raises
        ------
        BadFileError
            Not a JSON list of attempt records (cut short, not UTF-8, an unknown field).
        """
        what = "every attempt of the sweep's members"
        data = read_json(path, what)
        if not isinstance(data, list):
            raise BadFileError(path, f"holds a JSON {type(data).__name__}, expected a list of "
                               "attempts ([{...}, ...])", what)
        attempts = []
        for i, record in enumerate(data):
            try:
                if not isinstance(record, dict):
                    raise TypeError(f"a JSON {type(record).__name__}, expected an object")
                attempts.append(Attempt(**record))
            except TypeError as exc:
                raise BadFileError(path, f"attempt {i + 1}: not an attempt record ({exc})",
                                   what) from None
        return attempts

    def add(self, attempt: Attempt) -> Attempt:
        self.attempts.append(attempt)
        return attempt

    def latest(self, member: str) -> Attempt | None:
        """The newest attempt of a member, if any."""
        for attempt in reversed(self.attempts):
            if attempt.member == member:
                return attempt
        return None

    def count(self, member: str) -> int:
        return sum(1 for a in self.attempts if a.member == member)

    def active(self, executor: str | None = None) -> list[Attempt]:
        """Attempts that may still change (pending or running)."""
        return [a for a in self.attempts if not a.final and (executor is None or a.executor == executor)]

    def save(self) -> None:
        self.path.parent.mkdir(parents=True, exist_ok=True)
        tmp = self.path.with_suffix(".tmp")
        tmp.write_text(json.dumps([asdict(a) for a in self.attempts], indent=2))
        tmp.replace(self.path)  # atomic: an interrupt never leaves half a record


def log_tail(path: str | Path | None, lines: int = 15) -> str:
    """The last ``lines`` lines of a log file ('' when there is none)."""
    if path is None:
        return ""
    try:
        with Path(path).open("rb") as fh:
            fh.seek(0, 2)
            size = fh.tell()
            fh.seek(max(0, size - 64 * 1024))
            text = fh.read().decode("utf-8", errors="replace")
    except OSError:
        return ""
    return "\n".join(text.splitlines()[-lines:])


class Executor(ABC):
    """Runs members and reports their attempts; one interface for this machine and SLURM.

    The driver calls :meth:`check` before anything is submitted, :meth:`submit` with the
    members to (re)start, then :meth:`poll` every :attr:`poll_interval` seconds until no
    attempt is active, and :meth:`interrupt` on Ctrl-C.
    """

    #: ``"local"`` or ``"slurm"``.
    kind: str
    #: Seconds between two polls.
    poll_interval: float

    @abstractmethod
    def check(self, members: Sequence[Member]) -> None:
        """Refuse (raise :class:`~drumflow.sweep.spec.SweepError`) what cannot run here."""

    @abstractmethod
    def submit(self, members: Sequence[Member], ledger: Ledger) -> None:
        """Start (or queue) these members; add one pending attempt each to the ledger."""

    @abstractmethod
    def poll(self, ledger: Ledger) -> None:
        """Update the ledger's active attempts of this executor (states, nodes, exit codes)."""

    @abstractmethod
    def interrupt(self, ledger: Ledger) -> str:
        """The user pressed Ctrl-C: stop what must stop; return what happened, for the user."""

    def describe(self) -> dict[str, Any]:
        """Settings and versions for the sweep's provenance."""
        return {"kind": self.kind}
