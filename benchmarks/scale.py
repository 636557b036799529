"""How each command's time grows: poses, candidates and parameters at three sizes each, on one core
and on two (issue 33, item 6). The commands as a user runs them (subprocesses of the installed
`kincal` and `kincal-compensate`), on the built-in kr500 with data from `kincal simulate` (its
default truth: 1 mm / 0.05 deg errors, joint compliance, 0.02 mm noise, 3 reflectors). One core:
`taskset -c 0` (the threads the code starts share it). Prints one JSON object; BENCHMARKS.md
("Scale") has the table and the command.

    .venv/bin/python benchmarks/scale.py --workdir /tmp/kincal-scale
"""

from __future__ import annotations

import argparse
import json
import math
import os
import shutil
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

BIN = Path(sys.executable).parent
KINCAL = str(BIN / "kincal")
KCOMP = str(BIN / "kincal-compensate")


def timed(argv: list[str], cores: str) -> float:
    """Wall time (s) of one run of argv pinned to `cores` (taskset list); a failure stops the script."""
    t0 = time.perf_counter()
    p = subprocess.run(["taskset", "-c", cores, *argv], capture_output=True, text=True)
    dt = time.perf_counter() - t0
    if p.returncode != 0:
        raise SystemExit(f"{' '.join(argv)} failed:\n{p.stderr[-2000:]}")
    return dt


def smooth_joint_path(n: int, seed: int = 1) -> np.ndarray:
    """n configurations (deg) of a smooth joint path of the kr500: each joint a sum of two slow sines
    inside 60% of its range, joint 5 kept 5 deg from the wrist singularity."""
    rng = np.random.default_rng(seed)
    t = np.linspace(0.0, 1.0, n)[:, None]
    lo = np.array([-185, -130, -100, -350, -120, -350.0])
    hi = np.array([185, 20, 144, 350, 120, 350.0])
    mid, half = (lo + hi) / 2, 0.3 * (hi - lo)
    f1, f2 = rng.uniform(1, 5, 6), rng.uniform(5, 20, 6)
    q = mid + half * (0.7 * np.sin(2 * math.pi * f1 * t) + 0.3 * np.sin(2 * math.pi * f2 * t))
    q[:, 4] = np.where(np.abs(q[:, 4]) < 5, 5.0, q[:, 4])
    return q


def program(path: Path, n: int, seed: int = 1) -> None:
    """A pose program of n poses: smooth_joint_path through `kincal fk`."""
    q = smooth_joint_path(n, seed)
    joints = path.with_suffix(".joints.csv")
    np.savetxt(joints, q, delimiter=",", header="q1,q2,q3,q4,q5,q6", comments="", fmt="%.6f")
    subprocess.run([KINCAL, "fk", "--robot", "kr500", "--joints", str(joints), "--out", str(path)], check=True,
                   capture_output=True)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--workdir", default="/tmp/kincal-scale")
    ap.add_argument("--quick", action="store_true", help="the smallest size of each only (a check of the script)")
    a = ap.parse_args()
    wd = Path(a.workdir)
    shutil.rmtree(wd, ignore_errors=True)
    wd.mkdir(parents=True)
    cores = {"1": "0", "2": "0,1"} if (os.cpu_count() or 1) >= 2 else {"1": "0"}
    out: dict[str, dict[str, float]] = {}

    def record(name: str, argv: list[str]) -> None:
        out[name] = {c: round(timed(argv, cs), 3) for c, cs in cores.items()}
        print(name, out[name], file=sys.stderr, flush=True)

    pick = (lambda xs: xs[:1]) if a.quick else (lambda xs: xs)
    truth = wd / "truth.json"
    for n in pick([50, 150, 500]):
        data = wd / f"m{n}.csv"
        subprocess.run([KINCAL, "simulate", "--robot", "kr500", "--poses", str(n), "--out", str(data), "--seed", "1",
                        "--truth-out", str(truth)], check=True, capture_output=True)
        record(f"identify_{n}_poses", [KINCAL, "identify", "--robot", "kr500", "--data", str(data),
                                       "--out", str(wd / "model.json")])
        record(f"diagnose_{n}_poses", [KINCAL, "diagnose", "--robot", "kr500", "--data", str(data),
                                       "--out", str(wd / f"diag{n}")])
    data = wd / "m150.csv" if not a.quick else wd / "m50.csv"
    for effects in pick(["none", "joint_compliance", "joint_compliance,transmission_error,backlash"]):
        record(f"identify_effects_{effects.replace(',', '+')}",
               [KINCAL, "identify", "--robot", "kr500", "--data", str(data), "--out", str(wd / "model.json"),
                "--effects", effects])
    for n in pick([10_000, 30_000, 100_000]):
        record(f"plan_{n}_candidates", [KINCAL, "plan", "--robot", "kr500", "--poses", "60", "--candidates", str(n),
                                        "--out", str(wd / "plan.csv")])
    # the compensation: the identified model (compliance kept) on programs of three lengths
    subprocess.run([KINCAL, "identify", "--robot", "kr500", "--data", str(data), "--out", str(wd / "model.json")],
                   check=True, capture_output=True)
    for n in pick([10_000, 100_000, 1_000_000]):
        prog = wd / f"p{n}.csv"
        program(prog, n)
        record(f"kincal_compensate_cpp_{n}_poses", [KCOMP, "--model", str(wd / "model.json"), "--program", str(prog),
                                                    "--out", str(wd / "j.csv")])
        record(f"kincal_compensate_py_{n}_poses", [KINCAL, "compensate", "--model", str(wd / "model.json"),
                                                   "--program", str(prog), "--out", str(wd / "j.csv")])
    print(json.dumps(out, indent=1))


if __name__ == "__main__":
    main()
