"""Native programs read and filtered (issue 19, readers): a hand-written KRL program (tests/data/programs/
tape.src + tape.dat: folds, comments, I/O, a FOR loop, speeds, E6AXIS home, E6POS / POS / FRAME
declarations, an inline LIN target, CIRC) and a RAPID module (tape.mod: tooldata, a declared work
object, jointtarget + MoveAbsJ, CONST / PERS robtargets, an inline MoveL target, MoveC, I/O) are
compensated on the calibrated kr500 (conftest: 1 mm / 0.05 deg errors and compliance, seed 9) with
filtered targets. A line diff shows that only the target lines change; the changed targets, read by
regular expressions here, are selected by the controller's branch choice (select_branch) as joints
at which the calibrated model reaches the program's pose (within the printed precision). Targets
computed at run time are an error unless --skip-unresolved; malformed programs give file:line
errors, exit 1, and no output file."""

from __future__ import annotations

import difflib
import re
import shutil
from pathlib import Path

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

import kincal
from kincal import _core

from conftest import run
from test_filtered_targets import _abc_of_quaternion

DATA = Path(__file__).resolve().parents[1] / "data" / "programs"
N = r"(-?\d+(?:\.\d+)?)"


def _changed(a: str, b: str) -> list[int]:
    """1-based numbers of the lines of a that differ in b (the files have the same line count)."""
    la, lb = a.split("\n"), b.split("\n")
    assert len(la) == len(lb)
    ops = difflib.SequenceMatcher(a=la, b=lb, autojunk=False).get_opcodes()
    assert all(op in ("equal", "replace") for op, *_ in ops)
    return [i + 1 for i, (x, y) in enumerate(zip(la, lb)) if x != y]


@pytest.fixture()
def model(tmp_path, calibrated):
    path = tmp_path / "m.json"
    path.write_text(calibrated.to_json())
    return path


@pytest.mark.parametrize("tool", ["kincal", "kincal-compensate"])
def test_krl_only_target_lines_change(tmp_path, model, calibrated, tool):
    for f in ("tape.src", "tape.dat"):
        shutil.copy(DATA / f, tmp_path / f)
    (tmp_path / "out").mkdir()
    args = ["compensate"] if tool == "kincal" else []
    r = run(tool, *args, "--model", str(model), "--program", str(tmp_path / "tape.src"), "--out",
            str(tmp_path / "out" / "tape.src"), "--targets", "filtered")
    assert r.returncode == 0, r.stderr
    src_in, src_out = (DATA / "tape.src").read_text(), (tmp_path / "out" / "tape.src").read_text()
    dat_in, dat_out = (DATA / "tape.dat").read_text(), (tmp_path / "out" / "tape.dat").read_text()
    # only the inline LIN target in the .src; in the .dat the five Cartesian declarations, not the
    # E6AXIS home, the PDAT or the folds
    assert [src_in.split("\n")[i - 1] for i in _changed(src_in, src_out)] == \
        ["LIN {X 2000.0,Y -600.0,Z 520.0,A 0.0,B 90.0,C 0.0}"]
    assert [dat_in.split("\n")[i - 1].split("=")[0] for i in _changed(dat_in, dat_out)] == \
        ["DECL E6POS XP1", "DECL E6POS XP2", "DECL POS XAUX", "DECL E6POS XP3", "DECL FRAME XP4"]
    # the new targets: nominal poses with S and T that the controller turns into joints at which
    # the calibrated robot reaches the program's poses
    desired = {m.group(1): [float(m.group(k)) for k in range(2, 8)] for m in re.finditer(
        r"(\w+)=\{X " + N + ",Y " + N + ",Z " + N + ",A " + N + ",B " + N + ",C " + N, dat_in)}
    desired["inline"] = [2000.0, -600.0, 520.0, 0.0, 90.0, 0.0]
    new = {m.group(1): m for m in re.finditer(
        r"(\w+)=\{X " + N + ",Y " + N + ",Z " + N + ",A " + N + ",B " + N + ",C " + N + r"(?:,S (\d+),T (\d+))?", dat_out)}
    m = re.search(r"LIN \{X " + N + ",Y " + N + ",Z " + N + ",A " + N + ",B " + N + ",C " + N + r",S (\d+),T (\d+)\}",
                  src_out)
    assert m
    checked = 0
    for name, g, off in [(k, v, 1) for k, v in new.items() if v.group(8)] + [("inline", m, 0)]:
        pose = [float(g.group(k + off)) for k in range(1, 7)]
        t = {"pose": pose, "kuka_s": int(g.group(7 + off)), "kuka_t": int(g.group(8 + off))}
        q = _core.select_branch(calibrated, "krl", t)
        assert not isinstance(q, str), q
        reached = kincal.fk(calibrated, q)[0]
        assert np.linalg.norm(reached[:3] - desired[name][:3]) < 1e-3, name  # printed: 1e-4 mm, 1e-6 deg
        assert np.linalg.norm(np.asarray(pose[:3]) - desired[name][:3]) > 0.1  # the target did move
        checked += 1
    assert checked == 5  # XP1, XP2, XAUX, XP3 and the inline target (the FRAME has no S and T)


