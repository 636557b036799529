"""Planning a probe campaign (`kincal plan --kind sphere|plane|distance`): the orientations to touch
each station with, and the accuracy they promise.

The stations are placed as `kincal simulate --kind` places them (spheres and pivots in reach, a
block's top, the face towards the robot, its sideways faces and the surface plate it stands on), and
every station gets a pool of candidate touches: the probe's axis within the cone, the commanded
angles by inverse kinematics on the robot's model, inside its limits and away from singularities.
From the pool the plan takes ``touches`` per station, one station after the other in turns, each
time the candidate that most increases log det of the information matrix (Bayesian D-optimality)

    M = P + A^T A / sigma^2 + sum over the chosen touches J_i^T J_i / sigma^2

where J_i are the identification Jacobian's rows of the touch (3 for a sphere, 1 for a plane or a
ballbar; the same residuals as `kincal identify`), A the artifact's terms (its lengths and angles;
the core weighs them as one row of the data each), P the priors of `kincal identify`
(1 / sd^2 of every parameter with a prior) and sigma the probe's noise along each constraint. The
parameters that the identifiability analysis holds on the whole pool (e.g. the base frame, which the
stations' unknowns absorb) are left out.

The predicted TCP uncertainty is the ball centre's error over the configurations given (or random
ones inside the limits) that the probe's noise leaves in the MAP estimate (its covariance
M^-1 (M - P) M^-1), after the best rigid transform: the part of the error that a rigid motion of the
whole set explains is projected out, as the accuracy figure removes it (the base frame is free in
these data). Its RMS over the configurations is a weighted sum of chi-square variables; the median
and the 90th percentile over repeated campaigns are reported. Apart: what the priors decide, the
error of a robot one prior sd off the priors' centre (M^-1 P M^-1), large where the touches do not
determine the model (a missing known length); and the same noise figure for the first ``touches``
candidates of each station (random touches), what the plan gains over touching at random.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, Callable, Literal, Optional, Sequence, Union

import numpy as np

from .. import _core
from .._core import Robot
from . import identify as ident
from . import simulation as sim
from .fitting import options
from .plan import KeepOut, _tool_frames, keep_out, path_order

if TYPE_CHECKING:
    from .._core import MeasurementSet
    from ..typing_ import FloatArray, IntArray

Kind = Literal["sphere", "plane", "distance"]
#: a candidate's tool Jacobian: its smallest singular value at least this share of its largest
MIN_SIGMA = 0.02
#: rows of the identification's residual per touch of each kind (the constraint's equations)
EQUATIONS = {"sphere": 3, "plane": 1, "distance": 1}


@dataclass
class ProbePlan:
    """The chosen touches (a measurement set without measurements: q_deg, kind, station, radius,
    length and the artifact of the stations as placed) and what they promise."""
    kind: str
    data: MeasurementSet
    tcp_uncertainty_mm: float         #: predicted RMS of the ball centre over the configurations, rigid part removed (median)
    tcp_uncertainty_p90_mm: float     #: its 90th percentile over repeated campaigns
    priors_tcp_mm: float              #: the same (median) for a robot one prior sd off the priors' centre, noise aside
    random_tcp_uncertainty_mm: float  #: the same for touches drawn at random from the pools
    configurations: int               #: how many configurations the predictions are over
    candidates: int                   #: candidate touches per station
    parameters: list[str]
    stddev: FloatArray                #: predicted standard deviation of each parameter (core units)
    units: list[str]
    left_out: list[tuple[str, str]]   #: (name, reason) of the parameters held on the whole pool

    def summary(self, noise_mm: float) -> str:
        names = self.data.station_names or []
        counts = np.bincount(np.asarray(self.data.station), minlength=len(names))
        lines = [f"{len(self.data)} {self.kind} touches at {len(names)} stations ("
                 + ", ".join(f"{n}: {c}" for n, c in zip(names, counts)) + f"), chosen from {self.candidates} "
                 "candidates each (D-optimal, with identify's priors)",
                 f"predicted TCP uncertainty (the ball centre, RMS over {self.configurations} configurations after "
                 f"the best rigid transform, probe noise {noise_mm:g} mm): {self.tcp_uncertainty_mm:.4f} mm in "
                 f"the median campaign, {self.tcp_uncertainty_p90_mm:.4f} mm in 9 of 10 (random touches: "
                 f"{self.random_tcp_uncertainty_mm:.4f} mm)",
                 f"left to the priors: {self.priors_tcp_mm:.4f} mm more where the robot is one prior sd off them"
                 + (" (these touches do not determine the model: add stations, a known length or orientations)"
                    if self.priors_tcp_mm > self.tcp_uncertainty_mm else "")]
        if self.left_out:
            lines.append("held on every candidate (not determined by these data):")
            lines += [f"  {n:<22} {why}" for n, why in self.left_out]
        return "\n".join(lines)


def ball_centres(robot: Robot, q: FloatArray, offset: Union[Sequence[float], FloatArray]) -> FloatArray:
    """The ball centres (``offset``: mm in the tool frame) of a robot's calibrated model at q (deg),
    base frame, every joint's last motion positive (a backlash reads it)."""
    q = np.asarray(q, dtype=float)
    p = np.asarray(_core.fk(robot, q, True, False, np.ones_like(q)))
    out: FloatArray = p[:, :3] + np.array([_core.abc_to_rotation(abc) for abc in p[:, 3:]]) @ np.asarray(offset, dtype=float)
    return out


