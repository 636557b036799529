"""The `kincal` command: argument parsing, one function per subcommand that calls the package (see
../README.md for the contract)."""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path
from typing import Optional, Sequence

import numpy as np

from . import _core, load_robot
from . import cli_campaign as campaign
from . import cli_fivebar as hidden
from . import cli_programs as programs
from . import diagnose as diagnosis
from . import feed as feedmod
from . import fivebar, priors, report
from . import identify as ident
from . import strict_json
from .blas_threads import one_blas_thread
from .fitting import DEFAULT_LOSS_SCALE_MM, FitOptions, masses
from .kinematics_files import fk_file, ik_file
from .setups import robot_for_setup
from .urdf import spec_urdf, urdf_left_out


def _robot(args) -> _core.Robot:
    return load_robot(args.robot, getattr(args, "base", None), getattr(args, "tip", None),
                      getattr(args, "joint_convention", None))


def cmd_fk(args) -> None:
    robot = _robot(args)
    if args.setup is not None:
        if args.frame != "instrument":
            raise ValueError("--setup NAME chooses an instrument placement: it needs --frame instrument")
        robot = robot_for_setup(robot, args.setup, args.robot)
    fk_file(robot, args.robot, args.joints, args.out, args.frame, args.temperature)


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


def cmd_ik(args) -> None:
    ik_file(_robot(args), args.robot, args.poses, args.out, args.all)


def _comp_kwargs(args) -> dict:
    return dict(compensate=not args.nominal, instrument=args.frame == "instrument",
                finite_difference=args.finite_difference, delta=args.delta, epsilon=args.epsilon,
                max_iterations=args.max_iterations, corrected_start=not args.paper_start, residual=args.residual,
                temperature_c=args.temperature, initial_direction=_directions(args.initial_direction),
                keep_branch=args.keep_branch)


def cmd_compensate(args) -> None:
    robot = load_robot(args.model, joint_convention=args.joint_convention)
    if args.frame == "instrument" and not robot.identified:
        raise ValueError(f"{args.model}: --frame instrument needs an identified model (kincal identify)")
    if len(args.program) > 1 or Path(args.program[0]).is_dir():
        programs.compensate_backup(robot, args, _comp_kwargs(args))
        return
    res = programs.compensate(robot, args, _comp_kwargs(args))
    for w in res["warnings"]:
        print(f"kincal compensate: warning: {w}", file=sys.stderr)
    it = np.asarray(res["iterations"])
    written = ", ".join(res.get("files") or [str(args.out)])  # a KRL program is its .src and .dat
    print(f"{written}: {len(it)} poses compensated, iterations {it.min()}..{it.max()} "
          f"(mean {it.mean():.2f}), largest residual |F| {max(res['residual']):.3g}", file=sys.stderr)
    for line in programs.summary(res):
        print(f"{written}: {line}", file=sys.stderr)


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


def cmd_simulate(args) -> None:
    robot = _robot(args)
    if args.truth:
        truth = load_robot(args.truth)
        if truth.dof != robot.dof:
            raise ValueError(f"{args.truth}: {truth.dof} joints but {args.robot} has {robot.dof}")
    else:
        truth = ident.default_truth(robot, seed=args.seed)
    pool = args.poses * (10 if args.select == "observability" else 1)
    hidden = [ident.parse_hidden_effect(h, robot.dof, args.harmonics) for h in args.hide]
    data = ident.simulate(truth, pool, seed=args.seed, noise_mm=args.noise, targets=args.targets,
                          outlier_fraction=args.outliers, outlier_mm=args.outlier_mm, effects=hidden,
                          orientation_noise_deg=args.orientation_noise, duration_h=args.duration)
    if args.truth_out and not args.truth:  # the truth as measured: its hidden effects too (not the
        # instrument's drift, a property of the measurement that no robot model carries)
        acting = [e for e in hidden if e[0].name != "drift"]
        _core.write_file_atomic(args.truth_out, (truth.with_effects(acting, 20.0) if acting else truth).to_json())
    if args.select == "observability":
        from . import plan
        data = plan.select_observable(robot, data, args.poses)
    data = dict(data, q_deg=_core.joints_to_controller(robot, data["q_deg"]))  # the controller's numbers
    _core.write_file_atomic(args.out, ident.measurements_csv(data, robot.dof))
    print(f"wrote {len(data['pose'])} measured points of {args.poses} poses to {args.out}", file=sys.stderr)


