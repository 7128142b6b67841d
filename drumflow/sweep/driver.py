"""The sweep directory and the loop that drives an executor until every member has finished.

Layout of a sweep directory::

    DIR/
      sweep.toml             the sweep file as given (provenance; reruns read this copy)
      base.toml              the base case file as given
      sweep.json             the expanded members (id, axis values, case hash), executor
                             settings, software versions, times of each session
      members/<id>/          each member's run directory (drumflow run: manifest, case hash)
      logs/<id>.<n>.log      local executor: what attempt n of a member printed
      slurm/                 slurm executor: array.sh, submissions.json, logs/<job>_<task>.out
      executor/attempts.json every attempt: executor, job id, node, times, state, exit code
      analysis/              drumflow sweep DIR --analyse: report.html, members.csv, fit.json

A member is *done* when its run directory holds a ``summary.json`` of the member's case hash
with status ``ok`` (what ``drumflow run`` writes last); done members are never run again. A
member whose run was interrupted (Ctrl-C, a killed job) resumes from its newest restart file
when it runs again, because ``drumflow run`` into the same directory does that. Members whose
last attempt *failed* are run again only when asked (``requeue_failed``).
"""

from __future__ import annotations

import json
import shutil
import socket
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from drumflow.dem.thermo import ThermoParser, log_files
from drumflow.errors import BadFileError
from drumflow.readers import read_json_object
from drumflow.rundir import software_versions
from drumflow.sweep.executor import Attempt, Executor, Ledger, log_tail
from drumflow.sweep.spec import Member, Sweep, SweepError, format_value, load_sweep

__all__ = ["MemberStatus", "SweepDir", "SweepOutcome", "member_done", "open_sweep", "run_sweep",
           "simulated_time"]

SWEEP_FILE = "sweep.toml"
BASE_FILE = "base.toml"
STATE_FILE = "sweep.json"
_STATE_WHAT = "the sweep's members and sessions"


def member_done(run_dir: Path, case_hash: str) -> bool:
    """True when the run directory holds a finished, healthy run of this case.

    Raises
    ------
    BadFileError
        The member's ``summary.json`` is there but damaged (cut short, not UTF-8, not an
        object). It is refused, not read as "not done": a damaged summary is no run being
        finished (``drumflow run`` writes it whole, then renames it), and a done member taken
        as pending would silently drop out of ``--analyse`` or be run again.
    """
    path = run_dir / "summary.json"
    if not path.exists():
        return False
    try:
        summary = read_json_object(path, "the member's run summary")
    except BadFileError as exc:
        raise BadFileError(path, exc.problem + f"; delete it and rerun `drumflow post {run_dir}` "
                           "to write it again", "the member's run summary") from None
    return (summary.get("case_hash") == case_hash and summary.get("status") == "ok"
            and "short_run_steps" not in summary)


def simulated_time(run_dir: Path) -> float | None:
    """Simulated seconds the member's DEM run has reached (its newest LIGGGHTS log)."""
    logs = log_files(run_dir / "dem")
    if not logs:
        return None
    try:
        with logs[-1].open("rb") as fh:
            fh.seek(0, 2)
            fh.seek(max(0, fh.tell() - 16 * 1024))
            text = fh.read().decode("utf-8", errors="replace")
    except OSError:
        return None
    parser = ThermoParser()
    for line in text.splitlines():
        parser(line)
    return parser.rows[-1][1] if parser.rows else None


@dataclass
class MemberStatus:
    """One row of the live table.

    Attributes
    ----------
    state
        ``pending`` (not started or queued), ``running``, ``done``, ``failed`` or
        ``interrupted`` (stopped before it finished; resumes on rerun).
    simulated_s, total_s
        Simulated time reached and asked for.
    eta_s
        Wall seconds left, from the rate seen since the monitor first saw this attempt run.
    """

    member: Member
    state: str
    simulated_s: float | None
    total_s: float
    eta_s: float | None
    attempt: Attempt | None
    attempts: int

    @property
    def where(self) -> str:
        a = self.attempt
        if a is None:
            return ""
        return " @ ".join(x for x in (a.job_id, a.node) if x)


@dataclass
class SweepOutcome:
    """What a sweep session ended with."""

    statuses: list[MemberStatus]
    interrupted: bool = False
    message: str = ""

    @property
    def failed(self) -> list[MemberStatus]:
        return [s for s in self.statuses if s.state == "failed"]

    @property
    def all_done(self) -> bool:
        return all(s.state == "done" for s in self.statuses)


