"""The folders of `kincal accuracy iso9283` and `kincal accuracy axis`: the JSON, the figures
(matplotlib) and a one-page report.html (report.py). Everything is computed before the folder is
touched: bad input leaves nothing behind."""

from __future__ import annotations

import io
import json
import math
import os
import tempfile
from pathlib import Path
from typing import Optional, Union

import numpy as np

from . import _core, report
from . import accuracy as acc

COLOURS = ["tab:blue", "tab:orange", "tab:green", "tab:red", "tab:purple", "tab:brown"]


def _plt():
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    return plt


def _png(fig) -> bytes:
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=100, metadata={"Software": None})
    _plt().close(fig)
    return buf.getvalue()


def write_folder(out: Union[str, Path], files: dict) -> None:
    """``files`` (name -> text or bytes) written into the folder ``out`` (created), each atomically."""
    folder = Path(out)
    folder.mkdir(parents=True, exist_ok=True)
    for name, content in files.items():
        path = folder / name
        if isinstance(content, str):
            _core.write_file_atomic(str(path), content)
            continue
        fd, tmp = tempfile.mkstemp(dir=folder, prefix=f".{name}.")
        try:
            with os.fdopen(fd, "wb") as f:
                f.write(content)
            os.replace(tmp, path)
        except BaseException:
            os.unlink(tmp)
            raise


def _f(v: Optional[float], digits: int = 4) -> str:
    return "" if v is None else f"{v:.{digits}f}"


# --- ISO 9283 -----------------------------------------------------------------------------------

