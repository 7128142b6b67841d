"""Headless-Chromium screenshots of drumflow's HTML pages, shared by the report and paper
page tests: the page lays out, and its embedded base64 PNGs decode and are drawn."""

from __future__ import annotations

import base64
import io
import re
import shutil
import struct
import subprocess
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

CHROMIUM = shutil.which("chromium")

_PICTURE_URI = r'src="data:image/(png|gif);base64,([^"]*)"'


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
    """A data URI of a solid red PNG with the pixel size of the matched PNG or GIF data URI."""
    import matplotlib.image as mpimg

    data = base64.b64decode(match.group(2))
    if match.group(1) == "png":
        # PNG header: 8-byte signature, IHDR chunk length and type, then width and height (big
        # endian, 4 bytes each) at bytes 16-24.
        width, height = struct.unpack(">II", data[16:24])
    else:
        # GIF header: 6-byte signature, then width and height (little endian, 2 bytes each).
        width, height = struct.unpack("<HH", data[6:10])
    buf = io.BytesIO()
    mpimg.imsave(buf, np.tile(np.array([1.0, 0.0, 0.0]), (height, width, 1)), format="png")
    return 'src="data:image/png;base64,' + base64.b64encode(buf.getvalue()).decode() + '"'


def _red(shot: NDArray[np.float64]) -> NDArray[np.bool_]:
    return np.asarray((shot[..., 0] > 0.8) & (shot[..., 1] < 0.2) & (shot[..., 2] < 0.2))


def shots_with_red_pictures(html: Path, workdir: Path, size: tuple[int, int]
                            ) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.bool_]]:
    """The page's screenshot, the screenshot of the same page with every picture a solid red
    PNG of the same pixel size, and the mask of red pixels (where pictures are drawn)."""
    import matplotlib.image as mpimg

    png = workdir / "page.png"
    screenshot(html, png, workdir / "chromium-profile", size=size)
    assert png.is_file() and png.stat().st_size > 0
    shot = mpimg.imread(png)[..., :3].astype(np.float64)
    red_html = workdir / "red.html"
    red_html.write_text(re.sub(_PICTURE_URI, _solid_red_like, html.read_text()), encoding="utf-8")
    red_png = workdir / "red.png"
    screenshot(red_html, red_png, workdir / "chromium-profile-2", size=size)
    red_shot = mpimg.imread(red_png)[..., :3].astype(np.float64)
    return shot, red_shot, _red(red_shot)


def assert_pictures_drawn(shot: NDArray[np.float64], red_shot: NDArray[np.float64],
                          red: NDArray[np.bool_]) -> None:
    """Outside the pictures both shots are the same page: if a real picture had not decoded,
    it would collapse to its alt text and shift everything below it. A difference of 0.1 in
    grey level is far above anti-aliasing noise; 0.5 % of the pixels allows for edge pixels.
    Inside, the real pictures are drawn: a plot is mostly white and black, not solid red."""
    differs = np.abs(shot.mean(axis=2) - red_shot.mean(axis=2)) > 0.1
    assert differs[~red].mean() < 0.005
    assert _red(shot)[red].mean() < 0.1
