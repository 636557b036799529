"""The `kincal` command (see ../README.md for the contract): one module per command group, each
parsing its commands' arguments and calling the package; this one puts them together and runs one.

    kinematics   fk, ik
    programs     compensate, feed
    calibration  simulate, identify, validate, diagnose
    fivebar      hidden-robot
    campaign     plan, accuracy
    tools        bench, demo
"""

from __future__ import annotations

import argparse
import sys
from typing import Optional, Sequence

from . import calibration, campaign, fivebar, kinematics, programs, tools
from .blas_threads import one_blas_thread


def build_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog="kincal", description="Calibration and compensation of industrial robots")
    sub = p.add_subparsers(dest="command", required=True)
    kinematics.add_commands(sub)
    programs.add_compensate(sub)
    calibration.add_commands(sub)
    programs.add_feed(sub)
    calibration.add_diagnose(sub)
    fivebar.add_commands(sub)
    campaign.add_commands(sub)
    tools.add_commands(sub)
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
