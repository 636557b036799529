"""kincal plan: D-optimal campaign planning (simulated kr500 truths; the measurements are the truth's
target points in the instrument frame plus Gaussian noise of 0.02 mm per coordinate)."""

from __future__ import annotations

import numpy as np
import pytest

import kincal
from kincal import _core
from kincal.calibration import plan
from kincal.calibration import identify as ident

from conftest import run

TARGETS = ident.DEFAULT_TARGETS[:3]
NOISE = 0.02


def _measure(truth, q: np.ndarray, noise: float, seed: int) -> kincal.MeasurementSet:
    """The truth's target points (instrument frame, every effect it carries) at q, plus noise."""
    pose = np.asarray(_core.fk(truth, q, True, True))
    R = np.stack([_core.abc_to_rotation(p[3:]) for p in pose])
    pts = (R[:, None] @ TARGETS[None, :, :, None])[..., 0] + pose[:, None, :3]
    d = plan._campaign(truth, q, TARGETS)
    return d.with_columns(xyz=pts.reshape(-1, 3) + np.random.default_rng(seed).normal(0.0, noise,
                                                                                       (len(q) * len(TARGETS), 3)))


def _held_rms(res, truth, q) -> float:
    e = _core.point_errors(res.robot, res.targets, _measure(truth, q, 0.0, 0))
    return float(np.sqrt(np.mean(e ** 2)))


@pytest.fixture(scope="module")
def robot():
    return kincal.load_robot("kr500")


def test_planned_configurations_beat_random_ones(robot):
    """15 truths (default_truth seeds 1-15: 1 mm / 0.05 deg geometric errors, compliance), 3,000 random
    candidates each: 30 planned configurations against 30 random ones of the same candidates, both
    identified (geometry + compliance) from noisy measurements; error on 300 other candidates (whole
    configurations held out) against the noise-free truth. This test took truths 1-5 and asserted a
    median ratio of at most 0.85 (0.844 there); over truths 1-40 (an audit, thirty-second session) the
    ratios ran 0.53-1.19 with a median of 0.847, and two of the eight groups of five had medians of
    0.877 and 0.921: a planned campaign is some 15% better in the median, not on every draw. Over
    truths 1-15 the median is 0.844; asserted (a statement of those draws): at most 0.9."""
    ratios = []
    for s in range(15):
        truth = ident.default_truth(robot, seed=s + 1)
        every = plan.random_candidates(robot, 3300, seed=100 + s)
        held, cand = every[:300], every[300:]   # held-out configurations are never candidates
        p = plan.plan(robot, 30, targets=TARGETS, candidates=cand, seed=s)
        rng = np.random.default_rng(s)
        rand = cand[rng.choice(len(cand), 30, replace=False)]
        planned = ident.identify(robot, _measure(truth, p.q_deg, NOISE, s), k_folds=0)
        random = ident.identify(robot, _measure(truth, rand, NOISE, s), k_folds=0)
        ratios.append(_held_rms(planned, truth, held) / _held_rms(random, truth, held))
    print("planned / random:", np.round(ratios, 3))
    assert np.median(ratios) <= 0.9, ratios


def test_predicted_tcp_uncertainty_matches_a_noise_only_truth(robot):
    """Truth: the nominal geometry with compliance 0.003 deg/kN m, no geometric error (a noise-only
    truth); 5 noise draws of the planned campaign. The plan's predicted TCP uncertainty is within 25%
    of the measured RMS error at the candidates (RMS over the 5 draws)."""
    cand = plan.random_candidates(robot, 3000, seed=7)
    p = plan.plan(robot, 30, targets=TARGETS, candidates=cand, noise_mm=NOISE)
    truth = robot.with_calibrated(0, 0.0, 0.0, 0.003, ident.DEFAULT_INSTRUMENT)
    sq = [_held_rms(ident.identify(robot, _measure(truth, p.q_deg, NOISE, 50 + s), k_folds=0), truth, cand) ** 2
          for s in range(5)]
    measured = float(np.sqrt(np.mean(sq)))
    assert abs(p.tcp_uncertainty_mm - measured) <= 0.25 * measured, (p.tcp_uncertainty_mm, measured)


def test_greedy_is_the_plain_greedy_on_small_pools():
    """On fewer candidates than the stochastic sample, each step scores every candidate: the choice is
    the plain greedy's (recomputed here with full determinants on random rows)."""
    rng = np.random.default_rng(3)
    J = rng.normal(size=(300 * 3, 8))
    chosen = plan.greedy_d_optimal(J, 3, 6, ridge=1e-3)
    M = 1e-3 * np.eye(8)
    ref = []
    for _ in range(6):
        base = np.linalg.slogdet(M)[1]
        gains = [(-np.inf if i in ref else np.linalg.slogdet(M + J[3 * i:3 * i + 3].T @ J[3 * i:3 * i + 3])[1] - base)
                 for i in range(300)]
        ref.append(int(np.argmax(gains)))
        M = M + J[3 * ref[-1]:3 * ref[-1] + 3].T @ J[3 * ref[-1]:3 * ref[-1] + 3]
    assert chosen == ref


def test_keep_out_rules(robot):
    """Every chosen configuration obeys the joint limits, the box and the instrument's range and
    incidence; the path order is a nearest-neighbour tour."""
    box = (500.0, 3000.0, -2000.0, 2000.0, 200.0, 2500.0)
    rules = plan.KeepOut(box=box, instrument=(3500.0, -1500.0, 0.0), max_range=5000.0, max_incidence_deg=75.0,
                         min_sigma=0.02)
    p = plan.plan(robot, 12, targets=TARGETS, n_candidates=4000, rules=rules)
    ok, _ = plan.keep_out(robot, p.q_deg, TARGETS, rules)
    assert ok.all() and len(p.q_deg) == 12
    tcp = plan._tool_frames(robot, p.q_deg)[:, :3, 3]
    b = np.asarray(box).reshape(3, 2)
    assert np.all((tcp >= b[:, 0]) & (tcp <= b[:, 1]))
    for i in range(1, len(p.q_deg) - 1):   # each next one is the nearest of those left
        left = p.q_deg[i:]
        assert np.argmin(np.linalg.norm(left - p.q_deg[i - 1], axis=1)) == 0


def test_cli_plan_and_errors(tmp_path):
    r = run("kincal", "plan", "--robot", "kr500", "--poses", "15", "--targets", "2", "--out", str(tmp_path / "q.csv"),
            "--candidates", "2000")
    assert r.returncode == 0, r.stderr
    assert "predicted TCP uncertainty" in r.stdout and "predicted standard deviation" in r.stdout
    q = np.loadtxt(tmp_path / "q.csv", delimiter=",", skiprows=1)
    assert q.shape == (15, 6)
    r = run("kincal", "plan", "--robot", "kr500", "--poses", "15", "--out", str(tmp_path / "bad.csv"),
            "--box", "0,1,0,1,0,1")
    assert r.returncode != 0 and "fewer than the 15 poses" in r.stderr and not (tmp_path / "bad.csv").exists()
    r = run("kincal", "plan", "--robot", "kr500", "--poses", "5", "--out", str(tmp_path / "bad.csv"),
            "--box", "0,1")
    assert r.returncode != 0 and "--box 0,1: expected 6" in r.stderr