@pytest.mark.parametrize("tool", ["kincal", "kincal-compensate"])
def test_rapid_only_target_lines_change(tmp_path, model, calibrated, tool):
    args = ["compensate"] if tool == "kincal" else []
    out = tmp_path / "tape.mod"
    r = run(tool, *args, "--model", str(model), "--program", str(DATA / "tape.mod"), "--out", str(out),
            "--targets", "filtered")
    assert r.returncode == 0, r.stderr
    a, b = (DATA / "tape.mod").read_text(), out.read_text()
    changed = [a.split("\n")[i - 1].strip() for i in _changed(a, b)]
    assert [c.split("[[")[0] for c in changed] == ["CONST robtarget p1:=", "CONST robtarget p2:=",
                                                   "PERS robtarget paux:=", "CONST robtarget p3:=", "MoveL "]
    # the work object wtable (uframe x + 500, oframe y - 20) and the tool thead (TCP 350 mm along the flange's
    # z) are applied: the TCP is the object pose moved by (500, -20, 0), the model's tool (the flange) 350 mm
    # behind it along the target's z; the new robtargets stay in the work object
    for line in b.split("\n"):
        m = re.search(r"\[\[([^\]]*)\],\[([^\]]*)\],\[([^\]]*)\],\[9E9", line)
        if not m:
            continue
        old = re.search(r"\[\[([^\]]*)\]", a.split("\n")[b.split("\n").index(line)]).group(1)
        want = np.array([float(v) for v in old.split(",")]) + [500, -20, 0]
        xyz = np.array([float(v) for v in m.group(1).split(",")]) + [500, -20, 0]
        w, x, y, z = (float(v) for v in m.group(2).split(","))
        flange = xyz - Rotation.from_quat([x, y, z, w]).apply([0, 0, 350])
        t = {"pose": list(flange) + _abc_of_quaternion(w, x, y, z), "abb_conf": [int(v) for v in m.group(3).split(",")]}
        q = _core.select_branch(calibrated, "rapid", t)
        assert not isinstance(q, str), q
        reached = kincal.fk(calibrated, q)[0]
        tcp = reached[:3] + Rotation.from_euler("ZYX", reached[3:], degrees=True).apply([0, 0, 350])
        assert np.linalg.norm(tcp - want) < 1e-3