@dataclass
class SweepDir:
    """An opened sweep directory with its validated sweep and members."""

    root: Path
    sweep: Sweep
    members: list[Member]
    #: True when this session made the directory (open_sweep from a sweep file into a new
    #: folder): a session refused before any member ran may then remove it, and only then.
    created: bool = False
    ledger: Ledger = field(init=False)

    def __post_init__(self) -> None:
        self.ledger = Ledger(self.root)

    def member_dir(self, member: Member) -> Path:
        return self.root / "members" / member.id

    def done(self, member: Member) -> bool:
        return member_done(self.member_dir(member), member.hash)

    def record_session(self, executor: Executor) -> None:
        """Append this session's executor settings and software versions to sweep.json."""
        path = self.root / STATE_FILE
        state = read_json_object(path, _STATE_WHAT)
        state.setdefault("sessions", []).append({
            "started": time.strftime("%Y-%m-%dT%H:%M:%S%z"), "host": socket.gethostname(),
            "executor": executor.describe(), "versions": software_versions(),
        })
        path.write_text(json.dumps(state, indent=2, default=str))


def open_sweep(target: Path, out: Path | None = None) -> SweepDir:
    """Open a sweep: from a sweep file into ``out``, or an existing sweep directory.

    A sweep file is validated and expanded first; only then is the directory written (the
    sweep and base files copied, every member's case written to ``members/<id>/case.toml``).
    Rerunning into a directory whose members hold other cases (an edited sweep file) is
    refused, naming the members.

    Raises
    ------
    SweepError
        The sweep file is invalid, a member is a case the model refuses, or ``out`` holds a
        different sweep.
    BadFileError
        A member's ``manifest.json`` or the directory's ``sweep.json`` or
        ``executor/attempts.json`` is damaged.
    """
    target = Path(target)
    if target.is_dir():
        root = target.resolve()
        # What the target is comes first: a folder that is no sweep directory is the mistake,
        # whatever --out says.
        if not (root / SWEEP_FILE).is_file():
            raise SweepError([f"{root}: a directory, not a sweep file, and not a sweep directory "
                              f"(no {SWEEP_FILE}); give a sweep file (TOML) or a sweep directory"])
        if out is not None and out.resolve() != root:
            raise SweepError([f"--out {out}: give --out only with a sweep file, not a sweep directory"])
        sweep, _, members = load_sweep(root / SWEEP_FILE, base=root / BASE_FILE)
        return SweepDir(root, sweep, members)
    sweep, _, members = load_sweep(target)
    root = (out if out is not None else Path("runs") / "sweep" / sweep.name).resolve()
    clashes = []
    for m in members:
        manifest = root / "members" / m.id / "manifest.json"
        if manifest.exists():
            old = read_json_object(manifest, f"the manifest of member {m.id}").get("case_hash")
            if old and old != m.hash:
                clashes.append(f"member {m.id} ({m.label()}): {root / 'members' / m.id} holds a "
                               f"run of another case (hash {old[:12]}, now {m.hash[:12]})")
    if clashes:
        raise SweepError(clashes + ["the sweep file changed since this directory was run; "
                                    "choose another --out directory"], target)
    created = not root.exists()
    root.mkdir(parents=True, exist_ok=True)
    shutil.copyfile(target, root / SWEEP_FILE)
    shutil.copyfile(target.parent / sweep.base, root / BASE_FILE)
    for m in members:
        d = root / "members" / m.id
        d.mkdir(parents=True, exist_ok=True)
        if not (d / "case.toml").exists() or (d / "case.toml").read_text() != m.case_toml:
            (d / "case.toml").write_text(m.case_toml)
    state_path = root / STATE_FILE
    state = read_json_object(state_path, _STATE_WHAT) if state_path.exists() else {}
    state.update({
        "sweep": sweep.model_dump(mode="json"),
        "source": str(target.resolve()),
        "members": [{"id": m.id, "index": m.index, "values": m.values, "case_hash": m.hash}
                    for m in members],
    })
    state_path.write_text(json.dumps(state, indent=2, default=str))
    return SweepDir(root, sweep, members, created=created)


