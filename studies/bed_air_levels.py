"""The level of air that goes around the bed (issue 32) beside the levels of issue 31: the
shipped periodic bed-air slices' heat, as the volumetric coefficient the level table uses.

How to use::

    .venv/bin/python studies/bed_air_levels.py [--out results/paper/levels]

Reads, for model one's parcels and model two, the periodic slice's ``heat.json`` (each cell's
own diffusivity, the default) and its two bounds (``heat_turbulent.json``, ``heat_molecular.json``
or model two's separate molecular folder) with the case beside them, and writes
OUT/levels_air_around_the_bed.json and .csv: per slice and mixing, the heat, the contact
efficiency, the saturated (through-curtain) air per metre, and the slice's volumetric
coefficient two ways, as ``studies/interior_levels.py`` defines them: Q / (V (T_p - T_in)) and
Q / (V LMTD) with the air in at T_in and out at the slice's outlet (V = pi D^2 L / 4). A bed-air
slice is one frozen state (5 s), not a coupled run: no T(3.5 s) or h columns.

Also OUT/frozen_against_loop.json and .csv: model two's slice with the coupled loop's choices
switched on one at a time (:data:`SWITCHES`, ``--flux``, ``--film``, ``--mixing`` of
``drumflow bed-air``), from the heat files of :data:`SWITCHES_DIR` that exist.
"""

from __future__ import annotations

import argparse
import json
import math
import tomllib
from pathlib import Path
from typing import Any

import pandas as pd

from drumflow.air.bed_heat import heat_file_name

ROOT = Path(__file__).resolve().parents[1]
AIR = ROOT / "results" / "air"
#: slice name -> (case file, {mixing: heat file}), all from the repository root.
SLICES: dict[str, tuple[Path, dict[str, Path]]] = {
    "model_one_cg2_5.0s_periodic": (
        ROOT / "results/paper/levels/runs/paper_model_one_shells_cg2/case.toml",
        {m: AIR / "bed_air_model_one_cg2_5.0s_periodic_heat" / f for m, f in
         (("local", "heat.json"), ("turbulent", "heat_turbulent.json"),
          ("molecular", "heat_molecular.json"))}),
    "model_two_5.0s_mesh0.1_periodic": (
        AIR / "bed_air_model_two_5.0s_mesh0.1_inlet-outlet" / "case.toml",
        {"local": AIR / "bed_air_model_two_5.0s_mesh0.1_periodic" / "heat.json",
         "turbulent": AIR / "bed_air_model_two_5.0s_mesh0.1_periodic" / "heat_turbulent.json",
         "molecular": AIR / "bed_air_model_two_5.0s_mesh0.1_periodic_molecular" / "heat.json"}),
}
#: The frozen analysis against the coupled loop's choices (issue 32), each switched on model
#: two's 5 s state, 0.1 m mesh, periodic (one flow, ``drumflow bed-air --heat-only`` per row):
#: label -> (mixing, flux, film); the heat file is heat_file_name's.
SWITCHES_DIR = AIR / "bed_air_model_two_5.0s_mesh0.1_periodic_switches"
SWITCHES: dict[str, tuple[str, str, str]] = {
    "the analysis (default)": ("local", "relative", "gunn"),
    "lab-frame flux": ("local", "absolute", "gunn"),
    "lab-frame flux + the bed's carried air": ("local", "carried", "gunn"),
    "Ranz-Marshall film": ("local", "relative", "ranz_marshall"),
    "molecular mixing": ("molecular", "relative", "gunn"),
    "the loop's three (lab flux, molecular, Ranz-Marshall)": ("molecular", "absolute",
                                                             "ranz_marshall"),
}
#: The plant's measured volumetric coefficient (issue 34), as in studies/interior_levels.py.
PLANT_UA = 290.0


def row(name: str, mixing: str, case_file: Path, heat_file: Path) -> dict[str, Any]:
    case = tomllib.loads(case_file.read_text())
    heat = json.loads(heat_file.read_text())
    diameter, length = float(case["drum"]["diameter"]), float(case["drum"]["length"])
    volume = math.pi / 4.0 * diameter**2 * length
    t_p, t_in = heat["particle_mean_temperature_C"], heat["air_inlet_temperature_C"]
    t_out = heat["air_outlet_temperature_C"]
    d_in, d_out = t_p - t_in, t_p - t_out
    lmtd = (d_in - d_out) / math.log(d_in / d_out) if abs(d_in - d_out) > 1e-9 else d_in
    q = float(heat["heat_W"])
    return {
        "slice": name, "mixing": mixing, "heat_file": str(heat_file.relative_to(ROOT)),
        "heat_W": q, "heat_bulk_W": heat["heat_bulk_W"],
        "bed_heat_W": heat["by_category"]["bed"]["heat_W"],
        "curtain_heat_W": heat["by_category"]["curtain"]["heat_W"],
        "contact_efficiency": heat["contact_efficiency"],
        "saturated_flow_m3_s_m": heat["saturated_flow_m3_s_m"],
        "particle_mean_C": t_p, "air_outlet_C": t_out,
        "volumetric_coefficient_W_m3K": q / (volume * d_in),
        "volumetric_coefficient_lmtd_W_m3K": q / (volume * lmtd),
        "plant_volumetric_coefficient_W_m3K": PLANT_UA,
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--out", type=Path, default=ROOT / "results" / "paper" / "levels")
    args = parser.parse_args()
    rows = [row(name, mixing, case_file, heat_file)
            for name, (case_file, files) in SLICES.items()
            for mixing, heat_file in files.items()]
    args.out.mkdir(parents=True, exist_ok=True)
    (args.out / "levels_air_around_the_bed.json").write_text(json.dumps(rows, indent=2) + "\n")
    pd.DataFrame(rows).to_csv(args.out / "levels_air_around_the_bed.csv", index=False)
    switches = []
    for label, (mixing, flux, film) in SWITCHES.items():
        heat_file = SWITCHES_DIR / heat_file_name(mixing, flux, film)
        if heat_file.is_file():  # rows not yet solved are left out, never guessed
            switches.append({"switch": label, "flux": flux, "film": film,
                             **row("model_two_5.0s_mesh0.1_periodic", mixing,
                                   SLICES["model_two_5.0s_mesh0.1_periodic"][0], heat_file)})
    (args.out / "frozen_against_loop.json").write_text(json.dumps(switches, indent=2) + "\n")
    pd.DataFrame(switches).to_csv(args.out / "frozen_against_loop.csv", index=False)
    rows += switches
    for r in rows:
        print(f"{r.get('switch', r['slice']):34.34s} {r['mixing']:9s} {r['heat_W'] / 1e3:7.1f} kW  eff "
              f"{r['contact_efficiency']:.3f}  sat {r['saturated_flow_m3_s_m']:.3g}  Ua "
              f"{r['volumetric_coefficient_W_m3K']:,.0f} "
              f"(LMTD {r['volumetric_coefficient_lmtd_W_m3K']:,.0f})")


if __name__ == "__main__":
    main()