def rigid_rms(a: FloatArray, b: FloatArray) -> float:
    """RMS distance of the points a from b after the best rigid transform of a onto b (the core's
    Horn fit): the accuracy of a probe calibration, whose data do not see the base frame."""
    m = np.asarray(_core.rigid_fit(a, b))
    return float(np.sqrt(np.mean(np.sum((a @ m[:3, :3].T + m[:3, 3] - b) ** 2, axis=1))))


def _subset(data: MeasurementSet, rows: IntArray) -> MeasurementSet:
    """The rows ``rows`` of a measurement set, numbered again from 0 (its other entries as they are)."""
    return data.subset(rows).with_columns(pose=np.arange(len(rows), dtype=np.int32))


def _whitened_rows(J: FloatArray, data: MeasurementSet, sigma: float) -> tuple[FloatArray, IntArray]:
    """The Jacobian's rows of each touch (residual_size rows per row in J, the constraint's
    equations first) divided by the noise, as (touches, equations, columns), and each touch's
    station."""
    n = len(data.pose)
    eq = {EQUATIONS[k] for k in data.station_kinds or []}
    if len(eq) != 1:
        raise ValueError("plan: one kind of station per plan")
    e = eq.pop()
    size = J.shape[0] // n
    return J.reshape(n, size, -1)[:, :e, :] / sigma, np.asarray(data.station, dtype=int)


def _ball_jacobian(robot: Robot, q: FloatArray, probe: FloatArray, effects: list[_core.Effect],
                   names: list[str]) -> FloatArray:
    """d(ball centre)/d(parameter) at the configurations q (rows: configuration-major, x y z) for the
    parameters ``names`` (the probe layout's; columns absent from a point layout are 0)."""
    frames = _tool_frames(robot, q)
    pts = frames[:, :3, :3] @ probe + frames[:, :3, 3]
    n = len(q)
    data = _core.MeasurementSet({"pose": np.arange(n, dtype=np.int32), "q_deg": q, "xyz": pts,
                                 "target": np.zeros(n, dtype=np.int32), "payload_kg": np.full(n, np.nan),
                                 "line": np.zeros(n, dtype=np.int32), "source": "<plan>",
                                 "dir": np.ones((n, robot.dof))}, robot.dof)
    pm = _core.PointModel(robot, 1, effects)
    x = np.asarray(pm.start(data), dtype=float)
    for p in pm.layout.parameters:
        if p.kind == "target":
            x[p.index] = probe["xyz".index(p.name[-1])]
        elif p.kind == "base":  # the points in the robot's base frame, as the balls the projector sees
            x[p.index] = 0.0
    _, G = pm.residuals(list(x), data, True)
    G = np.asarray(G)
    col = {p.name: p.index for p in pm.layout.parameters}
    out = np.zeros((G.shape[0], len(names)))
    for k, name in enumerate(names):
        if name in col:
            out[:, k] = G[:, col[name]]
    return out


