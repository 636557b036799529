"""Planning a calibration campaign (`kincal plan`): the K robot configurations that determine the
model's parameters best, inside the joint limits and the user's keep-out rules.

Criterion: D-optimality. The identification Jacobian of every candidate configuration (the rows of
its targets' points, at the nominal model) is computed in the C++ core; its columns are scaled to
unit RMS over the candidates, and the parameters that no choice of candidates can determine (those
the identifiability analysis of `kincal identify` fixes on the candidate pool, e.g. the tool frame
beside the target offsets) are left out. A greedy search then adds, K times, the candidate that most
increases log det of the information matrix M = sum J_i^T J_i (started at a small multiple of the
identity: a faint prior that keeps the first steps well posed). The gain of candidate i is
log det(I + J_i M^-1 J_i^T); with many candidates each step scores a random sample of them
(stochastic greedy, see greedy_d_optimal): 100,000 candidates to 60 poses in seconds.

Reported for the plan, on the unscaled parameters: the predicted standard deviation of each
parameter (noise sigma per coordinate, covariance sigma^2 (J^T J)^-1), the predicted RMS uncertainty
of a measured point at the candidates (the TCP uncertainty: what a held-out configuration's error
will be, noise aside), and the observability indices of the literature: O1 = (s_1 ... s_m)^(1/m) /
sqrt(n) over the singular values of the scaled Jacobian of the plan (n its rows), its condition
number and its smallest singular value.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Callable, Optional, Sequence, Union

import numpy as np

from .. import _core
from . import identify as ident
from .._core import Robot
from ..stats.grouping import subset
from .fitting import options

if TYPE_CHECKING:
    from .._core import MeasurementSet
    from ..typing_ import BoolArray, FloatArray, IntArray


@dataclass
class KeepOut:
    """Rules a candidate configuration must satisfy besides the joint limits.

    ``min_sigma``: the smallest singular value of the tool's Jacobian (angular rows times the
    robot's reach, so both are in mm per rad) at least this share of the largest (0..1): away from
    singularities. ``box``: xmin, xmax, ymin, ymax, zmin, zmax (mm, base frame) the TCP stays in.
    ``instrument``: the instrument's position (mm, base frame); then every target must be within
    ``max_range`` (mm) of it and seen at most ``max_incidence_deg`` off the tool's z axis (the
    reflector's normal)."""
    min_sigma: float = 0.0
    box: Optional[Sequence[float]] = None
    instrument: Optional[Sequence[float]] = None
    max_range: float = math.inf
    max_incidence_deg: float = 180.0


@dataclass
class Plan:
    """The chosen configurations (in path order) and what they promise."""
    q_deg: FloatArray
    parameters: list[str]             #: names of the parameters the plan determines
    stddev: FloatArray                #: predicted standard deviation of each (its unit in ``units``)
    units: list[str]
    left_out: list[tuple[str, str]]   #: (name, reason) of the parameters no candidate determines
    tcp_uncertainty_mm: float         #: predicted RMS error of a point predicted at the candidates
    o1: float
    condition_number: float
    min_singular_value: float
    candidates: int                   #: candidates after the keep-out rules
    rejected: dict[str, int] = field(default_factory=dict)  #: rule -> candidates it removed

    def summary(self, noise_mm: float) -> str:
        lines = [f"{len(self.q_deg)} configurations chosen from {self.candidates} candidates (D-optimal)"]
        for rule, n in self.rejected.items():
            lines.append(f"  {n} candidates removed: {rule}")
        lines.append(f"observability: O1 {self.o1:.4g}, condition number {self.condition_number:.4g}, "
                     f"smallest singular value {self.min_singular_value:.4g}")
        lines.append(f"predicted TCP uncertainty (RMS over the candidates, noise {noise_mm:g} mm per "
                     f"coordinate): {self.tcp_uncertainty_mm:.4f} mm")
        if self.left_out:
            lines.append("not determined by any candidate (held at the starting model):")
            lines += [f"  {n:<22} {why}" for n, why in self.left_out]
        lines.append("predicted standard deviation of each parameter:")
        lines += [f"  {n:<22} {s:.3g} {u}" for n, s, u in zip(self.parameters, self.stddev, self.units)]
        return "\n".join(lines)


