"""Standard accuracy statistics from measured runs: ISO 9283 (robots) and ISO 230-2 / VDI/DGQ 3441
(one axis, or one coordinate of a mechanism). `kincal accuracy iso9283` and `kincal accuracy axis`;
the reports are written by accuracy_report.py.

Sources of the formulas (symbols as in the standards; every standard deviation has n - 1 in its
denominator):

- ISO 9283:1998, *Manipulating industrial robots - Performance criteria and related test methods*:
  7.2.1 pose accuracy AP (AP_P = |barycentre - commanded position|, AP_x = mean x - x_c, ...;
  AP_a = mean a - a_c, ...), 7.2.2 pose repeatability (RP_l = mean(l) + 3 S_l with l_j the distance
  of attained position j from the barycentre; RP_a = +-3 S_a), 7.3 multi-directional pose accuracy
  variation (vAP_P: the largest distance between the barycentres reached from two approach
  directions; vAP_a: the largest difference of their mean angles), 7.4 distance accuracy
  (AD = mean attained distance - commanded distance) and distance repeatability (RD = +-3 S_D), and
  6.2 (the test cube and the poses P1..P5, see iso9283_plan.py).
- ISO 230-2:2014, *Test code for machine tools - Part 2: Determination of accuracy and repeatability
  of positioning of numerically controlled axes*: positional deviation x_ij = measured - target;
  mean unidirectional positional deviations mean_up, mean_down; reversal value B_i = mean_up -
  mean_down and of the axis B = max |B_i|; unidirectional repeatability R_up = 4 s_up, bidirectional
  R_i = max(2 s_up + 2 s_down + |B_i|, R_up, R_down), R = max R_i; bidirectional systematic
  positioning error E = max(mean_up, mean_down) - min(mean_up, mean_down) over all targets; mean
  bidirectional positioning error M = max - min of (mean_up + mean_down) / 2; bidirectional accuracy
  A = max(mean_up + 2 s_up, mean_down + 2 s_down) - min(mean_up - 2 s_up, mean_down - 2 s_down).
- VDI/DGQ 3441:1977, *Statistische Pruefung der Arbeits- und Positionsgenauigkeit von
  Werkzeugmaschinen*: per target j the mean position deviation mean_j = (mean_up + mean_down) / 2,
  reversal span U_j = |mean_up - mean_down|, position scatter Ps_j = 6 s_j with s_j the mean of the
  two directions' standard deviations; position deviation Pa = max mean_j - min mean_j; position
  uncertainty P = max(mean_j + (U_j + Ps_j) / 2) - min(mean_j - (U_j + Ps_j) / 2); U and Ps the
  largest over the targets. Per metre of travel (as the Kiper paper states its figures): P / L with
  L the travel (largest - smallest target) in metres.

Orientation angles a,b,c are the contract's KUKA ABC angles; their deviations are taken angle by
angle, wrapped to (-180, 180], as ISO 9283 does with its own angle triple (near b = +-90 deg a and c
are coupled and their separate statistics lose their meaning).

Rows may come in any order: they are sorted (points in natural order: P2 before P10) before any sum,
so the same rows give the same report to the last bit."""

from __future__ import annotations

import csv
import itertools
import math
import re
from typing import TYPE_CHECKING, Any, Optional, Sequence, TypeVar

import numpy as np

from .. import _core

if TYPE_CHECKING:
    from ..typing_ import FloatArray, IntArray

#: what rows are grouped by (a point's name, a direction, a target position)
K = TypeVar("K")

POSITION = ["x", "y", "z"]
ANGLES = ["a", "b", "c"]


# --- reading ------------------------------------------------------------------------------------

def read_table(path: str, required: Sequence[str], optional: Sequence[str] = ()) -> dict[str, Any]:
    """The columns ``required`` (a missing one is an error naming it) and those of ``optional`` the
    CSV has, as texts, with ``line`` (the file's line of each row; blank lines skipped)."""
    with open(path, newline="", encoding="utf-8-sig") as f:  # a leading BOM (Excel) is no part of a name
        reader = csv.reader(f)
        head: Optional[list[str]] = None
        cols: dict[str, list[str]] = {}
        lines: list[int] = []
        for row in reader:
            if not any(c.strip() for c in row):
                continue
            if head is None:
                head = [h.strip() for h in row]
                for name in required:
                    if name not in head:
                        raise ValueError(f"{path}:{reader.line_num}: missing column '{name}' (header: {','.join(head)})")
                names = list(required) + [n for n in optional if n in head]
                cols = {n: [] for n in names}
                index = {n: head.index(n) for n in names}
                continue
            if len(row) != len(head):
                raise ValueError(f"{path}:{reader.line_num}: {len(row)} fields, the header has {len(head)}")
            for n, i in index.items():
                cols[n].append(row[i].strip())
            lines.append(reader.line_num)
    if head is None:
        raise ValueError(f"{path}: empty file (expected a header row)")
    if not lines:
        raise ValueError(f"{path}: no data rows")
    return dict(cols, line=lines, source=path)


