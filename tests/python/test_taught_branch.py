"""The taught branch kept (issue 30, item 3). Programs taught on the nominal kr500 at joints chosen with the
wrist flipped (A5 < 0) and turned axes (A4, A6 beyond +-180 deg, A1 negative), each target's pose the
nominal pose of its joints and its branch data those of the joints (KRL S/T, RAPID confdata, FANUC
CONFIG with turns), are filtered on the calibrated kr500 (conftest: 1 mm / 0.05 deg errors and
compliance, seed 9). Truth: the taught joints. Read back by regular expressions here, every written
target has the taught S (cfx; F/N U/D T/B), the taught T (quadrants, turns) wherever the compensated
joint stays on its side of the border (a crossing is named in a warning), the controller's selection
of it lies within 2 deg of the taught joints (the same solution), and the calibrated model there
reaches the program's pose. Before this issue the branch nearest the previous pose (from home) was
written: S 6 came back as S 2. A target whose taught solution the calibrated robot cannot reach
inside the joint limits is an error naming it, a warning with --allow-branch-change."""

from __future__ import annotations

import math
import re

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

import kincal
from kincal import _core

from conftest import run
from test_filtered_targets import _abc_of_quaternion

# taught joints (deg): wrist flipped, A4 / A6 turned past 180, A1 on both sides; all inside the kr500's limits
TAUGHT = np.array([
    [10.0, -70.0, 100.0, 30.0, -40.0, 60.0],
    [-15.0, -80.0, 95.0, -200.0, -35.0, 190.0],
    [20.0, -60.0, 110.0, 150.0, -50.0, -250.0],
    [-5.0, -75.0, 105.0, 40.0, 45.0, 200.0],
    [0.0, -65.0, 90.0, -30.0, -60.0, -40.0],  # A1 on its border: taught T bit clear
])
N = r"(-?\d+(?:\.\d+)?)"


def _quaternion(abc):
    x, y, z, w = Rotation.from_euler("ZYX", abc, degrees=True).as_quat()
    return [w, x, y, z]


def _program(kind: str, poses, branch) -> str:
    if kind == "krl":
        src = "DEF taught()\n" + "".join(f"  LIN XP{i + 1} C_DIS\n" for i in range(len(poses))) + "END\n"
        dat = "DEFDAT taught\n" + "".join(
            f"DECL E6POS XP{i + 1}={{X {p[0]:.4f},Y {p[1]:.4f},Z {p[2]:.4f},A {p[3]:.6f},B {p[4]:.6f},C {p[5]:.6f},"
            f"S {b['kuka_s']},T {b['kuka_t']},E1 0.0,E2 0.0,E3 0.0,E4 0.0,E5 0.0,E6 0.0}}\n"
            for i, (p, b) in enumerate(zip(poses, branch))) + "ENDDAT\n"
        return src + "\x00" + dat
    if kind == "rapid":
        decl = "".join(
            f"  CONST robtarget p{i + 1}:=[[{p[0]:.4f},{p[1]:.4f},{p[2]:.4f}],[{','.join(f'{v:.9f}' for v in _quaternion(p[3:]))}],"
            f"[{','.join(str(v) for v in b['abb_conf'])}],[9E9,9E9,9E9,9E9,9E9,9E9]];\n"
            for i, (p, b) in enumerate(zip(poses, branch)))
        moves = "".join(f"    MoveL p{i + 1}, v200, fine, tool0;\n" for i in range(len(poses)))
        return f"MODULE Taught\n{decl}  PROC main()\n{moves}  ENDPROC\nENDMODULE\n"
    mn = "".join(f"{i + 1:4d}:  L P[{i + 1}] 200mm/sec FINE    ;\n" for i in range(len(poses)))
    pos = "".join(
        f"P[{i + 1}]{{\n   GP1:\n\tUF : 0, UT : 1,\t\tCONFIG : '{b['fanuc_config']}',\n"
        f"\tX = {p[0]:10.3f}  mm,\tY = {p[1]:10.3f}  mm,\tZ = {p[2]:10.3f}  mm,\n"
        f"\tW = {p[5]:10.3f} deg,\tP = {p[4]:10.3f} deg,\tR = {p[3]:10.3f} deg\n}};\n"
        for i, (p, b) in enumerate(zip(poses, branch)))
    return f"/PROG  TAUGHT\n/ATTR\n/MN\n{mn}/POS\n{pos}/END\n"


