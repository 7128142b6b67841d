"""The HTML report and the particle render, on synthetic run directories."""

from __future__ import annotations

import base64
import re
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from support.synthetic_run import AIR_FLOW, H_TRUE

from drumflow.errors import RenderError, RunDirectoryError
from drumflow.report.html import write_report
from drumflow.report.render import render_particles, render_particles_isolated

PNG_MAGIC = b"\x89PNG\r\n\x1a\n"
SRC_RE = re.compile(r'src="([^"]*)"')


@pytest.fixture(scope="module")
def single(
    tmp_path_factory: pytest.TempPathFactory,
    write_synthetic_run: Callable[..., Any],
) -> tuple[Path, str]:
    """A one-run report with the 3-D render (rendered once for the module: ~5 s)."""
    tmp = tmp_path_factory.mktemp("report")
    run = write_synthetic_run(tmp / "run")
    out = write_report([run], tmp / "out" / "report.html")
    return out, out.read_text(encoding="utf-8")


def _images(html: str) -> list[bytes]:
    return [base64.b64decode(src.split(",", 1)[1]) for src in SRC_RE.findall(html)]


def test_one_self_contained_file(single: tuple[Path, str]) -> None:
    out, html = single
    assert out.is_absolute() and out.is_file()
    assert [p.name for p in out.parent.iterdir()] == ["report.html"]  # nothing beside it
    assert "http://" not in html and "https://" not in html
    # No external resource of any kind: no stylesheet link, no script, every src a PNG data URI.
    assert "<link" not in html and "<script" not in html
    sources = SRC_RE.findall(html)
    assert sources and all(s.startswith("data:image/png;base64,") for s in sources)
    assert all(img.startswith(PNG_MAGIC) for img in _images(html))


def test_tables_and_figures_present(single: tuple[Path, str]) -> None:
    _, html = single
    for text in ("Table 6.", "Table 7.", "Case", "Observables (summary.json)",
                 "Mean particle temperature", "Figure 4", "Figure 6", "Figure 9",
                 "<details><summary>manifest.json</summary>"):
        assert text in html, text
    # Table 6 shows the recovered h (60 W/(m2 K), printed with 5 significant digits).
    assert f"<td>{H_TRUE:.5g}</td>" in html
    # Mean temperature, h per step, crossings, Figure 6 render, Figure 9: five pictures.
    assert len(SRC_RE.findall(html)) == 5
    assert "could not be rendered" not in html  # the PyVista picture really is there
    # The manifest is pretty JSON (escaped quotes, indented).
    assert "&#34;case_hash&#34;" in html or "&quot;case_hash&quot;" in html


def test_single_run_explains_missing_table8(single: tuple[Path, str]) -> None:
    _, html = single
    assert "Table 8 (correlation and ANOVA) is not available" in html
    assert "A single run cannot identify the exponent b" in html


def test_sweep_has_anova_and_comparison(
    tmp_path: Path,
    write_synthetic_run: Callable[..., Any],
    synthetic_case_dict: Callable[..., Any],
) -> None:
    r1 = write_synthetic_run(tmp_path / "a")
    d2 = synthetic_case_dict(air={"mass_flow": 2 * AIR_FLOW})
    d2["name"] = "smoke_air50"
    r2 = write_synthetic_run(tmp_path / "b", h=H_TRUE * 2**0.5, case_dict=d2)
    html = write_report([r1, r2], tmp_path / "sweep.html", render_3d=False).read_text()
    assert "Table 8. Analysis of variance" in html
    assert "Adjusted R-squared" in html
    assert "Table 8 (correlation and ANOVA) is not available" not in html
    assert "<caption>Runs</caption>" in html and "smoke_air50" in html
    assert "3-D rendering was switched off" in html


def test_run_without_air_still_renders(
    tmp_path: Path,
    write_synthetic_run: Callable[..., Any],
    synthetic_case_dict: Callable[..., Any],
) -> None:
    d = synthetic_case_dict(air={"model": "none"})
    root = write_synthetic_run(tmp_path / "r", case_dict=d, constant_temperature=True)
    html = write_report([root], tmp_path / "noair.html", render_3d=False).read_text()
    assert "heat-transfer methodology not applied" in html
    assert "the run had no air" in html
    assert "Table 7 (exchanger model) is not available" in html
    # The observables are still there: summary table, mean temperature and crossing pictures.
    assert "Observables (summary.json)" in html
    assert len(SRC_RE.findall(html)) >= 2


