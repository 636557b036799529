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
``spline`` (the default) is the quintic interpolating spline through the same points, whose
derivatives are exact and smooth: it does not invent violations.
"""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Optional, Sequence

import numpy as np

METHODS = ("spline", "linear")
DEFAULT_SAMPLES = 2900
#: default commanded rate of s: about 250 mm/s of tool speed on the paper's 1480 mm line (rad/s)
DEFAULT_FEED = 0.25


def path_parameter(q_rad: np.ndarray) -> np.ndarray:
    """Total vector displacement s at every program point (rad)."""
    d = np.linalg.norm(np.diff(q_rad, axis=0), axis=1)
    return np.concatenate([[0.0], np.cumsum(d)])


def resample(q_rad: np.ndarray, samples: int = DEFAULT_SAMPLES, method: str = "spline"):
    """s (samples,) and q, q', q'', q''' at those s (samples x dof), derivatives in s."""
    if method not in METHODS:
        raise ValueError(f"unknown method '{method}' ({', '.join(METHODS)})")
    q_rad = np.asarray(q_rad, dtype=float)
    if q_rad.ndim != 2 or len(q_rad) < 2:
        raise ValueError("a joint program needs at least two points")
    s_nodes = path_parameter(q_rad)
    keep = np.concatenate([[True], np.diff(s_nodes) > 1e-12])  # repeated points carry no path
    s_nodes, q_nodes = s_nodes[keep], q_rad[keep]
    if len(s_nodes) < 2:
        raise ValueError("the program does not move")
    s = np.linspace(0.0, s_nodes[-1], samples)
    if method == "linear":
        q = np.column_stack([np.interp(s, s_nodes, q_nodes[:, i]) for i in range(q_nodes.shape[1])])
        d1 = np.gradient(q, s, axis=0)
        d2 = np.gradient(d1, s, axis=0)
        d3 = np.gradient(d2, s, axis=0)
        return s, q, d1, d2, d3
    from scipy.interpolate import make_interp_spline

    k = 5 if len(s_nodes) >= 6 else (3 if len(s_nodes) >= 4 else 1)
    spl = make_interp_spline(s_nodes, q_nodes, k=k, axis=0)
    return s, spl(s), spl(s, 1), spl(s, 2), spl(s, 3)


def _runs(mask: np.ndarray):
    """(start, end) index pairs of the True runs of a boolean array."""
    if not mask.any():
        return []
    d = np.diff(np.concatenate([[0], mask.astype(np.int8), [0]]))
    return list(zip(np.flatnonzero(d == 1), np.flatnonzero(d == -1) - 1))


def time_optimal(s: np.ndarray, d1: np.ndarray, d2: np.ndarray, v: np.ndarray, a: np.ndarray,
                 cap: Optional[np.ndarray] = None) -> tuple[np.ndarray, float]:
    """Time-optimal rate of s along the path (from rest to rest) under |q' s-dot| <= v and
    |q' s-ddot + q'' s-dot^2| <= a per axis, and s-dot <= cap (e.g. the jerk cap of eq. 28): the
    forward-backward integration of x = s-dot^2 on the grid (C++ core). Returns s-dot(s) and the
    traversal time."""
    from . import _core

    c = np.zeros(0) if cap is None else np.asarray(cap, dtype=float)
    sd, t = _core.time_optimal_feed(np.asarray(s, dtype=float), np.ascontiguousarray(d1), np.ascontiguousarray(d2),
                                    np.asarray(v, dtype=float), np.asarray(a, dtype=float), c)
    return np.asarray(sd), float(t)


def analyse(q_deg: np.ndarray, v_max: Sequence[float], a_max: Sequence[float], j_max: Sequence[float], *,
            feed: float = DEFAULT_FEED, samples: int = DEFAULT_SAMPLES, method: str = "spline",
            optimal: bool = True) -> dict:
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
    violations = []
    for limit, curve, norm in (("velocity", sv, nv), ("acceleration", sa, na2), ("jerk", sj, nj3)):
        for i0, i1 in _runs(feed > curve):
            k = i0 + int(np.argmin(curve[i0:i1 + 1]))
            violations.append({"axis": int(np.argmax(norm[k])) + 1, "s": float(s[i0]), "s_end": float(s[i1]),
                               "limit": limit, "worst_s": float(s[k]), "allowed_feed": float(curve[k])})
    violations.sort(key=lambda d: (d["s"], d["limit"]))
    # chain rule at the constant feed: axis velocity, acceleration and jerk against the limits
    const = {"velocity_ratio": (p1 * feed / v).tolist(), "acceleration_ratio": (p2 * feed ** 2 / a).tolist(),
             "jerk_ratio": (p3 * feed ** 3 / j).tolist()}
    out = {
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
    out["arrays"] = {"s": s, "q": qs, "d1": d1, "d2": d2, "d3": d3, "sv": sv, "sa": sa, "sj": sj}
    return out


def json_ready(result: dict) -> dict:
    """A result of analyse() for feed.json: arrays as lists, the raw arrays left out."""
    def conv(x):
        if isinstance(x, np.ndarray):
            return x.tolist()
        if isinstance(x, dict):
            return {k: conv(v) for k, v in x.items() if k != "arrays"}
        if isinstance(x, list):
            return [conv(v) for v in x]
        return x
    return conv(result)


def robot_limits(robot) -> tuple[list, list, list]:
    """Velocity, acceleration and jerk limits (deg/s, /s^2, /s^3) of a robot's model."""
    joints = json.loads(robot.to_json())["nominal"]["joints"]
    v = [jt["max_velocity_deg_s"] for jt in joints]
    a = [jt["max_acceleration_deg_s2"] for jt in joints]
    j = [jt["max_jerk_deg_s3"] for jt in joints]
    return v, a, j


