"""Programs as users write them (issue 30, item 6): every program of tests/data/programs/corpus (KRL from KSS 5
and KSS 8 with a controller's $config.dat, RAPID modules, FANUC LS, URScript; see the README there) is filtered
with `kincal compensate --targets filtered` on the calibrated kr500 (conftest: 1 mm / 0.05 deg errors and
compliance, seed 9), placed in reach by the frames of the table below, and checked by a reader written here
(regular expressions, not kincal's parser):

(a) a line diff: only target values change (numbers of the pose and the branch data; external axes, speeds,
    everything else byte for byte), besides the declarations of copies that issue 30 item 4 adds (a target used
    in a second frame: NAME_k declared next to NAME, the motions in that frame renamed);
(b) every written Cartesian target: the controller's nominal IK (select_branch with the written branch data;
    URScript: the solution nearest the previous joints, as a UR moves) gives joints at which the calibrated model
    reaches the program's pose through the frames this reader finds (KRL BASE_DATA/TOOL_DATA of FDAT, $BASE/$TOOL,
    WITH; RAPID wobjdata uframe*oframe and tooldata of the statement; LS --uframe/--utool; a track axis moving the
    base; --program-base for base 0), to 1e-3 mm and 1e-3 deg (LS prints 1e-3 mm and deg: 5e-3 mm there);
(c) the taught branch: S (ABB cfx; FANUC F/N U/D T/B) as in the input; T bits (cf1/cf4/cf6; turns) too, unless
    kincal warns naming the target (the compensation moved a joint across the border).

A refused program: exit 1, the expected cause in stderr, nothing written. The table's "needs" names the features
of issue 30 each expectation depends on (the build before them fails those entries; that is expected)."""

from __future__ import annotations

import difflib
import math
import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

import kincal
from kincal import _core

from conftest import run

CORPUS = Path(__file__).resolve().parents[1] / "data" / "programs" / "corpus"
CONFIG = CORPUS / "krl_backup" / "KRC" / "R1" / "System" / "$config.dat"
NUM = r"-?\d*\.?\d+(?:[Ee][+-]?\d+)?"


@dataclass
class Case:
    path: str                    # relative to CORPUS
    expect: str                  # "filtered" or "refused: <text in stderr>"
    args: list = field(default_factory=list)   # frames and options, as a user gives them
    needs: str = ""              # the features of issue 30 the expectation depends on
    declarations: bool = False   # the controller's $config.dat given with --declarations


