"""Robot models: URDF chains, model JSON, FK against KDL, the Python API."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

import kincal
from kincal import _core

from conftest import random_q


def _urdf_of(robot: kincal.Robot) -> str:
    """A URDF of a kincal model (links in metres), written independently of kincal's reader."""
    spec = json.loads(robot.to_json())["nominal"]
    out = ['<robot name="copy">', '<link name="base"/>']
    prev = np.zeros(3)
    for i, j in enumerate(spec["joints"]):
        p = np.asarray(j["point_mm"]) / 1000.0
        lo, hi = (math.radians(v) for v in j["limits_deg"])
        out.append(f'<link name="l{i}"><inertial><mass value="{j["mass_kg"]}"/>'
                   f'<origin xyz="{" ".join(str(v) for v in (np.asarray(j["com_mm"]) / 1000.0 - p))}"/></inertial></link>')
        out.append(f'<joint name="j{i}" type="revolute"><parent link="{"base" if i == 0 else f"l{i - 1}"}"/>'
                   f'<child link="l{i}"/><origin xyz="{" ".join(str(v) for v in p - prev)}" rpy="0 0 0"/>'
                   f'<axis xyz="{" ".join(str(v) for v in j["axis"])}"/>'
                   f'<limit lower="{lo}" upper="{hi}" velocity="1" effort="1"/></joint>')
        prev = p
    t = spec["tool"]
    a, b, c = (math.radians(v) for v in t["abc_deg"])
    out.append('<link name="tool"/>')
    out.append(f'<joint name="tool" type="fixed"><parent link="l5"/><child link="tool"/>'
               f'<origin xyz="{" ".join(str(v) for v in np.asarray(t["xyz_mm"]) / 1000.0 - prev)}" rpy="{c} {b} {a}"/></joint>')
    out.append("</robot>")
    return "\n".join(out)


def test_urdf_chain_has_the_same_kinematics(tmp_path, kr500):
    path = tmp_path / "copy.urdf"
    path.write_text(_urdf_of(kr500))
    r = kincal.load_robot(path)
    assert r.dof == 6 and r.closed_form_ik
    q = random_q(kr500, np.random.default_rng(5), 200)
    a, b = kincal.fk(r, q), kincal.fk(kr500, q)
    assert np.abs(a[:, :3] - b[:, :3]).max() < 1e-9
    for qi in q[:50]:
        assert np.abs(_core.fk_matrix(r, qi) - _core.kdl_fk(r, qi)).max() < 1e-9
    tau_u, _ = _core.gravity_torque(r, q[0])
    spec = json.loads(kr500.to_json())["nominal"]
    assert abs(sum(j["mass_kg"] for j in spec["joints"]) - sum(j["mass_kg"] for j in json.loads(r.to_json())["nominal"]["joints"])) < 1e-9
    assert np.all(np.isfinite(tau_u))


def test_urdf_that_is_not_a_serial_revolute_chain(tmp_path):
    bad = tmp_path / "slider.urdf"
    bad.write_text('<robot name="s"><link name="a"/><link name="b"/>'
                   '<joint name="p" type="prismatic"><parent link="a"/><child link="b"/><axis xyz="1 0 0"/></joint></robot>')
    with pytest.raises(ValueError, match="slider.urdf: joint 'p': type 'prismatic' is not supported"):
        kincal.load_robot(bad)
    (tmp_path / "broken.urdf").write_text("<robot>\n<link name='a'>\n</robot>")
    with pytest.raises(ValueError, match=r"broken.urdf:3:\d+: not valid XML"):
        kincal.load_robot(tmp_path / "broken.urdf")


def test_model_json_round_trip_and_version(tmp_path, calibrated):
    text = calibrated.to_json()
    assert json.loads(text)["format"] == "kincal-model"
    assert kincal.Robot.from_json(text).to_json() == text
    doc = json.loads(text)
    doc["version"] = 4
    with pytest.raises(ValueError, match="model version 4 is not supported"):
        kincal.Robot.from_json(json.dumps(doc), "future.json")


def test_api_errors_are_value_errors(kr500):
    with pytest.raises(ValueError, match="3 columns, the robot has 6 joints"):
        kincal.fk(kr500, [[0, 0, 0]])
    with pytest.raises(ValueError, match="NaN"):
        kincal.fk(kr500, [[0, 0, float("nan"), 0, 0, 0]])
    for f in (_core.gravity_torque, _core.kdl_fk, _core.jacobian):  # no out-of-bounds read on a short vector
        with pytest.raises(ValueError, match="4 columns, the robot has 6 joints"):
            f(kr500, np.zeros(4))
    with pytest.raises(ValueError, match="pose 1: pose out of reach"):
        kincal.compensate(kr500, [[2000, 0, 500, 180, 0, 180], [9000, 0, 500, 180, 0, 180]])


def test_jacobian_matches_finite_differences(calibrated):
    q = np.array([15.0, -70.0, 100.0, 20.0, 35.0, -40.0])
    j = kincal.jacobian(calibrated, q)
    h = 1e-6
    for k in range(6):
        dq = np.zeros(6)
        dq[k] = math.degrees(h)
        tp, tm = _core.fk_matrix(calibrated, q + dq), _core.fk_matrix(calibrated, q - dq)
        assert np.abs((tp[:3, 3] - tm[:3, 3]) / (2 * h) - j[:3, k]).max() < 1e-4


def test_python_abc_helpers_are_exact_at_the_pole():
    """The tool frame placed by --tool-targets (the core's rotation_to_abc) and the URDF writer take ABC
    angles from the core: at b = 90 - 1e-10 deg with every entry rounded by 2e-15 (as a kinematic chain
    leaves it) the angles give back the rotation within 1e-5 deg (a Python copy without the pole's
    branch was 177 deg off)."""
    import numpy as np

    from kincal import _core
    from kincal.io import urdf

    rng = np.random.default_rng(3)
    for _ in range(20):
        r = _core.abc_to_rotation(np.array([rng.uniform(-179, 179), 90 - 1e-10, rng.uniform(-179, 179)]))
        r = r + rng.uniform(-2e-15, 2e-15, (3, 3))
        for abc in (_core.rotation_to_abc(r), urdf._abc(r)):
            back = _core.abc_to_rotation(np.array(abc))
            angle = np.degrees(np.arccos(np.clip((np.trace(r.T @ back) - 1) / 2, -1, 1)))
            assert angle < 1e-5, abc
