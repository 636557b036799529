"""One BLAS thread for the `kincal` command unless the user chose a number (cli.main runs every command in it)."""

from __future__ import annotations

import os
from contextlib import contextmanager
from typing import Iterator


@contextmanager
def one_blas_thread() -> Iterator[None]:
    """kincal's matrices are small (tens to a few hundred rows): a BLAS thread pool costs more to wake than it
    saves (BENCHMARKS.md, issue 29: `identify` on 540 rows took 2.67 s with OpenBLAS's two threads, 1.9 s with
    one). Unless the user chose a number of threads, the commands run with one."""
    chosen = any(v in os.environ for v in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"))
    try:
        from threadpoolctl import threadpool_limits
    except ImportError:  # (a dependency; without it, BLAS's own default)
        chosen = True
    if chosen:
        yield
        return
    with threadpool_limits(limits=1, user_api="blas"):
        yield
