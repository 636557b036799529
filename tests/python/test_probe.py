"""Measurements without a tracker through the command line: `kincal simulate --kind` writes a probe
campaign and its artifact file, `kincal identify --artifact` calibrates from it, and bad probe input
is one `file:line: cause` message, exit 1, nothing written. Truth: kincal simulate's default (the
kr500 with 1 mm / 0.05 deg geometric errors and joint compliance 0.003 deg/kNm, --seed 3), probe noise
0.005 mm along each constraint."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

import kincal
from kincal import _core
from kincal.calibration import identify as ident, simulation
from kincal.calibration.probe_plan import ball_centres as _balls, rigid_rms as _rigid_rms

from conftest import run


def test_spheres_with_a_length_bar_from_the_command_line(tmp_path):
    d = tmp_path
    r = run("kincal", "simulate", "--robot", "kr500", "--kind", "sphere", "--stations", "6", "--touches", "25",
            "--cone", "60", "--out", str(d / "s.csv"), "--truth-out", str(d / "truth.json"), "--seed", "3")
    assert r.returncode == 0, r.stderr
    assert (d / "s-artifact.csv").read_text().startswith("a,b,distance_mm,angle_deg\nS1,S2,")
    r = run("kincal", "identify", "--robot", "kr500", "--data", str(d / "s.csv"), "--artifact",
            str(d / "s-artifact.csv"), "--out", str(d / "model.json"), "--effects", "joint_compliance")
    assert r.returncode == 0, r.stderr
    assert "probe rows only: the stations' unknowns absorb the base frame" in r.stdout
    held = next(line for line in r.stdout.splitlines() if line.startswith("held-out poses"))
    assert float(held.split()[3]) < 0.02  # held-out RMS after (mm), 5 folds of whole configurations
    model = kincal.load_robot(str(d / "model.json"))
    truth = kincal.load_robot(str(d / "truth.json"))
    target = np.asarray(json.loads((d / "model.json").read_text())["identification"]["targets_mm"][0])
    rng = np.random.default_rng(7)
    lim = np.asarray(truth.limits_deg)
    q = rng.uniform(0.9 * lim[:, 0], 0.9 * lim[:, 1], size=(200, 6))
    t = _balls(truth, q, np.array([0, 0, 150.0]))
    before = _rigid_rms(_balls(kincal.load_robot("kr500"), q, np.array([0, 0, 150.0])), t)
    after = _rigid_rms(_balls(model, q, target), t)
    print(f"ball centre RMS after the best rigid transform: nominal {before:.3f} mm, identified {after:.4f} mm")
    assert before > 1.0 and after < 0.03, (before, after)  # measured: 5.05 mm and 0.0087 mm
    assert "scale: not determined" not in r.stdout
    # without the known lengths the summary names the scale as what these data cannot see
    r = run("kincal", "identify", "--robot", "kr500", "--data", str(d / "s.csv"), "--out", str(d / "m2.json"),
            "--effects", "joint_compliance", "--folds", "0")
    assert r.returncode == 0, r.stderr
    assert "scale: not determined by these data" in r.stdout and "--artifact" in r.stdout


def _similarity_rms(a: np.ndarray, b: np.ndarray) -> float:
    """RMS of the 3-D distance between points b and a after the best similarity transform of a onto b
    (rotation, translation and scale: Umeyama)."""
    ma, mb = a.mean(0), b.mean(0)
    u, s, vt = np.linalg.svd((b - mb).T @ (a - ma) / len(a))
    d = np.diag([1.0, 1.0, np.sign(np.linalg.det(u @ vt))])
    rot = u @ d @ vt
    scale = np.trace(np.diag(s) @ d) / np.mean(np.sum((a - ma) ** 2, axis=1))
    return float(np.sqrt(np.mean(np.sum((scale * (a - ma) @ rot.T - (b - mb)) ** 2, axis=1))))


def test_without_the_length_only_the_scale_is_free(tmp_path):
    """Issue 32: without a known length the ball centres the fit predicts equal those of the fit with
    it after the best similarity transform, to 0.01 mm. Here with identify's defaults (the priors: the
    scale held at its prior) where the C++ test (Stations.WithoutALengthTheScaleIsNamedAndOnlyItIsFree)
    fits without priors. Truths: default_truth seeds 1-10 (the kr500 with 1 mm / 0.05 deg errors and
    joint compliance 0.003 deg/kNm); campaigns: 6 spheres x 25 touches in a 60 deg cone, 0.005 mm
    noise, the one length the distance between the first two spheres; the model joint_compliance, no
    validation; scored on 200 random configurations within 90% of the limits. Measured: 0.0022 mm on
    truth 3, below 0.0003 mm on the nine others. (With priors the priors set the scale and no
    parameter is held for it: this path did not change with the C++ test's fix, and met the claim
    before it too.)"""
    robot = kincal.load_robot("kr500")
    lim = np.asarray(robot.limits_deg)
    gaps = []
    for seed in range(1, 11):
        truth = simulation.default_truth(robot, seed)
        without = simulation.simulate_probe(truth, "sphere", stations=6, touches=25, cone_deg=60, seed=seed,
                                            artifact=False)
        plate = simulation.simulate_probe(truth, "sphere", stations=6, touches=25, cone_deg=60, seed=seed)
        length = tmp_path / f"length{seed}.csv"  # the first of the simulated distances: S1 to S2
        length.write_text("\n".join(_core.format_artifact(plate, 6).splitlines()[:2]) + "\n")
        with_length = _core.read_artifact(str(length), without, 6)
        assert len(with_length.artifact) == 1
        fits = [ident.identify(robot, d, effects="joint_compliance", k_folds=0) for d in (with_length, without)]
        assert fits[0].fit.scale_determined and not fits[1].fit.scale_determined
        q = np.random.default_rng(seed).uniform(0.9 * lim[:, 0], 0.9 * lim[:, 1], size=(200, 6))
        a, b = (_balls(f.robot, q, f.targets[0]) for f in fits)
        gaps.append(_similarity_rms(b, a))
    print("ball centres without the length, after the similarity (mm):", np.round(gaps, 5))
    assert max(gaps) < 0.01, gaps


def test_a_ballbar_and_block_faces_simulate_and_read_back(tmp_path):
    for kind, n in (("distance", 3), ("plane", 4)):
        out = tmp_path / f"{kind}.csv"
        r = run("kincal", "simulate", "--robot", "kr500", "--kind", kind, "--stations", str(n), "--touches", "12",
                "--cone", "40", "--out", str(out))
        assert r.returncode == 0, r.stderr
        data = ident.read_measurements(str(out), kincal.load_robot("kr500"), str(tmp_path / f"{kind}-artifact.csv"))
        assert set(data["station_kinds"]) == {kind} and len(data["station_names"]) == n
        assert len(data["artifact"]) == (n - 1 if kind == "distance" else 4)  # 3 angles and an edge
        probe_rows = data["station"] >= 0
        assert np.all(probe_rows)
        if kind == "distance":  # every ballbar row carries its measured length, near the bar's 150 mm
            assert np.all(np.abs(data["length_mm"] - 150) < 0.1)


@pytest.mark.parametrize("name, rows, artifact, expect", [
    ("few", "0,0,-90,90,0,30,0,sphere,A\n1,5,-90,90,0,30,0,sphere,A\n", None,
     "m.csv:2: station 'A' has 2 row(s); a sphere station needs 3 at least"),
    ("length", "0,0,-90,90,0,30,0,distance,A\n", None, "m.csv:2: a distance row needs its 'length' (mm)"),
    ("artifact", "".join(f"{i},{i},-90,90,0,30,{5 * i},sphere,A\n" for i in range(4)),
     "a,b,distance_mm,angle_deg\nA,B,100,\n", "a.csv:2: station 'B' is in no row of"),
])
def test_bad_probe_input(tmp_path, name, rows, artifact, expect):
    (tmp_path / "m.csv").write_text("pose,q1,q2,q3,q4,q5,q6,kind,station\n" + rows)
    argv = ["identify", "--robot", "kr500", "--data", str(tmp_path / "m.csv"), "--out", str(tmp_path / "o.json"),
            "--folds", "0"]
    if artifact:
        (tmp_path / "a.csv").write_text(artifact)
        argv += ["--artifact", str(tmp_path / "a.csv")]
    r = run("kincal", *argv)
    assert r.returncode == 1
    assert expect in r.stderr, r.stderr
    assert not (tmp_path / "o.json").exists()


def test_the_diagnosis_names_a_backlash_hidden_in_a_sphere_campaign(tmp_path):
    # truth: kincal simulate's default kr500 truth (seed 4) with a backlash of 0.0006 rad per direction
    # sign on joint 1 (the rows carry dir1..dir6); 6 spheres x 40 touches, 60 deg cone, their distances
    from kincal.calibration import simulation as sim
    truth = ident.default_truth(kincal.load_robot("kr500"), seed=4)
    truth = truth.with_effects([(_core.Effect("backlash", 1), [0.0006])], 20.0)
    data = sim.simulate_probe(truth, "sphere", stations=6, touches=40, cone_deg=60, seed=5)
    (tmp_path / "s.csv").write_text(ident.measurements_csv(data, 6))
    (tmp_path / "a.csv").write_text(_core.format_artifact(data, 6))
    r = run("kincal", "diagnose", "--robot", "kr500", "--data", str(tmp_path / "s.csv"), "--artifact",
            str(tmp_path / "a.csv"), "--out", str(tmp_path / "d"))
    assert r.returncode == 0, r.stderr
    assert "step 1: backlash(joint 1)" in r.stderr + r.stdout
    step = json.loads((tmp_path / "d" / "diagnosis.json").read_text())["steps"][0]
    assert (step["effect"], step["joint"]) == ("backlash", 1)
    assert step["rms_after_mm"] < 0.5 * step["rms_before_mm"]  # measured: 1.05 -> 0.26 mm held out
    assert (tmp_path / "d" / "model.json").exists() and (tmp_path / "d" / "report.html").exists()


def test_validate_refits_a_new_probe_campaigns_stations(tmp_path):
    # truth: kincal simulate's default kr500 truth (seed 4); the model identified on one sphere campaign
    # (seed 5) is checked on another of the same truth at other stations (seed 11), only the
    # stations, placement and ball offset refitted
    from kincal.calibration import simulation as sim
    truth = ident.default_truth(kincal.load_robot("kr500"), seed=4)
    for name, seed in (("fit", 5), ("new", 11)):
        data = sim.simulate_probe(truth, "sphere", stations=6, touches=25, cone_deg=60, seed=seed)
        (tmp_path / f"{name}.csv").write_text(ident.measurements_csv(data, 6))
        (tmp_path / f"{name}-a.csv").write_text(_core.format_artifact(data, 6))
    r = run("kincal", "identify", "--robot", "kr500", "--data", str(tmp_path / "fit.csv"), "--artifact",
            str(tmp_path / "fit-a.csv"), "--effects", "joint_compliance", "--folds", "0",
            "--out", str(tmp_path / "cal.json"))
    assert r.returncode == 0, r.stderr
    r = run("kincal", "validate", "--model", str(tmp_path / "cal.json"), "--data", str(tmp_path / "new.csv"),
            "--artifact", str(tmp_path / "new-a.csv"), "--out", str(tmp_path / "v.json"))
    assert r.returncode == 0, r.stderr
    v = json.loads((tmp_path / "v.json").read_text())
    assert "the probe stations" in v["refitted"]
    assert v["before_rms_mm"] > 1.0 and v["rms_mm"] < 0.02, v  # measured: 3.46 -> 0.0084 mm


MUKCA = Path(__file__).resolve().parents[1] / "data" / "mukca"
PLACEMENTS = ("front", "left", "lower_left", "raised_back")


def _mukca_campaign(d: Path, name: str, placements: tuple[str, ...]) -> None:
    """MUKCa's Gen3 lite rows (tests/data/mukca) as a kincal probe campaign: one sphere station per
    placement and socket (angles in deg), the sockets' 50 mm as the artifact."""
    lines, art, pose = ["pose,q1,q2,q3,q4,q5,q6,kind,station"], ["a,b,distance_mm,angle_deg"], 0
    for p in placements:
        for k in (0, 1):
            for q in np.atleast_2d(np.loadtxt(MUKCA / p / f"hole_{k}.csv", delimiter=",")):
                lines.append(f"{pose}," + ",".join(repr(float(v)) for v in np.degrees(q)) + f",sphere,{p}/hole_{k}")
                pose += 1
        art.append(f"{p}/hole_0,{p}/hole_1,50,")
    (d / f"{name}.csv").write_text("\n".join(lines) + "\n")
    (d / f"{name}-artifact.csv").write_text("\n".join(art) + "\n")


