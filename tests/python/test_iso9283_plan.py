"""kincal accuracy plan-iso9283: the ISO 9283 cube (the largest that fits at the working orientation)
and its test poses P1..P5, on the built-in kr500 and on a URDF robot written here. Truth: the robots'
nominal models; reachability is checked here independently of the planner (every closed-form IK
solution flagged within the limits is checked against the limits and by forward kinematics)."""

from __future__ import annotations

import csv
import itertools
from pathlib import Path

import numpy as np
import pytest

import kincal

from conftest import run

# a 6R with a spherical wrist (0.4 m above the floor to the shoulder, 0.6 m upper arm, 0.65 m forearm,
# 0.1 m flange), its tool along the base's x axis at the zero pose
ARM6 = """<?xml version="1.0"?>
<robot name="arm6">
  <link name="base_link"/><link name="link1"/><link name="link2"/><link name="link3"/><link name="link4"/>
  <link name="link5"/><link name="link6"/><link name="tool0"/>
  <joint name="joint1" type="revolute"><parent link="base_link"/><child link="link1"/>
    <origin xyz="0 0 0.45" rpy="0 0 0"/><axis xyz="0 0 1"/><limit lower="-2.967" upper="2.967" effort="1" velocity="1"/></joint>
  <joint name="joint2" type="revolute"><parent link="link1"/><child link="link2"/>
    <origin xyz="0.15 0 0" rpy="0 0 0"/><axis xyz="0 1 0"/><limit lower="-1.745" upper="2.356" effort="1" velocity="1"/></joint>
  <joint name="joint3" type="revolute"><parent link="link2"/><child link="link3"/>
    <origin xyz="0 0 0.6" rpy="0 0 0"/><axis xyz="0 1 0"/><limit lower="-2.4" upper="1.2" effort="1" velocity="1"/></joint>
  <joint name="joint4" type="revolute"><parent link="link3"/><child link="link4"/>
    <origin xyz="0.25 0 0.12" rpy="0 0 0"/><axis xyz="1 0 0"/><limit lower="-3.2" upper="3.2" effort="1" velocity="1"/></joint>
  <joint name="joint5" type="revolute"><parent link="link4"/><child link="link5"/>
    <origin xyz="0.4 0 0" rpy="0 0 0"/><axis xyz="0 1 0"/><limit lower="-2.2" upper="2.2" effort="1" velocity="1"/></joint>
  <joint name="joint6" type="revolute"><parent link="link5"/><child link="link6"/>
    <origin xyz="0 0 0" rpy="0 0 0"/><axis xyz="1 0 0"/><limit lower="-6.28" upper="6.28" effort="1" velocity="1"/></joint>
  <joint name="flange" type="fixed"><parent link="link6"/><child link="tool0"/>
    <origin xyz="0.1 0 0" rpy="0 1.5707963267948966 0"/></joint>
</robot>
"""


def _reachable(robot, pose) -> bool:
    """A solution within the joint limits that lands on the pose (1e-6 mm, 1e-6 rad)."""
    lim = np.asarray(robot.limits_deg)
    target = kincal._core.abc_to_rotation(np.asarray(pose[3:], dtype=float))
    for s in kincal.ik(robot, pose):
        q = np.asarray(s["q_deg"])
        if not s["within_limits"] or np.any(q < lim[:, 0] - 1e-9) or np.any(q > lim[:, 1] + 1e-9):
            continue
        p = kincal.fk(robot, [q])[0]
        if np.linalg.norm(p[:3] - pose[:3]) < 1e-6 and \
                np.abs(kincal._core.abc_to_rotation(p[3:]) - target).max() < 1e-6:
            return True
    return False


def _flag(robot, pose) -> bool:
    """The IK's own within-limits flag (fast, for the search below)."""
    return any(s["within_limits"] for s in kincal.ik(robot, pose))


def _cube(centre, edge, k):
    u = np.linspace(-0.5, 0.5, k)
    return [np.asarray(centre) + edge * np.array(g) for g in itertools.product(u, u, u)]


def _fits(robot, centre, edge, abc, k, check=_flag) -> bool:
    return all(check(robot, np.r_[p, abc]) for p in _cube(centre, edge, k))


