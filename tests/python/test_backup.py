"""A controller backup as the input of `kincal compensate` and `kincal-compensate` (issue 30, item 1): a folder
of programs in every language kincal reads (tests/data/programs: tape.src + tape.dat, tape.mod, tape.ls,
tape.script, placed in sub-folders as a backup has them) and files it does not read, filtered on the
calibrated kr500 (conftest: 1 mm / 0.05 deg errors and compliance, seed 9). The same tree is written under
--out: each program filtered exactly as it is filtered alone, every other file copied byte for byte. A
program that fails (a malformed one) leaves no output of its own; the others are written, the failure is
listed with file:line and the exit status is 1."""

from __future__ import annotations

import re
import shutil
from pathlib import Path

import numpy as np
import pytest

from conftest import run

DATA = Path(__file__).resolve().parents[1] / "data" / "programs"


@pytest.fixture()
def model(tmp_path, calibrated):
    path = tmp_path / "m.json"
    path.write_text(calibrated.to_json())
    return path


def _backup(root: Path) -> Path:
    """A backup tree: KRL under KRC/R1/Program, RAPID under RAPID/TASK1/PROGMOD, LS and URScript beside, and
    files kincal does not read (a README, a binary, a CSV of I/O names)."""
    (root / "KRC" / "R1" / "Program").mkdir(parents=True)
    (root / "RAPID" / "TASK1" / "PROGMOD").mkdir(parents=True)
    (root / "fanuc").mkdir()
    (root / "ur").mkdir()
    for f in ("tape.src", "tape.dat"):
        shutil.copy(DATA / f, root / "KRC" / "R1" / "Program" / f)
    shutil.copy(DATA / "tape.mod", root / "RAPID" / "TASK1" / "PROGMOD" / "tape.mod")
    shutil.copy(DATA / "tape.ls", root / "fanuc" / "tape.ls")
    shutil.copy(DATA / "tape.script", root / "ur" / "tape.script")
    (root / "README.txt").write_text("cell 4, backup of 2026-11-20\n")
    (root / "KRC" / "R1" / "Program" / "logo.bin").write_bytes(bytes(range(256)) * 3)
    (root / "RAPID" / "io_names.csv").write_text("name,signal\nclamp,do1\n")
    return root


@pytest.mark.parametrize("tool", ["kincal", "kincal-compensate"])
def test_backup_folder_is_filtered_into_the_same_tree(tmp_path, model, tool):
    backup = _backup(tmp_path / "backup")
    out = tmp_path / "out"
    args = ["compensate"] if tool == "kincal" else []
    r = run(tool, *args, "--model", str(model), "--program", str(backup), "--out", str(out), "--targets", "filtered",
            "--skip-unresolved")
    assert r.returncode == 0, r.stderr
    assert "4 program(s) filtered, 3 file(s) copied unchanged, 0 program(s) failed" in r.stderr
    inputs = sorted(p.relative_to(backup) for p in backup.rglob("*") if p.is_file())
    assert sorted(p.relative_to(out) for p in out.rglob("*") if p.is_file()) == inputs
    for rel in ("README.txt", "KRC/R1/Program/logo.bin", "RAPID/io_names.csv"):
        assert (out / rel).read_bytes() == (backup / rel).read_bytes()
    # each program exactly as filtered alone
    alone = tmp_path / "alone"
    alone.mkdir()
    for rel in ("KRC/R1/Program/tape.src", "RAPID/TASK1/PROGMOD/tape.mod", "fanuc/tape.ls", "ur/tape.script"):
        r1 = run(tool, *args, "--model", str(model), "--program", str(backup / rel), "--out",
                 str(alone / Path(rel).name), "--targets", "filtered", "--skip-unresolved")
        assert r1.returncode == 0, r1.stderr
        assert (out / rel).read_text() == (alone / Path(rel).name).read_text(), rel
        assert (out / rel).read_text() != (backup / rel).read_text(), rel
    assert (out / "KRC/R1/Program/tape.dat").read_text() == (alone / "tape.dat").read_text()


