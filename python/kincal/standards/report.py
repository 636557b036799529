"""The folders of `kincal accuracy iso9283` and `kincal accuracy axis`: the JSON, the figures
(matplotlib) and a one-page report.html (report.py). Everything is computed before the folder is
touched: bad input leaves nothing behind."""

from __future__ import annotations

import io
import math
from pathlib import Path
from types import ModuleType
from typing import TYPE_CHECKING, Any, Optional, Union

import numpy as np

from .. import report
from ..io import strict_json
from . import accuracy as acc

if TYPE_CHECKING:
    from matplotlib.figure import Figure

COLOURS = ["tab:blue", "tab:orange", "tab:green", "tab:red", "tab:purple", "tab:brown"]


def _plt() -> ModuleType:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    return plt


def _png(fig: Figure) -> bytes:
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=100, metadata={"Software": None})
    _plt().close(fig)
    return buf.getvalue()


def write_folder(out: Union[str, Path], files: dict[str, Union[str, bytes]]) -> None:
    """``files`` (name -> text or bytes) written into the folder ``out`` (created), whole or not at
    all (report.staged_folder)."""
    with report.staged_folder(out) as stage:
        for name, content in files.items():
            (stage / name).write_bytes(content.encode() if isinstance(content, str) else content)


def _f(v: Optional[float], digits: int = 4) -> str:
    """``v`` to ``digits`` decimals; a value that rounds to zero without its sign ("-0.000" is "0.000")."""
    if v is None:
        return ""
    text = f"{v:.{digits}f}"
    return text[1:] if text.startswith("-") and float(text) == 0.0 else text


# Precision rule, for every table, figure and line of text of these reports: a measured value is
# printed to the largest power of ten not above a tenth of the run's repeatability figure (ISO 9283:
# the smallest RP_l for positions and distances, the smallest RP_a,b,c for angles; ISO 230-2 and
# VDI/DGQ 3441: the mean Ps_j = 6 s, per metre of travel for the per-metre figures). The
# repeatability figure is then shown to two significant digits (as the GUM states an uncertainty)
# and every other value to the same last digit: well below the scatter the run itself measured, no
# digit that is noise alone. Between 0 and 6 decimals; 4 when the run shows no scatter at all. A
# figure in um rounds to the same step (0.11 mm is 110 um there, not 107).
def decimals(spread: float) -> int:
    """Decimals of the precision rule above for a repeatability figure ``spread`` (in the unit printed)."""
    if not (math.isfinite(spread) and spread > 0):
        return 4
    return int(min(6, max(0, math.ceil(-math.log10(spread / 10.0) - 1e-9))))


def rounded(value: float, digits: int, factor: float = 1.0) -> str:
    """``value`` times ``factor`` (a change of unit) to the step 10^-digits of the original unit."""
    step = 10.0 ** -digits * factor
    shown = max(0, -math.floor(math.log10(step) + 1e-9))
    return _f(round(value * factor / step) * step, shown)


def _length_unit(extent_mm: float) -> tuple[str, float]:
    """(unit, factor from mm) for lengths of about ``extent_mm``: um below 1 mm."""
    return ("um", 1000.0) if extent_mm < 1.0 else ("mm", 1.0)


# --- ISO 9283 -----------------------------------------------------------------------------------

PLANES = ((1, "y"), (2, "z"))
#: the panel's half-width over the largest distance of an attained point or of the RP_l circle from
#: the barycentre: a margin where the arrow toward an off-scale commanded position fits
PANEL_MARGIN = 1.35
#: the commanded position is brought into the panels when it lies within this many times that distance
COMMANDED_REACH = 2.5


def iso9283_decimals(res: dict[str, Any]) -> tuple[int, int]:
    """(position decimals in mm, angle decimals in deg) of the precision rule for an ISO 9283 report."""
    pts = res["points"]
    pos = decimals(min(p["RP_l_mm"] for p in pts))
    ang = decimals(min(p[f"RP_{n}_deg"] for p in pts for n in acc.ANGLES)) if res["orientation"] else pos
    return pos, ang


