"""Which effects a serial robot's model carries, chosen by the data: the candidate effects of the
registry (joint_compliance, transmission_error, backlash, thermal_expansion, drift, joint_map, per
joint where it concerns one), their refit (Ceres, C++ core) and their linearisation (the columns a
candidate's parameters would add to the identification Jacobian at the current fit, every
candidate's in one evaluation), for the stepwise search of kincal.stepwise.

`kincal identify --effects auto` searches these candidates (every library effect that applies to
the robot and the data's columns) with the diagnosis's significance rule (F test, 3% linear
cross-validated gain), the model fitted once and each step taken on its linearisation, and, to
report an honest figure, makes the same choice again inside every training fold of its validation
(choose()). `kincal diagnose` searches the same candidates with the same rule, refitting the model
and confirming the cross-validated RMS at every step, then scores what remains against every
variable.

Joint compliance is one candidate for every gravity-loaded joint (JointCompliance), in the form
``--gravity`` gives: the torques from the model's link masses (``masses``, or ``auto`` on a model
that has masses), or from mass moments fitted with it (``fit``, or ``auto`` without masses: its
columns are the compliance columns at its own fit, where the bilinear deflection lies in their span).
A periodic effect of a joint angle is credited with the smaller of its gain and its gain on held-out
ranges of that angle. Candidates are scored on the robust pseudo-residual (robust_weights).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, Callable, Optional, Sequence

import numpy as np

from .. import _core
from ..stats import stepwise as engine
from .._core import Robot
from .candidates import (MAX_MAP_ORDER as MAX_MAP_ORDER, Candidate as Candidate, JointCompliance as JointCompliance,
                         applicable_joints as applicable_joints, candidates as candidates, check_data as check_data,
                         expand as expand, loaded_joints)
from ..stats.grouping import subset
from .fitting import FitOptions, folds as grouped_folds, point_errors
from .linearisation import evaluate as evaluate, equations, prior_rows as _prior_rows
from ..stats.robust_scores import loss_threshold, robust_noise, robust_weights

if TYPE_CHECKING:
    from .._core import MeasurementSet
    from ..typing_ import BoolArray, FloatArray

#: joint_map's smoothness penalty: order k's sine and cosine amplitudes weigh sqrt(lambda s) k (the
#: penalty is lambda s / pi times the integral of the map's squared slope over a turn; s: the mean
#: squared norm of the joint's order-1 columns, so lambda is relative to what the data see); the
#: cross-validation chooses lambda among these, together with the order. A map the data see over
#: part of a turn only stays smooth there and small beyond.
MAP_SMOOTHING = (1e-1, 1e-2, 1e-3)
#: joint_map's variant (order, smoothing) is chosen leaving out each of this many ranges of its angle
VARIANT_BLOCKS = 5
#: the significance rule of a step (the diagnosis's): F-test p below ALPHA and a linear
#: cross-validated gain above MIN_GAIN
ALPHA, MIN_GAIN = 1e-6, 0.03


class Spec:
    """The model under test: its effects (joint_compliance per joint, or JointCompliance) and the fit's
    options (a FitOptions)."""

    def __init__(self, robot: Robot, effects: Sequence[Candidate] = (), penalties: Sequence[tuple[str, float]] = (),
                 fit: Optional[FitOptions] = None) -> None:
        self.robot = robot
        self.effects: list[Candidate] = list(effects)
        #: (parameter name, weight): ridge penalties of the fit
        self.penalties: list[tuple[str, float]] = list(penalties)
        self.fit_options = fit or FitOptions()

    def with_(self, cand: Candidate, penalties: Sequence[tuple[str, float]] = ()) -> Spec:
        return Spec(self.robot, self.effects + [cand], self.penalties + list(penalties), self.fit_options)

    def penalties_of(self, effect: Candidate) -> list[tuple[str, float]]:
        """The penalties on an effect's parameters."""
        names = {f"joint{effect.joint}.{n}" for n in getattr(effect, "parameter_names", ())}
        return [p for p in self.penalties if p[0] in names]

    def has(self, cand: Candidate) -> bool:
        return any(e.name == cand.name and e.joint == cand.joint for e in self.effects)

    @property
    def core_effects(self) -> list[_core.Effect]:
        return expand(self.effects, self.robot)[0]

    @property
    def gravity(self) -> str:
        return expand(self.effects, self.robot)[1] or self.fit_options.gravity

    @property
    def compliance(self) -> list[int]:
        return [e.joint for e in self.core_effects if e.kind.gravity_loaded_only]

    def label(self) -> str:
        return " + ".join(["geometry"] + [e.label for e in self.effects])

    def fit(self, data: MeasurementSet, covariance: bool = False) -> _core.IdentifyResult:
        eff, gravity = expand(self.effects, self.robot)
        return self.fit_options.fit(self.robot, data, eff, covariance=covariance, penalties=self.penalties,
                                    gravity=gravity)

    def errors(self, res: _core.IdentifyResult, data: MeasurementSet) -> FloatArray:
        return point_errors(res, data)


