"""kincal diagnose on simulated data where the truth hides effects the starting (geometric) model
lacks; the workflow is not told which. Truth of every case: kr500 (or a URDF robot) with 1 mm /
0.05 deg geometric errors (seed 3), tracker at DEFAULT_INSTRUMENT, 250 poses x 3 reflectors, 0.02 mm
noise per coordinate (0.0346 mm RMS per point), plus the effects named in the case."""

from __future__ import annotations

import json

import numpy as np
import pytest

import kincal
from kincal import _core
from kincal import diagnose as dg
from kincal.calibration import identify as ident
from kincal.io.urdf import spec_urdf

from conftest import run

NOISE = 0.02 * np.sqrt(3)
D = np.radians


def _truth(robot, compliance=0.0):
    return robot.with_calibrated(3, 1.0, 0.05, compliance, ident.DEFAULT_INSTRUMENT)


@pytest.fixture(scope="module")
def kr500():
    return kincal.load_robot("kr500")


@pytest.mark.parametrize("hidden,expect", [
    ([("transmission_error", 3, [D(0.02), 0, 0, D(0.01)])], [("transmission_error", 3)]),
    ([("backlash", 2, [D(0.01)])], [("backlash", 2)]),
    ([("thermal_expansion", 0, [2e-5])], [("thermal_expansion", None)]),
    ([("transmission_error", 5, [D(0.03), 0, 0, 0])], [("transmission_error", 5)]),
])
def test_each_hidden_effect_is_named(kr500, hidden, expect):
    data = ident.simulate(_truth(kr500), 250, seed=4, targets=3, effects=hidden)
    out = dg.diagnose(kr500, data)
    assert [(s["effect"], s["joint"]) for s in out["steps"]] == expect
    assert out["final_rms_mm"] <= 1.3 * NOISE
    assert out["steps"][0]["rms_before_mm"] > 2 * out["final_rms_mm"]


def test_the_library_effect_is_named_over_a_map_that_contains_it(kr500):
    """The transmission error of the first case above, hidden in campaigns 4 + 10 s (s = 1..20: the
    truth's seed 3 for odd s, 20 + s for even s). On the linearisation a joint map of joint 3 of higher
    order gained a few tenths of a percent more than the library's transmission_error (harmonics 1, 2,
    which the map contains) on 6 of those 20, and was named (an audit, thirty-second session). The
    map's refits now meet the library effect on held ranges of the angle: on campaign 94 (truth 3),
    where the map of order 6 scored 84.48% against 84.15%, transmission_error is named, its own
    figures carried and the map it was preferred to recorded; on all 20 it is named (measured with the
    audit's script, not repeated here)."""
    hidden = [("transmission_error", 3, [D(0.02), 0, 0, D(0.01)])]
    data = ident.simulate(_truth(kr500), 250, seed=94, targets=3, effects=hidden)
    out = dg.diagnose(kr500, data)
    assert [(s["effect"], s["joint"]) for s in out["steps"]] == [("transmission_error", 3)]
    ev = out["steps"][0]["evidence"]
    assert ev["preferred_by_refits_to"]["effect"] == "joint_map" and ev["preferred_by_refits_to"]["joint"] == 3
    assert ev["parameters"] == 4  # the library effect's own figures (the map's were 12)
    refits = {str(v): mm for v, _, mm in ev["range_refit_rms_mm"]}
    assert refits["transmission_error(joint 3)"] < min(mm for v, mm in refits.items() if v != "transmission_error(joint 3)")
    assert out["final_rms_mm"] <= 1.3 * NOISE


def test_hidden_compliance_is_named(kr500):
    """truth with joint compliance (~0.003 deg/kN m on joints 2-5, the 300 kg head): compliance is
    named, as the library's effect on every gravity-loaded joint (one candidate, the torques from the
    model's masses: the first step `identify --effects auto` takes too), and nothing else."""
    data = ident.simulate(_truth(kr500, 0.003), 250, seed=4, targets=3)
    out = dg.diagnose(kr500, data)
    named = [(s["effect"], s["joint"], s.get("gravity")) for s in out["steps"]]
    assert named == [("joint_compliance", None, "masses")]
    assert out["final_rms_mm"] <= 1.3 * NOISE


def test_two_effects_named_in_order_of_size(kr500):
    """A large backlash on joint 2 (0.02 deg) and a smaller transmission error on joint 5
    (0.015 deg): both named, the larger first."""
    hidden = [("backlash", 2, [D(0.02)]), ("transmission_error", 5, [D(0.015), 0, 0, 0])]
    out = dg.diagnose(kr500, ident.simulate(_truth(kr500), 250, seed=6, targets=3, effects=hidden))
    assert [(s["effect"], s["joint"]) for s in out["steps"]] == [("backlash", 2), ("transmission_error", 5)]
    assert out["final_rms_mm"] <= 1.3 * NOISE


