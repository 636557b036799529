"""`kincal simulate`, `identify`, `validate` and `diagnose`: simulated campaigns, identification, its
check on new measurements and the diagnosis of what a model misses (kincal.calibration,
kincal.diagnose). Parsing and calling only."""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

import numpy as np

from .. import _core, diagnose as diagnosis, fivebar, load_robot
from ..calibration import identify as ident
from ..io import strict_json
from ..programs.kinematics_files import carried_targets
from ..io.urdf import spec_urdf, urdf_left_out
from .. import report
from ..calibration import simulation as sim
from .options import (artifact_opt, artifact_out, effect_opts, effects_arg, fit_options, fit_opts, harmonics_option,
                      loss_opts, probe_offset, probe_opts, probe_start, progress, robot_of, robot_opts, say, step_progress,
                      tool_targets)



def _simulate_probe(args: argparse.Namespace, robot: _core.Robot, truth: _core.Robot) -> None:
    """simulate --kind: a probe campaign and its artifact file."""
    probe = probe_offset(args)
    data = sim.simulate_probe(truth, args.kind, stations=args.stations, touches=args.touches, cone_deg=args.cone,
                              probe=probe, radius_mm=args.radius, length_mm=args.length, block_mm=args.block,
                              noise_mm=0.005 if args.noise is None else args.noise, seed=args.seed)
    data = data.with_columns(q_deg=_core.joints_to_controller(robot, data.q_deg))  # the controller's numbers
    art = artifact_out(args)
    text = ident.measurements_csv(data, robot.dof)
    artifact = _core.format_artifact(data, robot.dof) if data.artifact is not None else None
    _core.write_file_atomic(args.out, text)
    if artifact:
        _core.write_file_atomic(art, artifact)
    if args.truth_out and not args.truth:  # the truth drawn, once the campaign on it was made
        _core.write_file_atomic(args.truth_out, truth.to_json())
    print(f"wrote {len(data)} {args.kind} rows at {len(data.station_names or [])} stations to {args.out}"
          + (f", their known distances and angles to {art}" if artifact else ""), file=sys.stderr)


def cmd_simulate(args: argparse.Namespace) -> None:
    robot = robot_of(args)
    if args.truth:
        truth = load_robot(args.truth)
        if truth.dof != robot.dof:
            raise ValueError(f"{args.truth}: {truth.dof} joints but {args.robot} has {robot.dof}")
    else:
        truth = ident.default_truth(robot, seed=args.seed)
    if args.kind:
        _simulate_probe(args, robot, truth)
        return
    if args.poses is None:
        raise ValueError("--poses: the number of configurations to measure (or --kind for a probe campaign)")
    if args.noise is None:
        args.noise = 0.02
    pool = args.poses * (10 if args.select == "observability" else 1)
    hidden = [ident.parse_hidden_effect(h, robot.dof, args.harmonics) for h in args.hide]
    data = ident.simulate(truth, pool, seed=args.seed, noise_mm=args.noise, targets=args.targets,
                          outlier_fraction=args.outliers, outlier_mm=args.outlier_mm, effects=hidden,
                          orientation_noise_deg=args.orientation_noise, duration_h=args.duration)
    if args.truth_out and not args.truth:  # the truth as measured: its hidden effects too (not the
        # instrument's drift, a property of the measurement that no robot model carries)
        acting = [e for e in hidden if not e[0].kind.of_instrument]
        _core.write_file_atomic(args.truth_out, (truth.with_effects(acting, 20.0) if acting else truth).to_json())
    if args.select == "observability":
        from ..calibration import plan
        data = plan.select_observable(robot, data, args.poses)
    data = data.with_columns(q_deg=_core.joints_to_controller(robot, data.q_deg))  # the controller's numbers
    _core.write_file_atomic(args.out, ident.measurements_csv(data, robot.dof))
    print(f"wrote {len(data)} measured points of {args.poses} poses to {args.out}", file=sys.stderr)