def deviation_layout(runs: dict[str, Any], res: dict[str, Any]) -> dict[str, Any]:
    """What the attained-positions figure draws, in mm from each point's barycentre: per point and
    plane (x-y, x-z) a panel with its attained points (``xy``, and ``idx`` their rows), the RP_l
    circle's radius, the commanded position (``commanded``) and whether it is inside the panel
    (``commanded_inside``; otherwise ``arrow``: the tail and head of an arrow on the panel's edge
    pointing toward it). Every panel has the half-width ``lim_mm``: PANEL_MARGIN times the largest
    distance of an attained point or of an RP_l circle from its barycentre, enlarged to take the
    commanded positions in when they lie within COMMANDED_REACH times that distance (a compensated
    robot: AP and RP comparable). ``unit``/``scale``: the axes' unit (um below 1 mm) and factor from mm."""
    panels: list[dict[str, Any]] = []
    reach = 0.0
    for p in res["points"]:
        idx = np.array([i for i, n in enumerate(runs["point"]) if n == p["point"]])
        bary = np.asarray(p["barycentre_mm"], dtype=float)
        rel = runs["att"][idx, :3] - bary
        cmd = np.asarray(p["commanded"][:3], dtype=float) - bary
        for j, plane in PLANES:
            xy = rel[:, [0, j]]
            reach = max(reach, p["RP_l_mm"], float(np.hypot(xy[:, 0], xy[:, 1]).max()))
            panels.append({"point": p["point"], "plane": plane, "idx": idx, "xy": xy, "RP_l_mm": p["RP_l_mm"],
                           "AP_P_mm": p["AP_P_mm"], "commanded": cmd[[0, j]]})
    reach = max(reach, 1e-9)
    far = max(float(np.abs(q["commanded"]).max()) for q in panels)
    lim = PANEL_MARGIN * (max(reach, far) if far <= COMMANDED_REACH * reach else reach)
    for q in panels:
        c = q["commanded"]
        q["commanded_inside"] = bool(np.abs(c).max() <= 0.95 * lim)  # the + whole inside the panel
        if not q["commanded_inside"]:
            u = c / np.linalg.norm(c)
            edge = lim / float(np.abs(u).max())  # the ray from the barycentre meets the panel's edge here
            q["arrow"] = (0.8 * edge * u, 0.985 * edge * u)
    unit, scale = _length_unit(lim)
    return {"lim_mm": lim, "reach_mm": reach, "unit": unit, "scale": scale, "panels": panels}


