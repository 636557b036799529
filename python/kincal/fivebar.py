"""The Kiper paper's hidden robot: link-length synthesis, the error-correction matrix, commands,
and the diagnosis of what the four lengths miss (the engine of kincal.stepwise, with this
mechanism's candidates and refit) with its report.

A point set is a dict of numpy arrays (``id``, ``theta1_deg``, ``theta2_deg``, ``desired`` n x 2,
``measured`` n x 2), the rows of data/fivebar-table1.csv. Kinematics, synthesis, the subset search
and the nonlinear fit run in the C++ core; the minimax fit is a sequence of linear programs here.
"""

from __future__ import annotations

import math
import re
from pathlib import Path
from typing import Callable, Optional, Union

import numpy as np

from . import _core, report
from . import strict_json
from ._core import ErrorMatrix, FiveBar
from .csv_text import format_rows
from . import stepwise as engine

METHODS = ("polynomial", "lsq", "minimax", "nonlinear")

#: the paper's workspace (Table I): 100 mm x 150 mm
WORKSPACE = ((162.132, 262.132), (-75.0, 75.0))


def read_table(path: str) -> dict:
    """A table with the columns of data/fivebar-table1.csv (errors name file:line and cause)."""
    return _core.read_fivebar_table(str(path))


def largest_error(model: FiveBar, pts: dict, desired: bool) -> float:
    """The largest distance (mm) between the model's position at the commanded angles and the
    desired (``desired``) or the measured position of every point: a fit's score."""
    return float(_core.fivebar_max_error(model, pts, desired))



def minimax_fit(pts: dict, start: FiveBar, desired: bool = False, sides: int = 64, max_iter: int = 200) -> FiveBar:
    """The four lengths that minimise the largest distance between model and target (Chebyshev fit):
    linear programs on the linearised errors (each distance bounded by a regular polygon of
    ``sides`` sides) inside a trust region that shrinks when a step does not lower the true largest
    error. Needs no subset enumeration: it scales to hundreds of points."""
    from scipy.optimize import linprog

    x = np.array([start.a, start.b, start.c, start.d], dtype=float)
    model = FiveBar(*x)
    best = largest_error(model, pts, desired)
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
            err = largest_error(trial, pts, desired)
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
        err = largest_error(model, pts, desired)
    out.update(a=model.a, b=model.b, c=model.c, d=model.d, max_error_mm=float(err))
    return out


def model_of(fit_json: dict) -> FiveBar:
    return _core.fivebar_from_json(strict_json.dumps(fit_json))


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


#: how far (deg) a grid's angles may be from its model's commands: the rounding of a controller's
#: numbers, far below what a different fit changes (hundredths to tenths of a degree)
COMMAND_TOLERANCE_DEG = 0.005


def check_commanded_by(model: FiveBar, pts: dict, fit_file: str, grid_file: str) -> dict:
    """``pts`` when its angles are the commands ``model`` gives for its desired points: an error
    matrix corrects the model that commanded the grid, and only that one. Otherwise a ValueError
    naming the grid's line, the angles and the model's."""
    try:
        q = command(model, pts["desired"])
    except ValueError as e:  # "row K: ..." (K from 1): said at the grid file's line of that point
        m = re.match(r"row (\d+): (.*)", str(e))
        where = f"{grid_file}:{int(pts['line'][int(m.group(1)) - 1])}" if m else grid_file
        raise ValueError(f"{where}: {m.group(2) if m else e} for {fit_file}") from None
    d = q - np.c_[pts["theta1_deg"], pts["theta2_deg"]]
    diff = np.max(np.abs((d + 180.0) % 360.0 - 180.0), axis=1)  # angles modulo a turn (368.7 is 8.7)
    k = int(np.argmax(diff))
    if diff[k] > COMMAND_TOLERANCE_DEG:
        raise ValueError(f"{grid_file}:{int(pts['line'][k])}: the grid was not commanded by {fit_file}: point "
                         f"{int(pts['id'][k])} has theta1, theta2 = {pts['theta1_deg'][k]:.4f}, "
                         f"{pts['theta2_deg'][k]:.4f} deg where that model commands {q[k, 0]:.4f}, {q[k, 1]:.4f} "
                         f"({int(np.sum(diff > COMMAND_TOLERANCE_DEG))} of {len(diff)} points differ by more than "
                         f"{COMMAND_TOLERANCE_DEG} deg). The matrix corrects the model that commanded the grid: "
                         "measure a grid commanded by this fit (kincal hidden-robot command), or give the fit "
                         "that commanded it")
    return pts


def position_errors(points: dict) -> np.ndarray:
    """Distance (mm) between desired and measured position of every point."""
    return np.linalg.norm(points["measured"] - points["desired"], axis=1)


