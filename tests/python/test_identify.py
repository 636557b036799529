"""Identification through the command line and the Python API (simulated kr500 campaigns; the
truth of each test is stated in it). The C++ tests check the Jacobian, completeness and robustness."""

from __future__ import annotations

import json

import numpy as np
import pytest

import kincal
from kincal import _core
from kincal.calibration import plan
from kincal.calibration import identify as ident

from conftest import random_q, run

NOISE = 0.02
FLOOR = NOISE * np.sqrt(3.0)  # RMS distance of a point with 0.02 mm Gaussian noise per coordinate


@pytest.fixture(scope="module")
def campaign(tmp_path_factory):
    """truth: kr500 with 1 mm / 0.05 deg geometric errors and ~0.003 deg/kNm joint compliance (seed 5),
    seen from a tracker at DEFAULT_INSTRUMENT; 200 poses x 3 reflectors, 0.02 mm noise."""
    d = tmp_path_factory.mktemp("campaign")
    r = run("kincal", "simulate", "--robot", "kr500", "--poses", "200", "--seed", "5", "--out", str(d / "m.csv"),
            "--truth-out", str(d / "truth.json"))
    assert r.returncode == 0, r.stderr
    return d


def test_identify_reaches_noise_floor_with_compliance(campaign):
    r = run("kincal", "identify", "--robot", "kr500", "--data", str(campaign / "m.csv"), "--out", str(campaign / "cal.json"))
    assert r.returncode == 0, r.stderr
    model = json.loads((campaign / "cal.json").read_text())
    assert model["format"] == "kincal-model"
    v = model["identification"]["validation"]
    assert v["before_rms_mm"] > 1.0
    assert v["after_rms_mm"] <= 1.2 * FLOOR
    assert "held-out poses" in r.stdout and "condition number" in r.stdout
    # the redundant parameters are named in the summary
    assert "tool.rx" in r.stdout and "not identifiable" in r.stdout


def test_identify_without_compliance_shows_the_gap(campaign):
    r = run("kincal", "identify", "--robot", "kr500", "--data", str(campaign / "m.csv"), "--out", str(campaign / "geo.json"),
            "--effects", "none")
    assert r.returncode == 0, r.stderr
    v = json.loads((campaign / "geo.json").read_text())["identification"]["validation"]
    assert v["after_rms_mm"] > 1.5 * FLOOR


def test_kfold_validation(campaign):
    r = run("kincal", "identify", "--robot", "kr500", "--data", str(campaign / "m.csv"), "--out", str(campaign / "kf.json"),
            "--folds", "4")
    assert r.returncode == 0, r.stderr
    v = json.loads((campaign / "kf.json").read_text())["identification"]["validation"]
    assert v["scheme"] == "4-fold, whole configurations" and v["held_rows"] == 600 and v["fit_rows"] == 600
    # the campaign has no config column: 200 distinct configurations of 3 reflectors each
    assert v["configurations"] == 200 and "equal joint angles" in v["grouping"]
    assert v["after_rms_mm"] <= 1.2 * FLOOR


def test_fk_in_instrument_frame_predicts_the_measurements(campaign):
    """fk --frame instrument with pose/target columns gives the targets' points where the tracker saw them."""
    r = run("kincal", "identify", "--robot", "kr500", "--data", str(campaign / "m.csv"), "--out", str(campaign / "cal2.json"))
    assert r.returncode == 0, r.stderr
    r = run("kincal", "fk", "--robot", str(campaign / "cal2.json"), "--joints", str(campaign / "m.csv"), "--frame", "instrument",
            "--out", str(campaign / "pred.csv"))
    assert r.returncode == 0, r.stderr
    pred = np.genfromtxt(campaign / "pred.csv", delimiter=",", names=True)
    meas = np.genfromtxt(campaign / "m.csv", delimiter=",", names=True)
    err = np.sqrt((pred["x"] - meas["x"]) ** 2 + (pred["y"] - meas["y"]) ** 2 + (pred["z"] - meas["z"]) ** 2)
    assert np.sqrt(np.mean(err ** 2)) < 1.2 * FLOOR
    # in the base frame the same points differ by the tracker transform (metres away)
    r = run("kincal", "fk", "--robot", str(campaign / "cal2.json"), "--joints", str(campaign / "m.csv"), "--out",
            str(campaign / "base.csv"))
    base = np.genfromtxt(campaign / "base.csv", delimiter=",", names=True)
    assert np.min(np.abs(base["x"] - meas["x"])) > 100
    assert "no target column" not in r.stderr
    # without a target column the rows are the tool frame's: said on stderr, in one line
    (campaign / "q.csv").write_text("q1,q2,q3,q4,q5,q6\n0,-90,90,0,30,0\n")
    r = run("kincal", "fk", "--robot", str(campaign / "cal2.json"), "--joints", str(campaign / "q.csv"), "--frame",
            "instrument", "--out", str(campaign / "tool.csv"))
    assert r.returncode == 0 and r.stderr.count("\n") == 1 and "no target column" in r.stderr


