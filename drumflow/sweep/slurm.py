"""The SLURM executor: one job array per submission, one array task per member.

SLURM decides where and when members run; drumflow only submits, polls and records. Each
submission is ``sbatch --array=<member indices>%<max_parallel>`` of ``DIR/slurm/array.sh``;
array task ``i`` runs member ``i`` as one job step::

    srun --ntasks=1 --cpus-per-task=N drumflow run members/m00i/case.toml --out members/m00i --np N

so SLURM allocates the member's N cores to one task on one node, and drumflow's own
``mpirun -np N`` (the runner always launches LIGGGHTS through mpirun) starts the N ranks inside
that step. OpenMPI inside a SLURM step would count SLURM's *tasks* (1) as its slots and refuse
N ranks, so the step runs with ``OMPI_MCA_ras=^slurm`` (slots from the cores the step may use)
and ``OMPI_MCA_plm=isolated`` (no daemons on other nodes): a member never spans nodes.

Status: ``squeue`` for pending and running tasks; for tasks that left the queue, ``sacct``, or
where accounting is off (``AccountingStorageType=accounting_storage/none``, where sacct answers
"accounting storage is disabled"), ``scontrol show job`` (which knows finished jobs for
``MinJobAge`` seconds), and last the record the task's own script writes at its end
(``members/<id>/slurm-<job>.json``). Submissions (command, script hash, array job id) are in
``DIR/slurm/submissions.json``; each task's output in ``DIR/slurm/logs/<job>_<task>.out``.
"""

from __future__ import annotations

import hashlib
import json
import re
import shlex
import shutil
import subprocess
import sys
import time
from collections.abc import Sequence
from datetime import datetime
from pathlib import Path
from typing import Any

from drumflow.errors import EXIT_INTERRUPTED, BadFileError, SlurmError
from drumflow.readers import read_json, read_json_object
from drumflow.sweep.executor import Attempt, Executor, Ledger
from drumflow.sweep.run_settings import Runs, SlurmSettings
from drumflow.sweep.spec import Member, SweepError, member_id

__all__ = ["SlurmError", "SlurmExecutor", "array_spec", "slurm_version"]

#: SLURM job states and what they mean for an attempt.
_PENDING = {"PENDING", "REQUEUED", "REQUEUE_FED", "REQUEUE_HOLD", "RESV_DEL_HOLD", "CONFIGURING"}
_RUNNING = {"RUNNING", "COMPLETING", "SUSPENDED", "STOPPED", "SIGNALING", "STAGE_OUT", "RESIZING"}


def slurm_version() -> str | None:
    """``slurm 22.05.8`` or None when SLURM's commands are not installed."""
    try:
        out = subprocess.run(["sinfo", "--version"], capture_output=True, text=True, timeout=20)
    except (OSError, subprocess.TimeoutExpired):
        return None
    return out.stdout.strip() or None if out.returncode == 0 else None


def array_spec(indices: Sequence[int]) -> str:
    """``[0, 1, 2, 5]`` -> ``"0-2,5"`` (sbatch --array syntax)."""
    parts: list[str] = []
    ordered = sorted(set(indices))
    i = 0
    while i < len(ordered):
        j = i
        while j + 1 < len(ordered) and ordered[j + 1] == ordered[j] + 1:
            j += 1
        parts.append(str(ordered[i]) if i == j else f"{ordered[i]}-{ordered[j]}")
        i = j + 1
    return ",".join(parts)


def _run(command: list[str], timeout: float = 60.0) -> subprocess.CompletedProcess[str]:
    try:
        return subprocess.run(command, capture_output=True, text=True, timeout=timeout)
    except FileNotFoundError:
        raise SlurmError(f"{command[0]} not found: SLURM's client commands are not installed "
                         "(Debian: slurm-client; scripts/install.sh)") from None
    except subprocess.TimeoutExpired:
        raise SlurmError(f"{' '.join(command)} did not answer within {timeout:g} s") from None


def _epoch(text: str | None) -> float | None:
    if not text or text in ("Unknown", "None", "N/A"):
        return None
    try:
        return datetime.strptime(text, "%Y-%m-%dT%H:%M:%S").timestamp()
    except ValueError:
        return None