def test_mukcas_public_gen3_lite_data_one_placement_held_out(tmp_path):
    # someone else's data and URDF (MUKCa, MIT; tests/data/mukca/README.md): calibrated on three
    # placements of the two-socket artifact, checked on the fourth (its sockets refitted, nothing of
    # the robot): the ball's mean distance from its socket centre, against the nominal URDF's
    urdf = str(MUKCA / "gen3lite.urdf")
    robot = ["--robot", urdf, "--base", "kinova_base_link", "--tip", "ball_link"]
    after = {}
    for held in PLACEMENTS:
        _mukca_campaign(tmp_path, "fit", tuple(p for p in PLACEMENTS if p != held))
        _mukca_campaign(tmp_path, "held", (held,))
        r = run("kincal", "identify", *robot, "--data", str(tmp_path / "fit.csv"), "--artifact",
                str(tmp_path / "fit-artifact.csv"), "--effects", "none", "--folds", "0", "--out", str(tmp_path / "m.json"))
        assert r.returncode == 0, r.stderr
        r = run("kincal", "validate", "--model", str(tmp_path / "m.json"), "--data", str(tmp_path / "held.csv"),
                "--artifact", str(tmp_path / "held-artifact.csv"), "--out", str(tmp_path / "v.json"))
        assert r.returncode == 0, r.stderr
        v = json.loads((tmp_path / "v.json").read_text())
        after[held] = (v["before_mean_mm"], v["mean_mm"])
    print("held-out placement: nominal -> calibrated mean distance from the socket (mm):",
          {k: f"{b:.2f} -> {a:.2f}" for k, (b, a) in after.items()})
    # measured (2026-11-29, validate's bend from the residuals): front 4.77 -> 3.83, left 3.91 -> 1.44,
    # lower_left 4.99 -> 4.74, raised_back 8.95 -> 5.75 (with --loss-scale 0.1, the bend before: 4.64 -> 3.64,
    # 3.91 -> 1.43, 4.90 -> 4.74, 8.84 -> 5.66; the RMS falls with the new bend, 4.81 -> 4.51 mm on front)
    assert all(a < b for b, a in after.values())
