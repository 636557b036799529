"""Program files compensated a chunk at a time (issue 33, item 5): `kincal compensate` and
`kincal-compensate` write the joint program of the whole program (the poses compensated in memory by
kincal.compensate, written with 10 decimals), byte for byte, for CSV and G-code, with every effect and
backlash (the first motion's direction found, or given), on a program longer than one chunk; the summary
is the one of the per-pose results; an error in a later chunk names its line and leaves no file, and so
does an interrupted run."""

from __future__ import annotations

import json
import signal
import subprocess
import time
from pathlib import Path

import numpy as np
import pytest

import kincal
from kincal import _core

from conftest import _tool, run

N = 18_000  # 1.3 MB as CSV: longer than the 1 MiB the commands read at a time
LATE = 16_000  # a line past the first 1 MiB


def _every_effect_model(calibrated: kincal.Robot, path: Path) -> Path:
    """The calibrated kr500 with every effect: compliance, a transmission error of joint 2 fitted on a
    narrow range of its angles (the path extrapolates it), backlash of joints 1 and 3, thermal expansion."""
    m = json.loads(calibrated.to_json())
    c = m["calibrated"]
    c["effects"] += [
        {"effect": "transmission_error", "joint": 2, "harmonics": [1, 2],
         "parameters": [{"name": n, "unit": "deg", "value": v}
                        for n, v in zip(["te_sin1", "te_cos1", "te_sin2", "te_cos2"], [3e-4, -2e-4, 1e-4, 0.0])]},
        {"effect": "backlash", "joint": 1, "parameters": [{"name": "backlash", "unit": "deg", "value": -2e-4}]},
        {"effect": "backlash", "joint": 3, "parameters": [{"name": "backlash", "unit": "deg", "value": -3e-4}]},
        {"effect": "thermal_expansion", "joint": None,
         "parameters": [{"name": "thermal_expansion", "unit": "1/degC", "value": 1.2e-5}]},
    ]
    m["campaign"]["fitted_joint_ranges_deg"] = [[-180.0, 180.0], [-50.0, -45.0]] + [[-180.0, 180.0]] * 4
    path.write_text(json.dumps(m))
    return path


