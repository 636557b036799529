"""`kincal hidden-robot`: the five-bar hidden robot of the Kiper paper (fit, error matrix, joint
commands, the simulated over-constrained 6-bar), for kincal.cli."""

from __future__ import annotations

import argparse
import sys

from .. import _core
from .. import fivebar
from ..io import strict_json
from ..io.csv_text import format_rows


def cmd_hr_fit(args: argparse.Namespace) -> None:
    pts = fivebar.read_table(args.data)
    res = fivebar.fit(pts, args.method, args.score)
    _core.write_file_atomic(args.out, strict_json.dumps(res, indent=1) + "\n")
    print(f"{args.method} ({args.score} score): a={res['a']:.3f} b={res['b']:.3f} c={res['c']:.3f} d={res['d']:.3f} mm, "
          f"points {res['points']}, largest error {res['max_error_mm'] * 1000:.1f} um")


def cmd_hr_matrix(args: argparse.Namespace) -> None:
    model, pts = fivebar.load_fit(args.fit), fivebar.read_table(args.data)
    m = _core.ErrorMatrix.from_points(pts, args.data)  # a regular grid first, then commanded by the fit
    fivebar.check_commanded_by(model, pts, args.fit, args.data)
    _core.write_file_atomic(args.out, m.to_json())
    e = fivebar.position_errors(pts)
    print(f"error matrix {m.nx} x {m.ny} nodes, {m.dx:g} x {m.dy:g} mm, from ({m.x0:g}, {m.y0:g}); "
          f"measured errors up to {e.max() * 1000:.1f} um")


def cmd_hr_command(args: argparse.Namespace) -> None:
    model = fivebar.load_fit(args.fit)
    matrix = fivebar.load_matrix(args.matrix) if args.matrix else None
    q = _core.fivebar_command_file(model, matrix, args.targets)  # a point out of reach: file:line
    _core.write_file_atomic(args.out, format_rows(["theta1_deg", "theta2_deg"], q))


def cmd_hr_simulate(args: argparse.Namespace) -> None:
    truth = _core.paper_sixbar(args.seed)
    model = fivebar.load_fit(args.fit) if args.fit else fivebar.FiveBar()
    matrix = fivebar.load_matrix(args.matrix) if args.matrix else None
    xy = fivebar.grid_targets(args.grid) if args.targets is None else _core.read_csv_columns(args.targets, ["x", "y"])
    pts = _core.sixbar_campaign(truth, model, matrix, xy, args.noise, args.seed + 1)
    _core.write_file_atomic(args.out, fivebar.points_csv(pts))
    print(f"measured {len(pts['id'])} points on the simulated 6-bar (seed {args.seed}), "
          f"largest error {fivebar.position_errors(pts).max() * 1000:.1f} um", file=sys.stderr)


def add_commands(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """The `hidden-robot` command and its subcommands on the CLI's subparsers ``sub``."""
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