class SlurmExecutor(Executor):
    """Run members as one SLURM job array per submission.

    Parameters
    ----------
    root
        The sweep directory; it must be on a file system the compute nodes share.
    settings
        ``executor.slurm`` of the sweep file.
    runs
        ``runs`` of the sweep file.
    sweep_name
        The sweep's name (the job name is ``drumflow-<name>``).
    count
        Number of members (fixes the width of the member ids).
    """

    kind = "slurm"

    def __init__(self, root: Path, settings: SlurmSettings, runs: Runs, sweep_name: str,
                 count: int) -> None:
        self.root = Path(root).resolve()
        self.settings = settings
        self.runs = runs
        self.sweep_name = sweep_name
        self.count = count
        self.poll_interval = settings.poll_interval
        self.dir = self.root / "slurm"
        self._sacct_works: bool | None = None

    # -- the batch script ----------------------------------------------------------------
    def drumflow_command(self) -> str:
        """How the nodes start drumflow (``executor.slurm.drumflow``, or this Python)."""
        return self.settings.drumflow or f"{shlex.quote(sys.executable)} -m drumflow.cli"

    def script(self) -> str:
        """The array job's batch script (array task i runs member i)."""
        n = self.runs.processes
        width = len(member_id(0, self.count)) - 1
        timeout = f" --timeout {self.runs.timeout:g}" if self.runs.timeout is not None else ""
        setup = "\n".join(self.settings.setup)
        members = shlex.quote(str(self.root / "members"))
        return f"""#!/bin/bash
# drumflow sweep {self.sweep_name}: array task i runs member i (written by drumflow sweep).
set -uo pipefail
task="${{SLURM_ARRAY_TASK_ID:?this script runs as a SLURM array task}}"
member="$(printf 'm%0{width}d' "$task")"
member_dir={members}/"$member"
job="${{SLURM_ARRAY_JOB_ID}}_${{task}}"
started="$(date +%s)"
echo "drumflow sweep: member $member, array task $job (job $SLURM_JOB_ID) on $(hostname -s)"
{setup}
# One task with the member's cores; drumflow's own mpirun starts the ranks inside it. OpenMPI
# must not take SLURM's task count (1) as its slots, nor start daemons on other nodes.
export OMPI_MCA_ras=^slurm OMPI_MCA_plm=isolated
srun --ntasks=1 --cpus-per-task={n} {self.drumflow_command()} run "$member_dir/case.toml" \\
    --out "$member_dir" --np {n}{timeout} &
run_pid=$!
# SLURM's warning before the time limit (sbatch --signal=B:USR1@N) reaches this shell only: the
# run is asked to write a restart at its next air update and stop (exit 130), instead of being
# killed at the limit and losing everything since its last periodic restart.
stop_member() {{
    echo "drumflow sweep: time limit near, asking $member to stop"
    {self.drumflow_command()} stop "$member_dir" --no-wait
}}
trap stop_member USR1
while true; do
    wait "$run_pid"
    rc=$?
    kill -0 "$run_pid" 2>/dev/null || break  # a trapped signal ended the wait, not the run
done
printf '{{"job_id": "%s", "node": "%s", "started": %s, "ended": %s, "exit_code": %s}}\\n' \\
    "$job" "$(hostname -s)" "$started" "$(date +%s)" "$rc" > "$member_dir/slurm-$job.json"
exit $rc
"""

    def _sbatch_args(self, indices: Sequence[int]) -> list[str]:
        s = self.settings
        args = [
            f"--array={array_spec(indices)}%{s.max_parallel}",
            f"--job-name=drumflow-{self.sweep_name}",
            f"--output={self.dir / 'logs' / '%A_%a.out'}",
            "--nodes=1",
            "--ntasks=1",
            f"--cpus-per-task={self.runs.processes}",
            f"--chdir={self.root}",
        ]
        if s.partition:
            args.append(f"--partition={s.partition}")
        if s.account:
            args.append(f"--account={s.account}")
        if s.time_limit:
            args.append(f"--time={s.time_limit}")
        if s.stop_before_limit > 0:
            args.append(f"--signal=B:USR1@{s.stop_before_limit}")
        return args + list(s.sbatch_options)

    def _write_script(self) -> Path:
        self.dir.mkdir(parents=True, exist_ok=True)
        (self.dir / "logs").mkdir(exist_ok=True)
        path = self.dir / "array.sh"
        path.write_text(self.script())
        path.chmod(0o755)
        return path

    # -- the interface ---------------------------------------------------------------------
    def check(self, members: Sequence[Member]) -> None:
        """``sbatch --test-only``: SLURM checks partition, account, time and cores, submits nothing.

        Raises
        ------
        SweepError
            SLURM refused the job's options (names the sweep file's ``executor.slurm``).
        SlurmError
            SLURM is not installed or its controller does not answer.
        """
        if shutil.which("sbatch") is None:
            raise SlurmError("sbatch not found: SLURM's client commands are not installed "
                             "(Debian: slurm-client; scripts/install.sh)")
        if not members:
            return
        script = self._write_script()
        out = _run(["sbatch", "--test-only", *self._sbatch_args([m.index for m in members]),
                    str(script)])
        if out.returncode != 0:
            message = " ".join((out.stderr or out.stdout).split())
            if "Unable to contact" in message or "Connection refused" in message:
                raise SlurmError(f"sbatch: {message}")
            raise SweepError([
                f"executor.slurm: SLURM refuses the job array ({message}); settings: "
                f"{' '.join(self._sbatch_args([m.index for m in members]))}"
            ])

    def submit(self, members: Sequence[Member], ledger: Ledger) -> None:
        if not members:
            return
        script = self._write_script()
        indices = [m.index for m in members]
        command = ["sbatch", "--parsable", *self._sbatch_args(indices), str(script)]
        out = _run(command)
        if out.returncode != 0:
            raise SlurmError(f"sbatch refused the job array: {' '.join(out.stderr.split())}")
        job = out.stdout.strip().split(";")[0]
        if not job.isdigit():
            raise SlurmError(f"sbatch printed no job id: {out.stdout.strip()!r}")
        now = time.time()
        path = self.dir / "submissions.json"
        subs = self._submissions(path)
        subs.append({
            "array_job_id": job, "members": [m.id for m in members], "indices": indices,
            "command": command, "submitted": now,
            "script_sha256": hashlib.sha256(script.read_bytes()).hexdigest(),
        })
        path.write_text(json.dumps(subs, indent=2))
        for m in members:
            ledger.add(Attempt(member=m.id, executor=self.kind, job_id=f"{job}_{m.index}",
                               submitted=now, log=str(self.dir / "logs" / f"{job}_{m.index}.out")))
        ledger.save()

    @staticmethod
    def _submissions(path: Path) -> list[Any]:
        """The submissions recorded so far (none when ``path`` is missing).

        Raises
        ------
        BadFileError
            ``path`` is damaged or not a JSON list: appending to a guess would drop the
            record of job arrays already on the cluster.
        """
        if not path.exists():
            return []
        what = "the job arrays this sweep submitted"
        subs = read_json(path, what)
        if not isinstance(subs, list):
            raise BadFileError(path, f"holds a JSON {type(subs).__name__}, expected a list of "
                               "submissions ([{...}, ...])", what)
        return subs

    def poll(self, ledger: Ledger) -> None:
        active = ledger.active(self.kind)
        if not active:
            return
        arrays = sorted({a.job_id.split("_")[0] for a in active if a.job_id})
        queued = self._squeue(arrays)
        gone = [a for a in active if a.job_id not in queued]
        for a in active:
            if a.job_id in queued:
                state, node, reason, start = queued[a.job_id]
                if state in _PENDING:
                    a.state = "pending"
                    a.reason = reason if reason not in ("None", "") else None
                else:
                    a.state = "running"
                    a.node = node or a.node
                    a.started = start or a.started
                    a.reason = None
        if gone:
            finished = self._finished(arrays)
            for a in gone:
                self._settle(a, finished.get(a.job_id or ""))
        ledger.save()

    def interrupt(self, ledger: Ledger) -> str:
        jobs = sorted({a.job_id.split("_")[0] for a in ledger.active(self.kind) if a.job_id})
        if not jobs:
            return "nothing is queued on the cluster"
        return (f"the members keep running on the cluster (job array {', '.join(jobs)}); run the "
                f"same command again to watch them, or `scancel {' '.join(jobs)}` to stop them")

    def describe(self) -> dict[str, Any]:
        return {"kind": self.kind, "slurm": slurm_version(), "max_parallel": self.settings.max_parallel,
                "processes_per_member": self.runs.processes, "drumflow": self.drumflow_command(),
                "sbatch_options": self._sbatch_args([0])[1:]}

    # -- status -----------------------------------------------------------------------------
    def _squeue(self, arrays: Sequence[str]) -> dict[str, tuple[str, str, str, float | None]]:
        """Pending and running tasks: job id -> (state, node, reason, start time)."""
        out = _run(["squeue", "-h", "-r", "-j", ",".join(arrays), "-o", "%i|%T|%N|%r|%S"])
        if out.returncode != 0:
            if "Invalid job id" in out.stderr:
                return {}  # every task of these arrays has left the queue
            raise SlurmError(f"squeue failed: {' '.join(out.stderr.split())}")
        tasks: dict[str, tuple[str, str, str, float | None]] = {}
        for line in out.stdout.splitlines():
            parts = line.strip().split("|")
            if len(parts) == 5:
                tasks[parts[0]] = (parts[1], parts[2], parts[3], _epoch(parts[4]))
        return tasks

    def _finished(self, arrays: Sequence[str]) -> dict[str, dict[str, Any]]:
        """Tasks that left the queue: job id -> state, exit code, node, start, end."""
        if self._sacct_works is not False:
            out = _run(["sacct", "-n", "-P", "-X", "-j", ",".join(arrays),
                        "--format=JobID,State,ExitCode,NodeList,Start,End"])
            if out.returncode == 0 and "disabled" not in out.stderr + out.stdout:
                self._sacct_works = True
                found: dict[str, dict[str, Any]] = {}
                for line in out.stdout.splitlines():
                    p = line.split("|")
                    if len(p) == 6:
                        found[p[0]] = {"state": p[1].split()[0], "exit_code": p[2], "node": p[3],
                                       "started": _epoch(p[4]), "ended": _epoch(p[5])}
                return found
            # Accounting is off here (accounting_storage/none): scontrol knows finished jobs
            # for MinJobAge seconds.
            self._sacct_works = False
        found = {}
        for array in arrays:
            out = _run(["scontrol", "show", "job", "-o", array])
            if out.returncode != 0:
                continue
            for line in out.stdout.splitlines():
                fields = dict(re.findall(r"(\w+)=(\S*)", line))
                task = fields.get("ArrayTaskId", "")
                if not task.isdigit():
                    continue  # a pending range such as 2-3%1
                found[f"{fields.get('ArrayJobId', array)}_{task}"] = {
                    "state": fields.get("JobState", ""), "exit_code": fields.get("ExitCode"),
                    "node": fields.get("NodeList"), "started": _epoch(fields.get("StartTime")),
                    "ended": _epoch(fields.get("EndTime")),
                }
        return found

    def _settle(self, attempt: Attempt, info: dict[str, Any] | None) -> None:
        """Give a task that left the queue its final state."""
        own = self._own_record(attempt)
        if info is None and own is None:
            attempt.state = "failed"
            attempt.reason = ("left the queue; SLURM no longer knows it and it wrote no end "
                              "record (killed?)")
            attempt.ended = attempt.ended or time.time()
            return
        if info is not None:
            state = str(info["state"])
            attempt.node = info.get("node") or attempt.node
            attempt.started = info.get("started") or attempt.started
            attempt.ended = info.get("ended") or time.time()
            attempt.exit_code = info.get("exit_code")
            if state in _PENDING | _RUNNING:
                return  # requeued or still finishing: the next poll sees it in squeue
            attempt.state = "completed" if state == "COMPLETED" else "failed"
            attempt.reason = state
        if own is not None:
            # The task's own record has the member's exit code (SLURM's may be the step's).
            attempt.exit_code = str(own.get("exit_code"))
            attempt.node = own.get("node") or attempt.node
            if info is None:
                attempt.state = "completed" if own.get("exit_code") == 0 else "failed"
                attempt.ended = own.get("ended")
            if own.get("exit_code") == EXIT_INTERRUPTED:
                # Stopped before its time limit (or by `drumflow stop`) after writing a restart:
                # not a failure, and the next `drumflow sweep` resumes it.
                attempt.state = "interrupted"
                attempt.reason = "stopped after writing a restart; resumed on rerun"

    def _own_record(self, attempt: Attempt) -> dict[str, Any] | None:
        """The end record the task's script wrote (None when it wrote none: killed).

        Read only for a task that left the queue, so after its script finished writing it; a
        damaged one is refused rather than taken as "no record", which would settle the
        attempt as failed (or miss an exit code 130, a stop to resume) on a guess.

        Raises
        ------
        BadFileError
            The record is cut short, not UTF-8, not an object, or its ``exit_code`` is not a
            whole number.
        """
        path = self.root / "members" / attempt.member / f"slurm-{attempt.job_id}.json"
        if not path.exists():
            return None
        what = f"the end record of SLURM task {attempt.job_id}"
        data = read_json_object(path, what)
        code = data.get("exit_code")
        if not isinstance(code, int) or isinstance(code, bool):
            raise BadFileError(path, f"exit_code = {code!r}: expected the member's exit status, a "
                               "whole number; delete the file to let SLURM's record decide", what)
        return data