def random_candidates(robot: Robot, n: int, seed: int = 0) -> FloatArray:
    """n configurations drawn uniformly inside the joint limits (deg)."""
    lim = np.asarray(robot.limits_deg, dtype=float)
    return np.random.default_rng(seed).uniform(lim[:, 0], lim[:, 1], size=(n, robot.dof))


def _tool_frames(robot: Robot, q: FloatArray) -> FloatArray:
    """(n, 4, 4) tool frames (mm) in the base frame at the nominal model (R = Rz(a) Ry(b) Rx(c))."""
    pose = np.asarray(_core.fk(robot, q, False, False)).reshape(-1, 6)
    a, b, c = np.radians(pose[:, 3]), np.radians(pose[:, 4]), np.radians(pose[:, 5])
    ca, sa, cb, sb, cc, sc = np.cos(a), np.sin(a), np.cos(b), np.sin(b), np.cos(c), np.sin(c)
    f = np.zeros((len(pose), 4, 4))
    f[:, 0, 0], f[:, 0, 1], f[:, 0, 2] = ca * cb, ca * sb * sc - sa * cc, ca * sb * cc + sa * sc
    f[:, 1, 0], f[:, 1, 1], f[:, 1, 2] = sa * cb, sa * sb * sc + ca * cc, sa * sb * cc - ca * sc
    f[:, 2, 0], f[:, 2, 1], f[:, 2, 2] = -sb, cb * sc, cb * cc
    f[:, :3, 3] = pose[:, :3]
    f[:, 3, 3] = 1.0
    return f


def keep_out(robot: Robot, q: FloatArray, targets: FloatArray, rules: KeepOut) -> tuple[BoolArray, dict[str, int]]:
    """Boolean mask of the candidates inside the joint limits and every rule, and how many each
    rule removed."""
    lim = np.asarray(robot.limits_deg, dtype=float)
    ok = np.all((q >= lim[:, 0]) & (q <= lim[:, 1]), axis=1)
    rejected = {"outside the joint limits": int(np.sum(~ok))}
    if rules.min_sigma <= 0 and rules.box is None and rules.instrument is None:
        return ok, {k: v for k, v in rejected.items() if v}  # no rule needs the tool frames
    frames = _tool_frames(robot, q)
    if rules.min_sigma > 0:
        reach = float(np.max(np.linalg.norm(frames[:, :3, 3], axis=1)))
        J = np.array([_core.jacobian(robot, qi, False) for qi in q])  # (n, 6, dof): linear, then angular rows
        J = np.concatenate([J[:, :3], J[:, 3:] * reach], axis=1)
        s = np.linalg.svd(J, compute_uv=False)
        bad = s[:, -1] < rules.min_sigma * s[:, 0]
        rejected[f"near a singularity (smallest/largest singular value below {rules.min_sigma:g})"] = int(np.sum(bad & ok))
        ok &= ~bad
    if rules.box is not None:
        b = np.asarray(rules.box, dtype=float).reshape(3, 2)
        p = frames[:, :3, 3]
        bad = np.any((p < b[:, 0]) | (p > b[:, 1]), axis=1)
        rejected["TCP outside the workspace box"] = int(np.sum(bad & ok))
        ok &= ~bad
    if rules.instrument is not None:
        inst = np.asarray(rules.instrument, dtype=float)
        pts = frames[:, None, :3, :3] @ targets[None, :, :, None]
        pts = pts[..., 0] + frames[:, None, :3, 3]                      # (n, targets, 3)
        d = inst[None, None, :] - pts
        dist = np.linalg.norm(d, axis=2)
        normal = frames[:, None, :3, 2]
        cos = np.sum(d * normal, axis=2) / np.maximum(dist, 1e-9)
        bad = np.any(dist > rules.max_range, axis=1)
        rejected[f"a target beyond the instrument's range ({rules.max_range:g} mm)"] = int(np.sum(bad & ok))
        ok &= ~bad
        bad = np.any(cos < math.cos(math.radians(rules.max_incidence_deg)), axis=1)
        rejected[f"a target seen more than {rules.max_incidence_deg:g} deg off its normal"] = int(np.sum(bad & ok))
        ok &= ~bad
    return ok, {k: v for k, v in rejected.items() if v}


