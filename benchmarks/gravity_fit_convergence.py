"""Convergence of the fitted-moments identification (issue 29, item 3): the kr500 with its masses
stripped (a URDF without <inertial> tags, as tests/python/test_gravity_fit.py builds it), small
campaigns (15-25 configurations x 3 reflectors, 0.02 mm noise), kincal.identify's defaults
(joint_compliance, --gravity auto: the mass moments fitted, default priors).

Per campaign: the iterations and the stop reason of the fit on every row, the held-out RMS by
grouped 5-fold cross-validation (whole configurations per fold; the fold fits' iterations too), and
the RMS on 200 other configurations of the same truth (noisy); the geometry alone and the true masses
for comparison.

    .venv/bin/python benchmarks/gravity_fit_convergence.py [--seeds 1 2 3 4 5 6] [--poses 15 20 25]
"""

from __future__ import annotations

import argparse
import json
import re
import tempfile
import time
from pathlib import Path

import numpy as np

import kincal
from kincal import _core
from kincal.calibration import identify as ident
from kincal.io.urdf import spec_urdf

NOISE_MM = 0.02


def robots():
    kr500 = kincal.load_robot("kr500")
    text = spec_urdf(json.loads(kr500.to_json())["nominal"], "kr500")
    stripped = re.sub(r"\s*<inertial>.*?</inertial>", "", text, flags=re.S)
    d = Path(tempfile.mkdtemp())
    (d / "with.urdf").write_text(text)
    (d / "without.urdf").write_text(stripped)
    return kincal.load_robot(str(d / "with.urdf")), kincal.load_robot(str(d / "without.urdf"))


def rms(r, data) -> float:
    return float(np.sqrt(np.mean(np.asarray(_core.point_errors(r.robot, r.targets, data)) ** 2)))


def converged(r) -> bool:
    f = r.fit
    return bool(getattr(f, "converged", "NO_CONVERGENCE" not in f.termination))


def cross_validated(robot, data, effects, k=5, seed=0):
    """Grouped k-fold: each fold's rows predicted by the fit on the others; (RMS, fold iterations,
    folds that did not converge)."""
    errs, its, bad = [], [], 0
    for held in ident.folds(data, k, seed):
        r = ident.identify(robot, ident.subset(data, ~held), effects=effects, k_folds=0)
        errs.append(np.asarray(_core.point_errors(r.robot, r.targets, ident.subset(data, held))))
        its.append(r.fit.iterations)
        bad += not converged(r)
    e = np.concatenate(errs)
    return float(np.sqrt(np.mean(e ** 2))), its, bad


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--seeds", type=int, nargs="+", default=[1, 2, 3, 4, 5, 6])
    ap.add_argument("--poses", type=int, nargs="+", default=[15, 20, 25])
    a = ap.parse_args()
    with_masses, without = robots()
    rows = []
    print(f"{'poses':>5} {'seed':>4} | {'iter':>4} {'conv':>4} {'cv fold iter':>22} {'cv':>7} {'held':>7} | "
          f"{'geom cv':>7} {'geom held':>9} | {'mass cv':>7} {'mass held':>9} | {'s':>5}")
    for n in a.poses:
        for seed in a.seeds:
            truth = ident.default_truth(with_masses, seed=seed, compliance=0.003)
            fit = ident.simulate(truth, n, seed=seed, noise_mm=NOISE_MM, targets=3)
            held = ident.simulate(truth, 200, seed=seed + 100, noise_mm=NOISE_MM, targets=3)
            t0 = time.time()
            r = ident.identify(without, fit, k_folds=0)
            dt = time.time() - t0
            cv, its, bad = cross_validated(without, fit, ("joint_compliance",))
            g = ident.identify(without, fit, effects="none", k_folds=0)
            gcv, _, _ = cross_validated(without, fit, "none")
            m = ident.identify(with_masses, fit, k_folds=0)
            mcv, _, _ = cross_validated(with_masses, fit, ("joint_compliance",))
            row = dict(poses=n, seed=seed, iterations=r.fit.iterations, converged=converged(r),
                       termination=r.fit.termination, fold_iterations=its, folds_not_converged=bad,
                       cv_rms_mm=cv, held_rms_mm=rms(r, held), geometry_cv_rms_mm=gcv, geometry_held_rms_mm=rms(g, held),
                       masses_cv_rms_mm=mcv, masses_held_rms_mm=rms(m, held), seconds=dt)
            rows.append(row)
            print(f"{n:>5} {seed:>4} | {row['iterations']:>4} {'yes' if row['converged'] else 'NO':>4} "
                  f"{','.join(map(str, its)):>22} {cv:>7.4f} {row['held_rms_mm']:>7.4f} | {gcv:>7.4f} "
                  f"{row['geometry_held_rms_mm']:>9.4f} | {mcv:>7.4f} {row['masses_held_rms_mm']:>9.4f} | {dt:>5.1f}",
                  flush=True)
    its = np.array([r["iterations"] for r in rows])
    fold_its = np.concatenate([r["fold_iterations"] for r in rows])
    print(f"\nfits on every row: {sum(r['converged'] for r in rows)}/{len(rows)} converged, iterations median "
          f"{np.median(its):.0f}, max {its.max()}; fold fits: median {np.median(fold_its):.0f}, max {fold_its.max()}, "
          f"{sum(r['folds_not_converged'] for r in rows)}/{len(fold_its)} not converged")
    for key in ("cv_rms_mm", "held_rms_mm", "geometry_cv_rms_mm", "geometry_held_rms_mm", "masses_cv_rms_mm",
                "masses_held_rms_mm"):
        v = np.array([r[key] for r in rows])
        print(f"{key:<22} mean {v.mean():.4f}  median {np.median(v):.4f}  max {v.max():.4f}")


if __name__ == "__main__":
    main()
