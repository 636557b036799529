"""Model discrepancy: find where the model and the measurements disagree, name the missing effect,
add it, refit, and show the gap shrink (`kincal diagnose`).

Each step: the current model is fitted (Ceres, C++ core); every candidate effect of the library
(contract names: joint_compliance, transmission_error, backlash, thermal_expansion, per joint where
it concerns one) gives regressors, the columns its parameters would add to the identification
Jacobian at the current fit. They are projected off the span of the current model's columns (so a
constant joint offset cannot pass for compliance: the geometry absorbs it), then scored by an
F-test on the residual and by the drop of the cross-validated residual of a linear fit (k folds of
poses). The best significant candidate is added, everything is refitted, and its cross-validated
RMS must fall; otherwise, or when no candidate is significant, the workflow stops.
"""

from __future__ import annotations

import math
from typing import Any, Callable, Optional

import numpy as np

from . import _core
from ._core import Robot
from . import identify as ident


def _effect_name(e: tuple) -> str:
    return e[0] if e[1] <= 0 else f"{e[0]}(joint {e[1]})"


def candidates(robot: Robot, data: dict) -> tuple[list, list]:
    """(name, joint) of every candidate the data can support, and notes on those skipped."""
    out, notes = [], []
    lim = _core.PointModel(robot, 1)
    loaded = [int(n.split(".")[0][5:]) for n in lim.names if n.endswith(".compliance")]
    for j in loaded:
        out.append(("joint_compliance", j))
    for j in range(1, robot.dof + 1):
        out.append(("transmission_error", j))
    if "dir" in data:
        out.extend(("backlash", j) for j in range(1, robot.dof + 1))
    else:
        notes.append("backlash skipped: the data have no dir1..dirN columns")
    if "temperature_c" in data and np.ptp(data["temperature_c"]) > 0.5:
        out.append(("thermal_expansion", 0))
    else:
        notes.append("thermal_expansion skipped: no temperature_c column, or it does not vary")
    return out, notes


class Spec:
    """The model under test: which joints carry a compliance, which extra effects."""

    def __init__(self):
        self.compliance: list[int] = []
        self.effects: list[tuple[str, int]] = []

    def with_(self, cand: tuple) -> "Spec":
        s = Spec()
        s.compliance, s.effects = list(self.compliance), list(self.effects)
        if cand[0] == "joint_compliance":
            s.compliance.append(cand[1])
        else:
            s.effects.append(cand)
        return s

    def has(self, cand: tuple) -> bool:
        return cand[1] in self.compliance if cand[0] == "joint_compliance" else cand in self.effects

    def fit(self, robot: Robot, data: dict, loss: str = "huber") -> dict:
        return _core.identify(robot, data, bool(self.compliance), loss, 0.1, 100, [], None, False, False,
                              self.effects, self.compliance)

    def errors(self, res: dict, data: dict) -> np.ndarray:
        return _core.point_errors(res["robot"], res["targets"], data, res["effects"], res["t_ref"])


def cv_rms(spec: Spec, robot: Robot, data: dict, folds: list) -> float:
    """Cross-validated RMS point error (mm): fit on the other folds, predict each fold."""
    sq, n = 0.0, 0
    for held in folds:
        res = spec.fit(robot, ident.subset(data, ~held))
        e = spec.errors(res, ident.subset(data, held))
        sq += float(np.sum(e ** 2))
        n += len(e)
    return math.sqrt(sq / n)


def _regressors(robot: Robot, res: dict, data: dict, spec: Spec, cand: tuple):
    """Residual r (3n), the current model's free columns and the candidate's columns at the fit."""
    n_targets = len(res["targets"])
    effects = list(spec.effects) + ([cand] if cand[0] != "joint_compliance" else [])
    pm = _core.PointModel(res["robot"], n_targets, effects, res["t_ref"], True)
    names = list(pm.names)
    x = np.zeros(len(names))
    cal = res["robot"]
    for i, nme in enumerate(names):
        if nme.endswith(".compliance"):
            j = int(nme.split(".")[0][5:])
            x[i] = _compliance_of(cal, j)
    for t, off in enumerate(res["targets"]):
        for k, c in enumerate("xyz"):
            x[names.index(f"target{t}.{c}")] = off[k]
    # current effect values
    pos = {n: i for i, n in enumerate(names)}
    cur_names = list(res["names"])
    for nme, val in zip(cur_names, res["x"]):
        if nme in pos and ("te_" in nme or "backlash" in nme or nme == "thermal_expansion"):
            x[pos[nme]] = val
    r, J = pm.residuals(list(x), data, True)
    fixed = dict(zip(cur_names, res["fixed"]))
    cur_cols = [pos[nme] for nme in cur_names if nme in pos and not fixed[nme]]
    if cand[0] == "joint_compliance":
        cand_cols = [pos[f"joint{cand[1]}.compliance"]]
    else:
        prefix = "" if cand[0] == "thermal_expansion" else f"joint{cand[1]}."
        key = {"transmission_error": "te_", "backlash": "backlash", "thermal_expansion": "thermal_expansion"}[cand[0]]
        cand_cols = [i for i, nme in enumerate(names) if nme.startswith(prefix) and key in nme
                     and nme not in cur_names]
    return np.asarray(r), np.asarray(J)[:, cur_cols], np.asarray(J)[:, cand_cols]


