"""The settings study's table and the rows a resumed study keeps (drumflow.bench.settings)."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pandas as pd

from drumflow.bench.settings import earlier_rows, write_study

META = {"run_dir": "/runs/a", "restart_step": 1000, "steps": 100, "ranks": 1}


def test_a_kept_row_writes_the_same_table(tmp_path: Path) -> None:
    # Regression (CI of 84a8443): the JSON kept 10 digits, so 0.05116254999 came back as
    # 0.0511625500 and its 6-digit CSV value moved from 0.0511625 to 0.0511626 on the resume.
    rows = [
        {"variant": "baseline", "status": "ok", "coupled_wall_s": 0.05116254999,
         "physics_ok": np.bool_(True), "atoms": np.int64(7), "T_end_C": math.nan},
        {"variant": "skin_x2", "status": "ok", "coupled_wall_s": 1 / 3, "physics_ok": np.bool_(False),
         "atoms": np.int64(7), "T_end_C": 99.5},
        {"variant": "ranks_x2", "status": "skipped: needs 2 MPI ranks"},
    ]
    csv, js = tmp_path / "settings.csv", tmp_path / "settings.json"
    first = write_study(rows, {**META, "resumed": []}, csv, js).copy()
    first_csv = csv.read_text()
    kept = earlier_rows(tmp_path, META)
    assert list(kept) == ["baseline", "skin_x2"]  # a skipped row is measured again
    assert kept["baseline"]["coupled_wall_s"] == 0.05116254999
    assert kept["skin_x2"]["coupled_wall_s"] == 1 / 3
    assert kept["baseline"]["T_end_C"] is None  # NaN is null: the file stays strict JSON
    json.loads(js.read_text(), parse_constant=lambda c: (_ for _ in ()).throw(ValueError(c)))
    write_study([kept["baseline"], kept["skin_x2"], rows[2]], {**META, "resumed": list(kept)}, csv, js)
    assert csv.read_text() == first_csv
    again = pd.read_csv(csv)
    assert again["coupled_wall_s"].equals(pd.read_csv(tmp_path / "settings.csv")["coupled_wall_s"])
    assert first["coupled_wall_s"].iloc[0] == 0.05116254999


def test_rows_of_another_restart_are_not_kept(tmp_path: Path) -> None:
    write_study([{"variant": "baseline", "status": "ok", "coupled_wall_s": 1.0}],
                {**META, "resumed": []}, tmp_path / "settings.csv", tmp_path / "settings.json")
    assert earlier_rows(tmp_path, {**META, "restart_step": 2000}) == {}
    assert earlier_rows(tmp_path, {**META, "steps": 200}) == {}
    assert list(earlier_rows(tmp_path, META)) == ["baseline"]
