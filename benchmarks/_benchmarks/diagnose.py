"""The diagnosis (kincal.diagnose) on a simulated campaign with a hidden effect."""

from __future__ import annotations

import math
import time

from kincal import _core, load_robot
from kincal import diagnose as diagnosis
from kincal.calibration import identify as ident


def bench_diagnose(seed: int) -> dict:
    """kincal diagnose on 500 simulated kr500 poses (one reflector; truth: default_truth with a
    hidden backlash on joint 2), every candidate on every joint, 5 folds: seconds."""
    robot = load_robot("kr500")
    data = ident.simulate(ident.default_truth(robot, seed=seed), 500, seed=seed, targets=1,
                          effects=[(_core.Effect("backlash", 2), [math.radians(0.01)])])
    t0 = time.perf_counter()
    d = diagnosis.diagnose(robot, data)
    return {"diagnose_500_poses_s": time.perf_counter() - t0, "diagnose_500_poses_steps": len(d["steps"])}
