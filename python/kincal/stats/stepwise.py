"""The diagnosis engine, the same for every mechanism (the serial robot, the five-bar hidden robot):
the greedy search that names the effects a model misses, the F-test and the cross-validated scores.

Each step: the current model is fitted; every candidate effect gives regressors, the columns its
parameters would add to the identification Jacobian at the current fit. They are projected off the
span of the current model's columns (so a constant offset cannot pass for another effect: the model
absorbs it), then scored by an F-test on the residual and by the drop of the cross-validated
residual of a linear fit (the same folds). The best significant candidate is added, everything is
refitted, and its cross-validated RMS must fall; otherwise, or when no candidate is significant, the
search stops.

A candidate may come in variants: nested orders (a joint_map of order 1..K: the columns of order k
are the first ones of order k + 1), each with a ridge penalty on its parameters (a smoothness penalty:
weights growing with the order), from the Problem's ``variants``; the variant is chosen by
cross-validation (the simplest, in the order listed, whose held-out residual is within ORDER_MARGIN
of the best variant's; on the Problem's ``variant_folds`` when it has them, else the same folds),
told to the Problem (``chosen``: its refits use the same penalty), then scored as any candidate on
the same folds.

A mechanism supplies a Problem (its folds, its refit, its linearisation and its names) and its
candidates; effects are _core.Effect objects (or objects with their ``name`` and ``joint``).

With the refits' confirmation, a Problem's ``refine(effects, candidate)`` may choose the step's
variant again by refits before it is confirmed (the serial robot's joint_map: its order and smoothing
by refits holding out ranges of the joint's angle; the linearisation fits the model's own parameters
on every row, held ones included). It may return another kind of effect instead, a library effect
the map contains (a transmission_error of that joint): the step then carries that candidate's own
scores of the round and the one it was preferred to (``preferred_by_refits_to``).

Without the refit's confirmation (``confirm=False``: `kincal identify --effects auto`, which chooses
again inside every training fold of its own cross-validation, so its figure is honest without it) a
step is taken on the F-test and the linear cross-validated gain alone, and no refit but the
linearisation's is made: one fit per step.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, Callable, Generic, Optional, Protocol, Sequence, TypeVar

import numpy as np

from ..io import strict_json
from .fdist import f_survival

if TYPE_CHECKING:
    from ..typing_ import BoolArray, FloatArray

#: how many of a round's candidates (best cross-validated gain first) the history lists and the
#: verdict weighs
LISTED = 8

#: nested orders: a higher order is kept only when it lowers the held-out residual sum of squares by
#: more than this share of the best order's
ORDER_MARGIN = 0.01


class EffectLike(Protocol):
    """What the engine reads of an effect: its name and its joint (0: none; a _core.Effect, or a
    mechanism's own candidate such as the serial robot's JointCompliance)."""

    @property
    def name(self) -> str: ...

    @property
    def joint(self) -> int: ...


#: the effects of one mechanism's search (its candidates and its model's effects)
E = TypeVar("E", bound=EffectLike)

#: residual r (dims per point), the current model's free columns Jc and a candidate's columns R
Linearisation = Callable[[E], "tuple[FloatArray, FloatArray, FloatArray]"]


class Problem(Protocol[E]):
    """What the engine needs of a mechanism and its measurements."""

    @property
    def dims(self) -> int:
        """Coordinates per measured point (3: a serial robot's x, y, z; 2: the five-bar's x, y)."""
        ...

    @property
    def folds(self) -> Sequence[BoolArray]:
        """Boolean masks of the held-out points, one per fold (a partition of the points)."""
        ...

    def held_errors(self, effects: list[E], held: BoolArray) -> FloatArray:
        """Errors (one row per point) of the held points, the model with ``effects`` fitted on the others."""
        ...

    def linearise(self, effects: list[E]) -> Linearisation[E]:
        """The model with ``effects`` fitted on every point, linearised for each candidate."""
        ...

    def describe(self, effect: E) -> dict[str, Any]:
        """The names of an effect in diagnosis.json: ``{"effect": NAME, "joint": k or None, ...}``."""
        ...

    def label(self, effect: E) -> str:
        """An effect in words (e.g. "backlash(joint 2)")."""
        ...

    def model_label(self, effects: list[E]) -> str:
        """The model with ``effects`` in words (e.g. "geometry + backlash(joint 2)")."""
        ...


def cv_rms(problem: Problem[E], effects: list[E]) -> float:
    """Cross-validated RMS point error (mm): fit on the other folds, predict each fold."""
    sq, n = 0.0, 0
    for held in problem.folds:
        e = problem.held_errors(effects, held)
        sq += float(np.sum(e ** 2))
        n += len(e)
    return math.sqrt(sq / n)


def _basis(Jc: FloatArray) -> FloatArray:
    """An orthonormal basis of the span of the current model's columns (those of a rank-deficient
    set that add nothing left out). From the eigen-decomposition of the small Gram matrix of the
    unit-scaled columns, orthonormalised twice ("twice is enough"): a tall QR in a multi-threaded
    LAPACK takes 100 times longer on a loaded machine."""
    if Jc.shape[1] == 0:
        return np.zeros((Jc.shape[0], 0))
    n = np.linalg.norm(Jc, axis=0)
    Q: FloatArray = Jc[:, n > 0] / n[n > 0]
    for _ in range(2):
        w, V = np.linalg.eigh(Q.T @ Q)
        keep = w > 1e-12 * max(float(w[-1]), 1e-300)
        Q = Q @ (V[:, keep] / np.sqrt(w[keep]))
    return Q


def _padded(row_folds: Sequence[BoolArray], n: int) -> list[BoolArray]:
    """The held-out masks over n residual rows: rows past the masks' (a prior's pseudo-rows, after the
    data's) are never held out."""
    return [np.concatenate([h, np.zeros(n - len(h), dtype=bool)]) if len(h) < n else h for h in row_folds]


