"""The `kincal` command: thin, one function per subcommand (see ../README.md for the contract)."""

from __future__ import annotations

import argparse
import csv
import json
import math
import sys
import time
from pathlib import Path
from typing import Optional, Sequence

import numpy as np

from . import _core, compensate, fk, ik, line_program, load_robot
from . import diagnose as diagnosis
from . import feed as feedmod
from . import fivebar
from . import identify as ident
from .urdf import spec_urdf, urdf_left_out


def _fmt_rows(header: Sequence[str], rows) -> str:
    out = [",".join(header)]
    for r in rows:
        out.append(",".join(v if isinstance(v, str) else (str(v) if isinstance(v, (int, np.integer)) else repr(float(v)))
                            for v in r))
    return "\n".join(out) + "\n"


def _csv_columns(path: str, names: Sequence[str]) -> dict:
    """Extra columns (e.g. pose, target) of a CSV, row by row, when present (blank lines skipped)."""
    with open(path, newline="") as f:
        rows = [r for r in csv.reader(f) if any(c.strip() for c in r)]
    if not rows:
        return {}
    header = [h.strip() for h in rows[0]]
    return {n: [r[header.index(n)].strip() for r in rows[1:]] for n in names if n in header}


def _robot(args) -> _core.Robot:
    return load_robot(args.robot, getattr(args, "base", None), getattr(args, "tip", None))


def cmd_fk(args) -> None:
    robot = _robot(args)
    if args.frame == "instrument" and not robot.identified:
        raise ValueError(f"{args.robot}: --frame instrument needs an identified model (kincal identify)")
    q, _ = _core.read_joint_program(args.joints, robot.dof)
    ctx = _effect_columns(args.joints, robot, len(q), args.temperature)
    poses = fk(robot, q, frame=args.frame, dir=ctx.get("dir"), temperature_c=ctx.get("temperature_c"))
    extra = _csv_columns(args.joints, ["pose", "target"]) if args.joints.lower().endswith(".csv") else {}
    if "target" in extra:
        targets = _identified_targets(args.robot)
        for i, t in enumerate(extra["target"]):
            try:
                k = int(t)
            except ValueError:
                raise ValueError(f"{args.joints}:{i + 2}: column 'target': '{t}' is not an integer") from None
            if not 0 <= k < len(targets):
                raise ValueError(f"{args.joints}:{i + 2}: target {t} but the model knows {len(targets)} target(s)")
            r = _core.abc_to_rotation(poses[i, 3:]) if targets[k].any() else None
            if r is not None:
                poses[i, :3] = poses[i, :3] + r @ targets[k]
    header = list(extra) + ["x", "y", "z", "a", "b", "c"]
    rows = [[extra[k][i] for k in extra] + list(p) for i, p in enumerate(poses)]
    _core.write_file_atomic(args.out, _fmt_rows(header, rows))


def _effect_columns(path: str, robot: _core.Robot, n: int, temperature: Optional[float]) -> dict:
    """What the model's effects read from a joint file: dir1..dirN (backlash) and temperature_c
    (thermal expansion, unless --temperature); a missing column is an error naming it."""
    out: dict = {}
    if robot.needs_temperature and temperature is not None:
        out["temperature_c"] = np.full(n, float(temperature))
    if not (robot.needs_dir or (robot.needs_temperature and temperature is None)):
        return out
    header: list = []
    if path.lower().endswith(".csv"):
        with open(path, newline="") as f:
            header = [h.strip() for h in next(csv.reader(f), [])]
    if robot.needs_dir:
        names = [f"dir{j + 1}" for j in range(robot.dof)]
        missing = [c for c in names if c not in header]
        if missing:
            raise ValueError(f"{path}:1: missing column '{missing[0]}': the model has backlash, which needs each "
                             f"joint's direction of motion into the pose (dir1..dir{robot.dof}, +1 or -1)")
        d = _core.read_csv_columns(path, names)
        bad = np.argwhere((d != 1.0) & (d != -1.0))
        if len(bad):
            raise ValueError(f"{path}: row {bad[0][0] + 1}: column '{names[bad[0][1]]}': "
                             f"{d[bad[0][0], bad[0][1]]:g} is not +1 or -1")
        out["dir"] = d
    if robot.needs_temperature and temperature is None:
        if "temperature_c" not in header:
            raise ValueError(f"{path}:1: missing column 'temperature_c': the model has thermal expansion "
                             "(or give --temperature C)")
        else:
            out["temperature_c"] = _core.read_csv_columns(path, ["temperature_c"])[:, 0]
    return out


def _directions(text: Optional[str]) -> list:
    """--initial-direction: +1, -1, or one sign per joint, comma separated."""
    if text is None:
        return []
    try:
        v = [float(x) for x in text.split(",")]
    except ValueError:
        raise ValueError(f"--initial-direction {text}: expected +1, -1 or s1,..,s6") from None
    if len(v) not in (1, 6) or any(x not in (1.0, -1.0) for x in v):
        raise ValueError(f"--initial-direction {text}: one sign (+1 or -1) for all joints, or one per joint")
    return v


def _identified_targets(robot_arg: str) -> np.ndarray:
    """Target offsets (tool frame, mm) an identified model JSON carries; only the tool point otherwise."""
    if str(robot_arg).lower().endswith(".json"):
        with open(robot_arg) as f:
            d = json.load(f)
        t = d.get("identification", {}).get("targets_mm")
        if t:
            return np.asarray(t, dtype=float)
    return np.zeros((1, 3))


