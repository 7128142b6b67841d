"""The README's measured numbers are its results files' (issue 37, item 7). The README is not
rendered by MkDocs, so its numbers are typed; each row below names the typed text, the shipped file
and the key it comes from (read with the documentation's own ``value`` macro), and the test fails
when the file and the README disagree. Derived ratios are computed here from their two files."""

from __future__ import annotations

import importlib.util
import json
import re
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
README = (ROOT / "README.md").read_text(encoding="utf-8")

_spec = importlib.util.spec_from_file_location("drumflow_docs_doc_numbers_readme",
                                               ROOT / "docs" / "gen" / "doc_numbers.py")
assert _spec and _spec.loader
numbers = importlib.util.module_from_spec(_spec)
sys.modules[_spec.name] = numbers
_spec.loader.exec_module(numbers)

SMOKE = "docs/smoke/smoke_bench_results.csv"
PLANT = "docs/plant/paper_model_one_plant.json"
SPIN = "results/bench/paper_model_two_spin/ladder.csv"
CG_LADDER = "results/bench/paper_model_two_ladder/ladder.csv"
MEASURED = "results/bench/paper_model_two_ladder_measured/ladder.csv"
PERIODIC = "docs/plant/paper_model_one_plant_periodic.json"
AIR_CLOSURES = "docs/plant/paper_model_one_plant_air_closures.json"
LEVELS = "results/paper/levels/levels_model_two_cg2_mesh0.1.csv"

