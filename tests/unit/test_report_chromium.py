"""The report renders in a real browser: headless Chromium takes a screenshot of the page.

This checks what the string tests in test_report.py cannot: the page is valid enough for a
browser to lay out, and the embedded base64 PNGs decode and are drawn.
"""

from __future__ import annotations

import base64
import io
import re
import shutil
import struct
import subprocess
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from drumflow.report.html import write_report

CHROMIUM = shutil.which("chromium")

pytestmark = [
    pytest.mark.chromium,
    pytest.mark.skipif(
        CHROMIUM is None,
        reason="chromium is not installed (apt-get install -y chromium); the browser check needs it",
    ),
]


def screenshot(html: Path, png: Path, profile: Path, size: tuple[int, int] = (1200, 2000)) -> None:
    """Screenshot ``html`` with headless Chromium (no network, throw-away profile)."""
    assert CHROMIUM is not None
    cmd = [
        CHROMIUM, "--headless", "--no-sandbox", "--disable-gpu", "--disable-quic",
        "--no-first-run", "--disable-background-networking", "--disable-component-update",
        "--disable-sync", f"--user-data-dir={profile}", f"--screenshot={png}",
        f"--window-size={size[0]},{size[1]}", html.resolve().as_uri(),
    ]
    # 120 s: a cold Chromium start takes 1-3 s here; the limit only guards against a hang.
    proc = subprocess.run(cmd, capture_output=True, text=True, timeout=120, check=False)
    assert proc.returncode == 0, proc.stderr[-2000:]


def _solid_red_like(match: re.Match[str]) -> str:
    """A data URI of a solid red PNG with the pixel size of the matched PNG data URI."""
    import matplotlib.image as mpimg

    data = base64.b64decode(match.group(1))
    # PNG header: 8-byte signature, IHDR chunk length and type, then width and height (big
    # endian, 4 bytes each) at bytes 16-24.
    width, height = struct.unpack(">II", data[16:24])
    buf = io.BytesIO()
    mpimg.imsave(buf, np.tile(np.array([1.0, 0.0, 0.0]), (height, width, 1)), format="png")
    return 'src="data:image/png;base64,' + base64.b64encode(buf.getvalue()).decode() + '"'


def test_report_renders_in_chromium(tmp_path: Path, write_synthetic_run: Callable[..., Any]) -> None:
    import matplotlib.image as mpimg

    run = write_synthetic_run(tmp_path / "run")
    html = write_report([run], tmp_path / "report.html")
    png = tmp_path / "report.png"
    screenshot(html, png, tmp_path / "chromium-profile")
    assert png.is_file() and png.stat().st_size > 0
    shot = mpimg.imread(png)[..., :3].astype(np.float64)
    assert shot.shape[:2] == (2000, 1200)
    grey = shot.mean(axis=2)
    # A blank page is one colour (std 0). Black text and tables on white give a grey-level std
    # of about 0.12 here; 0.02 separates a blank page from a rendered one with margin.
    assert grey.std() > 0.02

    # The embedded pictures decode and are drawn where they belong. The same page with every
    # picture replaced by a solid red PNG of the same pixel size shows where pictures are drawn.
    red_html = tmp_path / "red.html"
    red_html.write_text(
        re.sub(r'src="data:image/png;base64,([^"]*)"', _solid_red_like, html.read_text()),
        encoding="utf-8",
    )
    red_png = tmp_path / "red.png"
    screenshot(red_html, red_png, tmp_path / "chromium-profile-2")
    red_shot = mpimg.imread(red_png)[..., :3].astype(np.float64)
    red = (red_shot[..., 0] > 0.8) & (red_shot[..., 1] < 0.2) & (red_shot[..., 2] < 0.2)
    # Figure 9 (700 x 420 px) is in the first 2000 px: about 12 % of the shot; require 5 %.
    assert red.mean() > 0.05
    # Outside the pictures both shots are the same page: if a real picture had not decoded,
    # it would collapse to its alt text and shift everything below it. A difference of 0.1 in
    # grey level is far above anti-aliasing noise; 0.5 % of the pixels allows for edge pixels.
    differs = np.abs(grey - red_shot.mean(axis=2)) > 0.1
    assert differs[~red].mean() < 0.005
    # Inside, the real pictures are drawn: a plot is mostly white and black, not solid red.
    real_red = (shot[..., 0] > 0.8) & (shot[..., 1] < 0.2) & (shot[..., 2] < 0.2)
    assert real_red[red].mean() < 0.1