def read_limits(path: str, dof: int, base: tuple[list, list, list]) -> tuple[list, list, list]:
    """A limits CSV (axis, v_max, a_max, j_max; axis from 1) overriding the given limits."""
    from . import _core

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


def figure(results: dict, v_max, a_max, j_max, feed: float, axis: int, path: str,
           window: Optional[tuple] = None, zoom: Optional[tuple] = None) -> None:
    """Fig. 1 of the paper for one axis: the coordinate and its three derivatives in s, the programs
    compared, with the constraint curves (velocity green, acceleration magenta, jerk cyan), over a
    window and a zoomed one."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    i = axis - 1
    v, a, j = (math.radians(x[i]) for x in (v_max, a_max, j_max))
    first = next(iter(results.values()))["arrays"]["s"]
    window = window or (float(first[0]), float(first[-1]))
    if zoom is None:
        mid, w = 0.5 * (window[0] + window[1]), 0.0075 * (first[-1] - first[0])
        zoom = (mid - w, mid + w)
    fig, axes = plt.subplots(4, 2, figsize=(12, 10), sharex="col", constrained_layout=True)
    colours = {"program": "tab:red", "compare": "tab:blue"}
    names = ["theta (rad)", "theta_s", "theta_ss", "theta_sss (1/rad^2)"]
    for col, (lo, hi) in enumerate((window, zoom)):
        for name, res in results.items():
            arr = res["arrays"]
            m = (arr["s"] >= lo) & (arr["s"] <= hi)
            for row, key in enumerate(("q", "d1", "d2", "d3")):
                axes[row, col].plot(arr["s"][m], arr[key][m, i], color=colours.get(name, None), lw=1,
                                    label=res.get("label", name))
        for row, bounds in enumerate([[], [(v / feed, "g", "velocity"), (a / feed, "m", "acceleration (eq. 22)"),
                                           (j / feed, "c", "jerk (eq. 23)")],
                                      [(a / feed ** 2, "m", "acceleration"), (j / feed ** 2, "c", "jerk (eq. 25)")],
                                      [(j / feed ** 3, "c", "jerk")]]):
            for val, c, lab in bounds:
                for sign in (1, -1):
                    axes[row, col].axhline(sign * val, color=c, ls=":", lw=1, label=lab if sign > 0 else None)
            axes[row, col].set_ylabel(names[row])
            if row > 0:
                data = np.concatenate([r["arrays"][("d1", "d2", "d3")[row - 1]][:, i] for r in results.values()])
                span = max(np.max(np.abs(data)) * 1.3, 1e-12)
                if not bounds or min(b[0] for b in bounds) > 20 * span:
                    axes[row, col].set_ylim(-span, span)  # the limits are far away: show the data
        axes[3, col].set_xlabel("s (rad)")
        axes[0, col].set_title(f"axis A{axis}, s in [{lo:.3f}, {hi:.3f}] rad")
    axes[1, 0].legend(fontsize=7, loc="upper right")
    axes[0, 0].legend(fontsize=8)
    fig.suptitle(f"derivative analysis at feed {feed:g} rad/s (constraint lines: +- limit / feed^k)")
    fig.savefig(path, dpi=100)
    plt.close(fig)


def analyse_files(robot, robot_arg: str, programs: dict, out: str, *, limits_path: Optional[str] = None,
                  feed: float = DEFAULT_FEED, samples: int = DEFAULT_SAMPLES, method: str = "spline",
                  window: Optional[tuple] = None, zoom: Optional[tuple] = None) -> dict:
    """`kincal feed`: the joint programs ``programs`` (key -> file: "program" and optionally
    "compare") analysed against the robot's limits (overridden by the CSV ``limits_path``); writes
    out/feed.json and one figure per axis. Returns the results by key (with ``file`` and ``label``)."""
    from . import _core

    limits = robot_limits(robot)
    if limits_path:
        limits = read_limits(limits_path, robot.dof, limits)
    for name, lim in zip(("velocity", "acceleration", "jerk"), limits):
        if not all(x > 0 for x in lim):
            raise ValueError(f"{robot_arg}: the model has no {name} limit for some axis; give --limits L.csv")
    results = {}
    for key, path in programs.items():
        q, _ = _core.read_joint_program(path, robot.dof)
        res = analyse(np.asarray(q), *limits, feed=feed, samples=samples, method=method)
        res["file"] = path
        res["label"] = Path(path).name
        results[key] = res
    folder = Path(out)
    folder.mkdir(parents=True, exist_ok=True)
    figures = []
    for axis in range(1, robot.dof + 1):
        name = f"axis{axis}.png"
        figure(results, *limits, feed, axis, str(folder / name), window=window, zoom=zoom)
        figures.append(name)
    doc = {"feed_rad_s": feed, "method": method, "samples": samples,
           "limits": {"v_max_deg_s": limits[0], "a_max_deg_s2": limits[1], "j_max_deg_s3": limits[2]},
           "programs": {k: json_ready(r) for k, r in results.items()},
           "figures": figures}
    _core.write_file_atomic(str(folder / "feed.json"), json.dumps(doc) + "\n")
    return results


def summary(results: dict, feed: float) -> str:
    """`kincal feed`'s summary of analyse_files()'s results: per program its length in s, its
    violations at the rate ``feed`` (the first ten) and its time-optimal traversal."""
    lines = []
    for k, r in results.items():
        t = r.get("time_optimal", {})
        lines.append(f"{k} ({r['file']}): s = {r['s_total_rad']:.4f} rad, {len(r['violations'])} violation(s) at "
                     f"{feed:g} rad/s; time-optimal traversal {t.get('time_s', float('nan')):.3f} s")
        for v in r["violations"][:10]:
            lines.append(f"  axis A{v['axis']} {v['limit']} limit from s = {v['s']:.4f} to {v['s_end']:.4f} rad "
                         f"(allowed feed down to {v['allowed_feed']:.4g} rad/s)")
    return "\n".join(lines)
