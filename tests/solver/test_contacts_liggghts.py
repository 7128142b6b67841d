"""Real LIGGGHTS runs of two particles: restitution of a head-on collision and conduction of a
held contact against the paper's Eq. 24 (drumflow.verify.contacts). About 10 s in all."""

from __future__ import annotations

import math
import shutil
from pathlib import Path

import pytest

from drumflow.dem.conduction import GEOMETRIC_AREA_FACTOR
from drumflow.runner import Runner
from drumflow.verify.contacts import (
    PAPER_YOUNGS_MODULUS,
    contact_conduction_check,
    restitution_check,
    run_conduction,
)

pytestmark = [
    pytest.mark.solver,
    pytest.mark.timeout(300),
    pytest.mark.skipif(shutil.which("liggghts") is None, reason="LIGGGHTS not installed (scripts/install.sh)"),
]


@pytest.mark.parametrize("E", [5e6, PAPER_YOUNGS_MODULUS])
def test_restitution_wall_value_at_default_time_step(tmp_path: Path, E: float) -> None:
    """e = 0.3 (drumflow's wall value) at the default 10 steps per contact: 0.295, within 2%."""
    check = restitution_check(tmp_path, Runner(), restitution=0.3, youngs_modulus=E)
    assert check.passed, check.as_dict()


@pytest.mark.parametrize("E", [5e6, PAPER_YOUNGS_MODULUS])
def test_restitution_particle_value_resolved(tmp_path: Path, E: float) -> None:
    """e = 0.1 comes within 2% once the contact spans 200 steps (measured 0.0991)."""
    check = restitution_check(tmp_path, Runner(), restitution=0.1, youngs_modulus=E, steps_per_contact=200)
    assert check.passed, check.as_dict()


@pytest.mark.xfail(strict=True, reason="drumflow's default 10 steps per Hertz contact realise "
                   "e = 0.085 for an input 0.1 (-15%): the default time step is too coarse for it")
def test_restitution_particle_value_at_default_time_step(tmp_path: Path) -> None:
    check = restitution_check(tmp_path, Runner(), restitution=0.1)
    assert check.passed, check.as_dict()


@pytest.mark.parametrize(("E", "E_ref"), [(5e6, None), (PAPER_YOUNGS_MODULUS, None),
                                          (1e5, PAPER_YOUNGS_MODULUS)])
def test_contact_conduction_matches_eq24(tmp_path: Path, E: float, E_ref: float | None) -> None:
    """drumflow's setting (overlap area, area_correction, k / sqrt(2 pi)) gives Eq. 24 within 2%:
    at the smoke case's 5 MPa, the paper's 517 kPa, and softened to 100 kPa against 517 kPa."""
    check = contact_conduction_check(tmp_path, Runner(), youngs_modulus=E, reference_modulus=E_ref)
    assert check.passed, check.as_dict()
    assert check.details["q_heatflux_output_W"] == pytest.approx(check.measured, rel=1e-6)


@pytest.mark.parametrize("fraction", [1e-3, 1e-2])
def test_liggghts_default_conduction_is_sqrt_2pi_above_eq24(tmp_path: Path, fraction: float) -> None:
    """LIGGGHTS' default (contact_area overlap, real k): q / q_Eq24 = sqrt(2 pi) sqrt(1 - delta/4R)."""
    res = run_conduction(tmp_path, Runner(), overlap_fraction=fraction, heat_options="contact_area overlap")
    assert res.ratio == pytest.approx(GEOMETRIC_AREA_FACTOR * math.sqrt(1 - fraction / 4), rel=1e-4)