def _compliance_of(robot: Robot, joint: int) -> float:
    import json

    return float(json.loads(robot.to_json())["calibrated"]["joints"][joint - 1]["compliance_deg_per_knm"])


def score(r: np.ndarray, Jc: np.ndarray, R: np.ndarray, pose_rows: np.ndarray, folds: list) -> dict:
    """F-test and cross-validated linear gain of regressors R on residual r, off the span of Jc."""
    from scipy.stats import f as fdist

    Q, _ = np.linalg.qr(Jc)
    Rp = R - Q @ (Q.T @ R)
    keep = np.linalg.norm(Rp, axis=0) > 1e-9 * max(1.0, float(np.linalg.norm(R)))
    if not keep.any():
        return {"F": 0.0, "p_value": 1.0, "cv_gain": 0.0, "absorbed": True}
    Rp = Rp[:, keep]
    k = Rp.shape[1]
    beta, *_ = np.linalg.lstsq(Rp, r, rcond=None)
    rss0, rss1 = float(r @ r), float(np.sum((r - Rp @ beta) ** 2))
    dof = len(r) - Jc.shape[1] - k
    F = ((rss0 - rss1) / k) / (rss1 / dof) if rss1 > 0 and dof > 0 else math.inf
    p = float(fdist.sf(F, k, dof)) if math.isfinite(F) else 0.0
    before = after = 0.0
    for held_pose in folds:
        h = held_pose[pose_rows]
        b, *_ = np.linalg.lstsq(Rp[~h], r[~h], rcond=None)
        before += float(r[h] @ r[h])
        after += float(np.sum((r[h] - Rp[h] @ b) ** 2))
    gain = 1.0 - math.sqrt(after / before) if before > 0 else 0.0
    return {"F": float(F), "p_value": p, "cv_gain": gain, "absorbed": False, "parameters": int(k)}


