"""Two builds of kincal-bench against each other, entry by entry: runs A and B in turn (A B A B ...),
pairs each run of A with the run of B beside it, and prints, for every timing entry, the medians and
the median of the pairs' ratios A/B (below 1: A faster). Alternating keeps the ratio honest when the
machine's speed drifts; the spread (min..max of the ratios) says how noisy the machine was.

    python benchmarks/compare_bench.py NEW/kincal-bench OLD/kincal-bench --pairs 9 --poses 2000
"""

from __future__ import annotations

import argparse
import json
import statistics
import subprocess
import sys

#: entries that are timings (ns per call: lower is better) or rates (per second: higher is better)
RATES = ("batch_poses_per_s", "batch_program_poses_per_s")


def run(binary: str, poses: int) -> dict:
    out = subprocess.run([binary, "--poses", str(poses)], capture_output=True, text=True, check=True).stdout
    return json.loads(out[out.index("{"):])


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("a", help="kincal-bench of the build under test")
    p.add_argument("b", help="kincal-bench of the baseline build")
    p.add_argument("--pairs", type=int, default=9)
    p.add_argument("--poses", type=int, default=2000)
    args = p.parse_args(argv)
    runs_a, runs_b = [], []
    for i in range(args.pairs):
        runs_a.append(run(args.a, args.poses))
        runs_b.append(run(args.b, args.poses))
        print(f"pair {i + 1} of {args.pairs}", file=sys.stderr)
    keys = [k for k in runs_a[0] if k.endswith("_ns") or k in RATES]
    print(f"{'entry':<32}{'A median':>14}{'B median':>14}{'A/B (time)':>12}{'min..max':>16}")
    worst = 0.0
    for k in keys:
        if k not in runs_b[0]:
            continue
        ratios = [(b[k] / a[k]) if k in RATES else (a[k] / b[k]) for a, b in zip(runs_a, runs_b)]
        r = statistics.median(ratios)
        worst = max(worst, r)
        print(f"{k:<32}{statistics.median(x[k] for x in runs_a):>14.6g}{statistics.median(x[k] for x in runs_b):>14.6g}"
              f"{r:>12.3f}{min(ratios):>8.3f}..{max(ratios):<7.3f}")
    print(f"largest median ratio A/B (time; rates inverted): {worst:.3f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