KRL_B = "krl_backup/KRC/R1/Program/"
UF = ["--uframe", "1=1700,-400,300,0,0,90", "--uframe", "2=1900,300,600,0,0,-20"]
UT = ["--utool", "1=0,0,230,0,0,0", "--utool", "2=0,-95,310,0,0,-25"]
TABLE = [
    # KRL: KSS 5 inline forms, KSS 8 ILF and spline, frames from $config.dat
    Case(KRL_B + "pallet_layer.src", "filtered", [], "declarations (XHOME, FDAT), per-motion frames (TOOL_NO/BASE_NO), taught branch", True),
    Case(KRL_B + "glue_bead.src", "filtered", [], "declarations, per-motion frames, copy XP2_1 (XP2 in a second base), inline LIN {..} C_DIS, taught branch (S 6)", True),
    Case(KRL_B + "seam_spline.src", "filtered", ["--skip-unresolved"], "declarations, $TOOL/$BASE = *_DATA[n] and WITH, SPLINE/SPL/SCIRC, SLIN_REL listed, taught branch", True),
    Case(KRL_B + "load_station.src", "filtered", [], "declarations, KSS 8 ILF (STOOL2(FPn)/SBASE(FPn.BASE_NO)), per-motion frames, taught branch (S 6)", True),
    Case(KRL_B + "grind_edge.src", "refused: #TCP", [], "declarations, stationary tool refused by name (IPO_FRAME #TCP)", True),
    Case("krl/pocket_mill.src", "filtered", [], "$BASE/$TOOL FRAME literals applied"),
    Case("krl/test_cell.src", "filtered", ["--program-base", "1200,-200,300,0,0,0"], "taught branch (S 6 target)"),
    # RAPID
    Case("rapid/rs_two_tools.mod", "filtered", [], "per-statement tooldata"),
    Case("rapid/spot_fixtures.mod", "filtered", [], "per-statement tooldata, copy pApproach_1/pSpot1_1 (second work object), SpotL read"),
    Case("rapid/weld_seam.mod", "filtered", ["--skip-unresolved"], "ArcLStart/ArcL/ArcC/ArcLEnd read, per-statement tooldata"),
    Case("rapid/multimove_rob1.mod", "filtered", [], "\\ID:= on declared and inline targets, per-statement tooldata"),
    Case("rapid/parta_prog.sys", "filtered", ["--program-base", "1500,-250,400,0,0,0"], ".sys read, robtargets over several lines, TriggL/SearchL read, MODULE name kept"),
    Case("rapid/track_beam.mod", "filtered", ["--track", "E1=1,0,0"], "--track, per-statement tooldata"),
    Case("rapid/turntable.mod", "refused: turntable.mod:11:", [], "an external axis that varies without --track is refused at its first motion"),
    # FANUC LS
    Case("ls/pick_two_frames.ls", "filtered", UF + UT, "taught branch"),
    Case("ls/arc_seam.ls", "filtered", ["--uframe", "3=2000,-150,550,0,0,15", "--utool", "3=-12,0,395,0,35,0"], "continuation lines with Arc Start/Arc End, taught branch"),
    Case("ls/calib_poses.ls", "filtered", ["--program-base", "1500,0,200,0,0,0"], "GP2 kept, taught branch"),
    Case("ls/take_st20.ls", "filtered", ["--uframe", "1=1700,-400,300,0,0,90", "--utool", "2=0,-95,310,0,0,-25", "--skip-unresolved"],
         "point logic (TB .. P-SPS) lines, Offset/Tool_Offset listed, taught branch"),
    Case("ls/track_load.ls", "filtered", ["--uframe", "2=1900,300,600,0,0,-20", "--utool", "1=0,0,230,0,0,0", "--track", "E1=0,1,0"], "--track (E1)"),
    # URScript
    Case("urscript/pick_place.script", "filtered", ["--program-base", "1600,-200,500,0,0,0", "--program-tool", "0,0,185,0,0,0"], ""),
    Case("urscript/polyscope_loop.script", "filtered", ["--program-base", "1550,100,450,0,0,0"], "global Waypoint_n_p read"),
    Case("urscript/relative_square.script", "refused: computed at run time", [], ""),
]


# ------------------------------------------------------------------------------------------------ frames
def iso(p) -> np.ndarray:
    t = np.eye(4)
    t[:3, :3] = Rotation.from_euler("ZYX", p[3:], degrees=True).as_matrix()
    t[:3, 3] = p[:3]
    return t


def iso_q(xyz, q) -> np.ndarray:
    t = np.eye(4)
    t[:3, :3] = Rotation.from_quat([q[1], q[2], q[3], q[0]]).as_matrix()
    t[:3, 3] = xyz
    return t


def xyzabc(t) -> list:
    return [*t[:3, 3], *Rotation.from_matrix(t[:3, :3]).as_euler("ZYX", degrees=True)]


def nums(s) -> list:
    return [float(v) for v in re.findall(NUM, s)]


def opt_frame(args, name, default=None):
    if name in args:
        return iso(nums(args[args.index(name) + 1]))
    return np.eye(4) if default is None else default


def opt_map(args, name) -> dict:
    return {int(args[i + 1].split("=")[0]): args[i + 1].split("=", 1)[1] for i, a in enumerate(args) if a == name}


@dataclass
class Use:
    """One motion's Cartesian target: its value's text and parsed pose, its frames (program frame in the robot's
    base, TCP in the flange), its branch data, and the names that identify it in kincal's messages."""
    name: str
    pose: np.ndarray      # 4x4 in the program's frame
    base: np.ndarray
    tool: np.ndarray
    branch: dict
    where: str
    external: float | None = None  # the track / external axis value (RAPID eax_a, LS E1), None when none