def fitted_compliance_columns(res: _core.IdentifyResult, data: MeasurementSet, spec: Spec) -> FloatArray:
    """The columns of JointCompliance("fit") for a model fitted without compliance (``res``, the model
    ``spec``): the model with it is fitted (its torques' mass moments with it), and its compliance
    columns are taken at that fit: each joint's deflection under the torques of the fitted moments.
    The deflection is bilinear in the compliances and the moments, so at the fit it lies in the span
    of these columns (the linearisation at zero moments sees no torque at all). Each column scaled to
    unit norm. (The calibrated model of that fit carries the fitted moments as its masses.)"""
    with_it = spec.with_(JointCompliance("fit")).fit(data)
    _, _, J, new, _ = evaluate(with_it, data, [])
    idx = [p.index for p in new if p.kind == "compliance"]
    R = J[:, idx]
    n = np.linalg.norm(R, axis=0)
    cols: FloatArray = R[:, n > 0] / n[n > 0]
    return cols


class _Linearised:
    """The model fitted on every point, linearised for the candidates: the residual r (dims n), the
    current model's free columns and each candidate's columns at the fit, from one evaluation of the
    identification Jacobian with every candidate's parameters appended (made on the first call); the
    residual as the pseudo-residual of the fit's robust loss (robust_weights). ``step(cand)``: the
    linearisation after a step taken without a refit."""

    def __init__(self, res: _core.IdentifyResult, data: MeasurementSet, candidates: Sequence[Candidate], robot: Robot,
                 dims: int, fit: FitOptions, spec: Optional[Spec] = None) -> None:
        self.res, self.data, self.robot, self.dims, self.fit, self.spec = res, data, robot, dims, fit, spec
        have = {(e.name, e.joint) for e in res.layout.effect_list}
        self.extra = [c for c in candidates if isinstance(c, _core.Effect) and not c.kind.gravity_loaded_only
                      and (c.name, c.joint) not in have]
        self.cols: Optional[dict[tuple[str, int, tuple[int, ...], str],
                                 tuple[FloatArray, FloatArray, FloatArray]]] = None
        self.added: list[FloatArray] = []  # the columns of the steps taken since the fit (unweighted)
        self.r_now: Optional[FloatArray] = None  # the residual after them (unweighted; None: the fit's)
        self.scale: Optional[float] = None  # where the candidates' scores bend (from the residual's spread)
        self.w: Optional[FloatArray] = None
        self._stacked: Optional[tuple[FloatArray, FloatArray]] = None  # (the fit's columns, them with the added ones)
        self.prior: Optional[tuple[FloatArray, FloatArray]] = None  # the priors' pseudo-rows (probe data)
        self._aug: Optional[tuple[FloatArray, FloatArray]] = None  # (current columns, them with the pseudo-rows)

    def raw(self, cand: Candidate) -> tuple[FloatArray, FloatArray, FloatArray]:
        """The unweighted residual, current columns and candidate columns at the fit."""
        if self.cols is None:
            self.r, self.cur, self.J, self.new, self.fit_of = evaluate(self.res, self.data, self.extra)
            self.prior = _prior_rows(self.res, self.data, self.fit_of)
            self.cols = {}
        key = (cand.name, cand.joint, tuple(cand.harmonics), getattr(cand, "gravity", ""))
        if key not in self.cols:
            if isinstance(cand, JointCompliance) and cand.gravity == "fit":
                spec = self.spec or Spec(self.robot, list(self.res.layout.effect_list), fit=self.fit)
                self.cols[key] = (self.r, self.cur, fitted_compliance_columns(self.res, self.data, spec))
                return self.cols[key]
            if (isinstance(cand, _core.Effect) and not cand.kind.gravity_loaded_only
                    and not any(cand == e for e in self.extra)):
                r, cur, J, new, fit_of = evaluate(self.res, self.data, [cand])  # not among the round's candidates
            else:
                r, cur, J, new, fit_of = self.r, self.cur, self.J, self.new, self.fit_of
            kind = "compliance" if cand.kind.gravity_loaded_only else cand.name
            idx = [p.index for p in new if p.kind == kind and (p.joint == cand.joint or isinstance(cand, JointCompliance))
                   and (kind == "compliance" or (p.index not in fit_of and p.effect == cand))]
            self.cols[key] = (r, cur, J[:, idx])
        return self.cols[key]

    def __call__(self, cand: Candidate) -> tuple[FloatArray, FloatArray, FloatArray]:
        r, cur, R = self.raw(cand)
        if self.r_now is not None:
            r = self.r_now
        if self.added:  # one array per linearisation: the search's basis of it is made once
            if self._stacked is None or self._stacked[0] is not cur:
                self._stacked = (cur, np.hstack([cur] + self.added))
            cur = self._stacked[1]
        if self.w is None:
            self.w = self._weights(r, cur.shape[1])
        return self._with_prior(r * self.w, cur, R)

    def _with_prior(self, r: FloatArray, cur: FloatArray, R: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray]:
        """r, the current columns and R with the priors' pseudo-rows after the data's (none unless
        _prior_rows gives them): the candidates scored on the fit's own maximum a posteriori problem."""
        if self.prior is None:
            return r, cur, R
        P, rp = self.prior
        if self._aug is None or self._aug[0] is not cur:  # one array per current columns: the search's basis made once
            Pc = np.hstack([P, np.zeros((len(P), cur.shape[1] - P.shape[1]))])  # the steps' added columns: no prior
            self._aug = (cur, np.vstack([cur, Pc]))
        return np.concatenate([r, rp]), self._aug[1], np.vstack([R, np.zeros((len(P), R.shape[1]))])

    def _weights(self, r: FloatArray, p: int) -> FloatArray:
        """The pseudo-residuals' weights of the residual r (p parameters fitted): the fit's loss, bending
        where the residual's own robust spread puts it (4.03 x; the fit's own bend, e.g. a fixed
        0.1 mm, would clip the very structure a candidate is to explain when the model lacks it)."""
        if self.scale is None:
            self.scale = loss_threshold(robust_noise(r, self.dims, p, equations(self.data)), self.dims)
        return robust_weights(r, self.dims, self.fit.loss, self.scale)

    def step(self, cand: Candidate) -> _Linearised:
        """The linearisation after ``cand`` was added without a refit: its columns join the model's,
        the residual is what their joint fit leaves (one reweighted Gauss-Newton step of the robust
        fit), and the robust loss's scale (when it comes from the data) and weights follow
        that residual, as the refit's would."""
        r, cur, R = self.raw(cand)
        r = r if self.r_now is None else self.r_now
        A = np.hstack([cur] + self.added + [R])
        w = self.w if self.w is not None else self._weights(r, cur.shape[1] + sum(a.shape[1] for a in self.added))
        sw = np.sqrt(w)  # iteratively reweighted least squares: the robust cost's Gauss-Newton step
        rw, Aw, _ = self._with_prior(r * sw, A * sw[:, None], R[:, :0])
        delta, *_ = np.linalg.lstsq(Aw, rw, rcond=None)
        out = _Linearised.__new__(_Linearised)
        out.__dict__.update(self.__dict__)
        out.added = self.added + [R]
        out._stacked = None
        out._aug = None
        out.r_now = r - A @ delta
        if self.prior is not None:  # the priors' pseudo-residuals after the step
            P, rp = self.prior
            out.prior = (P, rp - P @ delta[:P.shape[1]])
        out.scale = None  # from the new residual's spread, as the refit's would be
        out.w = None
        return out


