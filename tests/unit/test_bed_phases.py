"""Issue 32: the air around the bed at phases of one lifter period (drumflow.air.bed_phases).
Which state stands for the drum's angle, and the frame the particles are mapped into: checked
against hand values and against fields whose symmetry gives the answer. No solver."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from drumflow.air.bed_phases import PhaseLockedAir, lifter_spacing, nearest_phase
from drumflow.air.field import AirField
from drumflow.coupling.driver import air_velocity_at
from drumflow.physics.drum_frame import drum_angle, rotate_to_drum_frame

SPACING = 2.0 * math.pi / 12.0  # the paper's 12 lifters


def test_lifter_spacing() -> None:
    assert lifter_spacing(12) == pytest.approx(math.radians(30.0))
    assert lifter_spacing(0) is None


@pytest.mark.parametrize(("angle", "index", "frame"), [
    # On a state's own angle: that state, mapped by its angle.
    (0.10, 0, 0.10),
    (0.30, 1, 0.30),
    # Whole spacings later: the same state, the lifters one, three spacings on.
    (0.10 + SPACING, 0, 0.10),
    (0.30 + 3 * SPACING, 1, 0.30),
    # Between the states, nearest wins (0.22 is 0.12 from 0.10 and 0.08 from 0.30).
    (0.22 + 5 * SPACING, 1, 0.22),
    (0.18 - 2 * SPACING, 0, 0.18),
])
def test_the_nearest_state_modulo_the_lifter_spacing(angle: float, index: int, frame: float) -> None:
    k, mapped = nearest_phase(angle, [0.10, 0.30], SPACING)
    assert k == index
    assert mapped == pytest.approx(frame, abs=1e-12)
    # The mapping angle differs from the drum's by whole spacings: the lifters land on lifters.
    spacings = (angle - mapped) / SPACING
    assert spacings == pytest.approx(round(spacings), abs=1e-9)


def test_without_lifters_the_state_angle_itself() -> None:
    assert nearest_phase(5.0, [0.4], None) == (0, 0.4)


def _grid_field(velocity_of: object, omega: float) -> AirField:
    """A 1.2 m cube of nodes with ``velocity_of(x, y, z)`` at each node."""
    axes = [np.linspace(-0.6, 0.6, 25), np.linspace(-0.6, 0.6, 25), np.linspace(0.0, 0.2, 3)]
    X, Y, Z = np.meshgrid(*axes, indexing="ij")
    u = velocity_of(X, Y, Z)  # type: ignore[operator]
    return AirField(origin=np.array([-0.6, -0.6, 0.0]), spacing=np.array([0.05, 0.05, 0.1]),
                    velocity=np.stack(u, axis=-1), pressure=np.zeros(X.shape),
                    fluid=np.ones(X.shape, bool), omega=omega)


def _points(n: int = 200) -> np.ndarray:
    rng = np.random.default_rng(3)
    r, phi = 0.5 * np.sqrt(rng.random(n)), 2 * np.pi * rng.random(n)
    return np.column_stack([r * np.cos(phi), r * np.sin(phi), 0.2 * rng.random(n)])


def test_a_field_with_the_drums_symmetry_is_the_same_in_the_lab_at_any_phase() -> None:
    """A swirl u = w e_z x r - 3 e_z looks the same in every rotated frame: whichever state and
    mapping angle is taken, the lab velocity at a lab point is the swirl there."""
    omega, w = 0.5236, 0.7
    swirl = _grid_field(lambda x, y, z: (-w * y, w * x, -3.0 + 0 * z), omega)
    air = PhaseLockedAir([swirl, swirl], [0.1, 0.3], SPACING, omega)
    x = _points()
    for t in (0.0, 0.37, 1.91, 12.3):
        expect = np.column_stack([-w * x[:, 1], w * x[:, 0], np.full(len(x), -3.0)])
        assert np.allclose(air.sample_at(x, t), expect, atol=1e-9)


def test_a_single_state_at_the_drums_angle_is_the_mrf_field() -> None:
    """One state, sampled at a time when the drum stands at the state's angle plus whole
    lifter spacings: the field of that state at the drum-frame point turned back to the lab,
    which is what the one-way loop does with the MRF field at that time, up to the lifters'
    symmetry (here the drum angle itself, so exactly the same numbers)."""
    omega = 0.5236
    shear = _grid_field(lambda x, y, z: (0.3 * y + 0.1, -0.2 * x, -2.0 + x * y), omega)
    state_angle = 0.2
    air = PhaseLockedAir([shear], [state_angle], SPACING, omega)
    x = _points()
    t = state_angle / omega  # the drum at the state's own angle
    assert np.allclose(air.sample_at(x, t), air_velocity_at(shear, x, t, omega), atol=1e-12)
    assert np.allclose(air_velocity_at(air, x, t, omega), air.sample_at(x, t))
    # Three spacings later the particles are mapped by the state's angle, not the drum's.
    later = t + 3 * SPACING / omega
    k, mapped = air.phase(later)
    assert k == 0 and mapped == pytest.approx(state_angle)
    assert not np.allclose(rotate_to_drum_frame(x, mapped),
                           rotate_to_drum_frame(x, drum_angle(omega, later)))


def test_the_spec_round_trip(tmp_path) -> None:  # type: ignore[no-untyped-def]
    omega = 0.5236
    f = _grid_field(lambda x, y, z: (0 * x, 0 * y, -3.0 + 0 * z), omega)
    paths = [tmp_path / "a.npz", tmp_path / "b.npz"]
    for p in paths:
        f.to_npz(p)
    air = PhaseLockedAir.from_spec({"kind": "phases", "paths": [str(p) for p in paths],
                                    "angles": [0.1, 0.3], "spacing": SPACING, "omega": omega})
    assert len(air.fields) == 2 and air.angles == [0.1, 0.3] and air.spacing == SPACING


# -- the case field ---------------------------------------------------------------------------

ROOT = __import__("pathlib").Path(__file__).resolve().parents[2]
SMOKE = ROOT / "cases" / "smoke.toml"
SMOKE_STATE = ROOT / "results" / "states" / "smoke_1.0s.npz"


def _with_states(tmp_path, states: list[str], model: str = "cfd"):  # type: ignore[no-untyped-def]
    from drumflow.case import load_case

    text = SMOKE.read_text()
    listed = ", ".join(f'"{s}"' for s in states)
    text = text.replace("[air]\n", f"[air]\nbed_states = [{listed}]\n", 1)
    text = text.replace('model = "cfd"', f'model = "{model}"', 1)
    (tmp_path / "c.toml").write_text(text)
    return load_case(tmp_path / "c.toml")


def test_bed_states_keep_old_hashes_and_resolve_against_the_case_file(tmp_path) -> None:  # type: ignore[no-untyped-def]
    from drumflow.case import case_to_toml, load_case

    plain = load_case(SMOKE)
    assert "bed_states" not in plain.canonical_json() and "bed_states" not in case_to_toml(plain)
    case = _with_states(tmp_path, ["states/s.npz"])
    assert case.air.bed_states == [str((tmp_path / "states" / "s.npz").resolve())]
    assert case.hash() != plain.hash()
    # The empty drum's air is the same field with or without bed states (its cache is shared).
    from drumflow.air.field import air_cache_key

    assert air_cache_key(case) == air_cache_key(plain)


def test_bed_states_are_hashed_by_content(tmp_path) -> None:  # type: ignore[no-untyped-def]
    import shutil

    (tmp_path / "a").mkdir()
    shutil.copyfile(SMOKE_STATE, tmp_path / "a" / "s.npz")
    here = _with_states(tmp_path, ["a/s.npz"])
    (tmp_path / "b").mkdir()
    shutil.copyfile(SMOKE_STATE, tmp_path / "b" / "s.npz")
    moved = _with_states(tmp_path, ["b/s.npz"])
    assert here.hash() == moved.hash()


def test_bed_states_need_cfd_air(tmp_path) -> None:  # type: ignore[no-untyped-def]
    from drumflow.errors import CaseError

    with pytest.raises(CaseError, match="air.bed_states: 1 state"):
        _with_states(tmp_path, [str(SMOKE_STATE)], model="uniform")


def test_a_bed_state_of_another_scene_is_refused_by_its_field(tmp_path) -> None:  # type: ignore[no-untyped-def]
    from drumflow.dem.state import load_bed_states
    from drumflow.errors import StartStateError

    model_two = ROOT / "results" / "states" / "paper_model_two_cg2_5.0s.npz"
    case = _with_states(tmp_path, [str(SMOKE_STATE), str(model_two)])
    with pytest.raises(StartStateError, match=r"air\.bed_states\[1\] = .*another scene"):
        load_bed_states(case)
    missing = _with_states(tmp_path, ["nothing.npz"])
    with pytest.raises(StartStateError, match=r"air\.bed_states\[0\] = .*no such file"):
        load_bed_states(missing)
    assert len(load_bed_states(_with_states(tmp_path, [str(SMOKE_STATE)]))) == 1


def test_each_bed_state_is_cached_alone(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """A run with 1 of 4 states reuses that state's solve (the number of states is a convergence
    question: asking it must not solve the same state again); another state or another empty
    drum's air is another entry."""
    from drumflow.air import stage

    monkeypatch.setattr(stage, "air_cache_dir", lambda: tmp_path / "cache")
    assert stage.bed_phase_cache("air1", "a") == stage.bed_phase_cache("air1", "a")
    assert stage.bed_phase_cache("air1", "a") != stage.bed_phase_cache("air1", "b")
    assert stage.bed_phase_cache("air1", "a") != stage.bed_phase_cache("air2", "a")
    assert stage.bed_phase_cache("air1", "a").parent == tmp_path / "cache"