def diagnose(robot: Robot, data: dict, *, folds: int = 5, alpha: float = 1e-6, min_gain: float = 0.03,
             max_steps: int = 6, seed: int = 0, noise_mm: Optional[float] = None,
             progress: Optional[Callable[[str], None]] = None) -> dict:
    """The workflow; returns the diagnosis.json of the contract (plus details for the report).

    noise_rms_mm: with ``noise_mm`` (the instrument's noise per coordinate, if known) its RMS per
    point; otherwise the final fit's own scatter, an upper bound of the noise. The verdict says "at
    the noise level" when the cross-validated RMS is within 1.3 times the known noise, or, with the
    noise unknown, when no candidate is even significant."""
    say = progress or (lambda s: None)
    cands, notes = candidates(robot, data)
    fold_masks = ident.folds(data, folds, seed)
    # fold membership per residual row (3 per point) for the linear scores
    pose_rows = np.repeat(np.arange(len(data["pose"])), 3)
    row_folds = [np.repeat(m, 3) for m in fold_masks]
    spec = Spec()
    say("fitting the geometric model")
    cur = cv_rms(spec, robot, data, fold_masks)
    history: list[dict[str, Any]] = [{"model": "geometry", "cv_rms_mm": cur}]
    steps: list[dict[str, Any]] = []
    for _ in range(max_steps):
        res = spec.fit(robot, data)
        scored = []
        for c in cands:
            if spec.has(c):
                continue
            r, Jc, R = _regressors(robot, res, data, spec, c)
            s = score(r, Jc, R, np.arange(len(r)), row_folds)
            s["effect"], s["joint"] = c[0], (c[1] if c[1] > 0 else None)
            scored.append(s)
        scored.sort(key=lambda s: -s["cv_gain"])
        sig = [s for s in scored if s["p_value"] < alpha and s["cv_gain"] > min_gain]
        if not sig:
            history[-1]["candidates"] = scored[:8]
            break
        best = sig[0]
        cand = (best["effect"], best["joint"] or 0)
        trial = spec.with_(cand)
        say(f"step {len(steps) + 1}: {_effect_name(cand)} (F = {best['F']:.3g}, cross-validated gain "
            f"{best['cv_gain']:.1%}); refitting")
        new = cv_rms(trial, robot, data, fold_masks)
        if new >= cur:
            history[-1]["candidates"] = scored[:8]
            history[-1]["rejected"] = {"effect": cand[0], "joint": best["joint"], "cv_rms_mm": new}
            break
        steps.append({"effect": cand[0], "joint": best["joint"],
                      "evidence": {"F": best["F"], "p_value": best["p_value"], "parameters": best["parameters"],
                                   "cv_gain_linear": best["cv_gain"],
                                   "runners_up": [{"effect": s["effect"], "joint": s["joint"],
                                                   "cv_gain_linear": s["cv_gain"], "p_value": s["p_value"]}
                                                  for s in scored[1:4]]},
                      "rms_before_mm": cur, "rms_after_mm": new})
        history[-1]["candidates"] = scored[:8]
        spec, cur = trial, new
        history.append({"model": " + ".join(["geometry"] + [_effect_name(("joint_compliance", j)) for j in spec.compliance]
                                            + [_effect_name(e) for e in spec.effects]), "cv_rms_mm": cur})
    final = spec.fit(robot, data)
    e = spec.errors(final, data)
    n_res, n_par = 3 * len(e), int(np.sum(~np.asarray(final["fixed"])))
    scatter = math.sqrt(float(np.sum(e ** 2)) / max(1, n_res - n_par)) * math.sqrt(3.0)
    left = [s for s in history[-1].get("candidates", []) if s["p_value"] < alpha]
    if noise_mm is not None:
        noise = noise_mm * math.sqrt(3.0)
        at_noise = cur <= 1.3 * noise
    else:
        noise = scatter  # an upper bound of the instrument noise: the fit's own scatter
        at_noise = not left
    if at_noise:
        verdict = "what remains is at the noise level"
    else:
        gains = ", ".join(f"{_effect_name((s['effect'], s['joint'] or 0))} {s['cv_gain']:.1%}" for s in left[:3])
        verdict = ("what remains is structured but not explained by the library"
                   + (f" (significant candidates gain too little: {gains})" if left else ""))
    say(f"{len(steps)} effect(s) named; cross-validated RMS {cur * 1000:.1f} um, noise estimate "
        f"{noise * 1000:.1f} um: {verdict}")
    return {"steps": steps, "final_rms_mm": cur, "noise_rms_mm": noise, "noise_known": noise_mm is not None,
            "fit_scatter_mm": scatter, "verdict": verdict, "notes": notes,
            "history": history, "folds": folds,
            "final_model": {"compliance_joints": spec.compliance, "effects": [list(x) for x in spec.effects]},
            "_final_fit": final, "_spec": spec}


def _variable(robot: Robot, data: dict, effect: str, joint: Optional[int]):
    """The natural variable of an effect for plots: (values per point, axis label)."""
    j = joint or 1
    if effect == "transmission_error":
        return data["q_deg"][:, j - 1], f"q{joint} (deg)"
    if effect == "backlash":
        return data["dir"][:, j - 1] + np.random.default_rng(0).uniform(-0.15, 0.15, len(data["pose"])), \
            f"dir{joint} (sign of the last motion, jittered)"
    if effect == "thermal_expansion":
        return data["temperature_c"], "temperature (C)"
    tau = np.array([_core.gravity_torque(robot, q)[0][j - 1] for q in data["q_deg"]]) / 1000.0
    return tau, f"gravity torque on joint {joint} (N m)"


