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
from typing import Any, Callable, Optional, Sequence

import numpy as np

from . import _core
from ._core import Robot
from . import identify as ident


def _label(effect: str, joint: Optional[int]) -> str:
    return _core.Effect(effect, joint or 0).label


def _needs_column(kind) -> str:
    """The measurement-set key of the column an effect kind reads ('' when none)."""
    return "dir" if kind.needs == "dir" else kind.needs


def candidates(robot: Robot, data: dict, start: Sequence = ()) -> tuple[list, list]:
    """Every candidate effect (a _core.Effect per joint where it applies, from the registry) the data
    can support, and notes on those skipped. Effects of ``start`` (the model the diagnosis starts
    from) are no candidates."""
    out, notes = [], []
    have = {(e.name, e.joint) for e in start}
    for kind in _core.effect_kinds():
        if kind.domain != "serial":
            continue
        col = _needs_column(kind)
        if col == "dir" and col not in data:
            notes.append(f"{kind.name} skipped: the data have no dir1..dir{robot.dof} columns")
            continue
        if col == "temperature_c" and (col not in data or np.ptp(data[col]) <= 0.5):
            notes.append(f"{kind.name} skipped: no temperature_c column, or it does not vary")
            continue
        if col and col not in data:
            notes.append(f"{kind.name} skipped: the data have no {col} column")
            continue
        joints = ident.applicable_joints(robot, kind) if kind.concerns == "joint" else [0]
        out += [_core.Effect(kind.name, j) for j in joints if (kind.name, j) not in have]
    return out, notes


class Spec:
    """The model under test: its effects (joint_compliance per joint included) and the fit's options."""

    def __init__(self, effects: Sequence = (), **fit_options):
        self.effects: list = list(effects)
        self.fit_options = dict(fit_options)

    def with_(self, cand) -> "Spec":
        return Spec(self.effects + [cand], **self.fit_options)

    def has(self, cand) -> bool:
        return any(e.name == cand.name and e.joint == cand.joint for e in self.effects)

    @property
    def compliance(self) -> list:
        return [e.joint for e in self.effects if e.name == "joint_compliance"]

    def label(self) -> str:
        return " + ".join(["geometry"] + [e.label for e in self.effects])

    def fit(self, robot: Robot, data: dict) -> "_core.IdentifyResult":
        return _core.identify(robot, data, ident.options(self.effects, covariance=False, **self.fit_options))

    def errors(self, res, data: dict) -> np.ndarray:
        return _core.point_errors(res.robot, res.targets, data)


def cv_rms(spec: Spec, robot: Robot, data: dict, folds: list) -> float:
    """Cross-validated RMS point error (mm): fit on the other folds, predict each fold."""
    sq, n = 0.0, 0
    for held in folds:
        res = spec.fit(robot, ident.subset(data, ~held))
        e = spec.errors(res, ident.subset(data, held))
        sq += float(np.sum(e ** 2))
        n += len(e)
    return math.sqrt(sq / n)


def _key(p) -> tuple:
    return (p.kind, p.joint, p.target, p.name)


