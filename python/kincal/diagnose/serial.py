"""The diagnosis of a serial robot (`kincal diagnose --robot R`): its candidate effects from the
registry (joint_compliance, transmission_error, backlash, thermal_expansion, joint_map, per joint
where it concerns one; joint_map's order 1..MAX_MAP_ORDER chosen by the engine's cross-validation),
its refit (Ceres, C++ core) and its linearisation (the columns a candidate's parameters would add to
the identification Jacobian at the current fit, every candidate's in one evaluation), for the
engine's search; then what the final model still misses against every candidate variable
(residual_vars), the final model identified on all the data, and the files of the command.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Callable, Optional, Sequence, Union

import numpy as np

from .. import _core, grouping, report
from .. import identify as ident
from .. import strict_json
from .._core import Robot
from . import engine, residual_vars

#: joint_map candidates: orders 1..MAX_MAP_ORDER, the cross-validation chooses
MAX_MAP_ORDER = 8
#: joint_map's smoothness penalty: order k's sine and cosine amplitudes weigh sqrt(lambda s) k (the
#: penalty is lambda s / pi times the integral of the map's squared slope over a turn; s: the mean
#: squared norm of the joint's order-1 columns, so lambda is relative to what the data see); the
#: cross-validation chooses lambda among these, together with the order. A map the data see over
#: part of a turn only stays smooth there and small beyond.
MAP_SMOOTHING = (1e-1, 1e-2, 1e-3)
#: joint_map's variant (order, smoothing) is chosen leaving out each of this many ranges of its angle
VARIANT_BLOCKS = 5


def _needs_column(kind) -> str:
    """The measurement-set key of the column an effect kind reads ('' when none)."""
    return "dir" if kind.needs == "dir" else kind.needs


def candidates(robot: Robot, data: dict, start: Sequence = ()) -> tuple[list, list]:
    """Every candidate effect (a _core.Effect per joint where it applies, from the registry) the data
    can support, and notes on those skipped. Effects of ``start`` (the model the diagnosis starts
    from) are no candidates."""
    out, notes = [], []
    have = {(e.name, e.joint) for e in start}
    # identify's --gravity auto: the torques come from the link masses when any link has one (the core's
    # gravity_fitted)
    masses = any(j["mass_kg"] > 0 for j in json.loads(robot.to_json())["nominal"]["joints"])
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
        if col == "time_s" and (col not in data or np.ptp(data[col]) <= 0):
            notes.append(f"{kind.name} skipped: no time_s column, or it does not vary")
            continue
        if col and col not in data:
            notes.append(f"{kind.name} skipped: the data have no {col} column")
            continue
        joints = ident.applicable_joints(robot, kind) if kind.concerns == "joint" else [0]
        if kind.gravity_loaded_only and not masses:  # its columns would be 0: no torque to scale
            notes.append(f"{kind.name} skipped: the model has no link masses, so no joint carries a known gravity "
                         f"torque (--effects {kind.name} starts the diagnosis from it, the torques' mass moments "
                         "identified as `kincal identify --gravity fit` does)")
            continue
        if kind.name == "joint_map":  # the highest order: the engine chooses among its variants
            out += [_core.Effect(kind.name, j, order=MAX_MAP_ORDER) for j in joints if (kind.name, j) not in have]
        else:
            out += [_core.Effect(kind.name, j) for j in joints if (kind.name, j) not in have]
    return out, notes


class Spec:
    """The model under test: its effects (joint_compliance per joint included) and the fit's options."""

    def __init__(self, effects: Sequence = (), penalties: Sequence = (), **fit_options):
        self.effects: list = list(effects)
        self.penalties: list = list(penalties)  # (parameter name, weight): ridge penalties of the fit
        self.fit_options = dict(fit_options)

    def with_(self, cand, penalties: Sequence = ()) -> "Spec":
        return Spec(self.effects + [cand], self.penalties + list(penalties), **self.fit_options)

    def penalties_of(self, effect) -> list:
        """The penalties on an effect's parameters."""
        names = {f"joint{effect.joint}.{n}" for n in effect.parameter_names}
        return [p for p in self.penalties if p[0] in names]

    def has(self, cand) -> bool:
        return any(e.name == cand.name and e.joint == cand.joint for e in self.effects)

    @property
    def compliance(self) -> list:
        return [e.joint for e in self.effects if e.name == "joint_compliance"]

    def label(self) -> str:
        return " + ".join(["geometry"] + [e.label for e in self.effects])

    def fit(self, robot: Robot, data: dict) -> "_core.IdentifyResult":
        return _core.identify(robot, data, ident.options(self.effects, covariance=False, penalties=self.penalties,
                                                         **self.fit_options))

    def errors(self, res, data: dict) -> np.ndarray:
        return _core.point_errors(res.robot, res.targets, data)


def _key(p) -> tuple:
    return (p.kind, p.joint, p.target, p.name)


