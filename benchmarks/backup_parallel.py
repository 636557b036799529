"""A controller backup filtered on one core and on every core: N KRL programs (.src + .dat) of M taught
Cartesian targets each (LIN and PTP motions, E6POS with S and T, two tools and two bases from a
$config.dat), on the kr500 calibrated as the tests' synthetic truth (1 mm / 0.05 deg errors and joint
compliance, seed 9). Runs `kincal-compensate --program FOLDER --out OUT --targets filtered --jobs J`
for J = 1 and J = 0 (every core), alternated, and prints each run's wall time and the ratio of medians.

    python benchmarks/backup_parallel.py [--programs 100] [--targets 2000] [--runs 3]
"""

from __future__ import annotations

import argparse
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from scipy.spatial.transform import Rotation

import kincal
from kincal import _core

TOOLS = [(0.0, 0.0, 200.0, 0.0, 0.0, 0.0), (10.0, 0.0, 250.0, 0.0, 10.0, 0.0)]
BASES = [(0.0, 0.0, 0.0, 0.0, 0.0, 0.0), (50.0, 20.0, 0.0, 5.0, 0.0, 0.0)]


def _config_dat() -> str:
    return "\n".join([
        "DEFDAT  $CONFIG",
        "DECL GLOBAL E6AXIS XHOME={A1 0.0,A2 -90.0,A3 90.0,A4 0.0,A5 0.0,A6 0.0,E1 0.0,E2 0.0,E3 0.0,E4 0.0,E5 0.0,E6 0.0}",
        *[f"TOOL_DATA[{k + 1}]={{X {t[0]},Y {t[1]},Z {t[2]},A {t[3]},B {t[4]},C {t[5]}}}" for k, t in enumerate(TOOLS)],
        *[f"BASE_DATA[{k + 1}]={{X {t[0]},Y {t[1]},Z {t[2]},A {t[3]},B {t[4]},C {t[5]}}}" for k, t in enumerate(BASES)],
        "ENDDAT", ""])


def _iso(xyzabc) -> np.ndarray:
    t = np.eye(4)
    t[:3, :3] = Rotation.from_euler("ZYX", xyzabc[3:], degrees=True).as_matrix()  # KUKA A, B, C
    t[:3, 3] = xyzabc[:3]
    return t


def _xyzabc(t: np.ndarray) -> list[float]:
    return [*t[:3, 3], *Rotation.from_matrix(t[:3, :3]).as_euler("ZYX", degrees=True)]


def _program(robot: kincal.Robot, name: str, n: int, rng: np.random.Generator) -> tuple[str, str]:
    """A KSS 8 style program: SPTP home, then n targets (every fifth SPTP, the others SLIN), the first half
    in tool 1 and base 1, the second in tool 2 and base 2; each target taught at random joints (its S and
    T those of the joints, its pose their nominal pose in its base and tool)."""
    src = [f"DEF {name}()", "  SPTP XHOME", "  $TOOL=TOOL_DATA[1]", "  $BASE=BASE_DATA[1]"]
    dat = [f"DEFDAT {name}"]
    lo, hi = np.array([-40, -110, 60, -120, 20, -150]), np.array([40, -60, 120, 120, 100, 150])
    q = rng.uniform(lo, hi, size=(n, 6))
    for i in range(n):
        if i == n // 2:
            src += ["  $TOOL=TOOL_DATA[2]", "  $BASE=BASE_DATA[2]"]
        tool, base = TOOLS[i >= n // 2], BASES[i >= n // 2]
        flange = kincal.fk(robot, q[i], calibrated=False)[0]
        pose = _xyzabc(np.linalg.inv(_iso(base)) @ _iso(flange) @ _iso(tool))
        b = _core.branch_data(robot, q[i])
        motion = "SPTP" if i % 5 == 0 else "SLIN"
        src.append(f"  {motion} XP{i + 1}")
        dat.append(f"DECL E6POS XP{i + 1}={{X {pose[0]:.4f},Y {pose[1]:.4f},Z {pose[2]:.4f},A {pose[3]:.6f},"
                   f"B {pose[4]:.6f},C {pose[5]:.6f},S {b['kuka_s']},T {b['kuka_t']},E1 0.0,E2 0.0,E3 0.0,E4 0.0,"
                   f"E5 0.0,E6 0.0}}")
    src += ["END", ""]
    dat += ["ENDDAT", ""]
    return "\n".join(src), "\n".join(dat)


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--programs", type=int, default=100)
    ap.add_argument("--targets", type=int, default=2000)
    ap.add_argument("--runs", type=int, default=3)
    args = ap.parse_args()
    exe = Path(sys.executable).parent / "kincal-compensate"
    robot = kincal.load_robot("kr500").with_calibrated(seed=9, sigma_mm=1.0, sigma_deg=0.05, compliance=0.003)
    rng = np.random.default_rng(1)
    with tempfile.TemporaryDirectory() as tmp:
        root = Path(tmp)
        model = root / "model.json"
        model.write_text(robot.to_json())
        backup = root / "KRC" / "R1"
        (backup / "System").mkdir(parents=True)
        (backup / "Program").mkdir()
        (backup / "System" / "$config.dat").write_text(_config_dat())
        for k in range(args.programs):
            src, dat = _program(robot, f"prog{k:03d}", args.targets, rng)
            (backup / "Program" / f"prog{k:03d}.src").write_text(src)
            (backup / "Program" / f"prog{k:03d}.dat").write_text(dat)
        times: dict[int, list[float]] = {1: [], 0: []}
        for run in range(args.runs):
            for jobs in (1, 0):
                out = root / f"out{jobs}"
                shutil.rmtree(out, ignore_errors=True)
                t0 = time.perf_counter()
                r = subprocess.run([str(exe), "--model", str(model), "--program", str(root / "KRC"), "--out", str(out),
                                    "--targets", "filtered", "--jobs", str(jobs)], capture_output=True, text=True)
                times[jobs].append(time.perf_counter() - t0)
                if r.returncode != 0:
                    print(r.stderr[-3000:], file=sys.stderr)
                    return 1
                print(f"run {run + 1}, --jobs {jobs or 'all'}: {times[jobs][-1]:.2f} s", flush=True)
        one, all_ = statistics.median(times[1]), statistics.median(times[0])
        print(f"{args.programs} programs x {args.targets} targets: one core {one:.2f} s, every core "
              f"{all_:.2f} s (medians of {args.runs}); speed-up {one / all_:.2f}x")
    return 0


if __name__ == "__main__":
    sys.exit(main())