def _regressors(robot: Robot, res, data: dict, spec: Spec, cand):
    """Residual r (3n), the current model's free columns and the candidate's columns at the fit."""
    layout = res.layout
    extra = list(layout.effect_list) + ([cand] if cand.name != "joint_compliance" else [])
    pm = _core.PointModel(res.robot, len(res.targets), extra, res.t_ref, True)
    new = pm.layout.parameters
    old = {_key(p): p.index for p in layout.parameters}
    x = np.zeros(len(new))
    fit_x = np.asarray(res.x)
    for p in new:
        # geometry, tool and base are corrections to the calibrated model (zero); compliances,
        # targets and effect values are absolute
        if p.kind not in ("joint_geometry", "tool", "base") and _key(p) in old:
            x[p.index] = fit_x[old[_key(p)]]
    r, J = pm.residuals(list(x), data, True)
    fixed = np.asarray(res.fixed)
    cur_cols = [p.index for p in new if _key(p) in old and not fixed[old[_key(p)]]]
    kind = "compliance" if cand.name == "joint_compliance" else cand.name
    cand_cols = [p.index for p in new if p.kind == kind and p.joint == cand.joint
                 and (kind == "compliance" or _key(p) not in old)]
    return np.asarray(r), np.asarray(J)[:, cur_cols], np.asarray(J)[:, cand_cols]


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
             progress: Optional[Callable[[str], None]] = None, effects: Sequence = (), loss: str = "huber",
             loss_scale_mm: float = 0.1, orientation_weight: float = 100.0) -> dict:
    """The workflow; returns the diagnosis.json of the contract (plus details for the report).

    ``effects``: the model the diagnosis starts from besides the geometry (Effect objects or texts of
    ``--effects``); they are no candidates. ``loss``, ``loss_scale_mm``, ``orientation_weight``:
    identify's options, used in every fit.
    noise_rms_mm: with ``noise_mm`` (the instrument's noise per coordinate, if known) its RMS per
    point; otherwise the final fit's own scatter, an upper bound of the noise. The verdict says "at
    the noise level" when the cross-validated RMS is within 1.3 times the known noise, or, with the
    noise unknown, when no candidate is even significant."""
    say = progress or (lambda s: None)
    start_effects = ident.check_effects(effects, robot)
    ident.check_data_for(start_effects, data, robot)
    cands, notes = candidates(robot, data, start_effects)
    fold_masks = ident.folds(data, folds, seed)
    # fold membership per residual row (3 per point) for the linear scores
    row_folds = [np.repeat(m, 3) for m in fold_masks]
    start = Spec(start_effects, loss=loss, loss_scale_mm=loss_scale_mm, orientation_weight=orientation_weight)
    spec = start
    say(f"fitting the starting model ({spec.label()})")
    cur = cv_rms(spec, robot, data, fold_masks)
    history: list[dict[str, Any]] = [{"model": spec.label(), "cv_rms_mm": cur}]
    steps: list[dict[str, Any]] = []
    for _ in range(max_steps):
        res = spec.fit(robot, data)
        scored = []
        for c in cands:
            if spec.has(c):
                continue
            r, Jc, R = _regressors(robot, res, data, spec, c)
            s = score(r, Jc, R, np.arange(len(r)), row_folds)
            s["effect"], s["joint"] = c.name, (c.joint if c.joint > 0 else None)
            s["_cand"] = c
            scored.append(s)
        scored.sort(key=lambda s: -s["cv_gain"])
        sig = [s for s in scored if s["p_value"] < alpha and s["cv_gain"] > min_gain]
        if not sig:
            history[-1]["candidates"] = scored[:8]
            break
        best = sig[0]
        cand = best["_cand"]
        trial = spec.with_(cand)
        say(f"step {len(steps) + 1}: {cand.label} (F = {best['F']:.3g}, cross-validated gain "
            f"{best['cv_gain']:.1%}); refitting")
        new = cv_rms(trial, robot, data, fold_masks)
        if new >= cur:
            history[-1]["candidates"] = scored[:8]
            history[-1]["rejected"] = {"effect": cand.name, "joint": best["joint"], "cv_rms_mm": new}
            break
        steps.append({"effect": cand.name, "joint": best["joint"],
                      "evidence": {"F": best["F"], "p_value": best["p_value"], "parameters": best["parameters"],
                                   "cv_gain_linear": best["cv_gain"],
                                   "runners_up": [{"effect": s["effect"], "joint": s["joint"],
                                                   "cv_gain_linear": s["cv_gain"], "p_value": s["p_value"]}
                                                  for s in scored[1:4]]},
                      "rms_before_mm": cur, "rms_after_mm": new})
        history[-1]["candidates"] = scored[:8]
        spec, cur = trial, new
        history.append({"model": spec.label(), "cv_rms_mm": cur})
    for h in history:
        for s in h.get("candidates", []):
            s.pop("_cand", None)
    final = spec.fit(robot, data)
    e = spec.errors(final, data)
    n_res, n_par = 3 * len(e), int(np.sum(~np.asarray(final.fixed)))
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
        gains = ", ".join(f"{_label(s['effect'], s['joint'])} {s['cv_gain']:.1%}" for s in left[:3])
        verdict = ("what remains is structured but not explained by the library"
                   + (f" (significant candidates gain too little: {gains})" if left else ""))
    say(f"{len(steps)} effect(s) named; cross-validated RMS {cur * 1000:.1f} um, noise estimate "
        f"{noise * 1000:.1f} um: {verdict}")
    final_model = {"effects": [{"effect": x.name, "joint": x.joint or None, "label": x.label} for x in spec.effects],
                   "started_from": [x.label for x in start_effects]}
    return {"steps": steps, "final_rms_mm": cur, "noise_rms_mm": noise, "noise_known": noise_mm is not None,
            "fit_scatter_mm": scatter, "verdict": verdict, "notes": notes,
            "history": history, "folds": folds, "final_model": final_model,
            "_final_fit": final, "_spec": spec, "_start": start}


