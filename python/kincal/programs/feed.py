"""Derivative analysis of joint programs (section III of the Samak paper) and beyond.

The path is parametrised by the total vector displacement s of the axes (radians, Euclidean metric
in joint space), resampled uniformly and differentiated in s. From the normalised derivatives come
the feed limits of eqs. 21, 27 and 28: the largest rate of s (rad/s) each axis's velocity,
acceleration and jerk limit allows at every s. Eqs. 22-23 are kept as printed (the first derivative
divided by the acceleration and jerk limits); beside them the physically consistent chain-rule
terms (q' s-dot, q' s-ddot + q'' s-dot^2, q' s-dddot + 3 q'' s-dot s-ddot + q''' s-dot^3) and a
time-optimal feed profile under the velocity and acceleration limits with the jerk cap of eq. 28.

Resampling: ``linear`` is the paper's linear interpolation between the program's points (its
second derivative is a train of spikes at the points, its third is their differences);
``spline`` (the default) is the quintic interpolating spline through the same points: its derivatives
are smooth and, through exact points, exact (1e-5 on the tests' helix). It passes through every
point, so it differentiates the points' own scatter about a smooth path too (coordinates rounded
before the inverse kinematics, for instance): a scatter sigma at spacing h gives its third
derivative about 10 sigma / h^3 (point_scatter and scatter_derivative estimate it; the figures say
it).
"""

from __future__ import annotations

import functools
import math
import textwrap
from pathlib import Path
from typing import TYPE_CHECKING, Any, Optional, Sequence, Union

import numpy as np

from ..io import strict_json

if TYPE_CHECKING:
    from .._core import Robot
    from ..typing_ import BoolArray, FloatArray

METHODS = ("spline", "linear")
DEFAULT_SAMPLES = 2900
#: default commanded rate of s: about 250 mm/s of tool speed on the paper's 1480 mm line (rad/s)
DEFAULT_FEED = 0.25


def path_parameter(q_rad: FloatArray) -> FloatArray:
    """Total vector displacement s at every program point (rad)."""
    d = np.linalg.norm(np.diff(q_rad, axis=0), axis=1)
    return np.concatenate([[0.0], np.cumsum(d)])


def _nodes(q_rad: FloatArray) -> tuple[FloatArray, FloatArray]:
    """s and q at the program's points, repeated points dropped (they carry no path)."""
    q_rad = np.asarray(q_rad, dtype=float)
    if q_rad.ndim != 2 or len(q_rad) < 2:
        raise ValueError("a joint program needs at least two points")
    s_nodes = path_parameter(q_rad)
    keep = np.concatenate([[True], np.diff(s_nodes) > 1e-12])
    if keep.sum() < 2:
        raise ValueError("the program does not move")
    return s_nodes[keep], q_rad[keep]


def _degree(points: int) -> int:
    """The spline's degree for a program of this many (distinct) points."""
    return 5 if points >= 6 else (3 if points >= 4 else 1)


def resample(q_rad: FloatArray, samples: int = DEFAULT_SAMPLES, method: str = "spline"
             ) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray, FloatArray]:
    """s (samples,) and q, q', q'', q''' at those s (samples x dof), derivatives in s."""
    if method not in METHODS:
        raise ValueError(f"unknown method '{method}' ({', '.join(METHODS)})")
    q_rad = np.asarray(q_rad, dtype=float)
    s_nodes, q_nodes = _nodes(q_rad)
    s = np.linspace(0.0, s_nodes[-1], samples)
    if method == "linear":
        q = np.column_stack([np.interp(s, s_nodes, q_nodes[:, i]) for i in range(q_nodes.shape[1])])
        d1 = np.gradient(q, s, axis=0)
        d2 = np.gradient(d1, s, axis=0)
        d3 = np.gradient(d2, s, axis=0)
        return s, q, d1, d2, d3
    from scipy.interpolate import make_interp_spline

    k = _degree(len(s_nodes))
    spl = make_interp_spline(s_nodes, q_nodes, k=k, axis=0)
    return s, spl(s), spl(s, 1), spl(s, 2), spl(s, 3)


