"""atheris fuzzing of kincal's readers (CSV, pose and joint programs as CSV and G-code, measurement
CSV, model JSON, hidden-robot FIT.json and MATRIX.json), through the C++ core's text parsers.

    python tests/fuzz/fuzz_readers.py -max_total_time=SECONDS -timeout=5

The C++ core is not coverage-instrumented, so the harness does its own structure-aware mutation:
the fuzzer's bytes choose a valid seed document and a sequence of edits (insert a token that
readers find hard, delete a range, overwrite a byte, duplicate a slice). A reader may reject its
input only with ValueError (kincal's InputError, naming the source and cause); any other exception,
a crash of the process or an input that takes longer than -timeout is a finding."""

from __future__ import annotations

import json
import sys

import atheris

with atheris.instrument_imports():
    from kincal import _core

TOKENS = [b"nan", b"inf", b"-inf", b"1e309", b"1e-400", b"-0", b",", b"\n", b";", b"(", b")", b"A1=", b"A7=",
          b"X", b"Y", b"Z", b"A", b"B", b"C", b"G1", b"N", b'"', b"{", b"}", b"[", b"]", b":", b"1.2.3", b"q7",
          b'"version": 2', b'"format": "x"', b"0x1p3", b"  ", b"\t", b"\r", "\u00e9".encode(), b"\x00", b"e", b"-",
          b"9" * 40, b"A1=1e999", b"X--1", b"dir1", b"target", b"-1", b"+", b"null", b"true"]


def _seeds() -> list:
    robot = _core.Robot.load("kr500").to_json().encode()
    em = {"format": "kincal-error-matrix", "version": 1, "x0_mm": 0, "y0_mm": 0, "dx_mm": 5, "dy_mm": 5, "nx": 2,
          "ny": 2, "error_x_mm": [0, 0.1, 0, 0.1], "error_y_mm": [0, 0, 0.1, 0.1]}
    return [
        (b"x,y,z,a,b,c\n2000,0,1000,180,0,180\n2000,10,1000,180,0,180\n", (0, 1)),
        (b"N10 G1 X2000 Y0 Z1000 A180 B0 C180 F100 ; c\nN20 Y10\n(comment) G1 X2010\nM30\n", (2,)),
        (b"q1,q2,q3,q4,q5,q6\n0,-90,90,0,45,0\n1,-90,90,0,45,0\n", (0, 3)),
        (b"G1 A1=0 A2=-90 A3=90 A4=0 A5=45 A6=0\nG1 A1=1\n", (4,)),
        (b"pose,q1,q2,q3,q4,q5,q6,x,y,z,target,payload_kg,temperature_c,dir1,dir2,dir3,dir4,dir5,dir6\n"
         b"0,0,-90,90,0,5,0,1,2,3,0,300,21.5,1,-1,1,1,-1,1\n", (0, 5)),
        (robot, (6,)),
        (json.dumps({"a": 150, "b": 150, "c": 150, "d": 150}).encode(), (7,)),
        (json.dumps(em).encode(), (8,)),
    ]


SEEDS = _seeds()


def one(data: bytes) -> None:
    fdp = atheris.FuzzedDataProvider(data)
    seed, readers = SEEDS[fdp.ConsumeIntInRange(0, len(SEEDS) - 1)]
    s = bytearray(seed)
    for _ in range(fdp.ConsumeIntInRange(0, 10)):
        op = fdp.ConsumeIntInRange(0, 3)
        pos = fdp.ConsumeIntInRange(0, len(s))
        if op == 0:
            s[pos:pos] = TOKENS[fdp.ConsumeIntInRange(0, len(TOKENS) - 1)]
        elif op == 1:
            del s[pos:pos + fdp.ConsumeIntInRange(1, 16)]
        elif op == 2 and s:
            s[min(pos, len(s) - 1)] = fdp.ConsumeIntInRange(0, 255)
        else:
            n = fdp.ConsumeIntInRange(1, 64)
            s[pos:pos] = s[pos:pos + n]
    text = bytes(s).decode("utf-8", "replace")
    which = readers[fdp.ConsumeIntInRange(0, len(readers) - 1)]
    try:
        if which == 0:
            _core.parse_csv(text, "fuzz.csv")
        elif which == 1:
            _core.parse_pose_program(text, "fuzz.csv", False)
        elif which == 2:
            _core.parse_pose_program(text, "fuzz.gcode", True)
        elif which == 3:
            _core.parse_joint_program(text, "fuzz.csv", False, 6)
        elif which == 4:
            _core.parse_joint_program(text, "fuzz.gcode", True, 6)
        elif which == 5:
            _core.parse_measurements(text, "fuzz.csv", 6)
        elif which == 6:
            _core.Robot.from_json(text, "fuzz.json")
        elif which == 7:
            _core.fivebar_from_json(text, "fuzz.json")
        else:
            _core.ErrorMatrix.from_json(text, "fuzz.json")
    except ValueError:
        pass


if __name__ == "__main__":
    atheris.Setup(sys.argv, one)
    atheris.Fuzz()
