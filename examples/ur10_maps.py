"""An independent check of issue 14's UR10 targets: smooth per-joint angle-error maps on top of
geometry and compliance, fitted on one series only, predicting the others (only the tracker
placement and the probe offset refitted, by `kincal.identify.validate`).

    .venv/bin/python examples/ur10_maps.py [DATA_DIR] [--fit B] [--knots 24]

The maps are outside kincal's model: each joint's angle error is a periodic cubic B-spline of its
angle (``--knots`` per turn), applied to the commanded angles (q + f(q)) before the model sees them.
Their coefficients are a linearised least-squares fit to the residual of the fit series (the
point's Jacobian with respect to each joint angle, by finite differences of the model's points),
penalised by lambda |second differences|^2 + mu |coefficients|^2; then the model is refitted on the
corrected angles and the maps re-estimated (two rounds). lambda and mu are chosen on the fit series
alone, by a blocked cross-validation (each joint's angle range cut into 5 contiguous blocks, each
held out in turn: the maps asked for angles the fit did not see, as the other series ask); the
grouped 5-fold figure (whole configurations per fold) is printed beside it. The held-out series are
never used for any choice."""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import Optional

import numpy as np

import kincal
from kincal import _core
from kincal.io import datasets
from kincal.stats import grouping
from kincal.calibration import identify as ident
from kincal.diagnose.residual_vars import gravity_torques

SERIES = {"A": "Series_A/measurements_grid.csv", "B": "Series_B/measurements_joint_configurations.csv",
          "C": "Series_C/measurements_random_poses.csv", "D": "Series_D/measurements_iso_cubes.csv"}
REACH = 2000.0  # mm: the reference points that recover each predicted point from its distances


def predicted(model, targets, data: _core.MeasurementSet) -> np.ndarray:
    """The model's predicted points (instrument frame, n x 3), every effect acting: recovered from
    point_errors against four reference points (the origin and REACH along each axis)."""
    sq = []
    for off in (np.zeros(3), np.array([REACH, 0, 0]), np.array([0, REACH, 0]), np.array([0, 0, REACH])):
        d = data.with_columns(xyz=np.zeros_like(data.xyz) + off)
        sq.append(np.asarray(_core.point_errors(model, targets, d)) ** 2)
    return np.column_stack([(sq[0] - sq[k] + REACH ** 2) / (2 * REACH) for k in (1, 2, 3)])


def basis(q: np.ndarray, knots: int) -> np.ndarray:
    """Periodic cubic B-splines of the angle (deg, period 360) with ``knots`` knots: n x knots."""
    t = np.mod(q + 180.0, 360.0) / 360.0 * knots
    i = np.floor(t).astype(int)
    u = t - i
    b = np.zeros((len(q), knots))
    w = [(1 - u) ** 3 / 6, (3 * u ** 3 - 6 * u ** 2 + 4) / 6, (-3 * u ** 3 + 3 * u ** 2 + 3 * u + 1) / 6, u ** 3 / 6]
    for k in range(4):
        np.add.at(b, (np.arange(len(q)), (i - 1 + k) % knots), w[k])
    return b


def torque_basis(tau: np.ndarray, lo: float, hi: float, knots: int) -> np.ndarray:
    """Cubic B-splines of a gravity torque over [lo, hi] (the fit series' range; a torque outside it
    is clipped to it: the map extrapolates as a constant): n x (knots + 3)."""
    t = (np.clip(tau, lo, hi) - lo) / (hi - lo) * knots
    i = np.minimum(np.floor(t).astype(int), knots - 1)
    u = t - i
    b = np.zeros((len(tau), knots + 3))
    w = [(1 - u) ** 3 / 6, (3 * u ** 3 - 6 * u ** 2 + 4) / 6, (-3 * u ** 3 + 3 * u ** 2 + 3 * u + 1) / 6, u ** 3 / 6]
    for k in range(4):
        b[np.arange(len(tau)), i + k] += w[k]
    return b


def open_differences(n: int) -> np.ndarray:
    d = np.zeros((n - 2, n))
    for i in range(n - 2):
        d[i, i:i + 3] = (1.0, -2.0, 1.0)
    return d.T @ d


