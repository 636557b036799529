"""Between the targets (issue 19, item 3): `--tolerance MM` inserts targets where the real robot's
path between two compensated targets leaves the desired segment by more than MM.

Truth: the calibrated kr500 of conftest (1 mm / 0.05 deg errors and joint compliance, seed 9), no
noise. The program is the Samak paper's line (1480 mm along y, tool down) given by only 5 targets
370 mm apart (joint targets) or by its two ends (filtered targets), so that the controller's
interpolation between them leaves the line by more than the tolerance.
The written program is read back here by regular expressions (CSV rows, KRL E6AXIS / E6POS), and the
controller's motion is emulated here, independently of kincal's own check: joint targets move on a
straight line in joint space; filtered targets (LIN) on the nominal model's straight line between the
written poses (position linear, orientation by quaternion slerp; the nominal IK solution nearest the
previous point, from kincal's ik_all). The real robot's position there (the calibrated model's FK)
is measured at 20 points per segment (s = k/21) against the desired line: at most 0.05 mm."""

from __future__ import annotations

import re

import numpy as np
import pytest
from scipy.spatial.transform import Rotation, Slerp

import kincal
from kincal import _core

from conftest import run

TOL = 0.05
NUM = r"(-?\d+(?:\.\d+)?)"


def _abc_rot(abc) -> Rotation:
    # KUKA ABC: R = Rz(a) Ry(b) Rx(c)
    return Rotation.from_euler("ZYX", abc, degrees=True)


