"""The paper page renders in a real browser: headless Chromium screenshots it (as the report's
test does, tests/unit/test_report_chromium.py), and its embedded pictures decode and are drawn."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest
from support.chromium import assert_pictures_drawn, shots_with_red_pictures
from support.requirements import requires_program
from support.synthetic_run import AIR_FLOW, H_TRUE

from drumflow.report.paper_page import write_paper
from drumflow.report.paper_results import collect_paper_run

# Without Chromium: skipped on a workstation, failed under CI (support/requirements.py).
pytestmark = [pytest.mark.chromium, requires_program("chromium")]


def test_paper_page_renders_in_chromium(tmp_path: Path, write_synthetic_run: Callable[..., Any],
                                        synthetic_case_dict: Callable[..., dict[str, Any]]) -> None:
    runs = [
        collect_paper_run(write_synthetic_run(tmp_path / "model_one"), "one", render_3d=False),
        collect_paper_run(write_synthetic_run(
            tmp_path / "model_two", h=0.7 * H_TRUE,
            case_dict=synthetic_case_dict(air={"mass_flow": 2 * AIR_FLOW})), "two", render_3d=False),
    ]
    html = write_paper(runs, tmp_path / "out")["html"]
    shot, red_shot, red = shots_with_red_pictures(html, tmp_path, size=(1200, 3000))
    assert shot.shape[:2] == (3000, 1200)
    # A blank page has std 0; text and tables on white about 0.1 or more (the report's test).
    assert shot.mean(axis=2).std() > 0.02
    # Every picture a solid red PNG of the same size shows where pictures are drawn; outside
    # them both shots must agree (tests/support/chromium.py).
    # Figure 9 (700 x 460 px) sits in the first 3000 px: about 9 % of the shot; require 4 %.
    assert red.mean() > 0.04
    assert_pictures_drawn(shot, red_shot, red)
