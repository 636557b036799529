"""Compliance without a mass table (issue 17, item 4): a URDF stripped of its <inertial> tags gets its
gravity torques from identified mass moments (--gravity auto chooses that), and predicts held-out
configurations as well as the run with the true masses; the written model carries the deflection."""

from __future__ import annotations

import json
import re

import numpy as np
import pytest

import kincal
from kincal import _core
from kincal.calibration import identify as ident
from kincal.io.urdf import spec_urdf

from conftest import run

NOISE_MM = 0.02  # the simulated tracker's noise per coordinate


@pytest.fixture(scope="module")
def urdfs(tmp_path_factory, kr500):
    """The kr500's geometry and masses as a URDF, and the same URDF without its inertial tags."""
    d = tmp_path_factory.mktemp("gravity")
    text = spec_urdf(json.loads(kr500.to_json())["nominal"], "kr500")
    assert text.count("<inertial>") == 6
    stripped = re.sub(r"\s*<inertial>.*?</inertial>", "", text, flags=re.S)
    assert "<inertial>" not in stripped and "mass" not in stripped
    (d / "with.urdf").write_text(text)
    (d / "without.urdf").write_text(stripped)
    return d / "with.urdf", d / "without.urdf"


def _held_out_rms(res: ident.Identification, data: kincal.MeasurementSet) -> float:
    return float(np.sqrt(np.mean(np.asarray(_core.point_errors(res.robot, res.targets, data)) ** 2)))


@pytest.mark.parametrize("seed", [3, 8])
def test_fitted_gravity_predicts_as_well_as_the_true_masses(urdfs, seed):
    # truth: the URDF robot (its masses) with 1 mm / 0.05 deg geometric errors and compliance
    # 0.003 deg/kNm x U(0.5, 1.5) per loaded joint, seen from DEFAULT_INSTRUMENT; 80 configurations
    # with 3 reflectors and 0.02 mm noise to fit, 200 other whole configurations held out (the same
    # noise), and the same 200 noise-free
    with_masses, without = (kincal.load_robot(str(p)) for p in urdfs)
    truth = ident.default_truth(with_masses, seed=seed, compliance=0.003)
    fit = ident.simulate(truth, 80, seed=seed, noise_mm=NOISE_MM, targets=3)
    held = ident.simulate(truth, 200, seed=seed + 100, noise_mm=NOISE_MM, targets=3)
    exact = ident.simulate(truth, 200, seed=seed + 100, noise_mm=0.0, targets=3)
    assert not set(map(tuple, np.round(fit["q_deg"], 6))) & set(map(tuple, np.round(held["q_deg"], 6)))
    masses = ident.identify(with_masses, fit, k_folds=0)
    fitted = ident.identify(without, fit, k_folds=0)  # --gravity auto: no masses, so fit
    rigid = ident.identify(without, fit, effects="none", k_folds=0)
    assert masses.fit.layout.gravity == "masses" and fitted.fit.layout.gravity == "fit"
    e_masses, e_fitted, e_rigid = (_held_out_rms(r, held) for r in (masses, fitted, rigid))
    x_masses, x_fitted = (_held_out_rms(r, exact) for r in (masses, fitted))
    print(f"seed {seed}: held-out RMS (mm) true masses {e_masses:.4f}, fitted moments {e_fitted:.4f}, "
          f"no compliance {e_rigid:.4f}; against the noise-free truth {x_masses:.4f} / {x_fitted:.4f}")
    # the compliance is identified (the deflection is there: without it the error is many times the noise)
    assert e_rigid > 5 * e_fitted
    # the done-when figure: within 10% of the run with the true masses
    assert e_fitted <= 1.10 * e_masses
    # compliances and moments free but the held scale; the summary and the JSON say which gravity
    fx = {p["name"]: p for p in fitted.parameters()}
    assert fx["joint2.compliance"]["fixed"] and "scale" in fx["joint2.compliance"]["reason"]
    assert not fx["joint3.compliance"]["fixed"] and not fx["link3.moment_u"]["fixed"]
    assert "mass moments identified" in fitted.summary() and "from the model's link masses" in masses.summary()
    doc = json.loads(fitted.model_json())
    assert doc["identification"]["gravity"]["source"] == "fit"
    assert doc["identification"]["gravity"]["held_scale"]["parameter"] == "joint2.compliance"
    assert json.loads(masses.model_json())["identification"]["gravity"]["source"] == "masses"
    # the written model, read back, predicts with the identified deflection (fk, compensate read it)
    back = kincal.Robot.from_json(fitted.model_json(), "<written>")
    assert np.allclose(_core.point_errors(back, fitted.targets, held), _core.point_errors(fitted.robot, fitted.targets, held),
                       atol=1e-9)


def test_gravity_option_on_the_command_line(tmp_path, urdfs, kr500):
    # --gravity masses on a URDF without masses: one clear error, no model written; --gravity fit on
    # the built-in kr500 (it has masses) fits the moments and says so
    truth = ident.default_truth(kr500, seed=2)
    ident_data = ident.simulate(truth, 40, seed=2, noise_mm=NOISE_MM, targets=3)
    (tmp_path / "m.csv").write_text(ident.measurements_csv(ident_data, 6))
    out = tmp_path / "model.json"
    r = run("kincal", "identify", "--robot", str(urdfs[1]), "--data", str(tmp_path / "m.csv"), "--out", str(out),
            "--gravity", "masses", "--folds", "0")
    assert r.returncode != 0 and "no link masses" in r.stderr and not out.exists()
    r = run("kincal", "identify", "--robot", "kr500", "--data", str(tmp_path / "m.csv"), "--out", str(out),
            "--gravity", "fit", "--folds", "0")
    assert r.returncode == 0, r.stderr
    assert "mass moments identified" in r.stdout
    assert json.loads(out.read_text())["identification"]["gravity"]["source"] == "fit"