def test_calibrated_urdf_has_the_model_fk(campaign, tmp_path):
    """The URDF of the calibrated geometry (geometric fit: no compliance) has the model's FK to 1e-9 mm
    and no absurd link origins."""
    r = run("kincal", "identify", "--robot", "kr500", "--data", str(campaign / "m.csv"), "--out", str(tmp_path / "g.json"),
            "--effects", "none", "--urdf", str(tmp_path / "cal.urdf"))
    assert r.returncode == 0, r.stderr
    model = kincal.load_robot(str(tmp_path / "g.json"))
    urdf = kincal.load_robot(str(tmp_path / "cal.urdf"))
    rng = np.random.default_rng(3)
    lim = np.asarray(model.limits_deg)
    q = rng.uniform(lim[:, 0], lim[:, 1], size=(500, 6))
    a, b = kincal.fk(model, q), kincal.fk(urdf, q)
    assert np.max(np.abs(a[:, :3] - b[:, :3])) < 1e-9
    ra = np.array([_core.abc_to_rotation(p) for p in a[:, 3:]])
    rb = np.array([_core.abc_to_rotation(p) for p in b[:, 3:]])
    assert np.max(np.abs(ra - rb)) < 1e-12
    import xml.etree.ElementTree as ET
    for o in ET.parse(tmp_path / "cal.urdf").getroot().iter("origin"):
        assert np.linalg.norm([float(v) for v in o.get("xyz").split()]) < 3.0  # metres


def test_api_identify_and_robust_loss():
    """truth: kr500 seed 8 with compliance; 150 poses x 3 targets; 5% of the points 5 mm off. The
    Huber fit's held-out error stays within 10% of the clean fit's."""
    robot = kincal.load_robot("kr500")
    truth = ident.default_truth(robot, seed=8)
    clean = ident.simulate(truth, 150, seed=2, targets=3)
    dirty = ident.simulate(truth, 150, seed=2, targets=3, outlier_fraction=0.05, outlier_mm=5.0)
    held = ident.simulate(truth, 100, seed=3, targets=3)
    def held_rms(data):
        res = ident.identify(robot, data, k_folds=0)
        e = _core.point_errors(res.robot, res.targets, held)
        return float(np.sqrt(np.mean(e ** 2)))
    e_clean, e_dirty = held_rms(clean), held_rms(dirty)
    assert abs(e_dirty - e_clean) < 0.1 * e_clean


@pytest.mark.parametrize("content,message", [
    ("pose,q1,q2,q3,q4,q5,q6,x,y\n0,0,0,0,0,0,0,1,2\n", "missing column 'z'"),
    ("pose,q1,q2,q3,q4,q5,q6,x,y,z\n0,0,0,0,0,0,0,1,2,nan\n", ":2: column 'z'"),
    ("pose,q1,q2,q3,q4,q5,q6,x,y,z\n" + "".join(f"{i},0,-90,90,0,{i},0,1,2,3\n" for i in range(5)), "too few"),
])
def test_identify_bad_input(tmp_path, content, message):
    f = tmp_path / "m.csv"
    f.write_text(content)
    out = tmp_path / "model.json"
    r = run("kincal", "identify", "--robot", "kr500", "--data", str(f), "--out", str(out))
    assert r.returncode == 1
    assert message in r.stderr and str(f) in r.stderr
    assert not out.exists()


