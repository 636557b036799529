"""kincal identify against FIGAROH's geometric calibration: the same data, the same run (issue 33, item 3).

The issue's goals: one fit of the geometry without validation (`kincal identify --effects none --folds 0`)
at least 10x faster than FIGAROH's fit of the same data, and the default `kincal identify` (the effects the
data choose, 5-fold cross-validation) at least 2x faster.

Two campaigns:

- ur10b: the UR10 series B of ../shared/data/ipa-robot-accuracy (Landgraf et al., CASE 2021: a laser
  tracker, the T-Mac probe's position only; 1,495 configurations, one point each). kincal: the built-in
  `ur10` and the CSV that kincal.io.datasets.read_ipa and identify's measurements_csv make of it (as
  tests/python/test_ur10_path.py makes it).
- c540: `kincal simulate --robot kr500 --poses 180 --targets 3 --seed 3` (180 configurations x 3
  reflectors = 540 rows; simulate's default truth: 1 mm / 0.05 deg geometric errors and joint
  compliance, 0.02 mm noise).

FIGAROH (from PyPI; its own interpreter, --figaroh-env) gets the same rows: the URDF of kincal's nominal
robot (kincal.io.urdf.spec_urdf: its FK is kincal's to 1e-12 mm) and one CSV row per configuration with
the position of each marker (x1, y1, z1, x2, ... in m; the joints in rad). benchmarks/_figaroh_driver.py
runs BaseCalibration as FIGAROH's examples do: calibration_level full_params (six placement errors per
joint, reduced to the structural base parameters; FIGAROH's default estimation method), the base frame
and each marker's position unknown (known_baseframe / known_tipframe False), its UR10 example's cost
function, then initialize() and solve() (at most 3 fits with outliers > 5 cm excluded: none are). Where
the two differ: kincal's default fit has priors on the joint parameters and a Huber loss, FIGAROH's is
plain least squares; the parameter sets are each tool's own (kincal: 4 per joint, base, targets; FIGAROH:
its structural base parameters of 6 per joint). The fit quality printed beside the times (3-D RMS of
every point's residual after the fit) shows whether both solved the same problem; one run of kincal as
plain least squares (--loss none --prior-sd none, untimed) gives the least-squares minimum itself. (On c540,
FIGAROH's structural choice misses one direction the data determine: add_base_name renames the first six
base parameters to the base frame's, and there the sixth is d_px of the second joint; it ends at 0.87 mm
RMS against the 0.72 mm minimum, which its estimation.method excitation reaches: --figaroh-also.)

Timing: the campaigns are made first; then, each repetition, FIGAROH and the two kincal commands run in
turn (the order reversed every other repetition), each as a subprocess, and the kincal commands also
in-process (kincal.cli.main, same arguments). Figures are medians (and minima) of the repetitions:
- FIGAROH fit: initialize() + solve() timed inside the driver (reading the data, choosing the
  parameters, the Levenberg-Marquardt fit, FIGAROH's evaluation and quality report); not the interpreter's
  start, the imports (done before), nor loading the URDF (1-5 ms). "LM alone": the solve_optimisation()
  part of it, the solver and nothing else.
- kincal in-process: kincal.cli.main(["identify", ...]) after a warm-up call: reading the CSV, the fit(s),
  the validation, writing the model JSON and the summary (to a string); not the interpreter nor imports.
- command: the wall time of the whole process (interpreter, imports, everything), for both tools.
CPU seconds (user + system, every thread) are given beside each wall time: on a shared machine they move
less than wall time with the others' load. FIGAROH runs with one BLAS thread unless --figaroh-blas-threads
says otherwise (kincal's commands use one by default: blas_threads.py).

    .venv/bin/python benchmarks/figaroh_compare.py --repeats 5 [--workdir /tmp/figaroh-compare]

Skips (exit 0, with a message) when FIGAROH's environment is missing, and skips a campaign whose data
are missing.
"""

from __future__ import annotations

import argparse
import contextlib
import io
import json
import os
import resource
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable

import numpy as np

HERE = Path(__file__).resolve().parent
REPO = HERE.parent
BIN = Path(sys.executable).parent
KINCAL = str(BIN / "kincal")
DRIVER = HERE / "_figaroh_driver.py"
FIGAROH_ENV = REPO.parent / "figaroh-venv"
IPA = REPO.parent / "shared" / "data" / "ipa-robot-accuracy"
SERIES_B = "Series_B/measurements_joint_configurations.csv"