class SerialProblem:
    """The search problem of a serial robot (stepwise.Problem): its measurements, folds of poses
    and the fitting options of every fit; ``fits``: every linearisation's fit, in order. ``dims``:
    residual coordinates per row (3; 6 with measured orientations)."""

    def __init__(self, robot: Robot, data: MeasurementSet, folds: list[BoolArray], fit: FitOptions,
                 candidates: Sequence[Candidate] = ()) -> None:
        self.robot, self.data, self.folds, self.fit_options = robot, data, folds, fit
        self.candidates = list(candidates)
        #: (name, joint, order) -> the penalties of the variant chosen
        self.penalty: dict[tuple[str, int, int], list[tuple[str, float]]] = {}
        #: joint -> the mean squared norm of its joint_map's order-1 columns (the smoothing's scale)
        self.map_scale: dict[int, float] = {}
        #: joint -> the refitted range-held-out RMS of each joint_map variant (refine())
        self.refined: dict[int, dict[str, Any]] = {}
        self.fits: list[tuple[list[Candidate], _core.IdentifyResult]] = []
        self.dims = 6 if data.abc is not None else 3
        self.point_dims = 3
        #: a residual below this (mm per coordinate) is the computation's, not the data's: noise-free data
        self.resolution = 1e-6
        self._loaded: Optional[int] = None  # how many compliances the model's masses let the core fit (size())

    def spec(self, effects: Sequence[Candidate]) -> Spec:
        pen = [p for e in effects for p in self.penalty.get((e.name, e.joint, e.order), [])]
        return Spec(self.robot, effects, pen, self.fit_options)

    def held_errors(self, effects: list[Candidate], held: BoolArray) -> FloatArray:
        spec = self.spec(effects)
        res = spec.fit(subset(self.data, ~held))
        return spec.errors(res, subset(self.data, held))

    def linearise(self, effects: list[Candidate]) -> _Linearised:
        spec = self.spec(effects)
        res = spec.fit(self.data)
        self.fits.append((list(effects), res))
        return _Linearised(res, self.data, self.candidates, self.robot, self.dims, self.fit_options, spec)

    def variants(self, cand: Candidate, R: FloatArray) -> Optional[list[tuple[_core.Effect, int, FloatArray]]]:
        """joint_map's orders 1..K (its columns R: sine and cosine of each order, in order), each with
        each smoothness penalty of MAP_SMOOTHING (the strongest first): (effect, columns, weights).
        The library's transmission_error is fitted as it always was, without a penalty."""
        if not cand.kind.ordered:
            return None
        s = float(np.mean(np.sum(R[:, :2] ** 2, axis=0)))
        self.map_scale[cand.joint] = s
        kw = np.repeat(np.asarray(cand.harmonics, dtype=float), 2)
        return [(_core.Effect("joint_map", cand.joint, order=k), 2 * k, np.sqrt(lam * s) * kw[:2 * k])
                for k in range(1, cand.order + 1) for lam in MAP_SMOOTHING]

    def refine(self, effects: Sequence[Candidate], cand: Candidate) -> Candidate:
        """A joint_map step's variant (order, smoothing), chosen on the linearisation, chosen again by
        refits: each variant of the map added to the model with ``effects`` is fitted holding out, in
        turn, each of VARIANT_BLOCKS ranges of the joint's angle and predicts it (every parameter
        refitted without it: on the linearisation the model's own parameters are fitted on every row,
        the held range included, and a map that only a refit of the geometry keeps in check there
        looks better than it predicts); the first variant listed within ORDER_MARGIN of the best held-out
        sum of squares. Orders the library's transmission_error covers on that joint are not offered
        (covered()); that transmission_error itself is, first (where the model lacks it; with its
        default harmonics 1 and 2, a map of order 2 or more contains it): a map is kept instead only
        when it lowers the held ranges' sum of squares by more than ORDER_MARGIN (1%) of the best's
        (on the linearisation a map of higher order gained a few tenths of a percent over the library's
        effect on data hiding that very effect, and was named in its place). Any other candidate is
        returned as it is."""
        if not cand.kind.ordered or cand.joint not in self.map_scale:
            return cand
        top = max([c.order for c in self.candidates if c.kind.ordered and c.joint == cand.joint] + [cand.order])
        s = self.map_scale[cand.joint]
        base = [p for e in effects for p in self.penalty.get((e.name, e.joint, e.order), [])]
        held_masks = self.variant_folds(cand)
        if any(h.all() or not h.any() for h in held_masks):  # the angle's ranges do not split the rows
            return cand
        offered: list[tuple[_core.Effect, list[tuple[str, float]], Optional[float]]] = [
            (c, [], None) for c in self.candidates
            if isinstance(c, _core.Effect) and c.kind.harmonic and not c.kind.ordered and c.joint == cand.joint
            and not any(e.name == c.name and e.joint == c.joint for e in effects)]
        for k in range(1, top + 1):
            e = _core.Effect("joint_map", cand.joint, order=k)
            if self.covered(e, self.candidates):
                continue
            w = np.repeat(np.asarray(e.harmonics, dtype=float), 2)
            names = [f"joint{cand.joint}.{n}" for n in e.parameter_names]
            for lam in MAP_SMOOTHING:
                offered.append((e, [(n, float(np.sqrt(lam * s) * x)) for n, x in zip(names, w)], lam))
        ss = []
        for e, pen, _ in offered:
            spec = Spec(self.robot, list(effects) + [e], base + pen, self.fit_options)
            total = 0.0
            for held in held_masks:
                total += float(np.sum(spec.errors(spec.fit(subset(self.data, ~held)), subset(self.data, held)) ** 2))
            ss.append(total)
        best = min(ss)
        i = next(j for j, v in enumerate(ss) if v <= best * (1.0 + engine.ORDER_MARGIN))
        e, pen, smoothing = offered[i]
        n = len(self.data.pose)
        self.refined[cand.joint] = {"order": e.order if e.kind.ordered else None, "smoothing": smoothing,
                                    "linear_order": cand.order,
                                    "range_refit_rms_mm": [[o.label if not o.kind.ordered else o.order, l,
                                                            float(np.sqrt(v / n))]
                                                           for (o, _, l), v in zip(offered, ss)]}
        if e.kind.ordered:
            self.penalty[(e.name, e.joint, e.order)] = pen
        return e

    def variant_folds(self, cand: Candidate) -> list[BoolArray]:
        """joint_map's order and smoothing are chosen holding out, in turn, each of VARIANT_BLOCKS
        contiguous ranges of the joint's angle (equal numbers of points):
        a map must predict angles it has not seen, as it will on the next campaign."""
        q = np.asarray(self.data.q_deg, dtype=float)[:, cand.joint - 1]
        edges = np.quantile(q, np.linspace(0.0, 1.0, VARIANT_BLOCKS + 1))
        block = np.clip(np.searchsorted(edges, q, side="right") - 1, 0, VARIANT_BLOCKS - 1)
        return [block == b for b in range(VARIANT_BLOCKS)]

    def size(self, effect: Candidate) -> int:
        """How many free parameters an effect adds (none of them with a prior by default): joint
        compliance with the model's masses on the joints these rows load (the core holds the compliance
        of a joint below its share min_torque_share of the largest gravity torque)."""
        if isinstance(effect, JointCompliance):
            layout = _core.PointModel(self.robot, 1, fit_gravity=effect.gravity == "fit").layout
            if effect.gravity == "masses":
                if self._loaded is None:
                    self._loaded = len(loaded_joints(self.robot, self.data.q_deg, layout.loaded))
                return self._loaded
            return sum(p.kind in ("compliance", "gravity_moment") for p in layout.parameters)
        return int(effect.size)

    def admits(self, effects: Sequence[Candidate], cand: Candidate) -> bool:
        """Whether the core fits the model with ``cand`` added, by its rule for a fit with priors
        (fit_setup's free_parameters: no more free parameters without a prior, frames held as unseen
        included, than the data have rows): the starting fit's and every added effect's. Without any
        prior the core counts equations against every free parameter instead, and this rule is the
        stricter of the two."""
        if not self.fits:
            return True
        start_effects, res = self.fits[0]
        free = np.asarray(res.fixed) == 0
        unconstrained = int(np.sum(free & ~np.isfinite(np.asarray(res.prior_sd)))) + int(np.sum(res.held_unseen))
        added = sum(self.size(e) for e in list(effects)[len(start_effects):]) + self.size(cand)
        return unconstrained + added <= len(self.data.pose)

    def score_folds(self, cand: Candidate) -> Optional[list[BoolArray]]:
        """The folds on which a candidate must also gain (besides the configurations'): for a periodic
        error of a joint angle (transmission_error, joint_map), holding out in turn each of
        VARIANT_BLOCKS ranges of that angle. Such an effect must predict angles it has not seen, as on
        the next campaign: a sinusoid fitted over part of a turn that only mimics another effect there
        (the gravity's) is not kept for the turn."""
        return self.variant_folds(cand) if cand.kind.harmonic else None

    def variant_evidence(self, cand: Candidate, i: int, gains: Sequence[float]) -> dict[str, Any]:
        """A joint_map step's evidence: the order and smoothing chosen, and the best gain of each order
        1..MAX_MAP_ORDER held out by ranges of the joint's angle. Where refine() kept the library's
        transmission_error over the map: the map's order on the linearisation (``over_map_order``)
        and every variant's RMS on the held ranges (``range_refit_rms_mm``: [variant, smoothing, mm],
        the library effect's variant its label)."""
        g = np.asarray(gains).reshape(-1, len(MAP_SMOOTHING))
        ref = self.refined.get(cand.joint)
        if not cand.kind.ordered and ref and ref["order"] is None:  # refine() kept the library's effect
            return {"over_map_order": ref["linear_order"], "range_refit_rms_mm": ref["range_refit_rms_mm"]}
        out: dict[str, Any] = {"smoothing": MAP_SMOOTHING[i % len(MAP_SMOOTHING)]}
        if cand.kind.ordered:
            out["order"] = cand.order
            out["order_range_cv_gain"] = [round(float(x), 6) for x in g.max(axis=1)]
            if ref and ref["order"] == cand.order:  # chosen again by refits (refine())
                out.update(smoothing=ref["smoothing"], linear_order=ref["linear_order"],
                           linear_smoothing=out["smoothing"], range_refit_rms_mm=ref["range_refit_rms_mm"])
        return out

    def chosen(self, cand: _core.Effect, ridge: FloatArray) -> None:
        """The variant chosen for a candidate: its fits carry that penalty (weights in mm per rad)."""
        names = [f"joint{cand.joint}.{n}" for n in cand.parameter_names]
        self.penalty[(cand.name, cand.joint, cand.order)] = [(n, float(w)) for n, w in zip(names, ridge)]

    def covered(self, cand: Candidate, candidates: Sequence[Candidate]) -> bool:
        """A joint_map of order 1 or 2 is the library's transmission_error (orders 1, 2) where that is a
        candidate on the same joint: the library's name is kept."""
        return cand.kind.ordered and cand.order <= 2 and any(
            c.kind.harmonic and not c.kind.ordered and c.joint == cand.joint and set(range(1, cand.order + 1)) <= set(c.harmonics)
            for c in candidates)

    def describe(self, effect: Candidate) -> dict[str, Any]:
        d: dict[str, Any] = {"effect": effect.name, "joint": effect.joint if effect.joint > 0 else None}
        if effect.kind.ordered:
            d["order"] = effect.order
        if isinstance(effect, JointCompliance):
            d["gravity"] = effect.gravity
        return d

    def label(self, effect: Candidate) -> str:
        return effect.label

    def model_label(self, effects: list[Candidate]) -> str:
        return self.spec(effects).label()


