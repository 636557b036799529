"""The diagnosis of a serial robot (`kincal diagnose --robot R`): the stepwise search over the
candidate effects of kincal.effect_choice (those `identify --effects auto` chooses from, with the
same rule; here every step refitted and confirmed), with identify's fitting options in every fit;
then what the final
model still misses against every candidate variable (residual_vars), the final model identified on
all the data, and the files of the command.
"""

from __future__ import annotations

from pathlib import Path
from typing import Callable, Optional, Sequence, Union

import numpy as np

from .. import _core, grouping, report
from .. import identify as ident
from .. import stepwise as engine
from .. import strict_json
from .._core import Robot
from ..effect_choice import (ALPHA, MAX_MAP_ORDER, MIN_GAIN, JointCompliance,  # noqa: F401
                             SerialProblem, Spec, candidates, check_data, evaluate)
from ..fitting import FitOptions
from . import residual_vars

__all__ = ["JointCompliance", "SerialProblem", "Spec", "candidates", "diagnose", "final_identification", "run",
           "summary", "step_effect"]

def diagnose(robot: Robot, data: dict, *, folds: int = 5, alpha: float = ALPHA, min_gain: float = MIN_GAIN,
             max_steps: int = 6, seed: int = 0, noise_mm: Optional[float] = None,
             progress: Optional[Callable[[str], None]] = None, effects: Sequence = (),
             fit: Optional[FitOptions] = None, **fit_options) -> dict:
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


def fitting_report(fit: FitOptions) -> dict:
    """The fitting options of every fit, for diagnosis.json."""
    return {"loss": fit.loss, "loss_scale_mm": fit.loss_scale_mm, "gravity": fit.gravity,
            "prior_scale": "auto" if fit.prior_scale is None else fit.prior_scale,
            "prior_sd": "defaults" if fit.prior_sd is None else dict(fit.prior_sd),
            "prior_model": fit.prior_model is not None, "orientation_weight": fit.orientation_weight}


def step_effect(step: dict):
    """The _core.Effect a step of diagnosis.json names (joint_map with its order)."""
    if step["effect"] == "joint_map":
        return _core.Effect("joint_map", step["joint"], order=step["order"])
    if step.get("gravity"):
        return JointCompliance(step["gravity"])
    return _core.Effect(step["effect"], step["joint"] or 0)


def final_identification(robot: Robot, data: dict, diag: dict,
                         tool_targets: Optional[np.ndarray] = None) -> "ident.Identification":
    """The diagnosed model (every named effect and those it started from), identified on all the data
    with Ceres as `kincal identify` does (covariance included), ready for model.json; with
    ``tool_targets`` (the targets' offsets in the tool frame) the TCP is placed as identify's
    --tool-targets does."""
    spec: Spec = diag["_spec"]
    res = ident.identify(robot, data, effects=spec.effects, k_folds=0, penalties=spec.penalties, fit=spec.fit_options)
    res.validation = {"scheme": f"fitted on every row; cross-validated in the diagnosis ({diag['validation']['scheme']}, "
                                f"{diag['validation']['configurations']} configurations)",
                      "held_rows": 0, "fit_rows": int(len(data["pose"])),
                      "diagnosis_cv_rms_mm": diag["final_rms_mm"]}
    if tool_targets is not None:
        res = ident.tool_from_targets(res, tool_targets)
    return res


def run(robot: Robot, data: dict, out: Union[str, Path], *, title: str, tool_targets: Optional[np.ndarray] = None,
        progress: Optional[Callable[[str], None]] = None, **options) -> tuple[dict, "ident.Identification"]:
    """`kincal diagnose`: the diagnosis (``options``: those of diagnose()), the final model identified
    on all the data, and in the folder ``out`` report.html with its figures, diagnosis.json and
    model.json. Returns the diagnosis and the final identification."""
    from .serial_report import write_report

    say = progress or (lambda s: None)
    report.check_folder(out)  # before the work, not after it
    diag = diagnose(robot, data, progress=progress, **options)
    say("identifying the final model on all the data")
    model = final_identification(robot, data, diag, tool_targets)
    diag["final_model"]["file"] = "model.json"
    diag["final_model"]["parameters"] = [
        {"effect": e.name, "joint": e.joint or None, "label": e.label,
         "values": [v * sc for v, sc in zip(vals, e.file_scale)], "units": e.file_units}
        for e, vals in model.robot.effects]
    with report.staged_folder(out, owned=("step*.png", "residual_variables.png")) as folder:  # whole or nothing
        write_report(robot, data, diag, folder, title=title, model_file="model.json")
        _core.write_file_atomic(str(folder / "diagnosis.json"), strict_json.dumps(engine.contract_json(diag), indent=1) + "\n")
        _core.write_file_atomic(str(folder / "model.json"), model.model_json())
    return diag, model


def summary(diag: dict, model: "ident.Identification", out: Union[str, Path], seconds: float) -> str:
    """`kincal diagnose`'s summary of run()'s results: each named effect, the final verdict and the
    files written in ``out``."""
    folder = Path(out)
    lines = []
    for st in diag["steps"]:
        j = f" joint {st['joint']}" if st["joint"] else ""
        o = f" order {st['order']}" if st.get("order") else ""
        lines.append(f"{st['effect']}{j}{o}: cross-validated RMS {st['rms_before_mm'] * 1000:.1f} -> "
                     f"{st['rms_after_mm'] * 1000:.1f} um (F = {st['evidence']['F']:.3g})")
    lines.append(f"final cross-validated RMS {diag['final_rms_mm'] * 1000:.1f} um, {engine.noise_phrase(diag)}: "
                 f"{diag['verdict']} ({seconds:.1f} s); "
                 f"report: {folder / 'report.html'}; model ({' + '.join(['geometry'] + model.effect_labels())}): "
                 f"{folder / 'model.json'}")
    if diag.get("residual_summary"):
        lines.append(diag["residual_summary"])
    return "\n".join(lines)
