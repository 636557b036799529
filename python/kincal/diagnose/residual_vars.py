"""Which variable carries what a serial robot's model still misses, beyond the library's effects.

The residual of the final model (fitted on every point) is scored against every candidate variable:
each joint angle, the gravity torque of each gravity-loaded joint, temperature_c and time_s (when
the data have them and they vary), the measurement order (the row's place in the file) and each
joint's motion direction (dir1..dirN, when present). For a variable v, the residual is fitted as a
smooth function of v acting through every way the model can move a point: the instrument's
placement (its 3 translations and 3 rotations) and each joint's angle (the joint's column of the
identification Jacobian),

    r_i  ~  sum_c  C_ic f_c(v_i),   each f_c piecewise linear in v on KNOTS quantile knots
                                    (a discrete variable: one value per level),

a nonparametric varying-coefficient fit (lightly ridge-regularised), scored on the diagnosis's own
folds: its share is the part of the held-out residual sum of squares it removes (0: v carries
nothing; negative: fitting v only adds noise). So a gear error of joint 3 shows as q3, an instrument
drifting during the campaign as time_s or the measurement order, a thermal drift of the joint
offsets as temperature_c, a compliance that is not linear as a gravity torque.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any, Sequence, Union

import numpy as np

from .. import _core
from .._core import Robot

if TYPE_CHECKING:
    from .._core import MeasurementSet
    from ..typing_ import BoolArray, FloatArray

#: knots of the piecewise-linear functions of a continuous variable (at its quantiles)
KNOTS = 8
#: ridge on the normal equations, relative to their mean diagonal (the carriers are near collinear:
#: joint 1's rotation is the instrument's about the base z axis)
RIDGE = 1e-2
#: a variable "carries" the rest when its held-out share is at least this
CARRIES = 0.05


def variables(robot: Robot, data: MeasurementSet) -> list[dict[str, Any]]:
    """The candidate variables of a measurement set: dicts with ``variable`` (its name), ``label``
    (in words, with unit), ``values`` (one per row) and ``discrete``."""
    q = np.asarray(data.q_deg, dtype=float)
    n, dof = q.shape
    out = [{"variable": f"q{j + 1}", "label": f"joint {j + 1} angle (deg)", "values": q[:, j], "discrete": False}
           for j in range(dof)]
    loaded = list(_core.PointModel(robot, 1).layout.loaded)  # from 1
    if loaded:
        tau = gravity_torques(robot, q)
        out += [{"variable": f"tau{j}", "label": f"gravity torque on joint {j} (kN m)",
                 "values": tau[:, j - 1] / 1000.0, "discrete": False} for j in loaded]
    for key, label, col in (("temperature_c", "temperature (deg C)", data.temperature_c),
                            ("time_s", "measurement time (s)", data.time_s)):
        if col is not None and np.ptp(np.asarray(col, dtype=np.float64)) > 0:
            out.append({"variable": key, "label": label, "values": np.asarray(col, dtype=np.float64),
                        "discrete": False})
    out.append({"variable": "order", "label": "measurement order (row of the file)",
                "values": np.arange(n, dtype=float), "discrete": False})
    if data.dir is not None:
        d = np.asarray(data.dir, dtype=float)
        out += [{"variable": f"dir{j + 1}", "label": f"joint {j + 1} motion direction (sign)", "values": d[:, j],
                 "discrete": True} for j in range(dof) if len(np.unique(d[:, j])) > 1]
    return out


def gravity_torques(robot: Robot, q_deg: FloatArray) -> FloatArray:
    """Gravity torque (N m) on every joint at each row of joint angles (deg)."""
    return np.array([_core.gravity_torque(robot, qq)[0] for qq in np.asarray(q_deg, dtype=float)])


def carriers(res: _core.IdentifyResult, data: MeasurementSet) -> tuple[FloatArray, FloatArray]:
    """The residual r (dims per row) of a fit and the carriers C (one column per way the model moves
    a point: the instrument's 6 placement parameters, then each joint's angle, in mm per rad) at
    that fit."""
    from ..calibration.linearisation import evaluate

    dof = res.robot.dof
    extra = [_core.Effect("joint_map", j, order=1) for j in range(1, dof + 1)]
    r, _, J, new, fit_of = evaluate(res, data, extra)
    base = [p.index for p in new if p.kind == "base"]
    n = len(data.pose)
    dims = len(r) // n
    q = np.radians(np.asarray(data.q_deg, dtype=float))
    s, c = np.repeat(np.sin(q), dims, axis=0), np.repeat(np.cos(q), dims, axis=0)
    # the appended maps' (sine, cosine) columns, joint by joint (not the fit's own, nor a probe
    # campaign's stations after them)
    added = [p.index for p in new if p.effect in extra and p.index not in fit_of]
    tail = J[:, added]
    joints = tail[:, 0::2] * s + tail[:, 1::2] * c  # J_j = sin q_j d/d(s_1) + cos q_j d/d(c_1)
    return r, np.c_[J[:, base], joints]


def _basis(values: FloatArray, discrete: bool) -> FloatArray:
    """Per-row basis of a variable: indicators of its levels, or piecewise-linear hat functions on
    its quantile knots (empty when it does not vary)."""
    if discrete:
        levels = np.unique(values)
        return (values[:, None] == levels[None, :]).astype(float) if len(levels) > 1 else np.zeros((len(values), 0))
    knots = np.unique(np.quantile(values, np.linspace(0.0, 1.0, KNOTS)))
    if len(knots) < 2:
        return np.zeros((len(values), 0))
    eye = np.eye(len(knots))
    return np.column_stack([np.interp(values, knots, eye[k]) for k in range(len(knots))])


def score(r: FloatArray, C: FloatArray, variables: Sequence[dict[str, Any]],
          folds: Sequence[BoolArray]) -> list[dict[str, Any]]:
    """Each variable's held-out share of the residual (see the module), sorted, largest first: dicts
    with ``variable``, ``label``, ``share`` and ``rms_explained_mm`` (the RMS per point of what the
    fit removes from the held-out residual).

    The design row of point i is C_i (dims x m) times each basis value B_ib, so the normal equations
    are sums over the points of B_ib B_ib' (C_i^T C_i) and B_ib (C_i^T r_i): the per-point products
    are formed once for every variable and fold, the held-out sum of squares follows from them."""
    n = len(folds[0])
    dims = len(r) // n
    m = C.shape[1]
    Cn = (C / np.maximum(np.sqrt(np.mean(C ** 2, axis=0)), 1e-300)).reshape(n, dims, m)  # unit-RMS carriers
    rn = r.reshape(n, dims)
    M = np.einsum("idc,ide->ice", Cn, Cn).reshape(n, m * m)  # C_i^T C_i
    u = np.einsum("idc,id->ic", Cn, rn)  # C_i^T r_i
    rr = np.sum(rn ** 2, axis=1)
    out = []
    for v in variables:
        B = _basis(np.asarray(v["values"], dtype=float), v["discrete"])
        nb = B.shape[1]
        if nb == 0:
            continue
        W = (B[:, :, None] * B[:, None, :]).reshape(n, nb * nb)
        Bu = (B[:, :, None] * u[:, None, :]).reshape(n, nb * m)

        # the normal equations of the rows, unknowns ordered (basis, carrier)
        def normal(rows: Union[slice, BoolArray]) -> tuple[FloatArray, FloatArray]:
            G = (W[rows].T @ M[rows]).reshape(nb, nb, m, m).transpose(0, 2, 1, 3).reshape(nb * m, nb * m)
            return G, Bu[rows].sum(axis=0)

        G, g = normal(slice(None))
        before = after = 0.0
        for h in folds:
            Gh, gh = normal(h)
            Gt, gt = G - Gh, g - gh
            lam = RIDGE * max(float(np.trace(Gt)) / len(Gt), 1e-300)
            b = np.linalg.solve(Gt + lam * np.eye(len(Gt)), gt)
            ss = float(np.sum(rr[h]))
            before += ss
            after += ss - 2.0 * float(b @ gh) + float(b @ Gh @ b)
        share = 1.0 - after / before if before > 0 else 0.0
        out.append({"variable": v["variable"], "label": v["label"], "share": share,
                    "rms_explained_mm": float(np.sqrt(max(0.0, before - after) / n))})
    out.sort(key=lambda s: -s["share"])
    return out


def summary(scores: Sequence[dict[str, Any]]) -> str:
    """In words: the variable that carries the rest, and how much (or that none does)."""
    if not scores or scores[0]["share"] < CARRIES:
        return (f"no variable carries {CARRIES:.0%} of what remains (held out)" if scores
                else "no variable to score")
    top = scores[0]
    return (f"what remains is carried most by {top['variable']} ({top['label']}): a smooth function of it explains "
            f"{top['share']:.0%} of the residual's variance held out ({top['rms_explained_mm'] * 1000:.1f} um RMS)")