#: the kincal commands timed: (key, label, identify's options)
KINCAL_RUNS = [("folds0", "kincal identify --effects none --folds 0", ["--effects", "none", "--folds", "0"]),
               ("default", "kincal identify (defaults)", [])]
#: the goals of the issue: FIGAROH's fit time / kincal's
GOALS = {"folds0": 10.0, "default": 2.0}


@dataclass
class Case:
    name: str
    title: str
    robot: str  # kincal's robot (a built-in name)
    kincal_csv: Path
    figaroh_csv: Path
    urdf: Path
    markers: int
    configurations: int
    times: dict[str, list[tuple[float, float]]] = field(default_factory=dict)  # key: [(wall, cpu)]
    quality: dict[str, dict[str, Any]] = field(default_factory=dict)


# ------------------------------------------------------------------------------------------ data
def figaroh_inputs(case_robot: str, kincal_csv: Path, out_csv: Path, out_urdf: Path) -> tuple[int, int]:
    """The URDF of kincal's nominal `case_robot` and FIGAROH's CSV of the rows of `kincal_csv`: one row per
    configuration, the markers in target order. Returns (configurations, markers)."""
    import kincal
    from kincal import _core
    from kincal.calibration import identify as ident
    from kincal.io.urdf import spec_urdf

    robot = kincal.load_robot(case_robot)
    spec = json.loads(robot.to_json())["nominal"]
    out_urdf.write_text(spec_urdf(spec, case_robot))
    joints = [j["name"] for j in spec["joints"]]
    data = ident.read_measurements(str(kincal_csv), robot, None)
    q = _core.joints_from_controller(robot, data.q_deg)  # the model's angles (the file: the controller's)
    pose, target, xyz = data.pose, data.target, data.xyz
    markers = int(target.max()) + 1
    rows = []
    for p in np.unique(pose):
        idx = np.flatnonzero(pose == p)
        idx = idx[np.argsort(target[idx])]
        if list(target[idx]) != list(range(markers)):
            raise SystemExit(f"{kincal_csv}: configuration {p} does not measure each of the {markers} targets once; "
                             "FIGAROH needs every marker in every row")
        rows.append(np.concatenate([xyz[idx].ravel() / 1000.0, np.radians(q[idx[0]])]))
    header = [f"{c}{k + 1}" for k in range(markers) for c in "xyz"] + joints
    np.savetxt(out_csv, np.array(rows), delimiter=",", header=",".join(header), comments="", fmt="%.17g")
    return len(rows), markers


def make_cases(work: Path, which: list[str], ipa: Path) -> list[Case]:
    import kincal
    from kincal.calibration import identify as ident
    from kincal.io import datasets

    cases = []
    for name in which:
        if name == "ur10b":
            src = ipa / SERIES_B
            if not src.exists():
                print(f"skipped ur10b: {src} is not present", file=sys.stderr)
                continue
            csv = work / "ur10b.csv"
            csv.write_text(ident.measurements_csv(datasets.read_ipa(src), kincal.load_robot("ur10").dof))
            robot, title = "ur10", f"UR10 series B ({src.name})"
        elif name == "c540":
            csv = work / "c540.csv"
            run([KINCAL, "simulate", "--robot", "kr500", "--poses", "180", "--targets", "3", "--seed", "3",
                 "--out", str(csv)])
            robot, title = "kr500", "simulated kr500 campaign (simulate --poses 180 --targets 3 --seed 3)"
        else:
            raise SystemExit(f"unknown campaign {name!r} (ur10b, c540)")
        fcsv, urdf = work / f"{name}-figaroh.csv", work / f"{name}.urdf"
        n, m = figaroh_inputs(robot, csv, fcsv, urdf)
        cases.append(Case(name, title, robot, csv, fcsv, urdf, m, n))
    return cases


