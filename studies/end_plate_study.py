"""How much the end plates of a thin slice move the answer (drumflow issue 10).

How to use::

    .venv/bin/python studies/end_plate_study.py OUT_DIR RUN [RUN ...]

Each RUN is a run directory (or shipped results folder) of the same scene in sections of
different lengths, the particle count in proportion (the same fill). Model one's section is
0.1 m between two frictional end plates: 12.5 particle diameters. Model two's, 1 m, is 50. The
question is whether a section that narrow carries less (or more) falling mass per metre than a
wide one, through the friction and ordering at its plates. Compared per run, with the choices
fixed before looking:

- the falling mass flow of the cascading bed per metre of section, from the end of its start-up
  transient (MSER) to the run's end, with its 95 % half-width over whole lifter cycles: the
  same numbers `drumflow answer` gives (:func:`drumflow.bench.answer.replay_answer`);
- the paper's h (Eq. 39) and the mean temperature at 3.5 s.

Each row's differences are against the widest section. Written: OUT_DIR/end_plates.csv and
end_plates.json (with each run's case name, particles, wall time).
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
    """One run's row: section, gap in (parcel) diameters, flow per metre, h, T(3.5)."""
    case = load_case(root / "case.toml")
    moved = case.dem_case()
    replay = replay_answer(root)
    ref = replay.reference
    length = case.drum.length
    flow, half = float(ref["steady_mass_flow_kg_s"]), float(ref["steady_mass_flow_half_width_kg_s"])
    return {
        "run": root.name, "case": case.name, "section_m": length,
        "diameter_m": moved.particles.diameter,
        "gap_in_diameters": length / moved.particles.diameter,
        "particles": moved.particle_count, "end_s": replay.reference_time_s,
        "steady_start_s": float(ref["steady_start_s"]),
        "steady_mass_flow_kg_s": flow, "steady_mass_flow_half_width_kg_s": half,
        "flow_per_m_kg_s_m": flow / length, "flow_per_m_half_width_kg_s_m": half / length,
        "h_W_m2K": float(ref["h_W_m2K"]), "temperature_at_3_5_s_C": float(ref["temperature_C"]),
        "wall_s": replay.wall_at(replay.reference_time_s),
    }


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("out", type=Path, help="folder for end_plates.csv and end_plates.json")
    parser.add_argument("runs", type=Path, nargs="+", help="run directories, any order")
    args = parser.parse_args(argv)
    try:
        rows = sorted((measure(r) for r in args.runs), key=lambda r: -r["section_m"])
    except DrumflowError as exc:
        sys.stderr.write(f"error: {exc}\n")
        return exit_code(exc)
    widest = rows[0]
    for row in rows:
        row["flow_per_m_difference"] = row["flow_per_m_kg_s_m"] / widest["flow_per_m_kg_s_m"] - 1.0
        # Two independent intervals: the difference's half-width, relative to the widest flow.
        row["flow_per_m_difference_half_width"] = (
            (row["flow_per_m_half_width_kg_s_m"] ** 2 + widest["flow_per_m_half_width_kg_s_m"] ** 2) ** 0.5
            / widest["flow_per_m_kg_s_m"])
        row["h_difference"] = row["h_W_m2K"] / widest["h_W_m2K"] - 1.0
        row["temperature_difference_K"] = row["temperature_at_3_5_s_C"] - widest["temperature_at_3_5_s_C"]
    table = pd.DataFrame(rows)
    args.out.mkdir(parents=True, exist_ok=True)
    table.to_csv(args.out / "end_plates.csv", index=False, float_format="%.6g")
    (args.out / "end_plates.json").write_text(json.dumps(
        {"runs": [str(r) for r in args.runs], "results": json.loads(table.to_json(orient="records"))},
        indent=2))
    cols = ["run", "section_m", "gap_in_diameters", "flow_per_m_kg_s_m", "flow_per_m_half_width_kg_s_m",
            "flow_per_m_difference", "flow_per_m_difference_half_width", "h_difference",
            "temperature_difference_K", "wall_s"]
    with pd.option_context("display.width", 220, "display.max_columns", 20):
        print(table[cols].to_string(index=False))
    print(f"written: {args.out / 'end_plates.csv'}, {args.out / 'end_plates.json'}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