def test_nothing_hidden_nothing_named(kr500):
    """Truth: kr500 geometry, Gaussian noise 0.02 mm per coordinate. Without --noise the verdict
    cannot say "at the noise level" (the final fit's scatter only bounds the noise); given the
    instrument's noise, it can."""
    data = ident.simulate(_truth(kr500), 250, seed=8, targets=3)
    out = dg.diagnose(kr500, data)
    assert out["steps"] == []
    assert out["verdict"].startswith("no structure left that the library finds") and not out["noise_known"]
    assert "at the noise level" not in out["verdict"]
    known = dg.diagnose(kr500, data, noise_mm=0.02)
    assert known["steps"] == [] and known["noise_known"]
    assert known["verdict"] == "what remains is at the noise level"
    assert known["noise_rms_mm"] == pytest.approx(NOISE)


@pytest.mark.parametrize("hidden,expect", [
    ([("transmission_error", 4, [0, D(0.03), 0, 0])], [("transmission_error", 4)]),
    ([("backlash", 3, [D(0.01)])], [("backlash", 3)]),
    ([("thermal_expansion", 0, [2e-5])], [("thermal_expansion", None)]),
    (None, [("joint_compliance", None)]),
])
def test_urdf_robot(tmp_path, kr500, hidden, expect):
    """A URDF robot (the kr500 geometry and link masses written as URDF, so without kincal's
    300 kg head): each effect hidden in turn is named (joint compliance: ~0.01 deg/kN m, the arm's
    own weight loads joints 2 and 3 most; named as one effect on every loaded joint)."""
    spec = json.loads(kr500.to_json())["nominal"]
    (tmp_path / "r.urdf").write_text(spec_urdf(spec, "urdf_robot"))
    robot = kincal.load_robot(str(tmp_path / "r.urdf"))
    truth = _truth(robot, 0.01 if hidden is None else 0.0)
    data = ident.simulate(truth, 250, seed=5, targets=3, effects=hidden or [])
    out = dg.diagnose(robot, data)
    named = [(s["effect"], s["joint"]) for s in out["steps"]]
    assert named == expect
    assert out["final_rms_mm"] <= 1.3 * NOISE


def test_cli_writes_diagnosis_report_and_model(tmp_path):
    """truth: kincal simulate's default (kr500, seed 1: 1 mm / 0.05 deg geometric errors, ~0.003
    deg/kN m compliance) with a backlash of 0.015 deg on joint 3; 150 poses x 3 reflectors, 0.02 mm
    noise. Starting from geometry + compliance (--effects joint_compliance) with the reflectors'
    offsets known (--tool-targets), the diagnosis names the backlash and writes DIR/model.json: the
    final model in identify's format, loadable, carrying the backlash on joint 3 within 0.002 deg
    of the truth, with the known target offsets."""
    r = run("kincal", "simulate", "--robot", "kr500", "--poses", "150", "--out", str(tmp_path / "m.csv"),
            "--hide", "backlash:3:0.015")
    assert r.returncode == 0, r.stderr
    (tmp_path / "t.csv").write_text("x,y,z\n" + "".join(",".join(repr(float(v)) for v in t) + "\n"
                                                        for t in ident.DEFAULT_TARGETS[:3]))
    r = run("kincal", "diagnose", "--robot", "kr500", "--data", str(tmp_path / "m.csv"), "--out", str(tmp_path / "d"),
            "--effects", "joint_compliance", "--tool-targets", str(tmp_path / "t.csv"))
    assert r.returncode == 0, r.stderr
    doc = json.loads((tmp_path / "d" / "diagnosis.json").read_text())
    assert {"steps", "final_rms_mm", "noise_rms_mm"} <= set(doc)
    # 150 configurations (3 reflectors each), folds of whole configurations
    assert doc["validation"] == {"scheme": "5-fold, whole configurations", "configurations": 150,
                                 "grouping": "rows with equal joint angles (within 0.001 deg)"}
    assert [(s["effect"], s["joint"]) for s in doc["steps"]] == [("backlash", 3)]
    for s in doc["steps"]:
        assert s["rms_after_mm"] < s["rms_before_mm"]
    assert doc["final_rms_mm"] <= 1.3 * NOISE
    fm = doc["final_model"]
    assert fm["file"] == "model.json" and "backlash(joint 3)" in [e["label"] for e in fm["effects"]]
    assert "joint_compliance(joint 2)" in fm["started_from"]
    robot = kincal.load_robot(str(tmp_path / "d" / "model.json"))
    (e, v), = robot.effects
    assert (e.name, e.joint) == ("backlash", 3)
    assert abs(np.degrees(v[0]) - 0.015) < 0.002
    model = json.loads((tmp_path / "d" / "model.json").read_text())
    assert model["format"] == "kincal-model"
    assert "backlash(joint 3)" in model["identification"]["effects"]
    assert np.allclose(model["identification"]["targets_mm"], ident.DEFAULT_TARGETS[:3])
    # the final model (TCP placed from --tool-targets) records the angles it was fitted on: every row
    data = ident.read_measurements(str(tmp_path / "m.csv"), robot)
    assert np.allclose(model["campaign"]["fitted_joint_ranges_deg"], _core.joint_ranges(data["q_deg"]))
    page = (tmp_path / "d" / "report.html").read_text()
    assert "gap.png" in page and "residual_map.png" in page
    assert "model.json was written" in page
    # the noise was not given: the page never calls the fit's scatter a noise estimate
    assert "noise not known (the final fit" in page and "noise estimate" not in page
    for f in ("gap.png", "residual_map.png", "step1.png"):
        assert (tmp_path / "d" / f).read_bytes()[:4] == b"\x89PNG"


