"""The linearisation of a fit, for scoring candidate effects: the identification's residual and
Jacobian at a fit with more effects' parameters appended, which rows carry equations, and the fit's
priors as pseudo-rows (effect_choice's candidates and the diagnosis's residual variables use them)."""

from __future__ import annotations

from typing import TYPE_CHECKING, Optional, Sequence

import numpy as np

from .. import _core

if TYPE_CHECKING:
    from .._core import MeasurementSet
    from ..typing_ import BoolArray, FloatArray


def _key(p: _core.Parameter) -> tuple[str, int, int, str]:
    return (p.kind, p.joint, p.target, p.name)


def evaluate(res: _core.IdentifyResult, data: MeasurementSet, extra: Sequence[_core.Effect]
             ) -> tuple[FloatArray, FloatArray, FloatArray, list[_core.Parameter], dict[int, int]]:
    """The identification residual r and Jacobian J at a fit ``res`` with the ``extra`` effects'
    parameters appended (at zero): (r, the fit's free columns, J, the parameters, the fit's
    parameter index of each of them that is the fit's, by index)."""
    layout = res.layout
    pm = _core.PointModel(res.robot, len(res.targets), list(layout.effect_list) + list(extra), res.t_ref, True,
                          stations_of=layout)
    new = pm.layout.parameters
    old = {_key(p): p.index for p in layout.parameters}
    # the fit's parameters by name, not by place: the calibrated model may carry one the fit's did not
    # (a joint 1 whose identified tilt puts it under gravity gains a compliance, inserted before the
    # targets); an extra effect may repeat one of the fit's (its names come again, after the fit's)
    fit_of: dict[int, int] = {}
    taken: set[int] = set()
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


def equations(data: MeasurementSet) -> Optional[BoolArray]:
    """Per row and position coordinate, whether it carries an equation (a plane's or a ballbar's row
    has one: its first); None when every row has three."""
    station = np.asarray(data.station) if data.station is not None else np.full(len(data), -1)
    kinds = data.station_kinds or []
    one = np.array([s >= 0 and kinds[s] in ("plane", "distance") for s in station], dtype=bool)
    if not one.any():
        return None
    used = np.ones((len(station), 3), dtype=bool)
    used[one, 1:] = False
    return used


def prior_rows(res: _core.IdentifyResult, data: MeasurementSet, fit_of: dict[int, int]
                ) -> Optional[tuple[FloatArray, FloatArray]]:
    """On probe data, the fit's priors as pseudo-rows of the linearisation: for each of its free
    columns with a prior, noise / sd times the parameter's distance from the prior's centre, and
    noise / sd in its column (the fit's own weighting: priors.cpp's prior_terms). The fit of probe
    data is a maximum a posteriori one: without its priors the free geometry with the stations'
    unknowns (no prior) spans nearly every candidate's columns (a sphere campaign's compliance down to
    2.6e-5 mm), and a candidate the priors leave room for scores nothing. Tracker data keep the plain
    linearisation (their geometry is the data's; with these rows the UR10 series took transmission
    errors their folds do not support). None: no pseudo-rows."""
    if data.station is None or not np.any(np.asarray(data.station) >= 0):
        return None
    fixed, sd = np.asarray(res.fixed), np.asarray(res.prior_sd, dtype=float)
    x, x0 = np.asarray(res.x, dtype=float), np.asarray(res.start, dtype=float)
    cols = [k for k in fit_of.values() if not fixed[k]]  # the current columns' parameters, in order
    rows = [c for c, k in enumerate(cols) if np.isfinite(sd[k])]
    P = np.zeros((len(rows), len(cols)))
    rp = np.zeros(len(rows))
    for i, c in enumerate(rows):
        w = res.noise_mm / sd[cols[c]]
        P[i, c] = w
        rp[i] = w * (x[cols[c]] - x0[cols[c]])
    return P, rp
