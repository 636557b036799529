"""`kincal fk` and `kincal ik`: the model's forward and nominal inverse kinematics of pose and joint
files (kincal.programs.kinematics_files). Parsing and calling only."""

from __future__ import annotations

import argparse

from ..calibration.setups import robot_for_setup
from ..programs.kinematics_files import fk_file, ik_file
from .options import robot_of, robot_opts


def cmd_fk(args: argparse.Namespace) -> None:
    robot = robot_of(args)
    if args.setup is not None:
        if args.frame != "instrument":
            raise ValueError("--setup NAME chooses an instrument placement: it needs --frame instrument")
        robot = robot_for_setup(robot, args.setup, args.robot)
    fk_file(robot, args.robot, args.joints, args.out, args.frame, args.temperature)


def cmd_ik(args: argparse.Namespace) -> None:
    ik_file(robot_of(args), args.robot, args.poses, args.out, args.all)


def add_commands(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """fk and ik on the command line's subparsers ``sub``."""
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
