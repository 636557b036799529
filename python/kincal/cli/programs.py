"""`kincal compensate` and `kincal feed`: compensation of pose programs and controller programs (a
file, or a controller backup), with the program options (the controller languages KUKA KRL, ABB RAPID,
FANUC LS, URScript, G-code, CSV; joint or filtered targets, program name, speed, zone: every format is
written by the C++ core, the same code as kincal-compensate), and the derivative analysis of joint
programs against the drives' limits. Parsing and calling only."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import TYPE_CHECKING, Any, Callable, Optional, Union, cast

from .. import _core, load_robot
from ..programs import feed
from .options import joint_convention_option, robot_of, robot_opts, step_progress
from ..calibration.tool_frame import warn_nominal_tcp

if TYPE_CHECKING:
    from .._core import BackupResult, ControllerProgramResult

FORMATS = ["krl", "rapid", "fanuc-ls", "urscript", "gcode", "csv"]


def add_options(sp: argparse.ArgumentParser) -> None:
    joint_convention_option(sp)
    sp.add_argument("--format", choices=FORMATS,
                    help="the output's language (default: by --out's extension: .src KRL (+ .dat), .mod RAPID, "
                         ".ls FANUC LS, .script URScript, .csv CSV, other G-code)")
    sp.add_argument("--targets", choices=["joints", "filtered"], default="joints",
                    help="joints: joint targets (default); filtered: Cartesian targets with the controller's branch "
                         "data (KUKA S/T, ABB confdata, FANUC configuration) that its nominal model turns into the "
                         "compensated joints")
    sp.add_argument("--name", default="", help="program name (default: the output file's name)")
    sp.add_argument("--speed", type=float, help="joint motions: percent of the axes' maximum speed (default 20); "
                                                "linear motions: mm/s (default 250)")
    sp.add_argument("--zone", type=float, help="approximation / blending, mm (FANUC: the CNT value 0..100); "
                                               "default 0: exact stop")
    sp.add_argument("--max-targets-per-file", type=int, default=0,
                    help="split KRL and LS programs with more targets into parts a main program calls (default 2000)")
    sp.add_argument("--program-tool", help="a KRL or RAPID program's TCP in the model's tool frame: X,Y,Z,A,B,C (mm, deg)")
    sp.add_argument("--program-base", help="a KRL or RAPID program's base in the robot's base frame: X,Y,Z,A,B,C")
    sp.add_argument("--uframe", action="append", default=[], metavar="N=X,Y,Z,A,B,C",
                    help="a FANUC LS program's user frame N in the robot's base frame (repeat for each UF its "
                         "positions use; one UF alone may use --program-base)")
    sp.add_argument("--utool", action="append", default=[], metavar="N=X,Y,Z,A,B,C",
                    help="a FANUC LS program's tool N in the model's tool frame (repeat for each UT its positions "
                         "use; one UT alone may use --program-tool)")
    sp.add_argument("--skip-unresolved", action="store_true",
                    help="pass motions whose targets kincal does not compensate (computed at run time: RelTool, Offs, "
                         "CRobT, geometric operators, _REL motions, offsets; declared nowhere) through unchanged with a "
                         "warning (default: an error listing every one, file:line)")
    sp.add_argument("--declarations", nargs="+", default=[], metavar="FILE",
                    help="more files whose declarations the programs may name (a KRL $config.dat or .dat, RAPID "
                         "modules): targets, tools, bases, work objects")
    sp.add_argument("--allow-branch-change", action="store_true",
                    help="a taught target (KUKA S/T, ABB confdata, FANUC configuration) that the calibrated robot "
                         "cannot reach on its taught solution is written on another branch with a warning (default: "
                         "an error naming it)")
    sp.add_argument("--track", action="append", default=[], metavar="AXIS=X,Y,Z",
                    help="a linear track that carries the robot: external axis AXIS (E1..E6) moves the robot's base "
                         "by X,Y,Z (mm per unit of the axis) in the program's base frame (KRL, RAPID: base 0, "
                         "--program-base; FANUC LS: the robot's base at E1 = 0, in which --uframe is given)")
    sp.add_argument("--jobs", type=int, default=0,
                    help="a backup's programs filtered at once (default: every core)")
    sp.add_argument("--tolerance", type=float, metavar="MM",
                    help="insert targets where the real robot's path between two targets (joint interpolation; "
                         "for filtered targets the controller's straight line) leaves the desired segment by more "
                         "than MM; the summary gives the largest deviation before and after")


def _frame(text: Optional[str], option: str) -> list[float]:
    if text is None:
        return []
    try:
        v = [float(x) for x in text.split(",")]
    except ValueError:
        raise ValueError(f"{option} {text}: expected X,Y,Z,A,B,C") from None
    if len(v) != 6:
        raise ValueError(f"{option} {text}: expected 6 numbers X,Y,Z,A,B,C")
    return v


def compensate(robot: _core.Robot, args: argparse.Namespace, comp_kwargs: dict[str, Any],
               progress: Optional[Callable[[int, int], None]] = None
               ) -> Union[ControllerProgramResult, BackupResult]:
    """Compensates args.program (a file, or several files and folders: a controller backup) into args.out
    in the chosen language; returns the result dict (with `files`, the files written; a backup: `programs`,
    `copied`, `failed`). A model whose TCP is nominal (not measured) gets one warning line. One program's
    result has its count and extremes only (`poses`, `iterations_min`, ...; no per-pose arrays): a CSV or
    G-code program of any length is compensated in bounded memory."""
    warn_nominal_tcp(robot, args.model, "kincal compensate")
    options = _core.ProgramOptions(**comp_kwargs, keep_poses=False)
    return _core.compensate_to_controller(robot, [str(p) for p in args.program], str(args.out), options,
                                          format=args.format, targets=args.targets, name=args.name,
                                          speed=args.speed, zone=args.zone,
                                          max_targets_per_file=args.max_targets_per_file,
                                          program_tool=_frame(args.program_tool, "--program-tool"),
                                          program_base=_frame(args.program_base, "--program-base"),
                                          skip_unresolved=args.skip_unresolved, tolerance=args.tolerance,
                                          uframes=args.uframe, utools=args.utool,
                                          declarations=[str(d) for d in args.declarations],
                                          allow_branch_change=args.allow_branch_change, tracks=args.track,
                                          threads=args.jobs, progress=progress)


def summary(res: ControllerProgramResult) -> list[str]:
    """The summary's lines on a native program's targets (joints or filtered) and on --tolerance."""
    lines = [res["targets_note"]] if res.get("targets_note") else []
    if res.get("inserted") is None or res["path_before_mm"] != res["path_before_mm"]:  # NaN: no --tolerance
        return lines
    return lines + [f"path between targets: largest deviation from the desired segments {res['path_before_mm']:.4f} mm "
                    f"before, {res['path_after_mm']:.4f} mm after {res['inserted']} inserted target(s)"]


def compensate_backup(robot: _core.Robot, args: argparse.Namespace, comp_kwargs: dict[str, Any]) -> None:
    """A controller backup (folders, several files): every program filtered into the same tree under --out;
    a program that fails is listed (file:line: cause) and the exit status is 1, the others are written."""
    step = step_progress("kincal compensate: programs")  # (done counts from 1)
    res = cast("BackupResult",  # several programs or a folder: the core compensates a backup
               compensate(robot, args, comp_kwargs,
                          progress=None if step is None else lambda done, n: step(done - 1, n)))
    if sys.stderr.isatty():
        print(file=sys.stderr)
    for p in res["programs"]:
        for w in p["warnings"]:
            print(f"kincal compensate: warning: {w}", file=sys.stderr)
    written = [p for p in res["programs"] if not p["error"]]
    for p in written:
        if p["files"]:
            n = len(p["iterations"])
            print(f"{', '.join(p['files'])}: {n} target(s) compensated"
                  + (f"; {p['targets_note']}" if p["targets_note"] else ""), file=sys.stderr)
    print(f"{args.out}: {len([p for p in written if p['files']])} program(s) filtered, {len(res['copied'])} file(s) "
          f"copied unchanged, {res['failed']} program(s) failed", file=sys.stderr)
    if res["failed"]:
        lines = [f"{', '.join(p['inputs'])}:\n    " + p["error"].replace("\n", "\n    ")
                 for p in res["programs"] if p["error"]]
        raise ValueError(f"{res['failed']} program(s) not written (the others are):\n  " + "\n  ".join(lines))


def _comp_kwargs(args: argparse.Namespace) -> dict[str, Any]:
    return dict(compensate=not args.nominal, instrument=args.frame == "instrument",
                finite_difference=args.finite_difference, delta=args.delta, epsilon=args.epsilon,
                max_iterations=args.max_iterations, corrected_start=not args.paper_start, residual=args.residual,
                temperature_c=args.temperature,
                initial_direction=_core.parse_initial_direction(args.initial_direction or ""),
                keep_branch=args.keep_branch)


def cmd_compensate(args: argparse.Namespace) -> None:
    robot = load_robot(args.model, joint_convention=args.joint_convention)
    if args.frame == "instrument" and not robot.identified:
        raise ValueError(f"{args.model}: --frame instrument needs an identified model (kincal identify)")
    if len(args.program) > 1 or Path(args.program[0]).is_dir():
        compensate_backup(robot, args, _comp_kwargs(args))
        return
    res = cast("ControllerProgramResult", compensate(robot, args, _comp_kwargs(args)))  # one program: no backup
    for w in res["warnings"]:
        print(f"kincal compensate: warning: {w}", file=sys.stderr)
    n = res["poses"]
    written = ", ".join(res.get("files") or [str(args.out)])  # a KRL program is its .src and .dat
    print(f"{written}: {n} poses compensated, iterations {res['iterations_min']}..{res['iterations_max']} "
          f"(mean {res['iterations_total'] / n:.2f}), largest residual |F| {res['residual_max']:.3g}", file=sys.stderr)
    for line in summary(res):
        print(f"{written}: {line}", file=sys.stderr)


def _pair(text: str) -> tuple[float, float]:
    try:
        a, b = (float(x) for x in text.split(","))
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected two numbers S0,S1, not '{text}'") from None
    if not a < b:
        raise argparse.ArgumentTypeError(f"S0 must be below S1 in '{text}'")
    return a, b


def cmd_feed(args: argparse.Namespace) -> None:
    programs = {"program": args.program}
    if args.compare:
        programs["compare"] = args.compare
    results = feed.analyse_files(robot_of(args), args.robot, programs, args.out, limits_path=args.limits,
                                    feed=args.feed, samples=args.samples, method=args.method, window=args.window,
                                    zoom=args.zoom)
    print(feed.summary(results, args.feed))


def add_compensate(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """compensate on the command line's subparsers ``sub``."""
    sp = sub.add_parser("compensate", help="Newton compensation of a pose program into a joint program")
    sp.add_argument("--model", required=True, help="built-in name, URDF file or model JSON")
    sp.add_argument("--program", required=True, nargs="+",
                    help="pose program (CSV x,y,z,a,b,c or G-code X Y Z A B C) or a controller's program (.src with its "
                         ".dat, .mod, .ls, .script); several files or a folder: a controller backup, every program in "
                         "it filtered (--out is then a folder with the same tree)")
    sp.add_argument("--out", required=True, help="the program: .csv (q1..q6), G-code (A1=..), .src (KRL), .mod "
                                                 "(RAPID), .ls (FANUC LS), .script (URScript); a folder for a backup")
    sp.add_argument("--frame", choices=["base", "instrument"], default="base")
    add_options(sp)
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


