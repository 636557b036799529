"""The controller's joint numbers (issue 19, item 5): a FANUC controller's J3 is the forearm's angle to
the horizontal. On tests/data/fanuc_like.urdf (axis 2 = +y, axis 3 = -y, as ROS-Industrial FANUC
URDFs) the URDF's joint 3 is J3 + J2, i.e. J3 = q3 - q2 (hand-converted values below). Truth of the
synthetic data: the URDF robot with 1 mm / 0.05 deg errors and compliance (seed 13), no noise, 40
poses, the joint angles then rounded to 1/1024 deg (up to 0.0005 deg of error, the same in both
files); the same rows identified once as the model's angles (no convention) and once as the
controller's (J3 converted by hand, --joint-convention fanuc) give the same model to 1e-9 mm. An LS
joint program written for a fanuc model carries the controller's J3."""

from __future__ import annotations

import csv
import io
import json
import re
from pathlib import Path

import numpy as np
import pytest

import kincal
from kincal import _core
from kincal.calibration import identify as ident

from conftest import run

URDF = Path(__file__).resolve().parents[1] / "data" / "fanuc_like.urdf"


@pytest.fixture(scope="module")
def fanuc():
    return kincal.load_robot(URDF, joint_convention="fanuc")


def test_hand_converted_values(fanuc):
    q_model = np.array([[10.0, 20.0, 30.0, 40.0, 50.0, 60.0], [0.0, -35.5, -70.25, 0.0, 90.0, 0.0]])
    hand = np.array([[10.0, 20.0, 10.0, 40.0, 50.0, 60.0], [0.0, -35.5, -34.75, 0.0, 90.0, 0.0]])
    assert np.array_equal(_core.joints_to_controller(fanuc, q_model), hand)
    assert np.array_equal(_core.joints_from_controller(fanuc, hand), q_model)
    plain = kincal.load_robot(URDF)
    assert np.array_equal(_core.joints_to_controller(plain, q_model), q_model)
    assert _core.joint_convention(fanuc) == "fanuc" and _core.joint_convention(plain) == ""


def test_controller_j3_is_the_forearm_angle(fanuc):
    # with the controller's J3 held, moving J2 keeps the forearm's (and so the tool's) orientation
    rot = []
    for j2 in (-40.0, 0.0, 25.0, 60.0):
        q = _core.joints_from_controller(fanuc, np.array([[15.0, j2, -20.0, 30.0, 40.0, 50.0]]))
        rot.append(_core.fk_matrix(fanuc, q[0], False)[:3, :3])
    assert max(np.abs(r - rot[0]).max() for r in rot) < 1e-12


def _model_and_controller_csv(text: str) -> tuple[str, str]:
    """The rows with q1..q6 on multiples of 1/1024 deg (so that J3 = q3 - q2 and back are exact in
    binary: both files then give the reader the very same model angles), as the model's angles and
    as the controller's (J3 converted by hand: J3 = q3 - q2)."""
    rows = list(csv.DictReader(io.StringIO(text)))
    files = []
    for convert in (False, True):
        out = io.StringIO()
        w = csv.DictWriter(out, fieldnames=list(rows[0]), lineterminator="\n")
        w.writeheader()
        for r in rows:
            q = {f"q{j}": round(float(r[f"q{j}"]) * 1024) / 1024 for j in range(1, 7)}
            if convert:
                q["q3"] = q["q3"] - q["q2"]
            w.writerow({**r, **{k: repr(v) for k, v in q.items()}})
        files.append(out.getvalue())
    return files[0], files[1]