def error_map_figure(maps: list, path: str, title: str = "five-bar positioning error") -> None:
    """One panel per (label, points) pair: the error (um) at each desired position, one colour scale
    (logarithmic: report.error_norm)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    norm = report.error_norm(np.concatenate([position_errors(p) for _, p in maps]) * 1000)
    fig, axes = plt.subplots(1, len(maps), figsize=(4.2 * len(maps), 4.6), constrained_layout=True)
    axes = np.atleast_1d(axes)
    for ax, (label, p) in zip(axes, maps):
        e = position_errors(p) * 1000
        sc = ax.scatter(p["desired"][:, 0], p["desired"][:, 1], c=e, s=18, cmap="viridis", norm=norm)
        ax.set_title(f"{label}\nmax {e.max():.1f} um, RMS {np.sqrt(np.mean(e ** 2)):.1f} um", fontsize=10)
        ax.set_xlabel("x (mm)")
        ax.set_aspect("equal")
    axes[0].set_ylabel("y (mm)")
    fig.colorbar(sc, ax=list(axes), label="position error (um, log scale)")
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
        # joint_map (any order) is the serial diagnosis's; here the transmission error's two orders
        if kind.acts_on == "joint_angle" and not kind.needs and not kind.gravity_loaded_only and kind.name != "joint_map":
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


def predict(pts: dict, x: np.ndarray, effects: list) -> np.ndarray:
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
    r = least_squares(lambda x: (predict(pts, x, effects) - pts["measured"]).ravel(), x0, method="trf",
                      x_scale="jac", xtol=1e-12, ftol=1e-12, diff_step=1e-7)
    return r.x


def _subset(pts: dict, mask: Union[np.ndarray, slice]) -> dict:
    return {k: (v[mask] if isinstance(v, np.ndarray) else v) for k, v in pts.items()}


class Diagnosis:
    """The hidden robot's diagnosis problem (kincal.stepwise.Problem): the measured points,
    folds of points dealt at random, the refit of the lengths and the effects' parameters
    (fit_with_effects) and its linearisation: the current model's columns by central differences,
    a candidate's by the chain rule on the five-bar's Jacobians."""

    dims = 2

    def __init__(self, pts: dict, folds: int = 5, seed: int = 0):
        n = len(pts["id"])
        order = np.random.default_rng(seed).permutation(n)
        self.pts = pts
        self.folds = [np.isin(np.arange(n), order[i::folds]) for i in range(folds)]

    def held_errors(self, effects: list, held: np.ndarray) -> np.ndarray:
        x = fit_with_effects(_subset(self.pts, ~held), effects)
        return predict(_subset(self.pts, held), x, effects) - self.pts["measured"][held]

    def linearise(self, effects: list) -> engine.Linearisation:
        pts = self.pts
        x = fit_with_effects(pts, effects)
        r = (predict(pts, x, effects) - pts["measured"]).ravel()
        h = 1e-6
        cols = []
        for k in range(len(x)):
            xp, xm = x.copy(), x.copy()
            xp[k] += h
            xm[k] -= h
            cols.append(((predict(pts, xp, effects) - predict(pts, xm, effects)) / (2 * h)).ravel())
        Jc = np.array(cols).T
        model = FiveBar(*x[:4])
        return lambda eff: (r, Jc, self._regressors(model, eff))

    def _regressors(self, model: FiveBar, eff) -> np.ndarray:
        """The candidate's columns (2n x size): the point's derivative in the link length or actuator
        angle the effect changes, times the effect's basis functions."""
        pts = self.pts
        n = len(pts["id"])
        b = _basis(eff, np.radians(pts["theta1_deg"]), np.radians(pts["theta2_deg"]))
        R = np.zeros((2 * n, eff.size))
        for i in range(n):
            if _acts_on(eff) == "link_length":
                _, jl = _core.fivebar_errors(model, _subset(pts, slice(i, i + 1)))
                d = jl[:, eff.joint - 1]
            else:
                jm = model.jacobian(pts["theta1_deg"][i], pts["theta2_deg"][i])
                if jm is None:
                    raise ValueError(f"point {int(pts['id'][i])}: a singular pose of the hidden robot")
                d = jm[:, eff.joint - 1]
            R[2 * i:2 * i + 2] = np.outer(d, b[i])
        return R

    def describe(self, effect) -> dict:
        if _core.effect_kind(effect.name).concerns == "link":
            return {"effect": effect.name, "joint": None, "link": LINKS[effect.joint - 1]}
        return {"effect": effect.name, "joint": effect.joint}

    def label(self, effect) -> str:
        d = self.describe(effect)
        return f"{effect.name}(link {d['link']})" if "link" in d else effect.label

    def model_label(self, effects: list) -> str:
        return " + ".join(["four lengths"] + [self.label(e) for e in effects])


