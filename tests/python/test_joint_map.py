"""joint_map (a smooth periodic error of one joint's angle, any order) through every consumer, and the
diagnosis beyond the library: hidden gear errors of the 3rd and 5th order named as joint_map on
their joint, and what remains scored against every candidate variable.

Truth of the diagnosis cases: kr500 with 1 mm / 0.05 deg geometric errors (seed 3), tracker at
DEFAULT_INSTRUMENT, 250 poses x 3 reflectors (seed 4), 0.02 mm noise per coordinate (0.0346 mm RMS
per point), plus the gear error of the case: a pure harmonic of the joint angle (3 or 5 cycles per
turn) of the amplitude given."""

from __future__ import annotations

import json

import numpy as np
import pytest

import kincal
from kincal import _core
from kincal import diagnose as dg
from kincal.calibration import identify as ident
from kincal.diagnose import residual_vars

from conftest import run

NOISE = 0.02 * np.sqrt(3)  # RMS per point of the tracker noise
D = np.radians


def _write_csv(path, header, rows):
    path.write_text(",".join(header) + "\n" + "".join(",".join(repr(float(v)) for v in r) + "\n" for r in rows))


def _harmonic(order: int, sin_deg: float, cos_deg: float) -> list:
    """A joint_map of that order whose only non-zero amplitudes are the highest order's (rad)."""
    return [0.0] * (2 * order - 2) + [D(sin_deg), D(cos_deg)]


@pytest.fixture(scope="module")
def kr500():
    return kincal.load_robot("kr500")


def _truth(robot):
    return robot.with_calibrated(3, 1.0, 0.05, 0.0, ident.DEFAULT_INSTRUMENT)


def test_effect_parameters_and_errors():
    e = _core.Effect("joint_map", 3, order=5)
    assert (e.order, e.size, e.label) == (5, 10, "joint_map(joint 3)")
    assert e.parameter_names[-2:] == ["map_sin5", "map_cos5"] and e.file_units[0] == "deg"
    assert e == _core.Effect("joint_map", 3, harmonics=[1, 2, 3, 4, 5]) and e != _core.Effect("joint_map", 3, order=4)
    assert hash(e) == hash(_core.Effect("joint_map", 3, order=5))
    with pytest.raises(ValueError, match="order"):
        _core.Effect("backlash", 2, order=3)
    with pytest.raises(ValueError, match="1..K"):
        _core.Effect("joint_map", 2, harmonics=[2, 3])
    robot = kincal.load_robot("kr500")
    assert ident.parse_effects("joint_map:2:6", robot) == [_core.Effect("joint_map", 2, order=6)]
    assert len(ident.parse_effects("joint_map", robot)) == 6
    e, v = ident.parse_hidden_effect("joint_map:4:0,0,0.01,0.02", 6)
    assert e.order == 2 and np.allclose(np.degrees(v), [0, 0, 0.01, 0.02])
    with pytest.raises(ValueError, match="even number"):
        ident.parse_hidden_effect("joint_map:4:0,0,0.01", 6)