def _tool_targets(path: Optional[str], data: dict, data_path: str) -> Optional[np.ndarray]:
    """--tool-targets: x,y,z of each target of the measurements in the tool frame, one row each
    (checked before any fit: an error names the file and both counts)."""
    if not path:
        return None
    known = _core.read_csv_columns(path, ["x", "y", "z"])
    n = int(np.max(data["target"])) + 1
    if len(known) != n:
        raise ValueError(f"{path}: {len(known)} rows, but {data_path} measures {n} target(s) (one row of x,y,z per "
                         "target in the tool frame, in target order)")
    return known


def _fit_options(args, robot: _core.Robot) -> FitOptions:
    """The fitting options of identify and diagnose (one group of options, one default each)."""
    prior_model = load_robot(args.prior_model) if args.prior_model else None
    if prior_model is not None and prior_model.dof != robot.dof:
        raise ValueError(f"{args.prior_model}: {prior_model.dof} joints but the robot has {robot.dof}")
    if args.gravity == "masses" and not masses(robot):
        raise ValueError(f"--gravity masses: the model {args.robot} has no link masses (no inertial data); use "
                         "--gravity fit (or auto)")
    return FitOptions(loss=args.loss, loss_scale_mm=args.loss_scale or None,
                      prior_sd=priors.parse_prior_sd(args.prior_sd), prior_model=prior_model,
                      prior_scale=priors.parse_prior_scale(args.prior_scale), gravity=args.gravity,
                      orientation_weight=args.orientation_weight, max_iterations=args.max_iterations)


def _effects_arg(args, robot: _core.Robot, data: dict):
    """--effects: "auto" (identify's default) or a list (checked against the data's columns)."""
    if args.effects.strip() == "auto":
        return "auto"
    effects = ident.parse_effects(args.effects, robot, args.harmonics)
    ident.check_data_for(effects, dict(data, source=args.data), robot)
    return effects


def cmd_identify(args) -> None:
    robot = _robot(args)
    data = ident.read_measurements(args.data, robot)
    effects = _effects_arg(args, robot, data)
    if args.holdout is not None and args.folds is not None:
        raise ValueError("--holdout and --folds: give one (a split, or cross-validation)")
    known = _tool_targets(args.tool_targets, data, args.data)
    fit = _fit_options(args, robot)
    res = ident.identify(robot, data, effects=effects, fit=fit, harmonics=args.harmonics,
                         holdout=args.holdout, k_folds=5 if args.folds is None else args.folds, seed=args.seed,
                         progress=_progress("identify"),
                         fold_progress=campaign._step_progress("cross-validation, fold"),
                         hold_out_setups=args.hold_out_setups)
    if sys.stderr.isatty():
        print(file=sys.stderr)
    if known is not None:
        res = ident.tool_from_targets(res, known)
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


def cmd_validate(args) -> None:
    robot = load_robot(args.model)
    data = ident.read_measurements(args.data, robot)
    v = ident.validate(robot, data, loss=args.loss, loss_scale_mm=args.loss_scale)
    v["model"] = str(args.model)
    _core.write_file_atomic(args.out, strict_json.dumps(v, indent=1, sort_keys=True) + "\n")
    print(ident.validation_summary(v))


def _pair(text: str) -> tuple:
    try:
        a, b = (float(x) for x in text.split(","))
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected two numbers S0,S1, not '{text}'") from None
    if not a < b:
        raise argparse.ArgumentTypeError(f"S0 must be below S1 in '{text}'")
    return a, b


def cmd_feed(args) -> None:
    programs = {"program": args.program}
    if args.compare:
        programs["compare"] = args.compare
    results = feedmod.analyse_files(_robot(args), args.robot, programs, args.out, limits_path=args.limits,
                                    feed=args.feed, samples=args.samples, method=args.method, window=args.window,
                                    zoom=args.zoom)
    print(feedmod.summary(results, args.feed))


def _say(text: str) -> None:
    print(text, file=sys.stderr, flush=True)


def _diagnose_fivebar(args) -> None:
    pts = fivebar.read_table(args.data)
    report.check_folder(args.out)
    diag = fivebar.diagnose(pts, folds=args.folds, seed=args.seed, noise_mm=args.noise, say=_say)
    fivebar.write_diagnosis(pts, diag, args.out, title=f"kincal diagnose: {Path(args.data).name} (five-bar hidden robot)")
    print(fivebar.diagnosis_summary(diag))