def _deviation_figure(runs: dict[str, Any], res: dict[str, Any], layout: dict[str, Any]) -> bytes:
    """Attained positions around each point's barycentre (deviation_layout): per point, the x-y and
    x-z planes, the RP_l circle, and the commanded position or an arrow toward it."""
    plt = _plt()
    from matplotlib.lines import Line2D

    pts = res["points"]
    ncol = min(len(pts), 5)
    nblock = math.ceil(len(pts) / ncol)
    dirs = runs["direction"]
    labels = sorted(set(dirs)) if dirs is not None else [None]
    unit, k_u = layout["unit"], layout["scale"]
    lim = layout["lim_mm"] * k_u
    dpos = iso9283_decimals(res)[0]
    fig, axes = plt.subplots(2 * nblock, ncol, figsize=(2.1 * ncol + 0.9, 4.9 * nblock + 0.6), squeeze=False,
                             sharex=True, sharey=True, constrained_layout=True)
    circle = np.linspace(0, 2 * np.pi, 121)
    for n, q in enumerate(layout["panels"]):
        k, row = divmod(n, 2)
        ax = axes[2 * (k // ncol) + row, k % ncol]
        for c, lab in enumerate(labels):
            sel = np.ones(len(q["idx"]), bool) if lab is None else np.array([dirs[i] == lab for i in q["idx"]])
            ax.scatter(q["xy"][sel, 0] * k_u, q["xy"][sel, 1] * k_u, s=9, color=COLOURS[c % len(COLOURS)], alpha=0.75,
                       lw=0, zorder=2)
        r = q["RP_l_mm"] * k_u
        ax.plot(r * np.cos(circle), r * np.sin(circle), "k--", lw=0.8, zorder=3)
        ax.plot([0], [0], "rx", ms=7, mew=1.5, zorder=4)
        if q["commanded_inside"]:
            ax.plot([q["commanded"][0] * k_u], [q["commanded"][1] * k_u], "k+", ms=12, mew=1.5, zorder=5)
        else:
            tail, head = q["arrow"]
            ax.annotate("", xy=tuple(head * k_u), xytext=tuple(tail * k_u), zorder=5,
                        arrowprops={"arrowstyle": "-|>", "color": "k", "lw": 1.3, "mutation_scale": 11,
                                    "shrinkA": 0, "shrinkB": 0})
        ax.set_xlim(-lim, lim)
        ax.set_ylim(-lim, lim)
        ax.set_aspect("equal")
        ax.tick_params(labelsize=7)
        ax.set_title(f"{q['point']}: x-{q['plane']}, AP_P {q['AP_P_mm']:.{dpos}f} mm", fontsize=8)
        if k % ncol == 0:
            ax.set_ylabel(f"d{q['plane']} ({unit})", fontsize=8)
        if row == 1:  # every x-z panel shows its dx scale (the last block may be short)
            ax.set_xlabel(f"dx ({unit})", fontsize=8)
            ax.tick_params(labelbottom=True)
    for k in range(len(pts), nblock * ncol):
        for row in range(2):
            axes[2 * (k // ncol) + row, k % ncol].set_visible(False)
    # the legend names exactly what the panels draw
    handles = [Line2D([], [], ls="none", marker="o", ms=4, color=COLOURS[c % len(COLOURS)],
                      label="attained" if lab is None else f"attained, direction {lab}")
               for c, lab in enumerate(labels)]
    handles += [Line2D([], [], ls="--", lw=0.8, color="k", label="RP_l around the barycentre"),
                Line2D([], [], ls="none", marker="x", ms=7, mew=1.5, color="r", label="barycentre (the origin)")]
    if any(q["commanded_inside"] for q in layout["panels"]):
        handles.append(Line2D([], [], ls="none", marker="+", ms=12, mew=1.5, color="k", label="commanded"))
    if not all(q["commanded_inside"] for q in layout["panels"]):
        handles.append(Line2D([], [], ls="none", marker=r"$\rightarrow$", ms=13, color="k",
                              label="toward the commanded position (off the panel, AP_P away)"))
    fig.legend(handles=handles, loc="outside lower center", ncol=min(len(handles), {1: 1, 2: 2}.get(ncol, 3)),
               fontsize=8, frameon=False)
    return _png(fig)


def _summary_figure(res: dict[str, Any]) -> bytes:
    """AP_P and RP_l per point, each on its own axes and in its own unit (um below 1 mm), each bar
    labelled with its value (precision rule)."""
    plt = _plt()
    pts = res["points"]
    x = np.arange(len(pts))
    dpos = iso9283_decimals(res)[0]
    fig, axes = plt.subplots(1, 2, figsize=(max(7.0, 2.0 + 1.3 * len(pts)), 3.2), constrained_layout=True)
    for ax, key, name, col in ((axes[0], "AP_P_mm", "pose accuracy AP_P", "tab:blue"),
                               (axes[1], "RP_l_mm", "pose repeatability RP_l", "tab:orange")):
        v = np.array([p[key] for p in pts])
        unit, k_u = _length_unit(float(v.max()))
        bars = ax.bar(x, v * k_u, 0.6, color=col)
        ax.bar_label(bars, [rounded(w, dpos, k_u) for w in v], fontsize=7, padding=2)
        ax.set_xticks(x, [p["point"] for p in pts])
        ax.set_ylabel(unit)
        ax.set_ylim(0, 1.2 * max(float(v.max()) * k_u, 1e-9))
        ax.set_title(f"{name} ({unit})", fontsize=10)
    return _png(fig)


def iso9283_html(runs: dict[str, Any], res: dict[str, Any], title: str, layout: Optional[dict[str, Any]] = None,
                 data_name: str = "") -> str:
    esc = report.esc
    pts = res["points"]
    dp, da = iso9283_decimals(res)
    has_v = any("vAP_P_mm" in p for p in pts)
    head = ["point", "n", "AP_P", "AP_x", "AP_y", "AP_z", "RP_l"] + (["vAP_P"] if has_v else [])
    rows = [[p["point"], p["n"], _f(p["AP_P_mm"], dp), _f(p["AP_x_mm"], dp), _f(p["AP_y_mm"], dp),
             _f(p["AP_z_mm"], dp), _f(p["RP_l_mm"], dp)] + ([_f(p.get("vAP_P_mm"), dp)] if has_v else []) for p in pts]
    src = f" read from <code>{esc(data_name)}</code>" if data_name else ""
    body = [f"<h1>{esc(title)}</h1>",
            f"<p>{len(runs['point'])} measured poses of {len(pts)} point{'s' if len(pts) > 1 else ''}{src}, frame: "
            f"{esc(res['frame'])}. Formulas of ISO 9283:1998 (7.2 pose accuracy and repeatability, 7.3 "
            "multi-directional variation, 7.4 distance accuracy and repeatability); standard deviations with n - 1. Values are given to "
            "the largest power of ten below a tenth of the smallest repeatability (RP_l, RP_a,b,c).</p>",
            "<h2>Position (mm)</h2>", report.table(head, rows, numeric=True)]
    if res["orientation"]:
        head = ["point", "AP_a", "AP_b", "AP_c", "RP_a (+-)", "RP_b (+-)", "RP_c (+-)"]
        rows = [[p["point"]] + [_f(p[f"AP_{n}_deg"], da) for n in acc.ANGLES] +
                [_f(p[f"RP_{n}_deg"], da) for n in acc.ANGLES] for p in pts]
        body += ["<h2>Orientation (deg, KUKA ABC)</h2>", report.table(head, rows, numeric=True)]
    if "AD_mm" in res:
        d = res["distance"]
        body += ["<h2>Distance (mm)</h2>",
                 report.table(["between", "cycles", "commanded", "mean attained", "AD", "RD (+-)"],
                              [[" - ".join(d["points"]), d["n"], _f(d["commanded_mm"], dp), _f(d["mean_mm"], dp),
                                _f(res["AD_mm"], dp), _f(res["RD_mm"], dp)]], numeric=True)]
    unit = layout["unit"] if layout else "mm"
    where = ("it lies inside every panel (+)" if layout and all(q["commanded_inside"] for q in layout["panels"]) else
             "where it lies off the panel, an arrow on the panel's edge points toward it (the panel's title gives "
             "AP_P)" if layout and not any(q["commanded_inside"] for q in layout["panels"]) else
             "it is drawn (+) where it lies inside the panel; elsewhere an arrow on the panel's edge points toward "
             "it (the panel's title gives AP_P)")
    body += ["<h2>Attained positions around each barycentre</h2>",
             f"<p>Each panel is centred on the barycentre (x) of the point's attained positions, in {unit}: the dots "
             "are the attained positions (coloured by approach direction when the runs have them), the dashed circle "
             f"of radius RP_l is centred on the barycentre. The commanded position is AP_P away: {where}. Every panel "
             "has the same scale.</p>",
             report.figure("deviations.png", "attained positions around each barycentre"),
             report.figure("summary.png", "AP_P and RP_l per point"),
             "<h2>Definitions</h2><ul>"
             "<li>AP_P = |barycentre - commanded position|; AP_x = mean x - x_c (and y, z); AP_a = mean a - a_c "
             "(and b, c; angle differences wrapped to +-180 deg).</li>"
             "<li>RP_l = mean(l) + 3 S_l, l_j = |attained position j - barycentre|; RP_a = +-3 S_a.</li>"
             "<li>vAP_P: the largest distance between the barycentres of two approach directions.</li>"
             "<li>AD = mean attained distance - commanded distance (cycle by cycle); RD = +-3 S_D.</li></ul>"]
    return report.page(title, "\n".join(body))


def _default_label(data: str, out: str) -> str:
    """The run's name when the caller gives none: the output folder's name and the data file's."""
    return f"{Path(out).resolve().name} ({Path(data).name})"


def run_iso9283(data: str, out: str, distance: Optional[str] = None, model: Optional[str] = None,
                frame: str = "base", frame_label: Optional[str] = None, label: Optional[str] = None) -> dict[str, Any]:
    """`kincal accuracy iso9283`: DIR/iso9283.json, DIR/report.html and the figures; returns the report.
    ``frame_label``: the frame the data are in, as the report says it (default "base (as given)");
    ``label``: which run this is, in the report's title (default: the output folder's name and the
    data file's)."""
    names = acc.parse_distance(distance) if distance is not None else None
    if frame == "instrument" and model is None:
        raise ValueError("--frame instrument needs --model M (an identified model: its instrument placement)")
    if model is not None and frame != "instrument":
        raise ValueError(f"--model {model}: only read with --frame instrument (the attained points in the "
                         "instrument's frame)")
    runs = acc.read_runs(data)
    if model is not None:
        runs = acc.to_base(runs, model)
        from .._core import Robot
        from ..calibration.tool_frame import warn_nominal_tcp
        warn_nominal_tcp(Robot.load(model), model, "kincal accuracy")  # a TCP not measured: one line
    elif frame_label is not None:
        runs["frame"] = frame_label
    res = acc.iso9283(runs, names)
    layout = deviation_layout(runs, res)
    title = f"ISO 9283 pose accuracy and repeatability: {label or _default_label(data, out)}"
    files: dict[str, Union[str, bytes]] = {
        "deviations.png": _deviation_figure(runs, res, layout), "summary.png": _summary_figure(res),
        "iso9283.json": strict_json.dumps(res, indent=1) + "\n",
        "report.html": iso9283_html(runs, res, title, layout, Path(data).name)}
    write_folder(out, files)
    return res


def iso9283_summary(res: dict[str, Any], out: str) -> str:
    dp = iso9283_decimals(res)[0]
    w = dp + 7
    has_v = any("vAP_P_mm" in p for p in res["points"])
    lines = [f"{'point':<8}{'n':>5}{'AP_P mm':>{w}}{'RP_l mm':>{w}}" + (f"{'vAP_P mm':>{w}}" if has_v else "")]
    for p in res["points"]:
        v = f"{p['vAP_P_mm']:>{w}.{dp}f}" if "vAP_P_mm" in p else ""
        lines.append(f"{p['point']:<8}{p['n']:>5}{p['AP_P_mm']:>{w}.{dp}f}{p['RP_l_mm']:>{w}.{dp}f}{v}")
    if "AD_mm" in res:
        lines.append(f"distance {'-'.join(res['distance']['points'])}: AD {_f(res['AD_mm'], dp)} mm, "
                     f"RD +-{res['RD_mm']:.{dp}f} mm")
    lines.append(f"report: {Path(out) / 'report.html'}")
    return "\n".join(lines)


# --- ISO 230-2 / VDI/DGQ 3441 -------------------------------------------------------------------

def axis_decimals(res: dict[str, Any]) -> tuple[int, int]:
    """(decimals in the axis's unit, decimals of the per-metre figures in um/m) of the precision rule
    (the mean Ps_j of VDI/DGQ 3441, 6 s, as the repeatability figure; per metre of travel for the
    per-metre figures)."""
    vdi = res["vdi3441"]
    per_m = decimals(vdi["Ps_mean"] * 1000.0 / (vdi["travel"] / 1000.0)) if "P_per_m" in vdi else 0
    return decimals(vdi["Ps_mean"]), per_m


def axis_figures_text(res: dict[str, Any]) -> dict[str, str]:
    """The one-line statements of the figures, each value with its unit and to the precision rule's
    digits: ``iso`` (ISO 230-2: A, E, M, R, B), ``vdi`` (VDI/DGQ 3441: P, its value per metre, Pa, Ps,
    U) and ``per_m`` (P and Ps per metre of travel; empty without). The figure's titles, the page and
    the command's summary all use these."""
    u, iso, vdi = res["unit"], res["iso230_2"], res["vdi3441"]
    d, dm = axis_decimals(res)
    per_m = (f"P {vdi['P_per_m'] * 1000:.{dm}f} um/m, Ps {vdi['Ps_per_m'] * 1000:.{dm}f} um/m"
             if "P_per_m" in vdi else "")
    vdi_text = f"P {vdi['P']:.{d}f} {u}" + (f" ({vdi['P_per_m'] * 1000:.{dm}f} um/m)" if per_m else "")
    vdi_text += "".join(f", {k} {vdi[k]:.{d}f} {u}" for k in ("Pa", "Ps", "U"))
    return {"iso": ", ".join(f"{k} {iso[k]:.{d}f} {u}" for k in ("A", "E", "M", "R", "B")), "vdi": vdi_text,
            "per_m": per_m}


def _axis_figure(data: dict[str, Any], res: dict[str, Any]) -> bytes:
    """Per-axis deviation bands: above, ISO 230-2 (each run's deviation, the mean per direction and
    the band mean +- 2 s); below, VDI/DGQ 3441 (the mean position deviation and the band of
    (U_j + Ps_j) / 2 around it, whose extent is P)."""
    plt = _plt()
    unit = res["unit"]
    iso, vdi = res["iso230_2"], res["vdi3441"]
    text = axis_figures_text(res)
    tg = np.array([p["target"] for p in iso["targets"]])
    dev = data["measured"] - data["target"]
    fig, (a1, a2) = plt.subplots(2, 1, figsize=(10, 6.4), sharex=True, constrained_layout=True)
    for d, name, col, (mk, sk) in ((1, "up (+1)", "tab:blue", ("mean_up", "s_up")),
                                   (-1, "down (-1)", "tab:orange", ("mean_down", "s_down"))):
        sel = data["direction"] == d
        a1.scatter(data["target"][sel], dev[sel], s=6, color=col, alpha=0.5, lw=0)
        m = np.array([p[mk] for p in iso["targets"]])
        s = np.array([p[sk] for p in iso["targets"]])
        a1.plot(tg, m, "-o", color=col, ms=3, lw=1.2, label=f"mean {name}")
        a1.fill_between(tg, m - 2 * s, m + 2 * s, color=col, alpha=0.2, lw=0, label=f"mean +- 2 s, {name}")
        if len(tg) == 1:  # one target: the band as a bar
            a1.vlines(tg, m - 2 * s, m + 2 * s, color=col, alpha=0.3, lw=8)
    a1.set_ylabel(f"deviation ({unit})")
    a1.set_title(f"ISO 230-2: {text['iso']}", fontsize=10)
    a1.legend(fontsize=8, loc="upper left", bbox_to_anchor=(1.01, 1.0), frameon=False)
    mean = np.array([p["mean"] for p in vdi["targets"]])
    half = np.array([(p["U_j"] + p["Ps_j"]) / 2 for p in vdi["targets"]])
    a2.fill_between(tg, mean - half, mean + half, color="tab:green", alpha=0.25, lw=0, label="mean +- (U_j + Ps_j) / 2")
    if len(tg) == 1:
        a2.vlines(tg, mean - half, mean + half, color="tab:green", alpha=0.3, lw=8)
    a2.plot(tg, mean, "-o", color="tab:green", ms=3, lw=1.2, label="mean position deviation")
    top, bottom = float((mean + half).max()), float((mean - half).min())
    a2.axhline(top, color="k", ls=":", lw=0.8)
    a2.axhline(bottom, color="k", ls=":", lw=0.8, label="extent P")
    a2.set_xlabel(f"target ({unit})")
    a2.set_ylabel(f"deviation ({unit})")
    a2.set_title(f"VDI/DGQ 3441: {text['vdi']}", fontsize=10)
    a2.legend(fontsize=8, loc="upper left", bbox_to_anchor=(1.01, 1.0), frameon=False)
    pad = 0.1 * max(top - bottom, 1e-9)
    a2.set_ylim(bottom - pad, top + pad)
    return _png(fig)


def axis_html(data: dict[str, Any], res: dict[str, Any], title: str, data_name: str = "") -> str:
    u = res["unit"]
    iso, vdi = res["iso230_2"], res["vdi3441"]
    d = axis_decimals(res)[0]
    fig = report.figure("axis.png", "per-axis deviation bands")
    iso_rows = [[_f(p["target"], 3), f"{p['n_up']}/{p['n_down']}", _f(p["mean_up"], d), _f(p["mean_down"], d),
                 _f(p["s_up"], d), _f(p["s_down"], d), _f(p["B_i"], d), _f(p["R_i"], d)] for p in iso["targets"]]
    vdi_rows = [[_f(p["target"], 3), _f(p["mean"], d), _f(p["U_j"], d), _f(p["Ps_j"], d)] for p in vdi["targets"]]
    per_m = axis_figures_text(res)["per_m"]
    if per_m:
        per_m = f"<p>Per metre of travel ({vdi['travel'] / 1000:.4g} m): {per_m}.</p>"
    src = f" read from <code>{report.esc(data_name)}</code>" if data_name else ""
    body = f"""<h1>{report.esc(title)}</h1>
<p>{len(data['target'])} measured positions at {res['targets']} targets{src}, both directions; every value in {u}.
Deviation = measured - target. Standard deviations with n - 1. Values are given to the largest power of ten
below a tenth of the mean Ps_j (6 s), per metre of travel for the per-metre figures.</p>
<h2>ISO 230-2:2014</h2>
{report.table(["A", "E", "M", "R", "B", "mean reversal B"],
              [[_f(iso[k], d) for k in ("A", "E", "M", "R", "B", "B_mean")]], numeric=True)}
{report.table(["target", "runs up/down", "mean_up", "mean_down", "s_up", "s_down", "B_i", "R_i"], iso_rows, numeric=True)}
<h2>VDI/DGQ 3441:1977</h2>
{report.table(["P", "Pa", "Ps", "U", "Ps mean", "U mean"],
              [[_f(vdi[k], d) for k in ("P", "Pa", "Ps", "U", "Ps_mean", "U_mean")]], numeric=True)}
{per_m}
{report.table(["target", "mean", "U_j", "Ps_j"], vdi_rows, numeric=True)}
<h2>Deviation bands</h2>{fig}
<h2>Definitions</h2><ul>
<li>ISO 230-2: B_i = mean_up - mean_down, B = max |B_i|; R_i = max(2 s_up + 2 s_down + |B_i|, 4 s_up, 4 s_down),
R = max R_i; E = max - min of every mean_up and mean_down; M = max - min of (mean_up + mean_down) / 2;
A = max(mean + 2 s) - min(mean - 2 s) over both directions.</li>
<li>VDI/DGQ 3441: U_j = |mean_up - mean_down|, Ps_j = 6 (s_up + s_down) / 2, Pa = max - min of the mean
deviations, P = max(mean_j + (U_j + Ps_j) / 2) - min(mean_j - (U_j + Ps_j) / 2); U, Ps the largest over the
targets.</li></ul>"""
    return report.page(title, body)


def run_axis(data_path: str, out: str, unit: str = "mm", label: Optional[str] = None) -> dict[str, Any]:
    """`kincal accuracy axis`: DIR/axis.json, DIR/report.html and DIR/axis.png; returns the report.
    ``label``: which axis and run this is, in the report's title (default: the output folder's name
    and the data file's)."""
    if unit not in ("mm", "deg"):
        raise ValueError(f"--unit {unit}: expected mm or deg")
    data = acc.read_axis(data_path)
    res = acc.axis_statistics(data, unit)
    title = f"Positioning accuracy of one axis: {label or _default_label(data_path, out)}"
    files: dict[str, Union[str, bytes]] = {
        "axis.png": _axis_figure(data, res), "axis.json": strict_json.dumps(res, indent=1) + "\n",
        "report.html": axis_html(data, res, title, Path(data_path).name)}
    write_folder(out, files)
    return res


def axis_summary(res: dict[str, Any], out: str) -> str:
    text = axis_figures_text(res)
    return f"ISO 230-2: {text['iso']}\nVDI/DGQ 3441: {text['vdi']}\nreport: {Path(out) / 'report.html'}"
