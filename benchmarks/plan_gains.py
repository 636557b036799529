"""One step of `kincal plan`'s greedy: the D-optimal gains log det(I + A A^T), A = J_i L, of a sample of
candidates, by the core (`_core.d_optimal_gains`) and by the numpy code it replaced (a gather, a
product, a batched product and a Cholesky written out over the batch), in the same run, on the same
inputs (BENCHMARKS.md, "Planning 100,000 candidates in under a second").

Inputs: the plan's own scaled float32 Jacobian of 100,000 random kr500 candidates (3 reflectors,
geometry + compliance: 9 rows each, a column per parameter the plan keeps), a sample of 7,676 of them (the stochastic greedy's
sample at K = 60), L of M = 0.1 I + B^T B (B: 200 standard normal rows, seed 0).

    .venv/bin/python benchmarks/plan_gains.py [--repeats 50]
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from kincal import _core, load_robot
from kincal.calibration import identify as ident
from kincal.calibration import plan


def numpy_gains(Jb32: np.ndarray, idx: np.ndarray, L: np.ndarray) -> np.ndarray:
    """The gains as plan.py computed them before the core did (its _logdet_spd inlined)."""
    p = Jb32.shape[2]
    A = (Jb32[idx].reshape(-1, p) @ L).reshape(len(idx), Jb32.shape[1], p)
    G = A @ np.transpose(A, (0, 2, 1)) + np.eye(Jb32.shape[1], dtype=np.float32)
    Gt = np.ascontiguousarray(np.transpose(G, (1, 2, 0)))
    out = np.zeros(G.shape[0], dtype=G.dtype)
    for k in range(G.shape[1]):
        d = Gt[k, k]
        out += np.log(d)
        if k + 1 < G.shape[1]:
            Gt[k + 1:, k + 1:] -= (Gt[k + 1:, k] / d)[:, None, :] * Gt[k, k + 1:][None, :, :]
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--repeats", type=int, default=50)
    args = ap.parse_args()
    robot = load_robot("kr500")
    targets = ident.DEFAULT_TARGETS[:3]
    q = plan.random_candidates(robot, 100_000, 0)
    effects = [e for e in ident.check_effects(("joint_compliance",), robot) if isinstance(e, _core.Effect)]
    free, _ = plan._free_columns(robot, q, targets, effects, 0)
    J, _ = plan._jacobian(robot, q, targets, effects, free)
    scale = np.sqrt(np.einsum("ij,ij->j", J, J) / len(q))
    p = J.shape[1]
    Jb32 = J.reshape(len(q), 9, p).astype(np.float32)
    Jb32 *= (1.0 / scale).astype(np.float32)
    rng = np.random.default_rng(0)
    idx = np.sort(rng.choice(len(q), 7676, replace=False))
    B = rng.normal(size=(200, p))
    L = np.linalg.cholesky(np.linalg.inv(0.1 * np.eye(p) + B.T @ B)).astype(np.float32)
    times = {}
    runs = (("core", lambda: _core.d_optimal_gains(Jb32, idx, L)), ("numpy", lambda: numpy_gains(Jb32, idx, L)))
    for name, f in runs:
        f()
        t = time.perf_counter()
        for _ in range(args.repeats):
            g = f()
        times[name] = ((time.perf_counter() - t) / args.repeats * 1000, g)
    rel = float(np.max(np.abs(times["core"][1] - times["numpy"][1]) / np.abs(times["numpy"][1])))
    print(f"7,676 candidates, {p} columns: core {times['core'][0]:.2f} ms, numpy {times['numpy'][0]:.2f} ms "
          f"(ratio {times['numpy'][0] / times['core'][0]:.2f}); largest relative difference {rel:.1e}")


if __name__ == "__main__":
    main()
