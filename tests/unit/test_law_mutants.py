"""A fixed set of wrong laws that the law tests must catch (issue 36).

Each mutant changes one law with ``monkeypatch`` in the module where it is used (a function
or table replaced, or a function recompiled from its own source with one expression changed)
and runs the independent check of ``tests/unit/test_laws_*.py`` that guards it. The check must
raise AssertionError; a mutant that survives fails this test. Each test first runs the same
check unmutated and lets it pass, so a kill here is the changed law's doing.

``python tests/unit/test_law_mutants.py`` (from the repository root, with ``tests`` and
``tests/unit`` on the path) prints each mutant's measured failure.
"""

from __future__ import annotations
import __future__

import inspect
import sys
import textwrap
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from types import ModuleType
from typing import Any

import numpy as np
import pytest

sys.path[:0] = [str(Path(__file__).resolve().parent), str(Path(__file__).resolve().parents[1])]

import test_laws_air_properties as laws_air  # noqa: E402
import test_laws_coupling as laws_coupling  # noqa: E402
import test_laws_curtain as laws_curtain  # noqa: E402
import test_laws_drum as laws_drum  # noqa: E402
import test_laws_fluid_bed as laws_fluid_bed  # noqa: E402
import test_laws_grate as laws_grate  # noqa: E402
import test_laws_refrigeration as laws_refrigeration  # noqa: E402

from drumflow.coolers import _fluidization, curtain, drum, refrigeration  # noqa: E402
from drumflow.coolers import prediction as predict  # noqa: E402
from drumflow.coolers.grate import model as grate_model  # noqa: E402
from drumflow.coolers.grate import properties as grate_props  # noqa: E402
from drumflow.physics import air as air_properties  # noqa: E402
from drumflow.physics import particle_air as physics  # noqa: E402


def mutate_source(mp: pytest.MonkeyPatch, owner: Any, name: str, old: str, new: str) -> None:
    """Replace ``owner.name`` by its own source with ``old`` changed to ``new`` (exactly one
    occurrence), compiled in the defining module's namespace."""
    func = getattr(owner, name)
    source = textwrap.dedent(inspect.getsource(func))
    assert source.count(old) == 1, f"{name}: {old!r} occurs {source.count(old)} times"
    module = sys.modules[func.__module__]
    code = compile(source.replace(old, new), inspect.getsourcefile(func) or "<mutant>", "exec",
                   flags=__future__.annotations.compiler_flag, dont_inherit=True)
    namespace: dict[str, Any] = {}
    exec(code, vars(module), namespace)  # noqa: S102 - the package's own source, one edit
    mp.setattr(owner, name, namespace[name])


def scale_function(mp: pytest.MonkeyPatch, module: ModuleType, name: str, factor: float) -> None:
    """``module.name`` returns ``factor`` times its value."""
    original = getattr(module, name)

    def scaled(*args: Any, **kwargs: Any) -> Any:
        return factor * original(*args, **kwargs)

    mp.setattr(module, name, scaled)


@dataclass(frozen=True)
class Mutant:
    name: str
    apply: Callable[[pytest.MonkeyPatch], None]
    check: Callable[[], None]


def _air_k(mp: pytest.MonkeyPatch) -> None:
    column = np.asarray(air_properties.TABLE["thermal_conductivity"]) * 1.1
    mp.setitem(air_properties.TABLE, "thermal_conductivity", column)


def _curtain_k(mp: pytest.MonkeyPatch) -> None:
    lo, hi = curtain.PAPER_GAS_TABLE["conductivity"]
    mp.setitem(curtain.PAPER_GAS_TABLE, "conductivity", (1.1 * lo, 1.1 * hi))


def _curtain_k_typo(mp: pytest.MonkeyPatch) -> None:
    # 25.9e-3 typed as 29.5e-3 (two digits swapped).
    mp.setitem(curtain.PAPER_GAS_TABLE, "conductivity", (29.5e-3, 32.1e-3))


def _scaled_h(func: Callable[..., Any], factor: float) -> Callable[..., Any]:
    def scaled(*, h_w_m2k: float, **kwargs: Any) -> Any:
        return func(h_w_m2k=factor * h_w_m2k, **kwargs)

    return scaled