@pytest.mark.parametrize("tool", ["kincal", "kincal-compensate"])
def test_a_failing_program_leaves_no_output_and_the_others_are_written(tmp_path, model, tool):
    backup = _backup(tmp_path / "backup")
    bad = backup / "RAPID" / "TASK1" / "PROGMOD" / "tape.mod"
    bad.write_text(bad.read_text().replace("ENDMODULE", "! (ENDMODULE lost)"))
    (backup / "fanuc" / "tape.ls").rename(backup / "fanuc" / "TAPE2.LS")  # upper-case extensions are read too
    out = tmp_path / "out"
    args = ["compensate"] if tool == "kincal" else []
    r = run(tool, *args, "--model", str(model), "--program", str(backup), "--out", str(out), "--targets", "filtered",
            "--skip-unresolved")
    assert r.returncode == 1
    assert "3 program(s) filtered" in r.stderr and "1 program(s) failed" in r.stderr
    assert f"{bad}:" in r.stderr and "MODULE is not closed by ENDMODULE" in r.stderr
    assert not (out / "RAPID" / "TASK1" / "PROGMOD" / "tape.mod").exists()
    for rel in ("KRC/R1/Program/tape.src", "KRC/R1/Program/tape.dat", "fanuc/TAPE2.LS", "ur/tape.script",
                "README.txt"):
        assert (out / rel).exists(), rel
    assert not list(out.rglob("*.tmp*"))


def test_several_files_and_out_inside_the_input_refused(tmp_path, model):
    backup = _backup(tmp_path / "backup")
    out = tmp_path / "out"
    r = run("kincal", "compensate", "--model", str(model), "--program", str(backup / "fanuc" / "tape.ls"),
            str(backup / "ur" / "tape.script"), "--out", str(out), "--targets", "filtered", "--skip-unresolved")
    assert r.returncode == 0, r.stderr
    assert sorted(p.name for p in out.iterdir()) == ["tape.ls", "tape.script"]
    r = run("kincal", "compensate", "--model", str(model), "--program", str(backup), "--out", str(backup / "filtered"),
            "--targets", "filtered")
    assert r.returncode == 1
    assert "inside the input folder" in r.stderr
    assert not (backup / "filtered").exists()


KRC = DATA / "krl" / "KRC"


@pytest.mark.parametrize("tool", ["kincal", "kincal-compensate"])
def test_kuka_backup_each_target_in_its_own_tool_and_base(tmp_path, model, calibrated, tool):
    """A KUKA backup (tests/data/programs/krl/KRC, re-created: $config.dat with XHOME, TOOL_DATA[1..2],
    BASE_DATA[1..2] and two Cartesian targets; pick (KSS 5 inline forms, FDAT_ACT + BAS), weld (KSS 8
    SPTP/SLIN WITH $TOOL = STOOL2(..), $BASE = SBASE(..)) and service ($TOOL / $BASE / BAS(#TOOL, n))) filtered
    in one command. The independent reader of test_program_corpus follows each motion's tool and base from
    the programs' text; every written target, selected by the controller's nominal model through those
    frames, puts the calibrated robot's TCP on the program's pose (1e-3 mm, 1e-3 deg), with the taught S."""
    from test_program_corpus import krl_frames, krl_uses, line_diff_problems, reached_problems

    out = tmp_path / "out"
    args = ["compensate"] if tool == "kincal" else []
    r = run(tool, *args, "--model", str(model), "--program", str(KRC), "--out", str(out), "--targets", "filtered")
    assert r.returncode == 0, r.stderr
    assert "0 program(s) failed" in r.stderr
    config_in = (KRC / "R1" / "System" / "$config.dat").read_text()
    config_out = (out / "R1" / "System" / "$config.dat").read_text()
    frames = krl_frames(config_in)
    assert krl_frames(config_out).keys() == frames.keys()  # the frames themselves are not changed
    def visible(root: Path, src: Path) -> str:
        """What a program sees, the last declaration of a name winning in the reader: the other data lists'
        DECL GLOBAL lines, $config.dat, then its own .dat."""
        others = [l for d in sorted(root.rglob("*.dat")) if d.stem not in (src.stem, "$config")
                  for l in d.read_text().split("\n") if re.match(r"\s*DECL\s+GLOBAL\b", l, re.I)]
        return "\n".join(others + [(root / "R1" / "System" / "$config.dat").read_text(), src.with_suffix(".dat").read_text()])

    tools, bases, n = set(), set(), 0
    for src in sorted((KRC / "R1" / "Program").glob("*.src")):
        rel = src.relative_to(KRC)
        uses_in = krl_uses(src, visible(KRC, src), frames, np.eye(4))
        uses_out = krl_uses(out / rel, visible(out, out / rel), frames, np.eye(4))
        assert uses_in and not reached_problems(calibrated, uses_in, uses_out, "krl", r.stderr), src.name
        for a, b in ((src, out / rel), (src.with_suffix(".dat"), (out / rel).with_suffix(".dat"))):
            assert not line_diff_problems(a.read_text(), b.read_text(), a.suffix), a.name
        tools |= {u.tool.tobytes() for u in uses_in}
        bases |= {u.base.tobytes() for u in uses_in}
        n += len(uses_in)
    assert len(tools) >= 2 and len(bases) >= 2 and n >= 15
    assert not line_diff_problems(config_in, config_out, ".dat")
    assert "DECL E6AXIS XHOME={A1 0.0,A2 -90.0,A3 90.0,A4 0.0,A5 30.0,A6 0.0," in config_out  # kept as written


