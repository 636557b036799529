"""Timing helper of the benchmarks."""

from __future__ import annotations

import time
from typing import Any, Callable

import numpy as np


def median_ms(f: Callable[[], Any], n: int) -> tuple[float, Any]:
    """The median wall time of ``n`` calls of f (ms) and the last call's result."""
    ts = []
    out = None
    for _ in range(n):
        t = time.perf_counter()
        out = f()
        ts.append(time.perf_counter() - t)
    return float(np.median(ts)) * 1e3, out