# ------------------------------------------------------------------------------------------------ KRL
KRL_POS = r"\{\s*X\s+(" + NUM + r")\s*,\s*Y\s+(" + NUM + r")\s*,\s*Z\s+(" + NUM + r")\s*,\s*A\s+(" + NUM + r")\s*,\s*B\s+(" + \
    NUM + r")\s*,\s*C\s+(" + NUM + r")(?:\s*,\s*S\s+(\d+)\s*,\s*T\s+(\d+))?"
KRL_MOTION = re.compile(r"^\s*(PTP|LIN|CIRC|SPTP|SLIN|SCIRC|SPL)\s+(.*)$", re.I)


def krl_frames(text: str) -> dict:
    out = {}
    for m in re.finditer(r"^\s*\$?((?:TOOL|BASE)_DATA\[\d+\])\s*=\s*" + KRL_POS, text, re.M | re.I):
        out[m.group(1).upper()] = iso([float(m.group(k)) for k in range(2, 8)])
    return out


def krl_uses(src: Path, dat_text: str, frames: dict, pb: np.ndarray) -> list:
    text = src.read_text()
    decl = {m.group(1).upper(): re.search(KRL_POS, m.group(0))
            for m in re.finditer(r"DECL\s+(?:E6POS|POS)\s+(\w+)\s*=\s*" + KRL_POS, dat_text, re.I)}
    fdat = {m.group(1).upper(): m for m in re.finditer(r"DECL\s+FDAT\s+(\w+)\s*=\s*\{TOOL_NO\s+(\d+),BASE_NO\s+(\d+),IPO_FRAME\s+(#\w+)",
                                                       dat_text, re.I)}
    tool, base, uses = np.eye(4), np.eye(4), []

    def frame_of(kind, n):
        return np.eye(4) if int(n) == 0 else frames[f"{kind}_DATA[{int(n)}]"]

    def set_frames(code):
        nonlocal tool, base
        for m in re.finditer(r"\$(TOOL|BASE)\s*=\s*\$NULLFRAME|BAS\s*\(\s*#(TOOL|BASE)\s*,\s*(\d+)\s*\)", code, re.I):
            kind = (m.group(1) or m.group(2)).upper()
            f = np.eye(4) if m.group(1) else frame_of(kind, m.group(3))
            if kind == "TOOL":
                tool = f
            else:
                base = f
        for m in re.finditer(r"\$(TOOL|BASE)\s*=\s*(?:(TOOL|BASE)_DATA\[(\d+)\]|\{FRAME:\s*([^}]*)\}|S(?:TOOL2|BASE)\((\w+))", code, re.I):
            if m.group(3):
                f = frame_of(m.group(2).upper(), m.group(3))
            elif m.group(4):
                f = iso(nums(m.group(4)))
            elif m.group(5).upper() not in fdat:
                f = np.eye(4)  # FHOME of $config.dat: tool 0, base 0
            else:
                fd = fdat[m.group(5).upper()]
                f = frame_of(m.group(1).upper(), fd.group(2) if m.group(1).upper() == "TOOL" else fd.group(3))
            if m.group(1).upper() == "TOOL":
                tool = f
            else:
                base = f
    for i, line in enumerate(text.split("\n"), 1):
        code = line.split(";")[0]
        m = re.match(r"\s*FDAT_ACT\s*=\s*(\w+)", code, re.I)
        if m and m.group(1).upper() in fdat:
            fd = fdat[m.group(1).upper()]
            assert fd.group(4).upper() == "#BASE", f"{src.name}:{i}: IPO_FRAME {fd.group(4)} (the reader here knows #BASE only)"
            tool, base = frame_of("TOOL", fd.group(2)), frame_of("BASE", fd.group(3))
            continue
        mm = KRL_MOTION.match(code)
        if not mm:
            set_frames(code)
            continue
        set_frames(mm.group(2))  # WITH $TOOL = .., $BASE = ..
        args = re.split(r"\s+WITH\s+", mm.group(2), flags=re.I)[0]
        for tok in re.findall(r"\{[^}]*\}|\b\w+\b", args):
            if tok.startswith("{"):
                p = re.match(KRL_POS, tok)
                if not p:
                    continue  # a joint target {A1 ..}
                name, g = "", p
            elif tok.upper() in decl:
                name, g = tok, decl[tok.upper()]
            else:
                continue  # an approximation (C_DIS, ..), a joint target, a run-time target
            vals = [float(g.group(k)) for k in range(1, 7)]
            branch = {} if g.group(7) is None else {"kuka_s": int(g.group(7)), "kuka_t": int(g.group(8))}
            uses.append(Use(name, iso(vals), pb @ base, tool, branch, f"{src.name}:{i}"))
    return uses


