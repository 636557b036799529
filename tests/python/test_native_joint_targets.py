"""Joint targets in native programs (issue 19, readers with --targets joints, the default): the
hand-written programs of tests/data/programs (KRL tape.src + tape.dat, RAPID tape.mod, FANUC tape.ls,
URScript tape.script) are compensated on the calibrated kr500 (conftest: 1 mm / 0.05 deg errors and
compliance, seed 9, no noise). A target every motion to which interpolates in joints (PTP, MoveJ, J,
movej) and that nothing else names becomes a joint target (E6AXIS, jointtarget with MoveAbsJ, J1..J6,
a joint list); the targets of linear and circular motions stay Cartesian (filtered), so that they keep
their straight line. A line diff shows the lines that change; the joints, read here by regular
expressions (not the project's readers), put the calibrated robot on the program's pose within what
the printed precision allows: KRL and RAPID print 1e-6 deg (bound 1e-3 mm, 1e-4 deg), LS 1e-4 deg
(6 joints x 0.5e-4 deg x 3.3 m of reach: bound 0.02 mm, 5e-4 deg), URScript 1e-10 rad."""

from __future__ import annotations

import math
import re
import shutil
from pathlib import Path

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

import kincal

from conftest import run
from test_native_programs import _changed

DATA = Path(__file__).resolve().parents[1] / "data" / "programs"
N = r"(-?\d*\.?\d+)"


@pytest.fixture()
def model(tmp_path, calibrated):
    path = tmp_path / "m.json"
    path.write_text(calibrated.to_json())
    return path


def _compensate(tool, tmp_path, model, name, text=None, *extra):
    src = tmp_path / name
    if text is None:
        for f in DATA.glob(Path(name).stem + ".*"):
            shutil.copy(f, tmp_path / f.name)
    else:
        src.write_text(text)
    (tmp_path / "out").mkdir(exist_ok=True)
    out = tmp_path / "out" / name
    args = ["compensate"] if tool == "kincal" else []
    r = run(tool, *args, "--model", str(model), "--program", str(src), "--out", str(out), *extra)
    assert r.returncode == 0, r.stderr
    return r, out


def _assert_reaches(calibrated, q_deg, desired, mm, deg):
    """desired: x, y, z (mm) and KUKA A, B, C (deg) or a scipy Rotation"""
    p = kincal.fk(calibrated, np.asarray(q_deg, dtype=float))[0]
    want = desired[3] if isinstance(desired[3], Rotation) else Rotation.from_euler("ZYX", desired[3:], degrees=True)
    dr = Rotation.from_euler("ZYX", p[3:], degrees=True).inv() * want
    assert np.linalg.norm(p[:3] - np.asarray(desired[:3])) < mm
    assert math.degrees(dr.magnitude()) < deg


def _krl_axis(text, name):
    m = re.search(r"DECL E6AXIS " + name + r"=\{A1 " + N + ",A2 " + N + ",A3 " + N + ",A4 " + N + ",A5 " + N + ",A6 " + N +
                  r",E1 0\.0,E2 0\.0,E3 0\.0,E4 0\.0,E5 0\.0,E6 0\.0\}", text)
    assert m, text
    return [float(m.group(k)) for k in range(1, 7)]


@pytest.mark.parametrize("tool", ["kincal", "kincal-compensate"])
def test_krl_ptp_target_becomes_e6axis(tmp_path, model, calibrated, tool):
    r, out = _compensate(tool, tmp_path, model, "tape.src")
    assert "1 target(s) written as joints, 5 as filtered poses" in r.stderr
    dat_in, dat_out = (DATA / "tape.dat").read_text(), out.with_suffix(".dat").read_text()
    src_in, src_out = (DATA / "tape.src").read_text(), out.read_text()
    # XP1 (PTP only) becomes an E6AXIS; XP2..XP4 and the inline target (LIN, CIRC) stay Cartesian
    assert [dat_out.split("\n")[i - 1].split("=")[0] for i in _changed(dat_in, dat_out)] == \
        ["DECL E6AXIS XP1", "DECL E6POS XP2", "DECL POS XAUX", "DECL E6POS XP3", "DECL FRAME XP4"]
    assert [src_in.split("\n")[i - 1] for i in _changed(src_in, src_out)] == \
        ["LIN {X 2000.0,Y -600.0,Z 520.0,A 0.0,B 90.0,C 0.0}"]
    _assert_reaches(calibrated, _krl_axis(dat_out, "XP1"), [2000, -740, 600, 0, 90, 0], 1e-3, 1e-4)


