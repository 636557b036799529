"""Identification: our Ceres identification against scipy.optimize.least_squares."""

from __future__ import annotations

import numpy as np

from kincal import _core, load_robot
from kincal.calibration import identify as ident
from kincal.calibration import priors

from .numpy_model import NumpyPointModel
from .timing import median_ms


def bench_identify(poses: int, seed: int, repeats: int = 5) -> dict:
    """Identification on a simulated kr500 campaign (truth: default_truth(seed), one target, 0.02 mm
    noise), plain least squares. scipy_numpy_identify_ms: scipy.optimize.least_squares on the same
    residuals written in numpy (numpy_model.py, checked against ours in the tests) with its 2-point
    Jacobian, what a script has. identify_ms: our Ceres identification (analytic Jacobian; both
    stages, the identifiability analysis; without the covariance, which is
    identify_with_covariance_ms); scipy_identify_ms: scipy.optimize.least_squares ('trf') on the
    same residual function from our core with its own finite-difference Jacobian ('2-point', what a
    user without our Jacobian has); scipy_analytic_identify_ms: the same with our analytic
    Jacobian. scipy starts from the output of our first stage (a head start); each reports its
    final cost."""
    from scipy.optimize import least_squares

    robot = load_robot("kr500")
    truth = ident.default_truth(robot, seed=seed)
    data = ident.simulate(truth, poses, seed=seed, targets=1)

    opts = _core.IdentifyOptions(compliance=True, loss="none", covariance=False)
    opts_cov = _core.IdentifyOptions(compliance=True, loss="none", covariance=True)
    ours, res = median_ms(lambda: _core.identify(robot, data, opts), repeats)
    ours_cov, _ = median_ms(lambda: _core.identify(robot, data, opts_cov), repeats)
    # the defaults of `kincal identify`: priors and the robust loss scaled by the data, against the
    # identification before them (Huber at a fixed 0.1 mm, no priors)
    old = _core.IdentifyOptions(compliance=True, loss="huber", loss_scale_mm=0.1, covariance=False)
    new = _core.IdentifyOptions(compliance=True, loss="huber", loss_scale_mm=0.0, covariance=False, prior_scale=1.0,
                                prior_sd=priors.core_prior_sd(priors.DEFAULT_PRIOR_SD))
    old_ms, _ = median_ms(lambda: _core.identify(robot, data, old), repeats)
    map_ms, _ = median_ms(lambda: _core.identify(robot, data, new), repeats)
    pm = _core.PointModel(robot, 1)
    free = ~np.asarray(res.fixed)
    # scipy starts where our second stage starts (after our first stage fitted the base frame and
    # target on the nominal geometry): the held parameters then have the same values in both
    x0 = np.asarray(res.nominal_x, dtype=float)

    def full(z):
        x = x0.copy()
        x[free] = z
        return x

    def fun(z):
        return pm.residuals(full(z), data, False)[0]

    def jac(z):
        return pm.residuals(full(z), data, True)[1][:, free]

    tol = dict(method="trf", xtol=1e-12, ftol=1e-12, gtol=1e-12)
    # the baselines take a median of three runs too (one run moved by 30% on a loaded machine)
    fd_ms, fd = median_ms(lambda: least_squares(fun, x0[free], jac="2-point", **tol), 3)
    an_ms, an = median_ms(lambda: least_squares(fun, x0[free], jac=jac, **tol), max(1, repeats // 2))
    # what a script has: the same measurement model written in numpy, scipy's own Jacobian
    npm = NumpyPointModel(robot, 1)
    np_ms, npr = median_ms(lambda: least_squares(lambda z: npm.residuals(full(z), data), x0[free], jac="2-point",
                                                 **tol), 3)
    return {"identify_poses": poses, "identify_parameters": res.layout.size,
            "identify_free_parameters": int(free.sum()), "identify_ms": ours,
            "identify_with_covariance_ms": ours_cov, "identify_huber_fixed_ms": old_ms,
            "identify_map_data_scaled_ms": map_ms, "identify_map_ratio": map_ms / old_ms, "scipy_numpy_identify_ms": np_ms,
            "identify_speedup_vs_scipy_numpy": np_ms / ours, "scipy_numpy_identify_cost": float(npr.cost),
            "scipy_identify_ms": fd_ms,
            "scipy_analytic_identify_ms": an_ms, "identify_speedup_vs_scipy": fd_ms / ours,
            "identify_speedup_vs_scipy_analytic": an_ms / ours, "identify_cost": res.final_cost,
            "scipy_identify_cost": float(fd.cost), "scipy_analytic_identify_cost": float(an.cost)}