# ------------------------------------------------------------------------------------------------ RAPID
def rapid_statements(text: str) -> list:
    """(first line, statement without comments) in the order of the file."""
    out, cur, start = [], "", 0
    for i, line in enumerate(text.replace("\r", "").split("\n"), 1):
        code = re.sub(r"!.*$", "", line) if '"' not in line else line
        if not cur.strip() and re.match(r"\s*(?:(?:PROC|ENDPROC|MODULE|ENDMODULE|FUNC|ENDFUNC|TRAP|ENDTRAP|IF|ELSEIF|ELSE|ENDIF|"
                                        r"FOR|ENDFOR|WHILE|ENDWHILE|TEST|CASE|DEFAULT|ENDTEST|VERSION|LANGUAGE)\b|%%%)", code):
            continue  # a line that is no statement ending in ';'
        if not cur.strip():
            start = i
        cur += " " + code.strip()
        if cur.rstrip().endswith(";"):
            out.append((start, cur.strip()))
            cur = ""
        elif not cur.strip():
            cur = ""
    return out


def rapid_robtarget(v: str):
    parts = re.findall(r"\[([^\[\]]*)\]", v)
    return nums(parts[0]), nums(parts[1]), [int(x) for x in nums(parts[2])], parts[3]


RAPID_ONE = {"MOVEL", "MOVEJ", "ARCLSTART", "ARCL", "ARCLEND", "TRIGGL", "TRIGGJ", "MOVELDO", "MOVEJDO", "SPOTL"}
RAPID_TWO = {"MOVEC", "ARCC", "ARCCSTART", "ARCCEND", "TRIGGC"}


def rapid_uses(path: Path, pb: np.ndarray, track: tuple | None) -> list:
    stm = rapid_statements(path.read_text())
    rob, tools, wobjs = {}, {}, {}
    for line, s in stm:
        m = re.match(r"(?:LOCAL\s+|TASK\s+)?(CONST|PERS|VAR)\s+(robtarget|tooldata|wobjdata)\s+(\w+)\s*(?::=\s*(.*))?;$", s, re.I)
        if not m or m.group(4) is None:
            continue
        kind, name, v = m.group(2).lower(), m.group(3), m.group(4)
        if kind == "robtarget" and m.group(1).upper() != "VAR":
            rob[name.upper()] = v
        elif kind == "tooldata":
            n = nums(v.split("]]")[0])
            assert v.strip("[ ").upper().startswith("TRUE"), "a stationary tool: not read here"
            tools[name.upper()] = iso_q(n[:3], n[3:7])
        elif kind == "wobjdata":
            inner = v.strip()[1:-1]
            frames = re.findall(r"\[\[([^\]]*)\],\[([^\]]*)\]\]", inner)
            (u1, u2), (o1, o2) = frames[0], frames[1]
            wobjs[name.upper()] = iso_q(nums(u1), nums(u2)) @ iso_q(nums(o1), nums(o2))
    uses = []
    for line, s in stm:
        m = re.match(r"(\w+)((?:\\\w+)*)\s*(.*);$", s)
        if not m or m.group(1).upper() not in RAPID_ONE | RAPID_TWO | {"SEARCHL"}:
            continue
        args = _split_top(m.group(3).lstrip(", "))
        args = [re.sub(r"\\ID:=\s*\w+", "", a).strip() for a in args]
        instr = m.group(1).upper()
        targets = args[:1] if instr in RAPID_ONE else args[:2] if instr in RAPID_TWO else args[2:3]
        wobj = re.search(r"\\WObj:=(\w+)", s)
        frame = wobjs[wobj.group(1).upper()] if wobj else np.eye(4)
        tname = next((a.split("\\")[0].strip() for a in args if a.split("\\")[0].strip().upper() in tools | {"TOOL0": 0}), "tool0")
        tool = tools.get(tname.upper(), np.eye(4))
        for t in targets:
            v = t if t.startswith("[[") else rob.get(t.upper())
            if v is None:
                continue  # Offs(..), a VAR, .. : computed at run time
            xyz, q, conf, ext = rapid_robtarget(v)
            base = pb
            e = nums(ext)[0]
            if track is not None and e < 8e9:
                base = pb @ np.block([[np.eye(3), -e * np.asarray(track)[:, None]], [np.zeros((1, 3)), np.ones((1, 1))]])
            uses.append(Use(t if not t.startswith("[[") else "", iso_q(xyz, q), base @ frame, tool, {"abb_conf": conf},
                            f"{path.name}:{line}", e if e < 8e9 else None))
    return uses