def _write(tmp_path, kind, poses, branch):
    text = _program(kind, poses, branch)
    if kind == "krl":
        src, dat = text.split("\x00")
        (tmp_path / "taught.src").write_text(src)
        (tmp_path / "taught.dat").write_text(dat)
        return tmp_path / "taught.src"
    path = tmp_path / ("taught.mod" if kind == "rapid" else "taught.ls")
    path.write_text(text)
    return path


def _read_back(kind, out):
    """(pose, branch) of each written target, in order, by regular expressions."""
    if kind == "krl":
        return [([float(m.group(k)) for k in range(1, 7)], {"kuka_s": int(m.group(7)), "kuka_t": int(m.group(8))})
                for m in re.finditer(r"XP\d+=\{X " + N + ",Y " + N + ",Z " + N + ",A " + N + ",B " + N + ",C " + N +
                                     r",S (\d+),T (\d+)", out.with_suffix(".dat").read_text())]
    if kind == "rapid":
        return [([float(v) for v in m.group(1).split(",")] + _abc_of_quaternion(*[float(v) for v in m.group(2).split(",")]),
                 {"abb_conf": [int(v) for v in m.group(3).split(",")]})
                for m in re.finditer(r"robtarget p\d+:=\[\[([^\]]*)\],\[([^\]]*)\],\[([^\]]*)\]", out.read_text())]
    return [([float(m.group(k)) for k in (2, 3, 4)] + [float(m.group(7)), float(m.group(6)), float(m.group(5))],
             {"fanuc_config": m.group(1)})
            for m in re.finditer(r"CONFIG : '([^']*)',\s*X =\s*" + N + r"\s*mm,\s*Y =\s*" + N + r"\s*mm,\s*Z =\s*" + N +
                                 r"\s*mm,\s*W =\s*" + N + r"\s*deg,\s*P =\s*" + N + r"\s*deg,\s*R =\s*" + N, out.read_text())]


def _arm(kind, b):
    """The arm, elbow and wrist part of the branch data."""
    return {"krl": lambda: b["kuka_s"], "rapid": lambda: b["abb_conf"][3],
            "fanuc-ls": lambda: b["fanuc_config"].split(",")[0].replace(" ", "")}[kind]()


def _turns(kind, b):
    if kind == "krl":
        return [(b["kuka_t"] >> j) & 1 for j in range(6)]
    if kind == "rapid":
        return list(b["abb_conf"][:3])
    return [int(v) for v in b["fanuc_config"].split(",")[1:]]


TURN_JOINTS = {"krl": range(6), "rapid": (0, 3, 5), "fanuc-ls": (0, 3, 5)}


@pytest.mark.parametrize("kind", ["krl", "rapid", "fanuc-ls"])
@pytest.mark.parametrize("tool", ["kincal", "kincal-compensate"])
def test_taught_branch_kept(tmp_path, kr500, calibrated, kind, tool):
    poses = kincal.fk(kr500, TAUGHT)
    branch = [_core.branch_data(kr500, q) for q in TAUGHT]
    assert len({_arm(kind, b) for b in branch}) > 1  # both wrists taught
    prog = _write(tmp_path, kind, poses, branch)
    (tmp_path / "m.json").write_text(calibrated.to_json())
    out = tmp_path / "out" / prog.name
    out.parent.mkdir()
    args = ["compensate"] if tool == "kincal" else []
    r = run(tool, *args, "--model", str(tmp_path / "m.json"), "--program", str(prog), "--out", str(out),
            "--targets", "filtered")
    assert r.returncode == 0, r.stderr
    written = _read_back(kind, out)
    assert len(written) == len(TAUGHT)
    fmt = "fanuc-ls" if kind == "fanuc-ls" else kind
    for i, ((pose, b), q_taught, taught) in enumerate(zip(written, TAUGHT, branch)):
        assert _arm(kind, b) == _arm(kind, taught), f"target {i + 1}: {b} written, {taught} taught"
        sel = _core.select_branch(calibrated, fmt, {"pose": pose, **b})
        assert not isinstance(sel, str), sel
        assert np.abs(sel - q_taught).max() < 2.0, f"target {i + 1}: {sel} far from the taught {q_taught}"
        for k, (a, c) in enumerate(zip(_turns(kind, b), _turns(kind, taught))):
            if a != c:  # only where the compensated joint crossed the border, and then a warning names it
                j = list(TURN_JOINTS[kind])[k]
                assert abs(sel[j] - q_taught[j]) < 5.0
                assert "across its turn's border" in r.stderr
        reached = kincal.fk(calibrated, sel)[0]
        dr = Rotation.from_euler("ZYX", reached[3:], degrees=True).inv() * Rotation.from_euler("ZYX", poses[i][3:], degrees=True)
        tol = 5e-3 if kind == "fanuc-ls" else 1e-3
        assert np.linalg.norm(reached[:3] - poses[i][:3]) < tol
        assert math.degrees(dr.magnitude()) < tol


