"""Measurement campaigns and parameter identification (the Samak paper's calibration step 3).

A measurement set is a dict of numpy arrays, the rows of the contract's measurement CSV (``pose``,
``q_deg``, ``xyz``, ``target``, ``payload_kg``, ``line``, ``source``; optional ``temperature_c``, ``dir``,
``abc``, ``time_s``, ``config``/``setup`` int64 codes with ``config_names``/``setup_names``). The
heavy work (residuals, analytic Jacobian, Ceres) runs in the C++ core.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass, field
from typing import Callable, Optional, Sequence

import numpy as np

from . import _core, gravity as _gravity, grouping, priors
from ._core import Robot
from .setups import drift_report, setup_frames, validation_figures, validation_summary  # noqa: F401
from .setups import _refit_placements, _rms, validate  # noqa: F401  (kincal.identify.validate, as before)

#: reflector offsets (mm, tool frame) used by `kincal simulate --targets N`
DEFAULT_TARGETS = np.array([[0.0, 0.0, 0.0], [120.0, 0.0, 30.0], [0.0, 150.0, -20.0], [-100.0, -80.0, 40.0]])
#: where the simulated laser tracker sees the robot base: x, y, z (mm), a, b, c (deg)
DEFAULT_INSTRUMENT = (3500.0, -1500.0, -400.0, 35.0, 1.5, -0.8)
#: harmonic orders of transmission_error unless --harmonics says otherwise
DEFAULT_HARMONICS = (1, 2)
#: order of a joint_map named without one (--effects joint_map:J; joint_map:J:K gives K)
DEFAULT_MAP_ORDER = 4


def default_truth(robot: Robot, seed: int = 1, sigma_mm: float = 1.0, sigma_deg: float = 0.05,
                  compliance: float = 0.003) -> Robot:
    """A simulated true robot: realistic geometric errors and joint compliance, seen by an
    instrument at DEFAULT_INSTRUMENT."""
    return robot.with_calibrated(seed, sigma_mm, sigma_deg, compliance, DEFAULT_INSTRUMENT)


def simulate(truth: Robot, poses: int = 150, *, seed: int = 1, noise_mm: float = 0.02, targets: int = 1,
             outlier_fraction: float = 0.0, outlier_mm: float = 5.0, effects: Sequence = (),
             t_ref: float = 20.0, orientation_noise_deg: Optional[float] = None,
             duration_h: Optional[float] = None) -> dict:
    """Measure ``poses`` random configurations (inside the joint limits) of the truth's calibrated
    model with ``targets`` reflectors, Gaussian noise per coordinate and optional gross outliers.
    ``effects`` hides more effects in the truth: (Effect, values) or (name, joint from 1 or 0, values),
    the values in the registry's core units (``Effect.units``: radians for transmission_error's sine
    and cosine amplitudes and backlash's offset per direction sign, 1/degC for thermal_expansion about
    t_ref). Every row gets dir1..dirN and
    temperature_c (drifting from 18 to 30 C over the campaign). With ``orientation_noise_deg`` the
    tool frame's orientation is measured too (a 6-D probe): columns a, b, c. With ``duration_h`` the
    rows get time_s, the campaign running from 0 to that many hours in pose order; a hidden drift
    (mm/h and rad/h) without it gets a 3 h campaign, the drift centred on its mean time."""
    if poses < 1:
        raise ValueError(f"the number of poses must be positive, not {poses}")
    if not 1 <= targets <= len(DEFAULT_TARGETS):
        raise ValueError(f"--targets must be 1..{len(DEFAULT_TARGETS)}, not {targets}")
    if noise_mm < 0 or not math.isfinite(noise_mm):
        raise ValueError(f"the noise must be a finite non-negative number, not {noise_mm}")
    if not 0.0 <= outlier_fraction <= 1.0:
        raise ValueError(f"the outlier fraction must be in 0..1, not {outlier_fraction}")
    if duration_h is not None and not (duration_h > 0 and math.isfinite(duration_h)):
        raise ValueError(f"the campaign's duration must be a positive number of hours, not {duration_h}")
    return _core.simulate(truth, poses, seed, noise_mm, outlier_fraction, outlier_mm, DEFAULT_TARGETS[:targets], 0.9,
                          [_effect_value(e) for e in effects], t_ref,
                          -1.0 if orientation_noise_deg is None else float(orientation_noise_deg),
                          0.0 if duration_h is None else 3600.0 * float(duration_h))


def _effect_value(e: Sequence) -> tuple:
    """(Effect, values) from (Effect, values) or (name, joint from 1 or 0, values)."""
    if len(e) == 2 and isinstance(e[0], _core.Effect):
        return e[0], [float(v) for v in e[1]]
    name, joint, vals = e
    vals = [float(v) for v in vals]
    if name == "joint_map":  # its order from the number of values: a sine and a cosine per order
        return _core.Effect("joint_map", int(joint), order=max(1, len(vals) // 2)), vals
    return _core.Effect(str(name), int(joint)), vals


def applicable_joints(robot: Robot, kind: "_core.EffectKind") -> list:
    """Joints (from 1) where a joint-wise effect applies: the gravity-loaded ones (from the
    identification layout) for an effect that needs gravity, every joint otherwise."""
    if kind.gravity_loaded_only:
        return list(_core.PointModel(robot, 1).layout.loaded)
    return list(range(1, robot.dof + 1))


def parse_effects(text: str, robot: Robot, harmonics: Sequence[int] = DEFAULT_HARMONICS,
                  option: str = "--effects") -> list:
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
    out: list = []
    for item in items:
        name, _, joint = item.partition(":")
        name = name.strip()
        order = DEFAULT_MAP_ORDER
        if name == "joint_map" and ":" in joint:
            joint, _, k = joint.partition(":")
            try:
                order = int(k)
            except ValueError:
                raise ValueError(f"{option}: '{item}': joint_map's order must be a number 1..64") from None
        kind = next((k for k in _core.effect_kinds() if k.name == name), None)
        if kind is None:
            raise ValueError(f"{option}: unknown effect '{item}' (known: {known})")
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
                e = (_core.Effect(name, j, order=order) if name == "joint_map"
                     else _core.Effect(name, j, list(harmonics)))
                e.check(robot.dof)
            except ValueError as err:
                raise ValueError(f"{option}: '{item}': {err}") from None
            if e not in out:
                out.append(e)
    return out


def parse_hidden_effect(text: str, dof: int, harmonics: Sequence[int] = DEFAULT_HARMONICS) -> tuple:
    """NAME:JOINT:V1,V2.. of `kincal simulate --hide`: (Effect, values in core units). The values are
    in the model file's units (degrees for angles, 1/C for thermal_expansion: joint 0); their number
    comes from the registry (transmission_error: a sine and a cosine amplitude per harmonic order;
    joint_map: its order is half their number)."""
    parts = text.split(":")
    if len(parts) != 3:
        raise ValueError(f"--hide {text}: expected NAME:JOINT:VALUES")
    name, joint, vals = parts[0], parts[1], parts[2]
    kinds = [k for k in _core.effect_kinds() if k.domain == "serial" and k.name != "joint_compliance"]
    kind = next((k for k in kinds if k.name == name), None)
    if kind is None:
        raise ValueError(f"--hide {text}: unknown effect '{name}' ({', '.join(k.name for k in kinds)})")
    try:
        j = int(joint)
        v = [float(x) for x in vals.split(",")]
    except ValueError:
        raise ValueError(f"--hide {text}: joint and values must be numbers") from None
    if kind.concerns == "joint" and not 1 <= j <= dof:
        raise ValueError(f"--hide {text}: joint {j} is not one of 1..{dof}")
    if name == "joint_map":
        if len(v) < 2 or len(v) % 2 or len(v) > 128:
            raise ValueError(f"--hide {text}: joint_map takes a sine and a cosine amplitude (deg) per order "
                             "1..K: an even number of values, 2 to 128")
        e = _core.Effect(name, j, order=len(v) // 2)
    else:
        e = _core.Effect(name, j if kind.concerns == "joint" else 0, list(harmonics))
    if len(v) != e.size or not all(math.isfinite(x) for x in v):
        raise ValueError(f"--hide {text}: {e.label} takes {e.size} finite value(s) "
                         f"({', '.join(f'{n} ({u})' for n, u in zip(e.parameter_names, e.file_units))})")
    return e, [x / sc for x, sc in zip(v, e.file_scale)]


def check_data_for(effects: Sequence, data: dict, robot: Robot) -> None:
    """The data columns the effects read (the registry's ``needs``) are present: a clear error names
    the file and the column otherwise."""
    src = data.get("source", "<data>")
    for e in effects:
        need = _core.effect_kind(e.name).needs
        if need == "dir" and "dir" not in data:
            raise ValueError(f"{src}: {e.label} needs the dir1..dir{robot.dof} columns (the sign of each joint's "
                             "last motion into the pose)")
        if need == "temperature_c" and "temperature_c" not in data:
            raise ValueError(f"{src}: {e.label} needs the temperature_c column")
        if need == "time_s" and "time_s" not in data:
            raise ValueError(f"{src}: {e.label} needs the time_s column (when each point was measured, s)")


def options(effects: Sequence = (), *, loss: str = "huber", loss_scale_mm: float = 0.1, covariance: bool = True,
            orientation_weight: float = 100.0, max_iterations: int = 100,
            fix: Sequence[str] = (), penalties: Sequence = (), prior_sd: Optional[dict] = None,
            prior_scale: float = 0.0, gravity: str = "auto") -> "_core.IdentifyOptions":
    """IdentifyOptions for a list of effects (joint_compliance entries switch the compliance of their
    joints on; without any, the compliances stay at their start value). ``penalties``: ridge
    penalties (parameter name, weight in mm per unit of the parameter), e.g. the diagnosis's
    joint_map smoothness penalty. ``prior_sd`` (kinds in file units, priors.DEFAULT_PRIOR_SD) times
    ``prior_scale`` (0: no priors); ``loss_scale_mm`` 0: from the residuals."""
    effects = list(effects)
    o = _core.IdentifyOptions(compliance=any(e.name == "joint_compliance" for e in effects), loss=loss, gravity=gravity,
                              loss_scale_mm=loss_scale_mm, max_iterations=max_iterations, fix=list(fix),
                              effects=effects, covariance=covariance, orientation_weight=orientation_weight)
    o.penalties = [(str(n), float(w)) for n, w in penalties]
    o.prior_sd = priors.core_prior_sd(priors.DEFAULT_PRIOR_SD if prior_sd is None else prior_sd)
    o.prior_scale = float(prior_scale) if prior_sd is None or prior_sd else 0.0
    return o


def read_measurements(path: str, robot: Robot) -> dict:
    """The measurement CSV of the contract (errors name file:line and cause)."""
    return _core.read_measurements(str(path), robot.dof, robot)  # the controller's joint numbers converted


def measurements_csv(data: dict, dof: int) -> str:
    return _core.format_measurements(data, dof)


def subset(data: dict, mask: np.ndarray) -> dict:
    out = {k: (v[mask] if isinstance(v, np.ndarray) else v) for k, v in data.items()}
    return out


def split_poses(data: dict, holdout: float, seed: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """Row masks (fit, held out): a share of the configurations held out whole (grouping.split)."""
    return grouping.split(data, holdout, seed)


def folds(data: dict, k: int, seed: int = 0) -> list[np.ndarray]:
    """k masks of held-out rows, whole configurations per fold (grouping.folds)."""
    return grouping.folds(data, k, seed)


def _figures(e: np.ndarray, when: str, unit: str) -> dict:
    """RMS, mean (the Samak paper's figure) and max of errors: {when}_rms_{unit}, ..."""
    return {f"{when}_rms_{unit}": _rms(e), f"{when}_mean_{unit}": float(np.mean(e)), f"{when}_max_{unit}": float(np.max(e))}


@dataclass
class Identification:
    """What `kincal identify` found: the calibrated robot (with its identified effects), targets, the
    core's result (``fit``: an IdentifyResult) and the validation. ``effects``: the effects asked for."""
    robot: Robot
    targets: np.ndarray
    fit: "_core.IdentifyResult"
    effects: list
    validation: dict = field(default_factory=dict)
    fit_info: dict = field(default_factory=dict)  #: priors.report(): the priors and the loss
    worst: list = field(default_factory=list)  #: priors.down_weighted(): the most down-weighted rows

    def parameters(self) -> list:
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

    def effect_labels(self) -> list:
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
        return json.dumps(d, indent=1, sort_keys=True) + "\n"

    def summary(self) -> str:
        f, v = self.fit, self.validation
        lines = [f"identified {int(np.sum(~np.asarray(f.fixed)))} of {f.layout.size} parameters "
                 f"({', '.join(['geometry'] + self.effect_labels())}) in {f.iterations} iterations",
                 _gravity.summary_line(f), ""]
        if not f.converged:  # the parameters are where the solver stopped, not a least-squares optimum
            lines[1:1] = [f"did not converge: {f.stop_reason}. The parameters are where the solver stopped, not "
                          "the best fit: check the held-out figures against the geometry alone, and measure more "
                          "configurations, identify fewer effects (--effects) or raise the iteration cap "
                          "(max_iterations)"]
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
        periodic = sorted({e.joint for e, _ in self.robot.effects if e.name in ("transmission_error", "joint_map")})
        if ranges and periodic:
            lines.append("periodic effects known over the fitted angles (validate and compensate warn beyond them): " +
                         ", ".join(f"joint {j} {ranges[j - 1][0]:.0f}..{ranges[j - 1][1]:.0f} deg" for j in periodic))
        lines.append(f"condition number {f.condition_number:.4g}, observability index {f.observability_index:.4g}"
                     " (what the data determine)")
        if self.fit_info:
            lines += priors.summary_lines(f, self.fit_info, self.worst)
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


def orientation_errors_deg(robot: Robot, data: dict) -> np.ndarray:
    """Angle (deg) between the measured and the predicted tool orientation of every 6-D row (each
    row seen from its setup's placement, the model's drift at its time)."""
    return np.asarray(_core.orientation_errors(robot, data))


def check_effects(effects, robot: Robot, harmonics: Sequence[int] = DEFAULT_HARMONICS) -> list:
    """Effects as _core.Effect: a text of --effects, or a list of Effect objects and/or texts
    (``NAME`` or ``NAME:J``), checked against the registry and the robot."""
    if isinstance(effects, str):
        return parse_effects(effects, robot, harmonics)
    out: list = []
    for e in effects:
        for x in ([e] if isinstance(e, _core.Effect) else parse_effects(str(e), robot, harmonics)):
            x.check(robot.dof)
            if x not in out:
                out.append(x)
    return out


def _errors(r: "_core.IdentifyResult", h: dict) -> dict:
    """Position (and, with measured orientations, orientation) errors of the rows h: before (the
    nominal geometry, frames fitted) and after (the identified model r)."""
    out = {"ea": _core.point_errors(r.robot, r.targets, h), "eb": _core.point_errors(r.nominal_fitted,
                                                                                     r.nominal_targets, h)}
    if "abc" in h:
        out.update(oa=orientation_errors_deg(r.robot, h), ob=orientation_errors_deg(r.nominal_fitted, h))
    return out


def _cross_validated_errors(fit: priors.Fitter, data: dict, opts, held_masks,
                            progress: Optional[Callable[[int, int], None]]) -> dict:
    """_errors of every held-out row, each fold predicted by the model fitted on the other folds."""
    parts = []
    for i, held in enumerate(held_masks):
        if progress:
            progress(i, len(held_masks))
        try:
            model = fit(subset(data, ~held), opts)
        except ValueError as e:  # the core names the data's source and the fold's rows: say they are a fold's
            raise ValueError(f"cross-validation fold {i + 1} of {len(held_masks)} (the model fitted without "
                             f"{int(np.sum(held))} held-out rows): {e}") from None
        parts.append(_errors(model, subset(data, held)))
    return {k: np.concatenate([p[k] for p in parts]) for k in parts[0]}


def _setup_errors(fit: priors.Fitter, data: dict, opts, held_masks, loss: str, loss_scale_mm: float,
                  progress: Optional[Callable[[int, int], None]]) -> dict:
    """Errors of every setup held out whole: the model fitted on the other setups, the held one's
    placement and targets refitted on its rows (validate()'s refit)."""
    parts = []
    for i, held in enumerate(held_masks):
        if progress:
            progress(i, len(held_masks))
        r = fit(subset(data, ~held), opts)
        ea, eb, oa, ob, _ = _refit_placements(r.robot, subset(data, held), loss, loss_scale_mm)
        parts.append(dict(ea=ea, eb=eb, **({"oa": oa, "ob": ob} if oa is not None else {})))
    return {k: np.concatenate([p[k] for p in parts]) for k in parts[0]}


def identify(robot: Robot, data: dict, *, effects=("joint_compliance",), loss: str = "huber",
             loss_scale_mm: Optional[float] = None, prior_sd: Optional[dict] = None, prior_scale=1.0,
             prior_model: Optional[Robot] = None, holdout: Optional[float] = None, k_folds: int = 5, seed: int = 0,
             progress: Optional[Callable[[int, float], None]] = None,
             orientation_weight: float = 100.0, harmonics: Sequence[int] = DEFAULT_HARMONICS,
             fold_progress: Optional[Callable[[int, int], None]] = None,
             penalties: Sequence = (), hold_out_setups: bool = False, gravity: str = "auto",
             max_iterations: int = 100) -> Identification:
    """Identify the robot's parameters from measurements.

    ``loss_scale_mm``: where the robust loss bends (None: from the residuals' robust spread).
    ``prior_sd``: prior standard deviations by kind in file units (None: priors.DEFAULT_PRIOR_SD; {}:
    no priors), times ``prior_scale`` ("auto" or None: chosen by grouped cross-validation inside
    each training set), centred on ``prior_model``'s calibrated geometry when given (e.g. last
    year's calibration), else on the nominal model.

    ``effects``: what the model carries besides the geometry: _core.Effect objects or texts of
    ``--effects`` (``"joint_compliance"``, ``"transmission_error:3"``, ``"backlash:2"``,
    ``"thermal_expansion"``, or one comma-separated text).

    The model returned is fitted on every row. Its validation figures come from ``k_folds``-fold
    cross-validation (whole configurations per fold; 0: no validation). With ``holdout`` (a share in
    (0, 1)) a random share of the configurations is held out instead, and the model then excludes
    those rows (the validation says so). ``fold_progress(fold, folds)`` reports each validation fit.
    ``penalties``: ridge penalties (parameter name, weight in mm per unit of the parameter).
    ``hold_out_setups``: the validation holds out each setup (instrument placement) whole instead:
    the model fitted on the other setups, the held setup's placement and targets refitted on it as
    validate() does. ``max_iterations``: each Levenberg-Marquardt pass's cap (the result says whether it converged)."""
    effects = check_effects(effects, robot, harmonics)
    check_data_for(effects, data, robot)
    if loss not in ("none", "huber", "cauchy"):
        raise ValueError(f"unknown loss '{loss}' (none, huber, cauchy)")
    if k_folds == 1 or k_folds < 0:
        raise ValueError(f"--folds must be 0 (no validation) or at least 2, not {k_folds}")
    if holdout is not None and not 0.0 <= holdout < 1.0:
        raise ValueError(f"--holdout must be a share in (0, 1), not {holdout}")
    holdout = holdout or None  # a share of 0 holds nothing out
    auto = prior_scale is None or prior_scale == "auto"
    opts, cv_opts = (options(effects, loss=loss, loss_scale_mm=loss_scale_mm or 0.0, covariance=cov,
                             orientation_weight=orientation_weight, penalties=penalties, prior_sd=prior_sd,
                             prior_scale=1.0 if auto else float(prior_scale), gravity=gravity,
                             max_iterations=max_iterations)
                     for cov in (True, False))
    fit = priors.Fitter(robot, prior_model, auto_scale=auto, seed=seed)
    every_row = np.ones(len(data["pose"]), dtype=bool)
    if hold_out_setups:
        codes = np.asarray(data.get("setup", np.zeros(len(data["pose"]), dtype=np.int64)))
        if len(np.unique(codes)) < 2:
            raise ValueError("holding out whole setups needs a setup column with at least two setups")
        fit_mask, masks = every_row, [codes == c for c in np.unique(codes)]
        val = {"scheme": f"each of the {len(masks)} setups held out whole (its placement and targets refitted)",
               "grouping": "setup column", "configurations": int(grouping.configurations(data).count),
               "held_rows": int(len(codes)), "model_rows": "every row (validated by holding out setups)"}
    elif holdout is not None:
        fit_mask, held = split_poses(data, holdout, seed)
        val = dict(grouping.describe(data, f"{holdout:.0%} held out"), held_rows=int(held.sum()),
                   model_rows="the fitted rows only: the model excludes the held-out rows")
        masks = [held]
    elif k_folds > 1:
        fit_mask, masks = every_row, folds(data, k_folds, seed)
        val = dict(grouping.describe(data, f"{k_folds}-fold"),
                   held_rows=int(len(data["pose"])), model_rows="every row (validated by cross-validation)")
    else:
        fit_mask, masks = every_row, []
        val = {"scheme": "none", "held_rows": 0, "model_rows": "every row (not validated)"}
    # folds: each predicted by a model fitted without it; a split: by the delivered model itself
    if hold_out_setups:
        e = _setup_errors(fit, data, cv_opts, masks, loss, loss_scale_mm or 0.0, fold_progress)
    else:
        e = _cross_validated_errors(fit, data, cv_opts, masks, fold_progress) if masks and holdout is None else {}
    fit.scales.clear()
    r = fit(subset(data, fit_mask), opts, progress)
    if holdout is not None and val["held_rows"]:
        e = _errors(r, subset(data, ~fit_mask))
    if e:
        val.update(_figures(e["eb"], "before", "mm"), **_figures(e["ea"], "after", "mm"))
        if "oa" in e:
            val.update(_figures(e["ob"], "before", "deg"), **_figures(e["oa"], "after", "deg"))
    val["fit_rows"] = int(fit_mask.sum())
    choice = (f"{fit.scales[0]:g} (chosen by grouped cross-validation)" if fit.scales else f"{opts.prior_scale:g}")
    info = priors.report(r, loss, loss_scale_mm, choice)
    info["priors"]["centred_on"] = "the prior model's calibrated geometry" if prior_model else "the starting model"
    # the model records the angles its fit saw: where its periodic effects were measured
    calibrated = r.robot.with_fitted_ranges(_core.joint_ranges(data["q_deg"][fit_mask]))
    return Identification(robot=calibrated, targets=np.asarray(r.targets), fit=r, effects=list(effects),
                          validation=val, fit_info=info, worst=priors.down_weighted(r, subset(data, fit_mask)))


def tool_from_targets(result: Identification, known: np.ndarray) -> Identification:
    """The tool frame placed from known target offsets (tool_frame.tool_from_targets)."""
    from .tool_frame import tool_from_targets as place
    return place(result, known)