def test_render_failure_becomes_a_note(
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    write_synthetic_run: Callable[..., Any],
) -> None:
    import drumflow.report.render as render

    def broken(*args: object, **kwargs: object) -> Path:
        raise RenderError("no OpenGL here")

    monkeypatch.setattr(render, "render_particles_isolated", broken)
    root = write_synthetic_run(tmp_path / "r")
    html = write_report([root], tmp_path / "r.html").read_text()
    assert "the 3-D picture could not be rendered: no OpenGL here" in html


def test_missing_pictures_are_notes(tmp_path: Path, write_synthetic_run: Callable[..., Any]) -> None:
    root = write_synthetic_run(tmp_path / "r")
    (root / "post" / "crossings.png").unlink()
    (root / "post" / "mean_temperature.png").unlink()
    html = write_report([root], tmp_path / "r.html", render_3d=False).read_text()
    assert "no crossing plot" in html
    # The mean temperature is drawn from the CSV instead.
    assert "no mean_temperature.png in the run" in html


def test_case_text_is_escaped(
    tmp_path: Path,
    write_synthetic_run: Callable[..., Any],
    synthetic_case_dict: Callable[..., Any],
) -> None:
    d = synthetic_case_dict()
    d["description"] = "<script>alert(1)</script> & more"
    root = write_synthetic_run(tmp_path / "r", case_dict=d)
    html = write_report([root], tmp_path / "r.html", render_3d=False).read_text()
    assert "<script>" not in html
    assert "&lt;script&gt;alert(1)&lt;/script&gt; &amp; more" in html


def test_missing_run_directory_is_an_error(tmp_path: Path) -> None:
    with pytest.raises(RunDirectoryError, match="not a directory"):
        write_report([tmp_path / "nowhere"], tmp_path / "x.html")
    with pytest.raises(RunDirectoryError, match="no run directory"):
        write_report([], tmp_path / "x.html")


# ---------------------------------------------------------------------------- render.py


def _bed(n: int = 400) -> tuple[np.ndarray, ...]:
    rng = np.random.default_rng(0)
    r = 0.18 * np.sqrt(rng.uniform(0, 1, n))
    phi = rng.uniform(1.1 * np.pi, 1.9 * np.pi, n)
    x, y, z = r * np.cos(phi), r * np.sin(phi), rng.uniform(0, 0.08, n)
    return x, y, z, 70.0 + 100.0 * (y + 0.2)


def test_render_particles_draws_coloured_spheres(tmp_path: Path) -> None:
    import matplotlib.image as mpimg

    x, y, z, temp = _bed()
    x[0] = np.nan  # a lost particle is skipped, not an error
    out = render_particles(x, y, z, temp, tmp_path / "p.png", 0.2, 0.08,
                           particle_diameter=0.008, window_size=(400, 300))
    img = mpimg.imread(out)
    assert img.shape[:2] == (300, 400)
    rgb = img[..., :3]
    # coolwarm: hot particles are red (R >> B), cold ones blue (B >> R). A white or grey
    # picture has |R - B| ~ 0, so 0.3 separates "coloured" safely; each colour must cover at
    # least 0.5 % of the picture (the bed covers ~20 %).
    red = (rgb[..., 0] - rgb[..., 2]) > 0.3
    blue = (rgb[..., 2] - rgb[..., 0]) > 0.3
    assert red.mean() > 0.005 and blue.mean() > 0.005


def test_render_rejects_empty_input(tmp_path: Path) -> None:
    nan = np.full(3, np.nan)
    with pytest.raises(RenderError, match="no particle"):
        render_particles(nan, nan, nan, nan, tmp_path / "p.png", 0.2, 0.08)
    with pytest.raises(RenderError, match="differ in length"):
        render_particles([0.0], [0.0, 1.0], [0.0], [1.0], tmp_path / "p.png", 0.2, 0.08)


def test_isolated_render_reports_child_failure(tmp_path: Path) -> None:
    x, y, z, temp = _bed(10)
    # The radius check runs in the child: its error must come back as a RenderError.
    with pytest.raises(RenderError, match="exit status 1.*radius"):
        render_particles_isolated(x, y, z, temp, tmp_path / "p.png", -1.0, 0.08)
    assert not (tmp_path / "p.png").exists()