def cmd_ik(args) -> None:
    robot = _robot(args)
    if not robot.closed_form_ik:
        raise ValueError(f"{args.robot}: no closed-form IK for this robot ({robot.ik_reason})")
    poses, lines = _core.read_pose_program(args.poses)
    ref = list(robot.home_deg) or [0.0] * robot.dof
    rows = []
    for i, (pose, line) in enumerate(zip(poses, lines)):
        sols = ik(robot, pose, ref)
        if not sols:
            raise ValueError(f"{args.poses}:{line}: pose out of reach of the robot (no IK solution)")
        if args.all:
            rows += [[i, k, int(s["within_limits"])] + list(s["q_deg"]) for k, s in enumerate(sols)]
        ok = [s for s in sols if s["within_limits"]]
        if not ok:
            raise ValueError(f"{args.poses}:{line}: no IK solution within the joint limits")
        best = min(ok, key=lambda s: float(np.sum((np.asarray(s["q_deg"]) - ref) ** 2)))
        ref = list(best["q_deg"])
        if not args.all:
            rows.append(ref)
    qn = [f"q{j + 1}" for j in range(robot.dof)]
    header = ["row", "solution", "within_limits"] + qn if args.all else qn
    _core.write_file_atomic(args.out, _fmt_rows(header, rows))


def _comp_kwargs(args) -> dict:
    return dict(compensate=not args.nominal, instrument=args.frame == "instrument",
                finite_difference=args.finite_difference, delta=args.delta, epsilon=args.epsilon,
                max_iterations=args.max_iterations, corrected_start=not args.paper_start, residual=args.residual,
                temperature_c=args.temperature, initial_direction=_directions(args.initial_direction),
                keep_branch=args.keep_branch)


def cmd_compensate(args) -> None:
    robot = load_robot(args.model)
    if args.frame == "instrument" and not robot.identified:
        raise ValueError(f"{args.model}: --frame instrument needs an identified model (kincal identify)")
    res = _core.compensate_program(robot, args.program, args.out, **_comp_kwargs(args))
    for w in res["warnings"]:
        print(f"kincal compensate: warning: {w}", file=sys.stderr)
    it = np.asarray(res["iterations"])
    print(f"{args.out}: {len(it)} poses compensated, iterations {it.min()}..{it.max()} "
          f"(mean {it.mean():.2f}), largest residual |F| {max(res['residual']):.3g}", file=sys.stderr)


def _progress(label: str):
    """A one-line progress report on stderr for work that takes seconds (quiet when not a terminal)."""
    if not sys.stderr.isatty():
        return None

    def report(iteration: int, cost: float) -> None:
        print(f"\r{label}: iteration {iteration}, cost {cost:.6g}   ", end="", file=sys.stderr, flush=True)
    return report


def _harmonics(text: str) -> list:
    """--harmonics 1,2,3: transmission_error's harmonic orders."""
    try:
        h = [int(x) for x in text.split(",") if x.strip()]
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected harmonic orders such as 1,2,3, not '{text}'") from None
    if not h or any(k < 1 for k in h) or len(set(h)) != len(h):
        raise argparse.ArgumentTypeError(f"harmonic orders must be distinct positive integers, not '{text}'")
    return h


def _hidden_effect(text: str, dof: int, harmonics: Sequence[int] = ident.DEFAULT_HARMONICS) -> tuple:
    """NAME:JOINT:V1,V2.. of --hide: (Effect, values in core units). The values are in the model
    file's units (degrees for angles, 1/C for thermal_expansion: joint 0); their number comes from
    the registry (transmission_error: a sine and a cosine amplitude per harmonic order)."""
    parts = text.split(":")
    if len(parts) != 3:
        raise ValueError(f"--hide {text}: expected NAME:JOINT:VALUES")
    name, joint, vals = parts[0], parts[1], parts[2]
    kinds = [k for k in _core.effect_kinds() if k.domain == "serial" and k.name != "joint_compliance"]
    kind = next((k for k in kinds if k.name == name), None)
    if kind is None:
        raise ValueError(f"--hide {text}: unknown effect '{name}' ({', '.join(k.name for k in kinds)})")
    try:
        j = int(joint)
        v = [float(x) for x in vals.split(",")]
    except ValueError:
        raise ValueError(f"--hide {text}: joint and values must be numbers") from None
    if kind.concerns == "joint" and not 1 <= j <= dof:
        raise ValueError(f"--hide {text}: joint {j} is not one of 1..{dof}")
    e = _core.Effect(name, j if kind.concerns == "joint" else 0, list(harmonics))
    if len(v) != e.size or not all(math.isfinite(x) for x in v):
        raise ValueError(f"--hide {text}: {e.label} takes {e.size} finite value(s) "
                         f"({', '.join(f'{n} ({u})' for n, u in zip(e.parameter_names, e.file_units))})")
    return e, [x / sc for x, sc in zip(v, e.file_scale)]