def _projected(Q: FloatArray, R: FloatArray) -> tuple[FloatArray, BoolArray]:
    """R projected off the span of Q, and which columns survive (those the span does not absorb)."""
    Rp = R - Q @ (Q.T @ R)
    keep = np.linalg.norm(Rp, axis=0) > 1e-9 * max(1.0, float(np.linalg.norm(R)))
    return Rp, keep


def score(r: FloatArray, Jc: FloatArray, R: FloatArray, row_folds: Sequence[BoolArray],
          Q: Optional[FloatArray] = None, ridge: Optional[FloatArray] = None) -> dict[str, Any]:
    """F-test and cross-validated linear gain of regressors R on residual r, both off the span of Jc
    (the current model's columns refitted with the candidate's: a robust fit leaves part of r in
    their span; ``row_folds``: the held-out residual rows of each fold; ``Q``: an orthonormal basis
    of Jc's span, when the caller has it; ``ridge``: a penalty weight per column, in the fits of the
    cross-validation). Columns the span absorbs are dropped; a candidate absorbed whole scores
    nothing."""
    Q = _basis(Jc) if Q is None else Q
    r = r - Q @ (Q.T @ r)  # the current model refitted on its linearisation too (a robust fit leaves r off its span)
    Rp, keep = _projected(Q, R)
    if not keep.any():
        return {"F": 0.0, "p_value": 1.0, "cv_gain": 0.0, "absorbed": True}
    Rp = Rp[:, keep]
    sv = np.linalg.svd(Rp, compute_uv=False)
    k = int(np.sum(sv > 1e-9 * sv[0])) if len(sv) else 0  # the columns' rank: a redundant one adds nothing
    beta, *_ = np.linalg.lstsq(Rp, r, rcond=None)
    rss0, rss1 = float(r @ r), float(np.sum((r - Rp @ beta) ** 2))
    dof = len(r) - Jc.shape[1] - k
    if dof <= 0 or k == 0:  # more columns than the residual has coordinates: nothing can be tested
        return {"F": 0.0, "p_value": 1.0, "cv_gain": 0.0, "absorbed": False, "parameters": int(k), "untestable": True}
    F = ((rss0 - rss1) / k) / (rss1 / dof) if rss1 > 0 else math.inf
    p = f_survival(k, dof, F) if math.isfinite(F) else 0.0
    before = after = 0.0
    for h in _padded(row_folds, len(r)):
        if ridge is None:
            b, *_ = np.linalg.lstsq(Rp[~h], r[~h], rcond=None)
        else:
            A = Rp[~h]
            b = np.linalg.solve(A.T @ A + np.diag(np.asarray(ridge)[keep] ** 2), A.T @ r[~h])
        before += float(r[h] @ r[h])
        after += float(np.sum((r[h] - Rp[h] @ b) ** 2))
    gain = 1.0 - math.sqrt(after / before) if before > 0 else 0.0
    return {"F": float(F), "p_value": p, "cv_gain": gain, "absorbed": False, "parameters": int(k),
            "cv_ss_before": before, "cv_ss_after": after}


