"""Do the UR10 series share joint configurations? And how smooth is what geometry and compliance
leave? (Issue 14's UR10 targets: what a model fitted on series B can be asked about A, C and D.)

    .venv/bin/python examples/ur10_overlap.py [DATA_DIR]

For each pair of series, the distance from every configuration of one to the nearest of the other:
the largest angle difference over joints 1-5 (joint 6 barely moves the probe point), modulo 360 deg.
Then, on series A fitted by itself (geometry + compliance), its residual predicted from its own
other rows by a distance-weighted k-nearest-neighbour average (grouped 5-fold: whole configurations
per fold), once by joint angles, once by the row order alone (the measurement sequence)."""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
from scipy.spatial import cKDTree

import kincal
from kincal.io import datasets
from kincal.stats import grouping
from kincal.calibration import identify as ident
from kincal.calibration.setups import _refit_placements

sys.path.insert(0, str(Path(__file__).resolve().parent))
from ur10_maps import SERIES, predicted  # noqa: E402  (the UR10 examples' own helpers)


def nearest_deg(src: np.ndarray, dst: np.ndarray) -> np.ndarray:
    """Per row of ``dst``, the largest joint-angle difference (deg, modulo 360) to the nearest row
    of ``src`` (joints 1-5)."""
    tree = cKDTree(np.mod(src[:, :5], 360.0), boxsize=360.0)
    return tree.query(np.mod(dst[:, :5], 360.0), p=np.inf)[0]


def knn_cv(x: np.ndarray, r: np.ndarray, folds: list, k: int, **tree) -> float:
    """3-D RMS of the residual ``r`` less its distance-weighted k-neighbour average, held out by ``folds``."""
    e = []
    for f in folds:
        d, i = cKDTree(x[~f], **tree).query(x[f], k=k)
        w = 1.0 / np.maximum(d, 1e-9)
        e.append(r[f] - np.einsum("nk,nkc->nc", w, r[~f][i]) / w.sum(axis=1)[:, None])
    return float(np.sqrt(np.mean(np.sum(np.concatenate(e) ** 2, axis=1))))


def main() -> None:
    root = Path(sys.argv[1]) if len(sys.argv) > 1 else Path(__file__).resolve().parents[1] / ".." / "shared" / "data" / "ipa-robot-accuracy"
    series = {k: datasets.read_ipa(root / v) for k, v in SERIES.items()}
    print("nearest configuration of the other series (largest joint difference over joints 1-5, deg): "
          "10% / median / 90% of rows")
    for a in SERIES:
        for b in SERIES:
            if a != b:
                d = nearest_deg(series[b].q_deg, series[a].q_deg)
                print(f"  {a} to {b}: {np.percentile(d, 10):6.1f} {np.median(d):6.1f} {np.percentile(d, 90):6.1f}"
                      f"   rows within 5 deg: {np.mean(d < 5.0):.1%}")
    robot = kincal.load_robot("ur10")
    a = series["A"]
    fit = ident.identify(robot, a, effects="joint_compliance", k_folds=0)
    _, _, _, _, cal = _refit_placements(fit.robot, a)
    r = a.xyz - predicted(cal.robot, cal.targets, a)
    folds = grouping.folds(a, 5, 0)
    print(f"series A by itself, geometry + compliance: fitted 3-D RMS {np.sqrt(np.mean(np.sum(r ** 2, 1))):.3f} mm")
    q = np.mod(a.q_deg[:, :5], 360.0)
    order = np.arange(len(r), dtype=float)[:, None]
    for k in (2, 4, 8):
        print(f"  less its k={k} nearest rows, grouped 5-fold: by joint angles {knn_cv(q, r, folds, k, boxsize=360.0):.3f} mm, "
              f"by row order {knn_cv(order, r, folds, k):.3f} mm")


if __name__ == "__main__":
    main()
