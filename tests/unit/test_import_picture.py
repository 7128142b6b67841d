"""The import picture: no import circle; the physics floor at the bottom; stages in pipeline
order, each importing only earlier ones; the reduced-order coolers above analysis and never a
stage; each stage's entry point findable from its folder name; importing a small module stays
light."""

from __future__ import annotations

import ast
import importlib
import subprocess
import sys
from pathlib import Path

import pytest

PACKAGE = Path(__file__).resolve().parents[2] / "drumflow"

#: The ground floor: modules every room may import, which import only each other and the
#: physics floor (which itself imports errors alone). ``case`` is the validated case
#: file, ``errors`` the typed errors, ``rundir`` the run directory that owns every path,
#: ``runner`` the one process runner, ``readers`` the guarded file readers, ``_json`` JSON
#: that survives NaN, ``_lazy`` the lazy re-exports of the stage packages, ``skips`` why a
#: finished stage is skipped, ``convergence`` the pure convergence tests of a series, ``_mpl``
#: matplotlib imported when a picture is first drawn, ``machine_load`` what else the machine
#: did while the runner's program ran.
GROUND_FLOOR = ["case", "errors", "rundir", "runner", "readers", "_json", "_lazy", "_mpl", "skips",
                "convergence", "machine_load"]

#: The floors in order, lowest first. A room may import a lower one (or the ground floor),
#: never a higher one: the physics floor (laws and properties) under the simulation stages in
#: pipeline order, then analysis (observables and the paper's methodology), the reduced-order
#: coolers that read a run's results through analysis, and the rooms that drive or check it all.
ORDER = ["physics", "geometry", "air", "coupling", "dem", "analysis", "coolers", "report", "pipeline",
         "bench", "verify"]

#: What the physics floor may import: itself and the typed errors, nothing else of drumflow.
PHYSICS_MAY_IMPORT = {"physics", "errors"}

#: Stages and drivers a reduced-order cooler must never import (it reads a run's results
#: through analysis; importing a cooler must not load a solver stage).
COOLERS_MUST_NOT_IMPORT = {"geometry", "air", "coupling", "dem", "report", "pipeline", "bench",
                           "verify", "sweep", "cli", "validate"}


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


def _module_name(path: Path) -> str:
    parts = ["drumflow", *path.relative_to(PACKAGE).with_suffix("").parts]
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def _module_graph() -> dict[str, set[str]]:
    """drumflow module -> the drumflow modules it imports (any import statement, in a function
    or under TYPE_CHECKING too: a circle there is still a circle a reader has to untangle).

    ``from drumflow.x import y`` counts as an import of ``drumflow.x.y`` when that is a module,
    else of ``drumflow.x``; a submodule's import of its own package's ``__init__`` is left out
    (Python loads the package first anyway, so it is not a circle of the picture).
    """
    files = {_module_name(p): p for p in PACKAGE.rglob("*.py")}
    graph: dict[str, set[str]] = {m: set() for m in files}
    for module, path in files.items():
        package = module if path.name == "__init__.py" else module.rpartition(".")[0]
        for node in ast.walk(ast.parse(path.read_text())):
            targets: list[str] = []
            if isinstance(node, ast.ImportFrom):
                base = node.module or ""
                if node.level:
                    up = package.split(".")[: len(package.split(".")) - node.level + 1]
                    base = ".".join(up + ([base] if base else []))
                if base.split(".")[0] != "drumflow":
                    continue
                targets = [f"{base}.{a.name}" if f"{base}.{a.name}" in files else base for a in node.names]
            elif isinstance(node, ast.Import):
                targets = [a.name for a in node.names if a.name.split(".")[0] == "drumflow"]
            for target in targets:
                while target not in files and "." in target:
                    target = target.rpartition(".")[0]
                own_package = (files.get(target, Path()).name == "__init__.py"
                               and module.startswith(target + "."))
                if target != module and target in files and not own_package:
                    graph[module].add(target)
    return graph


def _circles(graph: dict[str, set[str]]) -> list[list[str]]:
    """One circle through each back edge of a depth-first walk (none when the graph is acyclic)."""
    found: list[list[str]] = []
    state: dict[str, int] = {}  # 1 = on the current path, 2 = done
    path: list[str] = []

    def visit(node: str) -> None:
        state[node] = 1
        path.append(node)
        for nxt in sorted(graph[node]):
            if state.get(nxt) == 1:
                found.append([*path[path.index(nxt):], nxt])
            elif nxt not in state:
                visit(nxt)
        path.pop()
        state[node] = 2

    for start in sorted(graph):
        if start not in state:
            visit(start)
    return found


def test_the_circle_finder_finds_a_circle() -> None:
    graph = {"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}}
    assert _circles(graph) == [["a", "b", "c", "a"]]
    assert _circles({"a": {"b"}, "b": set()}) == []


def test_no_import_circle() -> None:
    circles = [" -> ".join(c) for c in _circles(_module_graph())]
    assert circles == []


def _rooms_imported(room: str) -> dict[str, set[str]]:
    """File -> the top-level drumflow rooms (``physics``, ``case``, ...) it imports."""
    out: dict[str, set[str]] = {}
    for module, targets in _module_graph().items():
        if module.split(".")[1:2] == [room]:
            out[module] = {t.split(".")[1] for t in targets if len(t.split(".")) > 1} - {room}
    return out


def test_physics_is_the_bottom_floor() -> None:
    rooms = _rooms_imported("physics")
    assert rooms, "drumflow/physics/ is missing"
    wrong = {m: sorted(r - PHYSICS_MAY_IMPORT) for m, r in rooms.items() if r - PHYSICS_MAY_IMPORT}
    assert wrong == {}


def test_coolers_import_physics_and_analysis_never_a_stage() -> None:
    wrong = {m: sorted(r & COOLERS_MUST_NOT_IMPORT) for m, r in _rooms_imported("coolers").items()
             if r & COOLERS_MUST_NOT_IMPORT}
    assert wrong == {}


def test_the_ground_floor_imports_only_the_ground_floor_and_physics() -> None:
    allowed = set(GROUND_FLOOR) | {"physics"}
    wrong = {}
    for room in GROUND_FLOOR:
        wrong |= {m: sorted(r - allowed) for m, r in _rooms_imported(room).items() if r - allowed}
    assert wrong == {}


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
    code = ("import sys, drumflow.physics.particle_interior, drumflow.dem.timestep, drumflow.errors;"
            "print(sorted(m for m in ('pandas', 'drumflow.pipeline', 'gmsh', 'drumflow.dem.stage',"
            "'drumflow.air.stage') if m in sys.modules))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True,
                         timeout=120).stdout
    assert out.strip() == "[]"


def test_importing_a_cooler_loads_no_stage() -> None:
    # The rpm of a cooler must not travel through the simulation stages: importing every
    # whole-cooler model loads none of them (function-level imports of a run's readers aside).
    code = ("import sys, drumflow.coolers.drum, drumflow.coolers.prediction, drumflow.coolers.fluid_bed,"
            " drumflow.coolers.curtain, drumflow.coolers.grate.model, drumflow.coolers.refrigeration;"
            "print(sorted({m.split('.')[1] for m in sys.modules if m.startswith('drumflow.')"
            " and m.split('.')[1] in ('geometry', 'air', 'coupling', 'dem', 'report', 'pipeline')}))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True,
                         timeout=120).stdout
    assert out.strip() == "[]"