def _runs(mask: BoolArray) -> list[tuple[np.intp, np.intp]]:
    """(start, end) index pairs of the True runs of a boolean array."""
    if not mask.any():
        return []
    d = np.diff(np.concatenate([[0], mask.astype(np.int8), [0]]))
    return list(zip(np.flatnonzero(d == 1), np.flatnonzero(d == -1) - 1))


def time_optimal(s: FloatArray, d1: FloatArray, d2: FloatArray, v: FloatArray, a: FloatArray,
                 cap: Optional[FloatArray] = None) -> tuple[FloatArray, float]:
    """Time-optimal rate of s along the path (from rest to rest) under |q' s-dot| <= v and
    |q' s-ddot + q'' s-dot^2| <= a per axis, and s-dot <= cap (e.g. the jerk cap of eq. 28): the
    forward-backward integration of x = s-dot^2 on the grid (C++ core). Returns s-dot(s) and the
    traversal time."""
    from .. import _core

    c = np.zeros(0) if cap is None else np.asarray(cap, dtype=float)
    sd, t = _core.time_optimal_feed(np.asarray(s, dtype=float), np.ascontiguousarray(d1), np.ascontiguousarray(d2),
                                    np.asarray(v, dtype=float), np.asarray(a, dtype=float), c)
    return np.asarray(sd), float(t)


def analyse(q_deg: FloatArray, v_max: Sequence[float], a_max: Sequence[float], j_max: Sequence[float], *,
            feed: float = DEFAULT_FEED, samples: int = DEFAULT_SAMPLES, method: str = "spline",
            optimal: bool = True) -> dict[str, Any]:
    """The derivative analysis of one joint program (degrees, n x dof); limits per axis in deg/s,
    deg/s^2, deg/s^3. Returns the feed.json entry of the program plus the arrays (key ``arrays``)."""
    q = np.radians(np.asarray(q_deg, dtype=float))
    dof = q.shape[1]
    v, a, j = (np.radians(np.asarray(x, dtype=float)) for x in (v_max, a_max, j_max))
    for name, lim in (("velocity", v), ("acceleration", a), ("jerk", j)):
        if lim.shape != (dof,) or not np.all(lim > 0) or not np.all(np.isfinite(lim)):
            raise ValueError(f"{name} limits: {dof} positive finite values needed")
    if not (feed > 0 and math.isfinite(feed)):
        raise ValueError(f"the feed must be a positive number (rad/s), not {feed}")
    s, qs, d1, d2, d3 = resample(q, samples, method)
    a1, a2, a3 = np.abs(d1), np.abs(d2), np.abs(d3)
    nv = a1 / v                # |eq. 20|
    na2 = a2 / a               # |eq. 24|
    nj3 = a3 / j               # |eq. 26|
    p1, p2, p3 = a1.max(axis=0), a2.max(axis=0), a3.max(axis=0)  # peaks of eqs. 22, 23, 25 follow
    with np.errstate(divide="ignore"):
        sv = 1.0 / nv.max(axis=1)                              # eq. 21
        sa = np.sqrt(1.0 / na2.max(axis=1))                    # eq. 27
        sj = np.cbrt(1.0 / nj3.max(axis=1))                    # eq. 28
        s22 = 1.0 / (a1 / a).max(axis=1)                       # eq. 22 as printed
        s23 = 1.0 / (a1 / j).max(axis=1)                       # eq. 23 as printed
    violations: list[dict[str, Any]] = []
    for limit, curve, norm in (("velocity", sv, nv), ("acceleration", sa, na2), ("jerk", sj, nj3)):
        for i0, i1 in _runs(feed > curve):
            k = i0 + int(np.argmin(curve[i0:i1 + 1]))
            violations.append({"axis": int(np.argmax(norm[k])) + 1, "s": float(s[i0]), "s_end": float(s[i1]),
                               "limit": limit, "worst_s": float(s[k]), "allowed_feed": float(curve[k])})
    violations.sort(key=lambda d: (d["s"], d["limit"]))
    # chain rule at the constant feed: axis velocity, acceleration and jerk against the limits
    const = {"velocity_ratio": (p1 * feed / v).tolist(), "acceleration_ratio": (p2 * feed ** 2 / a).tolist(),
             "jerk_ratio": (p3 * feed ** 3 / j).tolist()}
    out: dict[str, Any] = {
        "method": method, "samples": int(samples), "feed_rad_s": feed,
        "s_total_rad": float(s[-1]), "s": s,
        "axes": [{"axis": i + 1, "peak_q_s_v": float(p1[i] / v[i]), "peak_q_s_a": float(p1[i] / a[i]),
                  "peak_q_s_j": float(p1[i] / j[i]), "peak_q_ss_a": float(p2[i] / a[i]),
                  "peak_q_ss_j": float(p2[i] / j[i]), "peak_q_sss_j": float(p3[i] / j[i])}
                 for i in range(dof)],
        "sdot_v_max": sv, "sdot_a_max": sa, "sdot_j_max": sj,
        "paper_eq22_sdot_max": s22, "paper_eq23_sdot_max": s23,
        "violations": violations,
        "constant_feed": const,
    }
    if optimal:
        sd, t = time_optimal(s, d1, d2, v, a, cap=sj)
        out["time_optimal"] = {"time_s": t, "constant_feed_time_s": float(s[-1] / feed), "sdot": sd}
    s_nodes, q_nodes = _nodes(q)
    out["arrays"] = {"s": s, "q": qs, "d1": d1, "d2": d2, "d3": d3, "sv": sv, "sa": sa, "sj": sj,
                     "scatter": point_scatter(q_nodes), "spacing": float(np.median(np.diff(s_nodes))),
                     "degree": _degree(len(s_nodes))}
    return out


