"""The real UR10 of ../shared/data/ipa-robot-accuracy (laser tracker, T-Mac probe; four series, each
measured from its own tracker placement), in the calls a user makes:

    .venv/bin/python examples/ur10_ipa.py [DATA_DIR] [--fit B] [--out DIR] [--joint]

1. the diagnosis on one series (default B): DIR/report.html, DIR/diagnosis.json and DIR/model.json
   (`kincal diagnose --robot ur10 --data B.csv --effects joint_compliance --out DIR`);
2. that model checked on each other series, only the tracker placement and the probe offset
   refitted (`kincal validate --model DIR/model.json --data A.csv --out VA.json`), with its warnings
   where the series takes the model's periodic effects outside the angles they were fitted on and
   the RMS of those rows against the others;
3. with --joint, all four series identified jointly, one placement per series (a `setup` column),
   validated by grouped 5-fold cross-validation (whole configurations per fold) and by holding out
   each series whole (`kincal identify --data ABCD.csv --hold-out-setups`; per series: the other
   three identified jointly, then `kincal validate` on it), and the diagnosis of all four jointly
   (`kincal diagnose --data ABCD.csv --effects joint_compliance --out DIR-joint`: what remains)."""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

import kincal
from kincal import _core
from kincal.io import datasets
from kincal import diagnose
from kincal.calibration import setups
from kincal.calibration import identify as ident

SERIES = {"A": "Series_A/measurements_grid.csv", "B": "Series_B/measurements_joint_configurations.csv",
          "C": "Series_C/measurements_random_poses.csv", "D": "Series_D/measurements_iso_cubes.csv"}


def with_setups(series: dict) -> _core.MeasurementSet:
    """The series as one campaign: a setup (tracker placement) per series, pose ids running on."""
    names = list(series)
    parts = []
    for k, name in enumerate(names):
        d = series[name].columns()  # writable copies of its columns
        d["setup"] = np.full(len(series[name]), k, dtype=np.int64)
        d["pose"] = d["pose"] + sum(len(series[n]) for n in names[:k])
        parts.append(d)
    out = {key: np.concatenate([p[key] for p in parts]) for key, v in parts[0].items() if isinstance(v, np.ndarray)}
    out.update(source="UR10 series " + "".join(names), setup_names=names)
    return _core.MeasurementSet(out)


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("data", nargs="?", default=str(Path(__file__).resolve().parents[1] / ".." / "shared" / "data" /
                                                  "ipa-robot-accuracy"))
    p.add_argument("--fit", default="B", choices=sorted(SERIES))
    p.add_argument("--out", default="ur10-diagnosis", help="the diagnosis's folder")
    p.add_argument("--joint", action="store_true", help="also identify all four series jointly (one setup each)")
    p.add_argument("--effects", default="joint_compliance",
                   help="the model the diagnosis starts from besides the geometry ('' : geometry alone)")
    args = p.parse_args()
    robot = kincal.load_robot("ur10")
    series = {k: datasets.read_ipa(Path(args.data) / v) for k, v in SERIES.items()}

    diag, model = diagnose.run(robot, series[args.fit], args.out, title=f"kincal diagnose: UR10 series {args.fit}",
                               effects=args.effects or (), progress=print)
    print(diagnose.summary(diag, model, args.out, 0.0))
    for k in sorted(SERIES):
        if k != args.fit:
            print(f"\nseries {k}, the model of series {args.fit} with only the placement and probe refitted:")
            v = ident.validate(model.robot, series[k])
            print(setups.validation_summary(v) + f"\n(per axis, the RMS of every x, y and z residual: "
                                                  f"{v['rms_mm'] / np.sqrt(3):.3f} mm)")
            if v["extrapolated"]:
                io = setups.inside_and_outside(model.robot, series[k])
                print("RMS after (before) of the rows inside every fitted range and of those outside one: " +
                      ", ".join(f"{w} {io[w]['rows']} rows {io[w]['rms_mm']:.3f} ({io[w]['before_rms_mm']:.3f}) mm"
                                for w in ("inside", "outside")))

    if args.joint:
        every = with_setups(series)
        res = ident.identify(robot, every, effects="joint_compliance")
        print("\nall four series jointly (one tracker placement each):\n" + res.summary())
        held = ident.identify(robot, every, effects="joint_compliance", hold_out_setups=True)
        v = held.validation
        print(f"\neach series held out whole: RMS {v['before_rms_mm']:.3f} -> {v['after_rms_mm']:.3f} mm, mean "
              f"{v['before_mean_mm']:.3f} -> {v['after_mean_mm']:.3f} mm, max {v['before_max_mm']:.3f} -> "
              f"{v['after_max_mm']:.3f} mm")
        for k in SERIES:
            others = with_setups({n: series[n] for n in SERIES if n != k})
            fit = ident.identify(robot, others, effects="joint_compliance", k_folds=0)
            print(f"\nseries {k}, the model of the other three series with only the placement and probe refitted:")
            print(setups.validation_summary(ident.validate(fit.robot, series[k])))
        jdiag, jmodel = diagnose.run(robot, every, args.out + "-joint", effects="joint_compliance",
                                     title="kincal diagnose: UR10 series A-D jointly (one setup each)", progress=print)
        print("\nthe diagnosis of all four series jointly:\n" + diagnose.summary(jdiag, jmodel, args.out + "-joint", 0.0))


if __name__ == "__main__":
    main()
