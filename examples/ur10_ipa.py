"""Calibrate the real UR10 of ../shared/data/ipa-robot-accuracy on one series, validate on the others.

    .venv/bin/python examples/ur10_ipa.py [DATA_DIR] [--fit B]

Fit series (default B, varied joint configurations): a 25% split of its poses is held out; the
other series are predicted with only the tracker frame and probe offset refitted (the geometry and
compliances are those identified on the fit series). Prints a table (mm)."""

from __future__ import annotations

import argparse
from pathlib import Path

import kincal
from kincal import datasets
from kincal import identify as ident

SERIES = {"A": "Series_A/measurements_grid.csv", "B": "Series_B/measurements_joint_configurations.csv",
          "C": "Series_C/measurements_random_poses.csv", "D": "Series_D/measurements_iso_cubes.csv"}


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("data", nargs="?", default=str(Path(__file__).resolve().parents[1] / ".." / "shared" / "data" /
                                                  "ipa-robot-accuracy"))
    p.add_argument("--fit", default="B", choices=sorted(SERIES))
    p.add_argument("--effects", default="joint_compliance",
                   help="as kincal identify --effects: NAME or NAME:J, comma separated, or none")
    p.add_argument("--diagnose", metavar="DIR", help="also run the diagnosis on the fit series, report in DIR")
    p.add_argument("--orientation", action="store_true",
                   help="use the probe's measured orientations too (6-D poses, weighted by the tracker's "
                        "median standard deviations: 0.012 mm against 0.00225 deg)")
    args = p.parse_args()
    robot = kincal.load_robot("ur10")
    data = {k: datasets.read_ipa(Path(args.data) / v) for k, v in SERIES.items()}
    effects = ident.parse_effects(args.effects, robot)
    if args.orientation:
        import math

        fit = datasets.read_ipa(Path(args.data) / SERIES[args.fit], orientation=True)
        res = ident.identify(robot, fit, effects=effects, orientation_weight=0.012 / math.radians(0.00225))
    else:
        res = ident.identify(robot, data[args.fit], effects=effects)
    print(res.summary())
    print()
    print(f"{'series':<34}{'points':>8}{'RMS before':>12}{'RMS after':>12}{'max before':>12}{'max after':>12}")
    v = res.validation
    print(f"{args.fit + ' held out (25% of poses)':<34}{v['held_rows']:>8}{v['before_rms_mm']:>12.3f}"
          f"{v['after_rms_mm']:>12.3f}{v['before_max_mm']:>12.3f}{v['after_max_mm']:>12.3f}")
    for k in sorted(SERIES):
        if k == args.fit:
            continue
        r = ident.validate(res.robot, data[k])
        print(f"{k + ' (frames refitted)':<34}{r['rows']:>8}{r['before_rms_mm']:>12.3f}{r['after_rms_mm']:>12.3f}"
              f"{r['before_max_mm']:>12.3f}{r['after_max_mm']:>12.3f}")
    if args.diagnose:
        import json
        from kincal import diagnose as dg
        out = Path(args.diagnose)
        out.mkdir(parents=True, exist_ok=True)
        d = dg.diagnose(robot, data[args.fit], progress=print)
        dg.write_report(robot, data[args.fit], d, out, title=f"kincal diagnose: UR10 series {args.fit}")
        (out / "diagnosis.json").write_text(json.dumps(dg.contract_json(d), indent=1))
        for st in d["steps"]:
            print(f"  {st['effect']} joint {st['joint']}: {st['rms_before_mm']:.3f} -> {st['rms_after_mm']:.3f} mm "
                  f"(F = {st['evidence']['F']:.3g}, p = {st['evidence']['p_value']:.2g})")
        print(f"  {d['verdict']}")


if __name__ == "__main__":
    main()