def _rigid_projector(points: FloatArray) -> FloatArray:
    """The projector onto the complement of the rigid motions of a point set (3n x 3n): what is left
    of an error field after its best rigid transform, to first order."""
    c = points - points.mean(axis=0)
    n = len(points)
    R = np.zeros((3 * n, 6))
    for k in range(3):
        R[k::3, k] = 1.0
    # small rotations w x c
    R[0::3, 4], R[0::3, 5] = c[:, 2], -c[:, 1]
    R[1::3, 3], R[1::3, 5] = -c[:, 2], c[:, 0]
    R[2::3, 3], R[2::3, 4] = c[:, 1], -c[:, 0]
    Q, _ = np.linalg.qr(R)
    out: FloatArray = np.eye(3 * n) - Q @ Q.T
    return out


def predicted_rms(G: FloatArray, cov: FloatArray, points: FloatArray, seed: int = 0) -> tuple[float, float]:
    """The median and the 90th percentile, over repeated campaigns, of the RMS over the points of the
    error G dx, dx ~ N(0, cov), after the best rigid transform. The mean square is a weighted sum of
    chi-square variables (weights: the squared singular values of the projected G cov^1/2 over the
    number of points); its quantiles are sampled (4,000 draws)."""
    w, V = np.linalg.eigh(0.5 * (cov + cov.T))
    half = V * np.sqrt(np.maximum(w, 0.0))
    s = np.linalg.svd(_rigid_projector(points) @ G @ half, compute_uv=False)
    z = np.random.default_rng(seed).standard_normal((4000, len(s)))
    rms = np.sqrt((z ** 2) @ (s ** 2) / len(points))
    return float(np.median(rms)), float(np.percentile(rms, 90))


def _greedy(Jw: FloatArray, station: IntArray, touches: int, M0: FloatArray,
            progress: Optional[Callable[[int, int], None]] = None) -> tuple[list[int], FloatArray]:
    """``touches`` candidates per station, the stations in turns, each the largest gain
    log det(I + J_i M^-1 J_i^T); returns the chosen rows and the final M^-1."""
    Minv = np.linalg.inv(M0)
    Minv = 0.5 * (Minv + Minv.T)
    stations = np.unique(station)
    left = np.ones(len(Jw), dtype=bool)
    chosen: list[int] = []
    e = Jw.shape[1]
    eye = np.eye(e)
    steps = touches * len(stations)
    turns = [s for _ in range(touches) for s in stations]
    while len(chosen) < steps:
        if progress:
            progress(len(chosen), steps)
        idx = np.flatnonzero(left & (station == turns[len(chosen)]))
        if len(idx) == 0:
            raise ValueError(f"plan: a station has fewer candidates than the {touches} touches asked for")
        A = Jw[idx]                                            # (c, e, p)
        S = eye + (A @ Minv) @ np.transpose(A, (0, 2, 1))      # (c, e, e)
        best = int(idx[int(np.argmax(np.linalg.slogdet(S)[1]))])
        chosen.append(best)
        left[best] = False
        Jc = Jw[best]
        U = Minv @ Jc.T
        Minv = Minv - U @ np.linalg.solve(eye + Jc @ U, U.T)
        Minv = 0.5 * (Minv + Minv.T)
    return chosen, Minv


def _covariances(Jw: FloatArray, rows: Sequence[int], M0: FloatArray, P: FloatArray) -> tuple[FloatArray, FloatArray]:
    """For the candidates ``rows``, with M = M0 + their information (P: the priors' part of M0): the
    covariance of the MAP estimate that the probe's noise causes, M^-1 (M - P) M^-1, and its error
    where the robot is off its prior's centre by one prior sd, M^-1 P M^-1 (the directions the data
    leave to the priors)."""
    A = Jw[list(rows)].reshape(-1, Jw.shape[2])
    M = M0 + A.T @ A
    C = np.linalg.inv(0.5 * (M + M.T))
    return C @ (M - P) @ C, C @ P @ C