def numbers(t: dict[str, Any], name: str) -> FloatArray:
    """Column ``name`` of a table as finite floats (an error names the file, line and column)."""
    out = np.empty(len(t["line"]))
    for i, (text, line) in enumerate(zip(t[name], t["line"])):
        try:
            v = float(text)
        except ValueError:
            raise ValueError(f"{t['source']}:{line}: column '{name}': '{text}' is not a number") from None
        if not math.isfinite(v):
            raise ValueError(f"{t['source']}:{line}: column '{name}': '{text}' is not a finite number")
        out[i] = v
    return out


def integers(t: dict[str, Any], name: str) -> IntArray:
    out = numbers(t, name)
    bad = np.flatnonzero(out != np.round(out))
    if len(bad):
        raise ValueError(f"{t['source']}:{t['line'][bad[0]]}: column '{name}': '{t[name][bad[0]]}' is not an integer")
    return out.astype(np.int64)


def natural_key(name: str) -> tuple[tuple[int, int, str], ...]:
    """P2 before P10: digit runs compare as numbers."""
    return tuple((0, int(p), "") if p.isdigit() else (1, 0, p) for p in re.split(r"(\d+)", name) if p)


def _triple_set(t_head: Sequence[str], names: Sequence[str], path: str) -> bool:
    """True when every column of ``names`` is there, False when none is; an error when some are."""
    have = [n for n in names if n in t_head]
    if have and len(have) != len(names):
        missing = [n for n in names if n not in t_head][0]
        raise ValueError(f"{path}:1: missing column '{missing}': orientation needs ac,bc,cc and a,b,c")
    return bool(have)


def read_runs(path: str) -> dict[str, Any]:
    """RUNS.csv of `kincal accuracy iso9283`: point, cycle, commanded xc,yc,zc[,ac,bc,cc], attained
    x,y,z[,a,b,c][,direction]. Returns the rows sorted (point, direction, cycle) with ``cmd`` and
    ``att`` (N x 3, or N x 6 with orientation), ``point``, ``cycle``, ``direction`` (None without the
    column), ``line``, ``source`` and ``orientation``."""
    cmd_names = ["xc", "yc", "zc"]
    probe = read_table(path, [], ["ac", "bc", "cc", "a", "b", "c", "direction"])
    orient = _triple_set(list(probe), ["ac", "bc", "cc", "a", "b", "c"], path)
    req = ["point", "cycle"] + cmd_names + (["ac", "bc", "cc"] if orient else []) + POSITION + (ANGLES if orient else [])
    t = read_table(path, req, ["direction"])
    cmd = np.column_stack([numbers(t, n) for n in cmd_names + (["ac", "bc", "cc"] if orient else [])])
    att = np.column_stack([numbers(t, n) for n in POSITION + (ANGLES if orient else [])])
    cycle = integers(t, "cycle")
    for i, p in enumerate(t["point"]):
        if not p:
            raise ValueError(f"{path}:{t['line'][i]}: column 'point' is empty")
    direction = t.get("direction")
    dkey = direction if direction is not None else [""] * len(cycle)
    order = sorted(range(len(cycle)), key=lambda i: (natural_key(t["point"][i]), t["point"][i], dkey[i], cycle[i]))
    seen: dict[tuple[str, str, int], int] = {}
    for i in order:
        key = (t["point"][i], dkey[i], cycle[i])
        if key in seen:
            what = f"point {key[0]}" + (f" direction {key[1]}" if direction is not None else "") + f" cycle {key[2]}"
            raise ValueError(f"{path}:{t['line'][i]}: {what} is measured twice (line {t['line'][seen[key]]} too)")
        seen[key] = i
    return dict(cmd=cmd[order], att=att[order], point=[t["point"][i] for i in order], cycle=cycle[order],
                direction=None if direction is None else [direction[i] for i in order],
                line=[t["line"][i] for i in order], source=path, orientation=orient)


