"""Where a model's periodic effects are extrapolated: the joint ranges a fit saw (model.json's
campaign.fitted_joint_ranges_deg), `kincal validate`'s warning when new data leave them, and the
warning of `kincal compensate` and `kincal-compensate` when a program does.

Truth of the end-to-end case: kr500 with 1 mm / 0.05 deg geometric errors and 0.003 deg/kN m joint
compliance (seed 3), a transmission error on joint 2 (0.02 deg sin q2 + 0.01 deg cos 2 q2), 3
reflectors, 0.02 mm noise per coordinate; the model is fitted on the rows with q2 below its median and
validated on those above it, then on rows of its own range; a program of 40 poses is compensated on
it, joint 2 swept over both halves, and streamed out and back again."""

from __future__ import annotations

import json

import numpy as np
import pytest

import kincal
from kincal import _core
from kincal.calibration import identify as ident

from conftest import run


@pytest.mark.parametrize("angles,expect", [
    (np.linspace(-180.0, -45.0, 50), [-180.0, -45.0]),            # UR10 series B's joint 1
    (np.linspace(-308.0, -180.0, 50), [52.0, 180.0]),             # series C's: the same turn, modulo 360
    (np.r_[np.linspace(170.0, 180.0, 5), np.linspace(-180.0, -170.0, 5)], [170.0, 190.0]),  # across +-180
    (np.linspace(-360.0, 360.0, 200), [-180.0, 180.0]),           # the whole turn, no gap over 10 deg
    (np.array([30.0]), [30.0, 30.0]),
])
def test_joint_ranges_are_the_circle_less_its_widest_gap(angles, expect):
    assert np.allclose(_core.joint_ranges(angles[:, None])[0], expect)


def test_outside_counts_turns_and_the_margin():
    lo, hi = -180.0, -45.0
    q = np.array([-180.5, -44.5, -43.0, -181.5, 180.0, 52.0, 315.0, -405.0, 0.0])
    # inside (within 1 deg), inside, outside, outside, inside (= -180), outside, inside (= -45),
    # inside (= -45), outside
    assert _core.outside_range(q, [lo, hi]) == [False, False, True, True, False, True, False, False, True]
    assert not any(_core.outside_range(q, [-180.0, 180.0]))


@pytest.fixture(scope="module")
def half_fit(tmp_path_factory):
    """The model fitted on the rows with q2 below its median (identify, geometry + the transmission
    error of joint 2): (folder, the simulated rows, the fitted rows' mask)."""
    tmp = tmp_path_factory.mktemp("coverage")
    robot = kincal.load_robot("kr500")
    truth = robot.with_calibrated(3, 1.0, 0.05, 0.003, ident.DEFAULT_INSTRUMENT)
    hidden = [("transmission_error", 2, [np.radians(0.02), 0.0, 0.0, np.radians(0.01)])]
    data = ident.simulate(truth, 300, seed=5, targets=3, effects=hidden)
    low = data["q_deg"][:, 1] < np.median(data["q_deg"][:, 1])
    for name, mask in (("fit", low), ("high", ~low)):
        (tmp / f"{name}.csv").write_text(ident.measurements_csv(ident.subset(data, mask), 6))
    r = run("kincal", "identify", "--robot", "kr500", "--data", str(tmp / "fit.csv"), "--out",
            str(tmp / "model.json"), "--effects", "transmission_error:2", "--folds", "0")
    assert r.returncode == 0, r.stderr
    q2 = data["q_deg"][low, 1]  # the summary says where the transmission error was fitted
    assert f"known over the fitted angles (validate and compensate warn beyond them): joint 2 " \
           f"{q2.min():.0f}..{q2.max():.0f} deg" in r.stdout, r.stdout
    return tmp, data, low


def test_validate_warns_where_a_periodic_effect_is_extrapolated(half_fit):
    tmp_path, data, low = half_fit
    ranges = json.loads((tmp_path / "model.json").read_text())["campaign"]["fitted_joint_ranges_deg"]
    fit_q = data["q_deg"][low]
    assert len(ranges) == 6
    assert np.allclose(ranges[1], [fit_q[:, 1].min(), fit_q[:, 1].max()])
    # the other half of joint 2's range: every row outside, named in the JSON and on stdout
    r = run("kincal", "validate", "--model", str(tmp_path / "model.json"), "--data", str(tmp_path / "high.csv"),
            "--out", str(tmp_path / "v.json"))
    assert r.returncode == 0, r.stderr
    ext = json.loads((tmp_path / "v.json").read_text())["extrapolated"]
    assert [e["joint"] for e in ext] == [2] and ext[0]["effects"] == "transmission_error(joint 2)"
    n_high = int((~low).sum())  # rows (a pose per reflector); those within 1 deg of the median are inside
    assert ext[0]["rows_outside"] > 0.95 * n_high
    assert "warning: joint 2 is outside" in r.stdout and "transmission_error(joint 2)" in r.stdout
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


