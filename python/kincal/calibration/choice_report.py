"""What `kincal identify --effects auto` tried and kept, for the model JSON (choice_report) and the
summary (choice_lines): every candidate with its F-test, its gains and its linearised
cross-validated RMS, what was kept, how many training folds kept it, and the held-out RMS of the
geometry beside the chosen model's."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any, Optional

from .. import _core
from . import effect_choice
from .fitting import rms

if TYPE_CHECKING:
    from ..typing_ import FloatArray


def choice_report(top: effect_choice.Choice, fold_choices: list[Optional[effect_choice.Choice]],
                  e: dict[str, FloatArray], val: dict[str, Any], k_folds: int) -> dict[str, Any]:
    """What `--effects auto` tried and kept: each candidate with its F-test, its linear
    cross-validated gain and RMS in the last round (kept: in the step that took it), how many of
    the validation's training folds kept each effect, and the held-out RMS of the starting model
    (the geometry) beside the chosen one's."""
    tried: dict[str, dict[str, Any]] = {}
    kept_labels = {x.label for x in top.effects}
    last = len(top.search.history) - 1
    for i, h in enumerate(top.search.history):
        for c in h.get("candidates", []):
            label = _label_of(c)
            if i < last and label not in kept_labels:
                continue  # as the last round scored it (one scored early and covered since is not listed)
            tried[label] = {"candidate": label, "F": c["F"], "p_value": c["p_value"], "cv_gain": c["cv_gain"],
                            "extrapolation_cv_gain": c.get("extrapolation_cv_gain"),
                            "cv_rms_linear_mm": c.get("cv_rms_linear_mm"), "parameters": c.get("parameters", 0),
                            "round": i + 1, "kept": False}
    kept = [x.label for x in top.effects]
    for k, label in enumerate(kept):
        if label in tried:
            tried[label]["kept"] = True
            tried[label]["step"] = k + 1
    counts: dict[str, int] = {}
    for ch in fold_choices:
        for x in (ch.effects if ch is not None else []):
            counts[x.label] = counts.get(x.label, 0) + 1
    out: dict[str, Any] = {
           "mode": "auto", "rule": f"F-test p < {effect_choice.ALPHA:g} and linear cross-validated gain > "
                                   f"{effect_choice.MIN_GAIN:.0%} (the diagnosis's), on {k_folds} folds of "
                                   "whole configurations",
           "kept": kept, "tried": sorted(tried.values(), key=lambda t: (not t["kept"], t.get("step", 0), -t["cv_gain"])),
           "notes": list(top.notes), "nested": bool(fold_choices),
           "folds_kept": counts, "folds": len(fold_choices)}
    if "e0" in e:
        out["start_cv_rms_mm"] = rms(e["e0"])
        out["chosen_cv_rms_mm"] = val.get("after_rms_mm")
    return out


def _label_of(c: dict[str, Any]) -> str:
    """A scored candidate's label (as _core.Effect.label names it)."""
    if c.get("gravity"):
        return effect_choice.JointCompliance(c["gravity"]).label
    if _core.effect_kind(c["effect"]).ordered:
        return _core.Effect(c["effect"], c["joint"], order=c["order"]).label
    return _core.Effect(c["effect"], c["joint"] or 0).label


def choice_lines(ch: dict[str, Any]) -> list[str]:
    """The summary's lines on `--effects auto`: every candidate tried, with its test and its
    cross-validated RMS, what was kept, how often the training folds kept it, and the held-out RMS
    of the geometry beside the chosen model's."""
    lines = [f"effects chosen by the data (--effects auto; {ch['rule']}):"]
    if ch["tried"]:
        lines.append(f"  {'candidate':<42}{'F':>10}{'p':>10}{'CV gain':>9}{'on ranges':>11}{'CV RMS (mm)':>13}")
        for t in ch["tried"]:
            p = "<1e-16" if t["p_value"] < 1e-16 else f"{t['p_value']:.2g}"
            rms = "-" if t["cv_rms_linear_mm"] is None else f"{t['cv_rms_linear_mm']:.4f}"
            ext = "" if t.get("extrapolation_cv_gain") is None else f"{t['extrapolation_cv_gain']:.1%}"
            lines.append(f"  {t['candidate']:<42}{t['F']:>10.3g}{p:>10}{t['cv_gain']:>9.1%}{ext:>11}{rms:>13}"
                         + (f"   kept (step {t['step']})" if t["kept"] else ""))
        lines.append("  (CV RMS: the model of its round with the candidate, linearised at that round's fit, on the "
                     "same folds; on ranges: a periodic effect's gain holding out ranges of its angle, the gain it "
                     "is credited with when less)")
    for n in ch["notes"]:
        lines.append(f"  note: {n}")
    kept = ", ".join(ch["kept"]) or "none: the geometry alone"
    folds = ""
    if ch["folds"]:
        per = ", ".join(f"{k} in {v}" for k, v in ch["folds_kept"].items())
        folds = f" (chosen again in each of the {ch['folds']} training folds: {per or 'none kept in any'})"
    lines.append(f"  kept: {kept}{folds}")
    if ch.get("start_cv_rms_mm") is not None and ch.get("chosen_cv_rms_mm") is not None:
        how = ("nested: the choice made inside each training fold" if ch["nested"] else
               "the choice made on the fitted rows only")
        lines.append(f"  held-out RMS: geometry alone {ch['start_cv_rms_mm']:.4f} mm, the chosen model "
                     f"{ch['chosen_cv_rms_mm']:.4f} mm ({how})")
    return lines
