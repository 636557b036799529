"""Programs in the controllers' languages (issue 19, writers): KUKA KRL (.src + .dat), ABB RAPID (.mod),
FANUC LS (.ls), URScript (.script), by extension and by --format, from `kincal compensate` and
`kincal-compensate` (the same C++ writer: identical files). Each program is read back here by an
independent reader (a few regular expressions in this file, not the project's parser) and its joints
compared with the compensated joints (kincal.compensate in memory) within the printed precision: KRL
and RAPID 6 decimals of a degree, LS 4, URScript 10 decimals of a radian. Limits: names, splitting
into parts, bad options (a clear error, exit 1, no file)."""

from __future__ import annotations

import io
import math
import re
from pathlib import Path

import numpy as np
import pytest

import kincal

from conftest import run

NUM = r"(-?\d+(?:\.\d+)?)"


def read_krl(src: Path) -> np.ndarray:
    """Joints of a KRL module: the PTP lines of the .src in order, each an E6AXIS of the .dat; a
    call of another module (NAME_1( )) reads that module."""
    dat = src.with_suffix(".dat").read_text()
    decl = {m.group(1): [float(m.group(k)) for k in range(2, 8)] for m in re.finditer(
        r"DECL E6AXIS (\w+)=\{A1 " + NUM + ",A2 " + NUM + ",A3 " + NUM + ",A4 " + NUM + ",A5 " + NUM + ",A6 " + NUM
        + r",E1 ", dat)}
    out = []
    for line in src.read_text().splitlines():
        if m := re.fullmatch(r"PTP (\w+)( C_DIS)?", line):
            out.append(decl[m.group(1)])
        elif m := re.fullmatch(r"(\w+)\( \)", line):
            out.extend(read_krl(src.with_name(m.group(1) + ".src")))
    return np.array(out)


def read_rapid(mod: Path) -> np.ndarray:
    text = mod.read_text()
    decl = {m.group(1): [float(x) for x in m.group(2).split(",")] for m in re.finditer(
        r"CONST jointtarget (\w+):=\[\[([^\]]*)\],\[9E9,9E9,9E9,9E9,9E9,9E9\]\];", text)}
    return np.array([decl[m.group(1)] for m in re.finditer(r"MoveAbsJ (\w+)\\NoEOffs,", text)])


def read_ls(ls: Path) -> np.ndarray:
    text = ls.read_text()
    calls = re.findall(r"^\s*\d+:\s+CALL (\w+)\s*;", text, re.M)
    if calls:
        return np.vstack([read_ls(ls.with_name(c + ".ls")) for c in calls])
    pos = {int(m.group(1)): [float(x) for x in re.findall(r"J\d=\s*" + NUM + " deg", m.group(2))]
           for m in re.finditer(r"P\[(\d+)\]\{(.*?)\};", text, re.S)}
    return np.array([pos[int(n)] for n in re.findall(r"^\s*\d+:\s+J P\[(\d+)\]", text, re.M)])


def read_urscript(script: Path) -> np.ndarray:
    rows = re.findall(r"movej\(\[([^\]]*)\]", script.read_text())
    return np.degrees(np.array([[float(x) for x in r.split(",")] for r in rows]))


READERS = {".src": (read_krl, 5e-7), ".mod": (read_rapid, 5e-7), ".ls": (read_ls, 5e-5),
           ".script": (read_urscript, np.degrees(5e-11))}


@pytest.fixture(scope="module")
def line(tmp_path_factory, calibrated):
    d = tmp_path_factory.mktemp("line")
    (d / "model.json").write_text(calibrated.to_json())
    poses = kincal.line_program(count=40)
    (d / "line.csv").write_text("x,y,z,a,b,c\n" + "".join(",".join(f"{v:.10f}" for v in p) + "\n" for p in poses))
    q = kincal.compensate(calibrated, poses)["q_deg"]
    return d, q


@pytest.mark.parametrize("ext", [".src", ".mod", ".ls", ".script"])
def test_written_joints_read_back(line, ext):
    d, q = line
    (d / "py").mkdir(exist_ok=True)
    (d / "cpp").mkdir(exist_ok=True)
    py, cpp = d / "py" / f"prog{ext}", d / "cpp" / f"prog{ext}"
    r1 = run("kincal", "compensate", "--model", str(d / "model.json"), "--program", str(d / "line.csv"), "--out", str(py))
    r2 = run("kincal-compensate", "--model", str(d / "model.json"), "--program", str(d / "line.csv"), "--out", str(cpp))
    assert r1.returncode == 0 and r2.returncode == 0, r1.stderr + r2.stderr
    # one writer: the same text from both programs
    assert py.read_text() == cpp.read_text()
    reader, tol = READERS[ext]
    got = reader(py)
    assert got.shape == q.shape
    err = np.abs(got - q).max()
    assert err <= tol * 1.0001, err  # rounding to the printed decimals, no more


