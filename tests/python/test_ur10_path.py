"""Real data, issue 14's user path on the UR10 of ../shared/data/ipa-robot-accuracy (Landgraf et al.,
CASE 2021; laser tracker and T-Mac probe, each series from its own tracker placement): `kincal
diagnose` on series B, starting from geometry + joint compliance, writes model.json; `kincal
validate` checks it on series A, C and D, refitting only the tracker placement and the probe offset.

Issue 14 asks for at most 0.30 mm RMS on A and D and 0.45 mm on C. That is NOT met: the 3-D RMS
measured on this path is A 0.482, C 0.675, D 0.398 mm (BENCHMARKS.md says why per-joint maps cannot
reach the targets on these data). This test records where the path stands, so that a change that
loses ground fails: each series within 5% of those figures and far below the nominal model, the
effects that got it there named, and the warning where a series leaves the angles they were
fitted on (C runs joint 1 at -308..-180 deg, B at -180..-45)."""

from __future__ import annotations

import json

import pytest

import kincal
from kincal import datasets
from kincal import identify as ident

from conftest import SHARED, run

BASE = SHARED / "data" / "ipa-robot-accuracy"
FILES = {"A": "Series_A/measurements_grid.csv", "B": "Series_B/measurements_joint_configurations.csv",
         "C": "Series_C/measurements_random_poses.csv", "D": "Series_D/measurements_iso_cubes.csv"}
#: the 3-D RMS (mm) this path measured on 2026-11-24 (examples/ur10_ipa.py prints the same)
MEASURED = {"A": 0.482, "C": 0.675, "D": 0.398}


def test_ur10_diagnose_on_b_validate_on_the_others(tmp_path):
    if not BASE.exists():
        pytest.skip("the shared UR10 data are not present")
    robot = kincal.load_robot("ur10")
    for k, f in FILES.items():
        (tmp_path / f"{k}.csv").write_text(ident.measurements_csv(datasets.read_ipa(BASE / f), robot.dof))
    r = run("kincal", "diagnose", "--robot", "ur10", "--data", str(tmp_path / "B.csv"), "--effects",
            "joint_compliance", "--out", str(tmp_path / "d"))
    assert r.returncode == 0, r.stderr
    steps = json.loads((tmp_path / "d" / "diagnosis.json").read_text())["steps"]
    assert {(s["effect"], s["joint"]) for s in steps} == {("joint_map", 1), ("transmission_error", 2), ("joint_map", 3)}
    for k, rms in MEASURED.items():
        r = run("kincal", "validate", "--model", str(tmp_path / "d" / "model.json"), "--data",
                str(tmp_path / f"{k}.csv"), "--out", str(tmp_path / f"v{k}.json"))
        assert r.returncode == 0, r.stderr
        v = json.loads((tmp_path / f"v{k}.json").read_text())
        print(f"series {k}: RMS {v['before_rms_mm']:.3f} -> {v['rms_mm']:.3f} mm")
        assert v["rms_mm"] <= 1.05 * rms, (k, v["rms_mm"])
        assert v["rms_mm"] < 0.7 * v["before_rms_mm"]
        if k == "C":
            joint1 = next(e for e in v["extrapolated"] if e["joint"] == 1)
            assert joint1["share_outside"] > 0.99 and "joint 1 is outside" in r.stdout