#: (text typed in the README with its number in brackets, file, key, format). The text without
#: the brackets is searched as it stands in a sentence; the value read from the file, formatted,
#: must be the bracketed number.
TYPED: list[tuple[str, str, str, str]] = [
    ("[83.63] °C mean temperature", SMOKE, "default.mean_temperature_C", ".2f"),
    ("[0.271] kg/s falling", SMOKE, "default.falling_mass_flow_kg_s", ".3f"),
    ("h = [76.5] W/(m² K)", SMOKE, "default.h_W_m2K", ".1f"),
    ("in [127] s of DEM wall time", SMOKE, "default.dem_wall_time_s", ".0f"),
    ("3.5 s [88.10] °C", "results/bench/paper_model_two_coarse_grain/comparison.csv",
     "quantity=mean_temperature_at_3.5_s_C:full", ".2f"),
    ("h from Eq. 39 is [47.4]", "results/paper/model_two/post/methodology.json",
     "heat_transfer.h_mean_W_m2K", ".1f"),
    ("reached [12.12] s", "results/paper/model_one/summary.json", "simulated_time_s", ".2f"),
    ("h [77.2] against", "results/paper/model_one/post/methodology.json",
     "heat_transfer.h_mean_W_m2K", ".1f"),
    ("predicts [30.6] °C", PLANT, "material_outlet_temperature_C", ".1f"),
    ("needs [1.63] m³/s per", PLANT, "curtain_air.needed_for_measured_material_outlet."
     "curtain_air_m3_s_per_m", ".2f"),
    ("measures [3.71] (its saturated flow", "docs/plant/paper_model_one_plant_periodic.json",
     "curtain_air.setting_m3_s_per_m", ".2f"),
    ("[37.8] °C, 8.7 K low", "docs/plant/paper_model_one_plant_periodic.json",
     "material_outlet_temperature_C", ".1f"),
    ("share alone, [2.73]", "docs/plant/paper_model_one_plant_periodic_curtains.json",
     "curtain_air.setting_m3_s_per_m", ".2f"),
    ("gives [40.6] °C", "docs/plant/paper_model_one_plant_periodic_curtains.json",
     "material_outlet_temperature_C", ".1f"),
    ("mixing ([3.22]-19.2)", AIR_CLOSURES,
     "curtain_air.mixing_bounds.molecular.curtain_air_m3_s_per_m", ".2f"),
    ("mixing (3.22-[19.2])", AIR_CLOSURES,
     "curtain_air.mixing_bounds.turbulent.curtain_air_m3_s_per_m", ".1f"),
    ("gives [39.0]-31.5 °C", AIR_CLOSURES, "curtain_air.mixing_bounds.molecular.material_outlet_C", ".1f"),
    ("gives 39.0-[31.5] °C", AIR_CLOSURES, "curtain_air.mixing_bounds.turbulent.material_outlet_C", ".1f"),
    ("flow by [5.4] %", SPIN, "default_step.error_steady_mass_flow", ".1%"),
    ("heat answer to\n  [0.35] %", CG_LADDER, "parcels.error_h", ".2%"),
    ("flow by [7.5] %", CG_LADDER, "parcels.error_steady_mass_flow", ".1%"),
    ("| measured (the paper's Table 1) | [46.5] |", PLANT, "measured.material_outlet_C", ".1f"),
    ("| measured (the paper's Table 1) | 46.5 | [59.0] |", PLANT, "measured.air_outlet_C", ".1f"),
    ("A 1,099 m²) | [40.92] |", PLANT, "paper_exchanger.material_outlet_C", ".2f"),
    ("A 1,099 m²) | 40.92 | [69.76] |", PLANT, "paper_exchanger.air_outlet_C", ".2f"),
    ("every falling granule | [30.62] |", PLANT, "material_outlet_temperature_C", ".2f"),
    ("every falling granule | 30.62 | [78.10] |", PLANT, "air_outlet_temperature_C", ".2f"),
    ("falling flow [109.5] kg/(s m)", PLANT, "plant_closures.falling_mass_flow_kg_s_m", ".1f"),
    ("fall height [1.21] m", PLANT, "plant_closures.fall_height_m", ".2f"),
    ("bed surface [2.68] m²/m", PLANT, "plant_closures.bed_surface_m2_per_m", ".2f"),
    ("from the periodic slice | [37.75] |", PERIODIC, "material_outlet_temperature_C", ".2f"),
    ("from the periodic slice | 37.75 | [72.32] |", PERIODIC, "air_outlet_temperature_C", ".2f"),
    ("and [3.71] m³/s per m through", PERIODIC, "curtain_air.setting_m3_s_per_m", ".2f"),
    ("dashpot, to 17.5 s | [17.50] |", MEASURED, "rung=reference:stop_time_s", ".2f"),
    ("dashpot, to 17.5 s | 17.50 | [26,895] |", MEASURED, "rung=reference:wall_s", ",.0f"),
    ("replayed on its series) | [14.00] |", MEASURED, "rung=reference_rule:stop_time_s", ".2f"),
    ("replayed on its series) | 14.00 | [22,983] |", MEASURED, "rung=reference_rule:wall_s", ",.0f"),
    ("| 22,983 | 0 | [+0.08] % |", MEASURED, "rung=reference_rule:error_steady_mass_flow", "+.2%"),
    ("| 22,983 | 0 | +0.08 % | [-0.01] % |", MEASURED, "rung=reference_rule:error_h", "+.2%"),
    ("old step (0.000298 s), dashpot, to 17.5 s | [17.51] |", MEASURED, "rung=old_defaults:stop_time_s",
     ".2f"),
    ("| 17.51 | [18,788] | +0.01 % |", MEASURED, "rung=old_defaults:wall_s", ",.0f"),
    ("| 18,788 | [+0.01] % |", MEASURED, "rung=old_defaults:error_temperature", "+.2%"),
    ("| 18,788 | +0.01 % | [+5.82] % |", MEASURED, "rung=old_defaults:error_steady_mass_flow", "+.2%"),
    ("| 18,788 | +0.01 % | +5.82 % | [-0.11] % |", MEASURED, "rung=old_defaults:error_h", "+.2%"),
    ("the old step, to 17.5 s | 17.51 | [821] |", MEASURED, "rung=parcels:wall_s", ",.0f"),
    ("| 821 | [-0.00] % |", MEASURED, "rung=parcels:error_temperature", "+.2%"),
    ("| 821 | -0.00 % | [+14.12] % |", MEASURED, "rung=parcels:error_steady_mass_flow", "+.2%"),
    ("| 821 | -0.00 % | +14.12 % | [+0.24] % |", MEASURED, "rung=parcels:error_h", "+.2%"),
    ("the rule live, from t = 0 | [14.01] |", MEASURED, "rung=fast:stop_time_s", ".2f"),
    ("from t = 0 | 14.01 | [17,686] |", MEASURED, "rung=fast:wall_s", ",.0f"),
    ("| 17,686 | [-0.00] % |", MEASURED, "rung=fast:error_temperature", "+.2%"),
    ("| 17,686 | -0.00 % | [+0.02] % |", MEASURED, "rung=fast:error_steady_mass_flow", "+.2%"),
    ("| 17,686 | -0.00 % | +0.02 % | [+0.00] % |", MEASURED, "rung=fast:error_h", "+.2%"),
    ("cascading flow is\n  [5.8] % high", MEASURED, "old_defaults.error_steady_mass_flow", ".1%"),
    ("the reference at\n  [14.0] s within", MEASURED, "reference_rule.stop_time_s", ".1f"),
    ("within [0.08] % of its end", MEASURED, "reference_rule.error_steady_mass_flow", ".2%"),
    ("falls from [4,389] W/(m³ K)", LEVELS, "level=lumped:volumetric_coefficient_lmtd_W_m3K", ",.0f"),
    ("to [3,336] with heat", LEVELS, "level=shells:volumetric_coefficient_lmtd_W_m3K", ",.0f"),
    ("[1,046] with air that warms", LEVELS, "level=shells_warming:volumetric_coefficient_lmtd_W_m3K",
     ",.0f"),
    ("and [82.3] with\n  the air around", LEVELS, "level=around_bed:volumetric_coefficient_lmtd_W_m3K",
     ".1f"),
    ("contact efficiency [0.079])", LEVELS, "level=around_bed:contact_efficiency", ".3f"),
    ("one state: [431] W/(m³ K)", "results/paper/levels/levels_model_one_cg2_1phase.csv",
     "level=around_bed:volumetric_coefficient_lmtd_W_m3K", ",.0f"),
    ("([8,880] s on this VM", "results/paper/levels/runs/paper_model_one_around_bed_cg2_1phase/"
     "summary.json", "wall_time_s", ",.0f"),
    ("the level now costs [1.06] times one-way", "results/bench/paper_model_one_levels_around_bed_cg2/"
     "levels.json", "summary.air around the bed.loop_cost_vs_first", ".2f"),
]