def _split_top(s: str) -> list:
    out, depth, cur = [], 0, ""
    for ch in s:
        depth += ch in "[(" and 1 or 0
        depth -= ch in "])" and 1 or 0
        if ch == "," and depth == 0:
            out.append(cur.strip())
            cur = ""
        else:
            cur += ch
    return out + [cur.strip()] if cur.strip() else out


# ------------------------------------------------------------------------------------------------ FANUC LS
LS_POS = re.compile(r"P\[(\d+)(?::\"[^\"]*\")?\]\{\s*GP1:\s*UF : (\d+), UT : (\d+),\s*CONFIG : '([^']*)',\s*X =\s*(" + NUM +
                    r")\s*mm,\s*Y =\s*(" + NUM + r")\s*mm,\s*Z =\s*(" + NUM + r")\s*mm,\s*W =\s*(" + NUM + r")\s*deg,\s*P =\s*(" +
                    NUM + r")\s*deg,\s*R =\s*(" + NUM + r")\s*deg(?:,\s*E1=\s*(" + NUM + r")\s*mm)?")


def ls_uses(path: Path, args: list) -> list:
    text = path.read_text()
    pos = {int(m.group(1)): m for m in LS_POS.finditer(text)}
    ufs, uts = opt_map(args, "--uframe"), opt_map(args, "--utool")
    track = opt_map(args, "--track")
    uses, mn = [], text.split("/MN")[1].split("/POS")[0].split("\n")
    first = text.split("\n").index("/MN") + 1
    for k, line in enumerate(mn):
        refs = re.findall(r"(?:^\s*\d+:\s*[JLC]\s+|^\s*:\s*)P\[(\d+)", line)
        if not refs or re.search(r"Offset|INC\b", line + (mn[k + 1] if k + 1 < len(mn) and mn[k + 1].lstrip().startswith(":") else "")):
            continue
        for r in refs:
            m = pos.get(int(r))
            if m is None:
                continue  # a joint position
            uf, ut = int(m.group(2)), int(m.group(3))
            base = iso(nums(ufs[uf])) if uf in ufs else opt_frame(args, "--program-base")
            tool = iso(nums(uts[ut])) if ut in uts else opt_frame(args, "--program-tool")
            if m.group(11) is not None and track:
                d = np.asarray(nums(track[1]))
                base = np.block([[np.eye(3), -float(m.group(11)) * d[:, None]], [np.zeros((1, 3)), np.ones((1, 1))]]) @ base
            x, y, z, w, p, rr = (float(m.group(j)) for j in range(5, 11))
            uses.append(Use(f"P[{r}]", iso([x, y, z, rr, p, w]), base, tool, {"fanuc_config": m.group(4)},
                            f"{path.name}:{first + k}", None if m.group(11) is None else float(m.group(11))))
    return uses


