"""FANUC LS and URScript programs read and filtered (issue 19, readers): a hand-written LS program
(tests/data/programs/tape.ls: /ATTR, comments, UFRAME/UTOOL, I/O, WAIT, a FOR loop, a joint HOME
position, CNT/FINE, C with its continuation line, a PR[] motion and an Offset motion) and a URScript
program (tape.script: set_tcp, set_payload, pose variables, a joint list, movej/movel/movec, a while
loop, I/O, a pose_trans motion) are compensated on the calibrated kr500 (conftest: 1 mm / 0.05 deg
errors and compliance, seed 9) with filtered targets. A line diff shows that only target values
change; the new values, read by regular expressions here, are poses at which the controller's
nominal IK (LS: the branch its CONFIG selects; UR: some IK solution, as a UR takes the one nearest its
joints) gives joints where the calibrated robot reaches the program's pose (within the printed
precision). Run-time targets are an error unless --skip-unresolved; malformed programs give file:line
errors, exit 1, and no output file."""

from __future__ import annotations

import math
import re
import shutil
from pathlib import Path

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

import kincal
from kincal import _core

from conftest import run
from test_native_programs import _changed

DATA = Path(__file__).resolve().parents[1] / "data" / "programs"
N = r"(-?\d*\.?\d+)"
LS_POS = (r"P\[(\d+)[^\]]*\]\{\s*GP1:\s*UF : 0, UT : 1,\s*CONFIG : '([^']*)',\s*X =\s*" + N + r"\s*mm,\s*Y =\s*" + N +
          r"\s*mm,\s*Z =\s*" + N + r"\s*mm,\s*W =\s*" + N + r"\s*deg,\s*P =\s*" + N + r"\s*deg,\s*R =\s*" + N)


def _ls_positions(text: str) -> dict:
    return {int(m.group(1)): (m.group(2), [float(m.group(k)) for k in (3, 4, 5, 8, 7, 6)])
            for m in re.finditer(LS_POS, text)}


def _ur_poses(text: str) -> list:
    out = []
    for m in re.finditer(r"(?<!set_tcp\()p\[([^\]]*)\]", text):
        v = [float(x) for x in m.group(1).split(",")]
        abc = Rotation.from_rotvec(v[3:]).as_euler("ZYX", degrees=True)
        out.append(np.array([1000 * v[0], 1000 * v[1], 1000 * v[2], *abc]))
    return out


@pytest.fixture()
def model(tmp_path, calibrated):
    path = tmp_path / "m.json"
    path.write_text(calibrated.to_json())
    return path


def _reaches(calibrated, q, desired, tol_mm) -> bool:
    p = kincal.fk(calibrated, q)[0]
    dr = Rotation.from_euler("ZYX", p[3:], degrees=True).inv() * Rotation.from_euler("ZYX", desired[3:], degrees=True)
    return np.linalg.norm(p[:3] - desired[:3]) < tol_mm and math.degrees(dr.magnitude()) < 1e-3


@pytest.mark.parametrize("tool", ["kincal", "kincal-compensate"])
def test_ls_only_target_values_change(tmp_path, model, calibrated, tool):
    shutil.copy(DATA / "tape.ls", tmp_path / "tape.ls")
    args = ["compensate"] if tool == "kincal" else []
    (tmp_path / "out").mkdir()
    out = tmp_path / "out" / "tape.ls"  # the program's own name: /PROG TAPE stays (a new name renames it)
    base = [*args, "--model", str(model), "--program", str(tmp_path / "tape.ls"), "--out", str(out), "--targets", "filtered"]
    r = run(tool, *base)
    assert r.returncode != 0 and not out.exists()
    assert "tape.ls:36" in r.stderr and "tape.ls:37" in r.stderr  # PR[2] and Offset,PR[3]
    r = run(tool, *base, "--skip-unresolved")
    assert r.returncode == 0, r.stderr
    assert "tape.ls:36" in r.stderr and "warning" in r.stderr
    a, b = (DATA / "tape.ls").read_text(), out.read_text()
    changed = _changed(a, b)
    lines = a.split("\n")
    # the X/Y/Z and W/P/R lines of P[2..5] (CONFIG where the branch data changes), nothing else
    xyz = [i + 1 for i, l in enumerate(lines) if l.lstrip().startswith(("X =", "W ="))]
    assert set(xyz) <= set(changed) and len(xyz) == 8
    assert all(lines[i - 1].lstrip().startswith(("X =", "W =", "UF : 0, UT : 1,\t\tCONFIG")) for i in changed)
    desired, new = _ls_positions(a), _ls_positions(b)
    assert sorted(new) == [2, 3, 4, 5]
    for n, (config, pose) in new.items():
        t = {"pose": pose, "fanuc_config": config}
        q = _core.select_branch(calibrated, "fanuc-ls", t)
        assert not isinstance(q, str), q
        assert _reaches(calibrated, q, np.array(desired[n][1]), 5e-3)


