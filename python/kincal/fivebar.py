"""The Kiper paper's hidden robot: link-length synthesis, the error-correction matrix, commands.

A point set is a dict of numpy arrays (``id``, ``theta1_deg``, ``theta2_deg``, ``desired`` n x 2,
``measured`` n x 2), the rows of data/fivebar-table1.csv. Kinematics, synthesis, the subset search
and the nonlinear fit run in the C++ core; the minimax fit is a sequence of linear programs here.
"""

from __future__ import annotations

import json
import math
from typing import Any, Optional

import numpy as np

from . import _core
from ._core import ErrorMatrix, FiveBar

METHODS = ("polynomial", "lsq", "minimax", "nonlinear")

#: the paper's workspace (Table I): 100 mm x 150 mm
WORKSPACE = ((162.132, 262.132), (-75.0, 75.0))


def read_table(path: str) -> dict:
    """A table with the columns of data/fivebar-table1.csv (errors name file:line and cause)."""
    return _core.read_fivebar_table(str(path))


def _max_error(model: FiveBar, pts: dict, desired: bool) -> float:
    return float(_core.fivebar_max_error(model, pts, desired))


def minimax_fit(pts: dict, start: FiveBar, desired: bool = False, sides: int = 64, max_iter: int = 200) -> FiveBar:
    """The four lengths that minimise the largest distance between model and target (Chebyshev fit):
    linear programs on the linearised errors (each distance bounded by a regular polygon of
    ``sides`` sides) inside a trust region that shrinks when a step does not lower the true largest
    error. Needs no subset enumeration: it scales to hundreds of points."""
    from scipy.optimize import linprog

    x = np.array([start.a, start.b, start.c, start.d], dtype=float)
    model = FiveBar(*x)
    best = _max_error(model, pts, desired)
    radius = 1.0  # mm
    ang = 2 * np.pi * np.arange(sides) / sides
    normals = np.stack([np.cos(ang), np.sin(ang)], axis=1)  # n_k . v <= t  for all k  (outer polygon)
    for _ in range(max_iter):
        e, J = _core.fivebar_errors(model, pts, desired)
        n = len(e)
        J = J.reshape(n, 2, 4)
        # variables: dx (4), t; minimise t; n_k . (e_i + J_i dx) <= t
        A = np.einsum("kc,ncj->nkj", normals, J).reshape(n * sides, 4)
        b = -(e @ normals.T).reshape(n * sides)
        A_ub = np.hstack([A, -np.ones((n * sides, 1))])
        res = linprog(np.r_[np.zeros(4), 1.0], A_ub=A_ub, b_ub=b,
                      bounds=[(-radius, radius)] * 4 + [(0, None)], method="highs")
        if res.status != 0:
            radius /= 4
            if radius < 1e-10:
                break
            continue
        trial = FiveBar(*(x + res.x[:4]))
        try:
            err = _max_error(trial, pts, desired)
        except ValueError:
            err = math.inf
        if err < best - 1e-12:
            x, model, best = x + res.x[:4], trial, err
            radius = min(radius * 2, 10.0)
        else:
            radius /= 4
            if radius < 1e-10:
                break
    return model


def fit(pts: dict, method: str = "lsq", score: str = "measured") -> dict:
    """Hidden-robot synthesis (FIT.json of the contract). ``score``: rank models by the largest
    distance at the commanded angles to the measured (default) or, as the paper does, the desired
    positions. polynomial: every pair of points (eqs. 1-3); lsq: every subset of 3..N (eqs. 4-6);
    minimax: the Chebyshev fit; nonlinear: Ceres least squares on the measured positions."""
    if method not in METHODS:
        raise ValueError(f"unknown method '{method}' ({', '.join(METHODS)})")
    if score not in ("measured", "desired"):
        raise ValueError(f"unknown score '{score}' (measured, desired)")
    desired = score == "desired"
    n = len(pts["id"])
    ids = [int(i) for i in pts["id"]]
    out: dict = {"method": method, "score": score}
    if method in ("polynomial", "lsq"):
        if n < (2 if method == "polynomial" else 3):
            raise ValueError(f"{method} needs at least {2 if method == 'polynomial' else 3} points, the table has {n}")
        model, use, err, tried = _core.fivebar_best_subset(pts, method == "lsq", desired,
                                                           2 if method == "polynomial" else 3,
                                                           2 if method == "polynomial" else n)
        out.update(points=[ids[i] for i in use], subsets_tried=int(tried))
    else:
        if n < 2:
            raise ValueError(f"{method} needs at least 2 points")
        model, rms = _core.fivebar_fit_nonlinear(pts, FiveBar())
        if method == "minimax":
            model = minimax_fit(pts, model, desired)
        out.update(points=ids)
        err = _max_error(model, pts, desired)
    out.update(a=model.a, b=model.b, c=model.c, d=model.d, max_error_mm=float(err))
    return out