def cmd_diagnose(args) -> None:
    if args.robot == "fivebar":
        _diagnose_fivebar(args)
        return
    robot = _robot(args)
    data = ident.read_measurements(args.data, robot)
    start = _effects_arg(args, robot, data)
    if start == "auto":
        raise ValueError("--effects auto: the diagnosis chooses its effects itself; --effects gives the model it "
                         "starts from (default: the geometry alone)")
    known = _tool_targets(args.tool_targets, data, args.data)
    fit = _fit_options(args, robot)
    t0 = time.perf_counter()
    diag, model = diagnosis.run(robot, data, args.out, title=f"kincal diagnose: {Path(args.data).name}",
                                tool_targets=known, progress=_say, folds=args.folds, seed=args.seed,
                                noise_mm=args.noise, effects=start, fit=fit)
    print(diagnosis.summary(diag, model, args.out, time.perf_counter() - t0))


def cmd_bench(args) -> None:
    import kincal_benchmarks

    r = kincal_benchmarks.run(args.poses, args.seed, args.threads, args.identify_poses, identify=not args.no_identify)
    print(strict_json.dumps({k: (round(v, 4) if isinstance(v, float) else v) for k, v in r.items()}))


def cmd_demo(args) -> None:
    from . import demo

    def say(i: int, n: int, what: str) -> None:
        print(f"[{i}/{n}] {what}", file=sys.stderr, flush=True)

    out = Path(args.out)
    print(demo.summary_text(demo.run(out, say)), file=sys.stderr)
    print(f"report: {out / 'report.html'}", file=sys.stderr)