def plan_probe(robot: Robot, kind: Kind, *, stations: int = 3, touches: int = 25, cone_deg: float = 35.0,
               probe: Sequence[float] = (0.0, 0.0, 150.0), radius_mm: float = 3.0, length_mm: float = 150.0,
               block_mm: float = 400.0, effects: Union[str, Sequence[Union[str, _core.Effect]]] = ("joint_compliance",),
               noise_mm: float = 0.005, candidates: int = 300, configurations: Optional[FloatArray] = None,
               n_configurations: int = 200, seed: int = 0,
               progress: Optional[Callable[[int, int], None]] = None) -> ProbePlan:
    """The probe campaign's plan (see the module's text). ``configurations``: where the TCP
    uncertainty is predicted (deg), else ``n_configurations`` random ones within 90% of each limit."""
    if touches < 1 or stations < 1:
        raise ValueError(f"--stations and --touches must be positive, not {stations} and {touches}")
    if candidates < 1 or candidates < touches:
        raise ValueError(f"--candidates ({candidates}) must be at least --touches ({touches})")
    if not (noise_mm > 0 and math.isfinite(noise_mm)):
        raise ValueError(f"--noise must be a positive number of mm, not {noise_mm}")
    probe_v = np.asarray(probe, dtype=float)
    core_effects = [e for e in ident.check_effects(effects, robot) if isinstance(e, _core.Effect)]
    pool = _pool(robot, kind, touches, stations=stations, touches=candidates, cone_deg=cone_deg, probe=probe_v,
                 radius_mm=radius_mm, length_mm=length_mm, block_mm=block_mm, seed=seed)
    # the layout, its priors and what the whole pool cannot determine: identify's own analysis
    res = _core.identify(robot, pool, options(core_effects, loss="none", max_iterations=0, covariance=False,
                                              prior_sd=None, prior_scale=1.0, target_start=[probe_v.tolist()]))
    params = list(res.layout.parameters)
    free = np.flatnonzero(~np.asarray(res.fixed))
    left_out = [(p.name, why) for p, fx, why in zip(params, res.fixed, res.fixed_reason) if fx]
    pm = _core.PointModel(robot, 1, [e for e in core_effects if not e.kind.gravity_loaded_only],
                          stations_of=res.layout)
    x = np.asarray(res.start, dtype=float)  # the ball at the probe's offset, the stations through it
    r, J = pm.residuals(list(x), pool, True, artifact=True, columns=free.tolist())
    if np.max(np.abs(r)) > 1e-6 * max(1.0, float(np.max(np.abs(probe_v)))):
        raise AssertionError(f"plan: the candidates are {np.max(np.abs(r)):.3g} mm off their stations at the start")
    J = np.asarray(J)
    n_rows = len(J) - len(pool.artifact or [])
    Jw, station = _whitened_rows(J[:n_rows], pool, noise_mm)
    # columns scaled: by the prior's sd where there is one, else to unit RMS over the pool's rows
    sd = np.asarray(res.prior_sd, dtype=float)[free]
    rms = np.sqrt(np.mean(Jw.reshape(-1, len(free)) ** 2, axis=0))
    scale = np.where(np.isfinite(sd), sd, 1.0 / np.maximum(rms, 1e-300))
    Jw = Jw * scale
    A = J[n_rows:] / noise_mm * scale
    P = np.diag(np.where(np.isfinite(sd), 1.0, 1e-6))
    M0 = P + A.T @ A
    picked, _ = _greedy(Jw, station, touches, M0, progress)
    chosen = _path_within_stations(pool, picked)
    q = configurations
    if q is None:
        lim = np.asarray(robot.limits_deg, dtype=float)
        q = np.random.default_rng(seed + 1).uniform(0.9 * lim[:, 0], 0.9 * lim[:, 1], size=(n_configurations, robot.dof))
    q = np.asarray(q, dtype=float)
    names = [params[i].name for i in free]
    G = _ball_jacobian(robot, q, probe_v, [e for e in core_effects if not e.kind.gravity_loaded_only], names) * scale
    frames = _tool_frames(robot, q)
    balls = frames[:, :3, :3] @ probe_v + frames[:, :3, 3]
    rand = [int(i) for s in np.unique(station) for i in np.flatnonzero(station == s)[:touches]]
    cov, from_priors = _covariances(Jw, picked, M0, P)
    median, p90 = predicted_rms(G, cov, balls, seed)
    return ProbePlan(kind=kind, data=_subset(pool, np.asarray(chosen)), tcp_uncertainty_mm=median,
                     tcp_uncertainty_p90_mm=p90, priors_tcp_mm=predicted_rms(G, from_priors, balls, seed)[0],
                     random_tcp_uncertainty_mm=predicted_rms(G, _covariances(Jw, rand, M0, P)[0], balls, seed)[0],
                     configurations=len(q), candidates=candidates, parameters=names,
                     stddev=np.sqrt(np.maximum(np.diag(cov), 0.0)) * scale, units=[params[i].unit for i in free], left_out=left_out)