def choose_variant(r: FloatArray, R: FloatArray, variants: Sequence[tuple[int, FloatArray]],
                   row_folds: Sequence[BoolArray], Q: FloatArray) -> tuple[int, list[float]]:
    """The variant of nested regressors (each: the first ``m`` columns of R and a ridge weight per
    column; off the span of Q) by cross-validation: the held-out residual sum of squares of each;
    the first listed within ORDER_MARGIN of the best. Returns its index and the cross-validated gain
    of each."""
    r = r - Q @ (Q.T @ r)  # as score(): the current model refitted on its linearisation too
    Rp, keep = _projected(Q, R)
    G, g = Rp.T @ Rp, Rp.T @ r
    groups: dict[int, list[int]] = {}  # variants of the same columns, solved together
    for i, (m, ridge) in enumerate(variants):
        groups.setdefault(m, []).append(i)
    solved = []  # per group of variants: its variants, the columns kept and each variant's ridge on the diagonal
    for m, idx in groups.items():
        cols = np.flatnonzero(keep[:m])
        w2 = np.array([np.asarray(variants[i][1], dtype=float)[cols] ** 2 for i in idx])
        solved.append((idx, cols, w2[:, :, None] * np.eye(len(cols))[None, :, :]))
    before = 0.0
    after = np.zeros(len(variants))
    for h in _padded(row_folds, len(r)):
        Rh, rh = Rp[h], r[h]
        Gh, gh, ss = Rh.T @ Rh, Rh.T @ rh, float(rh @ rh)
        before += ss
        Gt, gt = G - Gh, g - gh
        for idx, cols, ridge2 in solved:
            if not len(cols):
                after[idx] += ss
                continue
            A = Gt[cols][:, cols][None, :, :] + ridge2
            try:
                b = np.linalg.solve(A, np.broadcast_to(gt[cols], (len(idx), len(cols)))[:, :, None])[:, :, 0]
            except np.linalg.LinAlgError:
                b = np.array([np.linalg.lstsq(a, gt[cols], rcond=1e-14)[0] for a in A])
            Ghc = Gh[cols][:, cols]
            after[idx] += ss - 2.0 * b @ gh[cols] + np.einsum("vi,ij,vj->v", b, Ghc, b)
    best = float(np.min(after))
    choice = int(np.flatnonzero(after <= best * (1.0 + ORDER_MARGIN) + 1e-300)[0])
    gains = [1.0 - math.sqrt(a / before) if before > 0 else 0.0 for a in after]
    return choice, gains


@dataclass
class Search(Generic[E]):
    """What the search found: the effects added to the starting ones (in order) and the model's
    cross-validated RMS (None without the refits' confirmation); ``history`` (each model, its CV RMS
    and its LISTED best candidates), ``last_scores`` (the LISTED best candidates of the last round,
    best gain first; empty when the search stopped at its step limit); ``linearised``: the last
    linearisation (the model with ``effects`` fitted on every point, unless the search stopped at
    its step limit: then None)."""
    effects: list[E]
    steps: list[dict[str, Any]]
    history: list[dict[str, Any]]
    cv_rms_mm: Optional[float]
    last_scores: list[dict[str, Any]]
    linearised: Optional[Linearisation[E]] = None