@pytest.mark.parametrize("fmt,ext", [("krl", ".src"), ("rapid", ".mod"), ("fanuc-ls", ".ls"), ("urscript", ".script")])
def test_format_option_overrides_the_extension(line, fmt, ext):
    d, q = line
    out = d / f"by_option_{fmt.replace('-', '_')}.txt"
    if fmt == "krl":  # KRL writes NAME.src and NAME.dat whatever the extension given
        out = d / "by_option_krl.src"
    r = run("kincal", "compensate", "--model", str(d / "model.json"), "--program", str(d / "line.csv"), "--out", str(out),
            "--format", fmt)
    assert r.returncode == 0, r.stderr
    reader, tol = READERS[ext]
    assert np.abs(reader(out) - q).max() <= tol * 1.0001


def test_speed_zone_and_name(line):
    d, _ = line
    out = d / "sz.ls"
    r = run("kincal", "compensate", "--model", str(d / "model.json"), "--program", str(d / "line.csv"), "--out", str(out),
            "--speed", "35", "--zone", "50", "--name", "weld_1")
    assert r.returncode == 0, r.stderr
    text = out.read_text()
    assert text.startswith("/PROG  WELD_1\n")
    motions = re.findall(r"^\s*\d+:\s+J P\[\d+\] (\d+)% (\w+)\s*;", text, re.M)
    assert len(motions) == 40 and all(m[0] == "35" for m in motions)
    assert all(m[1] == "CNT50" for m in motions[:-1]) and motions[-1][1] == "FINE"
    out = d / "sz.mod"
    assert run("kincal", "compensate", "--model", str(d / "model.json"), "--program", str(d / "line.csv"), "--out",
               str(out), "--zone", "10").returncode == 0
    text = out.read_text()
    assert "CONST zonedata kc_zone:=[FALSE,10.000,15.000,15.000,1.5000,15.000,1.5000];" in text
    assert len(re.findall(r",kc_zone,tool0;", text)) == 39 and text.count(",fine,tool0;") == 1


def test_long_programs_are_split_into_parts(line):
    d, q = line
    for ext in (".src", ".ls"):
        out = d / f"split{ext}"
        r = run("kincal-compensate", "--model", str(d / "model.json"), "--program", str(d / "line.csv"), "--out",
                str(out), "--max-targets-per-file", "15")
        assert r.returncode == 0, r.stderr
        parts = sorted(p.name for p in d.glob(f"*_[0-9]{ext}"))
        stem = "split" if ext == ".src" else "SPLIT"  # FANUC program names are uppercase
        assert parts == [f"{stem}_{k}{ext}" for k in (1, 2, 3)], parts
        reader, tol = READERS[ext]
        assert np.abs(reader(out) - q).max() <= tol * 1.0001


@pytest.mark.parametrize("out,name", [("r.mod", "r" * 32), ("f.ls", "F" * 36), ("u.script", "u" * 64)])
def test_names_at_the_limit_are_taken(line, out, name):
    d, _ = line
    path = d / "limit" / out
    path.parent.mkdir(exist_ok=True)
    r = run("kincal-compensate", "--model", str(d / "model.json"), "--program", str(d / "line.csv"), "--out", str(path),
            "--name", name)
    assert r.returncode == 0, r.stderr
    assert name in path.read_text()


@pytest.mark.parametrize("tool", ["kincal", "kincal-compensate"])
@pytest.mark.parametrize("out,extra,cause", [
    ("a_name_far_too_long_for_krl.src", [], "longer than the 24 characters"),
    ("9lives.mod", [], "must start with a letter"),
    ("prog.src", ["--name", "other"], "a KRL module is named by its files"),
    ("zone.ls", ["--zone", "150"], "CNT value 0..100"),
    ("speed.script", ["--speed", "120"], "percentage in (0, 100]"),
    ("r.mod", ["--name", "r" * 33], "longer than the 32 characters"),
    ("f.ls", ["--name", "F" * 37], "longer than the 36 characters"),
    ("u.script", ["--name", "u" * 65], "longer than the 64 characters"),
    ("u.script", ["--name", "tape-1"], "only letters, digits and '_'"),
    ("r.mod", ["--name", "tape 1"], "only letters, digits and '_'"),
])
def test_bad_names_and_options(line, tool, out, extra, cause):
    d, _ = line
    args = ["compensate"] if tool == "kincal" else []
    path = d / "bad" / out
    path.parent.mkdir(exist_ok=True)
    r = run(tool, *args, "--model", str(d / "model.json"), "--program", str(d / "line.csv"), "--out", str(path), *extra)
    assert r.returncode == 1 and cause in r.stderr, r.stderr
    assert not any(path.parent.iterdir())  # no file, not even half of a KRL pair


