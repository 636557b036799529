"""`kincal compensate`'s program options: the controller languages (KUKA KRL, ABB RAPID, FANUC LS,
URScript, G-code, CSV), joint or filtered targets, program name, speed, zone. Every format is written
by the C++ core (the same code as kincal-compensate)."""

from __future__ import annotations

import sys

from . import _core
from .cli_campaign import _step_progress
from .tool_frame import warn_nominal_tcp

FORMATS = ["krl", "rapid", "fanuc-ls", "urscript", "gcode", "csv"]


def add_options(sp) -> None:
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


def joint_convention_option(sp) -> None:
    sp.add_argument("--joint-convention", choices=["fanuc"],
                    help="how the controller numbers the joints of a URDF or built-in robot (a model JSON carries "
                         "its own): fanuc, J3 is the forearm's angle to the horizontal; every joint angle in the "
                         "files is then the controller's")


def _frame(text, option: str) -> list:
    if text is None:
        return []
    try:
        v = [float(x) for x in text.split(",")]
    except ValueError:
        raise ValueError(f"{option} {text}: expected X,Y,Z,A,B,C") from None
    if len(v) != 6:
        raise ValueError(f"{option} {text}: expected 6 numbers X,Y,Z,A,B,C")
    return v


def compensate(robot, args, comp_kwargs: dict, progress=None) -> dict:
    """Compensates args.program (a file, or several files and folders: a controller backup) into args.out
    in the chosen language; returns the result dict (with `files`, the files written; a backup: `programs`,
    `copied`, `failed`). A model whose TCP is nominal (not measured) gets one warning line."""
    warn_nominal_tcp(robot, args.model, "kincal compensate")
    return _core.compensate_to_controller(robot, [str(p) for p in args.program], str(args.out), **comp_kwargs,
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


def summary(res: dict) -> list[str]:
    """The summary's lines on a native program's targets (joints or filtered) and on --tolerance."""
    lines = [res["targets_note"]] if res.get("targets_note") else []
    if res.get("inserted") is None or res["path_before_mm"] != res["path_before_mm"]:  # NaN: no --tolerance
        return lines
    return lines + [f"path between targets: largest deviation from the desired segments {res['path_before_mm']:.4f} mm "
                    f"before, {res['path_after_mm']:.4f} mm after {res['inserted']} inserted target(s)"]


def compensate_backup(robot, args, comp_kwargs: dict) -> None:
    """A controller backup (folders, several files): every program filtered into the same tree under --out;
    a program that fails is listed (file:line: cause) and the exit status is 1, the others are written."""
    step = _step_progress("kincal compensate: programs")  # (done counts from 1)
    res = compensate(robot, args, comp_kwargs, progress=None if step is None else lambda done, n: step(done - 1, n))
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
