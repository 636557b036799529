"""Measurement campaigns and parameter identification (the Samak paper's calibration step 3).

A measurement set is a ``kincal.MeasurementSet``: the rows of the contract's measurement CSV as read-only
columns (``pose``, ``q_deg``, ``xyz``, ``target``, ``payload_kg``, ``line``, ``source``; optional
``temperature_c``, ``dir``, ``abc``, ``time_s``, ``config``/``setup`` int64 codes with
``config_names``/``setup_names``, None when absent); the package's functions take one
(``kincal.MeasurementSet(columns)`` makes one from a dict). The
heavy work (residuals, analytic Jacobian, Ceres) runs in the C++ core.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass, field, replace
from typing import TYPE_CHECKING, Any, Callable, Iterable, Optional, Sequence, Union

import numpy as np

from .. import _core
from . import effect_choice, gravity as _gravity, priors
from ..stats import grouping
from ..io import strict_json
from .._core import Robot
from .choice_report import choice_lines, choice_report
from .tool_frame import tcp_summary_line, tool_from_targets as place
from .effect_choice import Candidate, applicable_joints, check_data as check_data_for
from ..stats.grouping import subset
from .fitting import DEFAULT_LOSS_SCALE_MM, FitOptions, orientation_errors_deg, point_errors, rms
from .setups import _refit_placements, drift_report, setup_frames
# the names kincal.identify had before the calibration package, re-exported (`X as X`: explicitly, for mypy)
from .fitting import options as options
from .setups import (validate as validate, validation_figures as validation_figures,
                     validation_summary as validation_summary)
from .simulation import (DEFAULT_HARMONICS as DEFAULT_HARMONICS, DEFAULT_INSTRUMENT as DEFAULT_INSTRUMENT,
                         DEFAULT_TARGETS as DEFAULT_TARGETS,
                         default_truth as default_truth, parse_hidden_effect as parse_hidden_effect,
                         simulate as simulate)

if TYPE_CHECKING:
    from .._core import Loss, MeasurementSet
    from ..typing_ import BoolArray, FloatArray

#: order of a joint_map named without one (--effects joint_map:J; joint_map:J:K gives K)
DEFAULT_MAP_ORDER = 4
#: folds of whole configurations on which `--effects auto` scores its candidates (inside each training set)
CHOICE_FOLDS = 5


def parse_effects(text: str, robot: Robot, harmonics: Sequence[int] = DEFAULT_HARMONICS,
                  option: str = "--effects") -> list[_core.Effect]:
    """The effects of ``--effects``: comma separated ``NAME`` (every joint where it applies: joint
    compliance only on the gravity-loaded joints) or ``NAME:J`` (joint J, from 1); ``joint_map:J:K``
    gives joint_map's order K (default DEFAULT_MAP_ORDER); ``none`` or an empty text is the geometry
    alone. ``harmonics``: transmission_error's orders. Errors name the bad item and what the registry
    knows."""
    items = [t.strip() for t in (text or "").split(",") if t.strip()]
    if items == ["none"]:
        return []
    serial = [k for k in _core.effect_kinds() if k.domain == "serial"]
    known = ", ".join(k.name for k in serial)
    out: list[_core.Effect] = []
    for item in items:
        name, _, joint = item.partition(":")
        name = name.strip()
        kind = next((k for k in _core.effect_kinds() if k.name == name), None)
        if kind is None:
            raise ValueError(f"{option}: unknown effect '{item}' (known: {known})")
        order = DEFAULT_MAP_ORDER
        if kind.ordered and ":" in joint:
            joint, _, k = joint.partition(":")
            try:
                order = int(k)
            except ValueError:
                raise ValueError(f"{option}: '{item}': {name}'s order must be a number 1..64") from None
        if kind.domain != "serial":
            raise ValueError(f"{option}: '{item}': {name} belongs to the {kind.domain} robot, not to a serial "
                             f"robot (known here: {known})")
        if joint.strip():
            if kind.concerns != "joint":
                raise ValueError(f"{option}: '{item}': {name} concerns the whole robot, not one joint "
                                 f"(write {name})")
            try:
                j = int(joint)
            except ValueError:
                raise ValueError(f"{option}: '{item}': the joint must be a number 1..{robot.dof}") from None
            if not 1 <= j <= robot.dof:
                raise ValueError(f"{option}: '{item}': joint {j} is not one of 1..{robot.dof}")
            if kind.gravity_loaded_only and j not in applicable_joints(robot, kind):
                raise ValueError(f"{option}: '{item}': gravity does not load joint {j} of {robot.name} "
                                 f"(loaded: {', '.join(map(str, applicable_joints(robot, kind)))})")
            joints = [j]
        else:
            joints = applicable_joints(robot, kind) if kind.concerns == "joint" else [0]
        for j in joints:
            try:
                e = (_core.Effect(name, j, order=order) if kind.ordered
                     else _core.Effect(name, j, list(harmonics)))
                e.check(robot.dof)
            except ValueError as err:
                raise ValueError(f"{option}: '{item}': {err}") from None
            if e not in out:
                out.append(e)
    return out


def read_measurements(path: str, robot: Robot, artifact: str | None = None) -> MeasurementSet:
    """The measurement CSV of the contract (errors name file:line and cause), with the known distances
    and angles between its probe stations from an artifact file."""
    data = _core.read_measurements(str(path), robot.dof, robot)  # the controller's joint numbers converted
    return _core.read_artifact(str(artifact), data, robot.dof) if artifact else data


def measurements_csv(data: MeasurementSet, dof: int) -> str:
    return _core.format_measurements(data, dof)


def split_poses(data: MeasurementSet, holdout: float, seed: int = 0) -> tuple[BoolArray, BoolArray]:
    """Row masks (fit, held out): a share of the configurations held out whole (grouping.split)."""
    return grouping.split(data, holdout, seed)


def folds(data: MeasurementSet, k: int, seed: int = 0) -> list[BoolArray]:
    """k masks of held-out rows, whole configurations per fold (grouping.folds)."""
    return grouping.folds(data, k, seed)


def _figures(e: FloatArray, when: str, unit: str) -> dict[str, float]:
    """RMS, mean (the Samak paper's figure) and max of errors: {when}_rms_{unit}, ..."""
    return {f"{when}_rms_{unit}": rms(e), f"{when}_mean_{unit}": float(np.mean(e)), f"{when}_max_{unit}": float(np.max(e))}


@dataclass
class Identification:
    """What `kincal identify` found: the calibrated robot (with its identified effects), targets, the
    core's result (``fit``: an IdentifyResult) and the validation. ``effects``: the effects asked for."""
    robot: Robot
    targets: FloatArray
    fit: _core.IdentifyResult
    effects: list[_core.Effect]
    validation: dict[str, Any] = field(default_factory=dict)
    fit_info: dict[str, Any] = field(default_factory=dict)  #: priors.report(): the priors and the loss
    #: priors.down_weighted(): the most down-weighted rows
    worst: list[tuple[int, int, float, float]] = field(default_factory=list)

    def parameters(self) -> list[dict[str, Any]]:
        """Every parameter of the fit in the model file's units (angles in degrees: the core's radians
        converted), with its standard deviation, prior and why it was held, if it was."""
        f = self.fit

        scale = priors.file_unit

        return [{"name": p.name, "kind": p.kind, "joint": p.joint or None, "unit": scale(p.unit)[1],
                 "value": float(v) * scale(p.unit)[0],
                 "stddev": (None if math.isnan(s) else float(s) * scale(p.unit)[0]), "fixed": bool(fx), "reason": r,
                 "at_prior": bool(ap), "prior_sd": (float(ps) * scale(p.unit)[0] if math.isfinite(ps) else None)}
                for p, v, s, fx, r, ap, ps in zip(f.layout.parameters, f.x, f.stddev, f.fixed, f.fixed_reason,
                                                  f.at_prior, f.prior_sd)]

    def effect_labels(self) -> list[str]:
        return [e.label for e in self.effects]

    def model_json(self) -> str:
        d = json.loads(self.robot.to_json())
        f = self.fit
        d["identification"] = {
            "effects": self.effect_labels(),
            "targets_mm": np.asarray(self.targets).tolist(),
            "parameters": self.parameters(),
            "condition_number": f.condition_number,
            "observability_index": f.observability_index,
            "correlations": [{"a": a, "b": b, "r": r} for a, b, r in f.correlations],
            "iterations": f.iterations, "converged": bool(f.converged), "stop_reason": f.stop_reason,
            "gravity": _gravity.report(f),
            "fit": {"rows": int(self.validation.get("fit_rows", 0)), "rms_mm": f.rms_mm, "max_mm": f.max_mm,
                    "nominal_rms_mm": f.nominal_rms_mm, "nominal_max_mm": f.nominal_max_mm},
            "validation": self.validation,
            **self.fit_info,
        }
        if f.layout.n_setups > 1:
            d["identification"]["setups"] = setup_frames(f.setups)
        drift = drift_report(f)
        if drift:
            d["identification"]["drift"] = drift
        return strict_json.dumps(d, indent=1, sort_keys=True) + "\n"

    def summary(self) -> str:
        f, v = self.fit, self.validation
        lines = [f"identified {int(np.sum(~np.asarray(f.fixed)))} of {f.layout.size} parameters "
                 f"({', '.join(['geometry'] + self.effect_labels())}) in {f.iterations} iterations",
                 _gravity.summary_line(f), ""]
        if not f.converged:  # the parameters are where the solver stopped, not a least-squares optimum
            lines[1:1] = [f"did not converge: {f.stop_reason}. The parameters are where the solver stopped, not "
                          "the best fit: check the held-out figures against the geometry alone, and measure more "
                          "configurations, identify fewer effects (--effects) or raise the iteration cap "
                          "(--max-iterations)"]
        lines.append(f"{'position error (mm)':<28}{'RMS before':>12}{'RMS after':>12}{'mean before':>12}"
                     f"{'mean after':>12}{'max before':>12}{'max after':>12}")
        lines.append(f"{'fitted poses':<28}{f.nominal_rms_mm:>12.4f}{f.rms_mm:>12.4f}{'-':>12}{'-':>12}"
                     f"{f.nominal_max_mm:>12.4f}{f.max_mm:>12.4f}")
        for unit, label in (("mm", "held-out poses"), ("deg", "orientation (deg), held out")):
            if f"after_rms_{unit}" in v:
                lines.append(f"{label:<28}" + "".join(f"{v[f'{w}_{s}_{unit}']:>12.4f}" for s in ("rms", "mean", "max")
                                                      for w in ("before", "after")))
        if v.get("held_rows"):
            lines.append(f"held out: {v['scheme']} ({v['configurations']} configurations: {v['grouping']})")
        if "model_rows" in v:
            lines.append(f"model fitted on {v['fit_rows']} rows: {v['model_rows']}")
        lines.append("")
        if f.layout.n_setups > 1:
            lines.append(f"{f.layout.n_setups} instrument placements (base frame seen from the instrument; fk and "
                         f"compensate --frame instrument use the first):")
            for st in setup_frames(f.setups):
                b = st["base_in_instrument"]
                lines.append(f"  {st['name']:<12} xyz {' '.join(f'{v:.3f}' for v in b['xyz_mm'])} mm, "
                             f"abc {' '.join(f'{v:.4f}' for v in b['abc_deg'])} deg")
        drift = drift_report(f)
        if drift:
            rates = ", ".join("{} {:+.4g} {}".format(x["name"], x["value"], x["unit"]) for x in drift["parameters"])
            lines.append(f"instrument drift about t = {drift['t_mean_s']:.0f} s (removed from the fit, never "
                         f"compensated): {rates}")
        ranges = self.robot.fitted_ranges_deg
        periodic = sorted({e.joint for e, _ in self.robot.effects if e.kind.harmonic})
        if ranges and periodic:
            lines.append("periodic effects known over the fitted angles (validate and compensate warn beyond them): " +
                         ", ".join(f"joint {j} {ranges[j - 1][0]:.0f}..{ranges[j - 1][1]:.0f} deg" for j in periodic))
        lines.append(f"condition number {f.condition_number:.4g}, observability index {f.observability_index:.4g}"
                     " (what the data determine)")
        if not f.scale_determined:
            lines.append("scale: not determined by these data (spheres and planes see no length), held at its prior; "
                         "add a known length with --artifact (a length bar, a ball plate, a block's edge)")
        lines += tcp_summary_line(self.robot)
        if self.fit_info:
            lines += priors.summary_lines(f, self.fit_info, self.worst)
        if "effect_choice" in self.fit_info:
            lines += choice_lines(self.fit_info["effect_choice"])
        fixed = [(p.name, why) for p, fx, why in zip(f.layout.parameters, f.fixed, f.fixed_reason) if fx]
        if fixed:
            lines.append("held at their start value:")
            for n, why in fixed:
                lines.append(f"  {n:<22} {why}")
        if f.correlations:
            lines.append("strong correlations:")
            for a, b, r in f.correlations[:20]:
                lines.append(f"  {a:<22} {b:<22} {r:+.3f}")
        lines.append("parameters (value +- standard deviation):")
        for p in self.parameters():
            if not p["fixed"]:
                sd = "" if p["stddev"] is None else f" +- {p['stddev']:.3g}"
                lines.append(f"  {p['name']:<22} {p['value']:+.6g}{sd} {p['unit']}")
        return "\n".join(lines)


def check_effects(effects: Union[str, Iterable[Union[str, Candidate]]], robot: Robot,
                  harmonics: Sequence[int] = DEFAULT_HARMONICS) -> list[Candidate]:
    """Effects as _core.Effect: a text of --effects, or a list of Effect objects and/or texts
    (``NAME`` or ``NAME:J``), checked against the registry and the robot."""
    if isinstance(effects, str):
        return list(parse_effects(effects, robot, harmonics))
    out: list[Candidate] = []
    for e in effects:
        if isinstance(e, effect_choice.JointCompliance):
            out.append(e)
            continue
        for x in ([e] if isinstance(e, _core.Effect) else parse_effects(str(e), robot, harmonics)):
            x.check(robot.dof)
            if x not in out:
                out.append(x)
    return out


def _errors(r: _core.IdentifyResult, h: MeasurementSet) -> dict[str, FloatArray]:
    """Position (and, with measured orientations, orientation) errors of the rows h: before (the
    nominal geometry, frames fitted) and after (the identified model r)."""
    out = {"ea": _core.point_errors(r.robot, r.targets, h, r.stations),
           "eb": _core.point_errors(r.nominal_fitted, r.nominal_targets, h, r.nominal_stations)}
    if h.abc is not None:  # the 6-D rows only (a mixed file's reflector rows have none)
        oa = orientation_errors_deg(r.robot, h)
        if len(oa):
            out.update(oa=oa, ob=orientation_errors_deg(r.nominal_fitted, h))
    return out


#: a training set's model: the model fitted on it and its effect choice (None: the effects were given)
ModelOf = Callable[["MeasurementSet"], "tuple[_core.IdentifyResult, Optional[effect_choice.Choice]]"]
#: the errors of a setup held out whole, on the model fitted on the others (_setup_refit)
SetupRefit = Callable[[Robot, "MeasurementSet"], "dict[str, FloatArray]"]


def _fold_errors(model_of: ModelOf, data: MeasurementSet, held_masks: Sequence[BoolArray],
                 progress: Optional[Callable[[int, int], None]], refit: Optional[SetupRefit] = None
                 ) -> tuple[dict[str, FloatArray], list[Optional[effect_choice.Choice]]]:
    """_errors of every held-out row, each fold predicted by the model fitted without it
    (``model_of(train)``: (result, choice or None)); with ``refit`` (a setup held out whole) the held
    rows' placement and targets are refitted on them first. Returns the errors and each fold's
    choice."""
    parts: list[dict[str, FloatArray]] = []
    choices: list[Optional[effect_choice.Choice]] = []
    for i, held in enumerate(held_masks):
        if progress:
            progress(i, len(held_masks))
        try:
            model, choice = model_of(subset(data, ~held))
        except ValueError as e:  # the core names the data's source and the fold's rows: say they are a fold's
            raise ValueError(f"cross-validation fold {i + 1} of {len(held_masks)} (the model fitted without "
                             f"{int(np.sum(held))} held-out rows): {e}") from None
        choices.append(choice)
        if refit is not None:
            parts.append(refit(model.robot, subset(data, held)))
            continue
        part = _errors(model, subset(data, held))
        if choice is not None:  # the starting model fitted on the same rows: its held-out figure, for free
            part["e0"] = point_errors(effect_choice.start_fit(choice), subset(data, held))
        parts.append(part)
    keys = dict.fromkeys(k for p in parts for k in p)  # a fold of reflector rows only has no orientation
    return {k: np.concatenate([p[k] for p in parts if k in p]) for k in keys}, choices


def _setup_refit(loss: Loss, loss_scale_mm: float) -> SetupRefit:
    """The errors of a setup held out whole: its placement and targets refitted on its rows
    (validate()'s refit) on the model fitted on the other setups."""
    def refit(robot: Robot, held: MeasurementSet) -> dict[str, FloatArray]:
        ea, eb, oa, ob, _ = _refit_placements(robot, held, loss, loss_scale_mm)
        out = {"ea": ea, "eb": eb}
        if oa is not None and ob is not None:  # measured orientations: both, or neither
            out.update(oa=oa, ob=ob)
        return out
    return refit


def _fit_options(fit: Optional[FitOptions], **kw: Any) -> FitOptions:
    """The fitting options: ``fit`` when given, else made of identify()'s keywords (prior_scale
    "auto" or None: chosen by grouped cross-validation)."""
    if fit is not None:
        return fit
    scale = kw.pop("prior_scale")
    kw["prior_scale"] = None if scale is None or scale == "auto" else float(scale)
    return FitOptions(**kw)


def _validation_scheme(data: MeasurementSet, fit: FitOptions, *, hold_out_setups: bool, holdout: Optional[float],
                       k_folds: int, seed: int
                       ) -> tuple[BoolArray, list[BoolArray], dict[str, Any], Optional[SetupRefit]]:
    """How identify() validates: the rows its model is fitted on, the held-out masks (each setup
    whole, a split of the configurations, or k folds of them; none), the validation's description
    and, for whole setups, the refit of a held setup's placement and targets."""
    every_row = np.ones(len(data.pose), dtype=bool)
    refit: Optional[SetupRefit] = None
    val: dict[str, Any]
    if hold_out_setups:
        codes = np.asarray(data.setup) if data.setup is not None else np.zeros(len(data), dtype=np.int64)
        if len(np.unique(codes)) < 2:
            raise ValueError("holding out whole setups needs a setup column with at least two setups")
        fit_mask, masks = every_row, [codes == c for c in np.unique(codes)]
        val = {"scheme": f"each of the {len(masks)} setups held out whole (its placement and targets refitted)",
               "grouping": "setup column", "configurations": int(grouping.configurations(data).count),
               "held_rows": int(len(codes)), "model_rows": "every row (validated by holding out setups)"}
        refit = _setup_refit(fit.loss, fit.loss_scale_mm or 0.0)
    elif holdout is not None:
        fit_mask, held = split_poses(data, holdout, seed)
        val = dict(grouping.describe(data, f"{holdout:.0%} held out"), held_rows=int(held.sum()),
                   model_rows="the fitted rows only: the model excludes the held-out rows")
        masks = [held]
    elif k_folds > 1:
        fit_mask, masks = every_row, folds(data, k_folds, seed)
        val = dict(grouping.describe(data, f"{k_folds}-fold"),
                   held_rows=int(len(data.pose)), model_rows="every row (validated by cross-validation)")
    else:
        fit_mask, masks = every_row, []
        val = {"scheme": "none", "held_rows": 0, "model_rows": "every row (not validated)"}
    return fit_mask, masks, val, refit


def identify(robot: Robot, data: MeasurementSet, *, effects: Union[str, Sequence[Union[str, Candidate]]] = "auto",
             fit: Optional[FitOptions] = None, loss: str = "huber",
             loss_scale_mm: Optional[float] = DEFAULT_LOSS_SCALE_MM, prior_sd: Optional[dict[str, float]] = None,
             prior_scale: Union[float, str, None] = 1.0,
             prior_model: Optional[Robot] = None, holdout: Optional[float] = None, k_folds: int = 5, seed: int = 0,
             progress: Optional[Callable[[int, float], None]] = None,
             orientation_weight: float = 100.0, harmonics: Sequence[int] = DEFAULT_HARMONICS,
             fold_progress: Optional[Callable[[int, int], None]] = None,
             penalties: Sequence[tuple[str, float]] = (), hold_out_setups: bool = False, gravity: str = "auto",
             max_iterations: int = 100, say: Optional[Callable[[str], None]] = None) -> Identification:
    """Identify the robot's parameters from measurements.

    ``fit``: the fitting options (kincal.fitting.FitOptions: priors, robust loss, gravity, orientation
    weight, iteration cap), shared with `kincal diagnose`; without it they are made of the keywords:
    ``loss_scale_mm``: where the robust loss bends (mm; None or 0, the default: from the residuals'
    robust spread);
    ``prior_sd``: prior standard deviations by kind in file units (None: priors.DEFAULT_PRIOR_SD; {}:
    no priors), times ``prior_scale`` ("auto" or None: chosen by grouped cross-validation inside
    each training set), centred on ``prior_model``'s calibrated geometry when given (e.g. last
    year's calibration), else on the nominal model.

    ``effects``: "auto" (the default: the data choose, see kincal.effect_choice: every library effect
    that applies is tried from the geometry and kept only when the diagnosis's significance rule
    says so; the choice made again inside each training fold of the validation, so that its figure
    does not favour the choice), or what the model carries besides the geometry: _core.Effect
    objects or texts of ``--effects`` (``"joint_compliance"``, ``"transmission_error:3"``,
    ``"backlash:2"``, ``"thermal_expansion"``, or one comma-separated text; ``"none"``: the geometry).

    The model returned is fitted on every row. Its validation figures come from ``k_folds``-fold
    cross-validation (whole configurations per fold; 0: no validation). With ``holdout`` (a share in
    (0, 1)) a random share of the configurations is held out instead, and the model then excludes
    those rows (the validation says so). ``fold_progress(fold, folds)`` reports each validation fit.
    ``penalties``: ridge penalties (parameter name, weight in mm per unit of the parameter).
    ``hold_out_setups``: the validation holds out each setup (instrument placement) whole instead:
    the model fitted on the other setups, the held setup's placement and targets refitted on it as
    validate() does. ``max_iterations``: each Levenberg-Marquardt pass's cap (the result says whether it
    converged)."""
    fit = _fit_options(fit, loss=loss, loss_scale_mm=loss_scale_mm, prior_sd=prior_sd, prior_scale=prior_scale,
                       prior_model=prior_model, gravity=gravity, orientation_weight=orientation_weight,
                       max_iterations=max_iterations)
    auto = isinstance(effects, str) and effects.strip() == "auto"
    effects = [] if auto else check_effects(effects, robot, harmonics)
    check_data_for(effects, data, robot)
    if k_folds == 1 or k_folds < 0:
        raise ValueError(f"--folds must be 0 (no validation) or at least 2, not {k_folds}")
    if holdout is not None and not 0.0 <= holdout < 1.0:
        raise ValueError(f"--holdout must be a share in (0, 1), not {holdout}")
    holdout = holdout or None  # a share of 0 holds nothing out
    core_effects, gravity_of = effect_choice.expand(effects, robot)

    def model_of(train: MeasurementSet) -> tuple[_core.IdentifyResult, Optional[effect_choice.Choice]]:
        """The model of a training set: its effects chosen on it (auto), then fitted on it."""
        if auto:
            ch = effect_choice.choose(robot, train, fit, k_folds=CHOICE_FOLDS, seed=seed)
            assert ch.fit is not None  # fit_chosen: the model chosen is fitted
            return ch.fit, ch
        return fit.fit(robot, train, core_effects, penalties=penalties, gravity=gravity_of, seed=seed), None

    fit_mask, masks, val, refit = _validation_scheme(data, fit, hold_out_setups=hold_out_setups, holdout=holdout,
                                                     k_folds=k_folds, seed=seed)
    # folds: each predicted by a model fitted (its effects chosen) without it; a split: by the delivered model
    e: dict[str, FloatArray] = {}
    fold_choices: list[Optional[effect_choice.Choice]] = []
    if masks and holdout is None:
        e, fold_choices = _fold_errors(model_of, data, masks, fold_progress, refit)
    train = subset(data, fit_mask)
    top = None
    if auto:
        if say:
            say("choosing the effects (--effects auto)")
        top = effect_choice.choose(robot, train, fit, k_folds=CHOICE_FOLDS, seed=seed, fit_chosen=False)
        effects = top.spec.effects
        core_effects, gravity_of = effect_choice.expand(effects, robot)
        penalties = list(penalties) + top.spec.penalties
    fitter = fit.fitter(robot, seed)
    r = fitter(train, fit.core(core_effects, covariance=True, penalties=penalties, gravity=gravity_of), progress)
    if holdout is not None and val["held_rows"]:
        e = _errors(r, subset(data, ~fit_mask))
        if top is not None:
            e["e0"] = point_errors(effect_choice.start_fit(top), subset(data, ~fit_mask))
    if e:
        val.update(_figures(e["eb"], "before", "mm"), **_figures(e["ea"], "after", "mm"))
        if "oa" in e:
            val.update(_figures(e["ob"], "before", "deg"), **_figures(e["oa"], "after", "deg"))
    val["fit_rows"] = int(fit_mask.sum())
    choice = (f"{fitter.scales[0]:g} (chosen by grouped cross-validation)" if fitter.scales else
              f"{fit.core().prior_scale:g}")
    info = priors.report(r, fit.loss, fit.loss_scale_mm, choice)
    info["priors"]["centred_on"] = "the prior model's calibrated geometry" if fit.prior_model else "the starting model"
    if top is not None:
        info["effect_choice"] = choice_report(top, fold_choices, e, val, CHOICE_FOLDS)
    # the model records the angles its fit saw: where its periodic effects were measured
    calibrated = r.robot.with_fitted_ranges(_core.joint_ranges(data.q_deg[fit_mask]))
    return Identification(robot=calibrated, targets=np.asarray(r.targets), fit=r, effects=list(core_effects),
                          validation=val, fit_info=info, worst=priors.down_weighted(r, train))


def tool_from_targets(result: Identification, known: FloatArray) -> Identification:
    """The tool frame placed from known target offsets (tool_frame.tool_from_targets); the known
    offsets become the targets."""
    known = np.asarray(known, dtype=float).reshape(-1, 3)
    return replace(result, robot=place(result.robot, result.targets, known), targets=known.copy())