def _nominal(robot: Robot) -> Robot:
    """The robot with its nominal model as its calibrated one (the plan linearises at the nominal
    model, where identify starts; a model file from an earlier calibration carries both)."""
    return robot.nominal_only() if robot.identified else robot


def _pool(robot: Robot, kind: Kind, needed: int, *, seed: int, **kw: Any) -> MeasurementSet:
    """The candidate touches: `kincal simulate --kind`'s campaign on the robot's nominal model, noise-free,
    without the candidates near a singularity (a touch there cannot be made again to the plan's
    orientation). Stations placed where the cone cannot be reached, or with fewer than ``needed``
    candidates left, are placed again (up to 10 placements, each drawn from the seed)."""
    why = ""
    for attempt in range(10):
        try:
            pool = sim.simulate_probe(_nominal(robot), kind, noise_mm=0.0, seed=seed + 7919 * attempt, **kw)
        except _core.InputError as e:
            why = str(e)
            if "block has 5 faces" in why:
                raise
            continue
        ok, _ = keep_out(robot, np.asarray(pool.q_deg), np.asarray(kw["probe"])[None, :],
                         KeepOut(min_sigma=MIN_SIGMA))
        counts = np.bincount(np.asarray(pool.station)[ok], minlength=len(pool.station_names or []))
        if np.all(counts >= needed):
            return _subset(pool, np.flatnonzero(ok))
        why = f"a station with {int(counts.min())} of {kw['touches']} candidates away from singularities"
    raise ValueError(f"plan: no placement of the stations in 10 tries ({why}); ask for more --candidates, fewer "
                     "--touches or a smaller --cone")


def _path_within_stations(pool: MeasurementSet, chosen: list[int]) -> IntArray:
    """The chosen touches station by station, each station's in a short path order (nearest
    neighbour in joint space)."""
    st = np.asarray(pool.station)[chosen]
    ch = np.asarray(chosen)
    out = []
    for s in np.unique(st):
        mine = ch[st == s]
        out.append(mine[path_order(np.asarray(pool.q_deg)[mine])])
    return np.concatenate(out)