@pytest.mark.parametrize("tool", ["kincal", "kincal-compensate"])
def test_rapid_task_targets_declared_in_a_data_module(tmp_path, model, tool):
    """A RAPID task whose data module (tooldata, wobjdata, robtargets; no motion) serves a program module: the
    targets are compensated where they are declared, in the data module, exactly as when the two are one
    module (tape.mod split in two), and the data module is not copied back over its filtered self."""
    lines = (DATA / "tape.mod").read_text().split("\n")
    decl = [l for l in lines if re.match(r"\s*(PERS|CONST|TASK PERS|VAR)\b", l)]
    body = [l for l in lines[1:] if l not in decl]
    task = tmp_path / "TASK1"
    (task / "PROGMOD").mkdir(parents=True)
    (task / "SYSMOD").mkdir()
    (task / "SYSMOD" / "Data.sys").write_text("\n".join(["MODULE Data(SYSMODULE)", *decl, "ENDMODULE", ""]))
    (task / "PROGMOD" / "Main.mod").write_text("\n".join(["MODULE Main", *body]))
    out = tmp_path / "out"
    args = ["compensate"] if tool == "kincal" else []
    r = run(tool, *args, "--model", str(model), "--program", str(task), "--out", str(out), "--targets", "filtered")
    assert r.returncode == 0, r.stderr
    alone = tmp_path / "alone.mod"
    assert run(tool, *args, "--model", str(model), "--program", str(DATA / "tape.mod"), "--out", str(alone),
               "--targets", "filtered").returncode == 0
    filtered = alone.read_text().split("\n")
    data_out = (out / "SYSMOD" / "Data.sys").read_text().split("\n")
    assert data_out[1:-2] == [filtered[lines.index(l)] for l in decl]
    assert data_out != (task / "SYSMOD" / "Data.sys").read_text().split("\n")
    assert (out / "PROGMOD" / "Main.mod").read_text().split("\n")[1:] == [filtered[lines.index(l)] if l else "" for l in body]


def _cell(dst: Path, tool1_x: float | None = None) -> Path:
    """A copy of the re-created KUKA backup; tool1_x moves TOOL_DATA[1] (another cell's tool)."""
    shutil.copytree(KRC, dst)
    if tool1_x is not None:
        cfg = dst / "R1" / "System" / "$config.dat"
        text = cfg.read_text()
        assert "TOOL_DATA[1]={X 240.0," in text
        cfg.write_text(text.replace("TOOL_DATA[1]={X 240.0,", f"TOOL_DATA[1]={{X {tool1_x},"))
    return dst


def test_each_controller_of_a_folder_has_its_own_declarations(tmp_path, model):
    """Two cells' backups in one folder (cellB's TOOL_DATA[1] 10 mm longer): each program takes its own
    controller's tools and targets: every output equals its cell filtered alone."""
    _cell(tmp_path / "cells" / "cellA")
    _cell(tmp_path / "cells" / "cellB", tool1_x=250.0)
    r = run("kincal-compensate", "--model", str(model), "--program", str(tmp_path / "cells"), "--out",
            str(tmp_path / "out"), "--targets", "filtered")
    assert r.returncode == 0, r.stderr
    for cell in ("cellA", "cellB"):
        r1 = run("kincal-compensate", "--model", str(model), "--program", str(tmp_path / "cells" / cell), "--out",
                 str(tmp_path / "alone" / cell), "--targets", "filtered")
        assert r1.returncode == 0, r1.stderr
        for f in (tmp_path / "alone" / cell).rglob("*"):
            if f.is_file():
                assert f.read_bytes() == (tmp_path / "out" / cell / f.relative_to(tmp_path / "alone" / cell)).read_bytes(), f
    a = (tmp_path / "out" / "cellA" / "R1" / "Program" / "pick.dat").read_text()
    b = (tmp_path / "out" / "cellB" / "R1" / "Program" / "pick.dat").read_text()
    assert a != b  # tool 1's targets compensated for each cell's tool