def build_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog="kincal", description="Calibration and compensation of industrial robots")
    sub = p.add_subparsers(dest="command", required=True)

    def robot_opts(sp):
        sp.add_argument("--robot", required=True, help="built-in name (kr500), URDF file or model JSON")
        sp.add_argument("--base", help="URDF: base link of the chain (default: the root link)")
        sp.add_argument("--tip", help="URDF: tip link of the chain (default: the only leaf)")
        programs.joint_convention_option(sp)

    def effect_opts(sp, default: str, what: str):
        names = ", ".join(k.name for k in _core.effect_kinds() if k.domain == "serial")
        sp.add_argument("--effects", default=default,
                        help=f"{what}, comma separated: NAME (every joint where it applies) or NAME:J (joint J); "
                             f"joint_map:J:K a joint_map of order K (default {ident.DEFAULT_MAP_ORDER}); "
                             f"'none' for the geometry alone (default: {default}; known: {names})")
        sp.add_argument("--harmonics", type=_harmonics, default=list(ident.DEFAULT_HARMONICS), metavar="K1,K2",
                        help="harmonic orders of transmission_error (default 1,2)")

    def loss_opts(sp, scale=0.1, why=""):
        sp.add_argument("--loss", choices=["huber", "cauchy", "none"], default="huber", help="robust loss")
        sp.add_argument("--loss-scale", type=float, default=scale, help="where the robust loss bends (mm; default "
                        + (f"{scale}{why})" if scale else "from the residuals' robust spread)"))

    def fit_opts(sp):
        """The fitting options of identify and diagnose: one group, one default each (kincal.fitting)."""
        loss_opts(sp, DEFAULT_LOSS_SCALE_MM)
        sp.add_argument("--prior-model", metavar="JSON", help="centre the priors on this model's calibrated "
                        "geometry (e.g. last year's calibration; default: the starting model)")
        sp.add_argument("--prior-sd", metavar="KIND=SD,..", help="prior standard deviations over the defaults "
                        f"({', '.join(f'{k}={v:g}' for k, v in priors.DEFAULT_PRIOR_SD.items())}; also base_mm, "
                        "base_deg, target_mm, an effect's name); 'none': no priors (what the data cannot determine "
                        "is then refused)")
        sp.add_argument("--prior-scale", default="1", help="times every prior sd, or 'auto' (grouped cross-validation)")
        sp.add_argument("--gravity", choices=["auto", "masses", "fit"], default="auto", help="the compliances' "
                        "gravity torques: the model's masses, or mass moments identified (fit); auto: fit when it "
                        "has no masses")
        sp.add_argument("--max-iterations", type=int, default=100, metavar="N",
                        help="the cap of each Levenberg-Marquardt solve (default 100)")
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
    sp.add_argument("--frame", choices=["base", "instrument"], default="base",
                    help="instrument: the identified model's instrument frame (its first setup's placement "
                         "unless --setup)")
    sp.add_argument("--setup", metavar="NAME", help="with --frame instrument: the placement of this setup of a "
                                                    "model identified from several")
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
    sp.add_argument("--program", required=True, nargs="+",
                    help="pose program (CSV x,y,z,a,b,c or G-code X Y Z A B C) or a controller's program (.src with its "
                         ".dat, .mod, .ls, .script); several files or a folder: a controller backup, every program in "
                         "it filtered (--out is then a folder with the same tree)")
    sp.add_argument("--out", required=True, help="the program: .csv (q1..q6), G-code (A1=..), .src (KRL), .mod "
                                                 "(RAPID), .ls (FANUC LS), .script (URScript); a folder for a backup")
    sp.add_argument("--frame", choices=["base", "instrument"], default="base")
    programs.add_options(sp)
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
                         "amplitude per order of --harmonics), joint_map:J:s1,c1,..,sK,cK (deg; orders 1..K), "
                         "backlash:J:b (deg per direction sign), thermal_expansion:0:alpha (1/C, about 20 C), "
                         "drift:0:vx,vy,vz,wx,wy,wz (the instrument's drift: mm/h and deg/h about the campaign's "
                         "mean time; 3 h unless --duration); repeatable")
    sp.add_argument("--duration", type=float, metavar="HOURS",
                    help="a time_s column: the campaign runs from 0 to HOURS in pose order")
    sp.add_argument("--harmonics", type=_harmonics, default=list(ident.DEFAULT_HARMONICS), metavar="K1,K2",
                    help="harmonic orders of a hidden transmission_error (default 1,2)")
    sp.add_argument("--seed", type=int, default=1)
    sp.set_defaults(func=cmd_simulate)

    sp = sub.add_parser("identify", help="parameter identification from measurements")
    robot_opts(sp)
    sp.add_argument("--data", required=True, help="measurement CSV (pose, q1..qN, x, y, z[, target, payload_kg, "
                                                  "time_s, config, setup]; a setup column: one placement each)")
    sp.add_argument("--out", required=True, help="model JSON")
    effect_opts(sp, "auto", "non-geometric effects to identify; 'auto': each library effect that applies is tried "
                "and kept only when it lowers the grouped cross-validated RMS (the diagnosis's rule; chosen again in "
                "each training fold of the validation)")
    fit_opts(sp)
    sp.add_argument("--holdout", type=float, default=None,
                    help="validate on a held-out share of the configurations instead of cross-validation (the "
                         "model then excludes those rows)")
    sp.add_argument("--folds", type=int, default=None,
                    help="k-fold cross-validation of the figures, whole configurations per fold (default 5; 0: "
                         "none); the model is fitted on every row")
    sp.add_argument("--hold-out-setups", action="store_true", help="validate by holding out each setup (instrument "
                    "placement) whole, its placement and targets refitted, instead of folds")
    sp.add_argument("--seed", type=int, default=0, help="seed of the validation split")
    sp.add_argument("--urdf", help="also write the calibrated geometry as a URDF")
    sp.set_defaults(func=cmd_identify)

    sp = sub.add_parser("validate", help="check a calibration on new measurements (placements and targets refitted)")
    sp.add_argument("--model", required=True, help="model JSON (kincal identify or diagnose), or any --robot")
    sp.add_argument("--data", required=True, help="measurement CSV of the new campaign (a setup column: one "
                                                  "placement per setup)")
    sp.add_argument("--out", required=True, help="V.json: points, rms_mm, mean_mm, max_mm, before_rms_mm, ...")
    loss_opts(sp)
    sp.set_defaults(func=cmd_validate)

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
    sp.add_argument("--folds", type=int, default=5, help="folds of the cross-validation (whole configurations per fold)")
    sp.add_argument("--seed", type=int, default=0, help="seed of the folds")
    sp.add_argument("--noise", type=float, help="the instrument's noise per coordinate (mm), when known")
    effect_opts(sp, "none", "the model the diagnosis starts from besides the geometry (these are no candidates)")
    fit_opts(sp)
    sp.set_defaults(func=cmd_diagnose)

    hidden.add_commands(sub)
    campaign.add_commands(sub, robot_opts, effect_opts)

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
        with one_blas_thread():
            args.func(args)
    except (ValueError, OSError) as e:
        print(f"kincal {args.command}: error: {e}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
