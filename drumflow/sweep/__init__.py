"""Sweeps: many runs of one base case over operating conditions, here or on a SLURM cluster.

``drumflow sweep SWEEP.toml --out DIR`` expands a sweep file into member cases
(:mod:`drumflow.sweep.spec`), runs them with an executor (:mod:`drumflow.sweep.local`,
:mod:`drumflow.sweep.slurm`) behind one interface (:mod:`drumflow.sweep.executor`), resumes
what was interrupted (:mod:`drumflow.sweep.driver`), and ``drumflow sweep DIR --analyse`` fits
the Nu-Re-Pr correlation over the members (:mod:`drumflow.sweep.analyse`).
"""

from drumflow.sweep.driver import (
    MemberStatus,
    SweepDir,
    SweepOutcome,
    failure_report,
    member_done,
    open_sweep,
    run_sweep,
    simulated_time,
)
from drumflow.sweep.executor import Attempt, Executor, Ledger
from drumflow.sweep.local import LocalExecutor, available_cores
from drumflow.sweep.slurm import SlurmError, SlurmExecutor
from drumflow.sweep.spec import Member, Sweep, SweepError, expand, load_sweep

__all__ = [
    "Attempt",
    "Executor",
    "Ledger",
    "LocalExecutor",
    "Member",
    "MemberStatus",
    "SlurmError",
    "SlurmExecutor",
    "Sweep",
    "SweepDir",
    "SweepError",
    "SweepOutcome",
    "available_cores",
    "expand",
    "failure_report",
    "load_sweep",
    "member_done",
    "open_sweep",
    "run_sweep",
    "simulated_time",
]
