"""The robust pseudo-residual on which the effect choice scores its candidates: each row's residual
weighed as a Huber (or Cauchy) loss weighs it, bending where the residual's own robust spread puts
it (the core's robust_noise and loss_threshold, priors.cpp, as Python sees them)."""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Optional

import numpy as np

if TYPE_CHECKING:
    from ..typing_ import BoolArray, FloatArray


def robust_weights(r: FloatArray, dims: int, loss: str, scale_mm: float) -> FloatArray:
    """The robust loss's weights at a fit, one per residual coordinate: each row (``dims``
    coordinates) weighed as the fit's loss weighs its residual norm (Huber: scale / norm beyond the
    scale; Cauchy: 1 / (1 + (norm / scale)^2)); ones without a robust loss. The candidates are scored
    on the pseudo-residuals w r (Huber's pseudo-observations: a row's residual clipped at the scale),
    so that a gross outlier cannot pass for an effect nor drown one."""
    norm = np.linalg.norm(np.asarray(r).reshape(-1, dims), axis=1)
    if loss == "none" or not scale_mm or scale_mm <= 0:
        w = np.ones_like(norm)
    elif loss == "cauchy":
        w = 1.0 / (1.0 + (norm / scale_mm) ** 2)
    else:
        w = np.minimum(1.0, scale_mm / np.maximum(norm, 1e-300))
    return np.repeat(w, dims)


def robust_noise(r: FloatArray, dims: int, p: int, used: Optional[BoolArray] = None) -> float:
    """The residuals' robust spread per coordinate (the core's robust_noise: 1.4826 x the median
    absolute deviation of the position coordinates, for p parameters). ``used``: per row and
    position coordinate, whether it carries an equation (a plane's or a ballbar's row has one, its
    other two are zero: counted, they would put the median at zero)."""
    v = np.asarray(r).reshape(-1, dims)[:, :3]
    v = v[np.asarray(used).reshape(v.shape)] if used is not None else v.ravel()
    if not len(v):
        return 1e-4
    mad = float(np.median(np.abs(v - np.median(v))))
    return max(1e-4, 1.4826 * mad * math.sqrt(len(v) / max(1.0, len(v) - p)))


def loss_threshold(noise_mm: float, dims: int) -> float:
    """Where the robust loss bends for a residual spread (the core's loss_threshold: the 99.9% point
    of a row's residual norm)."""
    return noise_mm * math.sqrt(22.458 if dims == 6 else 16.266)