def evaluate(res, data: dict, extra: Sequence) -> tuple:
    """The identification residual r and Jacobian J at a fit ``res`` with the ``extra`` effects'
    parameters appended (at zero): (r, the fit's free columns, J, the parameters, the fit's
    parameter index of each of them that is the fit's, by index)."""
    layout = res.layout
    pm = _core.PointModel(res.robot, len(res.targets), list(layout.effect_list) + list(extra), res.t_ref, True)
    new = pm.layout.parameters
    old = {_key(p): p.index for p in layout.parameters}
    # the fit's parameters by name, not by place: the calibrated model may carry one the fit's did not
    # (a joint 1 whose identified tilt puts it under gravity gains a compliance, inserted before the
    # targets); an extra effect may repeat one of the fit's (its names come again, after the fit's)
    fit_of: dict = {}
    taken: set = set()
    for p in new:
        k = old.get(_key(p))
        if k is not None and k not in taken:
            fit_of[p.index] = k
            taken.add(k)
    x = np.zeros(len(new))
    fit_x = np.asarray(res.x)
    for p in new:
        # geometry, tool and base are corrections to the calibrated model (zero); compliances,
        # targets and effect values are absolute
        if p.kind not in ("joint_geometry", "tool", "base") and p.index in fit_of:
            x[p.index] = fit_x[fit_of[p.index]]
    r, J = pm.residuals(list(x), data, True)
    J = np.asarray(J)
    fixed = np.asarray(res.fixed)
    cur = J[:, [i for i, k in fit_of.items() if not fixed[k]]]
    return np.asarray(r), cur, J, new, fit_of


class _Linearised:
    """The model fitted on every point, linearised for the candidates: the residual r (3n), the
    current model's free columns and each candidate's columns at the fit, from one evaluation of the
    identification Jacobian with every candidate's parameters appended (made on the first call)."""

    def __init__(self, res, data: dict, candidates: Sequence):
        self.res, self.data = res, data
        have = {(e.name, e.joint) for e in res.layout.effect_list}
        self.extra = [c for c in candidates if c.name != "joint_compliance" and (c.name, c.joint) not in have]
        self.cols: Optional[dict] = None

    def __call__(self, cand) -> tuple:
        if self.cols is None:
            self.r, self.cur, self.J, self.new, self.fit_of = evaluate(self.res, self.data, self.extra)
            self.cols = {}
        key = (cand.name, cand.joint, tuple(cand.harmonics))
        if key not in self.cols:
            if cand.name != "joint_compliance" and not any(cand == e for e in self.extra):
                r, cur, J, new, fit_of = evaluate(self.res, self.data, [cand])  # not among the round's candidates
            else:
                r, cur, J, new, fit_of = self.r, self.cur, self.J, self.new, self.fit_of
            kind = "compliance" if cand.name == "joint_compliance" else cand.name
            idx = [p.index for p in new if p.kind == kind and p.joint == cand.joint
                   and (kind == "compliance" or (p.index not in fit_of and p.effect == cand))]
            self.cols[key] = (r, cur, J[:, idx])
        return self.cols[key]


