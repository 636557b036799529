"""The campaign commands of the command line, before and after identification: `kincal plan` (the
configurations to measure) and `kincal accuracy` (the standard accuracy reports). Parsing and
calling only."""

from __future__ import annotations

import argparse
import math
import sys

from .. import _core
from ..calibration import identify as ident
from ..io.csv_text import format_rows
from .options import artifact_out, effect_opts, probe_offset, probe_opts, robot_of, robot_opts, step_progress



def _numbers(text: str, n: int, option: str) -> list[float]:
    """n comma-separated numbers of an option (a clear error otherwise)."""
    try:
        v = [float(x) for x in text.split(",")]
    except ValueError:
        v = []
    if len(v) != n or not all(math.isfinite(x) for x in v):
        raise ValueError(f"{option} {text}: expected {n} comma-separated numbers")
    return v


def _plan_probe(args: argparse.Namespace, robot: _core.Robot) -> None:
    """plan --kind: the touches at each station, and the artifact of the stations as placed."""
    from ..calibration import probe_plan

    conf = None
    if args.from_:
        conf = _core.read_csv_columns(args.from_, [f"q{j + 1}" for j in range(robot.dof)])
        conf = _core.joints_from_controller(robot, conf)
    noise = 0.005 if args.noise is None else args.noise
    res = probe_plan.plan_probe(robot, args.kind, stations=args.stations, touches=args.touches, cone_deg=args.cone,
                                probe=probe_offset(args), radius_mm=args.radius, length_mm=args.length,
                                block_mm=args.block, effects=ident.parse_effects(args.effects, robot, args.harmonics),
                                noise_mm=noise, candidates=300 if args.candidates is None else args.candidates, configurations=conf,
                                seed=args.seed, progress=step_progress("plan"))
    if sys.stderr.isatty():
        print(file=sys.stderr)
    data = res.data.with_columns(q_deg=_core.joints_to_controller(robot, res.data.q_deg))  # the controller's numbers
    art = artifact_out(args)
    _core.write_file_atomic(args.out, ident.measurements_csv(data, robot.dof))
    _core.write_file_atomic(art, _core.format_artifact(data, robot.dof))
    print(res.summary(noise))
    print(f"wrote {len(data)} touches (the commanded angles on the nominal model: replace each row's angles "
          f"with the controller's reading at the touch) to {args.out}, the stations' distances and angles as "
          f"placed to {art}")


def cmd_plan(args: argparse.Namespace) -> None:
    from ..calibration import plan

    robot = robot_of(args)
    if args.kind:
        ignored = [o for o, v in (("--poses", args.poses), ("--box", args.box), ("--instrument", args.instrument))
                   if v is not None] + (["--min-sigma"] if args.min_sigma else [])
        if ignored:
            raise ValueError(f"{', '.join(ignored)}: tracker campaign options; a probe campaign (--kind) places its "
                             "stations and keeps away from singularities itself")
        _plan_probe(args, robot)
        return
    if args.poses is None:
        raise ValueError("--poses: the number of configurations to measure (or --kind for a probe campaign)")
    if args.noise is None:
        args.noise = 0.02
    if args.targets.strip().isdigit():
        count = int(args.targets)
        if not 1 <= count <= len(ident.DEFAULT_TARGETS):
            raise ValueError(f"--targets {args.targets}: a count must be 1..{len(ident.DEFAULT_TARGETS)} (or give a "
                             "CSV of offsets x,y,z)")
        targets = ident.DEFAULT_TARGETS[:count]
    else:
        targets = _core.read_csv_columns(args.targets, ["x", "y", "z"])
    cand = None
    if args.from_:
        cand = _core.read_csv_columns(args.from_, [f"q{j + 1}" for j in range(robot.dof)])
    rules = plan.KeepOut(min_sigma=args.min_sigma,
                         box=_numbers(args.box, 6, "--box") if args.box else None,
                         instrument=_numbers(args.instrument, 3, "--instrument") if args.instrument else None,
                         max_range=args.range, max_incidence_deg=args.max_incidence)
    res = plan.plan(robot, args.poses, targets=targets, effects=ident.parse_effects(args.effects, robot, args.harmonics),
                    candidates=cand,
                    n_candidates=5000 if args.candidates is None else args.candidates, rules=rules, noise_mm=args.noise, seed=args.seed,
                    progress=step_progress("plan"))
    if sys.stderr.isatty():
        print(file=sys.stderr)
    _core.write_file_atomic(args.out, format_rows([f"q{j + 1}" for j in range(robot.dof)], res.q_deg.tolist()))
    print(res.summary(args.noise))
    print(f"wrote {len(res.q_deg)} configurations, in a short path order, to {args.out}")


def cmd_accuracy_iso9283(args: argparse.Namespace) -> None:
    from ..standards import report as rep

    res = rep.run_iso9283(args.data, args.out, distance=args.distance, model=args.model, frame=args.frame,
                          label=args.label)
    print(rep.iso9283_summary(res, args.out))


def cmd_accuracy_plan(args: argparse.Namespace) -> None:
    from ..standards import iso9283_plan as iso

    print(iso.write_plan(robot_of(args), args.out, cube=args.cube, orientation=args.orientation, z_min=args.z_min,
                         cycles=args.cycles))


