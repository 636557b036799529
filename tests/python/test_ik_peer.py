"""Our Paden-Kahan IK against an independent implementation from PyPI (EAIK, subproblem
decomposition), on random poses of the built-in kr500: the same exact solution sets."""

from __future__ import annotations

import json

import numpy as np
import pytest

import kincal
from kincal import _core

from conftest import count, random_q

eaik_hp = pytest.importorskip("eaik.IK_HP")


def _eaik_robot(robot: kincal.Robot):
    spec = json.loads(robot.to_json())["nominal"]
    pts = np.array([j["point_mm"] for j in spec["joints"]])
    axes = np.array([j["axis"] for j in spec["joints"]], dtype=float)
    p = np.vstack([pts[0], np.diff(pts, axis=0), np.asarray(spec["tool"]["xyz_mm"]) - pts[-1]])
    return eaik_hp.HPRobot(axes, p)


def _wrapped(a: np.ndarray) -> np.ndarray:
    return (np.asarray(a) + 180.0) % 360.0 - 180.0


@pytest.mark.peer
def test_same_solution_sets_as_eaik(kr500):
    peer = _eaik_robot(kr500)
    assert peer.hasKnownDecomposition()
    m0 = _core.fk_matrix(kr500, np.zeros(6))[:3, :3]
    rng = np.random.default_rng(41)
    compared = 0
    for q in random_q(kr500, rng, count(300)):
        t = _core.fk_matrix(kr500, q)
        pose = kincal.fk(kr500, q)[0]
        ours = np.array([s["q_deg"] for s in kincal.ik(kr500, pose, q)])
        te = t.copy()
        te[:3, :3] = t[:3, :3] @ m0.T  # EAIK's tool frame is the base orientation at q = 0
        sol = peer.IK(te)
        theirs = np.degrees(np.asarray(sol.Q))[~np.asarray(sol.is_LS, dtype=bool)]
        assert len(ours) == len(theirs), (q, ours, theirs)
        for s in theirs:  # every exact peer solution is one of ours (mod 360)
            d = np.abs(_wrapped(ours - s)).max(axis=1)
            assert d.min() < 1e-7, (q, s, ours)
        # FK(IK(T)) = T for all of ours
        for s in ours:
            ts = _core.fk_matrix(kr500, s)
            assert np.abs(ts[:3, 3] - t[:3, 3]).max() < 1e-9
            assert np.abs(ts[:3, :3] - t[:3, :3]).max() < 1e-12
        compared += 1
    assert compared == count(300)


def test_out_of_reach_is_an_empty_answer(kr500):
    assert kincal.ik(kr500, [9000, 0, 1000, 0, 90, 0]) == []


def test_solutions_flag_joint_limits(kr500):
    q = np.array([10.0, -60.0, 80.0, 30.0, 40.0, -20.0])
    sols = kincal.ik(kr500, kincal.fk(kr500, q)[0], q)
    assert 1 <= len(sols) <= 8
    lim = np.asarray(kr500.limits_deg)
    for s in sols:
        inside = bool(np.all((s["q_deg"] >= lim[:, 0] - 1e-9) & (s["q_deg"] <= lim[:, 1] + 1e-9)))
        assert s["within_limits"] == inside
    assert any(not s["within_limits"] for s in sols)  # A2 -130..20 excludes some branches