def _campaign(robot: Robot, q: FloatArray, targets: FloatArray) -> MeasurementSet:
    """A noise-free campaign at the nominal model (the instrument at the base), for the Jacobian."""
    n, t = len(q), len(targets)
    frames = _tool_frames(robot, q)
    pts = (frames[:, None, :3, :3] @ targets[None, :, :, None])[..., 0] + frames[:, None, :3, 3]
    rows = n * t
    return _core.MeasurementSet({"pose": np.repeat(np.arange(n, dtype=np.int32), t), "q_deg": np.repeat(q, t, axis=0),
                                 "xyz": pts.reshape(rows, 3), "target": np.tile(np.arange(t, dtype=np.int32), n),
                                 "payload_kg": np.full(rows, np.nan), "line": np.zeros(rows, dtype=np.int32),
                                 "source": "<plan>"}, robot.dof)


def _jacobian(robot: Robot, q: FloatArray, targets: FloatArray, effects: list[_core.Effect],
              columns: Optional[IntArray] = None) -> tuple[FloatArray, list[_core.Parameter]]:
    """The identification Jacobian (rows: pose-major, target, coordinate) at the nominal model with
    the targets at their offsets, of every parameter or of ``columns`` (indices), and the layout's
    parameters."""
    data = _campaign(robot, q, targets)
    pm = _core.PointModel(robot, len(targets), [e for e in effects if not e.kind.gravity_loaded_only])
    params = list(pm.layout.parameters)
    # the start (the nominal model; base and targets fitted to these noise-free points) from the first
    # 500 candidates: the same to 1e-7 (the plan's TCP figure), in a fraction of the time of 100,000
    x = np.asarray(pm.start(data if len(q) <= 500 else _campaign(robot, q[:500], targets)), dtype=float)
    for p in params:
        if p.kind == "target":          # target<k>.x, .y, .z: absolute offsets on the tool
            x[p.index] = targets[p.target]["xyz".index(p.name[-1])]
    _, J = pm.residuals(list(x), data, True, columns=None if columns is None else [int(c) for c in columns])
    return np.asarray(J), params


def _free_columns(robot: Robot, q: FloatArray, targets: FloatArray, effects: list[_core.Effect],
                  seed: int) -> tuple[IntArray, list[tuple[str, str]]]:
    """The columns no candidate set can leave undetermined: identify's identifiability analysis on
    (up to 2,000 of) the candidates; the others with identify's reason."""
    rng = np.random.default_rng(seed)
    sub = q[rng.choice(len(q), size=min(len(q), 2000), replace=False)]
    data = _campaign(robot, sub, targets)
    res = _core.identify(robot, data, options(effects, loss="none", max_iterations=0, covariance=False))
    fixed = np.asarray(res.fixed)
    compliance = any(e.kind.gravity_loaded_only for e in effects)
    free: list[int] = []
    left: list[tuple[str, str]] = []
    for p, fx, why in zip(res.layout.parameters, fixed, res.fixed_reason):
        if p.kind == "compliance" and not compliance:
            continue
        if fx:
            left.append((p.name, why))
        else:
            free.append(p.index)
    return np.asarray(free, dtype=int), left


