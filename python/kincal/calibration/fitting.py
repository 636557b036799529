"""The fitting options shared by every fit of a serial robot: `kincal identify`, `kincal diagnose`
(and the effect choice of `identify --effects auto`, which is the diagnosis's first steps) fit with
the same priors, robust loss, gravity, orientation weight and iteration cap, and the same defaults.

One default each, measured on the real data the project has (BENCHMARKS.md, "One fitting engine"):
- priors on the joint geometry (1 mm, 0.1 deg) and the tool (5 mm, 1 deg) at their overall width 1
  (priors.DEFAULT_PRIOR_SD): what the data cannot determine stays at its prior and is listed, never a
  refusal;
- the robust loss (Huber) bends where the residuals' robust spread puts it (4.03 x the noise;
  ``loss_scale_mm`` None): a fixed 0.1 mm predicted the UR10 series a little better from B, but bends
  below the structure a model still lacks (a fit that misses an effect becomes an L1 fit, distorted,
  slow to converge, and the diagnosis then misnames the effect), BENCHMARKS.md "One fitting engine";
- ``gravity`` "auto": the model's link masses when it has any, else the mass moments fitted.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING, Any, Callable, Optional, Sequence

import numpy as np

from .. import _core
from ..stats import grouping
from . import priors
from .._core import Robot

if TYPE_CHECKING:
    from .._core import Gravity, Loss, MeasurementSet
    from ..typing_ import BoolArray, FloatArray

LOSSES = ("none", "huber", "cauchy")
#: where the robust loss bends unless told (mm; None: from the residuals' robust spread; BENCHMARKS.md "One
#: fitting engine")
DEFAULT_LOSS_SCALE_MM: Optional[float] = None
GRAVITY = ("auto", "masses", "fit")


@dataclass(frozen=True)
class FitOptions:
    """How every fit of a campaign is made (the command line's fitting options).

    ``loss_scale_mm``: where the robust loss bends (mm; None or 0: from the residuals' robust spread);
    ``prior_sd``: prior standard deviations by kind in file units (None: priors.DEFAULT_PRIOR_SD, {}: no
    priors); ``prior_scale``: times every prior sd (None: chosen by grouped cross-validation inside
    each fit's own data); ``prior_model``: the priors' centre and the fits' start (default: the robot's
    nominal model); ``gravity``: the compliances' gravity torques (auto, masses, fit)."""
    loss: Loss = "huber"
    loss_scale_mm: Optional[float] = DEFAULT_LOSS_SCALE_MM
    prior_sd: Optional[dict[str, float]] = None
    prior_scale: Optional[float] = 1.0
    prior_model: Optional[Robot] = None
    gravity: Gravity = "auto"
    orientation_weight: float = 100.0
    max_iterations: int = 100
    target_start: Optional[Sequence[Sequence[float]]] = None  #: each target's start on the tool (mm; a probe's ball)
    noise_mm: Optional[float] = None  #: the instrument's noise per coordinate, when known (None: estimated)
    artifact_sd_mm: Optional[float] = None  #: the artifact's uncertainty (None: its terms weigh as a row's)

    def __post_init__(self) -> None:
        if self.loss not in LOSSES:
            raise ValueError(f"unknown loss '{self.loss}' ({', '.join(LOSSES)})")
        if self.gravity not in GRAVITY:
            raise ValueError(f"unknown gravity mode '{self.gravity}' ({', '.join(GRAVITY)})")
        if self.loss_scale_mm is not None and not (self.loss_scale_mm >= 0 and math.isfinite(self.loss_scale_mm)):
            raise ValueError(f"--loss-scale must be a finite number >= 0 (0: from the residuals), not "
                             f"{self.loss_scale_mm}")
        if self.max_iterations < 1:
            raise ValueError(f"the iteration cap must be at least 1, not {self.max_iterations}")
        if self.artifact_sd_mm is not None and not (self.artifact_sd_mm > 0 and math.isfinite(self.artifact_sd_mm)):
            raise ValueError(f"--artifact-sd must be a positive number of mm, not {self.artifact_sd_mm}")
        if self.noise_mm is not None and not (self.noise_mm > 0 and math.isfinite(self.noise_mm)):
            raise ValueError(f"the noise (--noise, --fit-noise) must be a positive number of mm, not {self.noise_mm}")

    def with_(self, **changes: Any) -> FitOptions:
        return replace(self, **changes)

    @property
    def auto_prior_scale(self) -> bool:
        return self.prior_scale is None

    def core(self, effects: Sequence[_core.Effect] = (), *, covariance: bool = True,
             penalties: Sequence[tuple[str, float]] = (), gravity: Optional[Gravity] = None) -> _core.IdentifyOptions:
        """The core's IdentifyOptions for a model with ``effects`` (``gravity`` overrides the mode)."""
        return options(effects, loss=self.loss, loss_scale_mm=self.loss_scale_mm or 0.0, covariance=covariance,
                       orientation_weight=self.orientation_weight, max_iterations=self.max_iterations,
                       penalties=penalties, prior_sd=self.prior_sd,
                       prior_scale=1.0 if self.prior_scale is None else float(self.prior_scale),
                       gravity=gravity or self.gravity, target_start=self.target_start, noise_mm=self.noise_mm,
                       artifact_sd_mm=self.artifact_sd_mm)

    def fitter(self, robot: Robot, seed: int = 0) -> priors.Fitter:
        """The fit of a data set from the starting model (priors centred there; their width chosen per
        fit by grouped cross-validation when ``prior_scale`` is None)."""
        return priors.Fitter(robot, self.prior_model, auto_scale=self.auto_prior_scale, seed=seed)

    def fit(self, robot: Robot, data: MeasurementSet, effects: Sequence[_core.Effect] = (), *, covariance: bool = False,
            penalties: Sequence[tuple[str, float]] = (), gravity: Optional[Gravity] = None, seed: int = 0,
            progress: Optional[Callable[[int, float], None]] = None) -> _core.IdentifyResult:
        """One fit of ``data`` with these options."""
        return self.fitter(robot, seed)(data, self.core(effects, covariance=covariance, penalties=penalties,
                                                         gravity=gravity), progress)


def options(effects: Sequence[_core.Effect] = (), *, loss: Loss = "huber", loss_scale_mm: float = 0.1,
            covariance: bool = True, orientation_weight: float = 100.0, max_iterations: int = 100,
            fix: Sequence[str] = (), penalties: Sequence[tuple[str, float]] = (),
            prior_sd: Optional[dict[str, float]] = None, prior_scale: float = 0.0,
            gravity: Gravity = "auto", target_start: Optional[Sequence[Sequence[float]]] = None,
            noise_mm: Optional[float] = None, artifact_sd_mm: Optional[float] = None) -> _core.IdentifyOptions:
    """IdentifyOptions for a list of effects (joint_compliance entries switch the compliance of their
    joints on; without any, the compliances stay at their start value). ``penalties``: ridge
    penalties (parameter name, weight in mm per unit of the parameter), e.g. the diagnosis's
    joint_map smoothness penalty. ``prior_sd`` (kinds in file units, priors.DEFAULT_PRIOR_SD) times
    ``prior_scale`` (0: no priors); ``loss_scale_mm`` 0: from the residuals; ``target_start``: each
    target's start on the tool (mm), e.g. a probe's nominal ball offset; ``noise_mm``: the noise per
    coordinate when known (weighs the priors, bends the loss; None: estimated from the residuals)."""
    effects = list(effects)
    o = _core.IdentifyOptions(compliance=any(e.kind.gravity_loaded_only for e in effects), loss=loss, gravity=gravity,
                              loss_scale_mm=loss_scale_mm, max_iterations=max_iterations, fix=list(fix),
                              effects=effects, covariance=covariance, orientation_weight=orientation_weight)
    o.penalties = [(str(n), float(w)) for n, w in penalties]
    o.prior_sd = priors.core_prior_sd(priors.DEFAULT_PRIOR_SD if prior_sd is None else prior_sd)
    o.prior_scale = float(prior_scale) if prior_sd is None or prior_sd else 0.0
    if target_start is not None:
        o.target_start = [np.asarray(t, dtype=float) for t in target_start]
    if noise_mm is not None:
        o.noise_mm = float(noise_mm)
    if artifact_sd_mm is not None:
        o.artifact_sd_mm = float(artifact_sd_mm)
    return o


def folds(data: MeasurementSet, k: int, seed: int = 0) -> list[BoolArray]:
    """k masks of held-out rows, whole configurations per fold, as many as the configurations allow
    (at least 2 configurations; none when fewer)."""
    k = min(k, grouping.configurations(data).count)
    return grouping.folds(data, k, seed) if k >= 2 else []


def rms(e: FloatArray) -> float:
    """The root mean square of errors (of the 3-D distances, or of angles); NaN for none (undefined:
    null in the files, strict_json)."""
    return float(np.sqrt(np.mean(np.square(e)))) if len(e) else float("nan")


def orientation_errors_deg(robot: Robot, data: MeasurementSet) -> FloatArray:
    """Angle (deg) between the measured and the predicted tool orientation of every 6-D row (each
    row seen from its setup's placement, the model's drift at its time)."""
    return np.asarray(_core.orientation_errors(robot, data))


def point_errors(res: _core.IdentifyResult, data: MeasurementSet) -> FloatArray:
    """3-D distance (mm) between each measured point and the fitted model's prediction (a probe row's
    error along its constraint, against the fit's station)."""
    return np.asarray(_core.point_errors(res.robot, res.targets, data, res.stations))


def masses(robot: Robot) -> bool:
    """Whether the robot's model has link masses (--gravity auto then uses them)."""
    return any(j.mass_kg > 0 for j in robot.nominal_spec.joints)


def gravity_fitted(robot: Robot, gravity: str) -> bool:
    """Whether the compliances' torques come from fitted mass moments (the core's rule)."""
    return gravity == "fit" or (gravity == "auto" and not masses(robot))
