"""The core's rigid fit (Horn; kincal._core.rigid_fit, core/rigid.hpp): the one home of the fit that
starts each instrument placement of an identification and places the TCP from known target offsets.
Truth: seeded random rotations and translations of random point sets, no noise (recovered to 1e-9),
and with 0.01 mm noise against numpy's own SVD solution; degenerate sets fall back to a translation."""

from __future__ import annotations

import numpy as np

from kincal import _core


def _rotation(rng: np.random.Generator) -> np.ndarray:
    q, r = np.linalg.qr(rng.normal(size=(3, 3)))
    q = q @ np.diag(np.sign(np.diag(r)))
    return q if np.linalg.det(q) > 0 else -q


def test_recovers_a_rigid_motion_and_agrees_with_numpy():
    rng = np.random.default_rng(31)
    for n in (3, 4, 10, 50):
        for _ in range(20):
            a = rng.normal(scale=300.0, size=(n, 3))
            r, t = _rotation(rng), rng.normal(scale=1000.0, size=3)
            b = a @ r.T + t
            m = _core.rigid_fit(a, b)
            assert np.allclose(m[:3, :3], r, atol=1e-9) and np.allclose(m[:3, 3], t, atol=1e-6)
            assert np.allclose(m[3], [0, 0, 0, 1])
            noisy = b + rng.normal(scale=0.01, size=b.shape)
            m = _core.rigid_fit(a, noisy)
            ca, cb = a.mean(axis=0), noisy.mean(axis=0)
            u, _, vt = np.linalg.svd((a - ca).T @ (noisy - cb))
            want = vt.T @ np.diag([1.0, 1.0, np.sign(np.linalg.det(vt.T @ u.T))]) @ u.T
            assert np.allclose(m[:3, :3], want, atol=1e-9) and np.allclose(m[:3, 3], cb - want @ ca, atol=1e-6)


def test_points_on_a_line_or_too_few_give_a_translation():
    a = np.array([[0.0, 0.0, 0.0], [100.0, 0.0, 0.0], [250.0, 0.0, 0.0]])
    for pts in (a, a[:2], a[:1]):
        m = _core.rigid_fit(pts, pts + [1.0, 2.0, 3.0])
        assert np.allclose(m[:3, :3], np.eye(3)) and np.allclose(m[:3, 3], [1.0, 2.0, 3.0])
