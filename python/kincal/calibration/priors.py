"""Identification's priors (maximum a posteriori) and its data-scaled robust loss, as Python sees them.

Every parameter of a kind named in the prior standard deviations gets a Gaussian prior centred on the
starting model (the nominal one, or ``--prior-model``, e.g. last year's calibration); what the data
cannot determine then stays at its prior instead of stopping the identification. The kinds, in the
model file's units: ``joint_mm`` and ``joint_deg`` (the joint lines' moves and tilts), ``compliance``
(deg/kNm), ``tool_mm``, ``tool_deg``, ``base_mm``, ``base_deg``, ``target_mm`` and an effect's name
(its parameters in the effect's file units). The C++ core (priors.cpp) weighs them by the residuals'
robust spread and sets the robust loss's scale from it.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any, Callable, Optional, Sequence, Union

import numpy as np

from .. import _core
from ..stats import grouping
from .._core import Robot

if TYPE_CHECKING:
    from .._core import MeasurementSet

#: prior standard deviations by kind (file units): a robot maker's tolerances for the joint geometry,
#: a tool known to a few mm; none for the compliances (their size per kN m differs 100-fold between
#: robots: a 0.01 deg/kNm prior cost 6% held out on the UR10 data), the base frames, the targets and
#: the extra effects (wide: the data determine them). The core holds them (default_prior_sd, in mm and
#: rad); here in the file's units (deg)
DEFAULT_PRIOR_SD = {(k[:-4] + "_deg" if k.endswith("_rad") else k): (math.degrees(v) if k.endswith("_rad") else v)
                    for k, v in _core.default_prior_sd()}
#: the overall widths `--prior-scale auto` chooses from, by grouped cross-validation
AUTO_SCALES = (0.1, 0.3, 1.0, 3.0, 10.0)
_GEOMETRIC = ("joint_mm", "joint_deg", "compliance", "tool_mm", "tool_deg", "base_mm", "base_deg", "target_mm")


def file_unit(unit: str) -> tuple[float, str]:
    """(factor, unit) taking a fit parameter from the core's unit to the model file's: radians (and
    rad/h) to degrees, every other unit as it is."""
    return (math.degrees(1.0), unit.replace("rad", "deg")) if unit.startswith("rad") else (1.0, unit)


def parse_prior_sd(text: Optional[str]) -> dict[str, float]:
    """``--prior-sd``: comma separated KIND=SD (file units) over the defaults; ``none`` removes every
    prior. Errors name the bad item and the kinds known."""
    sd = dict(DEFAULT_PRIOR_SD)
    text = (text or "").strip()
    if text == "none":
        return {}
    effects = [k.name for k in _core.effect_kinds() if k.domain == "serial" and not k.gravity_loaded_only]
    for item in filter(None, (t.strip() for t in text.split(","))):
        kind, eq, value = item.partition("=")
        kind = kind.strip()
        if not eq or kind not in _GEOMETRIC + tuple(effects):
            raise ValueError(f"--prior-sd: '{item}': expected KIND=SD with KIND one of "
                             f"{', '.join(_GEOMETRIC + tuple(effects))}")
        sd[kind] = _positive(value, f"--prior-sd: '{item}': the standard deviation must be a positive number")
    return sd


def core_prior_sd(sd: dict[str, float]) -> list[tuple[str, float]]:
    """The kinds in the core's units: degrees to radians, an effect's file units to its core units."""
    out = []
    for kind, v in sd.items():
        if kind.endswith("_deg"):
            out.append((kind[:-4] + "_rad", math.radians(v)))
        elif kind in _GEOMETRIC:
            out.append((kind, float(v)))
        else:
            scale = _core.Effect(kind, 1 if _core.effect_kind(kind).concerns == "joint" else 0).file_scale[0]
            out.append((kind, float(v) / scale))
    return out


def parse_prior_scale(text: Union[str, float, None]) -> Optional[float]:
    """``--prior-scale``: a positive number, or ``auto`` (None: chosen by cross-validation)."""
    if text is None:
        return 1.0
    if str(text).strip() == "auto":
        return None
    return _positive(text, f"--prior-scale: '{text}': a positive number or 'auto'")


def _positive(text: Union[str, float], message: str) -> float:
    """text as a finite positive number; ValueError(message) otherwise."""
    try:
        v = float(text)
    except ValueError:
        raise ValueError(message) from None
    if not (v > 0 and math.isfinite(v)):
        raise ValueError(message)
    return v


class Fitter:
    """identify() on a robot from its starting model: the nominal one, or a prior model's calibrated
    geometry (``prior_model``: the priors are centred there). With ``auto_scale`` every fit first
    chooses the priors' overall width on its own data by grouped cross-validation (AUTO_SCALES),
    so that a fold's choice never sees the rows it is validated on; ``scales`` records each choice."""

    def __init__(self, robot: Robot, prior_model: Optional[Robot] = None, auto_scale: bool = False,
                 folds: int = 5, seed: int = 0) -> None:
        if prior_model is not None and prior_model.dof != robot.dof:
            raise ValueError(f"--prior-model: {prior_model.dof} joints but the robot has {robot.dof}")
        self.robot = prior_model if prior_model is not None else robot
        self.from_calibrated = prior_model is not None
        self.auto_scale, self.folds, self.seed = auto_scale, folds, seed
        self.scales: list[float] = []

    def _once(self, data: MeasurementSet, opts: _core.IdentifyOptions,
              progress: Optional[Callable[[int, float], None]] = None) -> _core.IdentifyResult:
        return _core.identify(self.robot, data, opts, progress, self.from_calibrated)

    def __call__(self, data: MeasurementSet, opts: _core.IdentifyOptions,
                 progress: Optional[Callable[[int, float], None]] = None) -> _core.IdentifyResult:
        if self.auto_scale and opts.prior_scale > 0:
            opts = _copy(opts, prior_scale=self.choose_scale(data, opts))
            self.scales.append(opts.prior_scale)
        return self._once(data, opts, progress)

    def choose_scale(self, data: MeasurementSet, opts: _core.IdentifyOptions) -> float:
        """The overall prior width with the least grouped cross-validated RMS error on data."""
        k = min(self.folds, grouping.configurations(data).count)
        if k < 2:
            return 1.0
        masks = grouping.folds(data, k, self.seed)
        quiet = _copy(opts, covariance=False)
        best, best_rms = 1.0, math.inf
        for s in AUTO_SCALES:
            o = _copy(quiet, prior_scale=s)
            ss, n = 0.0, 0
            try:
                for held in masks:
                    r = self._once(grouping.subset(data, ~held), o)
                    e = np.asarray(_core.point_errors(r.robot, r.targets, grouping.subset(data, held), r.stations))
                    ss, n = ss + float(np.sum(e ** 2)), n + len(e)
            except ValueError:  # a fold these priors cannot fit (too narrow data for a wide prior)
                continue
            if n and math.sqrt(ss / n) < best_rms:
                best, best_rms = s, math.sqrt(ss / n)
        return best


