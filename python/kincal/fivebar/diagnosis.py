"""The diagnosis of the hidden robot: which pose-dependent effect do the four link lengths miss?
The stepwise engine of kincal.stats.stepwise with this mechanism's candidates (the registry's
five-bar effects on each link, transmission errors on each actuator) and refit, and its report."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Any, Callable, Optional, Union, cast

import numpy as np

from .. import _core
from .. import report
from ..io import strict_json
from ..stats import stepwise as engine
from .._core import FiveBar
from .hidden_robot import error_map_figure

if TYPE_CHECKING:
    from .._core import FiveBarPoints
    from ..typing_ import BoolArray, FloatArray

LINKS = ("a", "b", "c", "d")


def library() -> list[_core.Effect]:
    """The hidden robot's candidate effects, from the registry: every five-bar effect on each link
    a..d, and every joint-angle effect that needs no extra data (transmission error) on each
    actuator. Each is a _core.Effect (joint: the link or actuator, from 1)."""
    out: list[_core.Effect] = []
    for kind in _core.effect_kinds():
        if kind.domain == "fivebar" and kind.concerns == "link":
            out += [_core.Effect(kind.name, i + 1) for i in range(len(LINKS))]
    for kind in _core.effect_kinds():
        # joint_map (any order) is the serial diagnosis's; here the transmission error's two orders
        if kind.acts_on == "joint_angle" and not kind.needs and not kind.gravity_loaded_only and not kind.ordered:
            out += [_core.Effect(kind.name, j + 1) for j in range(2)]
    return out


def _acts_on(effect: _core.Effect) -> str:
    return _core.effect_kind(effect.name).acts_on


def _basis(effect: _core.Effect, t1: FloatArray, t2: FloatArray) -> FloatArray:
    """Per-point basis functions (n x effect.size) of an effect, the core's own (its effect's file): a
    link-length effect's at both actuated angles (link_deflection: p1 cos t1 + p2 sin t1 + p3 cos t2 +
    p4 sin t2, mm); a joint-angle effect of actuator j, the sum over its harmonic orders k of
    s_k sin(k tj) + c_k cos(k tj) (rad)."""
    b: FloatArray
    if _acts_on(effect) == "link_length":
        b = _core.link_basis(effect, np.asarray(t1, dtype=float), np.asarray(t2, dtype=float))
    else:
        b = _core.joint_basis(effect, np.asarray(t1 if effect.joint == 1 else t2, dtype=float))  # the core's basis
    if b.shape[1] != effect.size:
        raise ValueError(f"{effect.label}: {effect.size} parameters but the five-bar has {b.shape[1]} basis functions")
    return b


def predict(pts: FiveBarPoints, x: FloatArray, effects: list[_core.Effect]) -> FloatArray:
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


def fit_with_effects(pts: FiveBarPoints, effects: list[_core.Effect],
                     start: Optional[FloatArray] = None) -> FloatArray:
    """Least squares of the lengths and the effects' parameters on the measured positions
    (scipy's trust-region reflective; a few parameters, central-difference Jacobian)."""
    from scipy.optimize import least_squares

    x0 = np.r_[np.array([150.0, 150, 150, 150]) if start is None else start[:4], np.zeros(sum(e.size for e in effects))]
    if start is not None and len(start) > 4:
        x0[4:len(start)] = start[4:]
    r = least_squares(lambda x: (predict(pts, x, effects) - pts["measured"]).ravel(), x0, method="trf",
                      x_scale="jac", xtol=1e-12, ftol=1e-12, diff_step=1e-7)
    x: FloatArray = r.x  # scipy's result (scipy has no types here)
    return x


def _subset(pts: FiveBarPoints, mask: Union[BoolArray, slice]) -> FiveBarPoints:
    # the same keys, the arrays' rows picked: still a point set
    return cast("FiveBarPoints", {k: (v[mask] if isinstance(v, np.ndarray) else v) for k, v in pts.items()})


class Diagnosis:
    """The hidden robot's diagnosis problem (kincal.stepwise.Problem): the measured points,
    folds of points dealt at random, the refit of the lengths and the effects' parameters
    (fit_with_effects) and its linearisation: the current model's columns by central differences,
    a candidate's by the chain rule on the five-bar's Jacobians."""

    dims = 2

    def __init__(self, pts: FiveBarPoints, folds: int = 5, seed: int = 0) -> None:
        n = len(pts["id"])
        order = np.random.default_rng(seed).permutation(n)
        self.pts = pts
        self.folds = [np.isin(np.arange(n), order[i::folds]) for i in range(folds)]

    def held_errors(self, effects: list[_core.Effect], held: BoolArray) -> FloatArray:
        x = fit_with_effects(_subset(self.pts, ~held), effects)
        err: FloatArray = predict(_subset(self.pts, held), x, effects) - self.pts["measured"][held]
        return err

    def linearise(self, effects: list[_core.Effect]) -> engine.Linearisation[_core.Effect]:
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

    def _regressors(self, model: FiveBar, eff: _core.Effect) -> FloatArray:
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

    def describe(self, effect: _core.Effect) -> dict[str, Any]:
        if _core.effect_kind(effect.name).concerns == "link":
            return {"effect": effect.name, "joint": None, "link": LINKS[effect.joint - 1]}
        return {"effect": effect.name, "joint": effect.joint}

    def label(self, effect: _core.Effect) -> str:
        d = self.describe(effect)
        return f"{effect.name}(link {d['link']})" if "link" in d else effect.label

    def model_label(self, effects: list[_core.Effect]) -> str:
        return " + ".join(["four lengths"] + [self.label(e) for e in effects])


def diagnose(pts: FiveBarPoints, folds: int = 5, alpha: float = 1e-6, min_gain: float = 0.03, seed: int = 0,
             noise_mm: Optional[float] = None, say: Callable[[str], None] = lambda s: None) -> dict[str, Any]:
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


def effects_of(diag: dict[str, Any]) -> list[_core.Effect]:
    """The effects a diagnosis named (_core.Effect, joint: the link or actuator from 1)."""
    return [_core.Effect(s["effect"], LINKS.index(s["link"]) + 1 if s.get("link") else s["joint"])
            for s in diag["steps"]]


def write_diagnosis(pts: FiveBarPoints, diag: dict[str, Any], out: Union[str, Path], title: str) -> None:
    """In the folder ``out``: residual_map.png (the four lengths against the model with the named
    effects), report.html and diagnosis.json."""
    with report.staged_folder(out) as folder:  # the whole folder or nothing
        _write_diagnosis(pts, diag, folder, title)


def _write_diagnosis(pts: FiveBarPoints, diag: dict[str, Any], folder: Path, title: str) -> None:
    named = effects_of(diag)
    # point sets with the model's positions as the desired ones (the same keys)
    before = cast("FiveBarPoints", dict(pts, desired=predict(pts, fit_with_effects(pts, []), [])))
    after = cast("FiveBarPoints", dict(pts, desired=predict(pts, fit_with_effects(pts, named), named)))
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


def diagnosis_summary(diag: dict[str, Any]) -> str:
    """`kincal diagnose --robot fivebar`'s summary: each named effect and the final verdict."""
    lines = [f"{st['effect']} {st.get('link') or st['joint']}: cross-validated RMS "
             f"{st['rms_before_mm'] * 1000:.1f} -> {st['rms_after_mm'] * 1000:.1f} um" for st in diag["steps"]]
    return "\n".join(lines + [f"final {diag['final_rms_mm'] * 1000:.1f} um ({engine.noise_phrase(diag)}): "
                              f"{diag['verdict']}"])
