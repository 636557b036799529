"""Real data, the mission's user path on the UR10 of ../shared/data/ipa-robot-accuracy (Landgraf et al.,
CASE 2021; laser tracker and T-Mac probe, each series from its own tracker placement): `kincal
diagnose` on series B with its defaults (the fitting options identify uses: priors, Huber bent where the residuals say,
the effects the data choose), writes model.json; `kincal validate` checks it on series A, C and D,
refitting only the tracker placement and the probe offset.

Issue 29 asks for A <= 0.46, C <= 0.56, D <= 0.38 mm (3-D RMS; 5% better than the better start of
the session before: geometry 0.512 / 0.591 / 0.449, compliance 0.482 / 0.675 / 0.398). Measured on
2026-11-25: A 0.495, C 0.509, D 0.406 mm. Since 2026-11-27 a joint_map step's order and smoothing
are chosen again by refits holding out ranges of the joint's angle (the linearisation fitted the
model's own parameters on the held ranges too, and kept order 6 at smoothing 0.001, which predicts
B's held ranges at 0.496 mm against 0.411 for order 6 at 0.01): A 0.452, C 0.496, D 0.379 mm, all
three met (D by 0.001 mm; BENCHMARKS.md shows how the choice moves with the number of ranges).
Since the nineteenth session a target's depth along an axis every tool orientation of a campaign
shares is held (the core's hold_unseen_frames), at the model's own offset in validate: series D holds
the probe in two orientations about one axis, and its refit had fitted that depth on D's own rows
through a lever of 2e-4 (in-sample: the figure it reports). D was then 0.3802 mm, issue 29's 0.38 not
met by 0.0002 mm; A and C unchanged (0.4517, 0.4961). Since the thirty-first session validate's refit
bends its robust loss where every other fit does, at the residuals' robust spread (its own fixed
0.1 mm was the one default issue 29's single fitting engine had left apart; 0.83-1.09 mm here):
A 0.4512, C 0.4955, D 0.3791 mm, all three met again (D by 0.0009 mm). The
diagnosis names joint compliance (every loaded joint, the model's masses) and a smooth joint_map of
joint 1, a periodic effect credited with what it gains on held-out ranges of its angle. This test
holds that ground: each series within issue 29's target and within 2% of those figures, far below the
nominal model, the effects named, and the warning where a series leaves the angles they were fitted
on (C runs joint 1 at -308..-180 deg, B at -180..-45)."""

from __future__ import annotations

import json

import pytest

import kincal
from kincal.io import datasets
from kincal.calibration import identify as ident

from conftest import SHARED, run

BASE = SHARED / "data" / "ipa-robot-accuracy"
FILES = {"A": "Series_A/measurements_grid.csv", "B": "Series_B/measurements_joint_configurations.csv",
         "C": "Series_C/measurements_random_poses.csv", "D": "Series_D/measurements_iso_cubes.csv"}
#: the 3-D RMS (mm) this path measured on 2026-11-29, and issue 29's targets
MEASURED = {"A": 0.4512, "C": 0.4955, "D": 0.3791}
TARGET = {"A": 0.46, "C": 0.56, "D": 0.38}


def test_ur10_diagnose_on_b_validate_on_the_others(tmp_path):
    if not BASE.exists():
        pytest.skip("the shared UR10 data are not present")
    robot = kincal.load_robot("ur10")
    for k, f in FILES.items():
        (tmp_path / f"{k}.csv").write_text(ident.measurements_csv(datasets.read_ipa(BASE / f), robot.dof))
    r = run("kincal", "diagnose", "--robot", "ur10", "--data", str(tmp_path / "B.csv"), "--out", str(tmp_path / "d"))
    assert r.returncode == 0, r.stderr
    steps = json.loads((tmp_path / "d" / "diagnosis.json").read_text())["steps"]
    assert [(s["effect"], s["joint"]) for s in steps] == [("joint_compliance", None), ("joint_map", 1)]
    for k, rms in MEASURED.items():
        r = run("kincal", "validate", "--model", str(tmp_path / "d" / "model.json"), "--data",
                str(tmp_path / f"{k}.csv"), "--out", str(tmp_path / f"v{k}.json"))
        assert r.returncode == 0, r.stderr
        v = json.loads((tmp_path / f"v{k}.json").read_text())
        print(f"series {k}: RMS {v['before_rms_mm']:.3f} -> {v['rms_mm']:.3f} mm")
        assert v["rms_mm"] <= 1.02 * rms, (k, v["rms_mm"])
        assert v["rms_mm"] <= TARGET[k], (k, v["rms_mm"])
        assert v["loss"]["scale_from"] == "the residuals' robust spread" and v["loss"]["scale_mm"] > 0.1
        assert "the target offsets started from the model's" in v["refitted"]
        assert v["rms_mm"] < 0.7 * v["before_rms_mm"]
        if k == "C":
            joint1 = next(e for e in v["extrapolated"] if e["joint"] == 1)
            assert joint1["share_outside"] > 0.99 and "joint 1 is outside" in r.stdout