def _score_round(problem: Problem[E], regressors: Linearisation[E], effects: list[E], candidates: Sequence[E],
                 row_folds: list[BoolArray]) -> tuple[list[dict[str, Any]], Optional[float]]:
    """One round of the search: every candidate not yet in the model (and that the data can fit)
    scored against the current linearisation (its variant chosen first when it has several), with
    the residual's RMS. Each score carries its candidate (``_cand``) and columns (``_cols``)."""
    variants = getattr(problem, "variants", None)
    covered = getattr(problem, "covered", None)
    score_folds = getattr(problem, "score_folds", None)
    admits = getattr(problem, "admits", None)
    chosen = getattr(problem, "chosen", None)
    scored: list[dict[str, Any]] = []
    r_rms = None
    basis: Optional[tuple[FloatArray, FloatArray]] = None  # the current model's columns and their orthonormal basis
    for c in candidates:
        if any(e.name == c.name and e.joint == c.joint for e in effects):
            continue
        if admits and not admits(effects, c):  # more parameters than the data can fit
            continue
        r, Jc, R = regressors(c)
        n_data = len(row_folds[0]) if row_folds else len(r)  # the data's rows (a prior's pseudo-rows follow)
        if r_rms is None:
            r_rms = float(np.sqrt(np.mean(np.asarray(r[:n_data]) ** 2))) if n_data else 0.0
        if basis is None or basis[0] is not Jc:
            basis = (Jc, _basis(Jc))
        order: dict[str, Any] = {}
        ridge = None
        nested = variants(c, R) if variants else None
        if nested:
            sel = getattr(problem, "variant_folds", None)
            sel_folds = [np.repeat(f, problem.dims) for f in sel(c)] if sel else row_folds
            i, gains = choose_variant(r, R, [(m, w) for _, m, w in nested], sel_folds, basis[1])
            c, m, ridge = nested[i]
            R = R[:, :m]
            if covered and covered(c, candidates):
                continue
            if chosen:
                chosen(c, ridge)
            order = {"variant_cv_gain": [round(x, 6) for x in gains], "variant": i}
        s = score(r, Jc, R, row_folds, basis[1], ridge)
        own = score_folds(c) if score_folds else None  # e.g. a periodic effect: ranges of its angle
        if own and not s.get("absorbed") and not s.get("untestable"):  # it must also predict those
            s["extrapolation_cv_gain"] = score(r, Jc, R, [np.repeat(f, problem.dims) for f in own], basis[1],
                                               ridge)["cv_gain"]
        if "cv_ss_after" in s:  # the linearised cross-validated RMS per point, with the candidate
            s["cv_rms_linear_mm"] = math.sqrt(problem.dims * s.pop("cv_ss_after") / n_data)
            s.pop("cv_ss_before")
        s.update(problem.describe(c))
        s.update(order)
        s["_cand"] = c
        s["_cols"] = (r, Jc, R)
        scored.append(s)
    return scored, r_rms