def test_fivebar_link_deflection_is_named(tmp_path):
    """truth: the simulated over-constrained 6-bar (paper_sixbar(1)) with its actuator zero errors
    removed, so what the four hidden-robot lengths miss is the couplers' pose-dependent strain (and
    2 um clearance); 150 random points measured with 1 um noise. The diagnosis names
    link_deflection on the strained couplers b and c and nothing else."""
    from kincal import _core
    from kincal import fivebar as fb

    truth = _core.paper_sixbar(1)
    truth.offset1_deg = truth.offset2_deg = 0.0
    rng = np.random.default_rng(1)
    xy = np.c_[rng.uniform(163, 261, 150), rng.uniform(-74, 74, 150)]
    pts = _core.sixbar_campaign(truth, fb.FiveBar(), None, xy, 0.001, 2)
    rows = [[int(i), a, b, d[0], d[1], m[0], m[1]] for i, a, b, d, m in
            zip(pts["id"], pts["theta1_deg"], pts["theta2_deg"], pts["desired"], pts["measured"])]
    (tmp_path / "t.csv").write_text("point,theta1_deg,theta2_deg,x_desired_mm,y_desired_mm,x_measured_mm,y_measured_mm\n"
                                    + "".join(",".join(repr(float(v)) for v in r) + "\n" for r in rows))
    r = run("kincal", "diagnose", "--robot", "fivebar", "--data", str(tmp_path / "t.csv"), "--out", str(tmp_path / "d"))
    assert r.returncode == 0, r.stderr
    doc = json.loads((tmp_path / "d" / "diagnosis.json").read_text())
    named = {(s["effect"], s.get("link")) for s in doc["steps"]}
    assert named == {("link_deflection", "b"), ("link_deflection", "c")}
    assert doc["final_rms_mm"] < 0.1 * doc["steps"][0]["rms_before_mm"]
    assert (tmp_path / "d" / "residual_map.png").read_bytes()[:4] == b"\x89PNG"


def test_step_figure_draws_the_effect_less_its_mean(kr500):
    """The step figure's curve of a joint-angle effect is the identified change less its mean over the
    points: the residuals it is drawn on never show a constant (the joint's offset carries it). Truth:
    a transmission error on joint 2 of 0.10 deg sin q - 0.04 deg cos q + 0.02 deg sin 2q, seen over
    -140..5 deg only, where its mean is far from zero."""
    from types import SimpleNamespace

    from kincal import _core
    from kincal.diagnose import serial_report

    effect = _core.Effect("transmission_error", 2)
    robot = kr500.with_effects([(effect, [D(0.10), D(-0.04), D(0.02), 0.0])], 20.0)
    var = np.linspace(-140.0, 5.0, 300)
    xs, curve = serial_report._effect_curve(SimpleNamespace(robot=robot), {}, effect, var)

    def truth(deg):
        t = D(deg)
        return 0.10 * np.sin(t) - 0.04 * np.cos(t) + 0.02 * np.sin(2 * t)

    assert abs(np.mean(truth(var))) > 0.03  # a large offset over this range, so the check has teeth
    assert np.allclose(curve, truth(xs) - np.mean(truth(var)), atol=1e-12)