def _copy(o: _core.IdentifyOptions, **changes: Any) -> _core.IdentifyOptions:
    """A copy of IdentifyOptions with some fields changed."""
    c = _core.IdentifyOptions()
    for name in ("compliance", "loss", "loss_scale_mm", "max_iterations", "rank_tolerance", "min_torque_share",
                 "weak_tolerance", "correlation_threshold", "covariance", "fix", "compliance_joints", "effects",
                 "orientation_weight", "penalties", "prior_sd", "prior_scale", "gravity", "target_start", "noise_mm", "artifact_sd_mm"):
        setattr(c, name, changes.get(name, getattr(o, name)))
    return c


def down_weighted(fit: _core.IdentifyResult, data: MeasurementSet, n: int = 5) -> list[tuple[int, int, float, float]]:
    """The rows the robust loss down-weighted most: (pose, target, residual mm, weight), the weight
    the loss gives a row of that residual norm (Huber: scale / residual), smallest first."""
    scale = fit.loss_scale_mm
    if not scale or not len(data.pose):
        return []
    e = np.asarray(_core.point_errors(fit.robot, fit.targets, data, fit.stations))
    w = np.minimum(1.0, scale / np.maximum(e, 1e-12))
    order = [i for i in np.argsort(w) if w[i] < 1.0][:n]
    return [(int(data.pose[i]), int(data.target[i]), float(e[i]), float(w[i])) for i in order]


def report(fit: _core.IdentifyResult, loss: str, given_scale: Optional[float], scale_choice: str) -> dict[str, Any]:
    """What the model JSON and the summary say of the priors and the loss."""
    names = [p.name for p in fit.layout.parameters]
    at_prior = [n for n, a in zip(names, fit.at_prior) if a]
    return {"priors": {"scale": scale_choice, "at_prior": at_prior,
                       "parameters_with_prior": int(np.sum(np.isfinite(fit.prior_sd)))},
            "loss": {"name": loss, "scale_mm": fit.loss_scale_mm or None,
                     "noise_mm": fit.noise_mm or None,
                     "scale_from": "--loss-scale" if given_scale else "the residuals' robust spread"}}


def summary_lines(fit: _core.IdentifyResult, info: dict[str, Any],
                  worst: Sequence[tuple[int, int, float, float]]) -> list[str]:
    """The summary's lines on the loss, the priors and what stays at its prior."""
    lines = []
    loss = info["loss"]
    if loss["scale_mm"]:
        how = ("set by --loss-scale" if loss["scale_from"] == "--loss-scale" else
               f"{loss['scale_mm'] / loss['noise_mm']:.2f} x the residuals' robust spread {loss['noise_mm']:.4f} mm "
               "per coordinate")
        lines.append(f"robust loss: {loss['name']} bending at {loss['scale_mm']:.4f} mm ({how})")
        if worst:
            lines.append("  most down-weighted points (pose, target, residual, weight): " +
                         "; ".join(f"{p}, {t}, {e:.3f} mm, {w:.2f}" for p, t, e, w in worst))
    elif loss["noise_mm"]:
        lines.append(f"residuals' robust spread {loss['noise_mm']:.4f} mm per coordinate (no robust loss)")
    pr = info["priors"]
    if pr["parameters_with_prior"]:
        lines.append(f"priors on {pr['parameters_with_prior']} parameters, overall width x{pr['scale']}")
    if pr["at_prior"]:
        lines.append("held at prior: not determined by these poses (posterior sd / prior sd):")
        params = fit.layout.parameters
        for i, p in enumerate(params):
            if fit.at_prior[i]:  # in the file's units, as the parameters' list (angles in deg)
                k, unit = file_unit(p.unit)
                sd = fit.stddev[i]
                post = "" if math.isnan(sd) else f"{sd * k:.3g} / "
                lines.append(f"  {p.name:<22} {post}{fit.prior_sd[i] * k:.3g} {unit}")
    return lines