@pytest.mark.parametrize("tool", ["kincal", "kincal-compensate"])
def test_runtime_targets_are_listed(tmp_path, model, tool):
    mod = (DATA / "tape.mod").read_text().replace(
        "    WaitTime 0.5;\n", "    WaitTime 0.5;\n    MoveL Offs(p3,0,0,50),v100,fine,thead\\WObj:=wtable;\n"
        "    MoveL RelTool(p3,0,0,-20),v100,fine,thead\\WObj:=wtable;\n")
    (tmp_path / "rt.mod").write_text(mod)
    args = ["compensate"] if tool == "kincal" else []
    out = tmp_path / "out.mod"
    r = run(tool, *args, "--model", str(model), "--program", str(tmp_path / "rt.mod"), "--out", str(out),
            "--targets", "filtered")
    assert r.returncode == 1 and "2 motion(s) whose target kincal does not compensate" in r.stderr, r.stderr
    assert "rt.mod:20: computed at run time" in r.stderr and "Offs(p3" in r.stderr and "rt.mod:21:" in r.stderr
    assert not out.exists()
    r = run(tool, *args, "--model", str(model), "--program", str(tmp_path / "rt.mod"), "--out", str(out),
            "--targets", "filtered", "--skip-unresolved")
    assert r.returncode == 0 and "rt.mod:20: computed at run time" in r.stderr, r.stderr
    assert "passed through unchanged: MoveL Offs(p3,0,0,50)" in r.stderr
    assert "MoveL Offs(p3,0,0,50)," in out.read_text()


@pytest.mark.parametrize("tool", ["kincal", "kincal-compensate"])
@pytest.mark.parametrize("ext,edit,message", [
    (".mod", ("ENDMODULE\n", ""), "tape.mod:1: MODULE is not closed by ENDMODULE"),
    (".mod", ("MoveL p2,", "MoveL p9,"), "tape.mod:16: declared nowhere: MoveL p9,"),
    (".mod", ("[0,-2,-2,0],[9E9,9E9,9E9,9E9,9E9,9E9]];\n  CONST robtarget p2", "[0,-2,-2,0]];\n  CONST robtarget p2"),
     "tape.mod:6: a robtarget has 4 parts"),
    (".mod", ("[[1900,-720,500]", "[[1900,-72O,500]"), "tape.mod:7: the robtarget's trans and rot: '-72O' is not a number"),
    (".src", ("PTP XHOME\nEND\n", "PTP XHOME\n"), "tape.src:4: DEF is not closed by END"),
    (".src", ("LIN XP2 C_DIS", "LIN XP7 C_DIS"), "tape.src:26: declared nowhere: LIN XP7 C_DIS"),
    (".dat", ("Z 500.0,A 0.0", "Z 5OO.0,A 0.0"), "tape.dat:10: Z '5OO.0' is not a number"),
    (".dat", ("ENDDAT\n", ""), "tape.dat:3: DEFDAT is not closed by ENDDAT"),
])
def test_malformed_programs(tmp_path, model, tool, ext, edit, message):
    for f in ("tape.src", "tape.dat", "tape.mod"):
        text = (DATA / f).read_text()
        if f.endswith(ext):
            assert edit[0] in text
            text = text.replace(edit[0], edit[1], 1)
        (tmp_path / f).write_text(text)
    (tmp_path / "out").mkdir()
    prog = tmp_path / ("tape.mod" if ext == ".mod" else "tape.src")
    args = ["compensate"] if tool == "kincal" else []
    r = run(tool, *args, "--model", str(model), "--program", str(prog), "--out", str(tmp_path / "out" / prog.name),
            "--targets", "filtered")
    assert r.returncode == 1 and message in r.stderr, r.stderr
    assert not any((tmp_path / "out").iterdir())


