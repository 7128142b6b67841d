"""The paper page renders in a real browser: headless Chromium screenshots it (as the report's
test does, tests/unit/test_report_chromium.py), and its embedded pictures decode and are drawn."""

from __future__ import annotations

import re
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from support.synthetic_run import AIR_FLOW, H_TRUE
from test_report_chromium import CHROMIUM, _solid_red_like, screenshot

from drumflow.report.paper import collect_paper_run, write_paper

pytestmark = [
    pytest.mark.chromium,
    pytest.mark.skipif(
        CHROMIUM is None,
        reason="chromium is not installed (apt-get install -y chromium); the browser check needs it",
    ),
]


def test_paper_page_renders_in_chromium(tmp_path: Path, write_synthetic_run: Callable[..., Any],
                                        synthetic_case_dict: Callable[..., dict[str, Any]]) -> None:
    import matplotlib.image as mpimg

    runs = [
        collect_paper_run(write_synthetic_run(tmp_path / "model_one"), "one", render_3d=False),
        collect_paper_run(write_synthetic_run(
            tmp_path / "model_two", h=0.7 * H_TRUE,
            case_dict=synthetic_case_dict(air={"mass_flow": 2 * AIR_FLOW})), "two", render_3d=False),
    ]
    html = write_paper(runs, tmp_path / "out")["html"]
    png = tmp_path / "page.png"
    screenshot(html, png, tmp_path / "chromium-profile", size=(1200, 3000))
    shot = mpimg.imread(png)[..., :3].astype(np.float64)
    assert shot.shape[:2] == (3000, 1200)
    grey = shot.mean(axis=2)
    # A blank page has std 0; text and tables on white about 0.1 or more (the report's test).
    assert grey.std() > 0.02

    # The same page with every picture a solid red PNG of the same size shows where pictures
    # are drawn; outside them both shots must agree (a picture that failed to decode would
    # collapse to its alt text and shift the page).
    red_html = tmp_path / "red.html"
    red_html.write_text(
        re.sub(r'src="data:image/png;base64,([^"]*)"', _solid_red_like, html.read_text()),
        encoding="utf-8",
    )
    red_png = tmp_path / "red.png"
    screenshot(red_html, red_png, tmp_path / "chromium-profile-2", size=(1200, 3000))
    red_shot = mpimg.imread(red_png)[..., :3].astype(np.float64)
    red = (red_shot[..., 0] > 0.8) & (red_shot[..., 1] < 0.2) & (red_shot[..., 2] < 0.2)
    # Figure 9 (700 x 460 px) sits in the first 3000 px: about 9 % of the shot; require 4 %.
    assert red.mean() > 0.04
    differs = np.abs(grey - red_shot.mean(axis=2)) > 0.1
    assert differs[~red].mean() < 0.005
    real_red = (shot[..., 0] > 0.8) & (shot[..., 1] < 0.2) & (shot[..., 2] < 0.2)
    assert real_red[red].mean() < 0.1
