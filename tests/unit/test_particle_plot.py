"""The cross-section picture of a paper-scale bed draws a seeded sample, not every marker."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from drumflow.case import load_case
from drumflow.report import plots

CASES = Path(__file__).resolve().parents[2] / "cases"


def test_a_large_bed_is_drawn_from_a_seeded_sample(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    case = load_case(CASES / "smoke.toml")
    n = 3_000
    rng = np.random.default_rng(1)
    r = case.drum.radius * np.sqrt(rng.uniform(0, 1, n))
    a = rng.uniform(0, 2 * np.pi, n)
    x, y, T = r * np.cos(a), r * np.sin(a), rng.uniform(80, 90, n)
    x[:10] = np.nan  # lost particles are not drawn
    titles: list[str] = []
    real_title = plots.pyplot().Axes.set_title

    def spy(ax: object, label: str, *args: object, **kwargs: object) -> object:
        titles.append(label)
        return real_title(ax, label, *args, **kwargs)

    monkeypatch.setattr(plots.pyplot().Axes, "set_title", spy)
    monkeypatch.setattr(plots, "MAX_DRAWN_PARTICLES", 1_000)
    plots.plot_particles(x, y, T, case, tmp_path / "a.png", "bed")
    plots.plot_particles(x, y, T, case, tmp_path / "b.png", "bed")
    assert titles[0] == "bed (1,000 of 2,990 drawn)"
    # Seeded: the same picture twice.
    assert (tmp_path / "a.png").read_bytes() == (tmp_path / "b.png").read_bytes()
    monkeypatch.setattr(plots, "MAX_DRAWN_PARTICLES", 100_000)
    plots.plot_particles(x, y, T, case, tmp_path / "c.png", "all")
    assert titles[-1] == "all"
