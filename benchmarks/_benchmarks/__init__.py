"""The benchmarks of `kincal bench`: our code and its baselines timed in the same run.

Shipped in kincal's wheel beside the package, not inside it. ``run`` returns one flat dict (the JSON
object the command prints): the C++ core's benchmarks (FK, Jacobians, IK, compensation against
KDL's solvers), then identify (Ceres against scipy), feed (the derivative analysis), diagnose and
plan (the campaign's D-optimal configurations).
"""

from __future__ import annotations

import time

from .diagnose import bench_diagnose
from .feed import bench_feed
from .identify import bench_identify
from .plan import bench_plan

__all__ = ["run", "bench_identify", "bench_feed", "bench_diagnose", "bench_plan"]


def run(poses: int = 2000, seed: int = 1, threads: int = 0, identify_poses: int = 1000,
        identify: bool = True) -> dict:
    """Every benchmark: ``poses`` random configurations for the core's (``threads`` batch threads,
    0: all cores), ``identify_poses`` for the identification; ``identify`` False skips the
    identification, the diagnosis and the plan. Adds ``bench_seconds``, the whole run's time."""
    from . import _bench

    t0 = time.perf_counter()
    r = dict(_bench.run_benchmarks(poses, seed, threads))
    if identify:
        r.update(bench_identify(identify_poses, seed))
    r.update(bench_feed(seed))
    if identify:
        r.update(bench_diagnose(seed))
        r.update(bench_plan(seed))
    r["bench_seconds"] = time.perf_counter() - t0
    return r