@pytest.mark.parametrize("tool", ["kincal", "kincal-compensate"])
def test_urscript_only_target_values_change(tmp_path, model, calibrated, tool):
    args = ["compensate"] if tool == "kincal" else []
    out = tmp_path / "out.script"
    base = [*args, "--model", str(model), "--program", str(DATA / "tape.script"), "--out", str(out), "--targets",
            "filtered"]
    r = run(tool, *base)
    assert r.returncode != 0 and "tape.script:19" in r.stderr and not out.exists()  # pose_trans
    r = run(tool, *base, "--skip-unresolved")
    assert r.returncode == 0, r.stderr
    a, b = (DATA / "tape.script").read_text(), out.read_text()
    assert _changed(a, b) == [5, 6, 11, 12]  # approach, lay_end, the inline movel and movec via points
    for old, new in zip(a.split("\n"), b.split("\n")):  # only the p[...] values inside the lines change
        assert re.sub(r"p\[[^\]]*\]", "p[]", old) == re.sub(r"p\[[^\]]*\]", "p[]", new)
    desired, written = _ur_poses(a), _ur_poses(b)
    assert len(desired) == len(written) == 5  # approach, lay_end, movel, movec via, pose_trans offset
    for d, w in zip(desired[:4], written[:4]):
        sols = [np.asarray(s["q_deg"]) for s in _core.ik_all(calibrated, w) if s["within_limits"]]
        assert any(_reaches(calibrated, q, d, 1e-3) for q in sols)
    assert np.allclose(desired[4], written[4])  # the offset inside pose_trans is not a target


MALFORMED = [
    ("tape.ls", lambda s: s.replace("/END\n", ""), "tape.ls:1", "not closed by /END"),
    ("tape.ls", lambda s: s.replace("L P[3] 200mm", "L P[9] 200mm"), "tape.ls:29", "not declared"),
    ("tape.ls", lambda s: s.replace("Y =  -600.000", "Y =  -6o0.000"), "tape.ls:62", "not a number"),
    ("tape.ls", lambda s: s.replace("W =   180.000 deg,\tP =     0.000 deg,\tR =   180.000 deg\n};\nP[5]",
                                    "W =   180.000 deg\n};\nP[5]"), "tape.ls:61", "no P value"),
    ("tape.script", lambda s: s[:s.rindex("end")], "tape.script:1", "not closed by 'end'"),
    ("tape.script", lambda s: s.replace("p[2.0, -0.72, 0.5, 0,", "p[2.0, -0.72, 0.5,"), "tape.script:11", "6 values"),
    ("tape.script", lambda s: s.replace("-0.48", "-0.4x8"), "tape.script:6", "not a number"),
    ("tape.script", lambda s: s.replace("movel(lay_end", "movel(lay_start"), "tape.script:16", "not assigned"),
]


@pytest.mark.parametrize("name,edit,where,cause", MALFORMED)
@pytest.mark.parametrize("tool", ["kincal", "kincal-compensate"])
def test_malformed_programs(tmp_path, model, name, edit, where, cause, tool):
    (tmp_path / name).write_text(edit((DATA / name).read_text()))
    out = tmp_path / ("out" + Path(name).suffix)
    args = ["compensate"] if tool == "kincal" else []
    r = run(tool, *args, "--model", str(model), "--program", str(tmp_path / name), "--out", str(out), "--targets",
            "filtered", "--skip-unresolved")
    assert r.returncode == 1, r.stderr
    assert where + ":" in r.stderr and cause in r.stderr, r.stderr
    assert not out.exists()


# P[n]: (UF, UT) in the several-frames program, and the frames given for them (X, Y, Z, A, B, C)
LS_FRAMES = {2: (1, 1), 3: (2, 1), 4: (2, 2), 5: (1, 2)}
UFRAMES = {1: [300.0, -200.0, 50.0, 10.0, 0.0, 0.0], 2: [-100.0, 80.0, 0.0, -15.0, 2.0, 0.0]}
UTOOLS = {1: [0.0, 0.0, 40.0, 0.0, 0.0, 0.0], 2: [5.0, -3.0, 60.0, 20.0, 0.0, 5.0]}
LS_ANY = (r"P\[(\d+)[^\]]*\]\{\s*GP1:\s*UF : (\d+), UT : (\d+),\s*CONFIG : '([^']*)',\s*X =\s*" + N + r"\s*mm,\s*Y =\s*" +
          N + r"\s*mm,\s*Z =\s*" + N + r"\s*mm,\s*W =\s*" + N + r"\s*deg,\s*P =\s*" + N + r"\s*deg,\s*R =\s*" + N)