def _read_program(path: Path):
    with open(path, newline="") as f:
        rows = list(csv.DictReader(f))
    poses = np.array([[float(r[k]) for k in "xyzabc"] for r in rows])
    return poses, [r["point"] for r in rows], [int(r["cycle"]) for r in rows]


def _check_plan(robot, path: Path, rng, centres: int):
    """The program's structure and geometry, the poses' reachability, and that the cube is the
    largest: it fits (11^3 lattice, verified solutions), a 5% larger one at its centre or at any of 26
    centres 5% of the edge away does not, and no random centre (an independent search: ``centres``
    reachable centres, bisection of the edge on a 7^3 lattice) holds one 5% larger."""
    poses, points, cycles = _read_program(path)
    assert len(poses) == 151 and points[0] == "P1" and cycles[0] == 0
    assert points[1:6] == ["P5", "P4", "P3", "P2", "P1"] and points[1:] == points[1:6] * 30
    assert cycles[1:] == [j for j in range(1, 31) for _ in range(5)]
    P = {n: poses[points.index(n)] for n in ("P1", "P2", "P3", "P4", "P5")}
    abc = P["P1"][3:]
    assert all(np.array_equal(p[3:], abc) for p in poses)
    centre = P["P1"][:3]
    edge = (P["P2"][0] - P["P3"][0]) / 0.8
    for name, s in (("P2", (1, 1, 1)), ("P3", (-1, 1, 1)), ("P4", (-1, -1, -1)), ("P5", (1, -1, -1))):
        assert np.allclose(P[name][:3], centre + 0.8 * edge / 2 * np.array(s), atol=1e-6)  # 10% of the diagonal
    for p in P.values():
        assert _reachable(robot, p)
    assert _fits(robot, centre, edge, abc, 11, check=_reachable)
    assert not _fits(robot, centre, 1.05 * edge, abc, 11)
    for d in itertools.product((-1, 0, 1), repeat=3):
        if any(d):
            c = centre + 0.05 * edge * np.asarray(d) / np.linalg.norm(d)
            assert not _fits(robot, c, 1.05 * edge, abc, 7), d
    lim = np.asarray(robot.limits_deg)
    xyz = kincal.fk(robot, rng.uniform(lim[:, 0], lim[:, 1], size=(4000, robot.dof)))[:, :3]
    lo, hi = xyz.min(axis=0), xyz.max(axis=0)
    best, tried, bisected = 0.0, 0, 0
    while tried < centres:
        c = rng.uniform(lo, hi)
        if not _flag(robot, np.r_[c, abc]):
            continue
        tried += 1
        if not _fits(robot, c, 0.5 * edge, abc, 7):
            continue  # its largest cube is under half the plan's
        a, b = 0.5 * edge, 2.0 * edge
        while b - a > 0.005 * edge:
            m = (a + b) / 2
            a, b = (m, b) if _fits(robot, c, m, abc, 7) else (a, m)
        best, bisected = max(best, a), bisected + 1
    assert bisected >= 5 and best < 1.05 * edge
    return centre, edge, abc


def test_kr500_cube_is_the_largest_and_its_program_compensates(tmp_path):
    """kr500 at its working orientation (the tool's at home: ABC 180, 0, 180, pointing down); the
    program is a pose program that `kincal compensate` turns into 151 joint rows within the limits;
    --cube 800 keeps the centre and scales P2..P5."""
    kr500 = kincal.load_robot("kr500")
    r = run("kincal", "accuracy", "plan-iso9283", "--robot", "kr500", "--out", str(tmp_path / "p.csv"))
    assert r.returncode == 0, r.stderr
    assert "P1:" in r.stdout and "largest that fits" in r.stdout
    centre, edge, abc = _check_plan(kr500, tmp_path / "p.csv", np.random.default_rng(1), centres=60)
    assert np.allclose(np.abs(abc), [180, 0, 180], atol=1e-6)
    assert edge > 1000.0
    r = run("kincal", "compensate", "--model", "kr500", "--program", str(tmp_path / "p.csv"), "--out",
            str(tmp_path / "q.csv"))
    assert r.returncode == 0, r.stderr
    q = np.loadtxt(tmp_path / "q.csv", delimiter=",", skiprows=1)
    lim = np.asarray(kr500.limits_deg)
    assert q.shape == (151, 6) and np.all(q >= lim[:, 0]) and np.all(q <= lim[:, 1])
    poses, _, _ = _read_program(tmp_path / "p.csv")
    assert np.abs(kincal.fk(kr500, q)[:, :3] - poses[:, :3]).max() < 1e-6
    r = run("kincal", "accuracy", "plan-iso9283", "--robot", "kr500", "--cube", "800", "--out", str(tmp_path / "s.csv"))
    assert r.returncode == 0, r.stderr
    small, points, _ = _read_program(tmp_path / "s.csv")
    p1, p2 = small[points.index("P1")], small[points.index("P2")]
    assert np.allclose(p1[:3], centre, atol=1e-6) and np.allclose(p2[:3] - p1[:3], 0.4 * 800, atol=1e-6)