def _line_distance(p: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    d = (b - a) / np.linalg.norm(b - a)
    v = p - a
    t = np.clip(v @ d, 0, np.linalg.norm(b - a))
    return np.linalg.norm(v - t[:, None] * d[None, :], axis=1)


def _joint_path(q: np.ndarray) -> np.ndarray:
    s = np.arange(1, 21) / 21.0
    return np.vstack([qa + s[:, None] * (qb - qa) for qa, qb in zip(q[:-1], q[1:])])


def _lin_path(robot, poses: np.ndarray, q0: np.ndarray) -> np.ndarray:
    """The controller's LIN between consecutive written poses: nominal IK nearest the last point."""
    out, ref = [], q0
    for pa, pb in zip(poses[:-1], poses[1:]):
        slerp = Slerp([0, 1], Rotation.concatenate([_abc_rot(pa[3:]), _abc_rot(pb[3:])]))
        for s in np.arange(1, 21) / 21.0:
            abc = slerp([s]).as_euler("ZYX", degrees=True)[0]
            pose = np.concatenate([pa[:3] + s * (pb[:3] - pa[:3]), abc])
            sols = [np.asarray(x["q_deg"]) for x in _core.ik_all(robot, pose, ref) if x["within_limits"]]
            ref = min(sols, key=lambda q: np.abs(q - ref).max())
            out.append(ref)
    return np.array(out)


@pytest.fixture(scope="module")
def sparse_line(tmp_path_factory, calibrated):
    d = tmp_path_factory.mktemp("tol")
    (d / "model.json").write_text(calibrated.to_json())
    poses = kincal.line_program(count=5, step_mm=370.0)
    (d / "line.csv").write_text("x,y,z,a,b,c\n" + "".join(",".join(f"{v:.10f}" for v in p) + "\n" for p in poses))
    return d, poses


def _deviation(calibrated, q_path, poses) -> float:
    p = np.asarray(_core.fk(calibrated, q_path, True))[:, :3]
    return float(_line_distance(p, poses[0, :3], poses[-1, :3]).max())


def _summary(stderr: str) -> tuple[float, float, int]:
    m = re.search(r"largest deviation from the desired segments ([\d.]+) mm before, ([\d.]+) mm after (\d+) inserted",
                  stderr)
    assert m, stderr
    return float(m.group(1)), float(m.group(2)), int(m.group(3))


@pytest.mark.parametrize("tool", ["kincal", "kincal-compensate"])
def test_joint_targets_keep_within_tolerance(sparse_line, calibrated, tool):
    d, poses = sparse_line
    args = ["compensate"] if tool == "kincal" else []
    out = d / f"joints_{tool}.csv"
    r = run(tool, *args, "--model", str(d / "model.json"), "--program", str(d / "line.csv"), "--out", str(out),
            "--tolerance", str(TOL))
    assert r.returncode == 0, r.stderr
    q = np.loadtxt(out, delimiter=",", skiprows=1)
    # the input's targets are all there, compensated as without --tolerance
    q0 = kincal.compensate(calibrated, poses)["q_deg"]
    assert all(np.abs(q - qi).max(axis=1).min() < 1e-8 for qi in q0)
    before = _deviation(calibrated, _joint_path(q0), poses)
    after = _deviation(calibrated, _joint_path(q), poses)
    assert before > 10 * TOL  # the sparse targets alone leave the line (else the test shows nothing)
    assert after <= TOL
    b, a, n = _summary(r.stderr)
    assert n == len(q) - len(poses) > 0
    assert b == pytest.approx(before, rel=0.05) and a <= TOL


@pytest.mark.parametrize("tool", ["kincal", "kincal-compensate"])
def test_filtered_lin_targets_keep_within_tolerance(sparse_line, calibrated, tool):
    # the nominal straight line between filtered targets 370 mm apart stays within 0.04 mm already:
    # the line's two ends only (1480 mm), where it does not
    d, _ = sparse_line
    poses = kincal.line_program(count=2, step_mm=1480.0)
    (d / "ends.csv").write_text("x,y,z,a,b,c\n" + "".join(",".join(f"{v:.10f}" for v in p) + "\n" for p in poses))
    args = ["compensate"] if tool == "kincal" else []
    out = d / f"lin_{'py' if tool == 'kincal' else 'cpp'}.src"
    r = run(tool, *args, "--model", str(d / "model.json"), "--program", str(d / "ends.csv"), "--out", str(out),
            "--targets", "filtered", "--tolerance", str(TOL))
    assert r.returncode == 0, r.stderr
    dat = out.with_suffix(".dat").read_text()
    written = np.array([[float(m.group(k)) for k in range(1, 7)] for m in re.finditer(
        r"DECL E6POS XP\d+=\{X " + NUM + ",Y " + NUM + ",Z " + NUM + ",A " + NUM + ",B " + NUM + ",C " + NUM, dat)])
    assert len(written) > len(poses)
    q_first = kincal.compensate(calibrated, poses[:1])["q_deg"][0]
    after = _deviation(calibrated, _lin_path(calibrated, written, q_first), poses)
    assert after <= TOL
    b, a, n = _summary(r.stderr)
    assert n == len(written) - len(poses) and b > TOL and a <= TOL


def test_gcode_keeps_its_lines_and_gets_inserted_motions(tmp_path, calibrated):
    poses = kincal.line_program(count=3, step_mm=500.0)
    lines = ["(line)", "N10 G90"] + [f"N{20 + 10 * i} G1 X{p[0]:.4f} Y{p[1]:.4f} Z{p[2]:.4f} A{p[3]:.4f} B{p[4]:.4f} "
                                     f"C{p[5]:.4f} F1000" for i, p in enumerate(poses)] + ["M30"]
    (tmp_path / "in.ngc").write_text("\n".join(lines) + "\n")
    (tmp_path / "m.json").write_text(calibrated.to_json())
    r = run("kincal", "compensate", "--model", str(tmp_path / "m.json"), "--program", str(tmp_path / "in.ngc"),
            "--out", str(tmp_path / "out.ngc"), "--tolerance", str(TOL))
    assert r.returncode == 0, r.stderr
    out = (tmp_path / "out.ngc").read_text().splitlines()
    kept = [l for l in out if not l.startswith("G1 A1=")]
    assert kept[:2] == lines[:2] and kept[-1] == "M30"
    assert [re.sub(r" A1=.*A6=\S+", "", l) for l in kept[2:-1]] == [f"N{20 + 10 * i} G1 F1000" for i in range(3)]
    assert len(out) - len(lines) == _summary(r.stderr)[2] > 0


def test_bad_tolerance_and_native_programs(tmp_path, calibrated):
    (tmp_path / "m.json").write_text(calibrated.to_json())
    (tmp_path / "l.csv").write_text("x,y,z,a,b,c\n2000,0,500,180,0,180\n2000,100,500,180,0,180\n")
    r = run("kincal-compensate", "--model", str(tmp_path / "m.json"), "--program", str(tmp_path / "l.csv"), "--out",
            str(tmp_path / "o.csv"), "--tolerance", "-1")
    assert r.returncode != 0 and "--tolerance" in r.stderr and not (tmp_path / "o.csv").exists()