# ------------------------------------------------------------------------------------------------ URScript
def ur_uses(path: Path, args: list) -> list:
    text = path.read_text()
    var = {}
    for m in re.finditer(r"^\s*(?:global\s+)?(\w+)\s*=\s*(p\[[^\]]*\])\s*$", text, re.M):
        var.setdefault(m.group(1), []).append(m.group(2))
    pb, tool = opt_frame(args, "--program-base"), opt_frame(args, "--program-tool")
    uses = []
    for i, line in enumerate(text.split("\n"), 1):
        m = re.match(r"\s*(movej|movel|movep|movec)\((.*)\)\s*$", line)
        if not m:
            continue
        a = _split_top(m.group(2))
        for t in a[:2] if m.group(1) == "movec" else a[:1]:
            v = t if t.startswith("p[") else (var[t][0] if len(var.get(t, [])) == 1 else None)
            if v is None:
                continue
            x = nums(v)
            pose = np.eye(4)
            pose[:3, :3] = Rotation.from_rotvec(x[3:]).as_matrix()
            pose[:3, 3] = 1000 * np.asarray(x[:3])
            uses.append(Use(t, pose, pb, tool, {}, f"{path.name}:{i}"))
    return uses


# ------------------------------------------------------------------------------------------------ the checks
def uses_of(case: Case, program: Path) -> list:
    ext = program.suffix.lower()
    if ext == ".src":
        dat = program.with_suffix(".dat")
        frames = krl_frames(CONFIG.read_text()) if case.declarations else {}
        return krl_uses(program, dat.read_text() if dat.exists() else "", frames, opt_frame(case.args, "--program-base"))
    if ext in (".mod", ".modx", ".sys"):
        tr = case.args[case.args.index("--track") + 1].split("=")[1] if "--track" in case.args else None
        return rapid_uses(program, opt_frame(case.args, "--program-base"), tuple(nums(tr)) if tr else None)
    if ext == ".ls":
        return ls_uses(program, [a.replace("E1=", "1=") if a.startswith("E1=") else a for a in case.args])
    return ur_uses(program, case.args)


def masked(text: str, ext: str, copies: dict) -> list:
    """The lines with every target value's numbers (pose and branch data) replaced by N, copies renamed."""
    def num_n(m):  # the value's numbers and its blanks (not its line ends): a value may be printed otherwise
        return re.sub(r"[ \t]+", "", re.sub(NUM, "N", m.group(0)))
    text = text.replace("\r", "")
    if ext == ".src" or ext == ".dat":
        # the branch data are part of the target's value: S and T added to an inline target that had none
        # (so that the controller takes the compensated branch) change nothing else
        text = re.sub(r"(X\s+" + NUM + r"\s*,\s*Y\s+" + NUM + r"\s*,\s*Z\s+" + NUM + r"\s*,\s*A\s+" + NUM + r"\s*,\s*B\s+" +
                      NUM + r"\s*,\s*C\s+" + NUM + r")(?:\s*,\s*S\s+\d+\s*,\s*T\s+\d+)?",
                      lambda m: re.sub(r"[ \t]+", "", re.sub(NUM, "N", m.group(1))), text)
    elif ext == ".ls":
        text = re.sub(r"CONFIG : '[^']*'", "CONFIG : 'N'", text)
        text = re.sub(r"\b[XYZWPR] =\s*" + NUM, num_n, text)
    elif ext == ".script":
        text = re.sub(r"(?<!set_tcp\()p\[[^\]]*\]", num_n, text)
    else:
        text = re.sub(r"\[\[[^\]]*\],\s*\[[^\]]*\],\s*\[[^\]]*\],", num_n, text)
    for new, old in copies.items():
        text = re.sub(r"\b" + new + r"\b", old, text)
    return text.split("\n")


