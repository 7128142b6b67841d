"""The timing-breakdown parser of :mod:`drumflow.bench.profile` on real LIGGGHTS 3.8 log text."""

from __future__ import annotations

import math

import pytest

from drumflow.bench.profile import CATEGORIES, GROUPS, parse_breakdowns

# A paper-scale interval run with `post no` (m2_air, 299,164 particles, 2 ranks): a loop time
# and no breakdown.
POST_NO = """\
    Step       sim_time    Atoms         KinEng         ke_rot         T_mean       overlap_            CPU
    3332 0.991786256748   299164 224.172952281 8.51878334053 89.4588361527 0.00428125612502 0
    3366 1.00190652467   299164 222.940665324 8.41640203146 89.4533557835 0.00422919399194 9.462389024
Loop time of 9.46255 on 2 procs for 34 steps with 299164 atoms, finish time Mon Nov 23 21:08:44 2026
"""

# The tiny drum on 2 ranks, an interval run with `post yes` under `modify_timing on`: the
# breakdown, every fix's time and the neighbour statistics. The end of the previous block comes
# first (its neighbour lines must not be taken for this one's). Trailing blanks dropped, and two
# of the last thermo row's leading ones (line length); the parser splits on white space.
POST_YES = """\
Neighbor list builds = 3
Dangerous builds = 0
    Step       sim_time    Atoms         KinEng         ke_rot         T_mean       overlap_            CPU
     320 0.020153032448      500 0.00335291664586 0.000127324897975 89.957029094 0.000102682254851 0
     400 0.02519129056      500 0.00382170326586 0.00015285560233 89.9462510982 7.97047288959e-05 0.204106946
   480 0.030229548672      500 0.00405698831208 0.000175340122642 89.9354731023 7.77537052365e-05 0.330106433
Loop time of 0.332466 on 2 procs for 160 steps with 500 atoms, finish time Mon Nov 23 21:27:37 2026


Pair  time (%) = 0.0138352 (4.16138)
Neigh time (%) = 0.00631637 (1.89985)
Comm  time (%) = 0.158388 (47.6404)
Outpt time (%) = 0.00407594 (1.22597)
Modfy time (%) = 0.271789 (81.7492)
Other time (%) = -0.121938 (-36.6768)
Fix m1 property/global time (%) = 6.71e-07 (0.000201825)
Fix m2 property/global time (%) = 1.755e-07 (5.27873e-05)
Fix m3 property/global time (%) = 2.155e-07 (6.48186e-05)
Fix m4 property/global time (%) = 2.705e-07 (8.13616e-05)
Fix m5 property/global time (%) = 1.25e-07 (3.75978e-05)
Fix m6 property/global time (%) = 2.61e-07 (7.85042e-05)
Fix m7 property/global time (%) = 9.55e-08 (2.87247e-05)
Fix m8 property/global time (%) = 2.35e-07 (7.06838e-05)
Fix gravi gravity time (%) = 0.00022722 (0.0683436)
Fix shell mesh/surface time (%) = 0.000556973 (0.167527)
Fix lifters mesh/surface time (%) = 0.0124067 (3.73173)
Fix walls wall/gran time (%) = 0.0399759 (12.024)
Fix wall_neighlist_shell neighlist/mesh time (%) = 0.00201358 (0.605648)
Fix n_neighs_mesh_shell property/atom time (%) = 2.1295e-06 (0.000640516)
Fix tracker_shell contacthistory/mesh time (%) = 0.000126367 (0.0380088)
Fix wall_neighlist_lifters neighlist/mesh time (%) = 0.00993999 (2.98977)
Fix n_neighs_mesh_lifters property/atom time (%) = 6.86e-07 (0.000206337)
Fix tracker_lifters contacthistory/mesh time (%) = 6.46575e-05 (0.0194478)
Fix spin move/mesh time (%) = 0.063874 (19.2122)
Fix end_in wall/gran time (%) = 0.00046736 (0.140574)
Fix history_end_in property/atom time (%) = 5.76e-07 (0.000173251)
Fix end_out wall/gran time (%) = 0.000144566 (0.0434829)
Fix history_end_out property/atom time (%) = 3.45e-07 (0.00010377)
Fix heat heat/gran/conduction time (%) = 0.0517044 (15.5518)
Fix directionalHeatFlux property/atom time (%) = 1.255e-07 (3.77482e-05)
Fix ste_heattransfer transportequation/scalar time (%) = 0.0873953 (26.287)
Fix Temp property/atom time (%) = 1.155e-07 (3.47404e-05)
Fix heatFlux property/atom time (%) = 6.42e-07 (0.000193102)
Fix heatSource property/atom time (%) = 1.15e-07 (3.459e-05)
Fix air_fx property/atom time (%) = 8.465e-07 (0.000254612)
Fix air_fy property/atom time (%) = 3.155e-07 (9.48968e-05)
Fix air_fz property/atom time (%) = 2.51e-07 (7.54963e-05)
Fix air_drag addforce time (%) = 0.00191307 (0.575419)
Fix integrate nve/sphere time (%) = 0.000778599 (0.234189)
Fix contacthistory contacthistory time (%) = 0.00019161 (0.0576327)

Nlocal:    250 ave 259 max 241 min
Histogram: 1 0 0 0 0 0 0 0 0 1
Nghost:    58.5 ave 61 max 56 min
Histogram: 1 0 0 0 0 0 0 0 0 1
Neighs:    1541 ave 1573 max 1509 min
Histogram: 1 0 0 0 0 0 0 0 0 1

Total # of neighbors = 3082
Ave neighs/atom = 6.164
Neighbor list builds = 5
Dangerous builds = 0
"""