def _iso(p) -> np.ndarray:
    t = np.eye(4)
    t[:3, :3] = Rotation.from_euler("ZYX", p[3:], degrees=True).as_matrix()
    t[:3, 3] = p[:3]
    return t


def _xyzabc(t: np.ndarray) -> list:
    return [*t[:3, 3], *Rotation.from_matrix(t[:3, :3]).as_euler("ZYX", degrees=True)]


def _several_frames_program(tmp_path) -> Path:
    """tape.ls with its Cartesian positions in two user frames and two tools (LS_FRAMES)."""
    tmp_path.mkdir(exist_ok=True)
    text = (DATA / "tape.ls").read_text()
    for n, (uf, ut) in LS_FRAMES.items():
        text = re.sub(r"(P\[" + str(n) + r"[^\]]*\]\{\s*GP1:\s*)UF : 0, UT : 1,", rf"\g<1>UF : {uf}, UT : {ut},", text)
    path = tmp_path / "frames.ls"
    text = text.replace("/PROG  TAPE", "/PROG  FRAMES", 1)  # named by its file, as on the controller
    path.write_text(text)
    return path


def _reached_in_frames(tool, tmp_path, model, calibrated, uframes: dict) -> list:
    """Compensates the several-frames program with ``uframes`` and UTOOLS given; per written position,
    whether the pose it describes in the robot's base (UFRAMES x pose x UTOOLS^-1, the frames the
    program means), run through the nominal IK branch its CONFIG selects, puts the calibrated robot's tool
    where the program's pose is (within 5e-3 mm, 1e-3 deg). Checks that only X..R and CONFIG lines change."""
    program = _several_frames_program(tmp_path)
    (tmp_path / "out").mkdir(exist_ok=True)
    out = tmp_path / "out" / program.name  # under its own name: only positions change (/PROG too otherwise)
    args = ["compensate"] if tool == "kincal" else []
    frames = [a for n, f in uframes.items() for a in ("--uframe", f"{n}=" + ",".join(map(str, f)))]
    frames += [a for n, f in UTOOLS.items() for a in ("--utool", f"{n}=" + ",".join(map(str, f)))]
    r = run(tool, *args, "--model", str(model), "--program", str(program), "--out", str(out), "--targets", "filtered",
            "--skip-unresolved", *frames)
    assert r.returncode == 0, r.stderr
    a, b = program.read_text(), out.read_text()
    lines = a.split("\n")
    assert all(lines[i - 1].lstrip().startswith(("X =", "W =", "UF : ")) for i in _changed(a, b))
    desired = {int(m.group(1)): [float(m.group(k)) for k in (5, 6, 7, 10, 9, 8)] for m in re.finditer(LS_ANY, a)}
    written = list(re.finditer(LS_ANY, b))
    assert sorted(int(m.group(1)) for m in written) == [2, 3, 4, 5]
    reached = []
    for m in written:
        n, uf, ut = int(m.group(1)), int(m.group(2)), int(m.group(3))
        assert (uf, ut) == LS_FRAMES[n]
        base, tcp = _iso(UFRAMES[uf]), np.linalg.inv(_iso(UTOOLS[ut]))
        pose = _xyzabc(base @ _iso([float(m.group(k)) for k in (5, 6, 7, 10, 9, 8)]) @ tcp)
        q = _core.select_branch(calibrated, "fanuc-ls", {"pose": pose, "fanuc_config": m.group(4)})
        reached.append(not isinstance(q, str) and
                       _reaches(calibrated, q, np.array(_xyzabc(base @ _iso(desired[n]) @ tcp)), 5e-3))
    return reached


@pytest.mark.parametrize("tool", ["kincal", "kincal-compensate"])
def test_ls_several_user_frames_and_tools(tmp_path, model, calibrated, tool):
    """An LS program whose positions use UF 1 and 2 and UT 1 and 2 (LS_FRAMES): each position is
    compensated in its own frames (--uframe N=.., --utool N=..), and only X..R and CONFIG change; every
    written position, read back here through its frames and CONFIG, puts the calibrated robot on the
    program's pose. The control: with the two user frames given the wrong way round, the same check
    fails for every position (so it sees the frames)."""
    assert all(_reached_in_frames(tool, tmp_path / "right", model, calibrated, UFRAMES))
    swapped = {1: UFRAMES[2], 2: UFRAMES[1]}
    assert not any(_reached_in_frames(tool, tmp_path / "swapped", model, calibrated, swapped))