def add_feed(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """feed on the command line's subparsers ``sub``."""
    sp = sub.add_parser("feed", help="derivative analysis of joint programs (Samak section III)")
    robot_opts(sp)
    sp.add_argument("--program", required=True, help="joint program (CSV q1..qN or G-code A1=..)")
    sp.add_argument("--compare", help="a second joint program drawn beside it (e.g. the uncompensated one)")
    sp.add_argument("--limits", help="CSV axis,v_max,a_max,j_max (deg/s, deg/s^2, deg/s^3) overriding the robot's")
    sp.add_argument("--feed", type=float, default=feed.DEFAULT_FEED,
                    help="commanded rate of total axis displacement s (rad/s) against which violations are found")
    sp.add_argument("--method", choices=list(feed.METHODS), default="spline",
                    help="resampling: quintic spline (default) or the paper's linear interpolation")
    sp.add_argument("--samples", type=int, default=feed.DEFAULT_SAMPLES, help="resampled points along s")
    sp.add_argument("--window", type=_pair, help="S0,S1: the s range of the figures' left column (rad; default all)")
    sp.add_argument("--zoom", type=_pair, help="S0,S1: the s range of the right column (default 1.5%% around the middle)")
    sp.add_argument("--out", required=True, help="folder for feed.json and the figures")
    sp.set_defaults(func=cmd_feed)