def test_measurements_in_controller_numbers_identify_the_same_model(tmp_path):
    robot = kincal.load_robot(URDF)
    truth = robot.with_calibrated(13, 1.0, 0.05, 0.003, ident.DEFAULT_INSTRUMENT)
    (tmp_path / "truth.json").write_text(truth.to_json())
    r = run("kincal", "simulate", "--robot", str(URDF), "--truth", str(tmp_path / "truth.json"), "--poses", "40",
            "--noise", "0", "--out", str(tmp_path / "sim.csv"))
    assert r.returncode == 0, r.stderr
    model_angles, controller = _model_and_controller_csv((tmp_path / "sim.csv").read_text())
    (tmp_path / "model_angles.csv").write_text(model_angles)
    (tmp_path / "controller.csv").write_text(controller)
    # the same effects on both (the subject is the convention; on noise-free data --effects auto also keeps
    # micron-sized maps and a backlash, whose fk would need dir columns)
    a = run("kincal", "identify", "--robot", str(URDF), "--data", str(tmp_path / "model_angles.csv"), "--out",
            str(tmp_path / "a.json"), "--effects", "joint_compliance")
    b = run("kincal", "identify", "--robot", str(URDF), "--joint-convention", "fanuc", "--data",
            str(tmp_path / "controller.csv"), "--out", str(tmp_path / "b.json"), "--effects", "joint_compliance")
    assert a.returncode == 0 and b.returncode == 0, a.stderr + b.stderr
    ma, mb = kincal.load_robot(tmp_path / "a.json"), kincal.load_robot(tmp_path / "b.json")
    assert json.loads((tmp_path / "b.json").read_text())["joint_convention"] == "fanuc"
    q = np.random.default_rng(3).uniform(-60, 60, size=(200, 6))
    pa, pb = _core.fk(ma, q, True, True), _core.fk(mb, q, True, True)
    assert np.abs(pa[:, :3] - pb[:, :3]).max() < 1e-9


def test_ls_joint_program_and_fk_carry_the_controller_j3(tmp_path, fanuc):
    cal = kincal.load_robot(URDF).with_calibrated(13, 1.0, 0.05, 0.003, ident.DEFAULT_INSTRUMENT)
    model = json.loads(cal.to_json())
    model["joint_convention"] = "fanuc"
    (tmp_path / "m.json").write_text(json.dumps(model))
    m = kincal.load_robot(tmp_path / "m.json")
    q_model = np.array([[5.0, 10.0, -20.0, 10.0, -40.0, 15.0], [8.0, 15.0, -15.0, 12.0, -45.0, 20.0],
                        [12.0, 20.0, -10.0, 15.0, -50.0, 25.0]])
    poses = kincal.fk(m, q_model)  # the calibrated robot at q_model: compensation gives q_model back
    (tmp_path / "p.csv").write_text("x,y,z,a,b,c\n" + "".join(",".join(f"{v:.12f}" for v in p) + "\n" for p in poses))
    for tool in ("kincal", "kincal-compensate"):
        out = tmp_path / f"j_{tool.replace('-', '_')}.ls"
        args = ["compensate"] if tool == "kincal" else []
        r = run(tool, *args, "--model", str(tmp_path / "m.json"), "--program", str(tmp_path / "p.csv"), "--out", str(out))
        assert r.returncode == 0, r.stderr
        j = np.array([[float(x) for x in re.findall(r"J\d=\s*(-?\d+\.\d+) deg", b)]
                      for b in re.findall(r"P\[\d+\]\{(.*?)\};", out.read_text(), re.S)])
        hand = q_model.copy()
        hand[:, 2] = q_model[:, 2] - q_model[:, 1]
        assert np.abs(j - hand).max() < 2e-4  # 4 decimals printed, + the compensation's 1e-7
    # kincal fk reads the controller's numbers
    (tmp_path / "q.csv").write_text("q1,q2,q3,q4,q5,q6\n" + "".join(",".join(repr(float(v)) for v in q) + "\n" for q in hand))
    r = run("kincal", "fk", "--robot", str(tmp_path / "m.json"), "--joints", str(tmp_path / "q.csv"), "--out",
            str(tmp_path / "fk.csv"))
    assert r.returncode == 0, r.stderr
    got = np.loadtxt(tmp_path / "fk.csv", delimiter=",", skiprows=1)
    assert np.abs(got[:, :3] - poses[:, :3]).max() < 1e-6


def test_simulate_writes_the_controller_numbers(tmp_path):
    # the same truth simulated with and without the convention: the same rows, J3 = q3 - q2
    truth = kincal.load_robot(URDF).with_calibrated(13, 1.0, 0.05, 0.003, ident.DEFAULT_INSTRUMENT)
    (tmp_path / "truth.json").write_text(truth.to_json())
    out = {}
    for conv in ([], ["--joint-convention", "fanuc"]):
        path = tmp_path / f"sim{len(conv)}.csv"
        r = run("kincal", "simulate", "--robot", str(URDF), *conv, "--truth", str(tmp_path / "truth.json"), "--poses",
                "5", "--noise", "0", "--out", str(path))
        assert r.returncode == 0, r.stderr
        out[len(conv)] = list(csv.DictReader(io.StringIO(path.read_text())))
    for a, b in zip(out[0], out[2]):
        assert float(b["q3"]) == pytest.approx(float(a["q3"]) - float(a["q2"]), abs=1e-9)
        assert b["x"] == a["x"] and b["q2"] == a["q2"]


