"""How and where the members of a sweep run: the ``[runs]`` and ``[executor]`` tables of a sweep
file (:mod:`drumflow.sweep.spec`), read by the executors (:mod:`drumflow.sweep.local`,
:mod:`drumflow.sweep.slurm`)."""

from __future__ import annotations

from typing import Literal

from pydantic import BaseModel, Field, model_validator

from drumflow.case import INPUT_MODEL_CONFIG

__all__ = [
    "ExecutorSpec",
    "LocalSettings",
    "Runs",
    "SlurmSettings",
    "SweepTable",
    "time_limit_seconds",
]


class SweepTable(BaseModel):
    """A table of a sweep file, read as strictly as a case file's sections."""

    # The one input-model config (strict types, finite numbers): drumflow.case.
    model_config = INPUT_MODEL_CONFIG


class Runs(SweepTable):
    """Settings of every member run."""

    processes: int = Field(1, ge=1, le=1024, description="MPI ranks of each member")
    timeout: float | None = Field(
        None, gt=0, description="solver wall-time limit of each member, s (none: no limit)"
    )


class LocalSettings(SweepTable):
    """The local executor: a bounded pool of `drumflow run` processes on this machine."""

    max_parallel: int | Literal["auto"] = Field(
        "auto", description="members at once; 'auto': as many as the cores hold "
        "(cores // runs.processes); never more than that"
    )
    poll_interval: float = Field(1.0, gt=0, le=600, description="status refresh, s")

    @model_validator(mode="after")
    def _positive(self) -> LocalSettings:
        if self.max_parallel != "auto" and self.max_parallel < 1:
            raise ValueError(f"executor.local.max_parallel = {self.max_parallel}: allowed >= 1 or 'auto'")
        return self


class SlurmSettings(SweepTable):
    """The SLURM executor: one job array, each task one member under ``srun``."""

    max_parallel: int = Field(4, ge=1, le=100_000, description="members running at once (%N)")
    partition: str | None = Field(None, min_length=1, description="sbatch --partition")
    account: str | None = Field(None, min_length=1, description="sbatch --account")
    time_limit: str | None = Field(
        None, pattern=r"^(\d+-)?\d+(:\d{2}){0,2}$",
        description="sbatch --time per member, e.g. '02:00:00' or '1-00:00:00'",
    )
    stop_before_limit: int = Field(
        300, ge=0, le=86_400,
        description="seconds before the time limit at which a member is asked to write a restart "
        "and stop (sbatch --signal=B:USR1@N; `drumflow stop`), so the rerun resumes from there; "
        "0: off (the limit kills it, and it resumes from its last periodic restart)",
    )
    sbatch_options: list[str] = Field(
        default_factory=list, description="more sbatch options, e.g. ['--mem=4G', '--qos=long']"
    )
    setup: list[str] = Field(
        default_factory=list,
        description="shell lines run before each member (e.g. 'module load openmpi')",
    )
    drumflow: str | None = Field(
        None, min_length=1,
        description="how the nodes start drumflow (default: this Python's `-m drumflow.cli`)",
    )
    poll_interval: float = Field(10.0, gt=0, le=600, description="squeue polling interval, s")

    @model_validator(mode="after")
    def _warning_inside_the_limit(self) -> SlurmSettings:
        limit = time_limit_seconds(self.time_limit) if self.time_limit else None
        if limit is not None and self.stop_before_limit >= limit:
            raise ValueError(
                f"stop_before_limit = {self.stop_before_limit} s is not below time_limit = "
                f"{self.time_limit!r} ({limit} s): the member would be asked to stop as it starts; "
                f"allowed: 0 (off) to {limit - 1} s")
        return self


def time_limit_seconds(limit: str) -> int:
    """A SLURM time limit (``[D-]HH:MM:SS``, ``MM:SS``, ``MM``) in seconds."""
    days, _, clock = limit.rpartition("-")
    parts = [int(x) for x in clock.split(":")]
    if days:  # with days, SLURM reads the clock as hours[:minutes[:seconds]]
        parts += [0] * (3 - len(parts))
        hours, minutes, seconds = parts
        return ((int(days) * 24 + hours) * 60 + minutes) * 60 + seconds
    if len(parts) == 1:
        return parts[0] * 60
    if len(parts) == 2:
        return parts[0] * 60 + parts[1]
    return (parts[0] * 60 + parts[1]) * 60 + parts[2]


class ExecutorSpec(SweepTable):
    """Where the members run."""

    kind: Literal["local", "slurm"] = "local"
    local: LocalSettings = LocalSettings()
    slurm: SlurmSettings = SlurmSettings()