def test_urdf_robot_cube_is_the_largest(tmp_path):
    """The URDF arm above at its working orientation (the tool along +x: ABC 0, 90, 0)."""
    (tmp_path / "arm6.urdf").write_text(ARM6)
    robot = kincal.load_robot(str(tmp_path / "arm6.urdf"))
    r = run("kincal", "accuracy", "plan-iso9283", "--robot", str(tmp_path / "arm6.urdf"), "--out",
            str(tmp_path / "p.csv"))
    assert r.returncode == 0, r.stderr
    _, edge, abc = _check_plan(robot, tmp_path / "p.csv", np.random.default_rng(2), centres=60)
    assert np.allclose(abc, [0, 90, 0], atol=1e-6) and edge > 300.0


@pytest.mark.parametrize("args,message", [
    (["--robot", "kr500", "--cube", "5000"], r"--cube 5000: a cube of 5000 mm does not fit in kr500's workspace .*"
                                             r"the largest that fits has a \d+ mm edge"),
    (["--robot", "kr500", "--cube", "-1"], r"--cube -1: the edge must be positive"),
    (["--robot", "kr500", "--orientation", "180,0"], r"--orientation 180,0: expected three numbers"),
    (["--robot", "ur10"], r"needs the closed-form IK"),
])
def test_bad_plan(tmp_path, args, message):
    """A cube that does not fit, a bad option, a robot without closed-form IK: exit 1, one message
    naming the option (or the robot), no program written."""
    import re

    r = run("kincal", "accuracy", "plan-iso9283", *args, "--out", str(tmp_path / "p.csv"))
    assert r.returncode == 1
    assert re.search(message, r.stderr), r.stderr
    assert not (tmp_path / "p.csv").exists()


def test_orientation_floor_and_cycles(tmp_path):
    """The URDF arm with its tool pointing down (--orientation 0,180,0), the cube kept above z = 300 mm
    (--z-min) and 2 cycles: every pose has that orientation, the cube's bottom face is at or above
    300 mm and within 5% of the edge of it (the floor is what limits it), its lattice is reachable,
    and the program has 1 + 2 x 5 rows."""
    (tmp_path / "arm6.urdf").write_text(ARM6)
    robot = kincal.load_robot(str(tmp_path / "arm6.urdf"))
    r = run("kincal", "accuracy", "plan-iso9283", "--robot", str(tmp_path / "arm6.urdf"), "--orientation", "0,180,0",
            "--z-min", "300", "--cycles", "2", "--out", str(tmp_path / "p.csv"))
    assert r.returncode == 0, r.stderr
    poses, points, cycles = _read_program(tmp_path / "p.csv")
    assert len(poses) == 11 and cycles == [0] + [1] * 5 + [2] * 5 and points[1:6] == ["P5", "P4", "P3", "P2", "P1"]
    assert np.allclose(poses[:, 3:], [0, 180, 0])
    centre = poses[0, :3]
    edge = (poses[points.index("P2"), 0] - poses[points.index("P3"), 0]) / 0.8
    bottom = centre[2] - edge / 2
    assert 300.0 - 1e-9 <= bottom < 300.0 + 0.05 * edge
    assert _fits(robot, centre, edge, poses[0, 3:], 11, check=_reachable)
