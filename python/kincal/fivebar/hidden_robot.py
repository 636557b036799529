"""The Kiper paper's hidden robot: link-length synthesis, the error-correction matrix, commands and
the error map (the diagnosis of what the four lengths miss: fivebar/diagnosis.py).

A point set is a dict of numpy arrays (``id``, ``theta1_deg``, ``theta2_deg``, ``desired`` n x 2,
``measured`` n x 2), the rows of data/fivebar-table1.csv. Kinematics, synthesis, the subset search
and the nonlinear fit run in the C++ core; the minimax fit is a sequence of linear programs here.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any, Optional

import numpy as np

from .. import _core
from .. import report
from ..io import strict_json
from .._core import ErrorMatrix, FiveBar
from ..io.csv_text import format_rows

if TYPE_CHECKING:
    from .._core import FiveBarPoints
    from ..typing_ import FloatArray

METHODS = ("polynomial", "lsq", "minimax", "nonlinear")

#: the paper's workspace (Table I): 100 mm x 150 mm
WORKSPACE = ((162.132, 262.132), (-75.0, 75.0))


def read_table(path: str) -> FiveBarPoints:
    """A table with the columns of data/fivebar-table1.csv (errors name file:line and cause)."""
    return _core.read_fivebar_table(str(path))


def largest_error(model: FiveBar, pts: FiveBarPoints, desired: bool) -> float:
    """The largest distance (mm) between the model's position at the commanded angles and the
    desired (``desired``) or the measured position of every point: a fit's score."""
    return float(_core.fivebar_max_error(model, pts, desired))



def minimax_fit(pts: FiveBarPoints, start: FiveBar, desired: bool = False, sides: int = 64,
                max_iter: int = 200) -> FiveBar:
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


def fit(pts: FiveBarPoints, method: str = "lsq", score: str = "measured") -> dict[str, Any]:
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
    out: dict[str, Any] = {"method": method, "score": score}
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


def model_of(fit_json: dict[str, Any]) -> FiveBar:
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


def grid_targets(spacing: float = 5.0,
                 workspace: tuple[tuple[float, float], tuple[float, float]] = WORKSPACE) -> FloatArray:
    (x0, x1), (y0, y1) = workspace
    xs = np.arange(x0, x1 + 1e-9, spacing)
    ys = np.arange(y0, y1 + 1e-9, spacing)
    return np.array([(x, y) for y in ys for x in xs])


def command(model: FiveBar, xy: FloatArray, matrix: Optional[ErrorMatrix] = None) -> FloatArray:
    """Joint commands (deg, n x 2) for desired points (n x 2)."""
    return _core.fivebar_command(model, matrix, np.asarray(xy, dtype=float).reshape(-1, 2))


#: how far (deg) a grid's angles may be from its model's commands: the rounding of a controller's
#: numbers, far below what a different fit changes (hundredths to tenths of a degree)
COMMAND_TOLERANCE_DEG = 0.005


def check_commanded_by(model: FiveBar, pts: FiveBarPoints, fit_file: str, grid_file: str) -> FiveBarPoints:
    """``pts`` when its angles are the commands ``model`` gives for its desired points: an error
    matrix corrects the model that commanded the grid, and only that one. Otherwise a ValueError
    naming the grid's line, the angles and the model's."""
    try:  # the core names the grid file's line of a point it cannot command
        q = _core.fivebar_command(model, None, np.asarray(pts["desired"], dtype=float).reshape(-1, 2), grid_file,
                                  [int(v) for v in pts["line"]])
    except ValueError as e:
        raise ValueError(f"{e} for {fit_file}") from None
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


def position_errors(points: FiveBarPoints) -> FloatArray:
    """Distance (mm) between desired and measured position of every point."""
    err: FloatArray = np.linalg.norm(points["measured"] - points["desired"], axis=1)
    return err


def error_map_figure(maps: list[tuple[str, FiveBarPoints]], path: str,
                     title: str = "five-bar positioning error") -> None:
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


def points_csv(pts: FiveBarPoints) -> str:
    """A point set as the CSV of data/fivebar-table1.csv."""
    rows = [[int(i), t1, t2, d[0], d[1], m[0], m[1]] for i, t1, t2, d, m in
            zip(pts["id"], pts["theta1_deg"], pts["theta2_deg"], pts["desired"], pts["measured"])]
    return format_rows(["point", "theta1_deg", "theta2_deg", "x_desired_mm", "y_desired_mm", "x_measured_mm",
                        "y_measured_mm"], rows)