def json_ready(result: dict[str, Any]) -> dict[str, Any]:
    """A result of analyse() for feed.json: arrays as lists, the raw arrays left out."""
    def conv(x: Any) -> Any:
        if isinstance(x, np.ndarray):
            return x.tolist()
        if isinstance(x, dict):
            return {k: conv(v) for k, v in x.items() if k != "arrays"}
        if isinstance(x, list):
            return [conv(v) for v in x]
        return x
    ready: dict[str, Any] = conv(result)
    return ready


def robot_limits(robot: Robot) -> tuple[list[float], list[float], list[float]]:
    """Velocity, acceleration and jerk limits (deg/s, /s^2, /s^3) of a robot's model."""
    joints = robot.nominal_spec.joints
    v = [jt.max_velocity_deg_s for jt in joints]
    a = [jt.max_acceleration_deg_s2 for jt in joints]
    j = [jt.max_jerk_deg_s3 for jt in joints]
    return v, a, j


def read_limits(path: str, dof: int, base: tuple[list[float], list[float], list[float]]
                ) -> tuple[list[float], list[float], list[float]]:
    """A limits CSV (axis, v_max, a_max, j_max; axis from 1) overriding the given limits."""
    from .. import _core

    t = _core.read_csv_columns(str(path), ["axis", "v_max", "a_max", "j_max"])
    v, a, j = (list(x) for x in base)
    for row, (ax, vv, aa, jj) in enumerate(t, start=2):
        k = int(ax)
        if k != ax or not 1 <= k <= dof:
            raise ValueError(f"{path}:{row}: axis {ax:g} is not one of 1..{dof}")
        if min(vv, aa, jj) <= 0:
            raise ValueError(f"{path}:{row}: limits must be positive")
        v[k - 1], a[k - 1], j[k - 1] = vv, aa, jj
    return v, a, j


#: order of the differences that estimate a program's scatter about a smooth path (a smooth path's
#: 6th differences are h^6 times its 6th derivative: negligible at a program's spacing)
SCATTER_ORDER = 6