def _number(text: str) -> str:
    """The bracketed number of a README phrase."""
    found = re.search(r"\[([^]]+)\]", text)
    assert found, f"no [number] in {text!r}"
    return found.group(1)


def _value(file: str, key: str, fmt: str) -> str:
    """``key`` as the macro takes it, or ``column=label:key`` for a CSV row picked by a label."""
    if "=" in key:
        pick, key = key.split(":", 1)
        column, label = pick.split("=", 1)
        return str(numbers.value(file, key, fmt, row={column: label})).rstrip("%")
    return str(numbers.value(file, key, fmt)).rstrip("%")


@pytest.mark.parametrize(("text", "file", "key", "fmt"), TYPED, ids=[t[0].replace("\n", " ") for t in TYPED])
def test_a_typed_readme_number_is_its_files(text: str, file: str, key: str, fmt: str) -> None:
    typed = text.replace("[", "").replace("]", "")
    assert typed in README, f"README no longer says {typed!r}: update this table with it"
    assert _value(file, key, fmt) == _number(text), f"{file} {key}"


def _json(path: str) -> dict:
    return json.loads((ROOT / path).read_text())


def test_model_one_around_the_bed_against_the_plant() -> None:
    """'431 W/(m³ K), 1.49 times the plant's': the run's coefficient over the table's plant."""
    table = "results/paper/levels/levels_model_one_cg2_1phase.csv"
    ua = float(numbers.value(table, "volumetric_coefficient_lmtd_W_m3K"))
    plant = float(numbers.value(table, "plant_volumetric_coefficient_W_m3K"))
    assert f"{ua / plant:.2f} times the plant's" in README.replace("\n  ", " ")


