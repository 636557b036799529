"""One FIGAROH geometric calibration, for benchmarks/figaroh_compare.py (run by it with the Python of the
environment FIGAROH is installed in, never kincal's): a URDF, a FIGAROH measurement CSV (x1, y1, z1, x2, ...
in m, one column per joint in rad, one row per configuration) and the number of markers; it writes FIGAROH's
unified YAML configuration (calibration_level full_params: six placement errors per joint, reduced to the
structural base parameters, with the unknown base frame and marker positions, known_baseframe and
known_tipframe False, as FIGAROH's examples set them; position of each marker measured, no orientation),
runs BaseCalibration's initialize() and solve() as a user does, and prints one JSON line: the time of each
phase (perf_counter, s) and the fit's figures.

    /path/to/figaroh-env/bin/python benchmarks/_figaroh_driver.py --urdf R.urdf --data D.csv --markers 3 \
        --workdir /tmp/x [--cost example|plain]

--cost example: the cost function of FIGAROH's UR10 example (figaroh-examples, examples/ur10/utils/
ur10_tools.py, UR10Calibration): SE(3) log-map residuals, then apply_measurement_weighting. --cost plain:
the estimated minus the measured coordinates (the same sum of squares for position-only data: the log map
only turns each point's error into the marker frame), a cheaper function a user could write instead.
"""

from __future__ import annotations

import argparse
import contextlib
import io
import json
import os
import sys
import time

# figaroh.data.observations, .tools.provenance, .tools.stages and .utils.results_manager: modules FIGAROH
# imports inside initialize() and solve(), imported here so that the fit's time is the fit's
import figaroh.data.observations
import figaroh.tools.provenance
import figaroh.tools.stages
import figaroh.utils.results_manager  # noqa: F401
import numpy as np
from figaroh.calibration.base_calibration import BaseCalibration
from figaroh.calibration.calibration_tools import calc_updated_fkm
from figaroh.tools.load_robot import load_robot


class Calibration(BaseCalibration):
    """BaseCalibration with a robot's cost function (BaseCalibration's own warns that one should be given)."""

    cost = "example"
    lm_s = 0.0
    lm_cpu_s = 0.0

    def cost_function(self, var: np.ndarray) -> np.ndarray:
        est = calc_updated_fkm(self.model, self.data, var, self.q_measured, self.calib_config)
        if self.cost == "plain":
            return est - self.PEE_measured
        raw = self._compute_logmap_residuals(self.PEE_measured, est)
        return self.apply_measurement_weighting(raw, pos_weight=1.0, orient_weight=0.5)

    def solve_optimisation(self, *args, **kwargs):  # type: ignore[override]
        t0, c0 = time.perf_counter(), time.process_time()
        out = super().solve_optimisation(*args, **kwargs)
        self.lm_s += time.perf_counter() - t0
        self.lm_cpu_s += time.process_time() - c0
        return out


def config_yaml(data: str, markers: int, tool_frame: str, samples: int, method: str = "structural") -> str:
    """FIGAROH's unified configuration of the calibration task."""
    marks = "\n".join(f"        - name: marker{k + 1}\n          measurable_dof: [true, true, true, false, false, false]"
                      for k in range(markers))
    return f"""robot:
  name: benchmark_robot
tasks:
  calibration:
    enabled: true
    type: kinematic_calibration
    parameters:
      calibration_level: full_params
      include_non_geometric: false
      estimation:
        method: {method}
    kinematics:
      base_frame: universe
      tool_frame: {tool_frame}
    measurements:
      markers:
{marks}
    data:
      source_file: {data}
      number_of_samples: {samples}
"""


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--urdf", required=True)
    p.add_argument("--data", required=True, help="FIGAROH measurement CSV")
    p.add_argument("--markers", type=int, required=True)
    p.add_argument("--tool-frame", default="tool0")
    p.add_argument("--workdir", required=True, help="where the YAML configuration is written")
    p.add_argument("--cost", choices=["example", "plain"], default="example")
    p.add_argument("--method", choices=["structural", "excitation", "map", "map_cv", "cv_subset"], default="structural",
                   help="FIGAROH's estimation.method (default structural, FIGAROH's default)")
    args = p.parse_args()
    with open(args.data) as f:
        samples = sum(1 for _ in f) - 1
    cfg = os.path.join(args.workdir, f"figaroh_{os.getpid()}.yaml")
    with open(cfg, "w") as f:
        f.write(config_yaml(os.path.abspath(args.data), args.markers, args.tool_frame, samples, args.method))

    t0 = time.perf_counter()
    robot = load_robot(args.urdf, load_by_urdf=True)
    t1, c1 = time.perf_counter(), time.process_time()
    Calibration.cost = args.cost
    calib = Calibration(robot, cfg)
    calib.calib_config["known_baseframe"] = False
    calib.calib_config["known_tipframe"] = False
    calib.initialize()  # reads the data, chooses the parameters (structural base parameters, frame guess)
    t2 = time.perf_counter()
    with contextlib.redirect_stdout(io.StringIO()):  # its quality report
        result = calib.solve(enable_logging=False)
    t3, c3 = time.perf_counter(), time.process_time()
    os.unlink(cfg)

    cc = calib.calib_config
    n, m = cc["NbSample"], cc["NbMarkers"]
    est = calib.get_pose_from_measure(result.x)
    err = (est - calib.PEE_measured).reshape(m, 3, n)  # (marker, xyz, sample), m
    point = np.sqrt((err ** 2).sum(axis=1)) * 1000.0  # mm, each point of each sample
    print(json.dumps({
        "load_robot_s": t1 - t0, "initialize_s": t2 - t1,
        "solve_s": t3 - t2, "lm_s": calib.lm_s, "fit_s": t3 - t1,
        "fit_cpu_s": c3 - c1, "lm_cpu_s": calib.lm_cpu_s,
        "rms_mm": float(np.sqrt(np.mean(point ** 2))), "max_mm": float(point.max()),
        "figaroh_rmse_mm": float(calib.evaluation_metrics["rmse"]) * 1000.0,
        "parameters": len(result.x), "samples": n, "markers": m, "points": n * m,
        "excluded_samples": len(calib.outlier_indices), "nfev": int(result.nfev),
        "success": bool(result.success), "status": calib.STATUS, "cost": args.cost, "method": args.method,
        "blas_env": {k: os.environ[k] for k in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS") if k in os.environ},
    }))
    return 0


if __name__ == "__main__":
    sys.exit(main())