@pytest.mark.realdata
def test_ur10_real_data_calibrates_across_series():
    """Real data: the UR10 laser-tracker series of ../shared/data/ipa-robot-accuracy (Landgraf et al.
    2021). Fitted on series B (varied joint configurations), predicted on series C (random poses)
    and D (ISO cubes) with only the tracker frame and probe offset refitted: the calibrated model
    beats the nominal one on every series. Measured: B held out 1.07 -> 0.41 mm, C 0.99 -> 0.50 mm,
    D 0.78 -> 0.50 mm RMS; we require at least a 30% reduction."""
    from conftest import SHARED
    from kincal.io import datasets
    base = SHARED / "data" / "ipa-robot-accuracy"
    if not base.exists():
        pytest.skip("the shared UR10 data are not present")
    robot = kincal.load_robot("ur10")
    res = ident.identify(robot, datasets.read_ipa(base / "Series_B/measurements_joint_configurations.csv"))
    assert res.validation["after_rms_mm"] < 0.7 * res.validation["before_rms_mm"]
    for f in ("Series_C/measurements_random_poses.csv", "Series_D/measurements_iso_cubes.csv"):
        v = ident.validate(res.robot, datasets.read_ipa(base / f))
        assert v["after_rms_mm"] < 0.7 * v["before_rms_mm"], (f, v)


def test_observability_selection_beats_random_poses():
    """30 poses chosen for observability (greedy D-optimal from 300 random ones) against 30 random
    ones, each set identified (geometry + compliance, Huber): the chosen set has the larger
    observability index on every draw, and predicts 200 other poses better in the median over 20
    draws (truth, campaign). Truths: default_truth(kr500, seed t), 3 reflectors, 0.02 mm noise; draws
    (t, campaign seed, held seed) = (3, 5, 99) and (k, 20 + k, 200 + k) for k = 1..19; the held-out
    poses noise-free, so that the figure is the model's error, not the noise's. This test took one
    draw (3, 5, 99) and the noisy held-out poses (0.035 mm of noise against some 0.002 mm of
    difference): on other draws the random set won on 9 of 43 (an audit in the thirty-second session).
    Measured: ratio chosen / random 0.66-1.47, median 0.839 (6 of 20 draws above 1); asserted, a
    statement of these draws rather than a hold-out: median at most 0.9."""
    robot = kincal.load_robot("kr500")
    ratios = []
    for k in range(20):
        t, c, h = (3, 5, 99) if k == 0 else (k, 20 + k, 200 + k)
        truth = ident.default_truth(robot, seed=t)
        held = ident.simulate(truth, 200, seed=h, targets=3, noise_mm=0.0)
        rand = ident.simulate(truth, 30, seed=c, targets=3)
        chosen = plan.select_observable(robot, ident.simulate(truth, 300, seed=c, targets=3), 30)
        assert len(np.unique(chosen["pose"])) == 30
        out = {}
        for name, d in (("random", rand), ("chosen", chosen)):
            r = _core.identify(robot, d, _core.IdentifyOptions(compliance=True, loss="huber"))
            e = _core.point_errors(r.robot, r.targets, held)
            out[name] = (r.observability_index, float(np.sqrt(np.mean(e ** 2))))
        assert out["chosen"][0] > out["random"][0], (t, c)
        ratios.append(out["chosen"][1] / out["random"][1])
    print("held-out RMS chosen / random:", np.round(ratios, 3))
    assert np.median(ratios) <= 0.9, ratios


def test_numpy_residuals_equal_the_core():
    """The numpy measurement model of the scipy benchmark baseline computes the core's residuals
    (kr500, compliance, two targets, a random parameter point) to 1e-9 mm."""
    from kincal._benchmarks.numpy_model import NumpyPointModel

    robot = kincal.load_robot("kr500")
    data = ident.simulate(ident.default_truth(robot, seed=1), 50, seed=1, targets=2)
    pm = _core.PointModel(robot, 2)
    x = np.asarray(pm.start(data))
    rng = np.random.default_rng(0)
    for p in pm.layout.parameters:
        if p.kind == "compliance":
            x[p.index] = 0.003
        elif p.unit == "rad":
            x[p.index] += 1e-3 * rng.normal()
        else:
            x[p.index] += rng.normal()
    r_core = np.asarray(pm.residuals(list(x), data, False)[0])
    r_np = NumpyPointModel(robot, 2).residuals(x, data)
    assert np.max(np.abs(r_core - r_np)) < 1e-9


