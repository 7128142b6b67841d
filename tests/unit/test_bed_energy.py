"""studies/bed_energy.py: a row spacing that is not positive is refused by name before any
file is read (the script reads a run's whole thermo log, minutes on a long run)."""

from __future__ import annotations

from pathlib import Path

import pytest
from support.scripts import load_script


@pytest.mark.parametrize("every", [0.0, -1.0, float("nan")])
def test_a_spacing_that_is_not_positive_is_refused_by_name(tmp_path: Path, every: float) -> None:
    script = load_script("bed_energy")
    with pytest.raises(ValueError, match=r"--every = .* s: must be positive"):
        script.energy_table(tmp_path / "no_run", every)
    assert script.main([str(tmp_path / "no_run"), str(tmp_path / "out"), "--every", str(every)]) == 2
    assert not (tmp_path / "out").exists()