def test_a_failing_group_keeps_the_files_it_shares(tmp_path, model):
    """service.src names a target declared nowhere: service and weld (which share weld.dat's XSEAM_START) are
    not written, and say so; pick is; $config.dat, which they read, is copied unchanged so the backup can be
    restored; an earlier run's output of the failed programs is removed."""
    cell = _cell(tmp_path / "KRC")
    out = tmp_path / "out"
    args = ["--model", str(model), "--program", str(cell), "--out", str(out), "--targets", "filtered"]
    assert run("kincal-compensate", *args).returncode == 0  # an earlier, good run
    src = cell / "R1" / "Program" / "service.src"
    src.write_text(src.read_text().replace("PTP XPARK", "PTP XPARK\nLIN XNOWHERE"))
    r = run("kincal-compensate", *args)
    assert r.returncode == 1
    assert "not written" in r.stderr and "service.src" in r.stderr and "weld.src" in r.stderr
    assert "declared nowhere: LIN XNOWHERE" in r.stderr
    program = out / "R1" / "Program"
    assert (program / "pick.src").exists() and (program / "pick.dat").exists()
    for name in ("service.src", "service.dat", "weld.src", "weld.dat"):
        assert not (program / name).exists(), name
    cfg = "R1/System/$config.dat"
    assert (out / cfg).read_bytes() == (cell / cfg).read_bytes()


def test_a_lone_program_writes_the_data_list_its_target_is_declared_in(tmp_path, model):
    """One program (upper-case file names, as some controllers write them) moving to XPARK of $config.dat,
    with no other program: $config.dat comes out with XPARK compensated; two .src files given as files take
    --declarations."""
    cell = tmp_path / "KRC"
    (cell / "R1" / "Program").mkdir(parents=True)
    (cell / "R1" / "System").mkdir()
    shutil.copy(KRC / "R1" / "System" / "$config.dat", cell / "R1" / "System" / "$config.dat")
    (cell / "R1" / "Program" / "PARK.SRC").write_text("DEF park( )\nPTP XHOME\nPTP XPARK\nLIN XP1\nEND\n")
    (cell / "R1" / "Program" / "PARK.DAT").write_text(
        "DEFDAT park\nDECL E6POS XP1={X 1800.0,Y 100.0,Z 1400.0,A 155.0,B 5.0,C 168.0}\nENDDAT\n")
    out = tmp_path / "out"
    r = run("kincal-compensate", "--model", str(model), "--program", str(cell), "--out", str(out), "--targets", "filtered")
    assert r.returncode == 0, r.stderr
    cfg_in = (cell / "R1" / "System" / "$config.dat").read_text()
    cfg_out = (out / "R1" / "System" / "$config.dat").read_text()
    changed = [l.split("=")[0] for l, m in zip(cfg_in.split("\n"), cfg_out.split("\n")) if l != m]
    assert changed == ["DECL E6POS XPARK"]
    assert (out / "R1" / "Program" / "PARK.DAT").read_text() != (cell / "R1" / "Program" / "PARK.DAT").read_text()
    # two programs given as files (each with its .dat), XHOME declared elsewhere (--declarations)
    programs = tmp_path / "progs"
    programs.mkdir()
    for n in (2, 3):
        (programs / f"park{n}.src").write_text(f"DEF park{n}( )\nPTP XHOME\nLIN XP1\nPTP XHOME\nEND\n")
        shutil.copy(cell / "R1" / "Program" / "PARK.DAT", programs / f"park{n}.dat")
    r = run("kincal-compensate", "--model", str(model), "--program", str(programs / "park2.src"),
            str(programs / "park3.src"), "--declarations", str(cell / "R1" / "System" / "$config.dat"), "--out",
            str(tmp_path / "o2"), "--targets", "filtered")
    assert r.returncode == 0, r.stderr
    assert sorted(p.name for p in (tmp_path / "o2").iterdir()) == ["park2.dat", "park2.src", "park3.dat", "park3.src"]