def test_model_file_fk_and_compensation(tmp_path):
    """A model with joint maps of order 5 on joint 3 and 3 on joint 5 (0.004-0.015 deg per order;
    kr500 with 1 mm / 0.05 deg errors and 0.003 deg/kN m compliance, seed 5): the model JSON carries
    them (with their order) and reads back equal; kincal fk applies them; kincal compensate and
    kincal-compensate agree to 1e-9 deg, and FK of the compensated program is the program (1e-9 mm)."""
    base = kincal.load_robot("kr500").with_calibrated(5, 1.0, 0.05, 0.003)
    maps = [(_core.Effect("joint_map", 3, order=5), list(D([0.015, -0.004, 0.006, 0.008, -0.005, 0.004, 0.007,
                                                           -0.006, 0.004, 0.005]))),
            (_core.Effect("joint_map", 5, order=3), list(D([-0.01, 0.006, 0.004, 0.0, 0.008, -0.003])))]
    robot = base.with_effects(maps, 20.0)
    (tmp_path / "m.json").write_text(robot.to_json())
    doc = json.loads((tmp_path / "m.json").read_text())
    written = [e for e in doc["calibrated"]["effects"] if e["effect"] == "joint_map"]
    assert [(e["joint"], e["order"], len(e["parameters"])) for e in written] == [(3, 5, 10), (5, 3, 6)]
    back = kincal.load_robot(str(tmp_path / "m.json"))
    got = {(e.name, e.joint, e.order): v for e, v in back.effects}
    for e, v in maps:
        assert np.allclose(got[("joint_map", e.joint, e.order)], v, rtol=0, atol=1e-15)
    # kincal fk (file) equals fk in memory, and the maps move the point
    rng = np.random.default_rng(2)
    lim = np.asarray(robot.limits_deg)
    q = rng.uniform(lim[:, 0] * 0.8, lim[:, 1] * 0.8, (40, 6))
    _write_csv(tmp_path / "q.csv", [f"q{j}" for j in range(1, 7)], q)
    r = run("kincal", "fk", "--robot", str(tmp_path / "m.json"), "--joints", str(tmp_path / "q.csv"), "--out",
            str(tmp_path / "p.csv"))
    assert r.returncode == 0, r.stderr
    p_file = np.loadtxt(tmp_path / "p.csv", delimiter=",", skiprows=1)
    p_mem = kincal.fk(robot, q)
    assert np.max(np.abs(p_file[:, :3] - p_mem[:, :3])) < 1e-6
    assert np.max(np.linalg.norm(p_mem[:, :3] - kincal.fk(base, q)[:, :3], axis=1)) > 0.1
    # compensation: Python and the standalone C++ program agree, and the program is reached
    poses = kincal.fk(base, q[:20])
    _write_csv(tmp_path / "path.csv", ["x", "y", "z", "a", "b", "c"], poses)
    args = ["--model", str(tmp_path / "m.json"), "--program", str(tmp_path / "path.csv")]
    r = run("kincal", "compensate", *args, "--out", str(tmp_path / "py.csv"))
    assert r.returncode == 0, r.stderr
    r = run("kincal-compensate", *args, "--out", str(tmp_path / "cpp.csv"))
    assert r.returncode == 0, r.stderr
    qp = np.loadtxt(tmp_path / "py.csv", delimiter=",", skiprows=1)
    qc = np.loadtxt(tmp_path / "cpp.csv", delimiter=",", skiprows=1)
    assert np.max(np.abs(qp - qc)) <= 1e-9
    # in memory with the same options: the same joints (the files carry 1e-10 deg); to convergence,
    # the program reached
    assert np.max(np.abs(kincal.compensate(robot, poses)["q_deg"] - qp)) < 1e-9
    res = kincal.compensate(robot, poses, epsilon=1e-20)
    reached = kincal.run_program(robot, res["q_deg"])
    assert np.max(np.linalg.norm(reached[:, :3] - poses[:, :3], axis=1)) < 1e-9


@pytest.mark.parametrize("joint,order,amp", [(3, 3, (0.015, 0.01)), (4, 5, (0.012, -0.008))])
def test_hidden_gear_error_is_named(kr500, joint, order, amp):
    """A gear error of the given order (only that harmonic, amplitudes in deg) on one joint: named
    joint_map on that joint, of an order that carries it, and the cross-validated RMS ends within
    1.5 times the noise."""
    data = ident.simulate(_truth(kr500), 250, seed=4, targets=3,
                          effects=[("joint_map", joint, _harmonic(order, *amp))])
    out = dg.diagnose(kr500, data)
    named = [(s["effect"], s["joint"]) for s in out["steps"]]
    print(f"order {order} on joint {joint}: named {named}, orders {[s.get('order') for s in out['steps']]}, "
          f"CV RMS {out['steps'][0]['rms_before_mm'] * 1000:.1f} -> {out['final_rms_mm'] * 1000:.1f} um "
          f"(noise {NOISE * 1000:.1f} um)")
    assert named == [("joint_map", joint)]
    assert order <= out["steps"][0]["order"] <= dg.serial.MAX_MAP_ORDER
    assert out["steps"][0]["evidence"]["order"] == out["steps"][0]["order"]
    assert out["final_rms_mm"] <= 1.5 * NOISE
    assert out["steps"][0]["rms_before_mm"] > 2 * out["final_rms_mm"]
    assert out["residual_variables"][0]["share"] < residual_vars.CARRIES  # nothing left to carry