def test_step_figure_draws_backlash_less_its_mean(kr500):
    """Backlash b dir draws one level per direction, less b times the mean direction over the points
    (what the joint's offset absorbs when the directions are unbalanced). Truth: b = 0.015 deg on
    joint 3; 70 of 100 points approach upwards (+1), the signs jittered by up to 0.15 as plotted."""
    from types import SimpleNamespace

    from kincal import _core
    from kincal.diagnose import serial_report

    effect = _core.Effect("backlash", 3)
    robot = kr500.with_effects([(effect, [D(0.015)])], 20.0)
    signs = np.r_[np.ones(70), -np.ones(30)]
    var = signs + np.random.default_rng(1).uniform(-0.15, 0.15, 100)
    xs, levels = serial_report._effect_curve(SimpleNamespace(robot=robot), {}, effect, var)
    assert xs.tolist() == [-1.0, 1.0]
    assert np.allclose(levels, 0.015 * (np.array([-1.0, 1.0]) - 0.4))


def test_linearisation_copies_the_fit_by_name_when_the_model_gains_a_parameter(kr500):
    """The diagnosis linearises the calibrated model at the fit. When the fit identified a tilt of
    joint 1 (as on UR10 series A), joint 1 carries a gravity torque in the calibrated model, which
    then has a joint1.compliance the fit's layout had not, inserted before the others; the fit's values
    must still reach their own parameters. Truth: kr500 with 1 mm / 0.05 deg errors and compliance
    (seed 3), 150 poses x 3 reflectors, 0.02 mm noise; the fitted robot's joint 1 axis tilted by 0.01
    deg. The residual must be that robot's own point errors (they were off by the reflector offsets)."""
    from types import SimpleNamespace

    from kincal import _core
    from kincal.diagnose.serial import evaluate

    data = ident.simulate(_truth(kr500, 0.003), 150, seed=4, targets=3)
    f = ident.identify(kr500, data, k_folds=0).fit
    doc = json.loads(f.robot.to_json())
    t = D(0.01)
    doc["calibrated"]["joints"][0]["axis"] = [np.sin(t), 0.0, np.cos(t)]
    tilted = _core.Robot.from_json(json.dumps(doc))
    res = SimpleNamespace(layout=f.layout, robot=tilted, targets=f.targets, t_ref=f.t_ref, x=f.x, fixed=f.fixed)
    grown = _core.PointModel(tilted, len(f.targets), list(f.layout.effect_list), f.t_ref, True).layout.parameters
    assert len(grown) == len(f.layout.parameters) + 1  # the case under test: one parameter more
    r = evaluate(res, data, [])[0]
    e = np.linalg.norm(np.asarray(r).reshape(-1, 3), axis=1)
    assert np.allclose(e, _core.point_errors(tilted, f.targets, data), atol=1e-6), np.max(e)


def test_report_helpers_name_what_they_show():
    """The report's labels: the starting model with each effect's joints gathered; a held-out share
    at or below zero read as none; a p-value that underflows is not printed as 0; the error maps'
    shared colour scale tells 5 um from 1000 um (logarithmic, down to a thousandth of the largest)."""
    from kincal import report
    from kincal.diagnose import serial_report as sr

    assert sr._compact("geometry + joint_compliance(joint 2) + joint_compliance(joint 3) + backlash(joint 2)") == \
        "geometry + joint_compliance(2, 3) + backlash(2)"
    assert sr._compact("geometry") == "geometry"
    assert sr._share(0.123) == "12.3%" and sr._share(-0.017) == "none (-1.7%)" and sr._share(0.0) == "none (0.0%)"
    assert sr._p(0.0) == "< 1e-300" and sr._p(4.2e-63) == "4.2e-63"
    norm = report.error_norm(np.r_[np.linspace(200.0, 1000.0, 50), np.linspace(3.0, 8.0, 50)])
    assert norm.vmax == 1000.0 and norm.vmin == 3.0
    assert norm(5.0) < 0.35 < 0.65 < norm(200.0)  # the after map's microns and the before map's apart
    assert report.error_norm(np.r_[0.0, 0.001, 1000.0]).vmin == 1.0  # a thousandth of the largest at least


