"""Grouped validation: which rows of a measurement set repeat one robot configuration, and splits and
folds that keep every configuration whole.

Real campaigns measure each configuration several times to average the tracker's noise. A split of
rows would put repeats of one configuration on both sides: the model then "predicts" points it was
fitted on and the held-out error is too good. Here a configuration is
- the rows that share a ``config`` column value, when the data have that column;
- otherwise the rows whose joint angles agree within ``JOINT_TOLERANCE_DEG`` on every joint;
and in both cases the rows of one ``pose`` id (the targets measured in one configuration) are one
configuration, whatever the other rule says.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:
    from .._core import MeasurementSet
    from ..typing_ import BoolArray, FloatArray, IntArray

#: joint angles that agree within this (deg) on every joint are one configuration
JOINT_TOLERANCE_DEG = 1e-3


def subset(data: MeasurementSet, mask: BoolArray) -> MeasurementSet:
    """The rows ``mask`` of a measurement set (its other entries as they are)."""
    return data.subset(mask)


@dataclass(frozen=True)
class Configurations:
    """The configuration (group) of every row: ``codes`` (0..count-1, in order of first appearance),
    ``count`` and ``rule`` (how they were found, in words for the summary and the JSON)."""
    codes: IntArray
    count: int
    rule: str


def _components(n: int, a: IntArray, b: IntArray) -> IntArray:
    """Connected components of n nodes joined by the edges (a[i], b[i]), labelled in order of first
    appearance. Each node takes the smallest label among its edges' ends, and then its label's label
    (pointer jumping), until nothing changes: every label stays a node of the same component, and at
    the end both ends of every edge carry one label (numpy only: scipy.sparse's graph routines cost
    a third of a second to import, more than the whole grouping of a campaign)."""
    lab = np.arange(n)
    a = np.asarray(a, dtype=np.int64)
    b = np.asarray(b, dtype=np.int64)
    while True:
        low = np.minimum(lab[a], lab[b])
        new = lab.copy()
        np.minimum.at(new, a, low)
        np.minimum.at(new, b, low)
        new = new[new]
        if np.array_equal(new, lab):
            break
        lab = new
    _, first, inverse = np.unique(lab, return_index=True, return_inverse=True)
    order = np.argsort(np.argsort(first))
    return order[inverse]


def _equal_joints(q: FloatArray, tol: float) -> tuple[IntArray, IntArray]:
    """Pairs of rows (i, j) whose joint angles agree within tol on every joint. Rows are sorted by a
    weighted mean of their angles (weights positive, summing to 1: rows that agree within tol on
    every joint agree within tol on it, and distinct configurations sharing one joint's angle, as on
    task data, still differ), each compared with the following ones while that key is within tol."""
    n = len(q)
    w = np.linspace(1.0, 2.0, q.shape[1]) / np.sum(np.linspace(1.0, 2.0, q.shape[1]))
    key = q @ w
    order = np.argsort(key, kind="stable")
    qs, ks = q[order], key[order]
    a_out, b_out = [], []
    for d in range(1, n):
        near = ks[d:] - ks[:-d] <= tol
        if not near.any():
            break
        same = near & np.all(np.abs(qs[d:] - qs[:-d]) <= tol, axis=1)
        idx = np.flatnonzero(same)
        a_out.append(order[idx])
        b_out.append(order[idx + d])
    if not a_out:
        return np.zeros(0, dtype=np.int64), np.zeros(0, dtype=np.int64)
    return np.concatenate(a_out), np.concatenate(b_out)


def configurations(data: MeasurementSet, tol_deg: float = JOINT_TOLERANCE_DEG) -> Configurations:
    """The configuration of every row of a measurement set (see the module's text)."""
    pose = np.asarray(data.pose)
    n = len(pose)
    if n == 0:
        return Configurations(np.zeros(0, dtype=np.int64), 0, "no rows")
    # rows of one pose id are one configuration: join each row to the first row of its pose
    _, first_of_pose, pose_code = np.unique(pose, return_index=True, return_inverse=True)
    a, b = [np.arange(n)], [first_of_pose[pose_code]]
    if data.config is not None:
        cfg = np.asarray(data.config)
        _, first_of_cfg, cfg_code = np.unique(cfg, return_index=True, return_inverse=True)
        a.append(np.arange(n))
        b.append(first_of_cfg[cfg_code])
        rule = "rows sharing a config value"
    else:
        ea, eb = _equal_joints(np.asarray(data.q_deg, dtype=float), tol_deg)
        a.append(ea)
        b.append(eb)
        rule = f"rows with equal joint angles (within {tol_deg:g} deg)"
    codes = _components(n, np.concatenate(a), np.concatenate(b))
    return Configurations(codes, int(codes.max()) + 1, rule)


def folds(data: MeasurementSet, k: int, seed: int = 0) -> list[BoolArray]:
    """k boolean masks of held-out rows: whole configurations dealt at random into k folds."""
    cfg = configurations(data)
    if k > cfg.count:
        raise ValueError(f"{data.source}: {k} folds need at least {k} configurations; the data "
                         f"have {cfg.count} ({cfg.rule})")
    perm = np.random.default_rng(seed).permutation(cfg.count)
    fold_of = np.empty(cfg.count, dtype=np.int64)
    fold_of[perm] = np.arange(cfg.count) % k
    return [fold_of[cfg.codes] == i for i in range(k)]


def split(data: MeasurementSet, share: float, seed: int = 0) -> tuple[BoolArray, BoolArray]:
    """Boolean row masks (fitted, held out): a random share of the configurations is held out whole."""
    cfg = configurations(data)
    n_out = int(round(share * cfg.count))
    out = np.random.default_rng(seed).choice(cfg.count, size=n_out, replace=False)
    held = np.isin(cfg.codes, out)
    return ~held, held


def describe(data: MeasurementSet, scheme: str) -> dict[str, Any]:
    """The validation scheme for a summary and a JSON: ``scheme`` (e.g. "5-fold"), the grouping rule
    and the number of configurations."""
    cfg = configurations(data)
    return {"scheme": f"{scheme}, whole configurations", "grouping": cfg.rule, "configurations": cfg.count}
