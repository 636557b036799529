"""The diagnosis of a serial robot (`kincal diagnose --robot R`): the stepwise search over the
candidate effects of kincal.effect_choice (those `identify --effects auto` chooses from, with the
same rule; here every step refitted and confirmed), with identify's fitting options in every fit;
then what the final
model still misses against every candidate variable (residual_vars), and the final model identified
on all the data (the command's files: workflow.py).
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any, Callable, Optional, Sequence, Union

import numpy as np

from .. import _core
from ..stats import grouping
from ..calibration import identify as ident
from ..stats import stepwise as engine
from .._core import Robot
from ..calibration.effect_choice import (ALPHA, MAX_MAP_ORDER, MIN_GAIN, JointCompliance,  # noqa: F401
                                         Candidate, SerialProblem, Spec, candidates, check_data, evaluate)
from ..calibration.fitting import FitOptions
from . import residual_vars

if TYPE_CHECKING:
    from .._core import MeasurementSet
    from ..typing_ import FloatArray

__all__ = ["JointCompliance", "SerialProblem", "Spec", "candidates", "diagnose", "final_identification", "step_effect"]

def diagnose(robot: Robot, data: MeasurementSet, *, folds: int = 5, alpha: float = ALPHA, min_gain: float = MIN_GAIN,
             max_steps: int = 6, seed: int = 0, noise_mm: Optional[float] = None,
             progress: Optional[Callable[[str], None]] = None,
             effects: Union[str, Sequence[Union[str, Candidate]]] = (),
             fit: Optional[FitOptions] = None, **fit_options: Any) -> dict[str, Any]:
    """The workflow (stepwise.search, then stepwise.conclude); returns the diagnosis.json of the
    contract (plus details for the report).

    ``effects``: the model the diagnosis starts from besides the geometry (Effect objects or texts of
    ``--effects``); they are no candidates. ``fit``: the fitting options of every fit (identify's:
    priors, robust loss, gravity, ...; or as keywords of FitOptions). ``noise_mm``: the
    instrument's noise per coordinate, if known (see stepwise.conclude).

    The candidates and the rule are those `kincal identify --effects auto` chooses with (its kept
    effects are these first steps); here each step is refitted and must lower the cross-validated
    RMS."""
    say = progress or (lambda s: None)
    fit = fit or FitOptions(**fit_options)
    start_effects = ident.check_effects(effects, robot)
    check_data(start_effects, data, robot)
    cands, notes = candidates(robot, data, start_effects, fit.gravity)
    problem = SerialProblem(robot, data, ident.folds(data, folds, seed), fit, cands)
    found = engine.search(problem, start_effects, cands, alpha=alpha, min_gain=min_gain, max_steps=max_steps,
                          say=say)
    spec = problem.spec(found.effects)
    final = spec.fit(data)
    concl = engine.conclude(problem, found, spec.errors(final, data), int(np.sum(~np.asarray(final.fixed))), noise_mm,
                            alpha, say)
    say("scoring what remains against every candidate variable")
    rest = residual_vars.score(*residual_vars.carriers(final, data), residual_vars.variables(robot, data),
                               problem.folds)
    say(residual_vars.summary(rest))
    final_model = {"effects": [dict(problem.describe(x), label=x.label) for x in spec.effects],
                   "started_from": [x.label for x in start_effects]}
    return {"steps": found.steps, "final_rms_mm": found.cv_rms_mm, "noise_rms_mm": concl["noise_rms_mm"],
            "noise_known": concl["noise_known"], "fit_scatter_mm": concl["fit_scatter_mm"],
            "noise_per_coordinate_mm": concl["noise_per_coordinate_mm"],
            "verdict": concl["verdict"], "residual_variables": rest, "residual_summary": residual_vars.summary(rest),
            "notes": notes, "history": found.history, "folds": folds,
            "validation": grouping.describe(data, f"{folds}-fold"), "fitting": fitting_report(fit),
            "final_model": final_model, "_final_fit": final, "_spec": spec, "_start": problem.spec(start_effects)}


def fitting_report(fit: FitOptions) -> dict[str, Any]:
    """The fitting options of every fit, for diagnosis.json."""
    return {"loss": fit.loss, "loss_scale_mm": fit.loss_scale_mm, "gravity": fit.gravity,
            "prior_scale": "auto" if fit.prior_scale is None else fit.prior_scale,
            "prior_sd": "defaults" if fit.prior_sd is None else dict(fit.prior_sd),
            "prior_model": fit.prior_model is not None, "orientation_weight": fit.orientation_weight}


def step_effect(step: dict[str, Any]) -> Candidate:
    """The _core.Effect a step of diagnosis.json names (joint_map with its order)."""
    if _core.effect_kind(step["effect"]).ordered:
        return _core.Effect(step["effect"], step["joint"], order=step["order"])
    if step.get("gravity"):
        return JointCompliance(step["gravity"])
    return _core.Effect(step["effect"], step["joint"] or 0)


def final_identification(robot: Robot, data: MeasurementSet, diag: dict[str, Any],
                         tool_targets: Optional[FloatArray] = None) -> ident.Identification:
    """The diagnosed model (every named effect and those it started from), identified on all the data
    with Ceres as `kincal identify` does (covariance included), ready for model.json; with
    ``tool_targets`` (the targets' offsets in the tool frame) the TCP is placed as identify's
    --tool-targets does."""
    spec: Spec = diag["_spec"]
    res = ident.identify(robot, data, effects=spec.effects, k_folds=0, penalties=spec.penalties, fit=spec.fit_options)
    res.validation = {"scheme": f"fitted on every row; cross-validated in the diagnosis ({diag['validation']['scheme']}, "
                                f"{diag['validation']['configurations']} configurations)",
                      "held_rows": 0, "fit_rows": int(len(data.pose)),
                      "diagnosis_cv_rms_mm": diag["final_rms_mm"]}
    if tool_targets is not None:
        res = ident.tool_from_targets(res, tool_targets)
    return res
