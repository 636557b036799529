"""Effects in identification: the --effects grammar (every form, every error), the typed parameter
layout, a model written by `kincal identify --effects` carrying the identified effects, and version 1
model files still reading. Truths and noise are stated in each test."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

import kincal
from kincal import _core
from kincal.calibration import identify as ident

from conftest import run

E = _core.Effect


@pytest.fixture(scope="module")
def kr500():
    return kincal.load_robot("kr500")


@pytest.mark.parametrize("text,harmonics,want", [
    # compliance without a joint: the gravity-loaded joints only (kr500: joint 1's axis is vertical)
    ("joint_compliance", (1, 2), [E("joint_compliance", j) for j in (2, 3, 4, 5, 6)]),
    ("joint_compliance:2", (1, 2), [E("joint_compliance", 2)]),
    ("transmission_error:3", (1, 2), [E("transmission_error", 3, [1, 2])]),
    ("transmission_error:3", (1, 2, 3), [E("transmission_error", 3, [1, 2, 3])]),
    ("backlash:2", (1, 2), [E("backlash", 2)]),
    ("backlash", (1, 2), [E("backlash", j) for j in range(1, 7)]),
    ("thermal_expansion", (1, 2), [E("thermal_expansion")]),
    (" transmission_error:3 , backlash:2,thermal_expansion", (1, 2),
     [E("transmission_error", 3), E("backlash", 2), E("thermal_expansion")]),
    ("backlash:2,backlash:2", (1, 2), [E("backlash", 2)]),
    ("none", (1, 2), []),
    ("", (1, 2), []),
])
def test_effects_grammar(kr500, text, harmonics, want):
    got = ident.parse_effects(text, kr500, harmonics)
    assert got == want
    assert [e.size for e in got] == [w.size for w in want]
    if text == "transmission_error:3" and harmonics == (1, 2, 3):
        assert got[0].size == 6 and got[0].parameter_names[-2:] == ["te_sin3", "te_cos3"]


def test_compliance_joints_come_from_the_robot(kr500, tmp_path):
    """A URDF robot whose joints 2 and 3 carry gravity (the kr500 geometry and link masses, no head):
    joint_compliance means the joints the layout marks as loaded, and those only."""
    from kincal.io.urdf import spec_urdf

    (tmp_path / "r.urdf").write_text(spec_urdf(json.loads(kr500.to_json())["nominal"], "urdf_robot"))
    robot = kincal.load_robot(str(tmp_path / "r.urdf"))
    loaded = _core.PointModel(robot, 1).layout.loaded
    assert 2 in loaded and 1 not in loaded
    assert [e.joint for e in ident.parse_effects("joint_compliance", robot)] == loaded


MEAS = ("pose,q1,q2,q3,q4,q5,q6,x,y,z\n"
        + "".join(f"{i},{i},-90,{90 + i},0,{5 + i},0,{1 + i},2,3\n" for i in range(40)))


@pytest.mark.parametrize("effects,message", [
    ("magic", ["'magic'", "known: joint_compliance, transmission_error, backlash, thermal_expansion"]),
    ("backlash:2,magic:1", ["'magic:1'", "known:"]),
    ("transmission_error:7", ["'transmission_error:7'", "joint 7 is not one of 1..6"]),
    ("backlash:0", ["'backlash:0'", "joint 0 is not one of 1..6"]),
    ("backlash:x", ["'backlash:x'", "1..6"]),
    ("link_deflection", ["'link_deflection'", "not to a serial robot"]),
    ("link_deflection:2", ["'link_deflection:2'", "not to a serial robot"]),
    ("thermal_expansion:2", ["'thermal_expansion:2'", "whole robot"]),
    ("joint_compliance:1", ["'joint_compliance:1'", "gravity does not load joint 1"]),
    ("backlash:2", ["m.csv", "dir1..dir6"]),
    ("thermal_expansion", ["m.csv", "temperature_c"]),
])
def test_effects_errors(tmp_path, effects, message):
    """Every bad --effects item is named with the cause (and the known names from the registry); an
    effect whose data column is missing names the file and the column; exit 1, no output file."""
    (tmp_path / "m.csv").write_text(MEAS)
    out = tmp_path / "model.json"
    r = run("kincal", "identify", "--robot", "kr500", "--data", str(tmp_path / "m.csv"), "--out", str(out),
            "--effects", effects)
    assert r.returncode == 1, r.stderr
    assert "kincal identify: error:" in r.stderr
    for m in message:
        assert m in r.stderr, r.stderr
    assert not out.exists()


def test_diagnose_effects_errors(tmp_path):
    (tmp_path / "m.csv").write_text(MEAS)
    r = run("kincal", "diagnose", "--robot", "kr500", "--data", str(tmp_path / "m.csv"), "--out", str(tmp_path / "d"),
            "--effects", "backlash:3")
    assert r.returncode == 1 and "m.csv" in r.stderr and "dir1..dir6" in r.stderr
    assert not (tmp_path / "d" / "model.json").exists()


def test_hide_takes_its_value_count_from_the_registry(tmp_path):
    """--hide transmission_error:J takes a sine and a cosine amplitude per order of --harmonics."""
    out = tmp_path / "m.csv"
    base = ["kincal", "simulate", "--robot", "kr500", "--poses", "5", "--out", str(out)]
    r = run(*base, "--hide", "transmission_error:2:0.01,0,0,0.01")
    assert r.returncode == 0, r.stderr
    r = run(*base, "--hide", "transmission_error:2:0.01,0,0,0.01", "--harmonics", "1,2,3")
    assert r.returncode == 1 and "takes 6 finite value(s)" in r.stderr and "te_cos3" in r.stderr
    r = run(*base, "--hide", "transmission_error:2:0.01,0,0,0.01,0.005,0", "--harmonics", "1,2,3")
    assert r.returncode == 0, r.stderr
    r = run(*base, "--hide", "backlash:2:0.01,0.02")
    assert r.returncode == 1 and "takes 1 finite value(s)" in r.stderr


def test_layout_kinds_and_joints(kr500):
    """The layout describes every parameter by kind, joint (from 1), target (from 0) and unit, in
    the order of the vector; the offsets bound the kinds."""
    eff = [E("transmission_error", 4, [1, 3]), E("backlash", 2), E("thermal_expansion")]
    L = _core.PointModel(kr500, 2, eff).layout
    ps = L.parameters
    assert len(ps) == L.size == len(L) == 4 * 6 + 5 + 6 + 6 + 3 * 2 + 4 + 1 + 1
    assert [p.index for p in ps] == list(range(L.size))
    kinds = [p.kind for p in ps]
    assert kinds == (["joint_geometry"] * 24 + ["compliance"] * 5 + ["tool"] * 6 + ["base"] * 6 + ["target"] * 6
                     + ["transmission_error"] * 4 + ["backlash", "thermal_expansion"])
    assert [p.joint for p in ps[:24]] == [j for j in range(1, 7) for _ in range(4)]
    assert [p.joint for p in ps[24:29]] == L.loaded == [2, 3, 4, 5, 6]
    assert all(p.joint == 0 and p.target == -1 for p in ps[29:41])
    assert [p.target for p in ps[41:47]] == [0, 0, 0, 1, 1, 1]
    assert [p.joint for p in ps[47:]] == [4, 4, 4, 4, 2, 0]
    assert [p.effect for p in ps[47:]] == [eff[0]] * 4 + [eff[1], eff[2]]
    assert all(p.effect is None for p in ps[:47])
    assert [p.unit for p in ps[47:]] == ["rad"] * 5 + ["1/degC"]
    assert (L.joints, L.compliance, L.tool, L.base, L.targets, L.effects) == (0, 24, 29, 35, 41, 47)
    assert L.effect_offset == [47, 51, 52] and L.effect_list == eff
    assert L.indices("compliance", 3) == [25]
    assert L.indices("backlash") == [51]
    assert L.indices("joint_geometry", 6) == [20, 21, 22, 23]


@pytest.fixture(scope="module")
def te_backlash_campaign(tmp_path_factory, kr500):
    """truth: kr500 with 1 mm / 0.05 deg geometric errors (seed 4), no compliance, a transmission
    error on joint 2 (0.02 deg sin q2, 0.01 deg cos 2q2) and a backlash of 0.015 deg on joint 3;
    200 poses x 3 reflectors, 0.02 mm noise per coordinate."""
    d = tmp_path_factory.mktemp("te_backlash")
    truth = kr500.with_calibrated(4, 1.0, 0.05, 0.0, ident.DEFAULT_INSTRUMENT)
    hidden = [(E("transmission_error", 2), [math.radians(v) for v in (0.02, 0.0, 0.0, 0.01)]),
              (E("backlash", 3), [math.radians(0.015)])]
    data = ident.simulate(truth, 200, seed=3, noise_mm=0.02, targets=3, effects=hidden)
    (d / "m.csv").write_text(ident.measurements_csv(data, 6))
    return d, hidden


def test_identify_writes_the_effects(te_backlash_campaign):
    """The model written by identify --effects transmission_error:2,backlash:3 loads with
    kincal.load_robot and carries both effects, each value within 0.004 deg of the truth's (the
    transmission error's amplitudes are 0.02 and 0.01 deg, its first harmonic shares its pattern in
    part with joint 2's geometry), and reaches the noise on held-out poses."""
    d, hidden = te_backlash_campaign
    r = run("kincal", "identify", "--robot", "kr500", "--data", str(d / "m.csv"), "--out", str(d / "model.json"),
            "--effects", "transmission_error:2,backlash:3")
    assert r.returncode == 0, r.stderr
    assert "transmission_error(joint 2), backlash(joint 3)" in r.stdout
    robot = kincal.load_robot(str(d / "model.json"))
    assert [e.label for e, _ in robot.effects] == [e.label for e, _ in hidden]
    for (e, got), (_, truth) in zip(robot.effects, hidden):
        assert np.max(np.abs(np.degrees(np.asarray(got) - truth))) < 0.004, (e, np.degrees(got))
    doc = json.loads((d / "model.json").read_text())
    assert doc["identification"]["effects"] == ["transmission_error(joint 2)", "backlash(joint 3)"]
    kinds = {(p["kind"], p["joint"]) for p in doc["identification"]["parameters"]}
    assert ("transmission_error", 2) in kinds and ("backlash", 3) in kinds
    assert doc["identification"]["validation"]["after_rms_mm"] < 1.2 * 0.02 * math.sqrt(3)
    # without the effects the same data stay far from the noise
    r = run("kincal", "identify", "--robot", "kr500", "--data", str(d / "m.csv"), "--out", str(d / "geo.json"),
            "--effects", "none")
    assert r.returncode == 0, r.stderr
    assert json.loads((d / "geo.json").read_text())["identification"]["validation"]["after_rms_mm"] > 0.1


