"""The identification residuals written in numpy, as a script with scipy would have them: the
baseline of `kincal bench`'s scipy_numpy_identify_ms. The same measurement model and the same
parameter vector as the C++ core's PointModel (points only, joint compliance, no extra effects);
a test checks both give the same residuals."""

from __future__ import annotations

import json
from typing import TYPE_CHECKING

import numpy as np

from kincal import _core

if TYPE_CHECKING:
    from kincal._core import MeasurementSet


def _unit_orthogonal(w: np.ndarray) -> np.ndarray:
    # Eigen's unitOrthogonal(), so that the tilt and move directions are the core's
    x, y, z = w
    eps = np.finfo(float).eps
    if not (abs(x) <= eps * abs(z) and abs(y) <= eps * abs(z)):
        u = np.array([-y, x, 0.0])
    else:
        u = np.array([0.0, -z, y])
    return u / np.linalg.norm(u)


def _skew(v: np.ndarray) -> np.ndarray:
    return np.array([[0, -v[2], v[1]], [v[2], 0, -v[0]], [-v[1], v[0], 0]])


def _exp(phi: np.ndarray) -> np.ndarray:
    th = np.linalg.norm(phi)
    if th < 1e-300:
        return np.eye(3)
    k = _skew(phi / th)
    return np.eye(3) + np.sin(th) * k + (1 - np.cos(th)) * k @ k


def _rot(w: np.ndarray, t: np.ndarray) -> np.ndarray:
    """Rotations about unit axis w by angles t (n,): n x 3 x 3."""
    k = _skew(w)
    return np.eye(3) + np.sin(t)[:, None, None] * k + (1 - np.cos(t))[:, None, None] * (k @ k)


class NumpyPointModel:
    def __init__(self, robot: _core.Robot, n_targets: int):
        doc = json.loads(robot.to_json())
        spec = doc["nominal"]
        self.w0 = [np.asarray(j["axis"], float) / np.linalg.norm(j["axis"]) for j in spec["joints"]]
        self.p0 = [np.asarray(j["point_mm"], float) for j in spec["joints"]]
        self.u = [_unit_orthogonal(w) for w in self.w0]
        self.v = [np.cross(w, u) for w, u in zip(self.w0, self.u)]
        self.mass = [float(j["mass_kg"]) for j in spec["joints"]]
        self.com = [np.asarray(j["com_mm"], float) for j in spec["joints"]]
        self.mp = float(spec["payload"]["mass_kg"])
        self.pc = np.asarray(spec["payload"]["com_mm"], float)
        self.g = np.asarray(spec["gravity_m_s2"], float)
        self.rm0 = _core.abc_to_rotation(np.asarray(spec["tool"]["abc_deg"], float))
        self.tm0 = np.asarray(spec["tool"]["xyz_mm"], float)
        # the placements are relative to the robot's campaign (PointModel's, from a nominal robot)
        b = doc["campaign"]["base_in_instrument"]
        self.rb0 = _core.abc_to_rotation(np.asarray(b["abc_deg"], float))
        self.tb0 = np.asarray(b["xyz_mm"], float)
        self.names = list(_core.PointModel(robot, n_targets).names)
        self.n = len(self.w0)
        self.loaded = [int(nm.split(".")[0][5:]) - 1 for nm in self.names if nm.endswith(".compliance")]

    def _chain(self, q, w, p):
        """Frames G_j (j = 0..n): rotations (n+1, N, 3, 3) and translations (n+1, N, 3)."""
        N = len(q)
        gr = [np.broadcast_to(np.eye(3), (N, 3, 3))]
        gt = [np.zeros((N, 3))]
        for j in range(self.n):
            e = _rot(w[j], q[:, j])
            et = p[j] - e @ p[j]
            gt.append(np.einsum("nij,nj->ni", gr[-1], et) + gt[-1])
            gr.append(gr[-1] @ e)
        return gr, gt

    def residuals(self, x: np.ndarray, data: MeasurementSet) -> np.ndarray:
        x = np.asarray(x, float)
        n = self.n
        w = [(self.w0[j] + x[4 * j] * self.u[j] + x[4 * j + 1] * self.v[j]) for j in range(n)]
        w = [a / np.linalg.norm(a) for a in w]
        p = [self.p0[j] + x[4 * j + 2] * self.u[j] + x[4 * j + 3] * self.v[j] for j in range(n)]
        c0 = 4 * n
        comp = dict(zip(self.loaded, x[c0:c0 + len(self.loaded)]))
        k = c0 + len(self.loaded)
        tm = self.tm0 + x[k:k + 3]
        rm = self.rm0 @ _exp(x[k + 3:k + 6])
        tb = self.tb0 + x[k + 6:k + 9]
        rb = self.rb0 @ _exp(x[k + 9:k + 12])
        targets = x[k + 12:].reshape(-1, 3)
        q = np.radians(np.asarray(data.q_deg, float))
        if comp:
            # joint deflection under gravity at the commanded angles: tau_j = w_j . (arm_j x g)
            gr, gt = self._chain(q, w, p)
            cp = np.einsum("nij,j->ni", gr[n], rm @ self.pc + tm) + gt[n]
            S = self.mp * cp
            M = self.mp
            tau = np.zeros((len(q), n))
            for j in range(n - 1, -1, -1):
                S = S + self.mass[j] * (np.einsum("nij,j->ni", gr[j + 1], self.com[j]) + gt[j + 1])
                M = M + self.mass[j]
                wc = np.einsum("nij,j->ni", gr[j], w[j])
                oc = np.einsum("nij,j->ni", gr[j], p[j]) + gt[j]
                arm = S - M * oc
                tau[:, j] = np.einsum("ni,ni->n", wc, np.cross(arm, self.g))
            for j, c in comp.items():
                q = q.copy()
                q[:, j] += np.radians(c) / 1e6 * tau[:, j]
        gr, gt = self._chain(q, w, p)
        tk = targets[np.asarray(data.target, int)]
        x0 = (rm @ tk.T).T + tm
        pt = np.einsum("nij,nj->ni", gr[n], x0) + gt[n]
        y = (rb @ pt.T).T + tb
        return (y - np.asarray(data.xyz, float)).ravel()