def second_differences(knots: int) -> np.ndarray:
    d = np.zeros((knots, knots))
    for i in range(knots):
        d[i, i], d[i, (i - 1) % knots], d[i, (i + 1) % knots] = -2.0, 1.0, 1.0
    return d.T @ d


def with_q(data: _core.MeasurementSet, q: np.ndarray) -> _core.MeasurementSet:
    return data.with_columns(q_deg=q)


class Maps:
    """Each joint's angle error: a periodic spline of its angle (``knots`` per turn), plus, with
    ``torque_knots``, a spline of its gravity torque on the gravity-loaded joints 2 and 3 (a
    stiffness that is not linear; torques of the nominal robot at the commanded angles, clipped to
    the fit series' range ``ranges``)."""

    def __init__(self, robot, knots: int, torque_knots: int = 0, ranges: Optional[dict] = None):
        self.robot, self.knots, self.torque_knots = robot, knots, torque_knots
        self.loaded = [1, 2] if torque_knots else []
        self.ranges = ranges or {}

    def torques(self, data: _core.MeasurementSet) -> np.ndarray:
        return gravity_torques(self.robot, data.q_deg) / 1000.0  # kN m

    def fix_ranges(self, data: _core.MeasurementSet) -> None:
        tau = self.torques(data)
        self.ranges = {j: (float(tau[:, j].min()), float(tau[:, j].max())) for j in self.loaded}

    def blocks(self, data: _core.MeasurementSet) -> list:
        """Per joint, the basis (n x m_j) of its angle error."""
        tau = self.torques(data) if self.loaded else None
        out = []
        for j in range(data.q_deg.shape[1]):
            b = basis(data.q_deg[:, j], self.knots)
            if j in self.loaded:
                b = np.hstack([b, torque_basis(tau[:, j], *self.ranges[j], self.torque_knots)])
            out.append(b)
        return out

    def penalty(self, lam: float, mu: float) -> np.ndarray:
        mats = []
        for j in range(self.robot.dof):
            m = lam * second_differences(self.knots) + mu * np.eye(self.knots)
            if j in self.loaded:
                n = self.torque_knots + 3
                t = lam * open_differences(n) + mu * np.eye(n)
                m = np.block([[m, np.zeros((self.knots, n))], [np.zeros((n, self.knots)), t]])
            mats.append(m)
        size = sum(len(m) for m in mats)
        out, k = np.zeros((size, size)), 0
        for m in mats:
            out[k:k + len(m), k:k + len(m)] = m
            k += len(m)
        return out

    def corrected(self, data: _core.MeasurementSet, coef: np.ndarray) -> _core.MeasurementSet:
        q, k = data.q_deg.copy(), 0
        for j, b in enumerate(self.blocks(data)):
            q[:, j] += b @ coef[k:k + b.shape[1]]
            k += b.shape[1]
        return with_q(data, q)

    def design(self, model, targets, data: _core.MeasurementSet) -> tuple:
        """The residual (3 per point) and the maps' columns (the points' derivatives, mm per deg)."""
        p0 = predicted(model, targets, data)
        cols = []
        for j, b in enumerate(self.blocks(data)):
            q = data.q_deg.copy()
            q[:, j] += 1e-3
            jac = (predicted(model, targets, with_q(data, q)) - p0) / 1e-3
            cols.append((jac[:, :, None] * b[:, None, :]).reshape(-1, b.shape[1]))
        return (data.xyz - p0).reshape(-1), np.hstack(cols)