def greedy_d_optimal(J: FloatArray, rows_per: int, k: int, ridge: float = 1e-3, epsilon: float = 0.01,
                     seed: int = 0, progress: Optional[Callable[[int, int], None]] = None,
                     col_scale: Optional[FloatArray] = None) -> list[int]:
    """Indices of k candidates (J: candidates' rows in blocks of rows_per, columns scaled, or divided by
    ``col_scale`` here without changing J) chosen one at a time for the largest gain
    log det(I + J_i M^-1 J_i^T), M = ridge I + the chosen J_i^T J_i.

    Each step scores a random sample of the candidates left, of size (n / k) ln(1 / epsilon) but at
    least 2,000 (all of them when fewer): the "stochastic greedy" of Mirzasoleiman et al. (AAAI 2015),
    within 1 - 1/e - epsilon of the optimum in expectation for this submodular criterion, and the
    plain greedy when the sample is every candidate. M^-1 follows each choice by the Woodbury
    identity; a gain is log det of a small matrix from the rows times the Cholesky factor of M^-1,
    computed by the core (d_optimal_gains) on its threads in single precision."""
    n, p = J.shape[0] // rows_per, J.shape[1]
    Jb = J.reshape(n, rows_per, p)
    cs = np.ones(p) if col_scale is None else np.asarray(col_scale, dtype=float)
    # for scoring only, the ranking needs no more digits: converted, then scaled in single precision
    Jb32 = Jb.astype(np.float32)
    Jb32 *= (1.0 / cs).astype(np.float32)
    eye = np.eye(rows_per)
    rng = np.random.default_rng(seed)
    sample = min(n, max(2000, int(math.ceil(n / k * math.log(1.0 / epsilon)))))
    Minv = np.eye(p) / ridge
    left = np.ones(n, dtype=bool)
    chosen: list[int] = []
    for step in range(k):
        if progress:
            progress(step, k)
        pool = np.flatnonzero(left)
        idx = pool if len(pool) <= sample else np.sort(rng.choice(pool, size=sample, replace=False))
        L = np.linalg.cholesky(Minv).astype(np.float32)
        gain = _core.d_optimal_gains(Jb32, idx, L)  # log det(I + A A^T), A = J_i L, on the core's threads
        best = int(idx[int(np.argmax(gain))])
        chosen.append(best)
        left[best] = False
        Jc = Jb[best] / cs
        U = Minv @ Jc.T                                    # Woodbury: M'^-1 = M^-1 - U (I + J U)^-1 U^T
        Minv = Minv - U @ np.linalg.solve(eye + Jc @ U, U.T)
        Minv = 0.5 * (Minv + Minv.T)
    return chosen


def path_order(q: FloatArray) -> IntArray:
    """An order of the configurations for a short robot path: nearest neighbour in joint space,
    starting from the one nearest to the middle of the set."""
    left = list(range(len(q)))
    cur = int(np.argmin(np.linalg.norm(q - q.mean(axis=0), axis=1)))
    order = [cur]
    left.remove(cur)
    while left:
        d = np.linalg.norm(q[left] - q[cur], axis=1)
        cur = left.pop(int(np.argmin(d)))
        order.append(cur)
    return np.asarray(order)