@pytest.mark.parametrize("case,edit,where", [
    ("krl-copy", ("tape.src", "$VEL.CP = 0.2", "XP2 = XP3\n$VEL.CP = 0.2"), "tape.src:27:"),
    ("krl-field", ("tape.src", "$VEL.CP = 0.2", "XP2.Z = 650.0\n$VEL.CP = 0.2"), "tape.src:27:"),
    ("rapid-field", ("tape.mod", "    WaitTime 0.5;", "    paux.trans.z := 650;\n    WaitTime 0.5;"), "tape.mod:18:"),
    ("krl-rel", ("tape.src", "WAIT SEC 0.5", "LIN_REL {Z 10.0}\nWAIT SEC 0.5"), "tape.src:29:"),
    ("krl-operator", ("tape.src", "WAIT SEC 0.5", "LIN XP3:{X 0.0,Y 0.0,Z 10.0,A 0.0,B 0.0,C 0.0}\nWAIT SEC 0.5"),
     "tape.src:29:"),
    ("rapid-crobt", ("tape.mod", "    WaitTime 0.5;", "    MoveL CRobT(\\Tool:=thead),v100,fine,thead;\n    WaitTime 0.5;"),
     "tape.mod:19:"),
])
def test_targets_assigned_or_computed_in_the_program_are_run_time(tmp_path, model, case, edit, where):
    # a target the program assigns (whole or one field) or computes (_REL, A:B, CRobT) is known at run time
    # only: listed, not compensated
    # from its declaration (the .src is read before the .dat that declares XP2)
    name, old, new = edit
    for f in ("tape.src", "tape.dat", "tape.mod"):
        text = (DATA / f).read_text()
        if f == name:
            assert old in text
            text = text.replace(old, new, 1)
        (tmp_path / f).write_text(text)
    (tmp_path / "out").mkdir()
    r = run("kincal", "compensate", "--model", str(model), "--program", str(tmp_path / name), "--out",
            str(tmp_path / "out" / name))
    assert r.returncode == 1 and "whose target kincal does not compensate" in r.stderr, r.stderr
    why = "a relative motion (LIN_REL)" if case == "krl-rel" else "computed at run time"
    assert f"{where} {why}" in r.stderr or (case.startswith("krl") and where in r.stderr and why in r.stderr), r.stderr
    assert not any((tmp_path / "out").iterdir())


@pytest.mark.parametrize("name", ["tape.src", "tape.mod", "tape.ls", "tape.script"])
def test_crlf_programs_keep_their_line_ends(tmp_path, model, name):
    # the same program with CRLF line ends (as controllers and Windows editors write them) comes out as
    # the LF one does, with CRLF: byte for byte, inserted --tolerance targets included
    for d, eol in (("lf", b"\n"), ("crlf", b"\r\n")):
        (tmp_path / d / "out").mkdir(parents=True)
        for f in DATA.glob(Path(name).stem + ".*"):
            (tmp_path / d / f.name).write_bytes(f.read_bytes().replace(b"\n", eol))
        r = run("kincal-compensate", "--model", str(model), "--program", str(tmp_path / d / name), "--out",
                str(tmp_path / d / "out" / name), "--skip-unresolved", "--tolerance", "0.001")
        assert r.returncode == 0, r.stderr
    inserted = int(re.search(r"after (\d+) inserted", r.stderr).group(1))
    assert inserted > 0  # (0.001 mm: the short segments of these programs need targets too)
    for f in (tmp_path / "lf" / "out").iterdir():
        lf, crlf = f.read_bytes(), (tmp_path / "crlf" / "out" / f.name).read_bytes()
        assert b"\r" not in lf and crlf == lf.replace(b"\n", b"\r\n"), f.name


def test_program_tool_and_base(tmp_path, model, calibrated):
    # --program-base B and --program-tool T: a program pose P (in B, of the TCP T) is the model's tool at
    # B P T^-1 in the robot's base. XP1 (PTP only) is written as joints: the calibrated model's tool there
    for f in ("tape.src", "tape.dat"):
        shutil.copy(DATA / f, tmp_path / f)
    (tmp_path / "out").mkdir()
    base, tool = [100.0, -50.0, 20.0, 5.0, 0.0, 0.0], [0.0, 0.0, 50.0, 0.0, 0.0, 10.0]
    r = run("kincal", "compensate", "--model", str(model), "--program", str(tmp_path / "tape.src"), "--out",
            str(tmp_path / "out" / "tape.src"), "--program-base", ",".join(map(str, base)), "--program-tool",
            ",".join(map(str, tool)))
    assert r.returncode == 0, r.stderr
    m = re.search(r"DECL E6AXIS XP1=\{A1 " + ",A\\d ".join([N] * 6), (tmp_path / "out" / "tape.dat").read_text())
    assert m
    q = [float(m.group(k)) for k in range(1, 7)]

    def iso(p):
        t = np.eye(4)
        t[:3, :3] = Rotation.from_euler("ZYX", p[3:], degrees=True).as_matrix()
        t[:3, 3] = p[:3]
        return t

    want = iso(base) @ iso([2000.0, -740.0, 600.0, 0.0, 90.0, 0.0]) @ np.linalg.inv(iso(tool))
    got = iso(kincal.fk(calibrated, q)[0])
    assert np.abs(got[:3, 3] - want[:3, 3]).max() < 1e-3
    assert np.degrees(Rotation.from_matrix(got[:3, :3].T @ want[:3, :3]).magnitude()) < 1e-4