@pytest.mark.parametrize("kind", ["krl", "rapid", "fanuc-ls"])
def test_unreachable_taught_solution_is_an_error(tmp_path, kr500, calibrated, kind):
    # the first target taught on the turn of A1 that its pose cannot have inside the limits (A1 + 360 deg)
    poses = kincal.fk(kr500, TAUGHT)
    branch = [_core.branch_data(kr500, q) for q in TAUGHT]
    turned = TAUGHT[0].copy()
    turned[0] -= 360.0  # -350 deg: beyond the kr500's A1 limit, the same pose
    branch[0] = _core.branch_data(kr500, turned)
    assert _turns(kind, branch[0]) != _turns(kind, _core.branch_data(kr500, TAUGHT[0]))
    prog = _write(tmp_path, kind, poses, branch)
    (tmp_path / "m.json").write_text(calibrated.to_json())
    out = tmp_path / "out" / prog.name
    out.parent.mkdir()
    base = ["compensate", "--model", str(tmp_path / "m.json"), "--program", str(prog), "--out", str(out),
            "--targets", "filtered"]
    r = run("kincal", *base)
    assert r.returncode == 1
    declared_in = prog.with_suffix(".dat") if kind == "krl" else prog  # the first target's line
    # (an LS position's line: its CONFIG's, where its values start)
    line = next(i + 1 for i, l in enumerate(declared_in.read_text().split("\n")) if re.search(r"XP1=|p1:=|CONFIG", l))
    assert f"{declared_in.name}:{line}:" in r.stderr and "taught" in r.stderr and "--allow-branch-change" in r.stderr
    assert not out.exists()
    r = run("kincal", *base, "--allow-branch-change")
    assert r.returncode == 0, r.stderr
    assert "--allow-branch-change" in r.stderr  # the warning naming the target
    assert len(_read_back(kind, out)) == len(TAUGHT)


def test_a_copy_is_named_by_the_motion_that_uses_it(tmp_path):
    """XA is taught for base 0 and used again in a base 5 m up, out of reach: the error names the motion
    (cp.src:5), the original's name, the second base and the copy it would have been written as."""
    (tmp_path / "cp.src").write_text("DEF cp( )\n$TOOL = $NULLFRAME\nPTP XA\n$BASE = {X 0.0,Y 0.0,Z 5000.0,A 0.0,B 0.0,C 0.0}\n"
                                     "PTP XA\nEND\n")
    (tmp_path / "cp.dat").write_text("DEFDAT cp\nDECL E6POS XA={X 1821.7535,Y 96.2456,Z 1403.9982,A 155.1308,"
                                      "B 5.7771,C 167.798,S 2,T 42}\nENDDAT\n")
    r = run("kincal-compensate", "--model", "kr500", "--program", str(tmp_path / "cp.src"), "--out",
            str(tmp_path / "out" / "cp.src"), "--targets", "filtered")
    assert r.returncode == 1
    assert "cp.src:5: XA in {X 0.0,Y 0.0,Z 5000.0" in r.stderr and "written as XA_1, declared after" in r.stderr
    assert not (tmp_path / "out").exists()