def cmd_simulate(args) -> None:
    robot = _robot(args)
    if args.truth:
        truth = load_robot(args.truth)
        if truth.dof != robot.dof:
            raise ValueError(f"{args.truth}: {truth.dof} joints but {args.robot} has {robot.dof}")
    else:
        truth = ident.default_truth(robot, seed=args.seed)
        if args.truth_out:
            _core.write_file_atomic(args.truth_out, truth.to_json())
    pool = args.poses * (10 if args.select == "observability" else 1)
    data = ident.simulate(truth, pool, seed=args.seed, noise_mm=args.noise, targets=args.targets,
                          outlier_fraction=args.outliers, outlier_mm=args.outlier_mm,
                          effects=[_hidden_effect(h, robot.dof, args.harmonics) for h in args.hide],
                          orientation_noise_deg=args.orientation_noise)
    if args.select == "observability":
        data = ident.select_observable(robot, data, args.poses)
    _core.write_file_atomic(args.out, ident.measurements_csv(data, robot.dof))
    print(f"wrote {len(data['pose'])} measured points of {args.poses} poses to {args.out}", file=sys.stderr)


def _effects(args, robot) -> list:
    """--effects (and --harmonics) as _core.Effect objects."""
    return ident.parse_effects(args.effects, robot, args.harmonics)


def _check_columns(effects: list, data: dict, path: str, robot) -> None:
    """The data columns the effects read are there (the error names the file and the column)."""
    ident.check_data_for(effects, dict(data, source=path), robot)


def cmd_identify(args) -> None:
    robot = _robot(args)
    effects = _effects(args, robot)
    data = ident.read_measurements(args.data, robot)
    _check_columns(effects, data, args.data, robot)
    res = ident.identify(robot, data, effects=effects, loss=args.loss, loss_scale_mm=args.loss_scale,
                         holdout=args.holdout, k_folds=args.folds, seed=args.seed,
                         progress=_progress("identify"), orientation_weight=args.orientation_weight)
    if sys.stderr.isatty():
        print(file=sys.stderr)
    if args.tool_targets:
        res = ident.tool_from_targets(res, _core.read_csv_columns(args.tool_targets, ["x", "y", "z"]))
    text = res.model_json()
    if args.urdf:
        cal = json.loads(text)["calibrated"]
        _core.write_file_atomic(args.urdf, spec_urdf(cal, cal.get("name", "calibrated").replace(" ", "_")))
        left = urdf_left_out(cal)
        if left:
            print(f"kincal identify: {args.urdf}: URDF carries geometry only; left out: {', '.join(left)} "
                  f"(in {args.out})", file=sys.stderr)
    _core.write_file_atomic(args.out, text)
    print(res.summary())


