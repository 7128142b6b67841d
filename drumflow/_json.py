"""JSON-ready values: NaN and infinities as ``null``, numpy scalars as Python ones.

``json.dumps`` writes a NaN as a bare ``NaN`` token, which is not JSON (browsers and ``jq``
refuse it); every drumflow file that may hold a missing number goes through :func:`json_safe`.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

import numpy as np


def json_safe(value: Any) -> Any:
    """``value`` with every non-finite float as None, numpy scalars as Python scalars, mappings
    as dicts with string keys and tuples as lists (recursively)."""
    if isinstance(value, Mapping):
        return {str(k): json_safe(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [json_safe(v) for v in value]
    if isinstance(value, bool | np.bool_):
        return bool(value)
    if isinstance(value, int | np.integer):
        return int(value)
    if isinstance(value, float | np.floating):
        f = float(value)
        return f if math.isfinite(f) else None
    return value
