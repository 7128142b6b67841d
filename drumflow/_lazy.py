"""Lazy re-exports for package ``__init__`` modules.

A stage package's ``__init__`` only re-exports; with :func:`lazy_exports` the names are loaded
on first use, so importing a light module of the package (a dataclass, a physics function)
does not load the stage and everything it imports.
"""

from __future__ import annotations

from collections.abc import Callable
from importlib import import_module
from typing import Any


def lazy_exports(
    package: str, exports: dict[str, str], namespace: dict[str, Any]
) -> tuple[Callable[[str], Any], Callable[[], list[str]]]:
    """Module ``__getattr__`` and ``__dir__`` for ``package`` re-exporting ``exports``.

    Parameters
    ----------
    package
        The package's ``__name__`` (for the error message).
    exports
        Public name -> the module that defines it.
    namespace
        The package's ``globals()``; a loaded name is stored there so later lookups are direct.
    """

    def __getattr__(name: str) -> Any:
        module = exports.get(name)
        if module is None:
            raise AttributeError(f"module {package!r} has no attribute {name!r}")
        value = getattr(import_module(module), name)
        namespace[name] = value
        return value

    def __dir__() -> list[str]:
        return sorted({*namespace, *exports})

    return __getattr__, __dir__