# ------------------------------------------------------------------------------------------ timing
def run(argv: list[str], env: dict[str, str] | None = None) -> tuple[float, float, str]:
    """(wall s, CPU s of the child, stdout) of one subprocess; a failure stops the script."""
    r0 = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    p = subprocess.run(argv, capture_output=True, text=True, env=env, check=False)
    wall = time.perf_counter() - t0
    r1 = resource.getrusage(resource.RUSAGE_CHILDREN)
    if p.returncode != 0:
        raise SystemExit(f"{' '.join(argv)} failed ({p.returncode}):\n{p.stderr[-3000:]}")
    return wall, (r1.ru_utime - r0.ru_utime) + (r1.ru_stime - r0.ru_stime), p.stdout


def in_process(argv: list[str]) -> tuple[float, float]:
    """(wall s, CPU s) of kincal.cli.main(argv) in this interpreter, its output to a string."""
    from kincal.cli import main

    out, err = io.StringIO(), io.StringIO()
    t0, c0 = time.perf_counter(), time.process_time()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        rc = main(argv)
    wall, cpu = time.perf_counter() - t0, time.process_time() - c0
    if rc != 0:
        raise SystemExit(f"kincal {' '.join(argv)} failed:\n{err.getvalue()[-3000:]}")
    return wall, cpu


def kincal_argv(case: Case, opts: list[str], out: Path) -> list[str]:
    return ["identify", "--robot", case.robot, "--data", str(case.kincal_csv), "--out", str(out), *opts]


def kincal_fit(path: Path) -> dict[str, Any]:
    """The fit figures a model JSON records (identification.fit: 3-D RMS and max over every row, mm)."""
    ident = json.loads(path.read_text())["identification"]
    fit = ident["fit"]
    v = ident.get("validation") or {}
    return {"rms_mm": fit["rms_mm"], "max_mm": fit["max_mm"], "rows": fit["rows"],
            "parameters": sum(1 for p in ident["parameters"] if not p.get("fixed")),
            "held_out_rms_mm": v.get("after_rms_mm"), "loss": ident["loss"]["name"],
            "effects": [str(e) for e in ident.get("effects", [])]}


def figaroh_argv(args: argparse.Namespace, case: Case, work: Path, method: str) -> list[str]:
    return [str(args.figaroh_env / "bin" / "python"), str(DRIVER), "--urdf", str(case.urdf), "--data",
            str(case.figaroh_csv), "--markers", str(case.markers), "--workdir", str(work), "--cost",
            args.figaroh_cost, "--method", method]


def figaroh_env(args: argparse.Namespace) -> dict[str, str]:
    env = dict(os.environ)
    if args.figaroh_blas_threads > 0:
        for k in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
            env[k] = str(args.figaroh_blas_threads)
    return env


def bench_case(args: argparse.Namespace, case: Case, work: Path) -> None:
    env = figaroh_env(args)
    fig = figaroh_argv(args, case, work, args.figaroh_method)
    model = {k: work / f"{case.name}-{k}.json" for k, _, _ in KINCAL_RUNS}

    def figaroh_step() -> None:
        wall, cpu, out = run(fig, env)
        r = json.loads(out.strip().splitlines()[-1])
        case.quality["figaroh"] = r
        for key, w, c in (("figaroh_fit", r["fit_s"], r["fit_cpu_s"]), ("figaroh_lm", r["lm_s"], r["lm_cpu_s"]),
                          ("figaroh_cmd", wall, cpu)):
            case.times.setdefault(key, []).append((w, c))

    def kincal_step(key: str, opts: list[str], inproc: bool) -> Callable[[], None]:
        def step() -> None:
            argv = kincal_argv(case, opts, model[key])
            if inproc:
                wall, cpu = in_process(argv)
                case.times.setdefault(f"{key}_inproc", []).append((wall, cpu))
            else:
                wall, cpu, _ = run([KINCAL, *argv])
                case.times.setdefault(f"{key}_cmd", []).append((wall, cpu))
            case.quality[key] = kincal_fit(model[key])
        return step

    steps = [figaroh_step] + [kincal_step(k, o, False) for k, _, o in KINCAL_RUNS] + \
        [kincal_step(k, o, True) for k, _, o in KINCAL_RUNS]
    print(f"{case.name}: warm-up (one untimed run of each)", file=sys.stderr)
    for s in steps:
        s()
    case.times.clear()
    for i in range(args.repeats):
        for s in (steps if i % 2 == 0 else steps[::-1]):
            s()
        print(f"{case.name}: repetition {i + 1} of {args.repeats}", file=sys.stderr)

    # untimed, for the fit quality only: kincal as plain least squares, and FIGAROH's other methods
    plain = work / f"{case.name}-plain.json"
    in_process(kincal_argv(case, ["--effects", "none", "--folds", "0", "--loss", "none", "--prior-sd", "none"], plain))
    case.quality["plain"] = kincal_fit(plain)
    for method in args.figaroh_also:
        wall, _, out = run(figaroh_argv(args, case, work, method), env)
        r = json.loads(out.strip().splitlines()[-1])
        r["cmd_s"] = wall
        case.quality[f"figaroh_{method}"] = r