def placement(model_path: str) -> tuple[FloatArray, FloatArray]:
    """The instrument placement of an identified model JSON: (R, t) with p_instrument = R p_base + t."""
    robot = _core.Robot.load(model_path)
    if not robot.identified:
        raise ValueError(f"{model_path}: --frame instrument needs an identified model (kincal identify)")
    _, xyz, abc = robot.placements[0]  # the campaign's (first) placement
    return _core.abc_to_rotation(np.asarray(abc, dtype=float)), np.asarray(xyz, dtype=float)


def to_base(runs: dict[str, Any], model_path: str) -> dict[str, Any]:
    """The attained poses (measured in the instrument frame) mapped into the robot base frame with the
    identified model's instrument placement; the commanded poses are in the base frame already."""
    R, t = placement(model_path)
    att = runs["att"].copy()
    att[:, :3] = (att[:, :3] - t) @ R  # R^T (p - t), row by row
    if runs["orientation"]:
        for i in range(len(att)):
            att[i, 3:] = _core.rotation_to_abc(R.T @ _core.abc_to_rotation(att[i, 3:]))
    return dict(runs, att=att, frame=f"instrument, mapped to the robot base by {model_path}")


# --- ISO 9283 -----------------------------------------------------------------------------------

def wrap(deg: FloatArray) -> FloatArray:
    """Angles (deg) wrapped to (-180, 180]."""
    return 180.0 - np.mod(180.0 - np.asarray(deg, dtype=float), 360.0)


def _groups(keys: Sequence[K]) -> list[tuple[K, IntArray]]:
    """Consecutive runs of equal keys (the rows are sorted): a list of (key, index array)."""
    return [(k, np.fromiter(g, dtype=np.int64)) for k, g in itertools.groupby(range(len(keys)), key=lambda i: keys[i])]


def pose_statistics(cmd: FloatArray, att: FloatArray) -> dict[str, Any]:
    """ISO 9283 7.2 for one commanded pose ``cmd`` (3 or 6) and its attained poses ``att`` (n x 3 or
    n x 6, n >= 2): AP and RP, and the barycentre."""
    bary = att[:, :3].mean(axis=0)
    ap = bary - cmd[:3]
    l = np.linalg.norm(att[:, :3] - bary, axis=1)
    s_l = float(np.std(l, ddof=1))
    out = {"n": len(att), "AP_P_mm": float(np.linalg.norm(ap)), "AP_x_mm": float(ap[0]), "AP_y_mm": float(ap[1]),
           "AP_z_mm": float(ap[2]), "RP_l_mm": float(l.mean() + 3.0 * s_l), "l_mean_mm": float(l.mean()),
           "S_l_mm": s_l, "barycentre_mm": [float(v) for v in bary]}
    if len(cmd) == 6:
        d = wrap(att[:, 3:] - cmd[3:])  # a_j - a_c
        mean = d.mean(axis=0)           # mean a - a_c
        s = np.std(d, axis=0, ddof=1)   # spread about the mean angle
        for k, name in enumerate(ANGLES):
            out[f"AP_{name}_deg"] = float(mean[k])
            out[f"RP_{name}_deg"] = float(3.0 * s[k])
        out["mean_abc_deg"] = [float(v) for v in wrap(cmd[3:] + mean)]
    return out