def test_tool_targets_place_the_tcp(campaign, tmp_path):
    """truth: the campaign fixture (reflectors at DEFAULT_TARGETS in the true tool frame, which is
    off the nominal by about 1 mm and 0.05 deg). Given those offsets, the identified model puts the
    TCP where the true one is: at 50 configurations around home both models' TCPs, seen from the
    tracker, agree within 0.1 mm."""
    (tmp_path / "t.csv").write_text("x,y,z\n" + "".join(f"{float(a)!r},{float(b)!r},{float(c)!r}\n" for a, b, c in ident.DEFAULT_TARGETS[:3]))
    r = run("kincal", "identify", "--robot", "kr500", "--data", str(campaign / "m.csv"), "--out", str(tmp_path / "m.json"),
            "--tool-targets", str(tmp_path / "t.csv"))
    assert r.returncode == 0, r.stderr
    model = kincal.load_robot(str(tmp_path / "m.json"))
    truth = kincal.load_robot(str(campaign / "truth.json"))
    q = np.asarray(kincal.load_robot("kr500").home_deg)[None, :] + np.random.default_rng(2).uniform(-20, 20, (50, 6))
    a = kincal.fk(model, q, frame="instrument")
    b = kincal.fk(truth, q, frame="instrument")
    assert np.max(np.linalg.norm(a[:, :3] - b[:, :3], axis=1)) < 0.1


def test_ipa_orientations_read_as_abc():
    """Real data: series B of ../shared/data/ipa-robot-accuracy. The probe's orientation columns
    (intrinsic XYZ Euler angles in degrees) read as KUKA ABC angles give the same rotation as
    scipy's Rotation.from_euler('XYZ') of the file's values, to 1e-12, on every row."""
    from scipy.spatial.transform import Rotation

    from conftest import SHARED
    from kincal.io import datasets
    path = SHARED / "data" / "ipa-robot-accuracy" / "Series_B/measurements_joint_configurations.csv"
    if not path.exists():
        pytest.skip("the shared UR10 data are not present")
    d = datasets.read_ipa(path, orientation=True)
    header = path.read_text().splitlines()[0].split(";")
    rows = [ln.split(";") for ln in path.read_text().splitlines()[1:] if ln.strip()]
    cols = [header.index(c) for c in ("measurement_rx", "measurement_ry", "measurement_rz")]
    eul = np.array([[float(r[c].replace(",", ".")) for c in cols] for r in rows])
    want = Rotation.from_euler("XYZ", eul, degrees=True).as_matrix()
    got = np.array([_core.abc_to_rotation(a) for a in d["abc"]])
    assert len(got) == len(want) > 100
    assert np.max(np.abs(got - want)) < 1e-12


def test_model_fitted_on_every_row_whatever_the_row_order():
    """truth: kr500 seed 4 with compliance; 120 poses x 2 targets, 0.02 mm noise. The delivered model
    is fitted on every row (the folds only validate it): the same campaign with its rows shuffled and
    its pose ids renumbered gives the same model, its predictions equal within 1e-6 mm."""
    robot = kincal.load_robot("kr500")
    data = ident.simulate(ident.default_truth(robot, seed=4), 120, seed=6, targets=2)
    rng = np.random.default_rng(9)
    perm = rng.permutation(len(data["pose"]))
    shuffled = ident.subset(data, perm)
    new_id = rng.permutation(1000)[: int(np.max(data["pose"])) + 1] + 5000
    shuffled = shuffled.with_columns(pose=new_id[shuffled["pose"]].astype(data["pose"].dtype))
    a = ident.identify(robot, data)
    b = ident.identify(robot, shuffled, seed=3)
    assert a.validation["fit_rows"] == b.validation["fit_rows"] == len(data["pose"])
    assert a.validation["model_rows"].startswith("every row")
    q = random_q(robot, rng, 50)
    pa, pb = _core.fk(a.robot, q, True, False), _core.fk(b.robot, q, True, False)
    assert np.max(np.linalg.norm(pa[:, :3] - pb[:, :3], axis=1)) < 1e-6
    assert np.max(np.abs(np.asarray(a.targets) - np.asarray(b.targets))) < 1e-6