def _path(n: int) -> np.ndarray:
    """n poses out and back (every joint turns around once)."""
    k = np.arange(n)
    u = np.where(k < n // 2, k, n - 1 - k) / (n // 2)
    return np.column_stack([1900 + 200 * u, -500 + 500 * u, 600 + 100 * u, 180 - 3 * u, 2 * u, np.full(n, 180.0)])


def _write(path: Path, poses: np.ndarray) -> None:
    """The poses as the shortest text that reads back to the same doubles (no exponents at these values)."""
    if path.suffix == ".csv":
        path.write_text("x,y,z,a,b,c\n" + "".join(",".join(repr(float(v)) for v in p) + "\n" for p in poses))
    else:
        path.write_text("; out and back\n" + "".join(
            "N{} G1 X{!r} Y{!r} Z{!r} A{!r} B{!r} C{!r} F2000\n".format(10 * (i + 1), *(float(v) for v in p))
            for i, p in enumerate(poses)) + "M30\n")


def _joint_program(q: np.ndarray, in_suffix: str, out_suffix: str) -> str:
    """The joint program format_joint_program writes for a program _write wrote."""
    words = [" ".join(f"A{j + 1}={v:.10f}" for j, v in enumerate(row)) for row in q]
    if out_suffix == ".csv":
        return "q1,q2,q3,q4,q5,q6\n" + "".join(",".join(f"{v:.10f}" for v in row) + "\n" for row in q)
    if in_suffix == ".csv":
        return "".join(f"G1 {w}\n" for w in words)
    return "; out and back\n" + "".join(f"N{10 * (i + 1)} G1 {w} F2000\n" for i, w in enumerate(words)) + "M30\n"


def _located(warnings: list, src: Path) -> list:
    """kincal.compensate's warnings ("pose i: ...") as the program file's ("src:line: ..."): pose i is on
    line i + 2 of the files _write writes."""
    out = []
    for w in warnings:
        head, rest = w.split(": ", 1)
        out.append(f"{src}:{int(head.split()[1]) + 2}: {rest}")
    return out


def _summary(res: dict) -> str:
    it = np.asarray(res["iterations"])
    return (f"{len(it)} poses compensated, iterations {it.min()}..{it.max()} (mean {it.mean():.2f}), "
            f"largest residual |F| {max(res['residual']):.3g}")


@pytest.mark.parametrize("initial", [None, "-1"])
def test_both_commands_write_the_program_compensated_whole(tmp_path, calibrated, initial):
    model = _every_effect_model(calibrated, tmp_path / "model.json")
    robot = kincal.load_robot(str(model))
    poses = _path(N)
    res = kincal.compensate(robot, poses, temperature_c=26.0, initial_direction=None if initial is None else -1.0)
    assert (np.diff(res["dir"], axis=0) != 0).any()  # the joints do turn around
    assert any("extrapolated" in w for w in res["warnings"])
    opts = ["--temperature", "26"] + ([] if initial is None else ["--initial-direction", initial])
    for src in (tmp_path / "p.csv", tmp_path / "p.gcode"):
        _write(src, poses)
        assert src.stat().st_size > 1 << 20
        for out in (tmp_path / "o.csv", tmp_path / "o.gcode"):
            expected = _joint_program(res["q_deg"], src.suffix, out.suffix)
            r = run("kincal", "compensate", "--model", str(model), "--program", str(src), "--out", str(out), *opts)
            assert r.returncode == 0, r.stderr
            assert out.read_text() == expected, (src.name, out.name)
            lines = r.stderr.splitlines()
            assert lines[-1] == f"{out}: {_summary(res)}"
            assert [w for w in lines if f" {src}:" in w] == [f"kincal compensate: warning: {w}"
                                                             for w in _located(res["warnings"], src)]
            out.unlink()
            r = run("kincal-compensate", "--model", str(model), "--program", str(src), "--out", str(out), *opts)
            assert r.returncode == 0, r.stderr
            assert out.read_text() == expected, (src.name, out.name)
            lines = r.stderr.splitlines()
            assert lines[-1] == f"{out}: {N} poses, at most {max(res['iterations'])} iterations, largest residual " \
                                f"{max(res['residual']):.3g}"
            assert [w for w in lines if f" {src}:" in w] == [f"kincal-compensate: warning: {w}"
                                                             for w in _located(res["warnings"], src)]


def test_small_chunks_through_the_binding(tmp_path, calibrated):
    """chunk_bytes as small as a line, or smaller: the same file and result as the whole program."""
    model = _every_effect_model(calibrated, tmp_path / "model.json")
    robot = kincal.load_robot(str(model))
    poses = _path(400)
    res = kincal.compensate(robot, poses, temperature_c=21.0)
    for src in (tmp_path / "p.csv", tmp_path / "p.gcode"):
        _write(src, poses)
        for chunk in (1, 50, 4096):
            out = tmp_path / ("o" + src.suffix)
            got = _core.compensate_program(robot, str(src), str(out),
                                           _core.ProgramOptions(temperature_c=21.0, chunk_bytes=chunk))
            assert out.read_text() == _joint_program(res["q_deg"], src.suffix, src.suffix)
            assert np.array_equal(got["q_deg"], res["q_deg"]) and np.array_equal(got["dir"], res["dir"])
            assert got["warnings"] == _located(res["warnings"], src)
            assert got["poses"] == 400 and got["iterations_max"] == max(res["iterations"])
            lean = _core.compensate_program(robot, str(src), str(out),
                                            _core.ProgramOptions(temperature_c=21.0, chunk_bytes=chunk, keep_poses=False))
            assert len(lean["q_deg"]) == 0 and lean["poses"] == 400
            assert (lean["iterations_min"], lean["iterations_max"], lean["iterations_total"], lean["residual_max"]) == (
                min(res["iterations"]), max(res["iterations"]), sum(res["iterations"]), max(res["residual"]))


@pytest.mark.parametrize("tool", ["kincal", "kincal-compensate"])
def test_a_bad_line_in_the_second_chunk(tmp_path, calibrated, tool):
    """The message names the file, the line (past the first 1 MiB) and the cause, also when a pose before it
    fails (the file's broken lines come first, as when it was read whole); no output, no temporary file."""
    model = _every_effect_model(calibrated, tmp_path / "model.json")
    poses = _path(N)
    args = ["compensate"] if tool == "kincal" else []
    for far in (False, True):
        src = tmp_path / "p.csv"
        _write(src, poses)
        lines = src.read_text().splitlines(keepends=True)
        if far:
            lines[99] = "9000,0,500,180,0,180\n"  # out of reach, in the first chunk
        lines[LATE - 1] = "2000,abc,500,180,0,180\n"
        src.write_text("".join(lines))
        assert len("".join(lines[:LATE - 1]).encode()) > 1 << 20
        out = tmp_path / "out.csv"
        r = run(tool, *args, "--model", str(model), "--program", str(src), "--out", str(out), "--temperature", "26")
        assert r.returncode != 0
        assert f"{src}:{LATE}: column 'y': 'abc' is not a number" in r.stderr, r.stderr
        assert len(r.stderr.strip().splitlines()) == 1, r.stderr
        assert not list(tmp_path.glob("out*"))
    # a pose that fails in the second chunk: its line, and no file
    lines = src.read_text().splitlines(keepends=True)
    lines[99] = lines[98]
    lines[LATE - 1] = "9000,0,500,180,0,180\n"
    src.write_text("".join(lines))
    r = run(tool, *args, "--model", str(model), "--program", str(src), "--out", str(tmp_path / "out.csv"),
            "--temperature", "26")
    assert r.returncode != 0 and f"{src}:{LATE}: pose out of reach" in r.stderr, r.stderr
    assert not list(tmp_path.glob("out*"))


@pytest.mark.parametrize("sig", [signal.SIGTERM, signal.SIGINT])
def test_an_interrupted_run_leaves_no_file(tmp_path, calibrated, sig):
    """kincal-compensate stopped by a signal while it writes: neither the output nor its temporary file
    is left (a program of millions of poses takes a minute)."""
    model = _every_effect_model(calibrated, tmp_path / "model.json")
    src, out = tmp_path / "p.csv", tmp_path / "out.csv"
    _write(src, np.tile(_path(N), (20, 1)))  # 360,000 poses: seconds of work
    # the signal at its default in the child: a run in the background (a CI job started with &) inherits
    # SIGINT ignored, which kincal-compensate keeps ignored, as a nohup'd command should
    p = subprocess.Popen([_tool("kincal-compensate"), "--model", str(model), "--program", str(src), "--out", str(out),
                          "--temperature", "26", "--initial-direction", "1"], stderr=subprocess.PIPE, text=True,
                         preexec_fn=lambda: signal.signal(sig, signal.SIG_DFL))
    deadline = time.monotonic() + 60
    while not list(tmp_path.glob("out.csv.tmp*")) and p.poll() is None and time.monotonic() < deadline:
        time.sleep(0.01)
    assert p.poll() is None, "the program ended before it could be interrupted"
    assert list(tmp_path.glob("out.csv.tmp*")), "no temporary file appeared within 60 s: nothing to clean up"
    p.send_signal(sig)
    p.communicate(timeout=60)
    assert p.returncode == -sig
    assert not list(tmp_path.glob("out*"))