def measure(truth: Robot, plan: MeasurementSet, probe: Sequence[float] = (0.0, 0.0, 150.0), noise_mm: float = 0.005,
            seed: int = 1) -> MeasurementSet:
    """The planned touches made on a true robot: each row's ball centre is where the plan put it on
    the nominal model (a sphere's centre, a point of a face, the ballbar's far end) with the same tool
    orientation, reached on the truth's calibrated model (Newton on its forward kinematics, from the
    planned angles), moved by ``noise_mm`` along the constraint (a sphere's three coordinates, a
    plane's normal, the ballbar's measured length). The returned set holds the truth's angles."""
    rng = np.random.default_rng(seed)
    probe_v = np.asarray(probe, dtype=float)
    q = np.asarray(plan.q_deg, dtype=float).copy()
    nominal = _tool_frames(truth, q)
    station_kinds = plan.station_kinds or []
    kinds = [station_kinds[s] for s in np.asarray(plan.station)]
    dirs = np.asarray(plan.dir, dtype=float) if plan.dir is not None else None  # the last motion's, when recorded
    length = np.asarray(plan.length_mm, dtype=float).copy()
    for i in range(len(q)):
        target = nominal[i].copy()
        if kinds[i] == "sphere":
            target[:3, 3] += rng.normal(0.0, noise_mm, 3)
        elif kinds[i] == "plane":
            target[:3, 3] += _plane_normal(nominal, plan, i) * rng.normal(0.0, noise_mm)
        else:
            length[i] += rng.normal(0.0, noise_mm)
        q[i] = _reach(truth, q[i], target, probe_v, None if dirs is None else dirs[i])
    return plan.with_columns(q_deg=q, length_mm=length)


def _plane_normal(frames: FloatArray, plan: MeasurementSet, i: int) -> FloatArray:
    """The unit normal of row i's plane, from the station's touches' tool axes (the probe points into
    the face, so their mean is along the inward normal)."""
    station = np.asarray(plan.station)
    rows = np.flatnonzero(station == station[i])
    z = frames[rows, :3, 2].mean(axis=0)
    out: FloatArray = -z / np.linalg.norm(z)
    return out


def _frame(truth: Robot, q: FloatArray, direction: Optional[FloatArray]) -> FloatArray:
    """The truth's calibrated tool frame (4 x 4, mm) at q (deg), its effects acting with the last
    motion's direction when given."""
    p = np.asarray(_core.fk(truth, q[None, :], True, False, None if direction is None else direction[None, :]))[0]
    f = np.eye(4)
    f[:3, :3] = _core.abc_to_rotation(p[3:])
    f[:3, 3] = p[:3]
    return f


def _reach(truth: Robot, q0: FloatArray, target: FloatArray, probe: FloatArray, direction: Optional[FloatArray] = None,
           iterations: int = 100) -> FloatArray:
    """Joint angles (deg) near q0 where the truth's calibrated model puts the ball centre at target's
    ball centre with target's orientation (damped Newton steps; its effects acting with the last
    motion's ``direction`` when given); ValueError when it cannot."""
    want = target[:3, :3] @ probe + target[:3, 3]
    q = q0.copy()
    for _ in range(iterations):
        f = _frame(truth, q, direction)
        e = np.concatenate([want - (f[:3, :3] @ probe + f[:3, 3]), _rotvec(target[:3, :3] @ f[:3, :3].T) * 1000.0])
        if np.linalg.norm(e) < 1e-9:
            return q
        Jt = np.asarray(_core.jacobian(truth, q, True, direction))  # the tool frame: linear rows, then angular
        J = np.vstack([Jt[:3] - _skew(f[:3, :3] @ probe) @ Jt[3:], Jt[3:] * 1000.0])  # the ball; rad on a 1 m lever
        q = q + np.degrees(J.T @ np.linalg.solve(J @ J.T + 1e-6 * np.eye(6), e))
    raise ValueError(f"the truth cannot reach a planned touch near {np.round(q0, 3).tolist()} deg "
                     f"(still {np.linalg.norm(e):.3g} mm off)")


def _skew(v: FloatArray) -> FloatArray:
    return np.array([[0, -v[2], v[1]], [v[2], 0, -v[0]], [-v[1], v[0], 0]])


def _rotvec(R: FloatArray) -> FloatArray:
    c = np.clip((np.trace(R) - 1) / 2, -1.0, 1.0)
    a = math.acos(c)
    w = np.array([R[2, 1] - R[1, 2], R[0, 2] - R[2, 0], R[1, 0] - R[0, 1]])
    return w / 2 if a < 1e-9 else w * a / (2 * math.sin(a))