def test_typed_result(te_backlash_campaign, kr500):
    """_core.identify takes IdentifyOptions and returns an IdentifyResult whose robot carries the
    effects asked for, whose layout describes x, and whose joint_compliance entries switch the
    compliance of their joints (the others held as not in the model)."""
    d, hidden = te_backlash_campaign
    data = ident.read_measurements(str(d / "m.csv"), kr500)
    opts = _core.IdentifyOptions(effects=[E("joint_compliance", 3)] + [e for e, _ in hidden], covariance=False)
    res = _core.identify(kr500, data, opts)
    assert isinstance(res, _core.IdentifyResult)
    assert [e for e, _ in res.effects] == [e for e, _ in hidden]
    assert [e for e, _ in res.robot.effects] == [e for e, _ in hidden]
    assert len(res.x) == len(res.fixed) == len(res.stddev) == res.layout.size
    comp = {p.joint: bool(res.fixed[p.index]) for p in res.layout.parameters if p.kind == "compliance"}
    assert comp == {2: True, 3: False, 4: True, 5: True, 6: True}
    assert res.targets.shape == (3, 3) and res.rms_mm < 0.04
    # the dict access of earlier versions still answers
    assert res["rms_mm"] == res.rms_mm and res["names"] == res.layout.names


def test_version_1_model_json_still_loads(kr500):
    """A model file of version 1 (no effects, no t_ref_c; the instrument's placement inside each
    model's section) reads, and its FK (in the instrument's frame too) is the version 3 file's."""
    robot = kr500.with_calibrated(2, 1.0, 0.05, 0.003, ident.DEFAULT_INSTRUMENT)
    doc = json.loads(robot.to_json())
    assert doc["version"] == 3
    doc["version"] = 1
    placement = doc.pop("campaign")["base_in_instrument"]
    for part in ("nominal", "calibrated"):
        if isinstance(doc.get(part), dict):
            doc[part].pop("effects", None)
            doc[part].pop("t_ref_c", None)
            doc[part]["base_in_instrument"] = placement
    old = _core.Robot.from_json(json.dumps(doc), "v1.json")
    assert old.effects == [] and old.identified
    q = np.random.default_rng(1).uniform(-60, 60, (50, 6))
    assert np.max(np.abs(kincal.fk(old, q, frame="instrument") - kincal.fk(robot, q, frame="instrument"))) < 1e-9