def point_scatter(q_rad: FloatArray, order: int = SCATTER_ORDER) -> FloatArray:
    """Per axis, the scatter (standard deviation, rad) of a program's points about a smooth path, such
    as the rounding of coordinates written before the inverse kinematics, as it shows in q(s): across
    the path (a component along it moves a point along the path and the chord-length s follows it).
    The ``order``-th differences of the points, each without its component along the chord of its
    window, are median-scaled to the standard deviation of independent normal scatter
    (|median| / 0.6745 / sqrt(C(2 order, order))). The smooth path adds its own differences (h^order
    times its order-th derivative), so where it bends within a few points this is an upper estimate.
    NaN with fewer than 3 order points."""
    q = np.asarray(q_rad, dtype=float)
    if len(q) < 3 * order:
        return np.full(q.shape[1], np.nan)
    d = np.diff(q, order, axis=0)
    chord = q[order:] - q[:-order]
    norm = np.linalg.norm(chord, axis=1, keepdims=True)
    t = np.divide(chord, norm, out=np.zeros_like(chord), where=norm > 0)
    across = d - t * np.sum(d * t, axis=1, keepdims=True)
    sigma: FloatArray = np.median(np.abs(across), axis=0) / 0.6744897501960817 / math.sqrt(math.comb(2 * order, order))
    return sigma


@functools.lru_cache(maxsize=8)
def _unit_scatter_gain(k: int, derivative: int) -> tuple[float, float]:
    """Standard deviation of the ``derivative``-th derivative of the degree-k interpolating spline
    through independent unit scatter at 101 points 1 apart: rms over the middle half, and largest
    (at the ends)."""
    from scipy.interpolate import make_interp_spline

    n = 101
    x = np.arange(n, dtype=float)
    xs = np.linspace(0.0, n - 1.0, 20 * (n - 1) + 1)
    m = make_interp_spline(x, np.eye(n), k=k, axis=0)(xs, derivative)  # the spline's weights on each point
    g = np.sqrt(np.sum(m * m, axis=1))
    mid = (xs > 0.25 * (n - 1)) & (xs < 0.75 * (n - 1))
    return float(np.sqrt(np.mean(g[mid] ** 2))), float(g.max())


def scatter_derivative(sigma: Union[float, FloatArray], spacing: float, derivative: int,
                       k: int = 5) -> tuple[FloatArray, FloatArray]:
    """What a scatter ``sigma`` (rad) of points ``spacing`` apart in s (rad) alone gives the
    ``derivative``-th derivative of the interpolating spline of degree k (rad/rad^derivative): its
    standard deviation in the middle of the path and the largest one (at the ends), for independent
    scatter. The spline is linear in the points, so this is sigma times the spline's gain, which
    scales as spacing^-derivative. The scatter's component along the path moves the points along it
    and the chord-length s follows them: only the rest shows in q(s)."""
    rms, top = _unit_scatter_gain(k, derivative)
    scale = np.asarray(sigma, dtype=float) / spacing ** derivative
    return scale * rms, scale * top


def panel_range(data: Sequence[FloatArray], lines: Sequence[float], margin: float = 0.08,
                reach: float = 3.0) -> tuple[tuple[float, float], list[float], list[float]]:
    """The y range of one figure panel and which of the (signed) limit lines it shows. The range comes
    from the data: their [min, max] widened by ``margin`` of their height on each side (flat data get
    a height of 10% of their value, or 1 at zero). A limit line is drawn if the range widened to take
    it (with the same margin) is at most ``reach`` times the data's range, lines nearest the data
    first: the data always fill at least 1/reach of the panel; the others are off scale. Lines within
    the data are always drawn. Returns (lo, hi), the drawn lines and the off-scale ones."""
    parts = [np.ravel(np.asarray(x, dtype=float)) for x in data]
    d = np.concatenate(parts) if parts else np.zeros(0)
    d = d[np.isfinite(d)]
    if d.size == 0:
        return (-1.0, 1.0), [], sorted(lines)
    lo, hi = float(d.min()), float(d.max())
    height = hi - lo
    if height <= 1e-12 * max(abs(lo), abs(hi)):
        height = 0.1 * max(abs(lo), abs(hi)) or 1.0
        mid = 0.5 * (lo + hi)
        lo, hi = mid - 0.5 * height, mid + 0.5 * height
    pad = margin * height
    lo, hi = lo - pad, hi + pad
    most = reach * (hi - lo)
    drawn: list[float] = []
    off: list[float] = []
    for val in sorted(lines, key=lambda x: max(lo - x, x - hi, 0.0)):
        nlo, nhi = min(lo, val - pad), max(hi, val + pad)
        if nhi - nlo <= most:
            lo, hi = nlo, nhi
            drawn.append(val)
        else:
            off.append(val)
    return (lo, hi), drawn, off