def bench_identify(poses: int, seed: int, repeats: int = 5) -> dict:
    """Identification on a simulated kr500 campaign (truth: default_truth(seed), one target, 0.02 mm
    noise), plain least squares. scipy_numpy_identify_ms: scipy.optimize.least_squares on the same
    residuals written in numpy (kincal/_numpy_model.py, checked against ours in the tests) with its
    2-point Jacobian, what a script has. identify_ms: our Ceres identification (analytic Jacobian; both stages, the
    identifiability analysis; without the covariance, which is identify_with_covariance_ms);
    scipy_identify_ms: scipy.optimize.least_squares ('trf') on the same residual function from our
    core with its own finite-difference Jacobian ('2-point', what a user without our Jacobian
    has); scipy_analytic_identify_ms: the same with our analytic Jacobian. scipy starts from the
    output of our first stage (a head start); each reports its final cost."""
    from scipy.optimize import least_squares

    robot = load_robot("kr500")
    truth = ident.default_truth(robot, seed=seed)
    data = ident.simulate(truth, poses, seed=seed, targets=1)

    def median_ms(f, n):
        ts = []
        for _ in range(n):
            t = time.perf_counter()
            out = f()
            ts.append(time.perf_counter() - t)
        return float(np.median(ts)) * 1e3, out

    opts = _core.IdentifyOptions(compliance=True, loss="none", covariance=False)
    opts_cov = _core.IdentifyOptions(compliance=True, loss="none", covariance=True)
    ours, res = median_ms(lambda: _core.identify(robot, data, opts), repeats)
    ours_cov, _ = median_ms(lambda: _core.identify(robot, data, opts_cov), repeats)
    pm = _core.PointModel(robot, 1)
    free = ~np.asarray(res.fixed)
    # scipy starts where our second stage starts (after our first stage fitted the base frame and
    # target on the nominal geometry): the held parameters then have the same values in both
    x0 = np.asarray(res.nominal_x, dtype=float)

    def full(z):
        x = x0.copy()
        x[free] = z
        return x

    def fun(z):
        return pm.residuals(full(z), data, False)[0]

    def jac(z):
        return pm.residuals(full(z), data, True)[1][:, free]

    tol = dict(method="trf", xtol=1e-12, ftol=1e-12, gtol=1e-12)
    # the baselines take a median of three runs too (one run moved by 30% on a loaded machine)
    fd_ms, fd = median_ms(lambda: least_squares(fun, x0[free], jac="2-point", **tol), 3)
    an_ms, an = median_ms(lambda: least_squares(fun, x0[free], jac=jac, **tol), max(1, repeats // 2))
    # what a script has: the same measurement model written in numpy, scipy's own Jacobian
    from ._numpy_model import NumpyPointModel

    npm = NumpyPointModel(robot, 1)
    np_ms, npr = median_ms(lambda: least_squares(lambda z: npm.residuals(full(z), data), x0[free], jac="2-point",
                                                 **tol), 3)
    return {"identify_poses": poses, "identify_parameters": res.layout.size,
            "identify_free_parameters": int(free.sum()), "identify_ms": ours,
            "identify_with_covariance_ms": ours_cov, "scipy_numpy_identify_ms": np_ms,
            "identify_speedup_vs_scipy_numpy": np_ms / ours, "scipy_numpy_identify_cost": float(npr.cost),
            "scipy_identify_ms": fd_ms,
            "scipy_analytic_identify_ms": an_ms, "identify_speedup_vs_scipy": fd_ms / ours,
            "identify_speedup_vs_scipy_analytic": an_ms / ours, "identify_cost": res.final_cost,
            "scipy_identify_cost": float(fd.cost), "scipy_analytic_identify_cost": float(an.cost)}


def _fivebar_points_csv(pts: dict) -> str:
    rows = [[int(i), t1, t2, d[0], d[1], m[0], m[1]] for i, t1, t2, d, m in
            zip(pts["id"], pts["theta1_deg"], pts["theta2_deg"], pts["desired"], pts["measured"])]
    return _fmt_rows(["point", "theta1_deg", "theta2_deg", "x_desired_mm", "y_desired_mm", "x_measured_mm",
                      "y_measured_mm"], rows)


def cmd_hr_fit(args) -> None:
    pts = fivebar.read_table(args.data)
    res = fivebar.fit(pts, args.method, args.score)
    _core.write_file_atomic(args.out, json.dumps(res, indent=1) + "\n")
    print(f"{args.method} ({args.score} score): a={res['a']:.3f} b={res['b']:.3f} c={res['c']:.3f} d={res['d']:.3f} mm, "
          f"points {res['points']}, largest error {res['max_error_mm'] * 1000:.1f} um")


def cmd_hr_matrix(args) -> None:
    fivebar.load_fit(args.fit)  # a readable FIT.json (the matrix belongs to the model that commanded the grid)
    pts = fivebar.read_table(args.data)
    m = _core.ErrorMatrix.from_points(pts, args.data)
    _core.write_file_atomic(args.out, m.to_json())
    e = fivebar.position_errors(pts)
    print(f"error matrix {m.nx} x {m.ny} nodes, {m.dx:g} x {m.dy:g} mm, from ({m.x0:g}, {m.y0:g}); "
          f"measured errors up to {e.max() * 1000:.1f} um")


def cmd_hr_command(args) -> None:
    model = fivebar.load_fit(args.fit)
    matrix = fivebar.load_matrix(args.matrix) if args.matrix else None
    xy = _core.read_csv_columns(args.targets, ["x", "y"])
    try:
        q = fivebar.command(model, xy, matrix)
    except ValueError as e:
        raise ValueError(f"{args.targets}: {e}") from None
    _core.write_file_atomic(args.out, _fmt_rows(["theta1_deg", "theta2_deg"], q))


def cmd_hr_simulate(args) -> None:
    truth = _core.paper_sixbar(args.seed)
    model = fivebar.load_fit(args.fit) if args.fit else fivebar.FiveBar()
    matrix = fivebar.load_matrix(args.matrix) if args.matrix else None
    xy = fivebar.grid_targets(args.grid) if args.targets is None else _core.read_csv_columns(args.targets, ["x", "y"])
    pts = _core.sixbar_campaign(truth, model, matrix, xy, args.noise, args.seed + 1)
    _core.write_file_atomic(args.out, _fivebar_points_csv(pts))
    print(f"measured {len(pts['id'])} points on the simulated 6-bar (seed {args.seed}), "
          f"largest error {fivebar.position_errors(pts).max() * 1000:.1f} um", file=sys.stderr)


def _pair(text: str) -> tuple:
    try:
        a, b = (float(x) for x in text.split(","))
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected two numbers S0,S1, not '{text}'") from None
    if not a < b:
        raise argparse.ArgumentTypeError(f"S0 must be below S1 in '{text}'")
    return a, b


def cmd_feed(args) -> None:
    robot = _robot(args)
    limits = feedmod.robot_limits(robot)
    if args.limits:
        limits = feedmod.read_limits(args.limits, robot.dof, limits)
    for name, lim in zip(("velocity", "acceleration", "jerk"), limits):
        if not all(x > 0 for x in lim):
            raise ValueError(f"{args.robot}: the model has no {name} limit for some axis; give --limits L.csv")
    programs = {"program": args.program}
    if args.compare:
        programs["compare"] = args.compare
    results = {}
    for key, path in programs.items():
        q, _ = _core.read_joint_program(path, robot.dof)
        res = feedmod.analyse(np.asarray(q), *limits, feed=args.feed, samples=args.samples, method=args.method)
        res["file"] = path
        res["label"] = Path(path).name
        results[key] = res
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    doc = {"feed_rad_s": args.feed, "method": args.method, "samples": args.samples,
           "limits": {"v_max_deg_s": limits[0], "a_max_deg_s2": limits[1], "j_max_deg_s3": limits[2]},
           "programs": {k: feedmod.json_ready(r) for k, r in results.items()},
           "figures": []}
    for axis in range(1, robot.dof + 1):
        name = f"axis{axis}.png"
        feedmod.figure(results, *limits, args.feed, axis, str(out / name), window=args.window, zoom=args.zoom)
        doc["figures"].append(name)
    _core.write_file_atomic(str(out / "feed.json"), json.dumps(doc) + "\n")
    for k, r in results.items():
        t = r.get("time_optimal", {})
        print(f"{k} ({r['file']}): s = {r['s_total_rad']:.4f} rad, {len(r['violations'])} violation(s) at "
              f"{args.feed:g} rad/s; time-optimal traversal {t.get('time_s', float('nan')):.3f} s")
        for v in r["violations"][:10]:
            print(f"  axis A{v['axis']} {v['limit']} limit from s = {v['s']:.4f} to {v['s_end']:.4f} rad "
                  f"(allowed feed down to {v['allowed_feed']:.4g} rad/s)")


def bench_feed(seed: int) -> dict:
    """The derivative analysis (spline resampling at the paper's 2900/297 samples per pose,
    derivatives, feed limits, violations and the time-optimal profile) of a smooth synthetic 6-axis
    joint program of 297 and of 100,000 poses: milliseconds, and per pose."""
    rng = np.random.default_rng(seed)
    amp, w, ph = rng.uniform(10, 60, 6), rng.uniform(0.5, 2.0, 6), rng.uniform(0, 6.28, 6)
    lim = ([80.0] * 6, [160.0] * 6, [1600.0] * 6)
    out = {}
    for n in (297, 100_000):
        t = np.linspace(0, 1, n)[:, None]
        q = amp * np.sin(w * t * 6.28 + ph)
        samples = max(feedmod.DEFAULT_SAMPLES, int(round(n * feedmod.DEFAULT_SAMPLES / 297)))
        feedmod.analyse(q[:50], *lim, samples=500)  # imports warm
        times = []
        for _ in range(3 if n < 1000 else 1):
            t0 = time.perf_counter()
            feedmod.analyse(q, *lim, samples=samples)
            times.append(time.perf_counter() - t0)
        out[f"feed_{n}_poses_ms"] = float(np.median(times)) * 1e3
        out[f"feed_{n}_poses_us_per_pose"] = float(np.median(times)) * 1e6 / n
    return out


def _diagnose_fivebar(args) -> None:
    import html

    pts = fivebar.read_table(args.data)
    diag = fivebar.diagnose(pts, folds=args.folds, seed=args.seed, noise_mm=args.noise,
                            say=lambda s: print(s, file=sys.stderr, flush=True))
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    x0 = fivebar.fit_with_effects(pts, [])
    before = dict(pts, desired=fivebar._predict(pts, x0, []))
    effects = [_core.Effect(s["effect"], fivebar.LINKS.index(s["link"]) + 1 if s.get("link") else s["joint"])
               for s in diag["steps"]]
    after = dict(pts, desired=fivebar._predict(pts, fivebar.fit_with_effects(pts, effects), effects))
    fivebar.error_map_figure([("four lengths", before), ("with the named effects", after)], str(out / "residual_map.png"),
                             title="five-bar: model minus measured position")
    rows = "".join(f"<tr><td>{k + 1}</td><td>{html.escape(s['effect'])}</td><td>{s.get('link') or s['joint']}</td>"
                   f"<td>{s['evidence']['F']:.3g}</td><td>{s['rms_before_mm'] * 1000:.1f}</td>"
                   f"<td>{s['rms_after_mm'] * 1000:.1f}</td></tr>" for k, s in enumerate(diag["steps"]))
    _core.write_file_atomic(str(out / "report.html"), f"""<!DOCTYPE html><html lang="en"><head><meta charset="utf-8">
<title>kincal diagnose: five-bar</title></head><body style="font-family:sans-serif;max-width:900px;margin:2em auto">
<h1>kincal diagnose: {html.escape(Path(args.data).name)} (five-bar hidden robot)</h1>
<table border="1" cellpadding="4"><tr><th>step</th><th>effect</th><th>link / actuator</th><th>F</th>
<th>CV RMS before (um)</th><th>after (um)</th></tr>{rows}</table>
<p>{html.escape(diag['verdict'])}: cross-validated RMS {diag['final_rms_mm'] * 1000:.1f} um.</p>
<img src="residual_map.png" alt="residual map" style="max-width:100%"></body></html>
""")
    _core.write_file_atomic(str(out / "diagnosis.json"), json.dumps(diagnosis.contract_json(diag), indent=1) + "\n")
    for st in diag["steps"]:
        print(f"{st['effect']} {st.get('link') or st['joint']}: cross-validated RMS "
              f"{st['rms_before_mm'] * 1000:.1f} -> {st['rms_after_mm'] * 1000:.1f} um")
    print(f"final {diag['final_rms_mm'] * 1000:.1f} um: {diag['verdict']}")


def cmd_diagnose(args) -> None:
    if args.robot == "fivebar":
        _diagnose_fivebar(args)
        return
    robot = _robot(args)
    start = _effects(args, robot)
    data = ident.read_measurements(args.data, robot)
    _check_columns(start, data, args.data, robot)
    known = _core.read_csv_columns(args.tool_targets, ["x", "y", "z"]) if args.tool_targets else None
    t0 = time.perf_counter()
    diag = diagnosis.diagnose(robot, data, folds=args.folds, seed=args.seed, noise_mm=args.noise,
                              progress=lambda s: print(s, file=sys.stderr, flush=True), effects=start,
                              loss=args.loss, loss_scale_mm=args.loss_scale,
                              orientation_weight=args.orientation_weight)
    print("identifying the final model on all the data", file=sys.stderr, flush=True)
    model = diagnosis.final_identification(robot, data, diag, known)
    diag["final_model"]["file"] = "model.json"
    diag["final_model"]["parameters"] = [
        {"effect": e.name, "joint": e.joint or None, "label": e.label,
         "values": [v * sc for v, sc in zip(vals, e.file_scale)], "units": e.file_units}
        for e, vals in model.robot.effects]
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    diagnosis.write_report(robot, data, diag, out, title=f"kincal diagnose: {Path(args.data).name}",
                           model_file="model.json")
    _core.write_file_atomic(str(out / "diagnosis.json"), json.dumps(diagnosis.contract_json(diag), indent=1) + "\n")
    _core.write_file_atomic(str(out / "model.json"), model.model_json())
    for st in diag["steps"]:
        j = f" joint {st['joint']}" if st["joint"] else ""
        print(f"{st['effect']}{j}: cross-validated RMS {st['rms_before_mm'] * 1000:.1f} -> "
              f"{st['rms_after_mm'] * 1000:.1f} um (F = {st['evidence']['F']:.3g})")
    print(f"final cross-validated RMS {diag['final_rms_mm'] * 1000:.1f} um, noise estimate "
          f"{diag['noise_rms_mm'] * 1000:.1f} um: {diag['verdict']} ({time.perf_counter() - t0:.1f} s); "
          f"report: {out / 'report.html'}; model ({' + '.join(['geometry'] + model.effect_labels())}): "
          f"{out / 'model.json'}")


def bench_diagnose(seed: int) -> dict:
    """kincal diagnose on 500 simulated kr500 poses (one reflector; truth: default_truth with a
    hidden backlash on joint 2), every candidate on every joint, 5 folds: seconds."""
    robot = load_robot("kr500")
    data = ident.simulate(ident.default_truth(robot, seed=seed), 500, seed=seed, targets=1,
                          effects=[(_core.Effect("backlash", 2), [math.radians(0.01)])])
    t0 = time.perf_counter()
    d = diagnosis.diagnose(robot, data)
    return {"diagnose_500_poses_s": time.perf_counter() - t0, "diagnose_500_poses_steps": len(d["steps"])}


def cmd_bench(args) -> None:
    t0 = time.perf_counter()
    r = _core.run_benchmarks(args.poses, args.seed, args.threads)
    if not args.no_identify:
        r.update(bench_identify(args.identify_poses, args.seed))
    r.update(bench_feed(args.seed))
    if not args.no_identify:
        r.update(bench_diagnose(args.seed))
    r["bench_seconds"] = time.perf_counter() - t0
    print(json.dumps({k: (round(v, 4) if isinstance(v, float) else v) for k, v in r.items()}))


def cmd_demo(args) -> None:
    from . import demo

    def say(i: int, n: int, what: str) -> None:
        print(f"[{i}/{n}] {what}", file=sys.stderr, flush=True)

    out = Path(args.out)
    summary = demo.run(out, say)
    print(f"identification: held-out RMS {summary['identification']['held_out_rms_before_mm']:.3f} -> "
          f"{summary['identification']['held_out_rms_after_mm']:.3f} mm; diagnosis named "
          + ", ".join(f"{d['effect']}" + (f" (joint {d['joint']})" if d["joint"] else "") for d in summary["diagnosis"])
          + f"; the line on the true robot: uncompensated {summary['position_error_uncompensated_mm']['mean']:.3f} mm, "
          f"compensated on the identified model {summary['position_error_compensated_mm']['mean']:.3f} mm, on the "
          f"diagnosed model {summary['position_error_compensated_diagnosed_mm']['mean']:.4f} mm (mean); feed violations "
          f"{summary['feed_violations']}; five-bar {summary['fivebar_max_error_mm']['fit_and_matrix'] * 1000:.1f} um "
          f"after fit + matrix ({summary['seconds']:.0f} s)", file=sys.stderr)
    print(f"report: {out / 'report.html'}", file=sys.stderr)


def build_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog="kincal", description="Calibration and compensation of industrial robots")
    sub = p.add_subparsers(dest="command", required=True)

    def robot_opts(sp):
        sp.add_argument("--robot", required=True, help="built-in name (kr500), URDF file or model JSON")
        sp.add_argument("--base", help="URDF: base link of the chain (default: the root link)")
        sp.add_argument("--tip", help="URDF: tip link of the chain (default: the only leaf)")

    def effect_opts(sp, default: str, what: str):
        names = ", ".join(k.name for k in _core.effect_kinds() if k.domain == "serial")
        sp.add_argument("--effects", default=default,
                        help=f"{what}, comma separated: NAME (every joint where it applies) or NAME:J (joint J); "
                             f"'none' for the geometry alone (default: {default}; known: {names})")
        sp.add_argument("--harmonics", type=_harmonics, default=list(ident.DEFAULT_HARMONICS), metavar="K1,K2",
                        help="harmonic orders of transmission_error (default 1,2)")

    def loss_opts(sp):
        sp.add_argument("--loss", choices=["huber", "cauchy", "none"], default="huber", help="robust loss")
        sp.add_argument("--loss-scale", type=float, default=0.1, help="where the robust loss bends (mm)")

    def model_opts(sp):
        sp.add_argument("--tool-targets", metavar="CSV",
                        help="x,y,z of every target in the tool frame (designed or measured on a CMM, in target "
                             "order): places the tool frame (TCP), which reflectors alone cannot")
        sp.add_argument("--orientation-weight", type=float, default=100.0, metavar="MM_PER_RAD",
                        help="with measured orientations (a,b,c): mm of position residual worth one rad (default "
                             "100: 0.02 mm against 0.011 deg of noise)")

    sp = sub.add_parser("fk", help="forward kinematics of a joint program")
    robot_opts(sp)
    sp.add_argument("--joints", required=True, help="CSV q1..qN (or a G-code joint program)")
    sp.add_argument("--out", required=True, help="CSV x,y,z,a,b,c")
    sp.add_argument("--frame", choices=["base", "instrument"], default="base")
    sp.add_argument("--temperature", type=float, help="thermal expansion: the temperature (C), instead of a "
                                                       "temperature_c column")
    sp.set_defaults(func=cmd_fk)

    sp = sub.add_parser("ik", help="nominal closed-form inverse kinematics of a pose program")
    robot_opts(sp)
    sp.add_argument("--poses", required=True, help="CSV x,y,z,a,b,c (or G-code X Y Z A B C)")
    sp.add_argument("--out", required=True, help="CSV q1..qN")
    sp.add_argument("--all", action="store_true", help="every solution, with row, solution, within_limits")
    sp.set_defaults(func=cmd_ik)

    sp = sub.add_parser("compensate", help="Newton compensation of a pose program into a joint program")
    sp.add_argument("--model", required=True, help="built-in name, URDF file or model JSON")
    sp.add_argument("--program", required=True, help="pose program: CSV x,y,z,a,b,c or G-code X Y Z A B C")
    sp.add_argument("--out", required=True, help="joint program: .csv (q1..q6) or G-code (A1=..)")
    sp.add_argument("--frame", choices=["base", "instrument"], default="base")
    sp.add_argument("--finite-difference", action="store_true", help="the paper's finite-difference Jacobian")
    sp.add_argument("--paper-start", action="store_true", help="start Newton from the nominal IK (no correction)")
    sp.add_argument("--nominal", action="store_true", help="nominal IK only: the uncompensated program")
    sp.add_argument("--delta", type=float, default=1e-8, help="finite-difference step, degrees (eq. 7)")
    sp.add_argument("--epsilon", type=float, default=1e-15, help="stop when |F|^2 < epsilon (eq. 9)")
    sp.add_argument("--max-iterations", type=int, default=20)
    sp.add_argument("--residual", choices=["rotation_vector", "abc"], default="rotation_vector",
                    help="Newton's orientation residual: the rotation vector (no singularity) or the paper's ABC "
                         "differences (eq. 6, singular at B = +-90)")
    sp.add_argument("--temperature", type=float, help="thermal expansion: the temperature (C) of every pose, unless "
                                                       "the CSV program has a temperature_c column")
    sp.add_argument("--initial-direction", help="backlash: each joint's direction into the first pose, +1 or -1 "
                                                "(one for all, or s1,..,s6; default: the direction of the first motion)")
    sp.add_argument("--keep-branch", action="store_true",
                    help="a branch change inside the program (to stay within the joint limits) is an error")
    sp.set_defaults(func=cmd_compensate)

    sp = sub.add_parser("simulate", help="a simulated measurement campaign on a true model")
    robot_opts(sp)
    sp.add_argument("--truth", help="model JSON of the true robot (default: realistic errors drawn with --seed: "
                                    "1 mm, 0.05 deg, joint compliance about 0.003 deg/kNm)")
    sp.add_argument("--truth-out", help="write the drawn true model here (when --truth is not given)")
    sp.add_argument("--poses", type=int, required=True, help="number of robot configurations")
    sp.add_argument("--out", required=True, help="measurement CSV")
    sp.add_argument("--targets", type=int, default=3, help="reflectors on the tool (1..4)")
    sp.add_argument("--noise", type=float, default=0.02, help="instrument noise per coordinate (mm)")
    sp.add_argument("--outliers", type=float, default=0.0, help="share of points with a gross error")
    sp.add_argument("--outlier-mm", type=float, default=5.0, help="size of a gross error (mm)")
    sp.add_argument("--orientation-noise", type=float, default=None, metavar="DEG",
                    help="measure the tool frame's orientation too (a 6-D probe), with this noise (deg)")
    sp.add_argument("--select", choices=["random", "observability"], default="random",
                    help="poses drawn at random inside the limits, or the most observable of 10 times as many")
    sp.add_argument("--hide", action="append", default=[], metavar="NAME:JOINT:VALUES",
                    help="an effect in the truth: transmission_error:J:s1,c1,s2,c2 (deg; a sine and a cosine "
                         "amplitude per order of --harmonics), backlash:J:b (deg per direction sign), "
                         "thermal_expansion:0:alpha (1/C, about 20 C); repeatable")
    sp.add_argument("--harmonics", type=_harmonics, default=list(ident.DEFAULT_HARMONICS), metavar="K1,K2",
                    help="harmonic orders of a hidden transmission_error (default 1,2)")
    sp.add_argument("--seed", type=int, default=1)
    sp.set_defaults(func=cmd_simulate)

    sp = sub.add_parser("identify", help="parameter identification from measurements")
    robot_opts(sp)
    sp.add_argument("--data", required=True, help="measurement CSV (pose, q1..qN, x, y, z[, target, payload_kg])")
    sp.add_argument("--out", required=True, help="model JSON")
    effect_opts(sp, "joint_compliance", "non-geometric effects to identify")
    loss_opts(sp)
    sp.add_argument("--holdout", type=float, default=0.25, help="share of poses held out for validation")
    sp.add_argument("--folds", type=int, default=0, help="k-fold cross-validation instead of a split (k >= 2)")
    sp.add_argument("--seed", type=int, default=0, help="seed of the validation split")
    sp.add_argument("--urdf", help="also write the calibrated geometry as a URDF")
    model_opts(sp)
    sp.set_defaults(func=cmd_identify)

    sp = sub.add_parser("feed", help="derivative analysis of joint programs (Samak section III)")
    robot_opts(sp)
    sp.add_argument("--program", required=True, help="joint program (CSV q1..qN or G-code A1=..)")
    sp.add_argument("--compare", help="a second joint program drawn beside it (e.g. the uncompensated one)")
    sp.add_argument("--limits", help="CSV axis,v_max,a_max,j_max (deg/s, deg/s^2, deg/s^3) overriding the robot's")
    sp.add_argument("--feed", type=float, default=feedmod.DEFAULT_FEED,
                    help="commanded rate of total axis displacement s (rad/s) against which violations are found")
    sp.add_argument("--method", choices=list(feedmod.METHODS), default="spline",
                    help="resampling: quintic spline (default) or the paper's linear interpolation")
    sp.add_argument("--samples", type=int, default=feedmod.DEFAULT_SAMPLES, help="resampled points along s")
    sp.add_argument("--window", type=_pair, help="S0,S1: the s range of the figures' left column (rad; default all)")
    sp.add_argument("--zoom", type=_pair, help="S0,S1: the s range of the right column (default 1.5%% around the middle)")
    sp.add_argument("--out", required=True, help="folder for feed.json and the figures")
    sp.set_defaults(func=cmd_feed)

    sp = sub.add_parser("diagnose", help="find the effect a model misses, add it, show the gap shrink")
    robot_opts(sp)
    sp.add_argument("--data", required=True, help="measurement CSV (with dir1..dirN, temperature_c when present); "
                                                  "with --robot fivebar a table with the columns of Table I")
    sp.add_argument("--out", required=True, help="folder for diagnosis.json, report.html, figures and model.json "
                                                 "(the final model, for compensate)")
    sp.add_argument("--folds", type=int, default=5, help="folds of poses for the cross-validation")
    sp.add_argument("--seed", type=int, default=0, help="seed of the folds")
    sp.add_argument("--noise", type=float, help="the instrument's noise per coordinate (mm), when known")
    effect_opts(sp, "none", "the model the diagnosis starts from besides the geometry (these are no candidates)")
    loss_opts(sp)
    model_opts(sp)
    sp.set_defaults(func=cmd_diagnose)

    hr = sub.add_parser("hidden-robot", help="five-bar hidden-robot calibration (the Kiper paper)")
    hsub = hr.add_subparsers(dest="hr_command", required=True)
    sp = hsub.add_parser("fit", help="link lengths of the hidden robot from measured points")
    sp.add_argument("--data", required=True, help="CSV with the columns of data/fivebar-table1.csv")
    sp.add_argument("--method", choices=list(fivebar.METHODS), default="lsq")
    sp.add_argument("--score", choices=["measured", "desired"], default="measured",
                    help="rank by the distance to the measured (default) or, as the paper, the desired position")
    sp.add_argument("--out", required=True, help="FIT.json")
    sp.set_defaults(func=cmd_hr_fit)
    sp = hsub.add_parser("matrix", help="the error-correction matrix from measured grid points")
    sp.add_argument("--fit", required=True, help="FIT.json of the model that commanded the grid")
    sp.add_argument("--data", required=True, help="GRID.csv (the columns of data/fivebar-table1.csv)")
    sp.add_argument("--out", required=True, help="MATRIX.json")
    sp.set_defaults(func=cmd_hr_matrix)
    sp = hsub.add_parser("command", help="joint commands for desired points")
    sp.add_argument("--fit", required=True, help="FIT.json")
    sp.add_argument("--matrix", help="MATRIX.json")
    sp.add_argument("--targets", required=True, help="CSV with x,y (mm)")
    sp.add_argument("--out", required=True, help="CSV theta1_deg,theta2_deg")
    sp.set_defaults(func=cmd_hr_command)
    sp = hsub.add_parser("simulate", help="measure points on the simulated over-constrained 6-bar")
    sp.add_argument("--fit", help="FIT.json commanding the mechanism (default: nominal 150 mm links)")
    sp.add_argument("--matrix", help="MATRIX.json applied to the commands")
    sp.add_argument("--targets", help="CSV with x,y (default: the 5 mm grid over the paper's workspace)")
    sp.add_argument("--grid", type=float, default=5.0, help="grid spacing (mm) when no --targets")
    sp.add_argument("--noise", type=float, default=0.001, help="instrument noise (mm; 0.020 FARO, 0.001 Renishaw)")
    sp.add_argument("--seed", type=int, default=1, help="the truth's manufacturing errors and the noise")
    sp.add_argument("--out", required=True, help="CSV with the columns of data/fivebar-table1.csv")
    sp.set_defaults(func=cmd_hr_simulate)

    sp = sub.add_parser("bench", help="benchmarks: our code and KDL's solvers in one run, JSON on stdout")
    sp.add_argument("--poses", type=int, default=2000)
    sp.add_argument("--seed", type=int, default=1)
    sp.add_argument("--threads", type=int, default=0, help="batch threads (default: all cores)")
    sp.add_argument("--identify-poses", type=int, default=1000, help="poses of the identification benchmark")
    sp.add_argument("--no-identify", action="store_true", help="skip the identification benchmark")
    sp.set_defaults(func=cmd_bench)

    sp = sub.add_parser("demo", help="the whole pipeline on the built-in example")
    sp.add_argument("--out", default="kincal-demo", help="output folder")
    sp.set_defaults(func=cmd_demo)
    return p


def main(argv: Optional[Sequence[str]] = None) -> int:
    args = build_parser().parse_args(argv)
    try:
        args.func(args)
    except (ValueError, OSError) as e:
        print(f"kincal {args.command}: error: {e}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
