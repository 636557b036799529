"""The TCP is measured or the user is told: 6-D rows identify the tool frame itself (fk and compensate
of the identified model reach the measured poses), reflectors alone leave it nominal and the model
says so ("tcp": "nominal"), and every command that uses such a model warns in one line."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

import kincal
from kincal import _core
from kincal.calibration import identify as ident

from conftest import run
from test_accuracy import HAND, _runs_csv

TCP_WARNING = "the TCP is nominal (not measured)"


@pytest.fixture(scope="module")
def truth(kr500) -> kincal.Robot:
    """kr500 with 1 mm / 0.05 deg geometric errors (its tool frame included), no compliance, seen from a
    tracker at DEFAULT_INSTRUMENT (seed 17). (With compliance in the truth a noise-free campaign is
    fitted to about 1 um RMS only, reflectors or 6-D rows alike: not the TCP's matter.)"""
    return kr500.with_calibrated(17, 1.0, 0.05, 0.0, ident.DEFAULT_INSTRUMENT)


@pytest.fixture(scope="module")
def six_d(kr500, truth) -> ident.Identification:
    """A noise-free 6-D campaign on the truth (300 poses of the tool frame, position and orientation
    measured exactly), identified as `kincal identify` does (priors, robust loss), without validation."""
    data = ident.simulate(truth, 300, seed=41, noise_mm=0.0, orientation_noise_deg=0.0)
    return ident.identify(kr500, data, k_folds=0)


def _instrument_pose_errors(model: kincal.Robot, data: dict) -> tuple:
    """Largest position (mm) and orientation (deg) error of fk (instrument frame, no target offset)
    against 6-D rows."""
    p = kincal.fk(model, data["q_deg"], frame="instrument")
    dp = np.linalg.norm(p[:, :3] - data["xyz"], axis=1)
    return float(np.max(dp)), max(_angle_deg(a, b) for a, b in zip(data["abc"], p[:, 3:]))


def _angle_deg(a, b) -> float:
    """The angle (deg) between two orientations given as ABC (deg), accurate near zero."""
    r = _core.abc_to_rotation(np.asarray(a, dtype=float)).T @ _core.abc_to_rotation(np.asarray(b, dtype=float))
    s = np.linalg.norm([r[2, 1] - r[1, 2], r[0, 2] - r[2, 0], r[1, 0] - r[0, 1]]) / 2.0
    return float(np.degrees(np.arctan2(s, (np.trace(r) - 1.0) / 2.0)))


def test_six_d_rows_identify_the_tool_frame(six_d, truth):
    """The 6-D rows' target has no offset (held at zero) and the tool frame is free; fk of the
    identified model reproduces 100 held-out noise-free poses (configurations not fitted, seed 42)
    to 1e-4 mm and 1e-5 deg, as the frame the rows measure; the model records "tcp": "measured"."""
    params = {p["name"]: p for p in six_d.parameters()}
    for k in ("x", "y", "z", "rx", "ry", "rz"):
        assert not params[f"tool.{k}"]["fixed"], params[f"tool.{k}"]["reason"]
    for k in "xyz":
        assert params[f"target0.{k}"]["fixed"] and params[f"target0.{k}"]["value"] == 0.0
    assert np.all(np.asarray(six_d.targets) == 0.0)
    held = ident.simulate(truth, 100, seed=42, noise_mm=0.0, orientation_noise_deg=0.0)
    dp, da = _instrument_pose_errors(six_d.robot, held)
    assert dp < 1e-4 and da < 1e-5, (dp, da)
    # the nominal geometry (its base and tool frames fitted) is mm away
    dp_nominal, _ = _instrument_pose_errors(six_d.fit.nominal_fitted, held)
    assert dp_nominal > 1.0
    doc = json.loads(six_d.model_json())
    assert doc["tcp"] == "measured" and doc["identification"]["targets_mm"] == [[0.0, 0.0, 0.0]]
    summary = six_d.summary()
    assert summary.count("TCP: measured") == 1 and "TCP: nominal" not in summary


def test_compensation_on_the_identified_model_reaches_the_poses(six_d, truth, kr500):
    """Desired tool poses (instrument frame: the truth's fk at 50 configurations around home, none of
    them fitted) compensated on the 6-D-identified model; the truth's fk of the joints found reaches
    them to 1e-4 mm and 1e-5 deg."""
    rng = np.random.default_rng(43)
    q = np.asarray(kr500.home_deg)[None, :] + rng.uniform(-30, 30, (50, 6))
    desired = kincal.fk(truth, q, frame="instrument")
    res = kincal.compensate(six_d.robot, desired, frame="instrument")
    reached = kincal.fk(truth, res["q_deg"], frame="instrument")
    dp = np.max(np.linalg.norm(reached[:, :3] - desired[:, :3], axis=1))
    da = max(_angle_deg(a, b) for a, b in zip(desired[:, 3:], reached[:, 3:]))
    assert dp < 1e-4 and da < 1e-5, (dp, da)


def test_mixed_campaign_six_d_rows_and_reflectors(kr500, truth, tmp_path):
    """A file of 6-D rows (the first target: the tool frame) and reflector rows (two more targets at
    DEFAULT_TARGETS[1:3], a, b, c empty), noise-free, 150 poses: read back from its CSV, identified,
    the reflectors' offsets come out in the tool frame (to 1e-5 mm) and held-out poses are
    reproduced by fk (1e-4 mm)."""
    data = ident.simulate(truth, 150, seed=44, noise_mm=0.0, orientation_noise_deg=0.0, targets=3)
    text = ident.measurements_csv(data, 6)
    lines = text.splitlines()
    assert lines[2].split(",")[10:13] == ["", "", ""]  # pose 0's second target: a reflector row
    (tmp_path / "m.csv").write_text(text)
    back = ident.read_measurements(str(tmp_path / "m.csv"), kr500)
    assert np.isnan(back["abc"][data["target"] != 0]).all() and not np.isnan(back["abc"][data["target"] == 0]).any()
    res = ident.identify(kr500, back, k_folds=2)
    assert res.robot.tcp == "measured"
    assert np.max(np.abs(np.asarray(res.targets) - ident.DEFAULT_TARGETS[:3])) < 1e-5
    held = ident.simulate(truth, 50, seed=45, noise_mm=0.0, orientation_noise_deg=0.0)
    dp, da = _instrument_pose_errors(res.robot, held)
    assert dp < 1e-4 and da < 1e-5, (dp, da)
    assert res.validation["after_rms_mm"] < 1e-4 and res.validation["after_rms_deg"] < 1e-5
    # 6-D rows of two targets would be two tool frames: a clear error
    two = back.with_columns(abc=np.where(np.isnan(back.abc), 0.0, back.abc))
    with pytest.raises(ValueError, match="6-D rows of target 0 and of target 1"):
        ident.identify(kr500, two, k_folds=0)


@pytest.fixture(scope="module")
def reflector_model(tmp_path_factory):
    """`kincal identify` of a reflector campaign (3 reflectors, 120 poses, 0.02 mm noise; no
    --tool-targets): the TCP stays nominal."""
    d = tmp_path_factory.mktemp("reflectors")
    r = run("kincal", "simulate", "--robot", "kr500", "--poses", "120", "--seed", "7", "--targets", "3",
            "--out", str(d / "m.csv"))
    assert r.returncode == 0, r.stderr
    r = run("kincal", "identify", "--robot", "kr500", "--data", str(d / "m.csv"), "--out", str(d / "m.json"),
            "--folds", "0")
    assert r.returncode == 0, r.stderr
    return d, r.stdout


def test_reflectors_only_record_a_nominal_tcp(reflector_model):
    d, stdout = reflector_model
    doc = json.loads((d / "m.json").read_text())
    assert doc["tcp"] == "nominal"
    tcp_lines = [ln for ln in stdout.splitlines() if ln.startswith("TCP:")]
    assert tcp_lines == ["TCP: nominal (reflectors, or a probe's ball, place only themselves, not the tool frame; "
                         "--tool-targets or a 6-D row measures it)"]


def test_tool_targets_record_where_the_tcp_comes_from(reflector_model, tmp_path):
    """--tool-targets places the TCP: "tcp": "tool-targets", and no warning afterwards."""
    d, _ = reflector_model
    (tmp_path / "t.csv").write_text("x,y,z\n" + "".join(f"{a!r},{b!r},{c!r}\n" for a, b, c in
                                                        ident.DEFAULT_TARGETS[:3].tolist()))
    r = run("kincal", "identify", "--robot", "kr500", "--data", str(d / "m.csv"), "--out", str(tmp_path / "m.json"),
            "--folds", "0", "--tool-targets", str(tmp_path / "t.csv"))
    assert r.returncode == 0, r.stderr
    assert json.loads((tmp_path / "m.json").read_text())["tcp"] == "tool-targets"
    assert "TCP: placed by --tool-targets" in r.stdout
    assert kincal.load_robot(str(tmp_path / "m.json")).tcp_warning("m.json") == ""


def _program(tmp_path) -> str:
    """A short pose program (base frame) near the kr500's home."""
    kr = kincal.load_robot("kr500")
    q = np.asarray(kr.home_deg)[None, :] + np.array([[0, 0, 0, 0, 0, 0], [10, -5, 5, 10, 5, -10.0]])
    p = kincal.fk(kr, q)
    (tmp_path / "prog.csv").write_text("x,y,z,a,b,c\n" + "".join(",".join(repr(float(v)) for v in row) + "\n"
                                                                 for row in p))
    return str(tmp_path / "prog.csv")


def _warning_lines(stderr: str) -> list:
    return [ln for ln in stderr.splitlines() if TCP_WARNING in ln]


@pytest.mark.parametrize("which", ["reflectors", "six_d", "builtin"])
def test_one_warning_line_for_a_nominal_tcp(which, reflector_model, six_d, tmp_path):
    """kincal compensate, kincal-compensate and kincal accuracy iso9283 --model each print exactly one
    warning line for the reflector-identified model, none for the 6-D-identified one (nor, for
    compensate, for a built-in robot)."""
    d, _ = reflector_model
    if which == "reflectors":
        model = str(d / "m.json")
    elif which == "six_d":
        model = str(tmp_path / "six.json")
        (tmp_path / "six.json").write_text(six_d.model_json())
    else:
        model = "kr500"
    want = 1 if which == "reflectors" else 0
    prog = _program(tmp_path)
    r = run("kincal", "compensate", "--model", model, "--program", prog, "--out", str(tmp_path / "a.csv"))
    assert r.returncode == 0, r.stderr
    lines = _warning_lines(r.stderr)
    assert len(lines) == want, r.stderr
    if want:
        assert lines[0] == (f"kincal compensate: warning: {model}: the TCP is nominal (not measured): every pose "
                            "carries the tool's error; identify with --tool-targets or 6-D rows")
    r = run("kincal-compensate", "--model", model, "--program", prog, "--out", str(tmp_path / "b.csv"))
    assert r.returncode == 0, r.stderr
    lines = _warning_lines(r.stderr)
    assert len(lines) == want, r.stderr
    if want:
        assert lines[0].startswith(f"kincal-compensate: warning: {model}: {TCP_WARNING}")
    r = run("kincal-compensate", "--model", model, "--stream", stdin=Path(prog).read_text())
    assert r.returncode == 0, r.stderr
    assert len(_warning_lines(r.stderr)) == want, r.stderr
    if which == "builtin":
        return
    (tmp_path / "runs.csv").write_text(_runs_csv(HAND))
    r = run("kincal", "accuracy", "iso9283", "--data", str(tmp_path / "runs.csv"), "--out", str(tmp_path / "iso"),
            "--model", model, "--frame", "instrument")
    assert r.returncode == 0, r.stderr
    lines = _warning_lines(r.stderr)
    assert len(lines) == want, r.stderr
    if want:
        assert lines[0].startswith(f"kincal accuracy: warning: {model}: {TCP_WARNING}")


def test_tcp_key_round_trips(reflector_model, six_d, kr500):
    """The model file's top-level "tcp" survives reading and writing (C++ reader and writer); a model
    without it (older files, built-in robots) records nothing; a value not known is an error."""
    d, _ = reflector_model
    for text, want in (((d / "m.json").read_text(), "nominal"), (six_d.model_json(), "measured")):
        robot = kincal.Robot.from_json(text, "m.json")
        assert robot.tcp == want
        again = json.loads(robot.to_json())
        assert again["tcp"] == want and kincal.Robot.from_json(robot.to_json()).tcp == want
    doc = json.loads((d / "m.json").read_text())
    del doc["tcp"]
    old = kincal.Robot.from_json(json.dumps(doc), "old.json")
    assert old.tcp == "" and "tcp" not in json.loads(old.to_json()) and old.tcp_warning("old.json") == ""
    assert kr500.tcp == "" and "tcp" not in json.loads(kr500.to_json())
    doc["tcp"] = "guessed"
    with pytest.raises(ValueError, match='old.json: tcp: "guessed" is not one of'):
        kincal.Robot.from_json(json.dumps(doc), "old.json")