def _fmt(x: float) -> str:
    """A limit's value: 3 significant digits, whole numbers from 1000 up (no exponent)."""
    return f"{x:.0f}" if abs(x) >= 1000 else f"{x:.3g}"


def off_scale_note(bounds: Sequence[tuple[float, str, str]], off: Sequence[float],
                   data: Sequence[FloatArray] = ()) -> str:
    """'off scale: jerk (eq. 23) ±104, ...' for the limit lines ``off`` of a panel whose lines are
    ``bounds`` ((value, kind, label), drawn at +-value), '(exceeded)' after a line the panel's ``data``
    pass; empty if none."""
    parts_d = [np.ravel(np.asarray(x, dtype=float)) for x in data]
    d = np.concatenate(parts_d) if parts_d else np.zeros(0)
    top, bottom = (float(d.max()), float(d.min())) if d.size else (-math.inf, math.inf)
    parts: list[str] = []
    for val, _, lab in bounds:
        plus, minus = val in off, -val in off
        passed = (plus and top > val) or (minus and bottom < -val)
        if plus and minus:
            parts.append(f"{lab} \u00b1{_fmt(val)}" + (" (exceeded)" if passed else ""))
        elif plus or minus:
            parts.append(f"{lab} {'+' if plus else '-'}{_fmt(val)}" + (" (exceeded)" if passed else ""))
    return "off scale: " + ", ".join(parts) if parts else ""


def _scatter_note(results: dict[str, dict[str, Any]], axis: int) -> str:
    """The figure's note on what the program points' scatter alone gives the derivatives."""
    if any(r.get("method") == "linear" for r in results.values()):
        return ("linear interpolation (the paper's): the second and third derivatives are spikes at the program's "
                "points and their differences, not the motion's derivatives")
    i = axis - 1
    parts: list[str] = []
    sig, spacing, k = -1.0, 1.0, 5
    for key, r in results.items():
        arr = r["arrays"]
        if "scatter" not in arr or not np.isfinite(arr["scatter"][i]):
            return ""
        parts.append(f"{arr['scatter'][i]:.2g} rad ({r.get('label', key)})")
        if arr["scatter"][i] > sig:  # the largest scatter, with its program's spacing
            sig, spacing, k = float(arr["scatter"][i]), float(arr["spacing"]), int(arr["degree"])
    (r2, _), (r3, _) = scatter_derivative(sig, spacing, 2, k), scatter_derivative(sig, spacing, 3, k)
    gain_mid, gain_end = _unit_scatter_gain(k, 3)
    return (f"The spline passes through every program point, so its derivatives also carry the points' scatter about "
            f"a smooth path (e.g. coordinates rounded before the inverse kinematics): on A{axis} about "
            f"{', '.join(parts)} by median {SCATTER_ORDER}th differences, points {spacing:.2g} rad apart in s. "
            f"That alone gives $\\theta_{{ss}}$ \u00b1{2 * r2:.2g} 1/rad and $\\theta_{{sss}}$ \u00b1{2 * r3:.2g} "
            f"1/rad$^2$ (2 standard deviations of independent scatter, {gain_end / gain_mid:.0f} times more at the ends): "
            f"a ripple of that size is the program's own, not the smooth path's.")


#: drawing order and style: the compared program wide and light underneath, the program on top
_STYLE: dict[str, dict[str, Any]] = {"compare": {"color": "tab:blue", "lw": 3.0, "alpha": 0.45, "zorder": 2},
          "program": {"color": "tab:red", "lw": 1.1, "zorder": 3}}