def cmd_accuracy_axis(args: argparse.Namespace) -> None:
    from ..standards import report as rep

    print(rep.axis_summary(rep.run_axis(args.data, args.out, args.unit, label=args.label), args.out))



def add_commands(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """The plan and accuracy subcommands on the command line's subparsers ``sub``."""
    sp = sub.add_parser("plan", help="the configurations to measure that determine the model best (D-optimal)")
    robot_opts(sp)
    sp.add_argument("--poses", type=int, help="number of configurations K (a tracker campaign)")
    sp.add_argument("--out", required=True, help="CSV q1..qN, in a short path order (with --kind: the touches, "
                    "a measurement CSV to fill with the controller's readings)")
    sp.add_argument("--targets", default="1", help="the reflectors: a CSV of offsets x,y,z on the tool (mm), or "
                    "their count (kincal simulate's offsets; default 1)")
    sp.add_argument("--from", dest="from_", metavar="CANDIDATES.csv", help="candidate configurations (q1..qN); "
                    "default: random ones inside the joint limits. With --kind: the configurations over which "
                    "the TCP uncertainty is predicted (default: 200 random ones 10%% inside the limits)")
    sp.add_argument("--candidates", type=int, default=None, help="number of random candidates (default 5000; with "
                    "--kind: candidate touches per station, default 300)")
    effect_opts(sp, "joint_compliance", "effects the campaign must identify")
    sp.add_argument("--noise", type=float, default=None, help="the instrument's noise per coordinate (mm; default "
                    "0.02), or the probe's along its constraint (default 0.005), for the predicted uncertainties")
    sp.add_argument("--min-sigma", type=float, default=0.0, help="keep out of singularities: the tool Jacobian's "
                    "smallest singular value at least this share of its largest (angular rows times the reach)")
    sp.add_argument("--box", metavar="XMIN,XMAX,YMIN,YMAX,ZMIN,ZMAX", help="the TCP stays in this box (mm, base)")
    sp.add_argument("--instrument", metavar="X,Y,Z", help="the instrument's position (mm, base frame)")
    sp.add_argument("--range", type=float, default=math.inf, help="with --instrument: its range (mm)")
    sp.add_argument("--max-incidence", type=float, default=180.0, help="with --instrument: the largest angle "
                    "(deg) between a reflector's normal (the tool's z axis) and the line to the instrument")
    sp.add_argument("--seed", type=int, default=0)
    probe_opts(sp, "a probe campaign (no tracker): the orientations at each station")
    sp.set_defaults(func=cmd_plan)

    acc = sub.add_parser("accuracy", help="standard accuracy reports: ISO 9283, ISO 230-2, VDI/DGQ 3441")
    asub = acc.add_subparsers(dest="accuracy_command", required=True)
    sp = asub.add_parser("iso9283", help="ISO 9283 pose accuracy and repeatability from measured runs")
    sp.add_argument("--data", required=True, help="RUNS.csv: point,cycle,xc,yc,zc[,ac,bc,cc],x,y,z[,a,b,c][,direction] "
                                                  "(mm, deg)")
    sp.add_argument("--out", required=True, help="folder for iso9283.json, report.html and the figures")
    sp.add_argument("--distance", metavar="P2,P4", help="distance accuracy AD and repeatability RD between two points")
    sp.add_argument("--model", help="identified model JSON whose instrument placement maps the attained points "
                                    "(with --frame instrument)")
    sp.add_argument("--frame", choices=["base", "instrument"], default="base",
                    help="frame of the attained x,y,z[,a,b,c]: the commanded poses' (base, default) or the "
                         "instrument's (mapped to the base with --model)")
    sp.add_argument("--label", help="what was run, in the report's title (default: the output folder's and the data "
                                    "file's names)")
    sp.set_defaults(func=cmd_accuracy_iso9283)
    sp = asub.add_parser("plan-iso9283", help="the ISO 9283 test poses P1..P5 and their 30-cycle pose program")
    robot_opts(sp)
    sp.add_argument("--cube", type=float, metavar="MM", help="the cube's edge (default: the largest that fits)")
    sp.add_argument("--orientation", metavar="A,B,C", help="the tool's orientation at every pose (deg; default: "
                                                           "its orientation at the robot's home pose)")
    sp.add_argument("--z-min", type=float, metavar="MM", help="keep the cube above this height (e.g. the floor)")
    sp.add_argument("--cycles", type=int, default=30, help="cycles of the program (default 30, as ISO 9283)")
    sp.add_argument("--out", required=True, help="pose program CSV x,y,z,a,b,c (with point and cycle columns)")
    sp.set_defaults(func=cmd_accuracy_plan)
    sp = asub.add_parser("axis", help="ISO 230-2 and VDI/DGQ 3441 positioning statistics of one axis")
    sp.add_argument("--data", required=True, help="AXIS.csv: target,direction,run,measured (one unit throughout)")
    sp.add_argument("--unit", choices=["mm", "deg"], default="mm", help="the file's unit (default mm)")
    sp.add_argument("--out", required=True, help="folder for axis.json, report.html and the figure")
    sp.add_argument("--label", help="what was run, in the report's title (default: the output folder's and the data "
                                    "file's names)")
    sp.set_defaults(func=cmd_accuracy_axis)