def test_the_levels_costs_and_states() -> None:
    """'one state gives the answer of four within 0.03 %', 'costs 3.0 times one-way at these
    parcels (the four states' porous solves, 1,253 s, and its DEM against one-way's whole run)':
    the 1-state table against the 4-state row, the bed states' solve time from the runs' shipped
    air record against the lumped run."""
    one = float(numbers.value("results/paper/levels/levels_model_two_cg2_mesh0.1_1phase.csv",
                              "volumetric_coefficient_lmtd_W_m3K"))
    four = float(numbers.value(LEVELS, "volumetric_coefficient_lmtd_W_m3K", row={"level": "around_bed"}))
    assert f"{abs(one / four - 1):.2%}" == "0.03%"
    runs = ROOT / "results" / "paper" / "levels" / "runs"
    solve = sum(s["wall_time_s"] for s in _json(str(runs / "paper_model_two_around_bed_cg2_mesh0.1"
                                                      / "air" / "bed_phases.json"))["states"])
    assert f"{solve:,.0f}" == "1,253"
    dem = _json(str(runs / "paper_model_two_around_bed_cg2_mesh0.1" / "summary.json"))["dem_wall_time_s"]
    lumped = _json(str(runs / "paper_model_two_lumped_cg2_mesh0.1" / "summary.json"))["wall_time_s"]
    assert f"{(solve + dem) / lumped:.1f}" == "3.0"


def test_the_coarse_graining_cost_ratio() -> None:
    """'23 times cheaper over 17.5 s ... (821 against 18,788 s of DEM, each run's run_record.json)'."""
    full = _json("results/paper/model_two/run_record.json")
    parcels = _json("results/paper_parcels/model_two/run_record.json")
    walls = [float(numbers.value(p, "dem_wall_time_s", ".0f").replace(",", ""))
             for p in ("results/paper/model_two/run_record.json",
                       "results/paper_parcels/model_two/run_record.json")]
    assert full and parcels
    assert f"{walls[1]:,.0f} against {walls[0]:,.0f} s of DEM" in README
    assert f"{walls[0] / walls[1]:.0f} times cheaper" in README


def test_the_fast_profile_ratio() -> None:
    """'2.82 times the conservative reference's speed ... fast_8.0s.csv' (coupled wall times)."""
    f = "results/bench/paper_model_one_settings/fast_8.0s.csv"
    rows = numbers._records(f, ROOT)
    first = next(iter(rows[0]))
    wall = {r[first]: float(r["coupled_wall_s"]) for r in rows}
    reference = max(wall.values())  # the conservative reference is the slowest row
    fast = min(wall.values())
    assert f"{reference / fast:.2f} times the conservative" in README


def test_the_papers_mesh_spread() -> None:
    """'needs h of 79 -> 62 -> 55 ... on model one and 79 -> 39 -> 24 on model two' and '0.22 K
    from its mesh-1 value (82.42)': the paper's tables through the paper cases' lumped solution."""
    from drumflow.analysis.published import PAPER_MODELS, mesh_h
    from drumflow.case import load_case

    flat = " ".join(README.split())
    for model, name in (("one", "model one"), ("two", "model two")):
        h = mesh_h(model, load_case(ROOT / "cases" / f"paper_model_{model}.toml"))  # type: ignore[arg-type]
        chain = " → ".join(f"{h[m]:.0f}" for m in ("mesh 1", "mesh 2", "mesh 3"))
        assert f"{chain} W/(m² K) on {name}" in flat or f"{chain} on {name}" in flat, (chain, name)
    ours = float(numbers.value("results/paper/model_one/post/mean_temperature.csv", "mean_temperature_C",
                               ".2f", row={"time_s": 3.50042208}))
    mesh1 = PAPER_MODELS["one"].mean_temperature_3p5s_mesh1_C
    assert f"{ours - mesh1:.2f} K from its mesh-1 value ({mesh1:.2f})" in flat


def test_the_loops_air_solve_speed_up() -> None:
    """'since made 10 times faster': the replay of model one's run of air around the bed, one
    preconditioner switch against one per system (results/bench/air_heat)."""
    replay = [r for r in _json("results/bench/air_heat/results.json")["results"]
              if r["grid"].startswith("replay of")]
    assert len(replay) == 1
    assert f"since made {replay[0]['speedup_median']:.0f} times faster" in README.replace("\n  ", " ")
