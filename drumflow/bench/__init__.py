"""``drumflow bench``: run time against error on one reference scene.

The entry point is :func:`drumflow.bench.stage.run`; the names below are re-exported lazily, so
importing :mod:`drumflow.bench.ladder` does not load pandas or the pipeline.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from drumflow._lazy import lazy_exports

_EXPORTS = {
    **{name: "drumflow.bench.stage" for name in
       ("TOLERANCES", "BenchInputs", "BenchResult", "run", "run_bench")},
    "Rung": "drumflow.bench.ladder",
    "ladder": "drumflow.bench.ladder",
}
__all__ = [
    "TOLERANCES",
    "BenchInputs",
    "BenchResult",
    "Rung",
    "ladder",
    "run",
    "run_bench",
]
__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS, globals())

if TYPE_CHECKING:
    from drumflow.bench.ladder import Rung, ladder
    from drumflow.bench.stage import (
        TOLERANCES,
        BenchInputs,
        BenchResult,
        run,
        run_bench,
    )
