"""Issue 32: a periodic slice's air closures (through-curtain air with its mixing bounds,
contact efficiencies) read from a bed-air folder, carried in a closures file, and taken by the
whole-cooler model. The shipped folders of model one's and the smoke drum's bed-air runs; no
solver."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest

from drumflow.analysis.air_closures import read_air_closures
from drumflow.analysis.closures import load_closures
from drumflow.errors import BadFileError

ROOT = Path(__file__).resolve().parents[2]
MODEL_ONE = ROOT / "results" / "air" / "bed_air_model_one_cg2_5.0s_periodic_heat"
SMOKE_CLOSURES = ROOT / "docs" / "plant" / "smoke_closures.json"


def _json(path: Path) -> dict:
    return json.loads(path.read_text())


def test_the_air_closures_are_the_folders_numbers() -> None:
    air = read_air_closures(MODEL_ONE / "heat.json")
    warm, split = _json(MODEL_ONE / "heat.json"), _json(MODEL_ONE / "split.json")
    assert air.curtain_air_m3_s_m == warm["saturated_flow_m3_s_m"]
    assert air.curtain_air_molecular_m3_s_m == _json(MODEL_ONE / "heat_molecular.json")[
        "saturated_flow_m3_s_m"]
    assert air.curtain_air_turbulent_m3_s_m == _json(MODEL_ONE / "heat_turbulent.json")[
        "saturated_flow_m3_s_m"]
    assert air.contact_efficiency_bed == warm["by_category"]["bed"]["contact_efficiency"]
    assert air.contact_efficiency_curtain == warm["by_category"]["curtain"]["contact_efficiency"]
    flows = split["bed"]["axial_flow_m3_s"]
    assert air.bypass_share == pytest.approx(flows["free"] / flows["total"])
    assert air.curtain_inflow_m3_s_m == split["bed"]["inflow_m3_s_m"]["curtain_from_free"]
    assert air.state_time_s == split["state"]["time_s"] and air.case_name == warm["case_name"]
    # The bounds bracket the closure (molecular mixing removes the least heat).
    assert air.curtain_air_molecular_m3_s_m < air.curtain_air_m3_s_m < air.curtain_air_turbulent_m3_s_m


def _copy(tmp_path: Path) -> Path:
    folder = tmp_path / "slice"
    shutil.copytree(MODEL_ONE, folder)
    return folder


def test_a_folder_without_the_bounds_has_none(tmp_path: Path) -> None:
    folder = _copy(tmp_path)
    (folder / "heat_turbulent.json").unlink()
    air = read_air_closures(folder / "heat.json")
    assert air.curtain_air_turbulent_m3_s_m is None and list(air.bounds()) == ["molecular"]


@pytest.mark.parametrize(("file", "change", "named"), [
    ("heat.json", {"contact_efficiency": 5000.0}, "contact_efficiency = 5000.0"),
    ("heat.json", {"saturated_flow_m3_s_m": "lots"}, "curtain_air_m3_s_m = 'lots'"),
    ("heat.json", {"by_category": {}}, "no by_category.bed.contact_efficiency"),
    ("split.json", {"axial": "inlet-outlet"}, "axial = inlet-outlet: allowed periodic"),
    ("heat_molecular.json", {"case_name": "another"}, "case_name = 'another'"),
])
def test_a_bad_folder_is_refused_by_name(tmp_path: Path, file: str, change: dict,
                                         named: str) -> None:
    folder = _copy(tmp_path)
    (folder / file).write_text(json.dumps({**_json(folder / file), **change}))
    with pytest.raises(BadFileError, match=named) as err:
        read_air_closures(folder / "heat.json")
    assert file in str(err.value)


def test_a_truncated_heat_file_is_refused(tmp_path: Path) -> None:
    folder = _copy(tmp_path)
    (folder / "heat.json").write_text((MODEL_ONE / "heat.json").read_text()[:200])
    with pytest.raises(BadFileError, match="heat.json"):
        read_air_closures(folder / "heat.json")


def test_old_closures_files_have_no_air() -> None:
    assert load_closures(SMOKE_CLOSURES).air is None


def test_the_plant_saves_and_reuses_the_slices_air(tmp_path: Path) -> None:
    """--curtain-air HEAT.json --save-closures: the saved file carries the air closures; the
    plant of that file then uses them by default (same outlets), 'all' still overrides, and the
    outlets at the mixing bounds order as more air through the curtains must: cooler NPK."""
    from drumflow.coolers.plant_from_slice import plant_from_slice

    heat, saved = MODEL_ONE / "heat.json", tmp_path / "closures.json"
    first = plant_from_slice(SMOKE_CLOSURES, cells=20, curtain_air=str(heat), sweep=False,
                             save_closures=saved)
    closures = load_closures(saved)
    assert closures.air == read_air_closures(heat)
    again = plant_from_slice(saved, cells=20, sweep=False)
    assert again.curtain_air == pytest.approx(closures.air.curtain_air_m3_s_m)
    assert again.curtain_air_from == str(heat)
    assert again.result.material_outlet_c == pytest.approx(first.result.material_outlet_c, abs=1e-9)
    everything = plant_from_slice(saved, cells=20, curtain_air="all", sweep=False)
    assert everything.curtain_air is None and not everything.mixing_bounds
    plain = plant_from_slice(SMOKE_CLOSURES, cells=20, sweep=False)
    assert everything.result.material_outlet_c == pytest.approx(plain.result.material_outlet_c)
    bounds = again.mixing_bounds
    assert set(bounds) == {"molecular", "turbulent"}
    assert bounds["molecular"].curtain_air_m3_s_m == closures.air.curtain_air_molecular_m3_s_m
    assert (bounds["molecular"].material_outlet_c > again.result.material_outlet_c
            > bounds["turbulent"].material_outlet_c)
    answer = again.to_dict()["curtain_air"]["mixing_bounds"]
    assert answer["turbulent"]["material_outlet_C"] == pytest.approx(
        bounds["turbulent"].material_outlet_c)


def test_a_closures_file_with_bad_air_is_refused_by_field(tmp_path: Path) -> None:
    from drumflow.coolers.plant_from_slice import plant_from_slice

    saved = tmp_path / "closures.json"
    plant_from_slice(SMOKE_CLOSURES, cells=20, curtain_air=str(MODEL_ONE / "heat.json"),
                     sweep=False, save_closures=saved)
    data = _json(saved)
    data["air"]["curtain_air_m3_s_m"] = -1.0
    saved.write_text(json.dumps(data))
    with pytest.raises(BadFileError, match=r"air\.curtain_air_m3_s_m = -1\.0"):
        load_closures(saved)