def test_fivebar_report_without_a_named_effect_says_so(tmp_path):
    """Truth: the Kiper paper's Table I points (data/fivebar-table1.csv): few points, nothing named.
    The report says that no effect was named, shows no "with the named effects" map and does not
    call what remains the noise (no --noise given)."""
    from conftest import SHARED

    table = SHARED / "data" / "fivebar-table1.csv"
    if not table.exists():
        pytest.skip(f"{table} is not present")
    r = run("kincal", "diagnose", "--robot", "fivebar", "--data", str(table), "--out", str(tmp_path / "d"))
    assert r.returncode == 0, r.stderr
    doc = json.loads((tmp_path / "d" / "diagnosis.json").read_text())
    assert doc["steps"] == [] and not doc["noise_known"]
    page = (tmp_path / "d" / "report.html").read_text()
    assert "No effect was named" in page and "at the noise level" not in page and "noise not known" in page


def test_a_failed_diagnosis_leaves_its_folder_as_it_was(tmp_path):
    """Truth: kr500 (kincal simulate's default, seed 1), 40 poses. A folder named model.json stands
    where the diagnosis writes its model: the command fails naming it, and the output folder holds
    nothing but that folder (no report, no diagnosis.json, no figures, no staging folder)."""
    r = run("kincal", "simulate", "--robot", "kr500", "--poses", "40", "--out", str(tmp_path / "m.csv"))
    assert r.returncode == 0, r.stderr
    (tmp_path / "d" / "model.json").mkdir(parents=True)
    r = run("kincal", "diagnose", "--robot", "kr500", "--data", str(tmp_path / "m.csv"), "--out", str(tmp_path / "d"))
    assert r.returncode != 0 and "model.json is a folder" in r.stderr, r.stderr
    assert [p.name for p in (tmp_path / "d").iterdir()] == ["model.json"]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["d", "m.csv"]


def test_a_model_without_masses_tries_compliance_with_fitted_moments(tmp_path, kr500):
    """A URDF robot without <inertial> blocks (the kr500 geometry): no joint carries a known gravity
    torque, so joint_compliance is a candidate with the torques' mass moments fitted with it (one
    candidate for every gravity-loaded joint, as `identify --gravity auto` fits it), and the notes
    say so; with the masses (the same URDF with them) it is the mass-based one; with --gravity fit
    the fitted one again."""
    import re

    from kincal.calibration.effect_choice import JointCompliance

    spec = json.loads(kr500.to_json())["nominal"]
    text = re.sub(r"<inertial>.*?</inertial>", "", spec_urdf(spec, "urdf_robot"), flags=re.S)
    assert "<inertial" not in text
    (tmp_path / "r.urdf").write_text(text)
    robot = kincal.load_robot(str(tmp_path / "r.urdf"))
    data = ident.simulate(_truth(robot), 20, seed=5)
    cands, notes = dg.serial.candidates(robot, data)
    assert [c for c in cands if c.name == "joint_compliance"] == [JointCompliance("fit")]
    assert any(n.startswith("joint_compliance on joints 2, 3, 4, 5, 6") and "the model has no link masses" in n
               for n in notes), notes
    (tmp_path / "m.urdf").write_text(spec_urdf(spec, "urdf_robot"))
    massed = kincal.load_robot(str(tmp_path / "m.urdf"))
    data = ident.simulate(_truth(massed), 20, seed=5)
    assert [c for c in dg.serial.candidates(massed, data)[0] if c.name == "joint_compliance"] == [JointCompliance()]
    assert [c for c in dg.serial.candidates(massed, data, gravity="fit")[0]
            if c.name == "joint_compliance"] == [JointCompliance("fit")]


def test_a_rerun_leaves_no_figure_of_the_run_before(tmp_path):
    """The folder shows one run: step figures an earlier diagnosis wrote into it and this one did not
    are removed (a file the diagnosis does not write stays). Truth: kr500 (simulate's default), 40
    poses, nothing hidden: no step named."""
    r = run("kincal", "simulate", "--robot", "kr500", "--poses", "40", "--out", str(tmp_path / "m.csv"))
    assert r.returncode == 0, r.stderr
    (tmp_path / "d").mkdir()
    for f in ("step1.png", "step7.png", "notes.txt"):
        (tmp_path / "d" / f).write_text("from before")
    r = run("kincal", "diagnose", "--robot", "kr500", "--data", str(tmp_path / "m.csv"), "--out", str(tmp_path / "d"))
    assert r.returncode == 0, r.stderr
    steps = json.loads((tmp_path / "d" / "diagnosis.json").read_text())["steps"]
    left = sorted(p.name for p in (tmp_path / "d").glob("step*.png"))
    assert left == [f"step{k + 1}.png" for k in range(len(steps))]
    assert (tmp_path / "d" / "notes.txt").read_text() == "from before"
