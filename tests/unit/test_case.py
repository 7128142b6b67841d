"""Case validation: every error names the field, the value and the allowed range."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

from drumflow.case import case_from_dict, load_case
from drumflow.errors import CaseError

ROOT = Path(__file__).resolve().parents[2]


@pytest.mark.parametrize("name", ["smoke", "paper_model_one", "paper_model_two"])
def test_shipped_cases_are_valid(name: str) -> None:
    case = load_case(ROOT / "cases" / f"{name}.toml")
    assert case.name == name


def test_paper_cases_carry_table_1() -> None:
    one = load_case(ROOT / "cases" / "paper_model_one.toml")
    two = load_case(ROOT / "cases" / "paper_model_two.toml")
    for case in (one, two):
        p = case.particles
        assert (case.drum.diameter, case.drum.rpm, case.drum.tilt_deg) == (3.0, 5.0, 1.5)
        assert (p.youngs_modulus, p.poisson_ratio, p.density) == (517e3, 0.45, 1050.0)
        assert (p.heat_capacity, p.conductivity) == (1465.38, 0.18596)
        assert case.contacts.particle_particle.friction == 0.4
        assert case.contacts.particle_wall.friction == 0.2
        assert case.contacts.particle_particle.restitution == 0.1
        assert case.contacts.particle_wall.restitution == 0.3
        assert case.air.mass_flow == 25.0 and case.air.inlet_temperature_C == 30.0
    assert (one.drum.length, one.particles.diameter, one.particle_count) == (0.1, 0.008, 467443)
    assert (two.drum.length, two.particles.diameter, two.particle_count) == (1.0, 0.020, 299164)
    # Total masses of Table 1: 131.57 kg and 1315.78 kg (rounded to 0.1% by the paper).
    assert one.particle_mass_total == pytest.approx(131.57, rel=1e-3)
    assert two.particle_mass_total == pytest.approx(1315.78, rel=1e-3)


def _problems(d: dict) -> list[str]:
    with pytest.raises(CaseError) as info:
        case_from_dict(d)
    return info.value.problems


def test_negative_size_names_field_value_and_range(smoke_dict: dict) -> None:
    smoke_dict["drum"]["diameter"] = -0.4
    (line,) = _problems(smoke_dict)
    assert "drum.diameter" in line and "-0.4" in line and "> 0" in line


def test_wrong_type(smoke_dict: dict) -> None:
    smoke_dict["lifters"]["count"] = "eight"
    (line,) = _problems(smoke_dict)
    assert "lifters.count" in line and "'eight'" in line


def test_missing_section(smoke_dict: dict) -> None:
    del smoke_dict["particles"]
    (line,) = _problems(smoke_dict)
    assert line == "particles: missing (required)"


def test_unknown_field_is_an_error(smoke_dict: dict) -> None:
    smoke_dict["drum"]["diamter"] = 0.4
    (line,) = _problems(smoke_dict)
    assert "drum.diamter" in line and "unknown field" in line


def test_time_step_union_gives_one_line(smoke_dict: dict) -> None:
    smoke_dict["run"]["time_step"] = "fast"
    (line,) = _problems(smoke_dict)
    assert line.startswith("run.time_step = 'fast'")


def test_particles_bigger_than_lifter_gap(smoke_dict: dict) -> None:
    smoke_dict["lifters"]["count"] = 24
    problems = _problems(smoke_dict)
    assert any("particles.diameter" in p and "gap between lifters" in p for p in problems)


def test_count_and_fill_are_exclusive(smoke_dict: dict) -> None:
    smoke_dict["particles"]["fill_fraction"] = 0.1
    (line,) = _problems(smoke_dict)
    assert "exactly one of 'count'" in line


def test_fill_fraction_gives_count(smoke_dict: dict) -> None:
    del smoke_dict["particles"]["count"]
    smoke_dict["particles"]["fill_fraction"] = 0.1
    case = case_from_dict(smoke_dict)
    # 10% of a 0.4 m x 0.08 m drum at a bed solids fraction of 0.6, over one 8 mm sphere.
    expected = 0.1 * 3.141592653589793 * 0.2**2 * 0.08 * 0.6 / (3.141592653589793 / 6 * 0.008**3)
    assert case.particle_count == round(expected)


def test_centrifuging_drum_is_refused(smoke_dict: dict) -> None:
    smoke_dict["drum"]["rpm"] = 60.0  # Froude 0.8 for 0.4 m at 60 rpm: allowed
    case_from_dict(smoke_dict)
    smoke_dict["drum"]["diameter"] = 1.0
    smoke_dict["lifters"]["base_height"] = 0.1
    problems = _problems(smoke_dict)
    assert any(p.startswith("drum.rpm = 60") and "Froude" in p for p in problems)


def test_too_many_particles(smoke_dict: dict) -> None:
    smoke_dict["particles"]["count"] = 200_000
    problems = _problems(smoke_dict)
    assert any("particles.count = 200000" in p and "35%" in p for p in problems)


def test_all_problems_reported_at_once(smoke_dict: dict) -> None:
    smoke_dict["drum"]["diameter"] = -1
    smoke_dict["particles"]["density"] = 0
    smoke_dict["run"]["processes"] = 0
    assert len(_problems(smoke_dict)) == 3


def test_missing_file_and_bad_toml(tmp_path: Path) -> None:
    with pytest.raises(CaseError, match="not found"):
        load_case(tmp_path / "nope.toml")
    bad = tmp_path / "bad.toml"
    bad.write_text("[drum\n")
    with pytest.raises(CaseError, match="not valid TOML"):
        load_case(bad)


def test_cli_check_exit_code_and_no_traceback(tmp_path: Path, smoke_dict: dict) -> None:
    import tomli_w

    smoke_dict["particles"]["diameter"] = -0.008
    path = tmp_path / "bad.toml"
    path.write_text(tomli_w.dumps(smoke_dict))
    out = subprocess.run(
        [sys.executable, "-m", "drumflow.cli", "check", str(path)],
        capture_output=True, text=True, timeout=120,
    )
    assert out.returncode == 2
    assert "Traceback" not in out.stderr + out.stdout
    assert "particles.diameter = -0.008" in out.stderr


def test_cli_check_good_case() -> None:
    out = subprocess.run(
        [sys.executable, "-m", "drumflow.cli", "check", str(ROOT / "cases" / "smoke.toml")],
        capture_output=True, text=True, timeout=120,
    )
    assert out.returncode == 0, out.stderr
    assert "valid" in out.stdout


def test_cli_check_refuses_what_is_not_built_yet(tmp_path: Path, smoke_dict: dict) -> None:
    import tomli_w

    smoke_dict["air"]["pressure_gradient_force"] = True
    path = tmp_path / "pgf.toml"
    path.write_text(tomli_w.dumps(smoke_dict))
    out = subprocess.run(
        [sys.executable, "-m", "drumflow.cli", "check", str(path)],
        capture_output=True, text=True, timeout=120,
    )
    assert out.returncode == 2
    assert "air.pressure_gradient_force = true" in out.stderr and "allowed: false" in out.stderr


def test_numeric_or_auto_fields_reject_nonpositive(smoke_dict: dict) -> None:
    """Regression: `float | "auto"` fields accepted negative sizes and time steps."""
    smoke_dict["air"]["mesh_size"] = -1
    smoke_dict["run"]["time_step"] = -1e-5
    smoke_dict["air"]["coupling_interval"] = 0
    smoke_dict["drum"]["facet_size"] = 0
    problems = _problems(smoke_dict)
    assert len(problems) == 4, problems
    assert any(p.startswith("air.mesh_size = -1:") and "> 0" in p and "'auto'" in p for p in problems)
    assert any(p.startswith("run.time_step = -1e-05:") for p in problems)
    assert any(p.startswith("air.coupling_interval = 0:") and ">= 1" in p for p in problems)


@pytest.mark.parametrize("size", [1e300, 0.41])
def test_air_mesh_size_larger_than_the_drum_is_refused(smoke_dict: dict, size: float) -> None:
    # Regression: `check` accepted air.mesh_size = 1e300 (the smoke drum is 0.4 m across).
    smoke_dict["air"]["mesh_size"] = size
    with pytest.raises(CaseError, match=r"air\.mesh_size = .* must be at most the drum diameter \(0\.4 m\)"):
        case_from_dict(smoke_dict)


def test_air_mesh_size_up_to_the_drum_is_accepted(smoke_dict: dict) -> None:
    smoke_dict["air"]["mesh_size"] = 0.4
    assert case_from_dict(smoke_dict).air.mesh_size == 0.4
