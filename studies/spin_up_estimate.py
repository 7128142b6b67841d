"""What a cached spin-up (issue 11, lever 2) would buy a sweep, replayed on a finished run.

How to use::

    .venv/bin/python studies/spin_up_estimate.py RUN OUT_DIR [--starts 3,5] [--reference-wall S]

RUN is a finished, post-processed run of a paper case (or its shipped folder,
``results/paper/model_two``). Lever 2 would cache the settled, cascading bed once and start
every run of a sweep that differs only in air, heat or time from it. This script measures what
that buys before anything is built, from the run itself:

- the run's own stop, ``run.stop = "converged"`` replayed from ``run.mass_flow_start``: its
  wall time to the first firing (:func:`drumflow.bench.answer.replay_answer`);
- for each cache time ``t_s`` (``--starts``): the same rule replayed with the falling-mass window
  opened at ``t_s``, as a run started from a bed cached at ``t_s`` would see it (its first
  ``t_s`` seconds are the cache, paid once per sweep). A member's wall time is the run's wall
  time from ``t_s`` to the rule's firing; the cache costs the run's wall time to ``t_s``.

The rule's stop and the answers at it are the replay's; the members' bed is the run's own bed
after ``t_s``, so this is the best case for the lever (a member whose air differs starts from a
bed spun up in other air). A member cannot give the mean temperature at 3.5 s from the start
(its heat starts on a cascading bed): that answer needs the run's own start or a prediction.

Written: OUT_DIR/spin_up.csv and spin_up.json, with the speed-up over ``--reference-wall``
(wall seconds of the reference run, e.g. ``ladder.json``'s) for sweeps of 1, 10 and infinitely
many members.
"""

from __future__ import annotations

import argparse
import json
import re
import shutil
import sys
import tempfile
from pathlib import Path
from typing import Any

import pandas as pd

from drumflow._json import json_safe
from drumflow.bench.answer import replay_answer
from drumflow.bench.answer_result import AnswerReplay
from drumflow.case import load_case
from drumflow.errors import DrumflowError, exit_code

SWEEP_SIZES = (1, 10)


def _wall_at(replay: AnswerReplay, time_s: float) -> float:
    """The run's wall time at the last grid time at or before ``time_s``."""
    table = replay.table
    rows = table[table["time_s"] <= time_s + 1e-9]
    if rows.empty:
        raise DrumflowError(f"no replay row at or before {time_s} s")
    return float(rows["wall_s"].iloc[-1])


def _replay_from(run: Path, start_s: float) -> AnswerReplay:
    """Replay ``run`` with the falling-mass window opened at ``start_s`` (a copy of its case)."""
    with tempfile.TemporaryDirectory() as scratch:
        copy = Path(scratch) / "run"
        shutil.copytree(run, copy, ignore=shutil.ignore_patterns("dumps", "restart", "field.npz"))
        toml = (copy / "case.toml").read_text()
        toml, n = re.subn(r"^mass_flow_start\s*=.*$", f"mass_flow_start = {start_s!r}", toml,
                          flags=re.M)
        if n != 1:
            raise DrumflowError(f"{run / 'case.toml'}: no single run.mass_flow_start line")
        (copy / "case.toml").write_text(toml)
        return replay_answer(copy)


def estimate(run: Path, starts: list[float], reference_wall_s: float) -> dict[str, Any]:
    """The rows of :mod:`spin_up.csv <scripts.spin_up_estimate>`, and what they rest on."""
    case = load_case(run / "case.toml")
    own = replay_answer(run)
    if own.first_fire_s is None:
        raise DrumflowError(f"{run}: the converged rule never fires in this run")
    rows: list[dict[str, Any]] = []
    own_wall = _wall_at(own, own.first_fire_s)
    rows.append({"start_s": case.run.mass_flow_start, "cached": False,
                 "stop_s": own.first_fire_s, "cache_wall_s": 0.0, "member_wall_s": own_wall})
    for start in starts:
        replay = _replay_from(run, start)
        if replay.first_fire_s is None:
            rows.append({"start_s": start, "cached": True, "stop_s": None,
                         "cache_wall_s": _wall_at(own, start), "member_wall_s": None})
            continue
        cache = _wall_at(own, start)
        rows.append({"start_s": start, "cached": True, "stop_s": replay.first_fire_s,
                     "cache_wall_s": cache,
                     "member_wall_s": _wall_at(own, replay.first_fire_s) - cache})
    for row in rows:
        member = row["member_wall_s"]
        for n in SWEEP_SIZES:
            row[f"speedup_{n}"] = (None if member is None else
                                   reference_wall_s / (member + row["cache_wall_s"] / n))
        row["speedup_inf"] = None if member is None else reference_wall_s / member
    return {"run": str(run), "reference_wall_s": reference_wall_s,
            "run_time_s": own.reference_time_s, "rows": rows,
            "note": ("best case: members start from the run's own bed after start_s; the "
                     "mean temperature at 3.5 s is not a member's answer")}


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("run", type=Path)
    parser.add_argument("out", type=Path)
    parser.add_argument("--starts", default="3,5", help="cache times, s (comma separated)")
    parser.add_argument("--reference-wall", type=float, required=True,
                        help="wall seconds of the reference run the speed-ups are against")
    args = parser.parse_args(argv)
    try:
        starts = [float(s) for s in args.starts.split(",") if s.strip()]
        result = estimate(args.run, starts, args.reference_wall)
    except (DrumflowError, ValueError) as exc:
        print(f"error: {exc}", file=sys.stderr)
        return exit_code(exc) if isinstance(exc, DrumflowError) else 2
    args.out.mkdir(parents=True, exist_ok=True)
    pd.DataFrame(result["rows"]).to_csv(args.out / "spin_up.csv", index=False)
    (args.out / "spin_up.json").write_text(json.dumps(json_safe(result), indent=2))
    print(pd.DataFrame(result["rows"]).to_string(index=False))
    return 0


if __name__ == "__main__":
    sys.exit(main())