def search(problem: Problem[E], start: Sequence[E], candidates: Sequence[E], *, alpha: float = 1e-6,
           min_gain: float = 0.03, max_steps: int = 6, say: Callable[[str], None] = lambda s: None,
           confirm: bool = True, cur: Optional[float] = None, listed: int = LISTED,
           refit: bool = True) -> Search[E]:
    """The greedy search from the model with the ``start`` effects: at most ``max_steps`` effects of
    ``candidates`` added, each significant (F-test p below ``alpha``), gaining more than ``min_gain``
    in the linear cross-validation, and (with ``confirm``) lowering the refitted model's
    cross-validated RMS. ``cur``: the starting model's cross-validated RMS when the caller has it
    (a search that goes on from another's end). ``listed``: how many of each round's candidates the
    history keeps. Without ``refit`` (and then without ``confirm``) the model is fitted once, at the
    start: each step's candidate columns join the model's and the next round scores against the
    residual of their linear fit (_Stepped)."""
    confirm = confirm and refit
    effects = list(start)
    row_folds = [np.repeat(m, problem.dims) for m in problem.folds]
    if confirm and cur is None:
        say(f"fitting the starting model ({problem.model_label(effects)})")
        cur = cv_rms(problem, effects)
    history: list[dict[str, Any]] = [{"model": problem.model_label(effects), "cv_rms_mm": cur}]
    regressors = None
    steps: list[dict[str, Any]] = []
    scored: list[dict[str, Any]] = []
    r_floor = getattr(problem, "resolution", None)  # a residual below it (per coordinate) explains nothing
    for _ in range(max_steps):
        if regressors is None:
            regressors = problem.linearise(effects)
        scored, r_rms = _score_round(problem, regressors, effects, candidates, row_folds)
        scored.sort(key=lambda s: -_credited(s))
        history[-1]["candidates"] = [{k: v for k, v in s.items() if not k.startswith(("_", "variant"))}
                                     for s in scored[:listed]]
        sig = [s for s in scored if s["p_value"] < alpha and _credited(s) > min_gain]
        if r_floor is not None and r_rms is not None and r_rms < r_floor:
            sig = []  # nothing left to explain: the residual is at the computation's resolution (noise-free data)
        if not sig:
            break
        best = sig[0]
        cand = best["_cand"]
        refine = getattr(problem, "refine", None)
        preferred_to = None
        if confirm and refine is not None:  # the variant chosen on the linearisation, chosen again by refits
            cand = refine(effects, cand)
            if cand.name != best["_cand"].name:  # another kind kept (a library effect the map contains)
                preferred_to = dict(problem.describe(best["_cand"]), cv_gain_linear=best["cv_gain"])
                # its own scores of this round (the round admitted the map that contains it)
                best = next((s for s in scored if problem.label(s["_cand"]) == problem.label(cand)), best)
        say(f"step {len(steps) + 1}: {problem.label(cand)} (F = {best['F']:.3g}, cross-validated gain "
            f"{best['cv_gain']:.1%})" + ("; refitting" if confirm else ""))
        new = cv_rms(problem, effects + [cand]) if confirm else None
        if new is not None and cur is not None and new >= cur:
            history[-1]["rejected"] = dict(problem.describe(cand), cv_rms_mm=new)
            break
        runners_up = [dict(problem.describe(s["_cand"]), cv_gain_linear=s["cv_gain"], p_value=s["p_value"])
                      for s in [s for s in scored[:4] if s is not best][:3]]
        evidence = {"F": best["F"], "p_value": best["p_value"], "parameters": best["parameters"],
                    "cv_gain_linear": best["cv_gain"], "runners_up": runners_up}
        if preferred_to is not None:
            evidence["preferred_by_refits_to"] = preferred_to
            if hasattr(problem, "variant_evidence"):
                evidence.update(problem.variant_evidence(cand, 0, []))
        elif "variant_cv_gain" in best:  # the variant chosen, and the cross-validated gain of each
            if hasattr(problem, "variant_evidence"):
                evidence.update(problem.variant_evidence(cand, best["variant"], best["variant_cv_gain"]))
            else:
                evidence.update(variant=best["variant"], variant_cv_gain=best["variant_cv_gain"])
        steps.append(dict(problem.describe(cand), evidence=evidence, rms_before_mm=cur, rms_after_mm=new))
        effects, cur = effects + [cand], new
        history.append({"model": problem.model_label(effects), "cv_rms_mm": cur})
        if refit:
            regressors = None
        elif hasattr(regressors, "step"):  # the problem's own step (e.g. re-weighed for a robust loss)
            regressors = regressors.step(cand)
        else:
            regressors = _Stepped(regressors, *best["_cols"])
        scored = []
    return Search(effects=effects, steps=steps, history=history, cv_rms_mm=cur, last_scores=scored[:LISTED],
                  linearised=None if steps and not refit else regressors)


def _credited(s: dict[str, Any]) -> float:
    """The gain a candidate is credited with: its cross-validated gain, or what it gains on the
    Problem's own folds for it (a periodic effect on held-out ranges of its angle) when less."""
    credited: float = min(s["cv_gain"], s.get("extrapolation_cv_gain", math.inf))
    return credited