def test_ik_writes_the_controller_numbers(tmp_path):
    cal = kincal.load_robot(URDF)
    model = json.loads(cal.to_json())
    model["joint_convention"] = "fanuc"
    (tmp_path / "m.json").write_text(json.dumps(model))
    q_model = np.array([[5.0, 10.0, -20.0, 10.0, -40.0, 15.0], [12.0, 20.0, -10.0, 15.0, -50.0, 25.0]])
    poses = kincal.fk(cal, q_model, calibrated=False)
    (tmp_path / "p.csv").write_text("x,y,z,a,b,c\n" + "".join(",".join(f"{v:.12f}" for v in p) + "\n" for p in poses))
    r = run("kincal", "ik", "--robot", str(tmp_path / "m.json"), "--poses", str(tmp_path / "p.csv"), "--out",
            str(tmp_path / "q.csv"), "--all")
    assert r.returncode == 0, r.stderr
    rows = np.loadtxt(tmp_path / "q.csv", delimiter=",", skiprows=1)
    hand = q_model.copy()
    hand[:, 2] = q_model[:, 2] - q_model[:, 1]  # J3 = q3 - q2
    for i in range(2):
        sols = rows[rows[:, 0] == i][:, 3:]
        assert np.abs(sols - hand[i]).max(axis=1).min() < 1e-8


def test_kincal_compensate_takes_the_convention_for_a_builtin_robot(tmp_path):
    # kr500 (axes 2 and 3 parallel) with --joint-convention fanuc: kincal-compensate writes what kincal
    # compensate writes, and against the plain run only J3 changes, by s q2 with one sign s for all rows
    q = np.array([[5.0, -80.0, 100.0, 10.0, 40.0, 15.0], [-20.0, -60.0, 80.0, -15.0, 50.0, 25.0]])
    poses = kincal.fk(kincal.load_robot("kr500"), q)
    (tmp_path / "p.csv").write_text("x,y,z,a,b,c\n" + "".join(",".join(f"{v:.12f}" for v in p) + "\n" for p in poses))
    out = {}
    for name, cmd in (("plain", ["kincal-compensate"]), ("cpp", ["kincal-compensate", "--joint-convention", "fanuc"]),
                      ("py", ["kincal", "compensate", "--joint-convention", "fanuc"])):
        r = run(*cmd, "--model", "kr500", "--program", str(tmp_path / "p.csv"), "--out", str(tmp_path / f"{name}.csv"))
        assert r.returncode == 0, r.stderr
        out[name] = (tmp_path / f"{name}.csv").read_text()
    assert out["cpp"] == out["py"]
    cols = lambda text: {k: np.array([float(row[k]) for row in csv.DictReader(io.StringIO(text))]) for k in
                         ("q1", "q2", "q3", "q4", "q5", "q6")}
    plain, conv = cols(out["plain"]), cols(out["cpp"])
    for k in ("q1", "q2", "q4", "q5", "q6"):
        assert np.array_equal(plain[k], conv[k])
    s = np.round((conv["q3"] - plain["q3"]) / plain["q2"])
    assert abs(s[0]) == 1 and np.all(s == s[0])
    assert np.abs(conv["q3"] - (plain["q3"] + s[0] * plain["q2"])).max() < 2e-6
    # a model JSON carries its own convention: the option is refused there, naming the file
    (tmp_path / "m.json").write_text(kincal.load_robot("kr500").to_json())
    r = run("kincal-compensate", "--model", str(tmp_path / "m.json"), "--joint-convention", "fanuc", "--program",
            str(tmp_path / "p.csv"), "--out", str(tmp_path / "x.csv"))
    assert r.returncode != 0 and "m.json" in r.stderr and "joint_convention" in r.stderr
    assert not (tmp_path / "x.csv").exists()


