"""The mutation study's mutmut configuration (studies/mutation.py): what it asks mutmut for is
what mutmut reads (the timeout multiplier decides which slow mutants count as timeouts)."""

from __future__ import annotations

import tomllib
from pathlib import Path

from support.scripts import load_script


def test_the_configuration_block_carries_the_modules_and_the_timeout_multiplier(tmp_path: Path) -> None:
    study = load_script("mutation")
    (tmp_path / "pyproject.toml").write_text('[project]\nname = "drumflow"\n')
    study._configure(tmp_path, ["grate_model"], 3.0)
    config = tomllib.loads((tmp_path / "pyproject.toml").read_text())["tool"]["mutmut"]
    assert config["timeout_multiplier"] == 3.0
    assert config["only_mutate"] == [study.MODULES["grate_model"][0]]
    assert config["pytest_add_cli_args_test_selection"] == sorted(study.MODULES["grate_model"][1])