def plan(robot: Robot, k: int, *, targets: FloatArray,
         effects: Union[str, Sequence[Union[str, _core.Effect]]] = ("joint_compliance",),
         candidates: Optional[FloatArray] = None, n_candidates: int = 5000, rules: KeepOut = KeepOut(),
         noise_mm: float = 0.02, seed: int = 0,
         progress: Optional[Callable[[int, int], None]] = None) -> Plan:
    """The K configurations of a campaign (see the module's text). ``targets``: the reflectors'
    offsets on the tool (mm, one row each); ``candidates``: the configurations to choose from (deg),
    or ``n_candidates`` random ones inside the joint limits."""
    targets = np.asarray(targets, dtype=float).reshape(-1, 3)
    # the core's effects (check_effects passes a JointCompliance through, which this plan cannot take)
    core_effects = [e for e in ident.check_effects(effects, robot) if isinstance(e, _core.Effect)]
    if noise_mm <= 0 or not math.isfinite(noise_mm):
        raise ValueError(f"--noise must be a positive number of mm, not {noise_mm}")
    q = random_candidates(robot, n_candidates, seed) if candidates is None else np.asarray(candidates, dtype=float)
    if q.ndim != 2 or q.shape[1] != robot.dof:
        raise ValueError(f"the candidates need {robot.dof} joint angles each")
    ok, rejected = keep_out(robot, q, targets, rules)
    q = q[ok]
    if k < 1:
        raise ValueError(f"--poses must be at least 1, not {k}")
    if len(q) < k:
        raise ValueError(f"only {len(q)} candidates satisfy the joint limits and the keep-out rules, fewer than "
                         f"the {k} poses asked for (" + "; ".join(f"{v} {r}" for r, v in rejected.items()) + ")")
    free, left = _free_columns(robot, q, targets, list(core_effects), seed)
    J, params = _jacobian(robot, q, targets, list(core_effects), free)
    # columns scaled to unit RMS per candidate: a candidate's rows are O(1), the ridge a faint prior
    # (the greedy scales its float32 copy as it makes it: with 100,000 candidates J is hundreds of MB)
    scale = np.sqrt(np.einsum("ij,ij->j", J, J) / len(q))  # (no temporary as large as J)
    if np.any(scale == 0):
        raise ValueError("a parameter has no effect on any candidate")
    rows_per = 3 * len(targets)
    picked = greedy_d_optimal(J, rows_per, k, seed=seed, progress=progress, col_scale=scale)
    chosen = np.asarray(picked)[path_order(q[picked])]
    rows = (chosen[:, None] * rows_per + np.arange(rows_per)[None, :]).ravel()
    Jp = J[rows]
    s = np.linalg.svd(Jp / scale, compute_uv=False)
    info = Jp.T @ Jp
    cov = noise_mm ** 2 * np.linalg.pinv(info)
    # predicted error of a point at the candidates (up to 20,000 of them): the rows' variance, as the
    # RMS of the point's error
    some = np.random.default_rng(seed + 1).choice(len(q), size=min(len(q), 20000), replace=False)
    Js = J[(some[:, None] * rows_per + np.arange(rows_per)[None, :]).ravel()]
    var_rows = np.sum((Js @ cov) * Js, axis=1)
    tcp = math.sqrt(float(np.sum(var_rows)) / (len(var_rows) / 3))
    m = len(s)
    o1 = float(np.exp(np.mean(np.log(np.maximum(s, 1e-300))))) / math.sqrt(Jp.shape[0])
    free_params = [params[i] for i in free]
    return Plan(q_deg=q[chosen], parameters=[p.name for p in free_params], stddev=np.sqrt(np.diag(cov)),
                units=[p.unit for p in free_params], left_out=left, tcp_uncertainty_mm=tcp, o1=o1,
                condition_number=float(s[0] / s[-1]) if m and s[-1] > 0 else math.inf,
                min_singular_value=float(s[-1]) if m else 0.0, candidates=int(len(q)), rejected=rejected)


def select_observable(robot: Robot, candidates: MeasurementSet, poses: int,
                      compliance: bool = True) -> MeasurementSet:
    """Choose ``poses`` of the candidate campaign's poses that maximise observability: greedy
    D-optimal design on the nominal model's identification Jacobian (unit-scaled columns of the
    parameters a generic campaign identifies), each step adding the pose that most increases
    log det of the information matrix. Returns the chosen rows."""
    n_targets = int(np.max(candidates.target)) + 1
    res = _core.identify(robot, candidates, _core.IdentifyOptions(compliance=compliance, loss="none", max_iterations=0,
                                                                  covariance=False))
    free = ~np.asarray(res.fixed)
    pm = _core.PointModel(robot, n_targets)
    _, J = pm.residuals(list(res.x), candidates, True)
    J = np.asarray(J)[:, free]
    J = J / np.maximum(np.linalg.norm(J, axis=0), 1e-300)
    ids = np.unique(candidates.pose)
    if poses >= len(ids):
        return candidates
    rows_of = {int(i): np.repeat(np.flatnonzero(candidates.pose == i) * 3, 3) + np.tile([0, 1, 2],
               int(np.sum(candidates.pose == i))) for i in ids}
    p = J.shape[1]
    info = 1e-6 * np.eye(p)
    chosen: list[int] = []
    left = [int(i) for i in ids]
    for _ in range(poses):
        inv = np.linalg.inv(info)
        best, gain = left[0], -np.inf
        for i in left:
            Ji = J[rows_of[i]]
            # log det(I + Ji inv Ji^T): the information this pose adds
            g = np.linalg.slogdet(np.eye(len(Ji)) + Ji @ inv @ Ji.T)[1]
            if g > gain:
                best, gain = i, g
        chosen.append(best)
        left.remove(best)
        info += J[rows_of[best]].T @ J[rows_of[best]]
    return subset(candidates, np.isin(candidates.pose, chosen))