def test_what_remains_is_carried_by_its_variable(kr500):
    """The diagnosis stopped before it adds anything (max_steps 0) on the 3rd-order case: the joint's
    angle carries what remains, most of it; with nothing hidden no variable carries 5%."""
    data = ident.simulate(_truth(kr500), 250, seed=4, targets=3, effects=[("joint_map", 3, _harmonic(3, 0.015, 0.01))])
    out = dg.diagnose(kr500, data, max_steps=0)
    top = out["residual_variables"][0]
    print("with the gear error:", [(s["variable"], round(s["share"], 3)) for s in out["residual_variables"][:4]])
    assert top["variable"] == "q3" and top["share"] > 0.5
    assert "q3" in out["residual_summary"]
    shares = [s["share"] for s in out["residual_variables"]]
    assert shares == sorted(shares, reverse=True)
    names = {s["variable"] for s in out["residual_variables"]}
    assert {"q1", "q6", "tau2", "temperature_c", "order", "dir1"} <= names
    quiet = ident.simulate(_truth(kr500), 250, seed=8, targets=3)
    quiet = quiet.with_columns(time_s=12.0 * np.arange(len(quiet), dtype=float))  # when each point was measured
    clean = dg.diagnose(kr500, quiet, max_steps=0)
    assert "time_s" in {s["variable"] for s in clean["residual_variables"]}
    print("nothing hidden:", [(s["variable"], round(s["share"], 3)) for s in clean["residual_variables"][:4]])
    assert clean["residual_variables"][0]["share"] < residual_vars.CARRIES
    assert "no variable carries" in clean["residual_summary"]


def test_identify_penalties(kr500):
    """identify's ridge penalties (parameter name, weight in mm per rad): truth kr500 with 1 mm /
    0.05 deg errors (seed 3) and a joint_map of order 3 on joint 2 (amplitudes 0.004-0.02 deg),
    150 poses x 3 reflectors, 0.02 mm noise. Without a penalty the fit reaches the noise and the
    third order (which the geometry cannot mimic; the first orders trade with the joint lines) is
    recovered within what the fit says of it; with an overwhelming penalty the map stays at zero and
    the fit does not reach the noise; a name the model lacks is an error. Without priors
    (prior_sd={}): with the default priors on the joint lines and none on the map, the map's first
    orders take what the priors hold back from the joint lines and the third order lands 0.0036 deg
    off.
    The recovery is checked on 21 draws (geometric truth's seed, campaign's seed): (3, 5) and, for
    s = 1..20, (3 for odd s and 20 + s for even s, 5 + 10 s). This test asserted the third order within 0.002 deg on the first draw alone
    (0.0018 there); the fit's standard deviation of the cosine is 0.0012-0.0015 deg, and on three of the
    20 others the error was 0.0021-0.0031 deg (an audit, thirty-second session). Now: each third-order
    amplitude within 4 of its own standard deviations of the truth, and the RMS of those 42 z-scores
    between 0.7 and 1.4 (the covariance is honest; measured 0.92, the largest |z| 2.2)."""
    truth_vals = D([0.02, -0.01, 0.004, 0.008, -0.006, 0.012])
    e = _core.Effect("joint_map", 2, order=3)
    z = []
    for ts, cs in [(3, 5)] + [(3 if s % 2 else 20 + s, 5 + 10 * s) for s in range(1, 21)]:
        truth = kr500.with_calibrated(ts, 1.0, 0.05, 0.0, ident.DEFAULT_INSTRUMENT)  # _truth's, seed ts
        draw = ident.simulate(truth, 150, seed=cs, targets=3, effects=[("joint_map", 2, truth_vals)])
        fit = ident.identify(kr500, draw, effects=[e], k_folds=0, prior_sd={})
        assert fit.fit.rms_mm < 1.1 * NOISE, (ts, cs)
        got = {p["name"]: p for p in fit.parameters()}
        for k, t in (("sin3", truth_vals[4]), ("cos3", truth_vals[5])):
            p = got[f"joint2.map_{k}"]
            z.append((p["value"] - np.degrees(t)) / p["stddev"])
            assert abs(z[-1]) < 4, (ts, cs, k, p)
        if (ts, cs) == (3, 5):
            data = draw
    print("third-order z-scores:", np.round(z, 2), "RMS", round(float(np.sqrt(np.mean(np.square(z)))), 3))
    assert 0.7 < np.sqrt(np.mean(np.square(z))) < 1.4
    names = [f"joint2.{n}" for n in e.parameter_names]
    held = ident.identify(kr500, data, effects=[e], k_folds=0, penalties=[(n, 1e9) for n in names], prior_sd={})
    (_, got0), = held.robot.effects
    assert np.max(np.abs(np.degrees(got0))) < 1e-6
    assert held.fit.rms_mm > 2 * NOISE
    with pytest.raises(ValueError, match="joint5.map_sin1"):
        ident.identify(kr500, data, effects=[e], k_folds=0, penalties=[("joint5.map_sin1", 1.0)])