def final_identification(robot: Robot, data: dict, diag: dict,
                         tool_targets: Optional[np.ndarray] = None) -> "ident.Identification":
    """The diagnosed model (every named effect and those it started from), identified on all the data
    with Ceres as `kincal identify` does (covariance included), ready for model.json; with
    ``tool_targets`` (the targets' offsets in the tool frame) the TCP is placed as identify's
    --tool-targets does."""
    spec: Spec = diag["_spec"]
    res = ident.identify(robot, data, effects=spec.effects, holdout=0.0, **spec.fit_options)
    res.validation = {"scheme": f"fitted on every row; cross-validated ({diag['folds']} folds) in the diagnosis",
                      "held_rows": 0, "fit_rows": int(len(data["pose"])),
                      "diagnosis_cv_rms_mm": diag["final_rms_mm"]}
    if tool_targets is not None:
        res = ident.tool_from_targets(res, tool_targets)
    return res


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


def write_report(robot: Robot, data: dict, diag: dict, out_dir, title: str = "kincal diagnose",
                 model_file: Optional[str] = None) -> list:
    """Figures and report.html of a diagnosis in out_dir; returns the files written. ``model_file``:
    the name of the final model's JSON written beside it (said in the report)."""
    import html
    from pathlib import Path

    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    out = Path(out_dir)
    files = []
    # 1. the gap shrinking step by step
    hist = diag["history"]
    # one horizontal bar per step, labelled by the effect that step added (the model is cumulative):
    # long labels never overlap
    fig, ax = plt.subplots(figsize=(8, 1.2 + 0.45 * len(hist)), constrained_layout=True)
    labels = [h["model"].split(" + ")[-1] if k else "geometry" for k, h in enumerate(hist)]
    labels = [lab if k == 0 else "+ " + lab for k, lab in enumerate(labels)]
    y = np.arange(len(hist))[::-1]
    vals = [h["cv_rms_mm"] * 1000 for h in hist]
    ax.barh(y, vals, color="tab:blue")
    for yy, v in zip(y, vals):
        ax.text(v, yy, f" {v:.1f}", va="center", fontsize=8)
    ax.axvline(diag["noise_rms_mm"] * 1000, color="k", ls="--", label="noise estimate")
    ax.set_yticks(y, labels, fontsize=8)
    ax.set_xlabel("cross-validated RMS (um), each step adds one effect to the model above it")
    ax.set_xlim(0, max(vals) * 1.15)
    ax.legend(loc="lower right", fontsize=8)
    fig.savefig(out / "gap.png", dpi=100)
    plt.close(fig)
    files.append("gap.png")
    # 2. residual maps before (geometry only) and after (final model), in the instrument frame
    start: Spec = diag["_start"]
    e0 = start.errors(start.fit(robot, data), data)
    e1 = diag["_spec"].errors(diag["_final_fit"], data)
    fig, axes = plt.subplots(1, 2, figsize=(10, 4.2), constrained_layout=True)
    vmax = float(np.max(e0)) * 1000
    for ax, e, lab in ((axes[0], e0, "starting model"), (axes[1], e1, "final model")):
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
    spec = start
    for k, st in enumerate(diag["steps"]):
        before = spec.errors(spec.fit(robot, data), data)
        spec = spec.with_(_core.Effect(st["effect"], st["joint"] or 0))
        after = spec.errors(spec.fit(robot, data), data)
        var, lab = _variable(robot, data, st["effect"], st["joint"])
        fig, ax = plt.subplots(figsize=(6.5, 3.4), constrained_layout=True)
        ax.scatter(var, before * 1000, s=6, alpha=0.6, label="before")
        ax.scatter(var, after * 1000, s=6, alpha=0.6, label="after")
        ax.set_xlabel(lab)
        ax.set_ylabel("point error (um)")
        ax.set_title(f"step {k + 1}: {_label(st['effect'], st['joint'])}", fontsize=10)
        ax.legend()
        name = f"step{k + 1}.png"
        fig.savefig(out / name, dpi=100)
        plt.close(fig)
        files.append(name)
    rows = "".join(
        f"<tr><td>{k + 1}</td><td>{html.escape(_label(s['effect'], s['joint']))}</td>"
        f"<td>{s['evidence']['F']:.3g}</td><td>{s['evidence']['p_value']:.2g}</td>"
        f"<td>{s['evidence']['cv_gain_linear']:.1%}</td><td>{s['rms_before_mm'] * 1000:.1f}</td>"
        f"<td>{s['rms_after_mm'] * 1000:.1f}</td></tr>" for k, s in enumerate(diag["steps"]))
    notes = "".join(f"<li>{html.escape(n)}</li>" for n in diag["notes"])
    fm = diag.get("final_model", {})
    model_note = "" if not model_file else (
        f"<p><b>Model:</b> {html.escape(model_file)} was written: the final model "
        f"({html.escape(' + '.join(['geometry'] + [e['label'] for e in fm.get('effects', [])]))}), identified on all "
        f"the data, ready for <code>kincal compensate --model {html.escape(model_file)}</code>.</p>")
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
{model_note}
<p>Files: diagnosis.json (the contract's summary), {", ".join(([model_file] if model_file else []) + files)}.</p>
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
