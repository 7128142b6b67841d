"""Matplotlib, imported when a picture is first drawn and always without a display.

Importing pyplot takes about half a second and picks a window backend; the commands that draw
nothing should pay neither, and a cluster node or a CI runner has no display. Every picture of
the package gets pyplot from :func:`pyplot`.
"""

from __future__ import annotations

from typing import Any

__all__ = ["pyplot"]


def pyplot() -> Any:
    """``matplotlib.pyplot`` on the off-screen Agg backend."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt
