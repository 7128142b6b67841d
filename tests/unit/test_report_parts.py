"""The pieces the two HTML pages share (drumflow.report.page_parts), and the small readers they
stand on: a missing run file against a damaged one, the run's recorded time step."""

from __future__ import annotations

import base64
import json
from pathlib import Path
from typing import Any

import pytest

from drumflow.errors import BadFileError
from drumflow.readers import read_json_object_if_present
from drumflow.report.page_parts import Figure, figure_uri, file_uri, fmt
from drumflow.rundir import RunDir


def test_cells_are_formatted_once_for_both_pages() -> None:
    assert fmt(None) == "–"
    assert fmt(float("nan")) == "–"
    assert fmt(True) == "yes"
    assert fmt(12345) == "12,345"
    assert fmt(3.14159265, 3) == "3.14"
    assert fmt([1.0, 2.5]) == "1, 2.5"


def test_a_drawn_figure_is_an_embedded_png() -> None:
    def draw(ax: Any) -> None:
        ax.plot([0, 1], [0, 1])

    uri = figure_uri(draw, size=(2.0, 2.0))
    assert uri.startswith("data:image/png;base64,")
    assert base64.b64decode(uri.split(",", 1)[1]).startswith(b"\x89PNG\r\n\x1a\n")
    assert Figure("t", uri=uri).note is None


def test_only_png_and_gif_files_are_embedded(tmp_path: Path) -> None:
    gif = tmp_path / "a.gif"
    gif.write_bytes(b"GIF89a" + b"\0" * 10)
    text = tmp_path / "a.txt"
    text.write_text("not a picture")
    assert (file_uri(gif) or "").startswith("data:image/gif;base64,")
    assert file_uri(text) is None
    assert file_uri(tmp_path / "missing.png") is None


def test_a_missing_json_is_none_and_a_damaged_one_is_refused(tmp_path: Path) -> None:
    assert read_json_object_if_present(tmp_path / "summary.json") is None
    good = tmp_path / "good.json"
    good.write_text(json.dumps({"a": 1}))
    assert read_json_object_if_present(good) == {"a": 1}
    cut = tmp_path / "cut.json"
    cut.write_text('{"a": ')
    with pytest.raises(BadFileError):
        read_json_object_if_present(cut)


def test_the_recorded_time_step_is_read_from_the_manifest(tmp_path: Path) -> None:
    run = RunDir(tmp_path / "run")
    assert run.recorded_time_step is None
    (run.root / "manifest.json").write_text(json.dumps({"time_step": {"time_step": 2.5e-5}}))
    assert RunDir(run.root).recorded_time_step == 2.5e-5
