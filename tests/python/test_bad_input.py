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
        # a number that is not a finite decimal names the word (before: "G1 Xnan" was copied through and its
        # motion dropped, exit 0; "X1,5" and "X1e400" read as X1)
        *[(f"compensate-gcode-{k}", {"p.gcode": "G1 X2000 Y0 Z1000 A180 B0 C180\nG1 " + w + " Y10\n"},
           ["compensate", "--model", "kr500", "--program", "{d}/p.gcode", "--out", "OUT"],
           f"p.gcode:2: broken number in word {w[0]} ('{w}'): not a finite decimal number")
          for k, w in (("nan", "Xnan"), ("NaN", "XNaN"), ("inf", "Xinf"), ("comma", "X1,5"), ("exponent", "X1e400"),
                       ("minus-inf", "Z-inf"))],
        # a joint program holding a Cartesian motion is ambiguous (before: the line was skipped)
        *[(f"{cmd}-gcode-cartesian", {"j.gcode": "G1 A1=0 A2=-90 A3=90 A4=0 A5=30 A6=0\nG1 X100 Y5\n"},
           [cmd, "--robot", "kr500", opt, "{d}/j.gcode", "--out", "OUT"],
           "j.gcode:2: pose word 'X100' in a joint program")
          for cmd, opt in (("fk", "--joints"), ("feed", "--program"))],
        ("csv-quote-unclosed", {"p.csv": 'x,y,z,a,b,c,note\n2000,0,1000,180,0,180,"open\n'},
         ["compensate", "--model", "kr500", "--program", "{d}/p.csv", "--out", "OUT"],
         "p.csv:2: a quoted field is not closed"),
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
        # an effect whose column the data lack: the core's check names the first row without it
        ("identify-effect-column", {"m.csv": MEAS_HEAD + "".join(f"{i},{i},-90,90,0,{5 + i},0,1,2,3\n" for i in range(30))},
         ["identify", "--robot", "kr500", "--data", "{d}/m.csv", "--out", "OUT", "--effects", "backlash:2"],
         "m.csv:2: backlash needs the dir1..dir6 columns (the sign of each joint's last motion into the pose)"),
        ("identify-time-column", {"m.csv": MEAS_HEAD + "".join(f"{i},{i},-90,90,0,{5 + i},0,1,2,3\n" for i in range(30))},
         ["identify", "--robot", "kr500", "--data", "{d}/m.csv", "--out", "OUT", "--effects", "drift"],
         "m.csv:2: drift needs the time_s column (when each point was measured, s)"),
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
def test_bad_input(tmp_path, request, name, files, argv, expect):
    # a broken JSON input is the case itself (conftest's strict-JSON check still reads every output)
    request.applymarker(pytest.mark.bad_json_input(*[f for f in files if f.endswith(".json")]))
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


@pytest.mark.parametrize("tool", ["kincal", "kincal-compensate"])
def test_nonfinite_gcode_stops_the_stream_and_writes_no_file(tmp_path, tool):
    # the same through the standalone program, its --stream included (README: it stops at the first bad line)
    (tmp_path / "p.gcode").write_text("G1 X2000 Y0 Z1000 A180 B0 C180\nG1 Xinf\nG1 X2010\n")
    out = tmp_path / "o.gcode"
    args = ["compensate"] if tool == "kincal" else []
    r = run(tool, *args, "--model", "kr500", "--program", str(tmp_path / "p.gcode"), "--out", str(out))
    assert r.returncode == 1 and "p.gcode:2: broken number in word X ('Xinf')" in r.stderr, r.stderr
    assert not out.exists()
    if tool == "kincal-compensate":
        r = run(tool, "--model", "kr500", "--stream", stdin=(tmp_path / "p.gcode").read_text())
        assert r.returncode == 1 and "stdin:2: broken number in word X ('Xinf')" in r.stderr, r.stderr
        assert len(r.stdout.splitlines()) == 1  # the first pose only


@pytest.mark.parametrize("tool", ["kincal", "kincal-compensate"])
def test_standard_csv_variants_are_not_bad_input(tmp_path, tool):
    # RFC 4180 quoted fields (a comma and a doubled quote inside) in an extra column and the UTF-8 byte
    # order mark Excel writes, CRLF line ends: read as the plain file (before: "8 fields, the header has 7"
    # and "missing column 'x'")
    (tmp_path / "plain.csv").write_text(GOOD_P)
    (tmp_path / "excel.csv").write_bytes(b"\xef\xbb\xbfx,y,z,a,b,c,note\r\n"
                                         b'2000,0,1000,180,0,180,"hello, ""world"""\r\n')
    args = ["compensate"] if tool == "kincal" else []
    for name in ("plain", "excel"):
        r = run(tool, *args, "--model", "kr500", "--program", str(tmp_path / f"{name}.csv"), "--out",
                str(tmp_path / f"{name}_out.csv"))
        assert r.returncode == 0, r.stderr
    assert (tmp_path / "excel_out.csv").read_text() == (tmp_path / "plain_out.csv").read_text()
    if tool == "kincal":  # joints for fk, the C++ reader through the bindings
        (tmp_path / "q.csv").write_bytes(b"\xef\xbb\xbfq1,q2,q3,q4,q5,q6,\"note, free\"\n0,-90,90,0,45,0,\"a, b\"\n")
        (tmp_path / "q0.csv").write_text(GOOD_Q)
        for name in ("q", "q0"):
            r = run("kincal", "fk", "--robot", "kr500", "--joints", str(tmp_path / f"{name}.csv"), "--out",
                    str(tmp_path / f"{name}_fk.csv"))
            assert r.returncode == 0, r.stderr
        assert (tmp_path / "q_fk.csv").read_text() == (tmp_path / "q0_fk.csv").read_text()


def test_python_csv_columns_read_past_a_byte_order_mark(tmp_path):
    # the Python side's column reader (pose, target, dirN of measurements and joint programs) reads a file
    # Excel saved with a BOM as the plain one: the first column keeps its name
    from kincal.io import csv_text

    (tmp_path / "m.csv").write_bytes(b"\xef\xbb\xbfpose,q1,target\r\n7,0.5,1\r\n")
    assert csv_text.header(str(tmp_path / "m.csv")) == ["pose", "q1", "target"]
    assert csv_text.text_columns(str(tmp_path / "m.csv"), ["pose", "target"]) == {"pose": ["7"], "target": ["1"]}
