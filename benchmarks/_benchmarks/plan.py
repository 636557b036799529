"""Campaign planning (kincal.plan): 100,000 random kr500 candidates to 60 configurations."""

from __future__ import annotations

import time

from kincal.calibration import identify as ident
from kincal import load_robot
from kincal.calibration import plan


def bench_plan(seed: int) -> dict:
    """kincal plan on 100,000 random kr500 candidates inside the joint limits, 3 reflectors,
    geometry + compliance, K = 60 (the Jacobian of every candidate, the identifiability analysis, the
    D-optimal choice, the predicted uncertainties): seconds, and the plan's predicted TCP
    uncertainty at 0.02 mm noise."""
    robot = load_robot("kr500")
    t0 = time.perf_counter()
    p = plan.plan(robot, 60, targets=ident.DEFAULT_TARGETS[:3], n_candidates=100_000, seed=seed)
    return {"plan_100k_to_60_s": time.perf_counter() - t0, "plan_100k_to_60_tcp_mm": p.tcp_uncertainty_mm}