def test_native_ls_joint_target_carries_the_controller_j3(tmp_path):
    # an existing LS program on the FANUC URDF model with the convention: its J-only position is written
    # in joint form, in the controller's numbers (J3 = q3 - q2, by hand)
    cal = kincal.load_robot(URDF).with_calibrated(13, 1.0, 0.05, 0.003, ident.DEFAULT_INSTRUMENT)
    model = json.loads(cal.to_json())
    model["joint_convention"] = "fanuc"
    (tmp_path / "m.json").write_text(json.dumps(model))
    q_model = np.array([8.0, 15.0, -15.0, 12.0, -45.0, 20.0])
    p = kincal.fk(kincal.load_robot(tmp_path / "m.json"), q_model[None, :])[0]
    (tmp_path / "J.ls").write_text(
        "/PROG  J\n/MN\n   1:  J P[1] 20% FINE    ;\n/POS\nP[1]{\n   GP1:\n\tUF : 0, UT : 1,\t\tCONFIG : 'N U T, 0, 0, 0',\n"
        f"\tX = {p[0]:.4f}  mm,\tY = {p[1]:.4f}  mm,\tZ = {p[2]:.4f}  mm,\n"
        f"\tW = {p[5]:.4f} deg,\tP = {p[4]:.4f} deg,\tR = {p[3]:.4f} deg\n}};\n/END\n")
    r = run("kincal-compensate", "--model", str(tmp_path / "m.json"), "--program", str(tmp_path / "J.ls"), "--out",
            str(tmp_path / "out.ls"))
    assert r.returncode == 0, r.stderr
    j = [float(x) for x in re.findall(r"J\d=\s*(-?\d+\.\d+) deg", (tmp_path / "out.ls").read_text())]
    hand = q_model.copy()
    hand[2] = q_model[2] - q_model[1]
    assert len(j) == 6 and np.abs(np.array(j) - hand).max() < 2e-3  # the pose printed to 1e-4 mm / deg


# --- identified, simulated and diagnosed models reload (the axes of joints 2 and 3 are never exactly
# parallel on them; a 0.18 deg misalignment once refused every one). Truth: kincal simulate's kr500
# (seed 3: 1 mm / 0.05 deg errors drawn per axis, joint compliance), FANUC convention, 60 poses, the
# default noise; identified with the default effects and with --effects none, diagnosed (model.json),
# and the truth file itself. The pose program: the nominal kr500's poses at Q_PROG (a program written
# for the nominal robot). kr500's axes 2 and 3 are both +y: s = +1, J3 = q3 + q2 (by hand).

Q_PROG = np.array([[5.0, -80.0, 100.0, 10.0, 40.0, 15.0], [-20.0, -60.0, 80.0, -15.0, 50.0, 25.0],
                   [0.0, -70.0, 90.0, 0.0, 30.0, 0.0], [30.0, -95.0, 110.0, 20.0, -35.0, -40.0]])
MODELS = ("identified", "geometry_only", "truth", "diagnosed")


@pytest.fixture(scope="module")
def fanuc_files(tmp_path_factory):
    d = tmp_path_factory.mktemp("fanuc_reload")
    steps = [("simulate", "--robot", "kr500", "--joint-convention", "fanuc", "--poses", "60", "--seed", "3",
              "--out", str(d / "m.csv"), "--truth-out", str(d / "truth.json")),
             ("identify", "--robot", "kr500", "--joint-convention", "fanuc", "--data", str(d / "m.csv"), "--out",
              str(d / "identified.json")),
             ("identify", "--robot", "kr500", "--joint-convention", "fanuc", "--effects", "none", "--data",
              str(d / "m.csv"), "--out", str(d / "geometry_only.json")),
             ("diagnose", "--robot", "kr500", "--joint-convention", "fanuc", "--data", str(d / "m.csv"), "--out",
              str(d / "diag"))]
    for args in steps:
        r = run("kincal", *args)
        assert r.returncode == 0, r.stderr
    poses = kincal.fk(kincal.load_robot("kr500"), Q_PROG, calibrated=False)
    (d / "p.csv").write_text("x,y,z,a,b,c\n" + "".join(",".join(f"{v:.12f}" for v in p) + "\n" for p in poses))
    paths = {"identified": d / "identified.json", "geometry_only": d / "geometry_only.json",
             "truth": d / "truth.json", "diagnosed": d / "diag" / "model.json"}
    return d, paths, poses


def _axes_angle_deg(model_json: dict, part: str) -> float:
    z2, z3 = (np.asarray(model_json[part]["joints"][j]["axis"], dtype=float) for j in (1, 2))
    return float(np.degrees(np.arccos(min(1.0, abs(z2 @ z3) / np.linalg.norm(z2) / np.linalg.norm(z3)))))


def _q_csv(path: Path) -> np.ndarray:
    rows = list(csv.DictReader(io.StringIO(path.read_text())))
    return np.array([[float(r[f"q{j}"]) for j in range(1, 7)] for r in rows])