def test_truth_out_carries_the_hidden_effects(tmp_path):
    """`simulate --truth-out` writes the truth as measured: kr500 (seed 1) with the hidden backlash
    of -0.015 deg on joint 3. Re-simulated from that file with nothing hidden, the same seed gives
    the same measurements (the backlash acts from the file), and the file names the backlash."""
    r = run("kincal", "simulate", "--robot", "kr500", "--poses", "40", "--out", str(tmp_path / "a.csv"),
            "--truth-out", str(tmp_path / "t.json"), "--hide", "backlash:3:-0.015")
    assert r.returncode == 0, r.stderr
    (e, v), = kincal.load_robot(str(tmp_path / "t.json")).effects
    assert (e.name, e.joint) == ("backlash", 3) and np.degrees(v[0]) == pytest.approx(-0.015)
    r = run("kincal", "simulate", "--robot", "kr500", "--truth", str(tmp_path / "t.json"), "--poses", "40",
            "--out", str(tmp_path / "b.csv"))
    assert r.returncode == 0, r.stderr
    a, b = (ident.read_measurements(str(tmp_path / f), kincal.load_robot("kr500")) for f in ("a.csv", "b.csv"))
    assert np.array_equal(a["q_deg"], b["q_deg"]) and np.allclose(a["xyz"], b["xyz"], atol=1e-9)


@pytest.mark.parametrize("defaults", [False, True])
def test_the_fit_stops_at_the_optimum(defaults):
    """truth: kr500 seed 2 (1 mm / 0.05 deg geometric errors, joint compliance); 400 poses x 1
    reflector, 0.02 mm noise. The solver stops on a 1e-10 relative change of the cost and, in the
    Gauss-Newton tail, takes steps with the Jacobian of the step before (chord steps: this campaign
    takes some in both fits, checked). What
    it delivers is still the optimum: a Gauss-Newton step from the solution with a Jacobian computed
    afresh there moves the predicted points by less than 1e-6 mm (RMS) and lowers the cost by less than
    1e-10 of it. Plain least squares, and the defaults of `kincal identify` (priors, the data-scaled
    Huber loss: the step on the maximum a posteriori problem, the priors as rows). The condition
    number and observability index, taken from the solver's last Jacobian, equal those of the fresh
    one to 1e-6."""
    from kincal.calibration import priors

    robot = kincal.load_robot("kr500")
    data = ident.simulate(ident.default_truth(robot, seed=2), 400, seed=2, targets=1)
    if defaults:
        opts = _core.IdentifyOptions(compliance=True, loss="huber", loss_scale_mm=0.0, covariance=False,
                                     prior_scale=1.0, prior_sd=priors.core_prior_sd(priors.DEFAULT_PRIOR_SD))
    else:
        opts = _core.IdentifyOptions(compliance=True, loss="none", covariance=False)
    res = _core.identify(robot, data, opts)
    assert res.converged, res.stop_reason
    assert res.chord_steps >= 1  # the path under test is taken (2 and 3 chord steps measured)
    pm = _core.PointModel(robot, 1)
    x = np.asarray(res.x, dtype=float)
    free = ~np.asarray(res.fixed)
    r, J = (np.asarray(a) for a in pm.residuals(list(x), data, True))
    J = J[:, free]
    if defaults:  # the robust loss's weights (Huber on each row's distance) and the priors as rows
        d = np.linalg.norm(r.reshape(-1, 3), axis=1)
        w = np.sqrt(np.minimum(1.0, res.loss_scale_mm / np.maximum(d, 1e-300))).repeat(3)
        sd = np.asarray(res.prior_sd, dtype=float)[free]
        has = np.isfinite(sd)
        P = np.zeros((int(has.sum()), int(free.sum())))
        P[np.arange(int(has.sum())), np.flatnonzero(has)] = res.noise_mm / sd[has]
        rp = (res.noise_mm / sd[has]) * (x[free][has] - np.asarray(res.start, dtype=float)[free][has])
        A, b = np.vstack([w[:, None] * J, P]), np.concatenate([w * r, rp])
    else:
        A, b = J, r
    step = np.linalg.lstsq(A, -b, rcond=None)[0]
    moved = J @ step
    assert np.sqrt(np.mean(np.sum(moved.reshape(-1, 3) ** 2, axis=1))) < 1e-6
    assert (b @ b - np.sum((b + A @ step) ** 2)) / (b @ b) < 1e-10
    # the observability figures: unit-scaled columns of what the data determine (not the priors)
    seen = ~np.asarray(res.fixed) & ~np.asarray(res.at_prior)
    _, Jall = pm.residuals(list(x), data, True)
    Jd = np.asarray(Jall)[:, seen]
    s = np.linalg.svd(Jd / np.linalg.norm(Jd, axis=0), compute_uv=False)
    assert res.condition_number == pytest.approx(s[0] / s[-1], rel=1e-6)
    assert res.observability_index == pytest.approx(np.exp(np.mean(np.log(s))) / np.sqrt(len(data)), rel=1e-6)
