"""What particle-particle conduction does to the paper's answer (drumflow issue 11).

How to use::

    .venv/bin/python studies/conduction_study.py OUT_DIR ON_RUN OFF_RUN

ON_RUN and OFF_RUN are run directories of one scene to the same time, the first with
``run.conduction = true`` (the paper's Eq. 24), the second with ``false`` (no heat fix in
LIGGGHTS; the coupling loop integrates the temperatures). With one-way air every particle
exchanges heat with the air, and conduction only moves heat between particles, so the mean
temperature, h and the falling mass flow should not move beyond the run's own noise: this
measures it. Compared, with the choices fixed before looking (the same numbers
`drumflow answer` gives, :func:`drumflow.bench.answer.replay_answer`):

- the mean temperature at 3.5 s and at the run's end;
- the paper's h (Eq. 39) over the run's window;
- the falling mass flow of the cascading bed from the end of its start-up (MSER) to the end,
  with its 95 % half-width over whole lifter cycles (two independent intervals combined).

Written: OUT_DIR/conduction.csv and conduction.json. Wall times are the runs' own and are not a
speed measurement (the two runs need not have had the machine alike); the side-by-side speed
of the two decks is ``drumflow bench CASE --from RUN --rungs no_conduction``.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path
from typing import Any

import pandas as pd

from drumflow.bench.answer import replay_answer
from drumflow.case import load_case
from drumflow.errors import DrumflowError, exit_code


def measure(root: Path) -> dict[str, Any]:
    """One run's row: conduction switch, T(3.5), T at the end, h, the cascading bed's flow."""
    case = load_case(root / "case.toml")
    replay = replay_answer(root)
    ref = replay.reference
    return {
        "run": root.name, "case": case.name, "conduction": case.run.conduction,
        "particles": case.dem_case().particle_count, "end_s": replay.reference_time_s,
        "temperature_at_3_5_s_C": float(ref["temperature_C"]),
        "temperature_at_end_C": float(replay_temperature_at_end(root)),
        "h_W_m2K": float(ref["h_W_m2K"]),
        "steady_start_s": float(ref["steady_start_s"]),
        "steady_mass_flow_kg_s": float(ref["steady_mass_flow_kg_s"]),
        "steady_mass_flow_half_width_kg_s": float(ref["steady_mass_flow_half_width_kg_s"]),
        "wall_s": replay.wall_at(replay.reference_time_s),
    }


def replay_temperature_at_end(root: Path) -> float:
    """The mean temperature of the last output step (post/mean_temperature.csv)."""
    series = pd.read_csv(root / "post" / "mean_temperature.csv")
    return float(series.iloc[-1, 1])


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("out", type=Path, help="folder for conduction.csv and conduction.json")
    parser.add_argument("on", type=Path, help="run directory with run.conduction = true")
    parser.add_argument("off", type=Path, help="run directory with run.conduction = false")
    args = parser.parse_args(argv)
    try:
        on, off = measure(args.on), measure(args.off)
    except DrumflowError as exc:
        sys.stderr.write(f"error: {exc}\n")
        return exit_code(exc)
    if not on["conduction"] or off["conduction"]:
        sys.stderr.write("error: ON_RUN must have run.conduction = true and OFF_RUN false\n")
        return 2
    flow = on["steady_mass_flow_kg_s"]
    halves = (on["steady_mass_flow_half_width_kg_s"], off["steady_mass_flow_half_width_kg_s"])
    difference = {
        "temperature_at_3_5_s_K": off["temperature_at_3_5_s_C"] - on["temperature_at_3_5_s_C"],
        "temperature_at_end_K": off["temperature_at_end_C"] - on["temperature_at_end_C"],
        "h_relative": off["h_W_m2K"] / on["h_W_m2K"] - 1.0,
        "steady_mass_flow_relative": off["steady_mass_flow_kg_s"] / flow - 1.0,
        "steady_mass_flow_relative_half_width": (halves[0] ** 2 + halves[1] ** 2) ** 0.5 / flow,
    }
    table = pd.DataFrame([on, off])
    args.out.mkdir(parents=True, exist_ok=True)
    table.to_csv(args.out / "conduction.csv", index=False, float_format="%.8g")
    (args.out / "conduction.json").write_text(json.dumps(
        {"runs": [str(args.on), str(args.off)], "results": json.loads(table.to_json(orient="records")),
         "off_minus_on": difference}, indent=2))
    with pd.option_context("display.width", 220, "display.max_columns", 20):
        print(table.to_string(index=False))
    for name, value in difference.items():
        print(f"{name}: {value:.6g}")
    print(f"written: {args.out / 'conduction.csv'}, {args.out / 'conduction.json'}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
