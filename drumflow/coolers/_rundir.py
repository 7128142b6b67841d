"""The run directory of a reduced-order cooler model: the same layout and manifest as a
drumflow slice run (case copy, case hash, versions, wall time), with the model's result in
``result.json`` and its plots beside it."""

from __future__ import annotations

import hashlib
import json
import time
from pathlib import Path
from typing import Any

from pydantic import BaseModel

from drumflow.rundir import RunDir


def case_hash(case: BaseModel) -> str:
    """SHA-256 of the validated case's canonical JSON (the key a run directory is bound to)."""
    text = json.dumps(case.model_dump(mode="json"), sort_keys=True)
    return hashlib.sha256(text.encode()).hexdigest()


def open_cooler_run(out: Path | str, kind: str, case: BaseModel, case_text: str,
                    force: bool = False) -> RunDir:
    """Create (or reopen) the run directory of one model evaluation and bind it to the case.

    Parameters
    ----------
    out
        The directory.
    kind
        The model, e.g. ``"grate"``, recorded in the manifest.
    case
        The validated case.
    case_text
        The case file's text, copied to ``case.toml``.
    force
        Reuse a directory that holds a run of another case.

    Raises
    ------
    RunDirectoryError
        The directory holds a run of a different case and ``force`` is false.
    """
    rundir = RunDir(out)
    rundir.bind_case(json.dumps(case.model_dump(mode="json")), case_hash(case), case_text, force=force)
    rundir.record("model", kind)
    return rundir


def write_result(rundir: RunDir, result: dict[str, Any], wall_time_s: float) -> Path:
    """Write ``result.json`` and record the wall time in the manifest."""
    path = rundir.root / "result.json"
    path.write_text(json.dumps(result, indent=2, default=float))
    rundir.record("wall_time_s", wall_time_s)
    rundir.record("finished", time.strftime("%Y-%m-%dT%H:%M:%S%z"))
    return path