def iso9283(runs: dict[str, Any], distance: Optional[Sequence[str]] = None) -> dict[str, Any]:
    """The ISO 9283 report of ``runs`` (read_runs): per point AP, RP (and vAP with directions); with
    ``distance`` (two point names) AD and RD over the cycles both points share."""
    src, cmd, att = runs["source"], runs["cmd"], runs["att"]
    dirs = runs["direction"]
    points: list[dict[str, Any]] = []
    by_point = _groups(runs["point"])
    for name, idx in by_point:
        c0 = cmd[idx[0]]
        for i in idx[1:]:
            dev = np.abs(np.r_[cmd[i, :3] - c0[:3], wrap(cmd[i, 3:] - c0[3:])])
            if dev.max() > 1e-3:
                raise ValueError(f"{src}:{runs['line'][i]}: point {name}: the commanded pose differs from line "
                                 f"{runs['line'][idx[0]]}'s (by {dev.max():.4g} mm or deg); one point, one commanded pose")
        if len(idx) < 2:
            raise ValueError(f"{src}:{runs['line'][idx[0]]}: point {name} has one cycle only: repeatability needs at "
                             "least 2 cycles (ISO 9283 asks for 30)")
        p = {"point": name, **pose_statistics(c0, att[idx]), "commanded": [float(v) for v in c0]}
        if dirs is not None:
            per = _groups([dirs[i] for i in idx])
            p["directions"] = []
            for label, j in per:
                if len(j) < 2:
                    raise ValueError(f"{src}:{runs['line'][idx[j[0]]]}: point {name} direction {label} has one cycle "
                                     "only: repeatability needs at least 2 cycles")
                s = pose_statistics(c0, att[idx[j]])
                p["directions"].append({"direction": label, **s})
            if len(per) >= 2:
                bary = np.array([d["barycentre_mm"] for d in p["directions"]])
                p["vAP_P_mm"] = max(float(np.linalg.norm(u - v)) for u, v in itertools.combinations(bary, 2))
                if runs["orientation"]:
                    ang = np.array([[d[f"AP_{n}_deg"] for n in ANGLES] for d in p["directions"]])
                    for k, n in enumerate(ANGLES):
                        p[f"vAP_{n}_deg"] = float(ang[:, k].max() - ang[:, k].min())
        points.append(p)
    out = {"standard": "ISO 9283:1998", "frame": runs.get("frame", "base (as given)"), "orientation": runs["orientation"],
           "points": points}
    if distance is not None:
        out.update(distance_statistics(runs, distance))
    return out


def parse_distance(text: str) -> list[str]:
    """--distance P2,P4: two distinct point names."""
    names = [x.strip() for x in text.split(",")]
    if len(names) != 2 or not all(names) or names[0] == names[1]:
        raise ValueError(f"--distance {text}: expected two different point names, such as P2,P4")
    return names


def distance_statistics(runs: dict[str, Any], names: Sequence[str]) -> dict[str, Any]:
    """ISO 9283 7.4: AD and RD between two points, cycle by cycle (and direction by direction)."""
    src = runs["source"]
    known = sorted(set(runs["point"]), key=natural_key)
    for n in names:
        if n not in known:
            raise ValueError(f"--distance {','.join(names)}: no point '{n}' in {src} (points: {', '.join(known)})")
    dirs = runs["direction"] or [""] * len(runs["point"])
    rows = [{(dirs[i], int(runs["cycle"][i])): i for i in range(len(dirs)) if runs["point"][i] == n} for n in names]
    for a, b in ((0, 1), (1, 0)):
        for key, i in rows[a].items():
            if key not in rows[b]:
                what = (f"direction {key[0]} " if key[0] else "") + f"cycle {key[1]}"
                raise ValueError(f"--distance {','.join(names)}: {src}:{runs['line'][i]}: {what} of {names[a]} has no "
                                 f"{names[b]} (the distance is taken cycle by cycle)")
    keys = sorted(rows[0])
    if len(keys) < 2:
        raise ValueError(f"--distance {','.join(names)}: one cycle only: distance repeatability needs at least 2")
    i1 = np.array([rows[0][k] for k in keys])
    i2 = np.array([rows[1][k] for k in keys])
    dc = float(np.linalg.norm(runs["cmd"][i1[0], :3] - runs["cmd"][i2[0], :3]))
    d = np.linalg.norm(runs["att"][i1, :3] - runs["att"][i2, :3], axis=1)
    s = float(np.std(d, ddof=1))
    return {"AD_mm": float(d.mean() - dc), "RD_mm": 3.0 * s,
            "distance": {"points": list(names), "n": len(d), "commanded_mm": dc, "mean_mm": float(d.mean()),
                         "S_D_mm": s}}


# --- ISO 230-2 and VDI/DGQ 3441 -----------------------------------------------------------------

def read_axis(path: str) -> dict[str, Any]:
    """AXIS.csv of `kincal accuracy axis`: target, direction (+1/-1), run, measured; sorted by target,
    direction, run (duplicates are an error)."""
    t = read_table(path, ["target", "direction", "run", "measured"])
    target, measured = numbers(t, "target"), numbers(t, "measured")
    direction = numbers(t, "direction")
    bad = np.flatnonzero((direction != 1.0) & (direction != -1.0))
    if len(bad):
        raise ValueError(f"{path}:{t['line'][bad[0]]}: column 'direction': '{t['direction'][bad[0]]}' is not +1 or -1")
    run = integers(t, "run")
    order = np.lexsort((run, -direction, target))
    for a, b in zip(order[:-1], order[1:]):
        if target[a] == target[b] and direction[a] == direction[b] and run[a] == run[b]:
            raise ValueError(f"{path}:{t['line'][b]}: target {t['target'][b]} direction {int(direction[b]):+d} run "
                             f"{run[b]} is measured twice (line {t['line'][a]} too)")
    return dict(target=target[order], direction=direction[order].astype(int), run=run[order],
                measured=measured[order], line=[t["line"][i] for i in order], source=path)


