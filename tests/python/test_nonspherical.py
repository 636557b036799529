"""A robot without a closed-form IK (the UR10: no spherical wrist): compensation starts from the
previous pose, and from a numerical IK when that fails, and lands on every pose."""

from __future__ import annotations

import numpy as np

import kincal


def test_ur10_compensation_without_closed_form_ik():
    """truth: the built-in ur10 with 1 mm / 0.05 deg errors (seed 3); 200 random configurations
    inside +-170 deg give the desired poses, compensated one by one from home: every pose is reached
    to 1e-6 mm and 1e-6 deg, inside the joint limits."""
    robot = kincal.load_robot("ur10")
    assert not robot.closed_form_ik
    cal = robot.with_calibrated(3, 1.0, 0.05, 0.0)
    rng = np.random.default_rng(4)
    q = rng.uniform(-170, 170, size=(200, 6))
    poses = kincal.fk(cal, q)
    for p in poses:
        res = kincal.compensate(cal, [p])
        reached = kincal.fk(cal, res["q_deg"])[0]
        assert np.max(np.abs(reached[:3] - p[:3])) < 1e-6
        d = (reached[3:] - p[3:] + 180) % 360 - 180
        assert np.max(np.abs(d)) < 1e-6


def test_ur10_program_keeps_its_branch():
    """A 400 mm line at constant orientation: consecutive joint solutions stay within 5 deg."""
    robot = kincal.load_robot("ur10")
    cal = robot.with_calibrated(5, 1.0, 0.05, 0.0)
    p0 = kincal.fk(cal, [[20, -110, 90, -70, -90, 10]])[0]
    poses = np.array([p0 + np.r_[0, 5.0 * i, 0, 0, 0, 0] for i in range(81)])
    q = kincal.compensate(cal, poses)["q_deg"]
    assert np.max(np.abs(np.diff(q, axis=0))) < 5.0
    assert np.max(np.abs(kincal.fk(cal, q)[:, :3] - poses[:, :3])) < 1e-6
