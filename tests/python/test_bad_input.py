"""Bad input, every command: one message naming the file (and line, where there is one) and the
cause, exit status 1, and no output file left behind."""

from __future__ import annotations

import json

import pytest

from conftest import run

GOOD_Q = "q1,q2,q3,q4,q5,q6\n0,-90,90,0,45,0\n"
GOOD_P = "x,y,z,a,b,c\n2000,0,1000,180,0,180\n"
MEAS_HEAD = "pose,q1,q2,q3,q4,q5,q6,x,y,z\n"
TABLE_HEAD = "point,theta1_deg,theta2_deg,x_desired_mm,y_desired_mm,x_measured_mm,y_measured_mm\n"


def _cases():
    # (name, files {name: text}, argv with {d} for the folder and OUT for the output, expected text)
    c = []
    for cmd, opt, head in (("fk", "--joints", None), ("ik", "--poses", None)):
        c += [
            (f"{cmd}-missing", {}, [cmd, "--robot", "kr500", opt, "{d}/nope.csv", "--out", "OUT"], "nope.csv"),
            (f"{cmd}-empty", {"e.csv": ""}, [cmd, "--robot", "kr500", opt, "{d}/e.csv", "--out", "OUT"], "e.csv"),
        ]
    c += [
        ("fk-text", {"q.csv": "q1,q2,q3,q4,q5,q6\n0,abc,90,0,45,0\n"},
         ["fk", "--robot", "kr500", "--joints", "{d}/q.csv", "--out", "OUT"], "q.csv:2"),
        ("fk-nan", {"q.csv": "q1,q2,q3,q4,q5,q6\n0,nan,90,0,45,0\n"},
         ["fk", "--robot", "kr500", "--joints", "{d}/q.csv", "--out", "OUT"], "q.csv:2"),
        ("fk-inf", {"q.csv": "q1,q2,q3,q4,q5,q6\n0,inf,90,0,45,0\n"},
         ["fk", "--robot", "kr500", "--joints", "{d}/q.csv", "--out", "OUT"], "q.csv:2"),
        ("fk-joint-count", {"q.csv": "q1,q2,q3,q4,q5,q6,q7\n0,0,0,0,0,0,0\n"},
         ["fk", "--robot", "kr500", "--joints", "{d}/q.csv", "--out", "OUT"], "q7"),
        ("fk-missing-column", {"q.csv": "q1,q2,q3,q4,q5\n0,0,0,0,0\n"},
         ["fk", "--robot", "kr500", "--joints", "{d}/q.csv", "--out", "OUT"], "q6"),
        ("ik-unreachable", {"p.csv": "x,y,z,a,b,c\n9000,0,0,0,0,0\n"},
         ["ik", "--robot", "kr500", "--poses", "{d}/p.csv", "--out", "OUT"], "p.csv:2"),
        ("compensate-gcode-broken", {"p.gcode": "G1 X2000 Y0 Z1.2.3 A180 B0 C180\n"},
         ["compensate", "--model", "kr500", "--program", "{d}/p.gcode", "--out", "OUT"], "p.gcode:1"),
        ("compensate-gcode-unset", {"p.gcode": "G1 X2000 Y0\n"},
         ["compensate", "--model", "kr500", "--program", "{d}/p.gcode", "--out", "OUT"], "p.gcode:1"),
        ("model-version", {"m.json": json.dumps({"format": "kincal-model", "version": 99, "nominal": {}})},
         ["compensate", "--model", "{d}/m.json", "--program", "{d}/p.csv", "--out", "OUT"], "m.json"),
        ("model-not-json", {"m.json": "{not json"},
         ["fk", "--robot", "{d}/m.json", "--joints", "{d}/q.csv", "--out", "OUT"], "m.json"),
        ("urdf-prismatic", {"r.urdf": '<robot name="r"><link name="a"/><link name="b"/>'
                            '<joint name="j" type="prismatic"><parent link="a"/><child link="b"/></joint></robot>'},
         ["fk", "--robot", "{d}/r.urdf", "--joints", "{d}/q.csv", "--out", "OUT"], "prismatic"),
        ("urdf-broken-xml", {"r.urdf": "<robot><link"},
         ["fk", "--robot", "{d}/r.urdf", "--joints", "{d}/q.csv", "--out", "OUT"], "r.urdf"),
        ("unknown-robot", {}, ["fk", "--robot", "kr9999", "--joints", "{d}/q.csv", "--out", "OUT"], "kr9999"),
        ("identify-too-few", {"m.csv": MEAS_HEAD + "".join(f"{i},0,-90,90,0,{i},0,1,2,3\n" for i in range(4))},
         ["identify", "--robot", "kr500", "--data", "{d}/m.csv", "--out", "OUT"], "m.csv"),
        ("identify-unknown-effect", {"m.csv": MEAS_HEAD + "0,0,-90,90,0,5,0,1,2,3\n"},
         ["identify", "--robot", "kr500", "--data", "{d}/m.csv", "--out", "OUT", "--effects", "magic"], "magic"),
        ("identify-dir-value", {"m.csv": "pose,q1,q2,q3,q4,q5,q6,x,y,z,dir1,dir2,dir3,dir4,dir5,dir6\n"
                                "0,0,-90,90,0,5,0,1,2,3,1,1,2,1,1,1\n"},
         ["identify", "--robot", "kr500", "--data", "{d}/m.csv", "--out", "OUT"], "m.csv:2"),
        ("simulate-bad-hide", {}, ["simulate", "--robot", "kr500", "--poses", "10", "--out", "OUT", "--hide", "x:1:2"],
         "unknown effect"),
        ("diagnose-missing", {}, ["diagnose", "--robot", "kr500", "--data", "{d}/nope.csv", "--out", "OUT"], "nope.csv"),
        ("feed-text", {"j.csv": "q1,q2,q3,q4,q5,q6\n0,0,0,0,0,x\n"},
         ["feed", "--robot", "kr500", "--program", "{d}/j.csv", "--out", "OUT"], "j.csv:2"),
        ("feed-limits", {"l.csv": "axis,v_max,a_max,j_max\n9,1,1,1\n"},
         ["feed", "--robot", "kr500", "--program", "{d}/q.csv", "--limits", "{d}/l.csv", "--out", "OUT"], "l.csv:2"),
        ("hr-fit-columns", {"t.csv": "point,theta1_deg\n1,2\n"},
         ["hidden-robot", "fit", "--data", "{d}/t.csv", "--out", "OUT"], "t.csv:1"),
        ("hr-fit-text", {"t.csv": TABLE_HEAD + "1,45,-45,212,0,abc,0\n"},
         ["hidden-robot", "fit", "--data", "{d}/t.csv", "--out", "OUT"], "t.csv:2"),
        ("hr-matrix-json", {"f.json": "[1,2", "t.csv": TABLE_HEAD + "1,45,-45,212,0,212,0\n"},
         ["hidden-robot", "matrix", "--fit", "{d}/f.json", "--data", "{d}/t.csv", "--out", "OUT"], "f.json"),
    ]
    return c


@pytest.mark.parametrize("name,files,argv,expect", _cases(), ids=[c[0] for c in _cases()])
def test_bad_input(tmp_path, name, files, argv, expect):
    (tmp_path / "q.csv").write_text(GOOD_Q)
    (tmp_path / "p.csv").write_text(GOOD_P)
    for f, text in files.items():
        (tmp_path / f).write_text(text)
    out = tmp_path / "out" / "result.csv" if name != "diagnose-missing" else tmp_path / "outdir"
    args = [a.replace("{d}", str(tmp_path)).replace("OUT", str(out)) for a in argv]
    r = run("kincal", *args)
    assert r.returncode == 1, (r.stdout, r.stderr)
    lines = [l for l in r.stderr.strip().splitlines() if l.strip()]
    assert len(lines) == 1, r.stderr
    assert expect in lines[0], lines[0]
    assert not out.exists()
    leftovers = [p for p in tmp_path.rglob("*") if p.name.startswith(".") or p.suffix == ".tmp"]
    assert not leftovers