#: LIGGGHTS prints each time and percentage with %g (6 significant digits): a percentage below
#: 100 is off by at most 5e-5, so six categories (or the fix groups) add up to their total
#: within 3e-4. 1e-3 leaves room and still catches a category lost or counted twice.
ROUNDING = 1e-3


def test_post_no_run_has_a_loop_time_and_no_breakdown() -> None:
    table = parse_breakdowns(POST_NO)
    assert len(table) == 1
    row = table.iloc[0]
    assert (row["step"], row["steps"], row["atoms"], row["procs"]) == (3366, 34, 299164, 2)
    assert row["sim_time_s"] == pytest.approx(1.00190652467)
    assert row["loop_s"] == pytest.approx(9.46255)
    assert not row["breakdown"]
    assert all(math.isnan(row[f"{c}_pct"]) for c in CATEGORIES)


def test_post_yes_block_gives_the_breakdown_and_the_fix_groups() -> None:
    table = parse_breakdowns(POST_YES)
    assert len(table) == 1
    row = table.iloc[0]
    assert (row["step"], row["steps"], row["atoms"], row["procs"]) == (480, 160, 500, 2)
    assert row["sim_time_s"] == pytest.approx(0.030229548672)
    assert row["loop_s"] == pytest.approx(0.332466)
    assert row["breakdown"]
    assert row["pair_pct"] == pytest.approx(4.16138)
    assert row["neigh_s"] == pytest.approx(0.00631637)
    assert row["comm_pct"] == pytest.approx(47.6404)
    assert row["output_pct"] == pytest.approx(1.22597)
    assert row["modify_pct"] == pytest.approx(81.7492)
    # Two ranks: the fixes' own communication is also stamped as Comm, so Other is negative.
    assert row["other_pct"] == pytest.approx(-36.6768)
    assert sum(row[f"{c}_pct"] for c in CATEGORIES) == pytest.approx(100.0, abs=ROUNDING)
    # Fix groups: heat/gran/conduction 15.5518 + transportequation/scalar 26.287; addforce alone.
    assert row["conduction_pct"] == pytest.approx(15.5518 + 26.287)
    assert row["air_drag_pct"] == pytest.approx(0.575419)
    assert row["integration_pct"] == pytest.approx(0.234189 + 0.0683436)
    walls = (0.167527 + 3.73173 + 12.024 + 0.605648 + 0.0380088 + 2.98977 + 0.0194478 + 19.2122
             + 0.140574 + 0.0434829)
    assert row["walls_pct"] == pytest.approx(walls)
    assert sum(row[f"{g}_pct"] for g in GROUPS) == pytest.approx(row["modify_pct"], abs=ROUNDING)
    assert row["neighs_per_atom"] == pytest.approx(6.164)
    assert (row["neighbor_builds"], row["dangerous_builds"]) == (5, 0)


def test_text_without_a_run_gives_an_empty_table() -> None:
    table = parse_breakdowns("LIGGGHTS (Version LIGGGHTS-PUBLIC 3.8.0)\n  500 atoms\n")
    assert table.empty
    assert {"step", "loop_s", "pair_pct", "walls_pct"} <= set(table.columns)


def test_build_counts_are_running_totals_between_set_ups() -> None:
    # Regression: LIGGGHTS counts neighbour-list builds from the last run that was set up, and
    # the coupling loop's `run N pre no` is not; summing the printed totals overcounted the
    # builds 3.5 times in the paper-scale settings study. Counts below are model two's (2
    # ranks, consecutive 34-step runs from the 3.47 s restart, each ending with `post yes`).
    def block(step: int, builds: int, dangerous: int = 0) -> str:
        return (f"    {step} 1.0 299164 1 1 88 0.004 0\n"
                f"Loop time of 17.0 on 2 procs for 34 steps with 299164 atoms, finish time x\n"
                f"Pair  time (%) = 1 (100)\nNeighbor list builds = {builds}\n"
                f"Dangerous builds = {dangerous}\n")

    text = ("Setting up run at Mon Nov 23 22:22:24 2026\n    11662 3.47 299164 1 1 88 0.004 0\n"
            "Loop time of 4.1e-06 on 2 procs for 0 steps with 299164 atoms, finish time x\n"
            "Neighbor list builds = 0\nDangerous builds = 0\n"
            + block(11696, 11) + block(11730, 22) + block(11764, 34, 1)
            # A later set-up (a run the deck issued itself) starts the count again.
            + "Setting up run at y\n" + block(11798, 12))
    table = parse_breakdowns(text)
    done = table[table["steps"] > 0]
    assert done["neighbor_builds_since"].tolist() == [11, 11, 12, 12]
    assert done["dangerous_builds_since"].tolist() == [0, 0, 1, 0]
    assert done["steps_since"].tolist() == [34, 34, 34, 34]
    # A breakdown only every other run: the increment covers both runs' steps.
    sparse = parse_breakdowns(text.replace("Neighbor list builds = 11\n", ""))
    row = sparse[sparse["step"] == 11730].iloc[0]
    assert (row["neighbor_builds_since"], row["steps_since"]) == (22, 68)
