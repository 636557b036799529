"""The closed-form IK of two kincal builds on the same poses (issue 33: a faster IK gives today's solutions).

Run it once per build (``PYTHONPATH=DIR`` for an installed other build) with ``--out FILE.npz``, then
``--compare A.npz B.npz``: per robot, whether every pose has the same solutions, the largest difference
of an angle (deg), and the differences of a whole turn, each checked to be a tie (the angle exactly half
a turn from the reference, as the other wrist's q6 is from the generating configuration, equally near
it in both builds). Poses: 10,000 per robot, each joint uniform in +-170 deg, |q5| >= 1 deg, the
generating configuration as the reference.
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

ROBOTS = ("kr500", str(Path(__file__).resolve().parents[1] / "tests" / "data" / "fanuc_like.urdf"))
POSES = 10000


def configurations(seed: int = 5) -> np.ndarray:
    rng = np.random.default_rng(seed)
    out = []
    while len(out) < POSES:
        q = rng.uniform(-170, 170, 6)
        if abs(q[4]) >= 1.0:
            out.append(q)
    return np.array(out)


def solve(out: Path) -> None:
    import kincal

    refs = configurations()
    res = {}
    for name in ROBOTS:
        robot = kincal.load_robot(name)
        sols = np.full((POSES, 8, 6), np.nan)
        for i, q in enumerate(refs):
            pose = np.asarray(kincal.fk(robot, q, calibrated=False)).reshape(-1)[:6]
            for k, s in enumerate(kincal.ik(robot, pose, q)):
                sols[i, k] = s["q_deg"]
        res[Path(name).stem] = sols
    np.savez(out, **res)


def compare(a_path: Path, b_path: Path) -> int:
    a, b = np.load(a_path), np.load(b_path)
    refs = configurations()
    ok = True
    for k in a.files:
        x, y = a[k], b[k]
        same = bool((np.isnan(x) == np.isnan(y)).all())
        d = np.abs(np.nan_to_num(x - y))
        turn = np.argwhere(d > 180)
        ties = all(abs(abs(x[i, s, j] - refs[i, j]) - 180) < 1e-9 and abs(abs(y[i, s, j] - refs[i, j]) - 180) < 1e-9
                   for i, s, j in turn)
        rest = d.copy()
        rest[tuple(turn.T)] = np.abs(np.remainder(d[tuple(turn.T)] + 180, 360) - 180)
        print(f"{k}: {int((~np.isnan(x[:, :, 0])).sum())} solutions, same count per pose: {same}; largest "
              f"difference {rest.max():.2e} deg (a whole turn apart: {len(turn)}, all ties: {ties})")
        ok = ok and same and ties and rest.max() < 1e-9
    return 0 if ok else 1


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--out", type=Path)
    p.add_argument("--compare", nargs=2, type=Path)
    a = p.parse_args()
    if a.out:
        solve(a.out)
        return 0
    if a.compare:
        return compare(*a.compare)
    p.error("give --out or --compare")
    return 2


if __name__ == "__main__":
    sys.exit(main())