class _Stepped(Generic[E]):
    """The linearisation after a step taken without a refit (search's ``refit=False``): the step's
    candidate columns R join the model's Jc, and the residual is what their joint linear
    least-squares fit leaves of r (one Gauss-Newton step from the last fit); every candidate's
    columns stay those of the last fit."""

    def __init__(self, base: Linearisation[E], r: FloatArray, Jc: FloatArray, R: FloatArray) -> None:
        self.base = base
        self.Jc = np.hstack([Jc, R])
        Q = _basis(self.Jc)
        self.r = r - Q @ (Q.T @ r)

    def __call__(self, cand: E) -> tuple[FloatArray, FloatArray, FloatArray]:
        return self.r, self.Jc, self.base(cand)[2]


def conclude(problem: Problem[E], found: Search[E], errors: FloatArray, n_params: int, noise_mm: Optional[float],
             alpha: float = 1e-6, say: Callable[[str], None] = lambda s: None) -> dict[str, Any]:
    """The verdict on what remains, from the final model's point errors fitted on every point
    (``errors``, ``n_params`` free parameters). noise_rms_mm: with ``noise_mm`` (the instrument's
    noise per coordinate, if known) its RMS per point; otherwise the final fit's own scatter, an
    upper bound of the noise. "At the noise level" when the cross-validated RMS is within 1.3 times
    the known noise; with the noise unknown, "no structure left that the library finds" when no
    candidate of the last round (of the LISTED best) is even significant (not "at the noise level":
    with few points nothing is significant, whatever remains)."""
    dims = getattr(problem, "point_dims", problem.dims)  # the errors' coordinates (3 with 6-D rows too)
    scatter = math.sqrt(float(np.sum(errors ** 2)) / max(1, dims * len(errors) - n_params)) * math.sqrt(dims)
    left = [s for s in found.last_scores if s["p_value"] < alpha]
    if noise_mm is not None:
        noise = noise_mm * math.sqrt(dims)
        at_noise = found.cv_rms_mm is not None and found.cv_rms_mm <= 1.3 * noise
    else:
        noise = scatter
        at_noise = not left
    if at_noise:
        verdict = ("what remains is at the noise level" if noise_mm is not None else
                   f"no structure left that the library finds ({len(errors)} points; the noise level is not known)")
    else:
        gains = ", ".join(f"{problem.label(s['_cand'])} {s['cv_gain']:.1%}" for s in left[:3])
        verdict = ("what remains is structured but not explained by the library"
                   + (f" (significant candidates gain too little: {gains})" if left else ""))
    out = {"noise_rms_mm": noise, "noise_known": noise_mm is not None, "fit_scatter_mm": scatter, "verdict": verdict,
           "noise_per_coordinate_mm": noise_mm}
    cv = "" if found.cv_rms_mm is None else f"; cross-validated RMS {found.cv_rms_mm * 1000:.1f} um"
    say(f"{len(found.steps)} effect(s) named{cv}, {noise_phrase(out)}: {verdict}")
    return out


def noise_phrase(diag: dict[str, Any]) -> str:
    """How a summary or report names the noise a verdict compares with: the instrument's, when given,
    or else the final fit's own scatter, which only bounds it (it also holds what no model explains)."""
    if diag["noise_known"]:
        per = diag.get("noise_per_coordinate_mm")
        return (f"the instrument's noise {diag['noise_rms_mm'] * 1000:.1f} um per point" +
                (f" ({per * 1000:.1f} um per coordinate)" if per is not None else ""))
    return (f"noise not known (the final fit's own scatter, {diag['noise_rms_mm'] * 1000:.1f} um, only bounds it; "
            f"--noise gives it)")


def contract_json(diag: dict[str, Any]) -> dict[str, Any]:
    """diagnosis.json: the contract's keys and the evidence, without the fitted objects (an infinite
    F statistic, from a perfect fit, is written as null: JSON has no infinity)."""
    out: dict[str, Any] = strict_json.finite_or_none({k: v for k, v in diag.items() if not k.startswith("_")})
    return out
