"""Every JSON file kincal writes is strict JSON (interfaces.md, "Output files"): an undefined figure
is written as null, never NaN or Infinity, and the readers (kincal fk, compensate, kincal-compensate)
take such a file. Also the strict writer itself and the suite's checker (conftest.py)."""

from __future__ import annotations

import dataclasses
import json
import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import kincal
from kincal.calibration import identify as ident
from kincal.io import strict_json

from conftest import non_strict_json_files, run, strict_json_error


# --- the writer ----------------------------------------------------------------------------------

def test_non_finite_floats_anywhere_become_null():
    obj = {"a": [1.0, [np.nan, (np.float32("inf"), -math.inf)]], "b": np.array([[0.5, np.nan], [np.inf, 2.0]]),
           "c": {"d": np.float64("nan"), "e": np.int64(3), "f": np.bool_(True), "g": "NaN"}, "h": float("-inf")}
    text = strict_json.dumps(obj, sort_keys=True)
    assert json.loads(text) == {"a": [1.0, [None, [None, None]]], "b": [[0.5, None], [None, 2.0]],
                                "c": {"d": None, "e": 3, "f": True, "g": "NaN"}, "h": None}
    assert strict_json_error(text) is None
    # finite values keep every digit (repr round trip)
    assert json.loads(strict_json.dumps([0.1 + 0.2, np.float64(1e-300)])) == [0.1 + 0.2, 1e-300]


def test_allow_nan_is_really_off():
    class Hidden:  # a value the cleaning cannot see: json's default hook returns a NaN
        pass

    with pytest.raises(ValueError, match="Out of range float values are not JSON compliant"):
        strict_json.dumps({"x": Hidden()}, default=lambda o: math.nan)
    with pytest.raises(TypeError):  # no caller can turn NaN back on
        strict_json.dumps({"x": 1.0}, allow_nan=True)
    # and plain json.dumps would have written the bare words the readers refuse
    assert json.dumps({"x": math.inf}) == '{"x": Infinity}'
    assert strict_json.dumps({"x": math.inf}) == '{"x": null}'


# --- the checker of the suite (conftest.py) --------------------------------------------------------

@pytest.mark.parametrize("text", ['{"a": NaN}', '[1, Infinity]', '{"a": {"b": [-Infinity]}}', '{"a": 1'])
def test_checker_refuses_nan_infinity_and_broken_text(text):
    assert strict_json_error(text) is not None


def test_checker_accepts_null():
    assert strict_json_error('{"condition_number": null, "x": [1.5, null]}') is None


@pytest.mark.bad_json_input("deep/inside/bad.json")
def test_checker_names_the_file(tmp_path):
    (tmp_path / "deep" / "inside").mkdir(parents=True)
    (tmp_path / "deep" / "inside" / "bad.json").write_text('{"rms_mm": NaN}\n')
    (tmp_path / "deep" / "good.json").write_text('{"rms_mm": null}\n')
    bad = non_strict_json_files(tmp_path)
    assert len(bad) == 1 and bad[0].startswith(str(tmp_path / "deep" / "inside" / "bad.json") + ": NaN")
    assert non_strict_json_files(tmp_path, ["deep/*"]) == []


@pytest.mark.bad_json_input("inner/*")
def test_the_autouse_check_fails_a_test_that_leaves_nan(tmp_path):
    """The suite's autouse fixture, run on a test that writes NaN into its tmp_path: that test errors,
    naming the file; a test writing null passes."""
    here = Path(__file__).resolve().parent
    (tmp_path / "conftest.py").write_text((here / "conftest.py").read_text())
    (tmp_path / "test_inner.py").write_text(
        "def test_writes_nan(tmp_path):\n"
        "    (tmp_path / 'out').mkdir()\n"
        "    (tmp_path / 'out' / 'v.json').write_text('{\"rms_mm\": NaN}')\n\n"
        "def test_writes_null(tmp_path):\n"
        "    (tmp_path / 'v.json').write_text('{\"rms_mm\": null}')\n")
    r = subprocess.run([sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", "--rootdir", str(tmp_path),
                        "--basetemp", str(tmp_path / "inner"), str(tmp_path / "test_inner.py")],
                       capture_output=True, text=True, timeout=300, cwd=str(tmp_path))
    assert r.returncode == 1, r.stdout + r.stderr
    # pytest counts a test whose teardown fails as passed (its call) plus an error (its teardown)
    assert "2 passed, 1 error" in r.stdout, r.stdout
    assert "ERROR at teardown of test_writes_nan" in r.stdout and "of test_writes_null" not in r.stdout
    assert "out/v.json: NaN is not JSON" in r.stdout


# --- a model with undefined figures, written and read back -----------------------------------------

class _Fit:
    """The core's IdentifyResult with some figures replaced (its properties are read-only)."""

    def __init__(self, fit, **figures):
        self._fit, self._figures = fit, figures

    def __getattr__(self, name):
        return self._figures[name] if name in self._figures else getattr(self._fit, name)