@pytest.mark.parametrize("tool", ["kincal", "kincal-compensate"])
def test_ls_several_frames_need_each_given(tmp_path, model, tool):
    """Positions in several UF or UT without a frame for each, or --uframe given for some of the UFs
    used only, or for one no position uses, or beside --program-base: an error naming the position's
    file:line (or the option) and the cause; --uframe on a KRL program or a pose program, a malformed
    --uframe and --tolerance across tools are errors too; no output file."""
    program = _several_frames_program(tmp_path)
    out = tmp_path / "out.ls"
    args = ["compensate"] if tool == "kincal" else []
    base = [*args, "--model", str(model), "--program", str(program), "--out", str(out), "--skip-unresolved"]
    line_p3 = program.read_text().split("\n").index("P[3]{") + 1
    line_p2 = program.read_text().split("\n").index('P[2:"approach"]{') + 1
    every = [a for n in (1, 2) for a in ("--uframe", f"{n}=0,0,0,0,0,0", "--utool", f"{n}=0,0,0,0,0,0")]
    cases = [([], f"frames.ls:{line_p3 + 2}: P[3] is in UF 2, P[2] in UF 1", "--uframe N=X,Y,Z,A,B,C"),
             (["--uframe", "1=0,0,0,0,0,0", "--uframe", "2=0,0,0,0,0,0"], "P[4] is in UT 2, P[2] in UT 1", "--utool"),
             (["--uframe", "1=0,0,0,0,0"], "--uframe 1=0,0,0,0,0: 5 numbers", "expected N=X,Y,Z,A,B,C"),
             (["--uframe", "x=0,0,0,0,0,0"], "--uframe x=0,0,0,0,0,0: not N=..", "number 0..99"),
             (["--uframe", "1=0x10,0,0,0,0,0"], "'0x10' is not a number", "--uframe"),
             (["--uframe", "2=0,0,0,0,0,0", "--utool", "2=0,0,0,0,0,0"], "P[2] is in UF 1, which no --uframe gives",
              f"frames.ls:{line_p2 + 2}"),
             (every + ["--uframe", "7=0,0,0,0,0,0"], "--uframe 7: no position is in UF 7", "frames.ls"),
             (every + ["--program-base", "1,0,0,0,0,0"], "--uframe and --program-base together", "--uframe"),
             (every[:-4] + ["--uframe", "2=0,0,0,0,0,0", "--utool", "2=0,0,10,0,0,0", "--tolerance", "0.05"],
              "--tolerance follows the path of one tool", "P[4] is in another tool than P[2]")]
    for extra, where, cause in cases:
        r = run(tool, *base, *extra)
        assert r.returncode == 1 and where in r.stderr and cause in r.stderr and not out.exists(), (extra, r.stderr)
    for f in ("tape.src", "tape.dat"):
        shutil.copy(DATA / f, tmp_path / f)
    r = run(tool, *args, "--model", str(model), "--program", str(tmp_path / "tape.src"), "--out",
            str(tmp_path / "o" / "tape.src"), "--uframe", "1=0,0,0,0,0,0")
    assert r.returncode == 1 and "apply to FANUC LS programs" in r.stderr and not (tmp_path / "o").exists(), r.stderr
    (tmp_path / "poses.csv").write_text("x,y,z,a,b,c\n2000,-720,600,180,0,180\n")
    r = run(tool, *args, "--model", str(model), "--program", str(tmp_path / "poses.csv"), "--out",
            str(tmp_path / "o.csv"), "--utool", "1=0,0,0,0,0,0")
    assert r.returncode == 1 and "apply to FANUC LS programs" in r.stderr and not (tmp_path / "o.csv").exists(), r.stderr


@pytest.mark.parametrize("tool", ["kincal", "kincal-compensate"])
def test_ls_program_takes_the_name_of_its_file(tmp_path, model, tool):
    """A FANUC LS program is named by /PROG (upper case, as its file on the controller): tape.ls
    written as other.ls says /PROG OTHER, every other line as when written under its own name; a
    name the controller cannot take is refused, naming --out and the rule, nothing written."""
    shutil.copy(DATA / "tape.ls", tmp_path / "tape.ls")
    args = ["compensate"] if tool == "kincal" else []
    common = [*args, "--model", str(model), "--program", str(tmp_path / "tape.ls"), "--targets", "filtered",
              "--skip-unresolved"]
    for d in ("same", "other", "bad"):
        (tmp_path / d).mkdir()
    assert run(tool, *common, "--out", str(tmp_path / "same" / "tape.ls")).returncode == 0
    r = run(tool, *common, "--out", str(tmp_path / "other" / "other.ls"))
    assert r.returncode == 0, r.stderr
    same, other = (tmp_path / "same" / "tape.ls").read_text(), (tmp_path / "other" / "other.ls").read_text()
    head = next(l for l in same.splitlines() if l.startswith("/PROG"))
    assert "TAPE" in head and other == same.replace(head, head.replace("TAPE", "OTHER"), 1)
    r = run(tool, *common, "--out", str(tmp_path / "bad" / "2nd.ls"))
    assert r.returncode == 1 and "a FANUC LS module is named by its file" in r.stderr and "'2ND' is not a" in r.stderr
    assert not any((tmp_path / "bad").iterdir())