def diagnose(pts: dict, folds: int = 5, alpha: float = 1e-6, min_gain: float = 0.03, seed: int = 0,
             noise_mm: Optional[float] = None, say: Callable[[str], None] = lambda s: None) -> dict:
    """The model-discrepancy workflow on the hidden robot (the engine of kincal.stepwise; contract
    names link_deflection, with "link": "a".."d", and transmission_error with the actuator as
    "joint"), every candidate of library() allowed."""
    problem = Diagnosis(pts, folds, seed)
    cands = library()
    found = engine.search(problem, [], cands, alpha=alpha, min_gain=min_gain, max_steps=len(cands), say=say)
    x = fit_with_effects(pts, found.effects)
    e = np.linalg.norm(predict(pts, x, found.effects) - pts["measured"], axis=1)
    concl = engine.conclude(problem, found, e, len(x), noise_mm, alpha, say)
    return {"steps": found.steps, "final_rms_mm": found.cv_rms_mm, "noise_rms_mm": concl["noise_rms_mm"],
            "noise_known": concl["noise_known"], "fit_scatter_mm": concl["fit_scatter_mm"],
            "noise_per_coordinate_mm": concl["noise_per_coordinate_mm"],
            "verdict": concl["verdict"], "notes": [], "history": found.history, "folds": folds,
            "lengths_mm": x[:4].tolist()}


def effects_of(diag: dict) -> list:
    """The effects a diagnosis named (_core.Effect, joint: the link or actuator from 1)."""
    return [_core.Effect(s["effect"], LINKS.index(s["link"]) + 1 if s.get("link") else s["joint"])
            for s in diag["steps"]]


def write_diagnosis(pts: dict, diag: dict, out: Union[str, Path], title: str) -> None:
    """In the folder ``out``: residual_map.png (the four lengths against the model with the named
    effects), report.html and diagnosis.json."""
    with report.staged_folder(out) as folder:  # the whole folder or nothing
        _write_diagnosis(pts, diag, folder, title)


def _write_diagnosis(pts: dict, diag: dict, folder: Path, title: str) -> None:
    named = effects_of(diag)
    before = dict(pts, desired=predict(pts, fit_with_effects(pts, []), []))
    after = dict(pts, desired=predict(pts, fit_with_effects(pts, named), named))
    error_map_figure([("four lengths", before)] + ([("with the named effects", after)] if named else []),
                     str(folder / "residual_map.png"), title="five-bar: model minus measured position")
    rows = [[k + 1, s["effect"], s.get("link") or s["joint"], f"{s['evidence']['F']:.3g}",
             f"{s['rms_before_mm'] * 1000:.1f}", f"{s['rms_after_mm'] * 1000:.1f}"] for k, s in enumerate(diag["steps"])]
    steps = (report.table(["step", "effect", "link / actuator", "F", "CV RMS before (um)", "after (um)"], rows,
                          numeric=True, text=[1, 2]) if rows else
             "<p>No effect was named: no candidate passed the test.</p>")
    body = f"""<h1>{report.esc(title)}</h1>
{steps}
<p>{report.esc(diag['verdict'])}: cross-validated RMS {diag['final_rms_mm'] * 1000:.1f} um; {report.esc(engine.noise_phrase(diag))}.</p>
{report.figure("residual_map.png", "residual map")}"""
    report.write(folder / "report.html", title, body)
    _core.write_file_atomic(str(folder / "diagnosis.json"), strict_json.dumps(engine.contract_json(diag), indent=1) + "\n")


def diagnosis_summary(diag: dict) -> str:
    """`kincal diagnose --robot fivebar`'s summary: each named effect and the final verdict."""
    lines = [f"{st['effect']} {st.get('link') or st['joint']}: cross-validated RMS "
             f"{st['rms_before_mm'] * 1000:.1f} -> {st['rms_after_mm'] * 1000:.1f} um" for st in diag["steps"]]
    return "\n".join(lines + [f"final {diag['final_rms_mm'] * 1000:.1f} um ({engine.noise_phrase(diag)}): "
                              f"{diag['verdict']}"])


def points_csv(pts: dict) -> str:
    """A point set as the CSV of data/fivebar-table1.csv."""
    rows = [[int(i), t1, t2, d[0], d[1], m[0], m[1]] for i, t1, t2, d, m in
            zip(pts["id"], pts["theta1_deg"], pts["theta2_deg"], pts["desired"], pts["measured"])]
    return format_rows(["point", "theta1_deg", "theta2_deg", "x_desired_mm", "y_desired_mm", "x_measured_mm",
                        "y_measured_mm"], rows)