def model_of(fit_json: dict) -> FiveBar:
    return _core.fivebar_from_json(json.dumps(fit_json))


def _read(path: str) -> str:
    try:
        with open(path) as f:
            return f.read()
    except OSError as e:
        raise ValueError(f"{path}: {e.strerror}") from None


def load_fit(path: str) -> FiveBar:
    """A FIT.json of `kincal hidden-robot fit` (errors name the file and cause)."""
    return _core.fivebar_from_json(_read(path), str(path))


def load_matrix(path: str) -> ErrorMatrix:
    """A MATRIX.json of `kincal hidden-robot matrix`."""
    return ErrorMatrix.from_json(_read(path), str(path))


def grid_targets(spacing: float = 5.0, workspace=WORKSPACE) -> np.ndarray:
    (x0, x1), (y0, y1) = workspace
    xs = np.arange(x0, x1 + 1e-9, spacing)
    ys = np.arange(y0, y1 + 1e-9, spacing)
    return np.array([(x, y) for y in ys for x in xs])


def command(model: FiveBar, xy: np.ndarray, matrix: Optional[ErrorMatrix] = None) -> np.ndarray:
    """Joint commands (deg, n x 2) for desired points (n x 2)."""
    return _core.fivebar_command(model, matrix, np.asarray(xy, dtype=float).reshape(-1, 2))


def position_errors(points: dict) -> np.ndarray:
    """Distance (mm) between desired and measured position of every point."""
    return np.linalg.norm(points["measured"] - points["desired"], axis=1)