@pytest.mark.parametrize("tool", ["kincal", "kincal-compensate"])
def test_compensate_warns_where_a_program_leaves_the_fitted_range(half_fit, tool):
    """40 poses (base frame) whose joint 2 sweeps from inside the fitted range to 20 deg beyond it:
    the warning names joint 2, its effect, the line of the first pose outside and how many are; the
    program's first half alone draws no warning."""
    tmp_path, data, low = half_fit
    model = kincal.load_robot(str(tmp_path / "model.json"))
    lo, hi = model.fitted_ranges_deg[1]
    q = np.tile(model.home_deg, (40, 1))  # the branch the first pose takes: the one nearest home
    q[:, 1] = np.linspace(hi - 20.0, hi + 20.0, 40)
    poses = kincal.fk(model, q)
    header = "x,y,z,a,b,c\n"
    rows = "".join(",".join(repr(float(v)) for v in p) + "\n" for p in poses)
    (tmp_path / "sweep.csv").write_text(header + rows)
    (tmp_path / "inside.csv").write_text(header + "".join(rows.splitlines(keepends=True)[:15]))
    cmd = ["kincal", "compensate"] if tool == "kincal" else ["kincal-compensate"]
    r = run(*cmd, "--model", str(tmp_path / "model.json"), "--program", str(tmp_path / "sweep.csv"),
            "--out", str(tmp_path / f"{tool}.csv"))
    assert r.returncode == 0, r.stderr
    got = np.loadtxt(tmp_path / f"{tool}.csv", delimiter=",", skiprows=1)
    out = got[:, 1] > hi + 1.0  # the sweep goes up from inside the range: outside is above it by the margin
    assert 15 <= out.sum() <= 25  # the half beyond the range, within its 1 deg margin
    first_line = int(np.argmax(out)) + 2  # the header is line 1
    line = next(x for x in r.stderr.splitlines() if "is outside" in x)
    assert f"sweep.csv:{first_line}: joint 2 is outside" in line and "transmission_error(joint 2)" in line
    assert f"at {int(out.sum())} of 40 poses compensated" in line
    r = run(*cmd, "--model", str(tmp_path / "model.json"), "--program", str(tmp_path / "inside.csv"),
            "--out", str(tmp_path / f"{tool}-inside.csv"))
    assert r.returncode == 0 and "is outside" not in r.stderr, r.stderr


def test_stream_warns_each_time_a_joint_leaves_the_fitted_range(half_fit):
    """kincal-compensate --stream: the 40-pose sweep beyond the range, then back, then beyond again
    (120 lines after the header): a warning on the line where joint 2 leaves the range, each time it
    leaves (twice), and none while it stays out or comes back."""
    tmp_path, data, low = half_fit
    model = kincal.load_robot(str(tmp_path / "model.json"))
    lo, hi = model.fitted_ranges_deg[1]
    q = np.tile(model.home_deg, (120, 1))
    sweep = np.linspace(hi - 20.0, hi + 20.0, 40)
    q[:, 1] = np.r_[sweep, sweep[::-1], sweep]
    poses = kincal.fk(model, q)
    lines = "x,y,z,a,b,c\n" + "".join(",".join(repr(float(v)) for v in p) + "\n" for p in poses)
    r = run("kincal-compensate", "--model", str(tmp_path / "model.json"), "--stream", stdin=lines)
    assert r.returncode == 0, r.stderr
    got = np.loadtxt(r.stdout.splitlines()[1:], delimiter=",")
    out = got[:, 1] > hi + 1.0  # outside: above the range by more than the margin
    leaves = [i + 2 for i in range(120) if out[i] and (i == 0 or not out[i - 1])]  # input lines (header: 1)
    assert len(leaves) == 2
    warned = [w for w in r.stderr.splitlines() if "is outside" in w]
    assert [w.split(":")[3] for w in warned] == [str(n) for n in leaves], r.stderr  # "...: stdin:N: ..."
    assert all(w.startswith("kincal-compensate: warning: stdin:") and "transmission_error(joint 2)" in w
               and "extrapolated from here" in w for w in warned)