def cv_rms(a: np.ndarray, y: np.ndarray, pen: np.ndarray, masks: list) -> float:
    e = []
    for m in masks:
        rows = np.repeat(m, 3)
        c = np.linalg.solve(a[~rows].T @ a[~rows] + pen, a[~rows].T @ y[~rows])
        e.append(y[rows] - a[rows] @ c)
    return float(np.sqrt(np.mean(np.sum(np.concatenate(e).reshape(-1, 3) ** 2, axis=1))))


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("data", nargs="?", default=str(Path(__file__).resolve().parents[1] / ".." / "shared" / "data" /
                                                  "ipa-robot-accuracy"))
    p.add_argument("--fit", default="B", choices=sorted(SERIES))
    p.add_argument("--knots", type=int, default=24)
    p.add_argument("--torque-knots", type=int, default=0,
                   help="also a spline of the gravity torque of joints 2 and 3 (0: none)")
    p.add_argument("--penalty", metavar="LAMBDA,MU", help="this penalty instead of the blocked cross-validation's")
    args = p.parse_args()
    robot = kincal.load_robot("ur10")
    series = {k: datasets.read_ipa(Path(args.data) / v) for k, v in SERIES.items()}
    fit_data = series[args.fit]
    maps = Maps(robot, args.knots, args.torque_knots)
    maps.fix_ranges(fit_data)
    start = ident.identify(robot, fit_data, effects="joint_compliance", k_folds=0)
    y, a = maps.design(start.robot, start.targets, fit_data)
    print(f"series {args.fit}, geometry + compliance: RMS {start.fit.rms_mm:.4f} mm (fitted)")
    folds = grouping.folds(fit_data, 5, 0)
    blocked = []
    for j in range(fit_data.q_deg.shape[1]):
        edges = np.quantile(fit_data.q_deg[:, j], np.linspace(0, 1, 6))
        blocked += [(fit_data.q_deg[:, j] >= edges[b]) & (fit_data.q_deg[:, j] <= edges[b + 1]) for b in range(5)]
    scores = {}
    given = None
    if args.penalty:
        try:
            lam, mu = (float(x) for x in args.penalty.split(","))
        except ValueError:
            p.error(f"--penalty {args.penalty}: expected LAMBDA,MU (two numbers)")
        given = (lam, mu)
    for lam in ((given[0],) if given else (1e0, 1e2, 1e4)):
        for mu in ((given[1],) if given else (1e1, 1e2, 1e3, 1e4, 1e5)):
            pen = maps.penalty(lam, mu)
            scores[(lam, mu)] = (cv_rms(a, y, pen, folds), cv_rms(a, y, pen, blocked))
            print(f"lambda {lam:g}, mu {mu:g}: grouped 5-fold RMS {scores[(lam, mu)][0]:.4f} mm, blocked by angle "
                  f"{scores[(lam, mu)][1]:.4f} mm")
    lam, mu = min(scores, key=lambda k: scores[k][1])
    pen = maps.penalty(lam, mu)
    print(f"{'given' if args.penalty else 'chosen by the blocked cross-validation on ' + args.fit}: lambda {lam:g}, "
          f"mu {mu:g}")
    coef = np.linalg.solve(a.T @ a + pen, a.T @ y)
    for _ in range(2):  # the model refitted on the corrected angles, the maps re-estimated on its residual
        model = ident.identify(robot, maps.corrected(fit_data, coef), effects="joint_compliance", k_folds=0)
        y, a = maps.design(model.robot, model.targets, maps.corrected(fit_data, coef))
        coef = coef + np.linalg.solve(a.T @ a + pen, a.T @ y)
    model = ident.identify(robot, maps.corrected(fit_data, coef), effects="joint_compliance", k_folds=0)
    print(f"series {args.fit} with the maps: RMS {model.fit.rms_mm:.4f} mm (fitted)")
    shift = np.stack([maps.corrected(s_, coef).q_deg - s_.q_deg for s_ in (fit_data,)])[0]
    for j in range(robot.dof):
        print(f"  joint {j + 1} correction on {args.fit}: {shift[:, j].min():+.4f} .. {shift[:, j].max():+.4f} deg")
    for k in sorted(SERIES):
        if k != args.fit:
            v0 = ident.validate(start.robot, series[k])
            v = ident.validate(model.robot, maps.corrected(series[k], coef))
            print(f"series {k}: geometry + compliance {v0['rms_mm']:.3f} mm RMS; with the maps {v['rms_mm']:.3f} mm "
                  f"(mean {v['mean_mm']:.3f}, max {v['max_mm']:.3f}; per axis, the RMS of every x, y and z "
                  f"residual: {v['rms_mm'] / np.sqrt(3):.3f} mm)")


if __name__ == "__main__":
    main()