def line_diff_problems(a: str, b: str, ext: str) -> list:
    names_a = set(re.findall(r"\b\w+\b", a))
    copies = {n: re.sub(r"_\d+$", "", n) for n in set(re.findall(r"\b(\w+_\d+)\b", b)) - names_a
              if re.sub(r"_\d+$", "", n) in names_a}
    la, lb = masked(a, ext, copies), masked(b, ext, copies)
    problems = []
    for op, i1, i2, j1, j2 in difflib.SequenceMatcher(a=la, b=lb, autojunk=False).get_opcodes():
        if op == "equal":
            continue
        if op == "insert" and all(l in la and re.search(r"\b(robtarget|E6POS|POS)\b", l, re.I) for l in lb[j1:j2]) and copies:
            continue  # a copy's declaration (its name renamed back above): the original's line with other values
        problems.append(f"{op} lines {i1 + 1}..{i2} -> {j1 + 1}..{j2}: {la[i1:i2][:2]} -> {lb[j1:j2][:2]}")
    return problems


def reached_problems(calibrated, uses_in, uses_out, fmt, stderr) -> list:
    problems = []
    if len(uses_in) != len(uses_out):
        return [f"{len(uses_in)} targets in, {len(uses_out)} out"]
    ref = None
    tol_mm = 5e-3 if fmt == "fanuc-ls" else 1e-3
    for ui, uo in zip(uses_in, uses_out):
        desired = ui.base @ ui.pose @ np.linalg.inv(ui.tool)
        written = uo.base @ uo.pose @ np.linalg.inv(uo.tool)
        if fmt == "urscript":
            sols = [np.asarray(s["q_deg"]) for s in _core.ik_all(calibrated, xyzabc(written)) if s["within_limits"]]
            if not sols:
                problems.append(f"{uo.where}: no IK solution")
                continue
            # a UR takes the solution nearest its joints: the first target any solution, then the nearest
            q = min(sols, key=lambda s: 0 if ref is None else np.abs(s - ref).max())
            if ref is None:
                q = min(sols, key=lambda s: np.linalg.norm(kincal.fk(calibrated, s)[0][:3] - desired[:3, 3]))
        else:
            q = _core.select_branch(calibrated, fmt, {"pose": xyzabc(written), **uo.branch})
            if isinstance(q, str):
                problems.append(f"{uo.where}: {q}")
                continue
        ref = q
        got = kincal.fk(calibrated, np.asarray(q))[0]
        dr = Rotation.from_euler("ZYX", got[3:], degrees=True).inv() * Rotation.from_matrix(desired[:3, :3])
        err_mm, err_deg = np.linalg.norm(got[:3] - desired[:3, 3]), math.degrees(dr.magnitude())
        if err_mm > tol_mm or err_deg > 1e-3:
            problems.append(f"{uo.where} {ui.name}: the robot reaches {err_mm:.4f} mm, {err_deg:.5f} deg from the program's pose")
        # (c) the taught branch
        if ui.branch and fmt != "urscript":
            named = ui.name and ui.name in stderr or ui.where in stderr
            if fmt == "krl" and "kuka_s" in ui.branch:
                if ui.branch["kuka_s"] != uo.branch.get("kuka_s"):
                    problems.append(f"{uo.where} {ui.name}: S {ui.branch['kuka_s']} taught, {uo.branch.get('kuka_s')} written")
                elif ui.branch["kuka_t"] != uo.branch["kuka_t"] and not named:
                    problems.append(f"{uo.where} {ui.name}: T {ui.branch['kuka_t']} taught, {uo.branch['kuka_t']} written, no warning")
            if fmt == "rapid":
                if ui.branch["abb_conf"][3] != uo.branch["abb_conf"][3]:
                    problems.append(f"{uo.where} {ui.name}: cfx {ui.branch['abb_conf']} taught, {uo.branch['abb_conf']} written")
                elif ui.branch["abb_conf"] != uo.branch["abb_conf"] and not named:
                    problems.append(f"{uo.where} {ui.name}: {ui.branch['abb_conf']} taught, {uo.branch['abb_conf']} written, no warning")
            if fmt == "fanuc-ls":
                a, b = ui.branch["fanuc_config"].split(","), uo.branch["fanuc_config"].split(",")
                if a[0].split() != b[0].split():
                    problems.append(f"{uo.where} {ui.name}: '{ui.branch['fanuc_config']}' taught, '{uo.branch['fanuc_config']}' written")
                elif [int(x) for x in a[1:]] != [int(x) for x in b[1:]] and not named:
                    problems.append(f"{uo.where} {ui.name}: turns of '{ui.branch['fanuc_config']}' changed, no warning")
    return problems


