"""`kincal bench` and `kincal demo`: the benchmarks of our code against its baselines, and the whole
pipeline on the built-in examples. Parsing and calling only."""

from __future__ import annotations

import argparse
import importlib
import sys
from pathlib import Path

from ..io import strict_json


def cmd_bench(args: argparse.Namespace) -> None:
    # shipped in the wheel as the private kincal._benchmarks (benchmarks/_benchmarks in the source)
    benchmarks = importlib.import_module("kincal._benchmarks")
    r = benchmarks.run(args.poses, args.seed, args.threads, args.identify_poses, identify=not args.no_identify)
    print(strict_json.dumps({k: (round(v, 4) if isinstance(v, float) else v) for k, v in r.items()}))


def cmd_demo(args: argparse.Namespace) -> None:
    from ..demo import pipeline as demo

    def say(i: int, n: int, what: str) -> None:
        print(f"[{i}/{n}] {what}", file=sys.stderr, flush=True)

    out = Path(args.out)
    print(demo.summary_text(demo.run(out, say)), file=sys.stderr)
    print(f"report: {out / 'report.html'}", file=sys.stderr)


def add_commands(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """bench and demo on the command line's subparsers ``sub``."""
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
