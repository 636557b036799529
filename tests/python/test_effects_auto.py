"""`kincal identify --effects auto` (the default): the data choose the effects by the diagnosis's rule,
the choice made again inside every training fold of the validation (nested), so that the figure
reported for the chosen model is honest; and `kincal diagnose` takes the same first steps.

Truth of the simulated campaigns: the kr500 (its link masses and the 300 kg head) or, for "masses
unknown", the kr500 geometry and link masses written as a URDF (the truth) while the model given to
identify is that URDF without its <inertial> tags; 1 mm / 0.05 deg geometric errors (default_truth,
seed 3), seen from DEFAULT_INSTRUMENT; joint compliance 0.003 deg/kN m on every gravity-loaded joint
(present) or none (absent); 3 reflectors, 0.02 mm Gaussian noise per coordinate. Every figure is a
grouped 5-fold cross-validated RMS of the 3-D point error (whole configurations per fold)."""

from __future__ import annotations

import json
import re

import numpy as np
import pytest

import kincal
from kincal import diagnose as dg
from kincal.calibration import identify as ident
from kincal.calibration.effect_choice import JointCompliance
from kincal.io.urdf import spec_urdf

from conftest import run

SIZES = (15, 25, 60)


@pytest.fixture(scope="module")
def robots(tmp_path_factory):
    kr500 = kincal.load_robot("kr500")
    d = tmp_path_factory.mktemp("auto")
    text = spec_urdf(json.loads(kr500.to_json())["nominal"], "kr500")
    (d / "with.urdf").write_text(text)
    (d / "without.urdf").write_text(re.sub(r"\s*<inertial>.*?</inertial>", "", text, flags=re.S))
    return {"kr500": kr500, "with": kincal.load_robot(str(d / "with.urdf")),
            "without": kincal.load_robot(str(d / "without.urdf"))}


CASES = {  # name: (the truth's robot, the model's robot, compliance of the truth)
    "present, masses known": ("kr500", "kr500", 0.003),
    "present, masses unknown": ("with", "without", 0.003),
    "absent": ("kr500", "kr500", 0.0),
}


def _campaign(robots, case: str, n: int) -> tuple:
    truth_robot, model_robot, compliance = CASES[case]
    truth = ident.default_truth(robots[truth_robot], seed=3, compliance=compliance)
    return robots[model_robot], ident.simulate(truth, n, seed=11 + n, targets=3)


def _complies(res: ident.Identification) -> bool:
    return any(e.name == "joint_compliance" for e in res.effects)


@pytest.mark.parametrize("case", list(CASES))
def test_auto_keeps_compliance_where_it_is_and_predicts_as_the_better_fixed_choice(robots, case):
    """At 15, 25 and 60 configurations: --effects auto keeps compliance in each present case at 60
    configurations and in no absent case; its nested cross-validated RMS is within 3% (the rule's
    own margin) of the better of --effects none and --effects joint_compliance. Issue 29's item, on
    its one draw per case (truth 3, campaign 11 + n). Not a general claim: on other draws (an audit,
    thirty-second session) the "masses unknown" case was 3-92% worse at 15 configurations on 8 of 39
    and 9% worse at 25 on one; the other two cases held on 21 draws each (BENCHMARKS.md, "Claims that
    held on one draw, audited")."""
    for n in SIZES:
        robot, data = _campaign(robots, case, n)
        auto = ident.identify(robot, data)
        none = ident.identify(robot, data, effects="none")
        comp = ident.identify(robot, data, effects="joint_compliance")
        cv = {k: r.validation["after_rms_mm"] for k, r in (("auto", auto), ("none", none), ("compliance", comp))}
        print(f"{case}, {n} configurations: kept {auto.effect_labels()}; CV RMS (mm) {cv}")
        assert auto.fit_info["effect_choice"]["nested"]
        assert cv["auto"] <= 1.03 * min(cv["none"], cv["compliance"]), (case, n, cv)
        if CASES[case][2] == 0.0:
            assert not _complies(auto), (case, n, auto.effect_labels())
        elif n == 60:
            assert _complies(auto), (case, n, auto.effect_labels())
            if case.endswith("unknown"):
                assert auto.fit.layout.gravity == "fit"


def test_auto_and_the_diagnosis_take_the_same_first_steps(robots):
    """Same data (kr500, compliance present, 60 configurations), same seed: the effects identify
    keeps are the diagnosis's first steps, in the same order."""
    robot, data = _campaign(robots, "present, masses known", 60)
    auto = ident.identify(robot, data, seed=0)
    diag = dg.diagnose(robot, data, seed=0)
    kept = auto.fit_info["effect_choice"]["kept"]
    assert kept, "compliance is present: something is kept"
    steps = [dg.step_effect(s).label for s in diag["steps"]]
    assert steps[:len(kept)] == kept


def test_auto_with_fitted_moments_is_one_candidate(robots):
    """Masses unknown: compliance is tried as one candidate (every gravity-loaded joint, the torques'
    mass moments fitted), and when kept the model carries it with gravity 'fit'."""
    robot, data = _campaign(robots, "present, masses unknown", 60)
    res = ident.identify(robot, data)
    tried = [t["candidate"] for t in res.fit_info["effect_choice"]["tried"]]
    assert JointCompliance("fit").label in tried
    assert "joint_compliance" not in tried
    assert res.fit_info["effect_choice"]["kept"][0] == JointCompliance("fit").label
    assert res.fit.layout.gravity == "fit"