FMT = {".src": "krl", ".mod": "rapid", ".modx": "rapid", ".sys": "rapid", ".ls": "fanuc-ls", ".script": "urscript"}
_RESULTS: dict = {}


def outcome(case: Case, calibrated, tmp_path_factory) -> tuple:
    """(what happened: "filtered", "filtered wrongly", "refused", "failed"; details)."""
    if case.path in _RESULTS:
        return _RESULTS[case.path]
    tmp = tmp_path_factory.mktemp("corpus")
    model = tmp / "m.json"
    model.write_text(calibrated.to_json())
    program = CORPUS / case.path
    out_dir = tmp / "out"
    out_dir.mkdir()
    out = out_dir / program.name
    extra = ["--declarations", str(CONFIG)] if case.declarations else []
    r = run("kincal", "compensate", "--model", str(model), "--program", str(program), "--out", str(out), "--targets",
            "filtered", *extra, *case.args)
    if r.returncode != 0:
        written = sorted(p.name for p in out_dir.iterdir())
        res = ("refused" if r.returncode == 1 and not written else "failed", r.stderr.strip()[-600:] + (f" (written: {written})" if written else ""))
    else:
        problems = []
        files = [(program, out)] + ([(program.with_suffix(".dat"), out.with_suffix(".dat"))] if program.suffix == ".src" and program.with_suffix(".dat").exists() else [])
        for a, b in files:
            if not b.exists():
                problems.append(f"{b.name} not written")
                continue
            problems += [f"{a.name}: {p}" for p in line_diff_problems(a.read_text(), b.read_text(), a.suffix.lower())]
        if not problems:
            try:
                uses_in, uses_out = uses_of(case, program), uses_of(case, out)
            except (AssertionError, KeyError) as e:
                uses_in, uses_out = [], []
                problems.append(f"the reader here cannot place the targets: {e!r}")
            if not uses_in:
                problems.append("the reader here found no Cartesian target")
            ext = {u.external for u in uses_in if u.external is not None}
            if len(ext) > 1 and "--track" not in case.args:
                problems.append(f"an external axis varies ({sorted(ext)}) and no --track: the targets were placed as if it stood still")
            problems += reached_problems(calibrated, uses_in, uses_out, FMT[program.suffix.lower()], r.stderr)
        res = ("filtered wrongly", "; ".join(problems[:6])) if problems else ("filtered", r.stderr.strip()[-300:])
    _RESULTS[case.path] = res
    return res


@pytest.mark.parametrize("case", TABLE, ids=[c.path.split("/")[-1] for c in TABLE])
def test_corpus_program(case, calibrated, tmp_path_factory):
    what, details = outcome(case, calibrated, tmp_path_factory)
    if case.expect == "filtered":
        assert what == "filtered", f"{case.path}: {what}: {details}  [needs: {case.needs}]"
    else:
        cause = case.expect.split(": ", 1)[1]
        assert what == "refused" and cause in details, f"{case.path}: {what}: {details}  [expected refused: {cause}; needs: {case.needs}]"


def test_corpus_summary(calibrated, tmp_path_factory):
    results = {c.path: outcome(c, calibrated, tmp_path_factory) for c in TABLE}
    langs = {Path(c.path).suffix.lower() for c in TABLE}
    assert len(TABLE) >= 20 and {".src", ".ls", ".script"} <= langs and langs & {".mod", ".sys"}
    filtered = [p for p, (w, _) in results.items() if w == "filtered"]
    wrong = [f"{p}: {d}" for p, (w, d) in results.items() if w == "filtered wrongly"]
    assert not wrong, "filtered wrongly:\n" + "\n".join(wrong)
    assert len(filtered) >= 0.8 * len(TABLE), f"{len(filtered)} of {len(TABLE)} filtered and verified: " + \
        ", ".join(f"{Path(p).name}: {w}" for p, (w, _) in results.items() if w != "filtered")