@dataclass
class Choice:
    """What a choice of effects found on one data set: the effects (the starting ones and those
    kept), the search (stepwise.Search), the candidates and the notes on those skipped, and the model
    with the effects fitted on that data set (``fit``, an IdentifyResult; ``spec``: its Spec)."""
    effects: list[Candidate]
    search: engine.Search[Candidate]
    candidates: list[Candidate]
    notes: list[str]
    spec: Spec
    fit: Optional[_core.IdentifyResult]
    problem: Optional[SerialProblem] = field(repr=False, default=None)


def choose(robot: Robot, data: MeasurementSet, fit: FitOptions, *, start: Sequence[Candidate] = (), k_folds: int = 5,
           seed: int = 0, max_steps: int = 6, say: Callable[[str], None] = lambda s: None,
           fit_chosen: bool = True) -> Choice:
    """`--effects auto` on one data set: the stepwise search over the candidates from the
    ``start`` effects (the significance rule of the diagnosis: ALPHA, MIN_GAIN, on ``k_folds`` folds
    of whole configurations), the starting model fitted once and each step's effect added to its
    linearisation (stepwise.search's refit=False); then, with ``fit_chosen``, the model chosen
    fitted on the data (``fit``; else None when a step was taken)."""
    cands, notes = candidates(robot, data, start, fit.gravity)
    problem = SerialProblem(robot, data, grouped_folds(data, k_folds, seed), fit, cands)
    if not problem.folds:
        spec = problem.spec(list(start))
        return Choice(list(start), engine.Search(list(start), [], [], None, []), cands,
                      notes + ["too few configurations to choose effects: the starting model kept"], spec,
                      spec.fit(data), problem)
    found = engine.search(problem, start, cands, alpha=ALPHA, min_gain=MIN_GAIN, max_steps=max_steps, say=say,
                          confirm=False, listed=len(cands), refit=False)
    spec = problem.spec(found.effects)
    res: Optional[_core.IdentifyResult]
    if isinstance(found.linearised, _Linearised):  # no step taken: the starting fit is the model's
        res = found.linearised.res
    else:
        res = spec.fit(data) if fit_chosen else None
    return Choice(found.effects, found, cands, notes, spec, res, problem)


def start_fit(choice: Choice) -> _core.IdentifyResult:
    """The starting model fitted on the choice's data (the first linearisation's fit; a choice made
    without a search carries its fit)."""
    if choice.problem and choice.problem.fits:
        return choice.problem.fits[0][1]
    assert choice.fit is not None, "a choice without a search carries its fit"
    return choice.fit