def test_gravity_masses_leaves_only_the_mass_based_candidate(robots):
    """--gravity masses: the fitted-moments candidate is never tried (kr500, compliance present)."""
    robot, data = _campaign(robots, "present, masses known", 25)
    res = ident.identify(robot, data, gravity="masses")
    tried = [t["candidate"] for t in res.fit_info["effect_choice"]["tried"]]
    assert JointCompliance("fit").label not in tried and "joint_compliance" in tried


def test_cli_summary_lists_what_was_tried_and_kept(tmp_path):
    """kincal simulate's default truth (kr500, compliance), 40 poses x 3 reflectors: `kincal identify`
    without --effects chooses; the summary lists the candidates with their cross-validated RMS and
    what was kept, the model JSON records the choice."""
    m = tmp_path / "m.csv"
    assert run("kincal", "simulate", "--robot", "kr500", "--poses", "40", "--out", str(m)).returncode == 0
    r = run("kincal", "identify", "--robot", "kr500", "--data", str(m), "--out", str(tmp_path / "model.json"))
    assert r.returncode == 0, r.stderr
    assert "effects chosen by the data (--effects auto" in r.stdout
    assert "kept (step 1)" in r.stdout and "  kept: joint_compliance" in r.stdout
    assert "held-out RMS: geometry alone" in r.stdout
    doc = json.loads((tmp_path / "model.json").read_text())
    ch = doc["identification"]["effect_choice"]
    assert ch["mode"] == "auto" and ch["nested"] and "joint_compliance" in ch["kept"]
    assert doc["identification"]["effects"] == [t for t in doc["identification"]["effects"]
                                               if t.startswith("joint_compliance")]


def test_diagnose_on_task_data_holds_the_wrist_at_its_prior(tmp_path):
    """Simulated task data (a fixed wrist: joints 4-6 at one pose, axes 1-3 within +-10 deg of it, 60
    configurations, one target at the tool's origin, 0.02 mm noise; truth default_truth seed 3):
    `kincal diagnose` with its defaults exits 0, writes its model, and lists the wrist parameters as
    held at prior (the data cannot determine them: without priors the fit refused them)."""
    kr500 = kincal.load_robot("kr500")
    truth = ident.default_truth(kr500, seed=3)
    rng = np.random.default_rng(1)
    q = np.tile([10.0, -80.0, 100.0, 20.0, 40.0, -30.0], (60, 1))
    q[:, :3] += rng.uniform(-10.0, 10.0, (60, 3))
    d = ident.simulate(truth, 1, seed=1, noise_mm=0.0)
    d = {k: (np.repeat(v[:1], 60, axis=0) if isinstance(v, np.ndarray) else v) for k, v in d.items()}
    d.update(pose=np.arange(60), q_deg=q, line=np.arange(60) + 2)
    d["xyz"] = kincal.fk(truth, q, frame="instrument")[:, :3] + rng.normal(0.0, 0.02, (60, 3))
    d = kincal.MeasurementSet(d)
    (tmp_path / "task.csv").write_text(ident.measurements_csv(d, kr500.dof))
    r = run("kincal", "diagnose", "--robot", "kr500", "--data", str(tmp_path / "task.csv"), "--out",
            str(tmp_path / "d"))
    assert r.returncode == 0, r.stderr
    model = json.loads((tmp_path / "d" / "model.json").read_text())
    held = model["identification"]["priors"]["at_prior"]
    wrist = [n for n in held if n.startswith(("joint5.", "joint6."))]
    assert len(wrist) >= 4, held
    assert kincal.load_robot(str(tmp_path / "d" / "model.json")).identified


def test_the_choice_offers_compliance_exactly_where_the_core_fits_it(robots):
    """The search offers a candidate only where the core will fit the model with it (the core's
    refusal: more free parameters without a prior, frames held as unseen included, than measured
    points; as many is fitted). Joint compliance with the model's masses adds only the compliances of
    the joints these poses load (the core holds the others), and its admission counts them so. Truth:
    the kr500 with default_truth (seed 3) and 0.003 deg/kN m compliance, one reflector, 0.02 mm noise;
    campaigns of 7-13 configurations, one point each, ten draws: the search agrees with the core on
    every one, and the draws reach both a refusal and a fit with exactly as many points as such
    parameters (the rule's edge)."""
    from kincal.calibration.effect_choice import SerialProblem, candidates
    from kincal.calibration.fitting import FitOptions, folds
    kr500 = robots["kr500"]
    truth = ident.default_truth(kr500, seed=3, compliance=0.003)
    fit = FitOptions()
    jc = JointCompliance("masses")
    refused = edge = 0
    for draw in range(10):
        for n in range(7, 14):
            data = ident.simulate(truth, n, seed=100 * draw + n, targets=1)
            problem = SerialProblem(kr500, data, folds(data, 3, 0), fit, candidates(kr500, data)[0])
            try:
                problem.linearise([])
            except ValueError:  # the geometry alone is refused: nothing to offer
                continue
            try:
                fit.fit(kr500, data, ident.effect_choice.expand([jc], kr500)[0], gravity="masses")
                fits = True
            except ValueError as e:
                assert "too few" in str(e)
                fits = False
            assert problem.admits([], jc) == fits, (draw, n, fits)
            res = problem.fits[0][1]
            free = (np.asarray(res.fixed) == 0) & ~np.isfinite(np.asarray(res.prior_sd))
            refused += not fits
            edge += fits and int(free.sum()) + int(np.sum(res.held_unseen)) + problem.size(jc) == n
    assert refused and edge, (refused, edge)
