"""Helpers of the frame and decomposition checks (drumflow.verify.resume, .air_field), no solver."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from drumflow.air.field import AirField
from drumflow.verify.air_field import profile_difference, sampled_profiles
from drumflow.verify.resume import read_stl_triangles, rotation_about_axis, wrap_angle
from drumflow.verify.scenes import tiny_drum


def _lifters(count: int) -> np.ndarray:
    """``count`` copies of an asymmetric pair of triangles (an L seen end-on), equally spaced."""
    one = np.array([[[0.08, 0.0, 0.0], [0.1, 0.0, 0.0], [0.1, 0.003, 0.05]],
                    [[0.08, 0.0, 0.0], [0.08, 0.012, 0.0], [0.083, 0.012, 0.05]]])
    return np.concatenate([_turn(one, 2.0 * math.pi * k / count) for k in range(count)])


def _turn(tris: np.ndarray, angle: float) -> np.ndarray:
    c, s = math.cos(angle), math.sin(angle)
    return tris @ np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]]).T


@pytest.mark.parametrize("angle", [0.0, 0.3, -0.45, 0.628, 2.0, -3.0])
def test_rotation_is_recovered_modulo_the_lifter_pitch(angle: float) -> None:
    ref = _lifters(6)
    moved = _turn(ref, angle)[::-1]  # another triangle order, as LIGGGHTS writes its own
    pitch = math.pi / 3.0
    assert rotation_about_axis(ref, moved, 6) == pytest.approx(wrap_angle(angle, pitch), abs=1e-12)


def test_wrap_angle_lands_in_the_half_open_pitch() -> None:
    pitch = math.pi / 3.0
    for angle in np.linspace(-7.0, 7.0, 57):
        w = wrap_angle(float(angle), pitch)
        assert -0.5 * pitch < w <= 0.5 * pitch + 1e-15
        assert math.isclose(math.remainder(angle - w, pitch), 0.0, abs_tol=1e-12)


def test_stl_is_read_as_triangles(tmp_path: Path) -> None:
    tris = _lifters(2)
    lines = ["solid x"]
    for t in tris:
        vertices = [" ".join(["  vertex", *(repr(float(c)) for c in v)]) for v in t]
        lines += ["facet normal 0 0 1", " outer loop", *vertices, " endloop", "endfacet"]
    (tmp_path / "a.stl").write_text("\n".join([*lines, "endsolid x"]) + "\n")
    np.testing.assert_array_equal(read_stl_triangles(tmp_path / "a.stl"), tris)
    (tmp_path / "b.stl").write_text("solid x\nendsolid x\n")
    with pytest.raises(ValueError, match="not an ASCII STL"):
        read_stl_triangles(tmp_path / "b.stl")


def test_profiles_of_plug_flow_and_their_difference() -> None:
    case = tiny_drum()
    plug = AirField.uniform(case)
    a = sampled_profiles(plug, case)
    assert len(a["points"]) > 500  # 12 radii x 24 lines x 3 planes, less those in the lifters
    np.testing.assert_allclose(a["swirl"], 0.0, atol=1e-12)
    np.testing.assert_allclose(a["axial"], plug.mean_axial_velocity(), rtol=1e-9)
    zero = profile_difference(a, a)
    assert zero["velocity_max"] == zero["swirl_rms"] == 0.0
    # A field 1% faster everywhere differs by 1% of the mean speed, at every point.
    faster = dict(a, velocity=1.01 * a["velocity"], axial=1.01 * a["axial"])
    diff = profile_difference(a, faster)
    assert diff["velocity_max"] == pytest.approx(0.01) and diff["velocity_rms"] == pytest.approx(0.01)
    with pytest.raises(ValueError, match="different points"):
        profile_difference(a, sampled_profiles(plug, case, radii=5))
