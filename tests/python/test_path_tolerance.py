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
is measured at 20 points per segment (s = k/21) against the desired line: at most 0.05 mm.
The same line's two ends as hand-written KRL, RAPID, LS and URScript programs (a joint motion to the
first end, a straight-line motion to the second): the inserted copies of the straight-line motion are
read back here and the emulated LIN keeps within 0.05 mm as well."""

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


def test_bad_tolerance(tmp_path, calibrated):
    (tmp_path / "m.json").write_text(calibrated.to_json())
    (tmp_path / "l.csv").write_text("x,y,z,a,b,c\n2000,0,500,180,0,180\n2000,100,500,180,0,180\n")
    r = run("kincal-compensate", "--model", str(tmp_path / "m.json"), "--program", str(tmp_path / "l.csv"), "--out",
            str(tmp_path / "o.csv"), "--tolerance", "-1")
    assert r.returncode != 0 and "--tolerance" in r.stderr and not (tmp_path / "o.csv").exists()


def _taught(robot, pose) -> dict:
    """The branch data of the nominal solution nearest home: what the program was taught on."""
    home = np.array([0, -90, 90, 0, 90, 0])
    sols = [np.asarray(s["q_deg"]) for s in kincal.ik(robot, pose) if s["within_limits"]]
    return _core.branch_data(robot, min(sols, key=lambda q: np.abs(q - home).max()))


def _native_line(lang: str, ends: np.ndarray, robot) -> dict:
    """The line's two ends as a hand-written program: a joint motion to the first, a straight line to
    the second (KRL PTP/LIN, RAPID MoveJ/MoveL, LS J/L, URScript movej/movel), with the branch data of the
    nominal solutions nearest home (the taught ones)."""
    a, b = ends
    conf = {id(p): _taught(robot, p) for p in (a, b)}
    krl = lambda p: "{" + ",".join(f"{k} {v:.4f}" for k, v in zip("XYZABC", p)) + "}"
    if lang == "krl":
        return {"line.src": "DEF line( )\n$VEL.CP = 0.2 ; m/s\nPTP XP1\nLIN XP2 C_DIS\nEND\n",
                "line.dat": f"DEFDAT line\nDECL E6POS XP1={krl(a)}\nDECL E6POS XP2={krl(b)}\nENDDAT\n"}
    if lang == "rapid":
        q = lambda p: ",".join(f"{v:.9f}" for v in np.roll(_abc_rot(p[3:]).as_quat(), 1))
        rt = lambda p: (f"[[{p[0]:.4f},{p[1]:.4f},{p[2]:.4f}],[{q(p)}],[{','.join(map(str, conf[id(p)]['abb_conf']))}],"
                        "[9E9,9E9,9E9,9E9,9E9,9E9]]")
        return {"line.mod": f"MODULE line\n  CONST robtarget p1:={rt(a)};\n  CONST robtarget p2:={rt(b)};\n"
                            "  PROC main()\n    MoveJ p1,v500,fine,tool0;\n    MoveL p2,v200,z1,tool0; ! the line\n"
                            "  ENDPROC\nENDMODULE\n"}
    if lang == "ls":
        pos = lambda n, p: (f"P[{n}]{{\n   GP1:\n\tUF : 0, UT : 1,\t\tCONFIG : '{conf[id(p)]['fanuc_config']}',\n"
                            f"\tX = {p[0]:.3f}  mm,\tY = {p[1]:.3f}  mm,\tZ = {p[2]:.3f}  mm,\n"
                            f"\tW = {p[5]:.3f} deg,\tP = {p[4]:.3f} deg,\tR = {p[3]:.3f} deg\n}};\n")
        return {"LINE.ls": "/PROG  LINE\n/ATTR\nLINE_COUNT\t= 3;\n/MN\n   1:  J P[1] 20% FINE    ;\n"
                           "   2:  L P[2] 200mm/sec CNT50    ;\n   3:  !done ;\n/POS\n" + pos(1, a) + pos(2, b) + "/END\n"}
    p = lambda x: "p[" + ", ".join(f"{v:.8f}" for v in [*(x[:3] / 1000), *_abc_rot(x[3:]).as_rotvec()]) + "]"
    return {"line.script": f"def line():\n  movej({p(a)}, a=1.4, v=1.05)\n  movel({p(b)}, a=1.2, v=0.2)\nend\n"}


def _native_poses(lang: str, files: dict) -> np.ndarray:
    """The written targets in the order the program moves to them (read here by regular expressions)."""
    if lang == "krl":
        dat = dict(re.findall(r"DECL E6POS (XP\d)=(\{[^}]*\})", files["line.dat"]))
        order = [dat["XP1"]] + re.findall(r"^LIN (\{[^}]*\}) C_DIS$", files["line.src"], re.M) + [dat["XP2"]]
        return np.array([[float(re.search(k + " " + NUM, t).group(1)) for k in ("X", "Y", "Z", "A", "B", "C")]
                         for t in order])
    if lang == "rapid":
        decl = dict(re.findall(r"robtarget (p\d):=(\[\[.*?\]\]);", files["line.mod"]))
        order = [decl["p1"]] + re.findall(r"^    MoveL (\[\[.*?\]\]),v200,z1,tool0;$", files["line.mod"], re.M) + [decl["p2"]]
        out = []
        for t in order:
            v = [float(x) for x in re.findall(r"-?\d+\.\d+|-?\d+", t)]
            out.append([*v[:3], *Rotation.from_quat([v[4], v[5], v[6], v[3]]).as_euler("ZYX", degrees=True)])
        return np.array(out)
    if lang == "ls":
        text = files["LINE.ls"]
        pos = {int(m.group(1)): [float(m.group(k)) for k in (2, 3, 4, 7, 6, 5)] for m in re.finditer(
            r"P\[(\d+)\]\{\s*GP1:\s*UF : 0, UT : 1,\s*CONFIG : '[^']*',\s*X =\s*" + NUM + r"\s*mm,\s*Y =\s*" + NUM +
            r"\s*mm,\s*Z =\s*" + NUM + r"\s*mm,\s*W =\s*" + NUM + r"\s*deg,\s*P =\s*" + NUM + r"\s*deg,\s*R =\s*" + NUM, text)}
        return np.array([pos[int(n)] for n in re.findall(r"^\s*\d+:\s+[JL] P\[(\d+)\]", text, re.M)])
    out = []
    for m in re.finditer(r"p\[([^\]]*)\]", files["line.script"]):
        v = [float(x) for x in m.group(1).split(",")]
        out.append([*(1000 * np.array(v[:3])), *Rotation.from_rotvec(v[3:]).as_euler("ZYX", degrees=True)])
    return np.array(out)


@pytest.mark.parametrize("lang", ["krl", "rapid", "ls", "urscript"])
def test_native_program_straight_line_keeps_within_tolerance(tmp_path, calibrated, lang):
    # a hand-written program along the Samak line's two ends (1480 mm): --tolerance inserts copies of the
    # straight-line motion (its speed, zone, tool) before it, every other line is kept; the controller's
    # LIN through the written targets, emulated here, keeps the real robot within 0.05 mm of the line
    ends = kincal.line_program(count=2, step_mm=1480.0)
    files = _native_line(lang, ends, calibrated)
    for name, text in files.items():
        (tmp_path / name).write_text(text)
    (tmp_path / "out").mkdir()
    (tmp_path / "m.json").write_text(calibrated.to_json())
    main = next(n for n in files if not n.endswith(".dat"))
    r = run("kincal", "compensate", "--model", str(tmp_path / "m.json"), "--program", str(tmp_path / main), "--out",
            str(tmp_path / "out" / main), "--targets", "filtered", "--tolerance", str(TOL))
    assert r.returncode == 0, r.stderr
    out = {n: (tmp_path / "out" / n).read_text() for n in files}
    written = _native_poses(lang, out)
    b, a, n = _summary(r.stderr)
    assert n == len(written) - 2 > 0 and b > TOL and a <= TOL
    q_first = kincal.compensate(calibrated, ends[:1])["q_deg"][0]
    assert _deviation(calibrated, _lin_path(calibrated, written, q_first), ends) <= TOL
    # the lines of the input are all there, in order; what was added is n copies of the line's motion
    src_in, src_out = files[main].splitlines(), out[main].splitlines()
    added = [l for l in src_out if l not in src_in]
    kept = [l for l in src_out if l in src_in]
    if lang == "ls":  # /MN renumbered: 1 J, n + 1 L, the comment; LINE_COUNT follows
        assert [re.sub(r"P\[\d+\].*", "", l) for l in src_out[4:n + 7]] == \
            ["   1:  J "] + [f"{k:4d}:  L " for k in range(2, n + 3)] + [f"{n + 3:4d}:  !done ;"]
        assert f"LINE_COUNT\t= {n + 3};" in src_out
    else:
        assert kept == [l for l in src_in if l in src_out]  # in their order
        assert len(kept) == len(src_in) - {"krl": 0, "rapid": 2, "urscript": 2}[lang]  # the two targets' lines
        motion = {"krl": r"LIN \{X .*,S \d+,T \d+\} C_DIS", "rapid": r"    MoveL \[\[.*\]\],v200,z1,tool0;",
                  "urscript": r"  movel\(p\[.*\], a=1\.2, v=0\.2\)"}[lang]
        # (URScript's targets are inline: its movej and movel lines change as well)
        assert sum(bool(re.fullmatch(motion, l)) for l in added) == n + (lang == "urscript")
        assert len(src_out) == len(src_in) + n
