"""`kincal plan --kind`: the touches at each probe station, and the TCP uncertainty they promise.

Truth: kincal simulate's default truth (ident.default_truth: the kr500 with 1 mm / 0.05 deg geometric
errors and joint compliance of about 0.003 deg/kNm), one per seed 1-5. The planned touches are made on
the truth by probe_plan.measure (the ball where the plan puts it, the truth's angles, the probe's noise
along each constraint: 0.005 mm on a sphere's coordinates, 0.002 mm on a ballbar's length), fitted
with identify (--effects joint_compliance, the probe's nominal offset as the start of its fit) and
scored as BENCHMARKS.md scores them: the ball centre's RMS over 200 configurations drawn within 90% of each of the
limits against the noise-free truth, after the best rigid transform."""

from __future__ import annotations

import json

import numpy as np
import pytest

import kincal
from kincal import _core
from kincal.calibration import identify as ident
from kincal.calibration.probe_plan import ball_centres as _balls, rigid_rms as _rigid_rms
from kincal.calibration import probe_plan as pp
from kincal.calibration.fitting import FitOptions

from conftest import run

PROBE = np.array([0.0, 0.0, 150.0])


def test_plan_writes_the_touches_and_the_stations_artifact(tmp_path):
    out = tmp_path / "p.csv"
    r = run("kincal", "plan", "--robot", "kr500", "--kind", "sphere", "--stations", "3", "--touches", "8", "--cone",
            "60", "--candidates", "80", "--out", str(out))
    assert r.returncode == 0, r.stderr
    robot = kincal.load_robot("kr500")
    data = ident.read_measurements(str(out), robot, str(tmp_path / "p-artifact.csv"))
    assert len(data["pose"]) == 24 and data["station_names"] == ["S1", "S2", "S3"]
    assert np.all(np.bincount(data["station"]) == 8)
    assert len(data["artifact"]) == 2  # the distances of S2 and S3 from S1, as placed
    line = next(s for s in r.stdout.splitlines() if s.startswith("predicted TCP uncertainty"))
    assert "in the median campaign" in line and "random touches" in line
    # the planned angles reach the stations: every row's nominal ball centre at its sphere's
    ball = _balls(robot, _core.joints_from_controller(robot, data["q_deg"]), PROBE)
    for s in range(3):
        mine = ball[data["station"] == s]
        assert np.max(np.linalg.norm(mine - mine.mean(axis=0), axis=1)) < 1e-6


@pytest.mark.parametrize("argv, expect", [
    (["--kind", "plane", "--stations", "6"], "a block has 5 faces"),
    (["--kind", "sphere", "--touches", "10", "--candidates", "5"], "--candidates (5) must be at least --touches (10)"),
    (["--kind", "sphere", "--probe", "0,150"], "--probe 0,150: expected X,Y,Z"),
    (["--kind", "distance", "--noise", "0"], "--noise must be a positive number"),
    (["--kind", "sphere", "--poses", "40"], "--poses: tracker campaign options"),
])
def test_bad_plan_input(tmp_path, argv, expect):
    r = run("kincal", "plan", "--robot", "kr500", *argv, "--out", str(tmp_path / "p.csv"))
    assert r.returncode == 1, r.stderr
    assert expect in r.stderr, r.stderr
    assert not (tmp_path / "p.csv").exists() and not (tmp_path / "p-artifact.csv").exists()


def test_measure_makes_the_touches_on_the_truth():
    # noise-free: the truth's ball centres of a sphere station coincide, a ballbar's lie at its length
    robot = kincal.load_robot("kr500")
    truth = ident.default_truth(robot, seed=2)
    for kind in ("sphere", "distance"):
        plan = pp.plan_probe(robot, kind, stations=2, touches=6, cone_deg=40, candidates=40, seed=3)
        made = pp.measure(truth, plan.data, PROBE, noise_mm=0.0)
        ball = _balls(truth, made["q_deg"], PROBE)
        planned = _balls(robot, plan.data["q_deg"], PROBE)
        assert np.max(np.linalg.norm(ball - planned, axis=1)) < 1e-6  # where the plan put the ball
        assert np.max(np.abs(made["q_deg"] - plan.data["q_deg"])) > 1e-3  # reached by the truth's own angles


@pytest.mark.parametrize("kind, stations, touches, noise, block", [
    ("sphere", 6, 25, 0.005, 400.0),
    ("plane", 5, 40, 0.005, 500.0),     # a 500 mm block's top, 3 sides and the plate it stands on
    ("distance", 4, 40, 0.002, 400.0),
])
def test_the_plans_prediction_matches_what_its_campaigns_reach(kind, stations, touches, noise, block):
    robot = kincal.load_robot("kr500")
    lim = np.asarray(robot.limits_deg)
    q = np.random.default_rng(7).uniform(0.9 * lim[:, 0], 0.9 * lim[:, 1], size=(200, 6))
    predicted, measured = [], []
    for seed in range(1, 6):
        plan = pp.plan_probe(robot, kind, stations=stations, touches=touches, cone_deg=60, probe=PROBE,
                             block_mm=block, noise_mm=noise, configurations=q, seed=seed)
        truth = ident.default_truth(robot, seed=seed)
        fit = ident.identify(robot, pp.measure(truth, plan.data, PROBE, noise, seed=seed), effects=["joint_compliance"],
                             k_folds=0, fit=FitOptions(target_start=[PROBE]))
        predicted.append(plan.tcp_uncertainty_mm)
        measured.append(_rigid_rms(_balls(fit.robot, q, np.asarray(fit.targets)[0]), _balls(truth, q, PROBE)))
        # predicted, the plan's touches beat as many drawn at random from the same pools (measured, a
        # random campaign at other stations may do as well: BENCHMARKS.md)
        assert plan.tcp_uncertainty_mm < plan.random_tcp_uncertainty_mm
    p, m = float(np.median(predicted)), float(np.median(measured))
    print(f"{kind}: predicted {np.round(predicted, 4)}, measured {np.round(measured, 4)} mm")
    # issue 32's marks: at most 0.05 mm, the prediction within 25% (both medians of 5 seeds). Fixed
    # seeds: one campaign's RMS scatters widely about its expectation (the faces': 0.01-0.05 mm), so
    # this holds the measured ground, it does not calibrate the prediction. Predicted / measured on
    # seeds 1-5: spheres 1.244, faces 1.064, ballbar 1.055. On other groups of five seeds (6-30, an
    # audit in the thirty-second session) 1.07-1.32, 0.77-3.38 and 0.67-1.51: the item is met on
    # these seeds only (BENCHMARKS.md, "Claims that held on one draw, audited")
    assert m <= 0.05 and abs(p / m - 1) <= 0.25, (p, m)