def test_krl_and_urscript_speed_zone_and_defaults(line):
    # KRL: BAS(#VEL_PTP, %), $APO.CDIS and C_DIS on every motion but the last; URScript: v in rad/s
    # (percent of 180 deg/s), r the blend radius in m, 0 on the last motion. Defaults: 20 %, exact stop
    d, _ = line
    base = ["kincal-compensate", "--model", str(d / "model.json"), "--program", str(d / "line.csv")]
    assert run(*base, "--out", str(d / "sz.src"), "--speed", "35", "--zone", "5").returncode == 0
    src = (d / "sz.src").read_text()
    assert "BAS(#VEL_PTP,35.0)" in src and "$APO.CDIS=5.000" in src
    ptp = re.findall(r"^PTP XP\d+( C_DIS)?$", src, re.M)
    assert len(ptp) == 40 and all(ptp[:-1]) and not ptp[-1]
    assert run(*base, "--out", str(d / "dflt.src")).returncode == 0
    src = (d / "dflt.src").read_text()
    assert "BAS(#VEL_PTP,20.0)" in src and "C_DIS" not in src and "$APO.CDIS" not in src
    assert run(*base, "--out", str(d / "sz.script"), "--speed", "50", "--zone", "5").returncode == 0
    moves = re.findall(r"movej\(\[[^\]]*\], a=1\.4, v=([\d.]+), r=([\d.]+)\)", (d / "sz.script").read_text())
    assert len(moves) == 40 and all(float(v) == pytest.approx(0.5 * math.pi, abs=1e-4) for v, _ in moves)
    assert all(r == "0.0050" for _, r in moves[:-1]) and moves[-1][1] == "0.0000"
    assert run(*base, "--out", str(d / "dflt.script")).returncode == 0
    moves = re.findall(r"v=([\d.]+), r=([\d.]+)\)", (d / "dflt.script").read_text())
    assert all(float(v) == pytest.approx(0.2 * math.pi, abs=1e-4) and r == "0.0000" for v, r in moves)


@pytest.mark.parametrize("fmt", ["csv", "gcode"])
def test_format_csv_and_gcode_by_option(line, fmt):
    d, q = line
    out = d / f"by_option.{fmt}.txt"
    r = run("kincal", "compensate", "--model", str(d / "model.json"), "--program", str(d / "line.csv"), "--out", str(out),
            "--format", fmt)
    assert r.returncode == 0, r.stderr
    text = out.read_text()
    if fmt == "csv":
        got = np.loadtxt(io.StringIO(text), delimiter=",", skiprows=1)[:, :6]
    else:
        got = np.array([[float(v) for v in re.findall(r"A\d=(-?\d+\.\d+)", l)] for l in text.splitlines() if "A1=" in l])
    assert got.shape == q.shape and np.abs(got - q).max() < 1e-6


def test_default_split_at_2000_targets(tmp_path, calibrated):
    # 2,001 targets: KRL and LS programs become two parts a main program calls (the controllers' limit)
    rng = np.random.default_rng(4)
    poses = kincal.line_program(count=2001, step_mm=0.5)
    poses[:, 2] += rng.uniform(0, 1, len(poses))
    (tmp_path / "p.csv").write_text("x,y,z,a,b,c\n" + "".join(",".join(f"{v:.6f}" for v in p) + "\n" for p in poses))
    (tmp_path / "m.json").write_text(calibrated.to_json())
    for ext, stem in ((".src", "big"), (".ls", "BIG")):
        r = run("kincal-compensate", "--model", str(tmp_path / "m.json"), "--program", str(tmp_path / "p.csv"), "--out",
                str(tmp_path / f"big{ext}"))
        assert r.returncode == 0, r.stderr
        assert sorted(p.name for p in tmp_path.glob(f"*_[0-9]{ext}")) == [f"{stem}_1{ext}", f"{stem}_2{ext}"]
