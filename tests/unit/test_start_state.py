"""Start states (drumflow.dem.state): pack/unpack round trip, refusals, the case field and the
deck a start state renders."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from drumflow.case import Case, case_from_dict, load_case, read_toml
from drumflow.dem.dumps import Snapshot
from drumflow.dem.state import (
    StartState,
    check_state,
    data_file_text,
    read_state,
    state_from_snapshot,
    temperature_file_text,
    write_state,
)
from drumflow.errors import EXIT_BAD_INPUT, StartStateError, exit_code

ROOT = Path(__file__).resolve().parents[2]
SMOKE = ROOT / "cases" / "smoke.toml"


def _case(**run: object) -> Case:
    data = read_toml(SMOKE)
    data["run"].update(run)
    return case_from_dict(data)


def _state(case: Case, n: int | None = None, seed: int = 3) -> StartState:
    n = case.particle_count if n is None else n
    rng = np.random.default_rng(seed)
    cols = {
        "id": np.arange(1, n + 1, dtype=np.float64),
        # Positions with every digit a text snapshot can carry, and more.
        **{c: rng.uniform(-0.19, 0.19, n) for c in "xyz"},
        **{c: rng.normal(0.0, 0.3, n) for c in ("vx", "vy", "vz")},
        **{c: rng.normal(0.0, 5.0, n) for c in ("omegax", "omegay", "omegaz")},
        "radius": np.full(n, 0.004),
        "T": 87.0 + rng.uniform(0.0, 3.0, n),
    }
    return state_from_snapshot(Snapshot(28800, cols), case, 3.5036e-5, "synthetic")


def test_round_trip_keeps_positions_and_temperatures_exactly(tmp_path: Path) -> None:
    case = _case()
    state = _state(case)
    path = write_state(state, tmp_path / "s.npz")
    back = read_state(path)
    assert np.array_equal(back.ids, state.ids)
    # float64: no contact overlaps more than in the source.
    assert np.array_equal(back.positions, state.positions)
    assert np.array_equal(back.temperatures_C, state.temperatures_C)
    assert np.array_equal(back.radii, state.radii)
    # float32: 7.2 digits against the text's 6.
    assert np.allclose(back.velocities, state.velocities, rtol=1e-7, atol=0)
    assert np.allclose(back.spins, state.spins, rtol=1e-7, atol=0)
    assert back.time_s == pytest.approx(28800 * 3.5036e-5, rel=1e-15)
    assert back.drum_angle_rad == pytest.approx(case.drum.omega * back.time_s, rel=1e-15)
    assert (back.case_hash, back.scene_hash) == (state.case_hash, state.scene_hash)
    assert back.step == 28800 and back.drumflow_version == state.drumflow_version
    # 3,000 particles of random data (the worst case for compression): under 60 bytes each.
    assert path.stat().st_size < 60 * len(state)
    assert not list(tmp_path.glob("*.partial"))


def test_ids_that_are_not_consecutive_are_kept(tmp_path: Path) -> None:
    case = _case()
    state = _state(case, n=10)
    ids = np.array([1, 2, 3, 5, 8, 13, 21, 34, 55, 89], dtype=np.int64)
    odd = StartState(**{**state.__dict__, "ids": ids})
    assert np.array_equal(read_state(write_state(odd, tmp_path / "s.npz")).ids, ids)


def test_refuses_another_scene_and_another_count() -> None:
    case = _case()
    state = _state(case)
    check_state(state, case, "s.npz")  # the run section may differ: the scene is the same
    check_state(state, _case(time=9.0, dump_interval=0.01), "s.npz")
    data = read_toml(SMOKE)
    data["drum"]["rpm"] = 20.0
    with pytest.raises(StartStateError, match=r"run\.start_state.*another scene") as err:
        check_state(state, case_from_dict(data), "s.npz")
    assert exit_code(err.value) == EXIT_BAD_INPUT
    fewer = _state(case, n=100)
    with pytest.raises(StartStateError, match="100 particles, the case 3,000"):
        check_state(fewer, case, "s.npz")


def test_refuses_a_file_that_is_not_a_state(tmp_path: Path) -> None:
    other = tmp_path / "other.npz"
    np.savez(other, a=np.arange(3))
    with pytest.raises(StartStateError, match="not a drumflow start state"):
        read_state(other)
    with pytest.raises(StartStateError, match="no such file"):
        read_state(tmp_path / "missing.npz")


def test_snapshot_without_spins_is_refused() -> None:
    from drumflow.errors import RunDirectoryError

    cols = {c: np.zeros(3) for c in ("id", "x", "y", "z", "vx", "vy", "vz", "radius", "T")}
    with pytest.raises(RunDirectoryError, match="omegax"):
        state_from_snapshot(Snapshot(0, cols), _case(), 1e-5)


def test_case_field_keeps_old_hashes_and_resolves_against_the_case_file(tmp_path: Path) -> None:
    plain = load_case(SMOKE)
    assert "start_state" not in plain.canonical_json()
    text = SMOKE.read_text().replace("[run]\n", '[run]\nstart_state = "states/s.npz"\n', 1)
    (tmp_path / "c.toml").write_text(text)
    case = load_case(tmp_path / "c.toml")
    assert case.run.start_state == str((tmp_path / "states" / "s.npz").resolve())
    assert case.hash() != plain.hash()


def test_data_and_temperature_files_carry_every_digit() -> None:
    case = _case()
    state = _state(case, n=5)
    text = data_file_text(state, case, ((-0.2, -0.2, -0.01), (0.2, 0.2, 0.09)))
    atoms = text.split("Atoms\n\n")[1].split("\n\nVelocities")[0].splitlines()
    first = [float(v) for v in atoms[0].split()]
    assert first[4:7] == list(state.positions[0])
    assert first[2] == 2 * state.radii[0]
    assert len(text.split("Velocities\n\n")[1].splitlines()) == 5
    lines = temperature_file_text(state).splitlines()
    assert lines[1] == "5"  # a LAMMPS atomfile: the count, then "id value"
    assert float(lines[2].split()[1]) == state.temperatures_C[0]


def test_deck_from_a_state_sets_clock_angle_and_temperatures() -> None:
    from drumflow.dem.deck import DeckFiles, deck_context, plan_steps, render_deck
    from drumflow.dem.timestep import choose_time_step

    case = _case()
    plan = plan_steps(case, choose_time_step(case))
    files = DeckFiles(lifters_stl_file="../geometry/lifters.stl", static_shell=True)
    deck = render_deck(deck_context(case, plan, files, start_step=28800, coupled=True))
    angle = np.degrees(case.drum.omega * 28800 * plan.time_step) % 360
    assert "reset_timestep  28800" in deck
    assert f"lifters.stl type 2 rotate axis 0. 0. 1. angle {angle:.12g}\n" in deck
    assert "variable start_T atomfile start_temperatures.txt" in deck
    assert "dump resume_mesh all mesh/stl 1 mesh_at_resume.*.stl lifters" in deck
    # The clock is reset after pair/gran/local (which refuses a later definition), before dumps.
    assert deck.index("compute contacts") < deck.index("reset_timestep") < deck.index("dump cross")
    fresh = render_deck(deck_context(case, plan, files, coupled=True))
    assert "reset_timestep" not in fresh and "rotate axis" not in fresh


def test_shipped_state_fits_the_smoke_case() -> None:
    state = read_state(ROOT / "results" / "states" / "smoke_1.0s.npz")
    check_state(state, load_case(SMOKE), "smoke_1.0s.npz")
    assert len(state) == 3000 and state.time_s == pytest.approx(1.009, abs=1e-3)
    assert (ROOT / "results" / "states" / "smoke_1.0s.npz").stat().st_size < 200_000


def test_case_hash_names_the_state_by_content_not_by_place(tmp_path: Path) -> None:
    """Regression: the resolved path entered the hash, so a moved checkout restarted its runs."""
    import shutil

    from drumflow.case import load_case

    shipped = Path(__file__).resolve().parents[2]
    hashes = []
    for place in ("a", "b"):
        folder = tmp_path / place
        folder.mkdir()
        shutil.copyfile(shipped / "results" / "states" / "smoke_1.0s.npz", folder / "state.npz")
        text = (shipped / "cases" / "smoke.toml").read_text().replace(
            "[run]\n", '[run]\nstart_state = "state.npz"\n', 1)
        (folder / "case.toml").write_text(text)
        hashes.append(load_case(folder / "case.toml").hash())
    assert hashes[0] == hashes[1]


def test_a_state_of_another_scene_is_refused_before_any_stage(tmp_path: Path) -> None:
    """Regression: the refusal came from the DEM stage, after the geometry and air stages ran."""
    import shutil
    import subprocess
    import sys

    shipped = Path(__file__).resolve().parents[2]
    shutil.copyfile(shipped / "results" / "states" / "smoke_1.0s.npz", tmp_path / "state.npz")
    text = (shipped / "cases" / "smoke.toml").read_text()
    text = text.replace("[run]\n", '[run]\nstart_state = "state.npz"\n', 1).replace(
        "rpm = 15.0", "rpm = 12.0", 1)
    (tmp_path / "case.toml").write_text(text)
    out = subprocess.run([sys.executable, "-m", "drumflow.cli", "run", str(tmp_path / "case.toml"),
                          "--out", str(tmp_path / "run")], capture_output=True, text=True,
                         timeout=120, check=False)
    assert out.returncode == 2, out.stdout + out.stderr
    assert "run.start_state" in out.stdout + out.stderr
    assert not (tmp_path / "run").exists()  # nothing left behind


#: The paper scenes' states (issue 35, item 2): the bed settled (2 s) and cascading (5 s); the
#: parcel states (coarse grain 2) from the level runs of results/paper/levels, model two's with
#: every particle from the rerun of its case that gave its closures (results/paper/README.md),
#: each against the case it fits, with its size limit (~42-52 bytes per particle).
LEVELS = Path("results") / "paper" / "levels" / "runs"
PAPER_STATES = {
    "paper_model_one_cg2_2.0s.npz": (LEVELS / "paper_model_one_shells_cg2" / "case.toml", 58_430, 2.009, 4e6),
    "paper_model_one_cg2_5.0s.npz": (LEVELS / "paper_model_one_shells_cg2" / "case.toml", 58_430, 5.002, 4e6),
    "paper_model_two_cg2_5.0s.npz": (LEVELS / "paper_model_two_lumped_cg2" / "case.toml", 37_396, 5.009, 4e6),
    "paper_model_two_2.0s.npz": (Path("cases") / "paper_model_two.toml", 299_164, 1.984, 20e6),
    "paper_model_two_5.0s.npz": (Path("cases") / "paper_model_two.toml", 299_164, 4.959, 20e6),
}


@pytest.mark.parametrize("name", sorted(PAPER_STATES))
def test_shipped_paper_states_fit_their_cases(name: str) -> None:
    case_file, count, time_s, size = PAPER_STATES[name]
    path = ROOT / "results" / "states" / name
    state = read_state(path)
    check_state(state, load_case(ROOT / case_file), name)
    assert len(state) == count and state.time_s == pytest.approx(time_s, abs=1e-3)
    assert path.stat().st_size < size  # compact enough for git
    # Cascading at 5 s: curtains fall from the top of the 3 m drum (free fall from 1.3 m or more
    # gives 5 m/s); at 2 s the bed still rides up with the drum (its wall moves at 0.79 m/s).
    fastest = float(np.linalg.norm(state.velocities, axis=1).max())
    assert fastest > 5.0 if time_s > 4 else fastest < 5.0


def test_a_state_of_a_shells_run_starts_a_lumped_run() -> None:
    # particles.interior is how a granule's inside is modelled, not where it is (regression:
    # the model-two state of a shells run was refused by the lumped case of the same scene).
    from drumflow.dem.state import scene_hash

    runs = ROOT / "results" / "paper" / "levels" / "runs"
    shells = load_case(runs / "paper_model_two_shells_cg2" / "case.toml")
    lumped = load_case(runs / "paper_model_two_lumped_cg2" / "case.toml")
    assert shells.particles.interior == "shells" and lumped.particles.interior == "lumped"
    assert scene_hash(shells) == scene_hash(lumped)
    bigger = lumped.model_copy(update={"particles": lumped.particles.model_copy(update={"diameter": 0.021})})
    assert scene_hash(bigger) != scene_hash(lumped)