@pytest.fixture(scope="module")
def undefined_figures(kr500, calibrated):
    """A real identification (geometry only; truth: the suite's calibrated kr500, 60 poses, 0.02 mm noise,
    seed 11) whose condition number is made infinite, observability index and a validation figure NaN."""
    res = ident.identify(kr500, ident.simulate(calibrated, 60, seed=11), effects="none", k_folds=0)
    assert math.isfinite(res.fit.condition_number)
    return dataclasses.replace(res, fit=_Fit(res.fit, condition_number=math.inf, observability_index=math.nan),
                               validation={**res.validation, "after_max_mm": math.nan})


def test_model_with_infinite_condition_number_is_strict(undefined_figures):
    text = undefined_figures.model_json()
    assert strict_json_error(text) is None
    assert "Infinity" not in text and "NaN" not in text
    d = json.loads(text)["identification"]
    assert d["condition_number"] is None and d["observability_index"] is None
    assert d["validation"]["after_max_mm"] is None
    assert d["fit"]["rms_mm"] == pytest.approx(undefined_figures.fit.rms_mm, rel=1e-15)  # the rest as it was


def test_fk_and_both_compensators_read_a_model_with_null_figures(tmp_path, undefined_figures):
    robot = undefined_figures.robot
    model = tmp_path / "model.json"
    model.write_text(undefined_figures.model_json())
    assert '"condition_number": null' in model.read_text()
    q = np.array([[10.0, -80.0, 95.0, 5.0, 30.0, -20.0], [-25.0, -70.0, 100.0, -10.0, 45.0, 60.0],
                  [40.0, -95.0, 110.0, 20.0, -35.0, 15.0]])
    (tmp_path / "q.csv").write_text("q1,q2,q3,q4,q5,q6\n" + "".join(",".join(f"{v:.10f}" for v in r) + "\n" for r in q))
    r = run("kincal", "fk", "--robot", str(model), "--joints", str(tmp_path / "q.csv"), "--out", str(tmp_path / "p.csv"))
    assert r.returncode == 0, r.stderr
    poses = np.loadtxt(tmp_path / "p.csv", delimiter=",", skiprows=1)
    assert np.allclose(poses, kincal.fk(robot, q), atol=1e-9)  # the model read is the one written
    for tool, cmd in (("kincal", ["compensate"]), ("kincal-compensate", [])):
        out = tmp_path / f"{tool}.csv"
        r = run(tool, *cmd, "--model", str(model), "--program", str(tmp_path / "p.csv"), "--out", str(out))
        assert r.returncode == 0, f"{tool}: {r.stderr}"
        back = np.loadtxt(out, delimiter=",", skiprows=1)
        # the compensated joints bring the identified robot onto the poses the same model gave
        assert np.abs(kincal.fk(robot, back)[:, :3] - poses[:, :3]).max() < 1e-6, tool


def test_model_reader_takes_null_for_an_unknown_axis_limit(kr500):
    doc = json.loads(kr500.to_json())
    j = doc["nominal"]["joints"][1]
    assert j["max_velocity_deg_s"] > 0
    j["max_velocity_deg_s"] = j["max_acceleration_deg_s2"] = j["max_jerk_deg_s3"] = None
    back = json.loads(kincal.Robot.from_json(json.dumps(doc), "m.json").to_json())["nominal"]["joints"][1]
    assert (back["max_velocity_deg_s"], back["max_acceleration_deg_s2"], back["max_jerk_deg_s3"]) == (0, 0, 0)  # unknown
    # a figure that must be known stays one: null there is refused, naming the field
    doc["nominal"]["joints"][1]["mass_kg"] = None
    with pytest.raises(ValueError, match=r"m.json: nominal.joints\[1\].mass_kg: not a number"):
        kincal.Robot.from_json(json.dumps(doc), "m.json")


def _one_joint_urdf(limit: str) -> str:
    return ('<robot name="one"><link name="a"/><link name="b"/>'
            '<joint name="j" type="revolute"><parent link="a"/><child link="b"/><origin xyz="0 0 0.5"/>'
            f'<axis xyz="0 0 1"/><limit {limit} effort="1"/></joint></robot>')


def test_urdf_with_an_infinite_figure(tmp_path):
    """A URDF may say velocity="inf" (no limit): the model text kincal makes of it is strict JSON and reads
    as an unknown limit; infinite joint limits are refused by name (before: "not valid JSON" of a text
    the user never saw)."""
    (tmp_path / "v.urdf").write_text(_one_joint_urdf('lower="-1" upper="1" velocity="inf"'))
    r = kincal.load_robot(tmp_path / "v.urdf")
    j = json.loads(r.to_json())["nominal"]["joints"][0]
    assert r.dof == 1 and j["max_velocity_deg_s"] == 0 and j["limits_deg"] == pytest.approx([-57.29577951308232,
                                                                                               57.29577951308232])
    (tmp_path / "l.urdf").write_text(_one_joint_urdf('lower="-inf" upper="inf" velocity="1"'))
    with pytest.raises(ValueError, match=r"l.urdf: nominal.joints\[0\].limits_deg: needs \[lower, upper\]"):
        kincal.load_robot(tmp_path / "l.urdf")