@pytest.mark.parametrize("which", MODELS)
def test_fanuc_model_reloads_and_compensates_to_its_poses(fanuc_files, which):
    d, paths, poses = fanuc_files
    path = paths[which]
    text = json.loads(path.read_text())
    assert text["joint_convention"] == "fanuc"
    assert _axes_angle_deg(text, "calibrated") > 0.01  # really not parallel: the case once refused
    m = kincal.load_robot(path)
    assert _core.joint_convention(m) == "fanuc"
    # the same model without the convention: the plain (model's own) joint angles
    plain_json = {k: v for k, v in text.items() if k != "joint_convention"}
    (d / f"{which}_plain.json").write_text(json.dumps(plain_json))
    plain_q = {}
    for tool in ("kincal", "kincal-compensate"):
        args = ["compensate"] if tool == "kincal" else []
        out = {}
        for name, model in (("fanuc", path), ("plain", d / f"{which}_plain.json")):
            out[name] = d / f"{which}_{name}_{tool}.csv"
            r = run(tool, *args, "--model", str(model), "--program", str(d / "p.csv"), "--out", str(out[name]))
            assert r.returncode == 0, r.stderr
        j, q = _q_csv(out["fanuc"]), _q_csv(out["plain"])
        plain_q[tool] = q
        # the controller's numbers differ from the model's by the coupling only: J3 = q3 + q2 (s = +1),
        # 10 decimals printed in each file
        assert np.abs(j[:, [0, 1, 3, 4, 5]] - q[:, [0, 1, 3, 4, 5]]).max() < 2e-10
        assert np.abs(j[:, 2] - (q[:, 2] + q[:, 1])).max() < 3e-10
        assert np.abs(j[:, 2] - q[:, 2]).min() > 50  # the coupling really acts (|q2| >= 60 deg here)
        assert np.abs(_core.joints_to_controller(m, q) - j).max() < 3e-10
        # back to the model's angles by hand, the reloaded (calibrated) model reaches the program's poses
        q_model = j.copy()
        q_model[:, 2] = j[:, 2] - j[:, 1]
        reached = kincal.fk(m, q_model)
        assert np.abs(reached[:, :3] - poses[:, :3]).max() < 1e-6
        assert np.abs((reached[:, 3:] - poses[:, 3:] + 180) % 360 - 180).max() < 1e-6  # deg, -180 = 180
        # kincal fk on the file reads the controller's numbers
        r = run("kincal", "fk", "--robot", str(path), "--joints", str(out["fanuc"]), "--out", str(d / f"{which}_fk.csv"))
        assert r.returncode == 0, r.stderr
        got = np.loadtxt(d / f"{which}_fk.csv", delimiter=",", skiprows=1)
        assert np.abs(got[:, :3] - poses[:, :3]).max() < 1e-6
    assert np.abs(plain_q["kincal"] - plain_q["kincal-compensate"]).max() < 2e-10
    # and validate reads it (the campaign's own measurements, in the controller's numbers)
    r = run("kincal", "validate", "--model", str(path), "--data", str(d / "m.csv"), "--out", str(d / f"{which}_V.json"))
    assert r.returncode == 0, r.stderr


def test_fanuc_model_with_axes_far_from_parallel_is_refused(fanuc_files, tmp_path):
    # joint 3's calibrated axis turned by 30 deg about x (normal to y): another arm, not a misalignment
    _, paths, _ = fanuc_files
    text = json.loads(paths["identified"].read_text())
    c, s = np.cos(np.radians(30)), np.sin(np.radians(30))
    x, y, z = text["calibrated"]["joints"][2]["axis"]
    text["calibrated"]["joints"][2]["axis"] = [x, c * y - s * z, s * y + c * z]
    angle = _axes_angle_deg(text, "calibrated")
    assert angle == pytest.approx(30, abs=0.5)
    bad = tmp_path / "bad.json"
    bad.write_text(json.dumps(text))
    with pytest.raises(Exception, match=rf"bad\.json.*axes of joints 2 and 3 are {angle:.1f} deg from parallel"):
        kincal.load_robot(bad)
    r = run("kincal-compensate", "--model", str(bad), "--program", str(paths["identified"].parent / "p.csv"), "--out",
            str(tmp_path / "x.csv"))
    assert r.returncode != 0 and "bad.json" in r.stderr and "deg from parallel" in r.stderr
    assert not (tmp_path / "x.csv").exists()