def figure(results: dict[str, dict[str, Any]], v_max: Sequence[float], a_max: Sequence[float],
           j_max: Sequence[float], feed: float, axis: int, path: str, window: Optional[tuple[float, float]] = None,
           zoom: Optional[tuple[float, float]] = None) -> dict[tuple[int, int], dict[str, Any]]:
    """Fig. 1 of the paper for one axis: the coordinate and its three derivatives in s, the programs
    compared, with the constraint lines +- limit / feed^k (velocity green, acceleration magenta, jerk
    cyan), over a window and a zoomed one. Every panel scales to its own data (panel_range); limit
    lines that would flatten the data are named with their values above the panel instead. Returns
    per panel (row 0-3: theta and its derivatives; column 0 the window, 1 the zoom) its y range, the
    limit lines drawn and off scale, and the note above it."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.lines import Line2D

    i = axis - 1
    v, a, j = (math.radians(x[i]) for x in (v_max, a_max, j_max))
    first = next(iter(results.values()))["arrays"]["s"]
    window = window or (float(first[0]), float(first[-1]))
    if zoom is None:
        mid, w = 0.5 * (window[0] + window[1]), 0.0075 * (first[-1] - first[0])
        zoom = (mid - w, mid + w)
    order = sorted(results, key=lambda k: _STYLE.get(k, {}).get("zorder", 4))
    # a row for the legend above the panels and one for the note below them: neither covers data
    fig = plt.figure(figsize=(12, 12), layout="constrained")
    grid = fig.add_gridspec(6, 2, height_ratios=[0.12, 1, 1, 1, 1, 0.3])
    axes = np.empty((4, 2), dtype=object)
    for col in range(2):
        for row in range(4):
            axes[row, col] = fig.add_subplot(grid[row + 1, col], sharex=axes[0, col] if row else None)
            if row < 3:
                axes[row, col].tick_params(labelbottom=False)
    top, bottom = fig.add_subplot(grid[0, :]), fig.add_subplot(grid[5, :])
    top.axis("off")
    bottom.axis("off")
    names = [r"$\theta$ (rad)", r"$\theta_s$ (rad/rad)", r"$\theta_{ss}$ (1/rad)", r"$\theta_{sss}$ (1/rad$^2$)"]
    colour = {"velocity": "g", "acceleration": "m", "jerk": "c"}
    rows = [[], [(v / feed, "velocity", "velocity"), (a / feed, "acceleration", "acceleration (eq. 22)"),
                 (j / feed, "jerk", "jerk (eq. 23)")],
            [(a / feed ** 2, "acceleration", "acceleration"), (j / feed ** 2, "jerk", "jerk (eq. 25)")],
            [(j / feed ** 3, "jerk", "jerk")]]
    kinds_drawn: set[str] = set()
    panels: dict[tuple[int, int], dict[str, Any]] = {}
    for col, (lo, hi) in enumerate((window, zoom)):
        for row, key in enumerate(("q", "d1", "d2", "d3")):
            ax = axes[row, col]
            data: list[FloatArray] = []
            for name in order:
                arr = results[name]["arrays"]
                m = (arr["s"] >= lo) & (arr["s"] <= hi)
                ax.plot(arr["s"][m], arr[key][m, i], **_STYLE.get(name, {"lw": 1, "zorder": 4}))
                data.append(arr[key][m, i])
            bounds = rows[row]
            (ylo, yhi), drawn, off = panel_range(data, [sg * b[0] for b in bounds for sg in (1, -1)])
            for val, kind, _ in bounds:
                for sg in (1, -1):
                    if sg * val in drawn:
                        ax.axhline(sg * val, color=colour[kind], ls=":", lw=1.2, zorder=1)
                        kinds_drawn.add(kind)
            ax.set_ylim(ylo, yhi)
            ax.set_ylabel(names[row])
            note = off_scale_note(bounds, off, data)
            if note:
                ax.set_title(note, fontsize=8, loc="right")
            panels[row, col] = {"ylim": (ylo, yhi), "drawn": drawn, "off": off, "note": note}
        axes[3, col].set_xlabel("s (rad)")
        axes[0, col].set_title(f"s in [{lo:.4g}, {hi:.4g}] rad" + (" (zoom)" if col else ""), fontsize=10)
    handles = [Line2D([], [], **{k: x for k, x in _STYLE.get(n, {"lw": 1}).items() if k != "zorder"},
                      label=results[n].get("label", n)) for n in reversed(order)]
    handles += [Line2D([], [], color=colour[k], ls=":", lw=1.2, label=f"{k} limit / feed$^k$")
                for k in ("velocity", "acceleration", "jerk") if k in kinds_drawn]
    fig.suptitle(f"axis A{axis}: the joint coordinate and its derivatives in s (total axis displacement, rad); "
                 f"constraint lines at feed {feed:g} rad/s")
    top.legend(handles=handles, loc="center", ncol=len(handles), fontsize=9, frameon=False)
    caption = bottom.text(0.0, 1.0, textwrap.fill(_scatter_note(results, axis), 185), fontsize=8, va="top", ha="left",
                       transform=bottom.transAxes)
    caption.set_in_layout(False)  # the row below the panels holds it; a long line must not squeeze them
    fig.savefig(path, dpi=100)
    plt.close(fig)
    return panels


def analyse_files(robot: Robot, robot_arg: str, programs: dict[str, str], out: str, *,
                  limits_path: Optional[str] = None, feed: float = DEFAULT_FEED, samples: int = DEFAULT_SAMPLES,
                  method: str = "spline", window: Optional[tuple[float, float]] = None,
                  zoom: Optional[tuple[float, float]] = None) -> dict[str, dict[str, Any]]:
    """`kincal feed`: the joint programs ``programs`` (key -> file: "program" and optionally
    "compare") analysed against the robot's limits (overridden by the CSV ``limits_path``); writes
    out/feed.json and one figure per axis. Returns the results by key (with ``file`` and ``label``)."""
    from .. import _core

    limits = robot_limits(robot)
    if limits_path:
        limits = read_limits(limits_path, robot.dof, limits)
    for name, lim in zip(("velocity", "acceleration", "jerk"), limits):
        if not all(x > 0 for x in lim):
            raise ValueError(f"{robot_arg}: the model has no {name} limit for some axis; give --limits L.csv")
    results: dict[str, dict[str, Any]] = {}
    for key, path in programs.items():
        q, _ = _core.read_joint_program(path, robot.dof)
        res = analyse(np.asarray(q), *limits, feed=feed, samples=samples, method=method)
        res["file"] = path
        res["label"] = Path(path).name
        results[key] = res
    folder = Path(out)
    folder.mkdir(parents=True, exist_ok=True)
    figures: list[str] = []
    for axis in range(1, robot.dof + 1):
        name = f"axis{axis}.png"
        figure(results, *limits, feed, axis, str(folder / name), window=window, zoom=zoom)
        figures.append(name)
    doc = {"feed_rad_s": feed, "method": method, "samples": samples,
           "limits": {"v_max_deg_s": limits[0], "a_max_deg_s2": limits[1], "j_max_deg_s3": limits[2]},
           "programs": {k: json_ready(r) for k, r in results.items()},
           "figures": figures}
    _core.write_file_atomic(str(folder / "feed.json"), strict_json.dumps(doc) + "\n")
    return results


def summary(results: dict[str, dict[str, Any]], feed: float) -> str:
    """`kincal feed`'s summary of analyse_files()'s results: per program its length in s, its
    violations at the rate ``feed`` (the first ten) and its time-optimal traversal."""
    lines: list[str] = []
    for k, r in results.items():
        t = r.get("time_optimal", {})
        lines.append(f"{k} ({r['file']}): s = {r['s_total_rad']:.4f} rad, {len(r['violations'])} violation(s) at "
                     f"{feed:g} rad/s; time-optimal traversal {t.get('time_s', float('nan')):.3f} s")
        for v in r["violations"][:10]:
            lines.append(f"  axis A{v['axis']} {v['limit']} limit from s = {v['s']:.4f} to {v['s_end']:.4f} rad "
                         f"(allowed feed down to {v['allowed_feed']:.4g} rad/s)")
    return "\n".join(lines)