RM_CALL = "ranz_marshall_h(g.velocity, s.diameter, gas.air_state())"
PLANT_H = "h_new = nu_new * k / new.particle_diameter_m"

MUTANTS: tuple[Mutant, ...] = (
    Mutant("curtain h at twice the gas velocity",
           lambda mp: mutate_source(mp, curtain, "solve_curtain", RM_CALL,
                                    "ranz_marshall_h(2.0 * g.velocity, s.diameter, gas.air_state())"),
           laws_curtain.check_film_coefficient),
    Mutant("curtain h at twice the gas velocity (outlets)",
           lambda mp: mutate_source(mp, curtain, "solve_curtain", RM_CALL,
                                    "ranz_marshall_h(2.0 * g.velocity, s.diameter, gas.air_state())"),
           laws_curtain.check_cross_flow_limit),
    Mutant("curtain radius in place of the diameter (film)",
           lambda mp: mutate_source(mp, curtain, "solve_curtain", RM_CALL,
                                    "ranz_marshall_h(g.velocity, 0.5 * s.diameter, gas.air_state())"),
           laws_curtain.check_low_loading),
    Mutant("curtain radius in place of the diameter (particle)",
           lambda mp: mutate_source(mp, curtain, "solve_curtain", "Sphere(s.diameter,",
                                    "Sphere(0.5 * s.diameter,"),
           laws_curtain.check_low_loading),
    Mutant("curtain voidage dropped",
           lambda mp: mutate_source(mp, curtain, "solve_curtain",
                                    "gas.density * g.velocity * voidage * geo.width",
                                    "gas.density * g.velocity * geo.width"),
           laws_curtain.check_cross_flow_limit),
    Mutant("curtain gas conductivity x1.1", _curtain_k, laws_curtain.check_gas_table),
    Mutant("curtain gas conductivity x1.1 (outlets)", _curtain_k, laws_curtain.check_cross_flow_limit),
    Mutant("curtain gas conductivity mistyped 29.5e-3", _curtain_k_typo, laws_curtain.check_gas_table),
    Mutant("grate air conductivity x1.1",
           lambda mp: mp.setattr(air_properties, "_K_HOT", air_properties._K_HOT * 1.1),
           laws_air.check_grate_air_table),
    Mutant("drum film coefficient x1.5",
           lambda mp: scale_function(mp, drum, "ranz_marshall_h", 1.5),
           laws_drum.check_drum_counter_current),
    Mutant("drum film coefficient x1.1",
           lambda mp: scale_function(mp, drum, "ranz_marshall_h", 1.1),
           laws_drum.check_drum_counter_current),
    Mutant("plant film coefficient x1.5",
           lambda mp: mutate_source(mp, predict, "predict_plant", PLANT_H, "h_new = 1.5 * nu_new * k "
                                    "/ new.particle_diameter_m"),
           laws_drum.check_plant_prediction),
    Mutant("plant exchanger h x1.1",
           lambda mp: mp.setattr(predict, "solve_outlet_temperature",
                                 _scaled_h(predict.solve_outlet_temperature, 1.1)),
           laws_drum.check_plant_prediction),
    Mutant("grate heat-transfer correlation x0.5",
           lambda mp: scale_function(mp, grate_model, "packed_bed_h", 0.5),
           laws_grate.check_cross_flow_limit),
    Mutant("grate heat-transfer correlation x1.5",
           lambda mp: scale_function(mp, grate_model, "packed_bed_h", 1.5),
           laws_grate.check_cross_flow_limit),
    Mutant("grate heat-transfer correlation x1.1",
           lambda mp: scale_function(mp, grate_model, "packed_bed_h", 1.1),
           laws_grate.check_cross_flow_limit),
    Mutant("grate j_H coefficient 0.78 -> 0.858",
           lambda mp: mutate_source(mp, grate_props, "packed_bed_h", "0.78 * safe", "0.858 * safe"),
           laws_grate.check_packed_bed_h),
    Mutant("grate Jeschar resistance d/(10 k) -> d/(11 k)",
           lambda mp: mutate_source(mp, grate_model._Grid, "h", "(10.0 * self.props", "(11.0 * self.props"),
           laws_grate.check_jeschar_limit),
    Mutant("fluid-bed h x1.5",
           lambda mp: scale_function(mp, _fluidization, "gunn_nusselt", 1.5),
           laws_fluid_bed.check_lumped_sections),
    Mutant("fluid-bed h x1.1",
           lambda mp: scale_function(mp, _fluidization, "gunn_nusselt", 1.1),
           laws_fluid_bed.check_lumped_sections),
    # Issue 34: the bed's expansion and the source's Table 1.
    Mutant("fluid-bed Johnsson 1.3 -> 1.43",
           lambda mp: mutate_source(mp, _fluidization, "johnsson_bubble_fraction",
                                    "1.3 / f", "1.43 / f"),
           laws_fluid_bed.check_bed_expansion),
    Mutant("fluid-bed Johnsson exponent -0.8 -> -0.88",
           lambda mp: mutate_source(mp, _fluidization, "johnsson_bubble_fraction",
                                    "excess_velocity**-0.8", "excess_velocity**-0.88"),
           laws_fluid_bed.check_bed_expansion),
    Mutant("fluid-bed Johnsson size term 0.26 -> 0.286",
           lambda mp: mutate_source(mp, _fluidization, "johnsson_bubble_fraction",
                                    "0.26 + 0.70 * math", "0.286 + 0.70 * math"),
           laws_fluid_bed.check_bed_expansion),
    Mutant("fluid-bed eps_mf Wen-Yu 14 -> 15.4",
           lambda mp: mp.setattr(_fluidization, "WEN_YU_INERTIAL", 15.4),
           laws_fluid_bed.check_bed_expansion),
    Mutant("fluid-bed bed height x1.1",
           lambda mp: mutate_source(mp, _fluidization, "bed_state", "height = solids_flow / (",
                                    "height = 1.1 * solids_flow / ("),
           laws_fluid_bed.check_bed_expansion),
    Mutant("Carnot COP x1.1",
           lambda mp: scale_function(mp, refrigeration, "carnot_cop", 1.1),
           laws_refrigeration.check_source_table_1),
    Mutant("source Table 1 cycle duty x1.1",
           lambda mp: mutate_source(mp, refrigeration, "source_table_cycles",
                                    "duty = row.duty * 1e3", "duty = row.duty * 1.1e3"),
           laws_refrigeration.check_source_table_1),
    Mutant("coupling drag x1.1",
           lambda mp: scale_function(mp, physics, "drag_force", 1.1),
           laws_coupling.check_drag),
    Mutant("coupling drag x1.1 (terminal velocity)",
           lambda mp: scale_function(mp, physics, "drag_force", 1.1),
           laws_coupling.check_terminal_velocity),
    Mutant("coupling Schiller-Naumann 0.15 -> 0.165",
           lambda mp: mutate_source(mp, physics, "drag_force", "(1.0 + 0.15 * re**0.687)",
                                    "(1.0 + 0.165 * re**0.687)"),
           laws_coupling.check_drag),
    Mutant("coupling Ranz-Marshall x1.1",
           lambda mp: scale_function(mp, physics, "ranz_marshall_h", 1.1),
           laws_coupling.check_ranz_marshall),
    Mutant("coupling Ranz-Marshall 0.3 -> 0.33",
           lambda mp: mutate_source(mp, physics, "ranz_marshall_h", "0.3 * np.sqrt(re)",
                                    "0.33 * np.sqrt(re)"),
           laws_coupling.check_ranz_marshall),
    Mutant("air conductivity x1.1", _air_k, laws_air.check_air_table),
)


def failure_of(mutant: Mutant) -> str | None:
    """The check's AssertionError message under the mutant, or None if it survives."""
    with pytest.MonkeyPatch.context() as mp:
        mutant.apply(mp)
        try:
            mutant.check()
        except AssertionError as exc:
            return str(exc).splitlines()[0] if str(exc) else "AssertionError"
    return None


@pytest.mark.parametrize("mutant", MUTANTS, ids=[m.name for m in MUTANTS])
def test_mutant_is_killed(mutant: Mutant) -> None:
    mutant.check()  # the unmutated law passes its check
    message = failure_of(mutant)
    assert message is not None, f"mutant survived: {mutant.name} ({mutant.check.__name__})"


if __name__ == "__main__":
    for m in MUTANTS:
        print(f"{m.name:55s} {m.check.__name__:28s} {failure_of(m) or 'SURVIVED'}")