class _Eta:
    """Wall-time left per member from the simulated-time rate of its current attempt."""

    def __init__(self) -> None:
        self.first: dict[tuple[str, str | None], tuple[float, float]] = {}

    def __call__(self, key: tuple[str, str | None], t: float | None, total: float) -> float | None:
        if t is None:
            return None
        now = time.monotonic()
        if key not in self.first:
            self.first[key] = (now, t)
            return None
        wall0, t0 = self.first[key]
        if t <= t0 or now <= wall0:
            return None
        return (total - t) * (now - wall0) / (t - t0)


def statuses(sd: SweepDir, eta: _Eta | None = None) -> list[MemberStatus]:
    """The state of every member, from its run directory and its latest attempt."""
    rows = []
    for m in sd.members:
        total = m.case.run.time
        attempt = sd.ledger.latest(m.id)
        count = sd.ledger.count(m.id)
        if sd.done(m):
            rows.append(MemberStatus(m, "done", total, total, 0.0, attempt, count))
            continue
        t = simulated_time(sd.member_dir(m))
        if attempt is None:
            state = "interrupted" if t is not None else "pending"
        elif attempt.state == "completed":
            # Exit code 0 but no healthy summary (e.g. particles lost at the end).
            state = "failed"
        else:
            state = attempt.state
        est = eta((m.id, attempt.job_id if attempt else None), t, total) if (
            eta is not None and state == "running") else None
        rows.append(MemberStatus(m, state, t, total, est, attempt, count))
    return rows


def to_run(sd: SweepDir, requeue_failed: bool) -> tuple[list[Member], list[MemberStatus]]:
    """Members to start now, and the failed ones left alone (without ``requeue_failed``)."""
    start, left = [], []
    for s in statuses(sd):
        if s.state == "done":
            continue
        a = s.attempt
        if a is not None and not a.final:
            continue  # still queued or running (a SLURM job of an earlier session)
        if s.state == "failed" and not requeue_failed:
            left.append(s)
            continue
        start.append(s.member)
    return start, left


def run_sweep(
    sd: SweepDir,
    executor: Executor,
    *,
    requeue_failed: bool = False,
    wait: bool = True,
    on_status: Callable[[list[MemberStatus]], None] | None = None,
) -> SweepOutcome:
    """Run every member that is not done, and watch them until none is active.

    Parameters
    ----------
    sd
        The opened sweep directory.
    executor
        Where the members run.
    requeue_failed
        Also run members whose last attempt failed (resuming from their restart files).
    wait
        Watch until every member finished; False returns right after submitting (SLURM).
    on_status
        Called with the member states after every poll (the live table).

    Returns
    -------
    SweepOutcome
        The final states; ``interrupted`` when Ctrl-C stopped the session.

    Raises
    ------
    SweepError
        The executor refuses the members (e.g. more MPI ranks than cores), before anything runs.
    """
    ledger = sd.ledger
    executor.poll(ledger)  # SLURM: settle jobs of earlier sessions before deciding
    start, _ = to_run(sd, requeue_failed)
    executor.check(start)
    sd.record_session(executor)
    eta = _Eta()
    try:
        executor.submit(start, ledger)
        while True:
            executor.poll(ledger)
            rows = statuses(sd, eta)
            if on_status is not None:
                on_status(rows)
            if not wait or not ledger.active(executor.kind):
                break
            time.sleep(executor.poll_interval)
    except KeyboardInterrupt:
        message = executor.interrupt(ledger)
        return SweepOutcome(statuses(sd), interrupted=True, message=message)
    return SweepOutcome(rows)


def failure_report(status: MemberStatus, lines: int = 15) -> str:
    """A failed member's last attempt with the tail of its log."""
    a = status.attempt
    head = f"{status.member.id} ({status.member.label()})"
    if a is None:
        return f"{head}: no attempt recorded"
    what = ", ".join(x for x in (
        a.reason, f"exit code {a.exit_code}" if a.exit_code is not None else None,
        a.job_id, a.node) if x)
    tail = log_tail(a.log, lines)
    return f"{head}: {what}\n  log: {a.log}\n" + "\n".join("  | " + ln for ln in tail.splitlines())


def axis_table(members: Sequence[Member]) -> list[dict[str, Any]]:
    """One dict per member: id, axis values as text, case hash."""
    return [{"member": m.id, **{k: format_value(v) for k, v in m.values.items()}, "hash": m.hash[:12]}
            for m in members]