# ------------------------------------------------------------------------------------------ report
def med(xs: list[tuple[float, float]], i: int) -> float:
    return statistics.median(x[i] for x in xs)


def low(xs: list[tuple[float, float]], i: int) -> float:
    return min(x[i] for x in xs)


def report(args: argparse.Namespace, case: Case) -> dict[str, Any]:
    t, q = case.times, case.quality
    f = q["figaroh"]
    print(f"\n== {case.name}: {case.title}: {case.configurations} configurations x {case.markers} marker(s) = "
          f"{case.configurations * case.markers} rows; {args.repeats} alternated repetitions, median (min)")
    print(f"{'':58}{'wall s':>17}{'CPU s':>17}{'RMS mm':>9}{'max mm':>8}{'params':>7}")

    def line(label: str, key: str, rms: float | None, mx: float | None, npar: Any) -> None:
        xs = t[key]
        tail = (f"{rms:9.4f}{mx:8.3f}{npar!s:>7}" if rms is not None else "")
        print(f"  {label:<56}{med(xs, 0):8.3f} ({low(xs, 0):6.3f}){med(xs, 1):8.3f} ({low(xs, 1):6.3f}){tail}")

    line(f"FIGAROH fit: initialize() + solve() [{args.figaroh_method}]", "figaroh_fit", f["rms_mm"], f["max_mm"],
         f["parameters"])
    line("  of which LM alone (solve_optimisation)", "figaroh_lm", None, None, None)
    line("  FIGAROH command (interpreter, imports, URDF, fit)", "figaroh_cmd", None, None, None)
    for key, label, _ in KINCAL_RUNS:
        k = q[key]
        line(f"{label}, in-process", f"{key}_inproc", k["rms_mm"], k["max_mm"], k["parameters"])
        line("  command", f"{key}_cmd", None, None, None)
    p = q["plain"]
    print(f"  kincal --effects none --folds 0 --loss none --prior-sd none (plain least squares, untimed): "
          f"RMS {p['rms_mm']:.4f} mm, max {p['max_mm']:.3f} mm, {p['parameters']} parameters")
    if q["default"].get("held_out_rms_mm") is not None:
        print(f"  kincal defaults: effects {', '.join(map(str, q['default']['effects'])) or 'none'}; "
              f"cross-validated RMS {q['default']['held_out_rms_mm']:.4f} mm")
    print(f"  FIGAROH: {f['excluded_samples']} sample(s) excluded as outliers, status {f['status']}, cost function "
          f"{f['cost']}, data+parameter choice {f['initialize_s']:.3f} s + solve {f['solve_s']:.3f} s (last run)")
    for method in args.figaroh_also:
        r = q[f"figaroh_{method}"]
        print(f"  FIGAROH estimation.method {method} (one run): fit {r['fit_s']:.3f} s (LM {r['lm_s']:.3f} s), "
              f"RMS {r['rms_mm']:.4f} mm, max {r['max_mm']:.3f} mm, {r['parameters']} parameters")

    ratios: dict[str, Any] = {}
    print("  speed-up (FIGAROH / kincal, ratio of the medians; goal):")
    for key, label, _ in KINCAL_RUNS:
        r = {"fit/inproc": med(t["figaroh_fit"], 0) / med(t[f"{key}_inproc"], 0),
             "lm/inproc": med(t["figaroh_lm"], 0) / med(t[f"{key}_inproc"], 0),
             "cmd/cmd": med(t["figaroh_cmd"], 0) / med(t[f"{key}_cmd"], 0),
             "fit/cmd": med(t["figaroh_fit"], 0) / med(t[f"{key}_cmd"], 0),
             "cpu fit/inproc": med(t["figaroh_fit"], 1) / med(t[f"{key}_inproc"], 1)}
        goal = GOALS[key]
        verdict = "met" if r["fit/inproc"] >= goal else "NOT met"
        print(f"    {label:<42} fit/in-process {r['fit/inproc']:6.2f}x  LM alone/in-process {r['lm/inproc']:6.2f}x  "
              f"command/command {r['cmd/cmd']:6.2f}x  fit/command {r['fit/cmd']:6.2f}x  (CPU: fit/in-process "
              f"{r['cpu fit/inproc']:6.2f}x); goal >= {goal:g}x: {verdict}")
        ratios[key] = r
    return {"case": case.name, "title": case.title, "configurations": case.configurations, "markers": case.markers,
            "times": {k: {"wall_median": med(v, 0), "wall_min": low(v, 0), "cpu_median": med(v, 1),
                          "cpu_min": low(v, 1), "runs": v} for k, v in t.items()},
            "quality": q, "ratios": ratios}


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--figaroh-env", type=Path, default=FIGAROH_ENV,
                   help=f"the virtual environment FIGAROH is installed in (default {FIGAROH_ENV})")
    p.add_argument("--data", type=Path, default=IPA, help=f"the UR10 data folder (default {IPA})")
    p.add_argument("--campaigns", default="ur10b,c540", help="comma separated: ur10b, c540")
    p.add_argument("--repeats", type=int, default=5)
    p.add_argument("--workdir", type=Path, help="keep the files here (default: a temporary folder)")
    p.add_argument("--figaroh-method", default="structural",
                   help="FIGAROH's estimation.method of the timed fit (default: structural, its default)")
    p.add_argument("--figaroh-also", action="append", default=[], metavar="METHOD",
                   help="also run FIGAROH once with this estimation.method, outside the alternation, for its fit "
                        "quality (e.g. excitation; on ur10b its parameter choice took 440 s)")
    p.add_argument("--figaroh-cost", choices=["example", "plain"], default="example",
                   help="FIGAROH's cost function: its UR10 example's (SE(3) log map; default) or estimated - measured")
    p.add_argument("--figaroh-blas-threads", type=int, default=1, help="0: FIGAROH's BLAS default")
    p.add_argument("--json", type=Path, help="also write every figure here")
    args = p.parse_args(argv)

    py = args.figaroh_env / "bin" / "python"
    if not py.exists():
        print(f"skipped: no FIGAROH environment at {args.figaroh_env} (--figaroh-env)")
        return 0
    probe = "import figaroh, pinocchio; print(getattr(figaroh, '__version__', '?'), pinocchio.__version__)"
    check = subprocess.run([str(py), "-c", probe], capture_output=True, text=True, check=False)
    if check.returncode != 0:
        print(f"skipped: {py} cannot import figaroh and pinocchio:\n{check.stderr[-1000:]}")
        return 0
    versions = check.stdout.split()

    tmp = None
    if args.workdir:
        work = args.workdir
        work.mkdir(parents=True, exist_ok=True)
    else:
        tmp = tempfile.mkdtemp(prefix="figaroh-compare-")
        work = Path(tmp)
    try:
        cases = make_cases(work, [c.strip() for c in args.campaigns.split(",") if c.strip()], args.data)
        if not cases:
            print("skipped: no campaign's data are present")
            return 0
        print(f"FIGAROH {versions[0]} (pinocchio {versions[1]}) in {args.figaroh_env}; kincal in {sys.prefix}; "
              f"{os.cpu_count()} cores, load average {os.getloadavg()[0]:.2f} at the start", flush=True)
        results = []
        for case in cases:
            bench_case(args, case, work)
            results.append(report(args, case))
        print(f"\nload average {os.getloadavg()[0]:.2f} at the end")
        if args.json:
            args.json.write_text(json.dumps({"figaroh": versions[0], "pinocchio": versions[1], "repeats": args.repeats,
                                             "figaroh_method": args.figaroh_method, "figaroh_cost": args.figaroh_cost,
                                             "figaroh_blas_threads": args.figaroh_blas_threads,
                                             "cases": results}, indent=1, default=str) + "\n")
    finally:
        if tmp:
            shutil.rmtree(tmp, ignore_errors=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