def axis_statistics(data: dict[str, Any], unit: str = "mm") -> dict[str, Any]:
    """ISO 230-2 and VDI/DGQ 3441 figures of one axis (see the module's docstring); every value in
    ``unit`` (mm or deg), as the file."""
    src = data["source"]
    dev = data["measured"] - data["target"]
    per: list[dict[str, Any]] = []
    for tgt, idx in _groups(list(data["target"])):
        side: dict[int, tuple[float, float, int]] = {}
        for d in (1, -1):
            j = idx[data["direction"][idx] == d]
            what = f"{src}: target {tgt:g}"
            if len(j) == 0:
                raise ValueError(f"{what} has no run in direction {d:+d} (both directions are needed, line "
                                 f"{data['line'][idx[0]]})")
            if len(j) < 2:
                raise ValueError(f"{src}:{data['line'][j[0]]}: target {tgt:g} direction {d:+d} has one run only: "
                                 "repeatability needs at least 2 runs (ISO 230-2 asks for 5)")
            side[d] = (float(dev[j].mean()), float(np.std(dev[j], ddof=1)), len(j))
        per.append({"target": float(tgt), "n_up": side[1][2], "n_down": side[-1][2], "mean_up": side[1][0],
                    "mean_down": side[-1][0], "s_up": side[1][1], "s_down": side[-1][1]})
    mu, md = np.array([p["mean_up"] for p in per]), np.array([p["mean_down"] for p in per])
    su, sd = np.array([p["s_up"] for p in per]), np.array([p["s_down"] for p in per])
    b_i = mu - md
    r_up, r_down = 4.0 * su, 4.0 * sd
    r_i = np.maximum(2.0 * su + 2.0 * sd + np.abs(b_i), np.maximum(r_up, r_down))
    mean_i = (mu + md) / 2.0
    for k, p in enumerate(per):
        p.update(B_i=float(b_i[k]), R_i=float(r_i[k]), R_up=float(r_up[k]), R_down=float(r_down[k]),
                 mean_i=float(mean_i[k]))
    iso = {"B": float(np.abs(b_i).max()), "B_mean": float(b_i.mean()), "R": float(r_i.max()),
           "R_up": float(r_up.max()), "R_down": float(r_down.max()),
           "E": float(max(mu.max(), md.max()) - min(mu.min(), md.min())),
           "E_up": float(mu.max() - mu.min()), "E_down": float(md.max() - md.min()),
           "M": float(mean_i.max() - mean_i.min()),
           "A": float(max((mu + 2 * su).max(), (md + 2 * sd).max()) - min((mu - 2 * su).min(), (md - 2 * sd).min())),
           "A_up": float((mu + 2 * su).max() - (mu - 2 * su).min()),
           "A_down": float((md + 2 * sd).max() - (md - 2 * sd).min()), "targets": per}
    u_j = np.abs(mu - md)
    ps_j = 6.0 * (su + sd) / 2.0
    half = (u_j + ps_j) / 2.0
    travel = float(data["target"].max() - data["target"].min())
    p_unc = float((mean_i + half).max() - (mean_i - half).min())
    vdi: dict[str, Any] = {"P": p_unc, "Pa": float(mean_i.max() - mean_i.min()),
           "Ps": float(ps_j.max()), "U": float(u_j.max()), "Ps_mean": float(ps_j.mean()), "U_mean": float(u_j.mean()),
           "travel": travel,
           "targets": [{"target": p["target"], "mean": float(mean_i[k]), "U_j": float(u_j[k]), "Ps_j": float(ps_j[k]),
                        "s_j": float((su[k] + sd[k]) / 2.0)} for k, p in enumerate(per)]}
    if unit == "mm" and travel > 0:
        vdi["P_per_m"] = p_unc / (travel / 1000.0)
        vdi["Ps_per_m"] = float(ps_j.max()) / (travel / 1000.0)
    return {"unit": unit, "targets": len(per), "iso230_2": iso, "vdi3441": vdi}
