"""The time-to-answer ladder (drumflow.bench.time_to_answer) on synthetic runs whose answers and
wall times are known by construction (tests/support/answer_run.py): errors against the
reference, the stop of each rung, wall times and speed-ups, and the spec's errors."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from support.answer_run import RUN_TIME, answer_inputs, write_answer_run
from typer.testing import CliRunner

from drumflow.bench.answer import replay_answer
from drumflow.bench.time_to_answer import answer_ladder, load_ladder_spec, write_ladder
from drumflow.cli import app
from drumflow.errors import CaseError

WALL = 600.0  # s, the synthetic runs' DEM wall time over RUN_TIME (run_record.json)
SCALE = 2.0  # the reference's stand-in factor


def _run(root: Path, h_factor: float = 1.0) -> Path:
    h, counts = answer_inputs(seed=11)
    write_answer_run(root, h * h_factor, counts)
    (root / "run_record.json").write_text(json.dumps(
        {"dem_wall_time_s": WALL, "simulated_time_s": RUN_TIME, "dem_wall_time_source": "synthetic"}))
    return root


def _spec(folder: Path, extra: str = "", reference: str = "reference") -> Path:
    text = f'''
title = "synthetic ladder"
reference = "{reference}"
answers = ["temperature", "mass_flow", "h"]
machine = "test"

[[rungs]]
name = "reference"
description = "the same run, standing in for one twice as slow"
run = "a"
wall_scale = {SCALE}
wall_scale_source = "by construction"

[[rungs]]
name = "defaults"
description = "to the end"
run = "a"

[[rungs]]
name = "settled"
description = "stopped once settled"
run = "a"
stop = "settled"

[[rungs]]
name = "rule"
description = "the converged rule"
run = "a"
stop = "rule"

[[rungs]]
name = "biased"
description = "h 5 % high"
run = "b"
stop = "settled"
{extra}'''
    path = folder / "ladder.toml"
    path.write_text(text)
    return path


@pytest.fixture(scope="module")
def folder(tmp_path_factory: pytest.TempPathFactory) -> Path:
    root = tmp_path_factory.mktemp("ladder")
    _run(root / "a")
    _run(root / "b", h_factor=1.05)
    return root


def test_rungs_stop_where_their_rules_say_with_walls_and_errors(folder: Path) -> None:
    ladder = answer_ladder(load_ladder_spec(_spec(folder)))
    rows = ladder.table.set_index("rung")
    own = replay_answer(folder / "a")
    # The reference and the same run to its end: no error; walls WALL x SCALE and WALL.
    for name, wall in (("reference", SCALE * WALL), ("defaults", WALL)):
        assert rows.loc[name, "stop_time_s"] == pytest.approx(RUN_TIME, abs=1e-6)
        assert rows.loc[name, "wall_s"] == pytest.approx(wall, rel=1e-9)
        assert rows.loc[name, "max_error"] == pytest.approx(0.0, abs=1e-12)
        assert rows.loc[name, "within_tolerance"]
    assert rows.loc["defaults", "speedup"] == pytest.approx(SCALE)
    assert rows.loc["reference", "wall_estimated"]
    # Settled against the reference, which is the same run: the latest of the replay's own
    # settled times, and the wall time of the updates up to it (constant per update).
    t = max(own.settled_s[q] for q in ("temperature", "mass_flow", "h"))  # type: ignore[type-var]
    assert rows.loc["settled", "stop_time_s"] == pytest.approx(t)
    assert rows.loc["settled", "wall_s"] == pytest.approx(WALL * t / RUN_TIME, rel=1e-9)
    assert rows.loc["settled", "speedup"] == pytest.approx(SCALE * RUN_TIME / t, rel=1e-9)
    assert rows.loc["settled", "max_error"] <= 0.01 and rows.loc["settled", "within_tolerance"]
    # The rule's first firing, with what it reports there.
    assert own.first_fire_s is not None
    assert rows.loc["rule", "stop_time_s"] == pytest.approx(own.first_fire_s)
    assert rows.loc["rule", "value_h"] == pytest.approx(own.at_first_fire["h_W_m2K"])
    # Regression: the firing's record lacked the cascading bed's flow (NaN in the ladder).
    assert rows.loc["rule", "value_steady_mass_flow"] == pytest.approx(
        own.at_first_fire["steady_mass_flow_kg_s"])
    assert np.isfinite(rows.loc["rule", "value_steady_mass_flow"])
    assert rows.loc["rule", "wall_estimated"] and rows.loc["settled", "wall_estimated"]
    # 5 % more h: never within 1 % of the reference; errors shown at the end.
    assert np.isnan(rows.loc["biased", "stop_time_s"]) and not rows.loc["biased", "within_tolerance"]
    assert rows.loc["biased", "error_h"] == pytest.approx(0.05, abs=2e-3)
    assert "never within 1%" in rows.loc["biased", "note"] and "h" in rows.loc["biased", "note"]
    # The noise floor is the reference's relative half-width.
    ref = own.reference
    assert ladder.noise_floor["h"] == pytest.approx(ref["h_half_width_W_m2K"] / ref["h_W_m2K"])


def test_writes_three_files_and_the_cli_prints_the_table(folder: Path, tmp_path: Path) -> None:
    result = CliRunner().invoke(app, ["ladder", str(_spec(folder)), "--out", str(tmp_path)])
    assert result.exit_code == 0, result.output
    assert "settled" in result.output and "noise floor" in result.output
    for name in ("ladder.csv", "ladder.json", "ladder.png"):
        assert (tmp_path / name).stat().st_size > 0
    data = json.loads((tmp_path / "ladder.json").read_text())
    assert data["reference"] == "reference" and len(data["rungs"]) == 5
    assert data["rungs"][4]["stop_time_s"] is None  # NaN written as null
    # Runs are named relative to the results folder, so a shipped ladder.json reads the same in
    # every checkout (they were absolute paths of the machine that wrote them).
    for rung in data["spec"]["rungs"]:
        assert not Path(rung["run"]).is_absolute()
        assert (tmp_path / rung["run"]).resolve() in {(folder / "a").resolve(), (folder / "b").resolve()}


@pytest.mark.parametrize(("extra", "reference", "named"), [
    ("", "nobody", "reference = 'nobody' is not a rung"),
    ("", "settled", "the reference runs to its end"),
    ('[[rungs]]\nname = "x"\ndescription = "d"\nrun = "a"\nwall_scale = 3.0\n', "reference",
     "needs wall_scale_source"),
    ('[[rungs]]\nname = "x"\ndescription = "d"\nrun = "nowhere"\n', "reference",
     "rungs[5].run = 'nowhere'"),
    ('[[rungs]]\nname = "x"\ndescription = "d"\nrun = "a"\nstop = "sometimes"\n', "reference",
     "rungs.5.stop"),
    ('[[rungs]]\nname = "defaults"\ndescription = "d"\nrun = "a"\n', "reference",
     "repeated: defaults"),
])
def test_bad_specs_are_named_before_any_replay(folder: Path, extra: str, reference: str,
                                               named: str) -> None:
    with pytest.raises(CaseError) as err:
        load_ladder_spec(_spec(folder, extra, reference))
    assert named in str(err.value)


def test_cli_bad_spec_is_exit_2_without_traceback(folder: Path) -> None:
    result = CliRunner().invoke(app, ["ladder", str(_spec(folder, reference="nobody"))])
    assert result.exit_code == 2
    assert "Traceback" not in result.output and "nobody" in result.output


def test_ladder_of_one_rung_writes_a_plot(folder: Path, tmp_path: Path) -> None:
    spec = tmp_path / "one.toml"
    spec.write_text(f'title = "one"\nreference = "r"\n[[rungs]]\nname = "r"\ndescription = "d"\n'
                    f'run = "{folder / "a"}"\n')
    paths = write_ladder(answer_ladder(load_ladder_spec(spec)), tmp_path / "out")
    assert paths["png"].stat().st_size > 0


def test_estimated_share_between_grid_times() -> None:
    # Regression: model two's rule fired at 15.008 s, between grid times; the share was looked
    # up at 15.008 exactly, found nowhere, and its partly estimated wall was called measured.
    import pandas as pd

    from drumflow.bench.time_to_answer import estimated_share

    table = pd.DataFrame({"time_s": [1.0, 1.1, 1.2], "wall_estimated_share": [1.0, 0.5, 0.4]})
    assert estimated_share(table, 1.15) == 0.5
    assert estimated_share(table, 1.2) == 0.4
    assert estimated_share(table, 0.5) == 1.0


def test_until_replays_a_run_as_if_it_had_ended_there(folder: Path, tmp_path: Path) -> None:
    """A window shorter than the run: the rung's end, values and errors are those of the run cut
    at `until` (what `replay_answer` reports for that end time), the reference too."""
    until = round(0.6 * RUN_TIME, 3)
    spec = tmp_path / "window.toml"
    spec.write_text(f'''
title = "a window"
reference = "short"
answers = ["temperature", "h"]

[[rungs]]
name = "short"
description = "the run cut at until"
run = "{folder / 'a'}"
until = {until}

[[rungs]]
name = "whole"
description = "the same run to its end"
run = "{folder / 'a'}"

[[rungs]]
name = "short_rule"
description = "the rule, cut at until"
run = "{folder / 'a'}"
until = {until}
stop = "rule"
''')
    ladder = answer_ladder(load_ladder_spec(spec))
    rows = ladder.table.set_index("rung")
    cut = replay_answer(folder / "a", times=[until])
    end = float(cut.table["time_s"].iloc[0])  # the last output at or before `until`
    assert end <= until + 1e-9 and end > until - 0.05
    assert rows.loc["short", "stop_time_s"] == pytest.approx(end)
    assert rows.loc["short", "run_end_s"] == pytest.approx(end)
    assert ladder.reference_values["h"] == pytest.approx(float(cut.table["h_W_m2K"].iloc[0]))
    assert rows.loc["short", "max_error"] == pytest.approx(0.0, abs=1e-12)
    # The whole run differs from its first 60 % by what h drifts after `until`.
    whole_h = float(replay_answer(folder / "a").reference["h_W_m2K"])
    assert rows.loc["whole", "error_h"] == pytest.approx(whole_h / ladder.reference_values["h"] - 1.0)
    # The rule cannot fire in a window ending before its minimum time: it runs to `until`.
    assert rows.loc["short_rule", "stop_time_s"] <= until + 1e-9
    bad = spec.read_text().replace(f"until = {until}\n", "until = -1\n", 1)
    with pytest.raises(CaseError, match="until"):
        load_ladder_spec(_write(tmp_path / "bad.toml", bad))


def _write(path: Path, text: str) -> Path:
    path.write_text(text)
    return path
