"""Strict JSON for every file kincal writes: no NaN or Infinity (JSON has neither; Python's json
writes them as bare words that strict readers, kincal-compensate's among them, refuse). An undefined
figure (a NaN, an infinite condition number, ...) is written as ``null``."""

from __future__ import annotations

import json
import math
from typing import Any

import numpy as np


def finite_or_none(obj: Any) -> Any:
    """``obj`` with every non-finite float (Python or numpy, inside dicts, lists, tuples and numpy
    arrays, at any depth) replaced by None; numpy scalars and arrays become plain Python values.
    Tuples become lists (as JSON writes them)."""
    if isinstance(obj, (bool, np.bool_)):
        return bool(obj)
    if isinstance(obj, (float, np.floating)):
        v = float(obj)
        return v if math.isfinite(v) else None
    if isinstance(obj, np.integer):
        return int(obj)
    if isinstance(obj, dict):
        return {k: finite_or_none(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [finite_or_none(v) for v in obj]
    if isinstance(obj, np.ndarray):
        return finite_or_none(obj.tolist())
    return obj


def dumps(obj: Any, **kw: Any) -> str:
    """``json.dumps(obj, **kw)`` with non-finite floats written as null and ``allow_nan=False``, so
    that nothing that is not strict JSON can be written (a value the cleaning cannot reach, e.g.
    one a ``default=`` hook returns, raises ValueError rather than write NaN; passing ``allow_nan``
    is a TypeError)."""
    return json.dumps(finite_or_none(obj), allow_nan=False, **kw)