def _deviation_figure(runs: dict, res: dict) -> bytes:
    """Attained positions around each commanded pose: per point, the deviations from the commanded
    position in the x-y and x-z planes (mm), the barycentre and the RP_l circle around it."""
    plt = _plt()
    pts = res["points"]
    ncol = min(len(pts), 5)
    nblock = math.ceil(len(pts) / ncol)
    dirs = runs["direction"]
    labels = sorted(set(dirs)) if dirs is not None else [None]
    dev = runs["att"][:, :3] - runs["cmd"][:, :3]
    lim = 1.08 * max(float(np.abs(dev).max()), max(p["RP_l_mm"] for p in pts) + max(p["AP_P_mm"] for p in pts), 1e-6)
    fig, axes = plt.subplots(2 * nblock, ncol, figsize=(2.1 * ncol + 0.9, 4.4 * nblock + 0.5), squeeze=False,
                             sharex=True, sharey=True, constrained_layout=True)
    circle = np.linspace(0, 2 * np.pi, 121)
    for k, p in enumerate(pts):
        idx = np.array([i for i, n in enumerate(runs["point"]) if n == p["point"]])
        bc = np.asarray(p["barycentre_mm"]) - np.asarray(p["commanded"][:3])
        for row, (j, plane) in enumerate(((1, "y"), (2, "z"))):
            ax = axes[2 * (k // ncol) + row, k % ncol]
            for c, lab in enumerate(labels):
                sel = idx if lab is None else idx[[dirs[i] == lab for i in idx]]
                ax.scatter(dev[sel, 0], dev[sel, j], s=7, color=COLOURS[c % len(COLOURS)], alpha=0.7, lw=0,
                           label="attained" if lab is None else f"direction {lab}")
            ax.plot(bc[0] + p["RP_l_mm"] * np.cos(circle), bc[j] + p["RP_l_mm"] * np.sin(circle), "k--", lw=0.8,
                    label="RP_l around the barycentre")
            ax.plot([0], [0], "k+", ms=12, mew=1.5, label="commanded")
            ax.plot([bc[0]], [bc[j]], "rx", ms=7, mew=1.5, label="barycentre")
            ax.set_xlim(-lim, lim)
            ax.set_ylim(-lim, lim)
            ax.set_aspect("equal")
            ax.tick_params(labelsize=7)
            ax.set_title(f"{p['point']}: x-{plane}", fontsize=9)
            if k % ncol == 0:
                ax.set_ylabel(f"d{plane} (mm)", fontsize=8)
            if row == 1:  # every x-z panel shows its dx scale (the last block may be short)
                ax.set_xlabel("dx (mm)", fontsize=8)
                ax.tick_params(labelbottom=True)
    for k in range(len(pts), nblock * ncol):
        for row in range(2):
            axes[2 * (k // ncol) + row, k % ncol].set_visible(False)
    handles, names = axes[0, 0].get_legend_handles_labels()
    fig.legend(handles, names, loc="outside lower center", ncol=min(len(names), {1: 1, 2: 2}.get(ncol, 4)), fontsize=8,
               frameon=False,
               markerscale=1.5)
    return _png(fig)


def _summary_figure(res: dict) -> bytes:
    """AP_P and RP_l per point, side by side (mm)."""
    plt = _plt()
    pts = res["points"]
    x = np.arange(len(pts))
    fig, ax = plt.subplots(figsize=(max(4.5, 1.2 + 0.9 * len(pts)), 3.2), constrained_layout=True)
    ap = [p["AP_P_mm"] for p in pts]
    rp = [p["RP_l_mm"] for p in pts]
    ax.bar(x - 0.2, ap, 0.4, label="AP_P", color="tab:blue")
    ax.bar(x + 0.2, rp, 0.4, label="RP_l", color="tab:orange")
    ax.set_xticks(x, [p["point"] for p in pts])
    ax.set_ylabel("mm")
    ax.set_ylim(0, 1.25 * max(ap + rp + [1e-9]))
    ax.legend(fontsize=8, ncol=2, loc="upper right")
    ax.set_title("pose accuracy and repeatability", fontsize=10)
    return _png(fig)


def iso9283_html(runs: dict, res: dict, title: str) -> str:
    esc = report.esc
    pts = res["points"]
    has_v = any("vAP_P_mm" in p for p in pts)
    head = ["point", "n", "AP_P", "AP_x", "AP_y", "AP_z", "RP_l"] + (["vAP_P"] if has_v else [])
    rows = [[p["point"], p["n"], _f(p["AP_P_mm"]), _f(p["AP_x_mm"]), _f(p["AP_y_mm"]), _f(p["AP_z_mm"]),
             _f(p["RP_l_mm"])] + ([_f(p.get("vAP_P_mm"))] if has_v else []) for p in pts]
    body = [f"<h1>{esc(title)}</h1>",
            f"<p>{len(runs['point'])} measured poses of {len(pts)} point{'s' if len(pts) > 1 else ''}, frame: {esc(res['frame'])}. "
            "Formulas of ISO 9283:1998 (7.2 pose accuracy and repeatability, 7.3 multi-directional variation, "
            "7.4 distance accuracy and repeatability); standard deviations with n - 1.</p>",
            "<h2>Position (mm)</h2>", report.table(head, rows, numeric=True)]
    if res["orientation"]:
        head = ["point", "AP_a", "AP_b", "AP_c", "RP_a (+-)", "RP_b (+-)", "RP_c (+-)"]
        rows = [[p["point"]] + [_f(p[f"AP_{n}_deg"]) for n in acc.ANGLES] + [_f(p[f"RP_{n}_deg"]) for n in acc.ANGLES]
                for p in pts]
        body += ["<h2>Orientation (deg, KUKA ABC)</h2>", report.table(head, rows, numeric=True)]
    if "AD_mm" in res:
        d = res["distance"]
        body += ["<h2>Distance (mm)</h2>",
                 report.table(["between", "cycles", "commanded", "mean attained", "AD", "RD (+-)"],
                              [[" - ".join(d["points"]), d["n"], _f(d["commanded_mm"]), _f(d["mean_mm"]),
                                _f(res["AD_mm"]), _f(res["RD_mm"])]], numeric=True)]
    body += ["<h2>Attained positions around each commanded pose</h2>",
             "<p>Deviation of every attained position from the commanded one (+); the barycentre (x) is AP_P away "
             "from it, the dashed circle of radius RP_l is centred on the barycentre.</p>",
             report.figure("deviations.png", "attained positions around each commanded pose"),
             report.figure("summary.png", "AP_P and RP_l per point"),
             "<h2>Definitions</h2><ul>"
             "<li>AP_P = |barycentre - commanded position|; AP_x = mean x - x_c (and y, z); AP_a = mean a - a_c "
             "(and b, c; angle differences wrapped to +-180 deg).</li>"
             "<li>RP_l = mean(l) + 3 S_l, l_j = |attained position j - barycentre|; RP_a = +-3 S_a.</li>"
             "<li>vAP_P: the largest distance between the barycentres of two approach directions.</li>"
             "<li>AD = mean attained distance - commanded distance (cycle by cycle); RD = +-3 S_D.</li></ul>"]
    return report.page(title, "\n".join(body))


def run_iso9283(data: str, out: str, distance: Optional[str] = None, model: Optional[str] = None,
                frame: str = "base", frame_label: Optional[str] = None) -> dict:
    """`kincal accuracy iso9283`: DIR/iso9283.json, DIR/report.html and the figures; returns the report.
    ``frame_label``: the frame the data are in, as the report says it (default "base (as given)")."""
    names = acc.parse_distance(distance) if distance is not None else None
    if frame == "instrument" and model is None:
        raise ValueError("--frame instrument needs --model M (an identified model: its instrument placement)")
    if model is not None and frame != "instrument":
        raise ValueError(f"--model {model}: only read with --frame instrument (the attained points in the "
                         "instrument's frame)")
    runs = acc.read_runs(data)
    if model is not None:
        runs = acc.to_base(runs, model)
    elif frame_label is not None:
        runs["frame"] = frame_label
    res = acc.iso9283(runs, names)
    files = {"deviations.png": _deviation_figure(runs, res), "summary.png": _summary_figure(res),
             "iso9283.json": json.dumps(res, indent=1) + "\n",
             "report.html": iso9283_html(runs, res, f"ISO 9283 pose accuracy and repeatability: {Path(data).name}")}
    write_folder(out, files)
    return res


def iso9283_summary(res: dict, out: str) -> str:
    lines = [f"{'point':<8}{'n':>5}{'AP_P mm':>11}{'RP_l mm':>11}" + ("  vAP_P mm" if any("vAP_P_mm" in p for p in
                                                                                        res["points"]) else "")]
    for p in res["points"]:
        v = f"{p['vAP_P_mm']:>10.4f}" if "vAP_P_mm" in p else ""
        lines.append(f"{p['point']:<8}{p['n']:>5}{p['AP_P_mm']:>11.4f}{p['RP_l_mm']:>11.4f}{v}")
    if "AD_mm" in res:
        lines.append(f"distance {'-'.join(res['distance']['points'])}: AD {res['AD_mm']:.4f} mm, RD +-{res['RD_mm']:.4f} mm")
    lines.append(f"report: {Path(out) / 'report.html'}")
    return "\n".join(lines)


# --- ISO 230-2 / VDI/DGQ 3441 -------------------------------------------------------------------

def _axis_figure(data: dict, res: dict) -> bytes:
    """Per-axis deviation bands: above, ISO 230-2 (each run's deviation, the mean per direction and
    the band mean +- 2 s); below, VDI/DGQ 3441 (the mean position deviation and the band of
    (U_j + Ps_j) / 2 around it, whose extent is P)."""
    plt = _plt()
    unit = res["unit"]
    iso, vdi = res["iso230_2"], res["vdi3441"]
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
    a1.set_title(f"ISO 230-2: A = {iso['A']:.4g}, E = {iso['E']:.4g}, R = {iso['R']:.4g}, B = {iso['B']:.4g} {unit}",
                 fontsize=10)
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
    per_m = f" ({vdi['P_per_m'] * 1000:.3g} um/m)" if "P_per_m" in vdi else ""
    a2.set_title(f"VDI/DGQ 3441: P = {vdi['P']:.4g} {unit}{per_m}, Ps = {vdi['Ps']:.4g}, U = {vdi['U']:.4g}, "
                 f"Pa = {vdi['Pa']:.4g}", fontsize=10)
    a2.legend(fontsize=8, loc="upper left", bbox_to_anchor=(1.01, 1.0), frameon=False)
    pad = 0.1 * max(top - bottom, 1e-9)
    a2.set_ylim(bottom - pad, top + pad)
    return _png(fig)


def axis_html(data: dict, res: dict, title: str) -> str:
    u = res["unit"]
    iso, vdi = res["iso230_2"], res["vdi3441"]
    fig = report.figure("axis.png", "per-axis deviation bands")
    iso_rows = [[_f(p["target"], 3), f"{p['n_up']}/{p['n_down']}", _f(p["mean_up"]), _f(p["mean_down"]), _f(p["s_up"]),
                 _f(p["s_down"]), _f(p["B_i"]), _f(p["R_i"])] for p in iso["targets"]]
    vdi_rows = [[_f(p["target"], 3), _f(p["mean"]), _f(p["U_j"]), _f(p["Ps_j"])] for p in vdi["targets"]]
    per_m = ""
    if "P_per_m" in vdi:
        per_m = (f"<p>Per metre of travel ({vdi['travel'] / 1000:.4g} m): P {vdi['P_per_m'] * 1000:.4g} um/m, "
                 f"Ps {vdi['Ps_per_m'] * 1000:.4g} um/m.</p>")
    body = f"""<h1>{report.esc(title)}</h1>
<p>{len(data['target'])} measured positions at {res['targets']} targets, both directions; every value in {u}.
Deviation = measured - target. Standard deviations with n - 1.</p>
<h2>ISO 230-2:2014</h2>
{report.table(["A", "E", "M", "R", "B", "mean reversal B"],
              [[_f(iso[k]) for k in ("A", "E", "M", "R", "B", "B_mean")]], numeric=True)}
{report.table(["target", "runs up/down", "mean_up", "mean_down", "s_up", "s_down", "B_i", "R_i"], iso_rows, numeric=True)}
<h2>VDI/DGQ 3441:1977</h2>
{report.table(["P", "Pa", "Ps", "U", "Ps mean", "U mean"],
              [[_f(vdi[k]) for k in ("P", "Pa", "Ps", "U", "Ps_mean", "U_mean")]], numeric=True)}
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


def run_axis(data_path: str, out: str, unit: str = "mm") -> dict:
    """`kincal accuracy axis`: DIR/axis.json, DIR/report.html and DIR/axis.png; returns the report."""
    if unit not in ("mm", "deg"):
        raise ValueError(f"--unit {unit}: expected mm or deg")
    data = acc.read_axis(data_path)
    res = acc.axis_statistics(data, unit)
    files = {"axis.png": _axis_figure(data, res), "axis.json": json.dumps(res, indent=1) + "\n",
             "report.html": axis_html(data, res, f"Positioning accuracy of one axis: {Path(data_path).name}")}
    write_folder(out, files)
    return res


def axis_summary(res: dict, out: str) -> str:
    u, iso, vdi = res["unit"], res["iso230_2"], res["vdi3441"]
    per_m = f" ({vdi['P_per_m'] * 1000:.4g} um/m)" if "P_per_m" in vdi else ""
    return (f"ISO 230-2: A {iso['A']:.4g}, E {iso['E']:.4g}, M {iso['M']:.4g}, R {iso['R']:.4g}, B {iso['B']:.4g} {u}\n"
            f"VDI/DGQ 3441: P {vdi['P']:.4g} {u}{per_m}, Pa {vdi['Pa']:.4g}, Ps {vdi['Ps']:.4g}, U {vdi['U']:.4g} {u}\n"
            f"report: {Path(out) / 'report.html'}")