def error_map_figure(maps: list, path: str, title: str = "five-bar positioning error") -> None:
    """One panel per (label, points) pair: the error (um) at each desired position, same colour scale."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    vmax = max(float(position_errors(p).max()) for _, p in maps) * 1000
    fig, axes = plt.subplots(1, len(maps), figsize=(4.2 * len(maps), 4.6), constrained_layout=True)
    axes = np.atleast_1d(axes)
    for ax, (label, p) in zip(axes, maps):
        e = position_errors(p) * 1000
        sc = ax.scatter(p["desired"][:, 0], p["desired"][:, 1], c=e, s=18, cmap="viridis", vmin=0, vmax=vmax)
        ax.set_title(f"{label}\nmax {e.max():.0f} um, RMS {np.sqrt(np.mean(e ** 2)):.0f} um", fontsize=10)
        ax.set_xlabel("x (mm)")
        ax.set_aspect("equal")
    axes[0].set_ylabel("y (mm)")
    fig.colorbar(sc, ax=list(axes), label="position error (um)")
    fig.suptitle(title)
    fig.savefig(path, dpi=110)
    plt.close(fig)


# ---------------------------------------------------------------------------------------------
# Diagnosis of the hidden robot: which pose-dependent effect do the four lengths miss?
# ---------------------------------------------------------------------------------------------
LINKS = ("a", "b", "c", "d")


def library() -> list:
    """The hidden robot's candidate effects, from the registry: every five-bar effect on each link
    a..d, and every joint-angle effect that needs no extra data (transmission error) on each
    actuator. Each is a _core.Effect (joint: the link or actuator, from 1)."""
    out = []
    for kind in _core.effect_kinds():
        if kind.domain == "fivebar" and kind.concerns == "link":
            out += [_core.Effect(kind.name, i + 1) for i in range(len(LINKS))]
    for kind in _core.effect_kinds():
        if kind.acts_on == "joint_angle" and not kind.needs and not kind.gravity_loaded_only:
            out += [_core.Effect(kind.name, j + 1) for j in range(2)]
    return out


def _acts_on(effect) -> str:
    return _core.effect_kind(effect.name).acts_on


def _basis(effect, t1: np.ndarray, t2: np.ndarray) -> np.ndarray:
    """Per-point basis functions (n x effect.size) of an effect: a link's length varies with the pose
    as p1 cos t1 + p2 sin t1 + p3 cos t2 + p4 sin t2 (mm); a joint-angle effect of actuator j is the
    sum over its harmonic orders k of s_k sin(k tj) + c_k cos(k tj) (rad)."""
    if _acts_on(effect) == "link_length":
        b = np.c_[np.cos(t1), np.sin(t1), np.cos(t2), np.sin(t2)]
    else:
        t = t1 if effect.joint == 1 else t2
        b = np.column_stack([f(k * t) for k in effect.harmonics for f in (np.sin, np.cos)])
    if b.shape[1] != effect.size:
        raise ValueError(f"{effect.label}: {effect.size} parameters but the five-bar has {b.shape[1]} basis functions")
    return b


def _predict(pts: dict, x: np.ndarray, effects: list) -> np.ndarray:
    """Model positions (n x 2) for lengths x[:4] and the effects' parameters after them (effects:
    _core.Effect objects, joint = link or actuator from 1)."""
    t1, t2 = np.radians(pts["theta1_deg"]), np.radians(pts["theta2_deg"])
    n = len(t1)
    L = np.tile(x[:4], (n, 1))
    dt = np.zeros((n, 2))
    k = 4
    for eff in effects:
        b = _basis(eff, t1, t2)
        if _acts_on(eff) == "link_length":
            L[:, eff.joint - 1] += b @ x[k:k + eff.size]
        else:
            dt[:, eff.joint - 1] += b @ x[k:k + eff.size]
        k += eff.size
    out = np.empty((n, 2))
    for i in range(n):
        c = FiveBar(*L[i]).fk(np.degrees(t1[i] + dt[i, 0]), np.degrees(t2[i] + dt[i, 1]))
        if c is None:
            raise ValueError(f"point {int(pts['id'][i])}: the model cannot close the loop there")
        out[i] = c
    return out


def fit_with_effects(pts: dict, effects: list, start: Optional[np.ndarray] = None) -> np.ndarray:
    """Least squares of the lengths and the effects' parameters on the measured positions
    (scipy's trust-region reflective; a few parameters, central-difference Jacobian)."""
    from scipy.optimize import least_squares

    x0 = np.r_[np.array([150.0, 150, 150, 150]) if start is None else start[:4], np.zeros(sum(e.size for e in effects))]
    if start is not None and len(start) > 4:
        x0[4:len(start)] = start[4:]
    r = least_squares(lambda x: (_predict(pts, x, effects) - pts["measured"]).ravel(), x0, method="trf",
                      x_scale="jac", xtol=1e-12, ftol=1e-12, diff_step=1e-7)
    return r.x


def diagnose(pts: dict, folds: int = 5, alpha: float = 1e-6, min_gain: float = 0.03, seed: int = 0,
             noise_mm: Optional[float] = None, say=lambda s: None) -> dict:
    """The model-discrepancy workflow on the hidden robot (contract names link_deflection, with
    "link": "a".."d", and transmission_error with the actuator as "joint")."""
    import math

    from scipy.stats import f as fdist

    n = len(pts["id"])
    rng = np.random.default_rng(seed)
    order = rng.permutation(n)
    masks = [np.isin(np.arange(n), order[i::folds]) for i in range(folds)]
    sub = lambda m: {k: (v[m] if isinstance(v, np.ndarray) else v) for k, v in pts.items()}  # noqa: E731

    def cv(effects):
        sq = 0.0
        for m in masks:
            x = fit_with_effects(sub(~m), effects)
            sq += float(np.sum((_predict(sub(m), x, effects) - pts["measured"][m]) ** 2))
        return math.sqrt(sq / n)

    cands = library()
    effects: list = []
    cur = cv(effects)
    steps = []
    while True:
        x = fit_with_effects(pts, effects)
        r = (_predict(pts, x, effects) - pts["measured"]).ravel()
        # current model's columns by central differences, candidates' by the chain rule on them
        h = 1e-6
        cols = []
        for k in range(len(x)):
            xp, xm = x.copy(), x.copy()
            xp[k] += h
            xm[k] -= h
            cols.append(((_predict(pts, xp, effects) - _predict(pts, xm, effects)) / (2 * h)).ravel())
        Jc = np.array(cols).T
        t1, t2 = np.radians(pts["theta1_deg"]), np.radians(pts["theta2_deg"])
        model = FiveBar(*x[:4])
        scored: list[dict[str, Any]] = []
        for eff in cands:
            if eff in effects:
                continue
            idx = eff.joint - 1
            b = _basis(eff, t1, t2)
            k_par = eff.size
            R = np.zeros((2 * n, k_par))
            for i in range(n):
                if _acts_on(eff) == "link_length":
                    _, jl = _core.fivebar_errors(model, {k: (v[i:i + 1] if isinstance(v, np.ndarray) else v)
                                                         for k, v in pts.items()})
                    d = jl[:, idx]
                else:
                    jm = model.jacobian(pts["theta1_deg"][i], pts["theta2_deg"][i])
                    if jm is None:
                        raise ValueError(f"point {int(pts['id'][i])}: a singular pose of the hidden robot")
                    d = jm[:, idx]
                R[2 * i:2 * i + 2] = np.outer(d, b[i])
            Q, _ = np.linalg.qr(Jc)
            Rp = R - Q @ (Q.T @ R)
            beta, *_ = np.linalg.lstsq(Rp, r, rcond=None)
            rss0, rss1 = float(r @ r), float(np.sum((r - Rp @ beta) ** 2))
            dof = 2 * n - Jc.shape[1] - k_par
            F = ((rss0 - rss1) / k_par) / (rss1 / dof) if rss1 > 0 and dof > 0 else math.inf
            p = float(fdist.sf(F, k_par, dof)) if math.isfinite(F) else 0.0
            before = after = 0.0
            for m in masks:
                rows = np.repeat(m, 2)
                bb, *_ = np.linalg.lstsq(Rp[~rows], r[~rows], rcond=None)
                before += float(r[rows] @ r[rows])
                after += float(np.sum((r[rows] - Rp[rows] @ bb) ** 2))
            scored.append({"effect": eff, "F": F, "p_value": p,
                           "cv_gain": 1 - math.sqrt(after / before) if before > 0 else 0.0})
        scored.sort(key=lambda s: -s["cv_gain"])
        sig = [s for s in scored if s["p_value"] < alpha and s["cv_gain"] > min_gain]
        if not sig:
            break
        best = sig[0]
        trial = effects + [best["effect"]]
        new = cv(trial)
        if new >= cur:
            break
        eff = best["effect"]
        step = {"effect": eff.name, "joint": None, "evidence": {"F": best["F"], "p_value": best["p_value"],
                                                                "cv_gain_linear": best["cv_gain"]},
                "rms_before_mm": cur, "rms_after_mm": new}
        if _core.effect_kind(eff.name).concerns == "link":
            step["link"] = LINKS[eff.joint - 1]
        else:
            step["joint"] = eff.joint
        steps.append(step)
        say(f"step {len(steps)}: {eff.name} ({step.get('link') or step['joint']}), cross-validated RMS "
            f"{cur * 1000:.1f} -> {new * 1000:.1f} um")
        effects, cur = trial, new
    x = fit_with_effects(pts, effects)
    e = np.linalg.norm(_predict(pts, x, effects) - pts["measured"], axis=1)
    scatter = math.sqrt(float(np.sum(e ** 2)) / max(1, 2 * n - len(x))) * math.sqrt(2.0)
    noise = scatter if noise_mm is None else noise_mm * math.sqrt(2.0)
    left = [s for s in scored if s["p_value"] < alpha]
    at_noise = (cur <= 1.3 * noise) if noise_mm is not None else not left
    return {"steps": steps, "final_rms_mm": cur, "noise_rms_mm": noise, "noise_known": noise_mm is not None,
            "verdict": "what remains is at the noise level" if at_noise else
            "what remains is structured but not explained by the library", "notes": [], "folds": folds,
            "lengths_mm": x[:4].tolist()}