@pytest.mark.parametrize("tool", ["kincal", "kincal-compensate"])
def test_rapid_movej_target_becomes_jointtarget_with_moveabsj(tmp_path, model, calibrated, tool):
    r, out = _compensate(tool, tmp_path, model, "tape.mod")
    assert "1 target(s) written as joints, 4 as filtered poses" in r.stderr
    a, b = (DATA / "tape.mod").read_text(), out.read_text()
    changed = [b.split("\n")[i - 1].strip() for i in _changed(a, b)]
    assert [c.split("[[")[0].split(",")[0] for c in changed] == [
        "CONST jointtarget p1:=", "CONST robtarget p2:=", "PERS robtarget paux:=", "CONST robtarget p3:=",
        "MoveAbsJ p1", "MoveL "]
    assert "MoveAbsJ p1,v500,z10,thead\\WObj:=wtable;" in changed  # only the instruction's name changes
    m = re.search(r"CONST jointtarget p1:=\[\[" + ",".join([N] * 6) + r"\],\[9E9,9E9,9E9,9E9,9E9,9E9\]\];", b)
    assert m
    # p1 is [1900, -720, 600] with q = (0.7071, 0, 0.7071, 0) in the work object wtable (x + 500, y - 20), the
    # TCP of thead (350 mm along the flange's z, which the orientation turns to the base's x): the model's
    # tool (the flange) at [2400 - 350, -740, 600]
    rot = Rotation.from_quat([0, 0.707106781, 0, 0.707106781])  # scipy: x, y, z, w
    _assert_reaches(calibrated, [float(m.group(k)) for k in range(1, 7)], [2050, -740, 600, rot], 1e-3, 1e-4)


def test_ls_j_position_becomes_joint_form(tmp_path, model, calibrated):
    r, out = _compensate("kincal", tmp_path, model, "tape.ls", None, "--skip-unresolved")
    assert "1 target(s) written as joints, 3 as filtered poses" in r.stderr
    a, b = (DATA / "tape.ls").read_text(), out.read_text()
    # P[2] (J motions only) in joint form on its three lines; P[3] (L and an Offset motion), P[4], P[5]
    # (C, L) stay Cartesian with their taught CONFIG line unchanged (the taught branch kept): 9 lines of /POS,
    # no line of /MN
    assert len(_changed(a, b)) == 9 and all(i > a.split("\n").index("/POS") for i in _changed(a, b))
    m = re.search(r"P\[2:\"approach\"\]\{\s*GP1:\s*UF : 0, UT : 1,\s*" +
                  r",\s*".join(f"J{j}=\\s*{N} deg" for j in range(1, 7)) + r"\s*\};", b)
    assert m, b
    # W 180, P 0, R 180 are KUKA C 180, B 0, A 180
    _assert_reaches(calibrated, [float(m.group(k)) for k in range(1, 7)], [2000, -720, 600, 180, 0, 180], 0.02, 5e-4)


def test_urscript_movej_pose_becomes_joint_list(tmp_path, model, calibrated):
    r, out = _compensate("kincal-compensate", tmp_path, model, "tape.script", None, "--skip-unresolved")
    assert "1 target(s) written as joints, 3 as filtered poses" in r.stderr
    a, b = (DATA / "tape.script").read_text(), out.read_text()
    # approach (movej only) becomes a joint list; lay_end (movec, movel) and the movel/movec literals stay poses
    changed = [b.split("\n")[i - 1].strip() for i in _changed(a, b)]
    assert [c[:15] for c in changed] == ["global approach", "global lay_end ", "movel(p[1.99964", "movec(p[2.04955"]
    assert changed[1].startswith("global lay_end = p[")
    m = re.search(r"global approach = \[" + ", ".join([N] * 6) + r"\]", b)
    assert m, b
    q = [math.degrees(float(m.group(k))) for k in range(1, 7)]
    _assert_reaches(calibrated, q, [2000, -720, 600, Rotation.from_rotvec([0, 3.14159265359, 0])], 1e-3, 1e-4)


@pytest.mark.parametrize("case", ["krl-lin", "rapid-movel", "rapid-offs", "ls-l", "ur-pose-trans"])
def test_targets_used_otherwise_stay_cartesian(tmp_path, model, case):
    # the joint-motion target is also the target of a linear motion, or named by a run-time expression:
    # it stays Cartesian (a joint target would lose the line, or break the expression)
    name, old, new = {
        "krl-lin": ("tape.src", "$OUT[17] = TRUE", "LIN XP1\n$OUT[17] = TRUE"),
        "rapid-movel": ("tape.mod", "    SetDO doHead,1;", "    MoveL p1,v100,fine,thead\\WObj:=wtable;\n    SetDO doHead,1;"),
        "rapid-offs": ("tape.mod", "    SetDO doHead,1;", "    MoveL Offs(p1,0,0,50),v100,fine,thead\\WObj:=wtable;\n"
                                                          "    SetDO doHead,1;"),
        "ls-l": ("tape.ls", "   6:  DO[1:head]=ON ;", "   6:  L P[2] 100mm/sec FINE    ;"),
        "ur-pose-trans": ("tape.script", "  sleep(0.5)", "  x = pose_trans(approach, p[0, 0, 0.1, 0, 0, 0])"),
    }[case]
    text = (DATA / name).read_text()
    assert old in text
    if name == "tape.src":
        shutil.copy(DATA / "tape.dat", tmp_path / "tape.dat")
    r, out = _compensate("kincal", tmp_path, model, name, text.replace(old, new), "--skip-unresolved")
    assert "0 target(s) written as joints" in r.stderr
    b = (out.with_suffix(".dat") if name == "tape.src" else out).read_text()
    assert not re.search(r"E6AXIS XP1|jointtarget p1|MoveAbsJ p1|J1=\s*-?\d+\.\d{4} deg|approach = \[", b)
