"""Fits that converge or say so (issue 29, item 3): the result, the summary and the model JSON say
whether the Levenberg-Marquardt passes converged and why they stopped; the fitted-moments fit (no
masses in the model) of a small campaign converges well within the iteration cap."""

from __future__ import annotations

import json
import re

import numpy as np
import pytest

import kincal
from kincal import _core
from kincal.calibration import identify as ident
from kincal.io.urdf import spec_urdf

NOISE_MM = 0.02  # the simulated tracker's noise per coordinate


@pytest.fixture(scope="module")
def robots(tmp_path_factory, kr500):
    """The kr500 as a URDF with its masses, and the same URDF without its inertial tags."""
    d = tmp_path_factory.mktemp("convergence")
    text = spec_urdf(json.loads(kr500.to_json())["nominal"], "kr500")
    stripped = re.sub(r"\s*<inertial>.*?</inertial>", "", text, flags=re.S)
    assert "<inertial>" not in stripped
    (d / "with.urdf").write_text(text)
    (d / "without.urdf").write_text(stripped)
    return kincal.load_robot(str(d / "with.urdf")), kincal.load_robot(str(d / "without.urdf"))


def _campaign(robot, poses: int, seed: int) -> tuple:
    # truth: the robot with 1 mm / 0.05 deg geometric errors and compliance 0.003 deg/kNm x U(0.5, 1.5)
    # per loaded joint; `poses` configurations x 3 reflectors with 0.02 mm noise per coordinate to fit,
    # 200 other configurations (the same noise) held out
    truth = ident.default_truth(robot, seed=seed, compliance=0.003)
    return (ident.simulate(truth, poses, seed=seed, noise_mm=NOISE_MM, targets=3),
            ident.simulate(truth, 200, seed=seed + 100, noise_mm=NOISE_MM, targets=3))


def _rms(res: ident.Identification, data: kincal.MeasurementSet) -> float:
    return float(np.sqrt(np.mean(np.asarray(_core.point_errors(res.robot, res.targets, data)) ** 2)))


def test_a_fit_stopped_at_its_cap_says_so(robots):
    # the fitted-moments fit of 20 configurations, each pass capped at 2 iterations: not converged, in
    # the result, the summary's line and the JSON, with the solver's reason
    with_masses, without = robots
    fit, _ = _campaign(with_masses, 20, seed=1)
    r = ident.identify(without, fit, k_folds=0, max_iterations=2)
    assert not r.fit.converged
    assert r.fit.stop_reason.startswith("NO_CONVERGENCE") and "cap of 2 iterations" in r.fit.stop_reason
    lines = r.summary().splitlines()
    flagged = [ln for ln in lines if ln.startswith("did not converge: ")]
    assert len(flagged) == 1 and "NO_CONVERGENCE" in flagged[0] and "--max-iterations" in flagged[0]
    doc = json.loads(r.model_json())["identification"]
    assert doc["converged"] is False and doc["stop_reason"] == r.fit.stop_reason


@pytest.mark.parametrize("gravity_source", ["masses", "fit"])
def test_a_normal_fit_says_it_converged(robots, gravity_source):
    with_masses, without = robots
    fit, _ = _campaign(with_masses, 40, seed=2)
    r = ident.identify(with_masses if gravity_source == "masses" else without, fit, k_folds=0)
    assert r.fit.layout.gravity == gravity_source
    assert r.fit.converged and r.fit.stop_reason.startswith("CONVERGENCE: ")
    assert not any(ln.startswith("did not converge") for ln in r.summary().splitlines())
    doc = json.loads(r.model_json())["identification"]
    assert doc["converged"] is True and doc["stop_reason"] == r.fit.stop_reason


@pytest.mark.parametrize("poses,seed", [(15, 9), (18, 6), (20, 1), (25, 3)])
def test_fitted_moments_of_a_small_campaign_converge_within_the_cap(robots, poses, seed):
    # the campaign of the issue (15-25 configurations x 3 reflectors, no masses in the model,
    # --gravity auto: the moments fitted): the fit on every row and each grouped-cross-validation
    # fold's fit converge, in fewer iterations (both robust passes together) than one pass's cap of
    # 100 (measured: at most 51 over 150 fold fits and 35 over 30 whole fits; before this change up to
    # 152, a pass at its cap), and the model predicts the held-out configurations far better than the
    # geometry alone (the symptom was a fit worse than that)
    with_masses, without = robots
    fit, held = _campaign(with_masses, poses, seed)
    r = ident.identify(without, fit, k_folds=0)
    assert r.fit.layout.gravity == "fit"
    assert r.fit.converged, r.fit.stop_reason
    assert r.fit.iterations < 100
    for mask in ident.folds(fit, 5, 0):
        f = ident.identify(without, ident.subset(fit, ~mask), k_folds=0)
        assert f.fit.converged and f.fit.iterations < 100, (f.fit.iterations, f.fit.stop_reason)
    rigid = ident.identify(without, fit, effects="none", k_folds=0)
    assert _rms(r, held) < 0.5 * _rms(rigid, held)
