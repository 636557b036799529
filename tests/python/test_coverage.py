"""Where a model's periodic effects are extrapolated: the joint ranges a fit saw (model.json's
identification.joint_ranges_deg) and `kincal validate`'s warning when new data leave them.

Truth of the end-to-end case: kr500 with 1 mm / 0.05 deg geometric errors and 0.003 deg/kN m joint
compliance (seed 3), a transmission error on joint 2 (0.02 deg sin q2 + 0.01 deg cos 2 q2), 3
reflectors, 0.02 mm noise per coordinate; the model is fitted on the rows with q2 below its median and
validated on those above it, then on rows of its own range."""

from __future__ import annotations

import json

import numpy as np
import pytest

import kincal
from kincal import coverage
from kincal import identify as ident

from conftest import run


@pytest.mark.parametrize("angles,expect", [
    (np.linspace(-180.0, -45.0, 50), [-180.0, -45.0]),            # UR10 series B's joint 1
    (np.linspace(-308.0, -180.0, 50), [52.0, 180.0]),             # series C's: the same turn, modulo 360
    (np.r_[np.linspace(170.0, 180.0, 5), np.linspace(-180.0, -170.0, 5)], [170.0, 190.0]),  # across +-180
    (np.linspace(-360.0, 360.0, 200), [-180.0, 180.0]),           # the whole turn, no gap over 10 deg
    (np.array([30.0]), [30.0, 30.0]),
])
def test_joint_ranges_are_the_circle_less_its_widest_gap(angles, expect):
    assert np.allclose(coverage.joint_ranges(angles[:, None])[0], expect)


def test_outside_counts_turns_and_the_margin():
    lo, hi = -180.0, -45.0
    q = np.array([-180.5, -44.5, -43.0, -181.5, 180.0, 52.0, 315.0, -405.0, 0.0])
    # inside (within 1 deg), inside, outside, outside, inside (= -180), outside, inside (= -45),
    # inside (= -45), outside
    assert coverage.outside(q, lo, hi).tolist() == [False, False, True, True, False, True, False, False, True]
    assert not coverage.outside(q, -180.0, 180.0).any()


def test_validate_warns_where_a_periodic_effect_is_extrapolated(tmp_path):
    robot = kincal.load_robot("kr500")
    truth = robot.with_calibrated(3, 1.0, 0.05, 0.003, ident.DEFAULT_INSTRUMENT)
    hidden = [("transmission_error", 2, [np.radians(0.02), 0.0, 0.0, np.radians(0.01)])]
    data = ident.simulate(truth, 300, seed=5, targets=3, effects=hidden)
    q2 = data["q_deg"][:, 1]
    low = q2 < np.median(q2)
    for name, mask in (("fit", low), ("high", ~low)):
        (tmp_path / f"{name}.csv").write_text(ident.measurements_csv(ident.subset(data, mask), 6))
    r = run("kincal", "identify", "--robot", "kr500", "--data", str(tmp_path / "fit.csv"), "--out",
            str(tmp_path / "model.json"), "--effects", "transmission_error:2", "--folds", "0")
    assert r.returncode == 0, r.stderr
    ranges = json.loads((tmp_path / "model.json").read_text())["identification"]["joint_ranges_deg"]
    fit_q = data["q_deg"][low]
    assert len(ranges) == 6
    assert np.allclose(ranges[1], [fit_q[:, 1].min(), fit_q[:, 1].max()])
    # the other half of joint 2's range: every row outside, named in the JSON and on stdout
    r = run("kincal", "validate", "--model", str(tmp_path / "model.json"), "--data", str(tmp_path / "high.csv"),
            "--out", str(tmp_path / "v.json"))
    assert r.returncode == 0, r.stderr
    ext = json.loads((tmp_path / "v.json").read_text())["extrapolated"]
    assert [e["joint"] for e in ext] == [2] and ext[0]["effects"] == ["transmission_error(joint 2)"]
    n_high = int((~low).sum())  # rows (a pose per reflector); those within 1 deg of the median are inside
    assert ext[0]["rows_outside"] > 0.95 * n_high
    assert "joint 2 outside" in r.stdout and "transmission_error(joint 2)" in r.stdout
    # rows of the fitted range: nothing to say
    r = run("kincal", "validate", "--model", str(tmp_path / "model.json"), "--data", str(tmp_path / "fit.csv"),
            "--out", str(tmp_path / "v2.json"))
    assert r.returncode == 0, r.stderr
    assert json.loads((tmp_path / "v2.json").read_text())["extrapolated"] == [] and "warning" not in r.stdout
    # a built-in robot has no fitted ranges, so nothing is claimed
    r = run("kincal", "validate", "--model", "kr500", "--data", str(tmp_path / "high.csv"), "--out",
            str(tmp_path / "v3.json"))
    assert r.returncode == 0, r.stderr
    assert json.loads((tmp_path / "v3.json").read_text())["extrapolated"] == []