class SerialProblem:
    """The diagnosis problem of a serial robot (engine.Problem): its measurements, folds of poses
    and the identification options of every fit."""

    dims = 3

    def __init__(self, robot: Robot, data: dict, folds: list, fit_options: dict, candidates: Sequence = ()):
        self.robot, self.data, self.folds, self.fit_options = robot, data, folds, fit_options
        self.candidates = list(candidates)
        self.penalty: dict = {}  # (name, joint, order) -> the penalties of the variant chosen

    def spec(self, effects: Sequence) -> Spec:
        pen = [p for e in effects for p in self.penalty.get((e.name, e.joint, e.order), [])]
        return Spec(effects, pen, **self.fit_options)

    def held_errors(self, effects: list, held: np.ndarray) -> np.ndarray:
        spec = self.spec(effects)
        res = spec.fit(self.robot, ident.subset(self.data, ~held))
        return spec.errors(res, ident.subset(self.data, held))

    def linearise(self, effects: list) -> engine.Linearisation:
        spec = self.spec(effects)
        res = spec.fit(self.robot, self.data)
        return _Linearised(res, self.data, self.candidates)

    def variants(self, cand, R: np.ndarray) -> Optional[list]:
        """joint_map's orders 1..K (its columns R: sine and cosine of each order, in order), each with
        each smoothness penalty of MAP_SMOOTHING (the strongest first): (effect, columns, weights).
        The library's transmission_error is fitted as it always was, without a penalty."""
        if cand.name != "joint_map":
            return None
        s = float(np.mean(np.sum(R[:, :2] ** 2, axis=0)))
        kw = np.repeat(np.asarray(cand.harmonics, dtype=float), 2)
        return [(_core.Effect("joint_map", cand.joint, order=k), 2 * k, np.sqrt(lam * s) * kw[:2 * k])
                for k in range(1, cand.order + 1) for lam in MAP_SMOOTHING]

    def variant_folds(self, cand) -> list:
        """joint_map's order and smoothing are chosen holding out, in turn, each of VARIANT_BLOCKS
        contiguous ranges of the joint's angle (equal numbers of points):
        a map must predict angles it has not seen, as it will on the next campaign."""
        q = np.asarray(self.data["q_deg"], dtype=float)[:, cand.joint - 1]
        edges = np.quantile(q, np.linspace(0.0, 1.0, VARIANT_BLOCKS + 1))
        block = np.clip(np.searchsorted(edges, q, side="right") - 1, 0, VARIANT_BLOCKS - 1)
        return [block == b for b in range(VARIANT_BLOCKS)]

    def variant_evidence(self, cand, i: int, gains: Sequence[float]) -> dict:
        """A joint_map step's evidence: the order and smoothing chosen, and the best gain of each order
        1..MAX_MAP_ORDER held out by ranges of the joint's angle."""
        g = np.asarray(gains).reshape(-1, len(MAP_SMOOTHING))
        out: dict = {"smoothing": MAP_SMOOTHING[i % len(MAP_SMOOTHING)]}
        if cand.name == "joint_map":
            out["order"] = cand.order
            out["order_range_cv_gain"] = [round(float(x), 6) for x in g.max(axis=1)]
        return out

    def chosen(self, cand, ridge: np.ndarray) -> None:
        """The variant chosen for a candidate: its fits carry that penalty (weights in mm per rad)."""
        names = [f"joint{cand.joint}.{n}" for n in cand.parameter_names]
        self.penalty[(cand.name, cand.joint, cand.order)] = [(n, float(w)) for n, w in zip(names, ridge)]

    def covered(self, cand, candidates: Sequence) -> bool:
        """A joint_map of order 1 or 2 is the library's transmission_error (orders 1, 2) where that is a
        candidate on the same joint: the library's name is kept."""
        return cand.name == "joint_map" and cand.order <= 2 and any(
            c.name == "transmission_error" and c.joint == cand.joint and set(range(1, cand.order + 1)) <= set(c.harmonics)
            for c in candidates)

    def describe(self, effect) -> dict:
        d = {"effect": effect.name, "joint": effect.joint if effect.joint > 0 else None}
        if effect.name == "joint_map":
            d["order"] = effect.order
        return d

    def label(self, effect) -> str:
        return effect.label

    def model_label(self, effects: list) -> str:
        return self.spec(effects).label()


def diagnose(robot: Robot, data: dict, *, folds: int = 5, alpha: float = 1e-6, min_gain: float = 0.03,
             max_steps: int = 6, seed: int = 0, noise_mm: Optional[float] = None,
             progress: Optional[Callable[[str], None]] = None, effects: Sequence = (), loss: str = "huber",
             loss_scale_mm: float = 0.1, orientation_weight: float = 100.0) -> dict:
    """The workflow (engine.search, then engine.conclude); returns the diagnosis.json of the
    contract (plus details for the report).

    ``effects``: the model the diagnosis starts from besides the geometry (Effect objects or texts of
    ``--effects``); they are no candidates. ``loss``, ``loss_scale_mm``, ``orientation_weight``:
    identify's options, used in every fit. ``noise_mm``: the instrument's noise per coordinate, if
    known (see engine.conclude)."""
    say = progress or (lambda s: None)
    start_effects = ident.check_effects(effects, robot)
    ident.check_data_for(start_effects, data, robot)
    cands, notes = candidates(robot, data, start_effects)
    fit_options = dict(loss=loss, loss_scale_mm=loss_scale_mm, orientation_weight=orientation_weight)
    problem = SerialProblem(robot, data, ident.folds(data, folds, seed), fit_options, cands)
    found = engine.search(problem, start_effects, cands, alpha=alpha, min_gain=min_gain, max_steps=max_steps, say=say)
    spec = problem.spec(found.effects)
    final = spec.fit(robot, data)
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
            "validation": grouping.describe(data, f"{folds}-fold"),
            "final_model": final_model, "_final_fit": final, "_spec": spec, "_start": problem.spec(start_effects)}


def step_effect(step: dict):
    """The _core.Effect a step of diagnosis.json names (joint_map with its order)."""
    if step["effect"] == "joint_map":
        return _core.Effect("joint_map", step["joint"], order=step["order"])
    return _core.Effect(step["effect"], step["joint"] or 0)


def final_identification(robot: Robot, data: dict, diag: dict,
                         tool_targets: Optional[np.ndarray] = None) -> "ident.Identification":
    """The diagnosed model (every named effect and those it started from), identified on all the data
    with Ceres as `kincal identify` does (covariance included), ready for model.json; with
    ``tool_targets`` (the targets' offsets in the tool frame) the TCP is placed as identify's
    --tool-targets does."""
    spec: Spec = diag["_spec"]
    res = ident.identify(robot, data, effects=spec.effects, k_folds=0, penalties=spec.penalties, **spec.fit_options)
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