@pytest.mark.parametrize("tool", ["kincal", "kincal-compensate"])
def test_crlf_gcode_keeps_its_line_ends(tmp_path, model, tool):
    # G-code with CRLF line ends comes back with CRLF (the LF program's output with each "\n" a "\r\n"),
    # --tolerance's inserted lines included; before, both tools wrote LF only
    poses = kincal.line_program(count=3, step_mm=700.0)
    text = "; course 1\nN10 G90 (absolute)\n" + "".join(
        f"N{20 + 10 * i} G1 " + " ".join(f"{k}{v:.4f}" for k, v in zip("XYZABC", p)) + " F3000 ; pose\n"
        for i, p in enumerate(poses)) + "M30\n"
    args = ["compensate"] if tool == "kincal" else []
    for d, eol in (("lf", b"\n"), ("crlf", b"\r\n")):
        (tmp_path / d).mkdir()
        (tmp_path / d / "p.gcode").write_bytes(text.encode().replace(b"\n", eol))
        r = run(tool, *args, "--model", str(model), "--program", str(tmp_path / d / "p.gcode"), "--out",
                str(tmp_path / d / "o.gcode"), "--tolerance", "0.001")
        assert r.returncode == 0, r.stderr
    lf, crlf = (tmp_path / "lf" / "o.gcode").read_bytes(), (tmp_path / "crlf" / "o.gcode").read_bytes()
    assert lf.count(b"\n") > text.count("\n")  # targets were inserted
    assert b"\r" not in lf and crlf == lf.replace(b"\n", b"\r\n")


@pytest.mark.parametrize("tool", ["kincal", "kincal-compensate"])
def test_filtered_module_takes_the_name_of_its_file(tmp_path, model, tool):
    # a KRL module is named by its files (DEF in the .src, DEFDAT in the .dat): written to another file name it
    # takes that name, every other line as when written under its own name; a file name the controller cannot
    # take is refused, naming --out and the rule, nothing written. RAPID does not tie a module's name to its
    # file's: MODULE keeps its name under any file name (issue 30: MainModule in test_4.mod came back renamed)
    for f in ("tape.src", "tape.dat", "tape.mod"):
        shutil.copy(DATA / f, tmp_path / f)
    args = ["compensate"] if tool == "kincal" else []
    for d in ("same", "other", "bad"):
        (tmp_path / d).mkdir()
    for prog, new, head in (("tape.src", "other.src", ["DEF tape( )", "DEFDAT  tape"]),
                            ("tape.mod", "other-1.mod", [])):
        common = [*args, "--model", str(model), "--program", str(tmp_path / prog), "--targets", "filtered"]
        assert run(tool, *common, "--out", str(tmp_path / "same" / prog)).returncode == 0
        r = run(tool, *common, "--out", str(tmp_path / "other" / new))
        assert r.returncode == 0, r.stderr
        exts = (".src", ".dat") if prog.endswith(".src") else (".mod",)
        same = "".join((tmp_path / "same" / ("tape" + e)).read_text() for e in exts)
        other = "".join((tmp_path / "other" / (Path(new).stem + e)).read_text() for e in exts)
        for h in head:
            assert h in same
            same = same.replace(h, h.replace("tape", "other"))
        assert other == same
        if prog.endswith(".mod"):
            assert "MODULE tape" in other
            continue
        bad = tmp_path / "bad" / ("other-1" + Path(prog).suffix)
        r = run(tool, *common, "--out", str(bad))
        assert r.returncode == 1 and f"--out {bad}: a KRL module is named by its file" in r.stderr, r.stderr
        assert "'other-1' is not a" in r.stderr and "a letter, then letters, digits or '_'" in r.stderr
        assert not any((tmp_path / "bad").iterdir())
