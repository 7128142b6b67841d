"""The import picture: stages in pipeline order, each importing only earlier ones; each stage's
entry point findable from its folder name; importing a small module stays light."""

from __future__ import annotations

import ast
import importlib
import subprocess
import sys
from pathlib import Path

import pytest

PACKAGE = Path(__file__).resolve().parents[2] / "drumflow"

#: The pipeline order. A stage may import an earlier one (or a ground-floor module such as
#: drumflow.case, errors, rundir, runner, air_properties), never a later one.
ORDER = ["geometry", "air", "coupling", "dem", "analysis", "report", "pipeline", "bench", "verify"]


def _imports() -> list[tuple[str, str, str]]:
    """(importing stage, imported stage, file) for every drumflow import, function-level too."""
    edges = []
    for path in PACKAGE.rglob("*.py"):
        rel = path.relative_to(PACKAGE)
        src = rel.parts[0].removesuffix(".py")
        for node in ast.walk(ast.parse(path.read_text())):
            modules: list[str] = []
            if isinstance(node, ast.ImportFrom) and node.module and node.module.startswith("drumflow"):
                modules = ([f"drumflow.{a.name}" for a in node.names] if node.module == "drumflow"
                           else [node.module])
            elif isinstance(node, ast.Import):
                modules = [a.name for a in node.names if a.name.startswith("drumflow.")]
            for module in modules:
                dst = module.split(".")[1]
                if dst != src and src in ORDER and dst in ORDER:
                    edges.append((src, dst, str(rel)))
    return edges


def test_no_stage_imports_a_later_one() -> None:
    backwards = [f"{f}: {s} imports {d}" for s, d, f in _imports() if ORDER.index(d) > ORDER.index(s)]
    assert backwards == []


@pytest.mark.parametrize("stage", ["geometry", "air", "dem", "bench"])
def test_each_stage_has_one_entry_point_named_after_its_folder(stage: str) -> None:
    module = importlib.import_module(f"drumflow.{stage}.stage")
    assert callable(module.run)
    assert list(__import__("inspect").signature(module.run).parameters) == ["case", "rundir", "runner",
                                                                            "inputs"]
    # The package re-exports it (lazily): drumflow.<stage>.run is the same function.
    assert importlib.import_module(f"drumflow.{stage}").run is module.run


def test_stage_packages_only_re_export() -> None:
    for stage in ("geometry", "air", "dem", "bench"):
        tree = ast.parse((PACKAGE / stage / "__init__.py").read_text())
        defs = [n.name for n in tree.body if isinstance(n, ast.FunctionDef | ast.ClassDef)]
        assert defs == [], f"drumflow/{stage}/__init__.py defines {defs}"


def test_importing_a_small_module_stays_light() -> None:
    code = ("import sys, drumflow.coolers.particle_interior, drumflow.dem.timestep, drumflow.errors;"
            "print(sorted(m for m in ('pandas', 'drumflow.pipeline', 'gmsh', 'drumflow.dem.stage',"
            "'drumflow.air.stage') if m in sys.modules))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True,
                         timeout=120).stdout
    assert out.strip() == "[]"