def test_identify_probe_start_is_checked_and_places_the_ball(tmp_path):
    # a ballbar campaign planned at 4 pivots (seed 2): identified from the tool frame's origin the
    # pivots started through points 150 mm off the balls (40-120 mm off after the fit, before the
    # start used --probe); with it the fit places the ball within 0.05 mm (the mark; the plan
    # promised 0.010)
    robot = kincal.load_robot("kr500")
    truth = ident.default_truth(robot, seed=2)
    plan = pp.plan_probe(robot, "distance", stations=4, touches=40, cone_deg=60, noise_mm=0.002, seed=2)
    data = pp.measure(truth, plan.data, PROBE, 0.002, seed=2)
    (tmp_path / "b.csv").write_text(ident.measurements_csv(data, 6))
    (tmp_path / "a.csv").write_text(_core.format_artifact(data, 6))
    argv = ["identify", "--robot", "kr500", "--data", str(tmp_path / "b.csv"), "--artifact", str(tmp_path / "a.csv"),
            "--effects", "joint_compliance", "--folds", "0", "--out", str(tmp_path / "m.json")]
    r = run("kincal", *argv, "--probe", "0,0,150")
    assert r.returncode == 0, r.stderr
    fit = kincal.load_robot(str(tmp_path / "m.json"))
    target = np.asarray(json.loads((tmp_path / "m.json").read_text())["identification"]["targets_mm"][0])
    assert np.linalg.norm(target - PROBE) < 5.0  # measured 2.5 mm: the ball's offset carries the truth's tool error
    lim = np.asarray(robot.limits_deg)
    q = np.random.default_rng(7).uniform(0.9 * lim[:, 0], 0.9 * lim[:, 1], size=(200, 6))
    assert _rigid_rms(_balls(fit, q, target), _balls(truth, q, PROBE)) < 0.05
    r = run("kincal", *argv[:-1], str(tmp_path / "m2.json"), "--probe", "0,0")
    assert r.returncode == 1 and "--probe 0,0: expected X,Y,Z" in r.stderr
    with pytest.raises(_core.InputError, match="2 target start"):
        ident.identify(robot, data, effects="none", k_folds=0, fit=FitOptions(target_start=[PROBE, PROBE]))


def test_a_calibrated_model_is_planned_at_its_nominal_one():
    # a model file from an earlier calibration (here a simulated truth: nominal and calibrated differ by
    # about 1 mm) plans as its nominal model does, where identify starts
    robot = kincal.load_robot("kr500")
    truth = ident.default_truth(robot, seed=2)
    a = pp.plan_probe(truth, "sphere", stations=2, touches=6, cone_deg=40, candidates=40, seed=3)
    b = pp.plan_probe(robot, "sphere", stations=2, touches=6, cone_deg=40, candidates=40, seed=3)
    assert np.array_equal(a.data["q_deg"], b.data["q_deg"]) and a.tcp_uncertainty_mm == b.tcp_uncertainty_mm


def test_residuals_of_chosen_columns_are_those_of_the_whole_jacobian():
    """PointModel.residuals(columns=...): the Jacobian of those parameters only, artifact terms
    included, equals the whole Jacobian's columns (a planned sphere campaign with its distances;
    the planner asks for the free columns only); a column outside the layout is refused."""
    robot = kincal.load_robot("kr500")
    pool = pp._pool(robot, "sphere", 5, stations=3, touches=5, cone_deg=35.0, probe=np.array([0.0, 0.0, 150.0]),
                    radius_mm=3.0, length_mm=150.0, block_mm=400.0, seed=3)
    assert len(pool["artifact"]) > 0
    res = _core.identify(robot, pool, pp.options([], loss="none", max_iterations=0, covariance=False, prior_sd=None,
                                                 prior_scale=1.0, target_start=[[0.0, 0.0, 150.0]]))
    pm = _core.PointModel(robot, 1, [], stations_of=res.layout)
    x = list(res.start)
    r_all, J_all = pm.residuals(x, pool, True, artifact=True)
    cols = [0, 7, 12, len(x) - 1, 3]
    r_some, J_some = pm.residuals(x, pool, True, artifact=True, columns=cols)
    assert np.asarray(J_some).shape == (len(r_all), len(cols))
    np.testing.assert_array_equal(np.asarray(r_some), np.asarray(r_all))
    np.testing.assert_array_equal(np.asarray(J_some), np.asarray(J_all)[:, cols])
    with pytest.raises(_core.InputError, match="column"):
        pm.residuals(x, pool, True, columns=[len(x)])