def cmd_identify(args: argparse.Namespace) -> None:
    robot = robot_of(args)
    data = ident.read_measurements(args.data, robot, args.artifact)
    effects = effects_arg(args, robot, data)
    if args.holdout is not None and args.folds is not None:
        raise ValueError("--holdout and --folds: give one (a split, or cross-validation)")
    known = tool_targets(args.tool_targets, data, args.data)
    fit = fit_options(args, robot)
    res = ident.identify(robot, data, effects=effects, fit=fit, harmonics=args.harmonics,
                         holdout=args.holdout, k_folds=5 if args.folds is None else args.folds, seed=args.seed,
                         progress=progress("identify"),
                         fold_progress=step_progress("cross-validation, fold"),
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


def cmd_validate(args: argparse.Namespace) -> None:
    robot = load_robot(args.model)
    data = ident.read_measurements(args.data, robot, args.artifact)
    # the targets start where the model's campaign put them, when it had as many (a depth these rows do
    # not see, a reflector's along the axis every orientation shares, is then held there, not at the flange)
    start = probe_start(args)
    carried = carried_targets(args.model)
    n_targets = int(np.max(data.target)) + 1 if len(data.target) else 0
    from_model = start is None and carried is not None and len(carried) == n_targets
    v = ident.validate(robot, data, loss=args.loss, loss_scale_mm=args.loss_scale,
                       target_start=carried.tolist() if from_model and carried is not None else start)
    v["model"] = str(args.model)
    if from_model:
        v["refitted"] += "; the target offsets started from the model's"
    _core.write_file_atomic(args.out, strict_json.dumps(v, indent=1, sort_keys=True) + "\n")
    print(ident.validation_summary(v))


def _diagnose_fivebar(args: argparse.Namespace) -> None:
    pts = fivebar.read_table(args.data)
    report.check_folder(args.out)
    diag = fivebar.diagnose(pts, folds=args.folds, seed=args.seed, noise_mm=args.noise, say=say)
    fivebar.write_diagnosis(pts, diag, args.out, title=f"kincal diagnose: {Path(args.data).name} (five-bar hidden robot)")
    print(fivebar.diagnosis_summary(diag))


def cmd_diagnose(args: argparse.Namespace) -> None:
    if args.robot == "fivebar":
        _diagnose_fivebar(args)
        return
    robot = robot_of(args)
    data = ident.read_measurements(args.data, robot, args.artifact)
    start = effects_arg(args, robot, data)
    if start == "auto":
        raise ValueError("--effects auto: the diagnosis chooses its effects itself; --effects gives the model it "
                         "starts from (default: the geometry alone)")
    known = tool_targets(args.tool_targets, data, args.data)
    fit = fit_options(args, robot)
    t0 = time.perf_counter()
    diag, model = diagnosis.run(robot, data, args.out, title=f"kincal diagnose: {Path(args.data).name}",
                                tool_targets=known, progress=say, folds=args.folds, seed=args.seed,
                                noise_mm=args.noise, effects=start, fit=fit)
    print(diagnosis.summary(diag, model, args.out, time.perf_counter() - t0))


def add_commands(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """simulate, identify and validate on the command line's subparsers ``sub``."""
    sp = sub.add_parser("simulate", help="a simulated measurement campaign on a true model")
    robot_opts(sp)
    sp.add_argument("--truth", help="model JSON of the true robot (default: realistic errors drawn with --seed: "
                                    "1 mm, 0.05 deg, joint compliance about 0.003 deg/kNm)")
    sp.add_argument("--truth-out", help="write the drawn true model here (when --truth is not given)")
    sp.add_argument("--poses", type=int, help="number of robot configurations (a tracker campaign)")
    sp.add_argument("--out", required=True, help="measurement CSV")
    sp.add_argument("--targets", type=int, default=3, help="reflectors on the tool (1..4)")
    sp.add_argument("--noise", type=float, default=None,
                    help="instrument noise per coordinate (mm; default 0.02), or along a probe's constraint (0.005)")
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
    harmonics_option(sp, "a hidden transmission_error")
    sp.add_argument("--seed", type=int, default=1)
    probe_opts(sp, "a probe campaign (no tracker)")
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
    artifact_opt(sp)
    sp.set_defaults(func=cmd_identify)

    sp = sub.add_parser("validate", help="check a calibration on new measurements (placements and targets refitted)")
    sp.add_argument("--model", required=True, help="model JSON (kincal identify or diagnose), or any --robot")
    sp.add_argument("--data", required=True, help="measurement CSV of the new campaign (a setup column: one "
                                                  "placement per setup)")
    sp.add_argument("--out", required=True, help="V.json: points, rms_mm, mean_mm, max_mm, before_rms_mm, ...")
    loss_opts(sp)
    artifact_opt(sp)
    sp.set_defaults(func=cmd_validate)


def add_diagnose(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """diagnose on the command line's subparsers ``sub``."""
    sp = sub.add_parser("diagnose", help="find the effect a model misses, add it, show the gap shrink")
    robot_opts(sp)
    sp.add_argument("--data", required=True, help="measurement CSV (with dir1..dirN, temperature_c when present); "
                                                  "with --robot fivebar a table with the columns of Table I")
    sp.add_argument("--out", required=True, help="folder for diagnosis.json, report.html, figures and model.json "
                                                 "(the final model, for compensate)")
    sp.add_argument("--folds", type=int, default=5, help="folds of the cross-validation (whole configurations per fold)")
    sp.add_argument("--seed", type=int, default=0, help="seed of the folds")
    sp.add_argument("--noise", type=float, help="the instrument's noise per coordinate (mm), when known: the "
                    "diagnosis stops when what remains is at it (the fits estimate theirs from the residuals)")
    effect_opts(sp, "none", "the model the diagnosis starts from besides the geometry (these are no candidates)")
    fit_opts(sp, noise=False)
    artifact_opt(sp)
    sp.set_defaults(func=cmd_diagnose)