def write_report(robot: Robot, data: dict, diag: dict, out_dir, title: str = "kincal diagnose") -> list:
    """Figures and report.html of a diagnosis in out_dir; returns the files written."""
    import html
    from pathlib import Path

    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    out = Path(out_dir)
    files = []
    # 1. the gap shrinking step by step
    hist = diag["history"]
    fig, ax = plt.subplots(figsize=(7, 3.6), constrained_layout=True)
    ax.bar(range(len(hist)), [h["cv_rms_mm"] * 1000 for h in hist], color="tab:blue")
    ax.axhline(diag["noise_rms_mm"] * 1000, color="k", ls="--", label="noise estimate")
    ax.set_xticks(range(len(hist)), [h["model"].replace(" + ", "\n+ ") for h in hist], fontsize=7)
    ax.set_ylabel("cross-validated RMS (um)")
    ax.legend()
    fig.savefig(out / "gap.png", dpi=100)
    plt.close(fig)
    files.append("gap.png")
    # 2. residual maps before (geometry only) and after (final model), in the instrument frame
    geo = Spec().fit(robot, data)
    e0 = Spec().errors(geo, data)
    e1 = diag["_spec"].errors(diag["_final_fit"], data)
    fig, axes = plt.subplots(1, 2, figsize=(10, 4.2), constrained_layout=True)
    vmax = float(np.max(e0)) * 1000
    for ax, e, lab in ((axes[0], e0, "geometric model"), (axes[1], e1, "final model")):
        sc = ax.scatter(data["xyz"][:, 0], data["xyz"][:, 1], c=e * 1000, s=8, cmap="viridis", vmin=0, vmax=vmax)
        ax.set_title(f"{lab}: RMS {np.sqrt(np.mean(e ** 2)) * 1000:.1f} um (fitted points)", fontsize=10)
        ax.set_xlabel("x (mm, instrument)")
        ax.set_aspect("equal")
    axes[0].set_ylabel("y (mm, instrument)")
    fig.colorbar(sc, ax=list(axes), label="point error (um)")
    fig.savefig(out / "residual_map.png", dpi=100)
    plt.close(fig)
    files.append("residual_map.png")
    # 3. residuals against each named effect's variable, before and after it was added
    spec = Spec()
    for k, st in enumerate(diag["steps"]):
        before = spec.errors(spec.fit(robot, data), data)
        spec = spec.with_((st["effect"], st["joint"] or 0))
        after = spec.errors(spec.fit(robot, data), data)
        var, lab = _variable(robot, data, st["effect"], st["joint"])
        fig, ax = plt.subplots(figsize=(6.5, 3.4), constrained_layout=True)
        ax.scatter(var, before * 1000, s=6, alpha=0.6, label="before")
        ax.scatter(var, after * 1000, s=6, alpha=0.6, label="after")
        ax.set_xlabel(lab)
        ax.set_ylabel("point error (um)")
        ax.set_title(f"step {k + 1}: {_effect_name((st['effect'], st['joint'] or 0))}", fontsize=10)
        ax.legend()
        name = f"step{k + 1}.png"
        fig.savefig(out / name, dpi=100)
        plt.close(fig)
        files.append(name)
    rows = "".join(
        f"<tr><td>{k + 1}</td><td>{html.escape(_effect_name((s['effect'], s['joint'] or 0)))}</td>"
        f"<td>{s['evidence']['F']:.3g}</td><td>{s['evidence']['p_value']:.2g}</td>"
        f"<td>{s['evidence']['cv_gain_linear']:.1%}</td><td>{s['rms_before_mm'] * 1000:.1f}</td>"
        f"<td>{s['rms_after_mm'] * 1000:.1f}</td></tr>" for k, s in enumerate(diag["steps"]))
    notes = "".join(f"<li>{html.escape(n)}</li>" for n in diag["notes"])
    steps_img = "".join(f'<figure><img src="{f}" alt="{f}"></figure>' for f in files if f.startswith("step"))
    page = f"""<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8"><title>{html.escape(title)}</title>
<style>body{{font-family:sans-serif;max-width:960px;margin:2em auto;color:#222}}
table{{border-collapse:collapse}}td,th{{border:1px solid #ccc;padding:4px 8px;text-align:right}}
img{{max-width:100%}}</style></head><body>
<h1>{html.escape(title)}</h1>
<p>{len(data['pose'])} measured points. Each step scores every candidate effect of the library against the
residual of the current model (projected off what the model can already absorb), adds the best significant one,
refits everything and checks that the cross-validated RMS ({diag['folds']} folds of poses) falls.</p>
<table><tr><th>step</th><th>effect</th><th>F</th><th>p</th><th>linear CV gain</th>
<th>CV RMS before (um)</th><th>after (um)</th></tr>{rows}</table>
<p><b>Result:</b> cross-validated RMS {diag['final_rms_mm'] * 1000:.1f} um against a noise estimate of
{diag['noise_rms_mm'] * 1000:.1f} um: {html.escape(diag['verdict'])}.</p>
<ul>{notes}</ul>
<h2>The gap, step by step</h2><figure><img src="gap.png" alt="gap"></figure>
<h2>Where the model and the measurements disagree</h2><figure><img src="residual_map.png" alt="residual map"></figure>
<h2>Residuals against each named effect</h2>{steps_img}
<p>Files: diagnosis.json (the contract's summary), {", ".join(files)}.</p>
</body></html>
"""
    from . import _core as core

    core.write_file_atomic(str(out / "report.html"), page)
    return files + ["report.html"]


def contract_json(diag: dict) -> dict:
    """diagnosis.json: the contract's keys and the evidence, without the fitted objects (an infinite
    F statistic, from a perfect fit, is written as null: JSON has no infinity)."""
    def clean(x):
        if isinstance(x, float) and not math.isfinite(x):
            return None
        if isinstance(x, dict):
            return {k: clean(v) for k, v in x.items()}
        if isinstance(x, (list, tuple)):
            return [clean(v) for v in x]
        return x
    return clean({k: v for k, v in diag.items() if not k.startswith("_")})
