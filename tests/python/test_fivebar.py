"""The five-bar hidden robot through the command line: Table I (real data of the Kiper paper), the
simulated over-constrained 6-bar (truth: kincal's paper_sixbar(seed), stated in fivebar.hpp), the
standalone corrector, and bad input."""

from __future__ import annotations

import json

import numpy as np
import pytest

from kincal import _core
from kincal import fivebar as fb

from conftest import SHARED, run

TABLE = SHARED / "data" / "fivebar-table1.csv"
TABLE_XY = [(212.132, 0), (212.132, 75), (262.132, 75), (262.132, 0), (262.132, -75), (212.132, -75),
            (162.132, -75), (162.132, 0), (162.132, 75)]

needs_table = pytest.mark.skipif(not TABLE.exists(), reason="../shared/data/fivebar-table1.csv is not present")


def _xy(path, pts) -> None:
    path.write_text("x,y\n" + "".join(f"{float(x)!r},{float(y)!r}\n" for x, y in pts))


@pytest.mark.realdata
@needs_table
def test_table1_reproduces_the_paper(tmp_path):
    r = run("kincal", "hidden-robot", "fit", "--data", str(TABLE), "--method", "polynomial", "--score", "desired",
            "--out", str(tmp_path / "p.json"))
    assert r.returncode == 0, r.stderr
    p = json.loads((tmp_path / "p.json").read_text())
    assert p["points"] == [1, 8] and p["method"] == "polynomial"
    assert abs(p["a"] - 149.868) < 5e-4 and abs(p["b"] - 150.0) < 5e-4 and abs(p["c"] - 150.0) < 5e-4
    r = run("kincal", "hidden-robot", "fit", "--data", str(TABLE), "--method", "lsq", "--score", "desired",
            "--out", str(tmp_path / "l.json"))
    l = json.loads((tmp_path / "l.json").read_text())
    assert l["points"] == [1, 3, 4, 8]
    assert abs(l["max_error_mm"] - 0.090) < 0.006


@pytest.mark.realdata
@needs_table
def test_minimax_beats_every_subset_on_table1():
    """Scored against the measured positions, the minimax fit reaches a largest error at least as
    small as the best polynomial pair and the best least-squares subset."""
    pts = fb.read_table(TABLE)
    mm = fb.fit(pts, "minimax")["max_error_mm"]
    assert mm <= fb.fit(pts, "polynomial")["max_error_mm"] + 1e-9
    assert mm <= fb.fit(pts, "lsq")["max_error_mm"] + 1e-9


def test_minimax_scales_to_hundreds_of_points():
    """300 points of the simulated 6-bar (seed 2, 20 um noise): C(300, n) subsets are out of the
    question; the minimax fit improves on the least-squares fit's largest error."""
    truth = _core.paper_sixbar(2)
    rng = np.random.default_rng(1)
    xy = np.c_[rng.uniform(162.132, 262.132, 300), rng.uniform(-75, 75, 300)]
    pts = _core.sixbar_campaign(truth, fb.FiveBar(), None, xy, 0.02, 7)
    nl = fb.fit(pts, "nonlinear")["max_error_mm"]
    mm = fb.fit(pts, "minimax")["max_error_mm"]
    assert mm < nl


def test_sixbar_fit_then_matrix_reaches_30_um(tmp_path):
    """truth: paper_sixbar(1); fit (minimax) on the 9 Table I positions measured with 20 um noise; the
    5 mm grid measured with 1 um noise through the fitted model; 300 random targets off the grid
    measured with 1 um noise: fit alone, then fit + matrix <= 30 um. Error maps are drawn."""
    _xy(tmp_path / "table.csv", TABLE_XY)
    rng = np.random.default_rng(5)
    val = np.c_[rng.uniform(163, 261, 300), rng.uniform(-74, 74, 300)]
    _xy(tmp_path / "val.csv", val)
    steps = [
        ("simulate", "--noise", "0.02", "--targets", str(tmp_path / "table.csv"), "--out", str(tmp_path / "t.csv")),
        ("fit", "--data", str(tmp_path / "t.csv"), "--method", "minimax", "--out", str(tmp_path / "fit.json")),
        ("simulate", "--fit", str(tmp_path / "fit.json"), "--out", str(tmp_path / "grid.csv")),
        ("matrix", "--fit", str(tmp_path / "fit.json"), "--data", str(tmp_path / "grid.csv"), "--out",
         str(tmp_path / "m.json")),
        ("simulate", "--targets", str(tmp_path / "val.csv"), "--out", str(tmp_path / "v0.csv")),
        ("simulate", "--fit", str(tmp_path / "fit.json"), "--targets", str(tmp_path / "val.csv"), "--out",
         str(tmp_path / "v1.csv")),
        ("simulate", "--fit", str(tmp_path / "fit.json"), "--matrix", str(tmp_path / "m.json"), "--targets",
         str(tmp_path / "val.csv"), "--out", str(tmp_path / "v2.csv")),
    ]
    for s in steps:
        r = run("kincal", "hidden-robot", *s)
        assert r.returncode == 0, (s, r.stderr)
    v0, v1, v2 = (fb.read_table(tmp_path / f"v{i}.csv") for i in range(3))
    e0, e1, e2 = (fb.position_errors(v).max() for v in (v0, v1, v2))
    assert e0 > 1.0           # nominal lengths: about the paper's 1.5 mm
    assert e1 < 0.5 * e0      # the hidden-robot fit alone
    assert e2 <= 0.030        # fit + error matrix: the paper's target
    fb.error_map_figure([("nominal", v0), ("after fit", v1), ("after fit + matrix", v2)], str(tmp_path / "maps.png"))
    assert (tmp_path / "maps.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_standalone_corrector_matches_python(tmp_path):
    fit = {"a": 149.9, "b": 150.05, "c": 149.95, "d": 150.1, "method": "test"}
    (tmp_path / "fit.json").write_text(json.dumps(fit))
    truth = _core.paper_sixbar(3)
    grid = _core.sixbar_campaign(truth, fb.model_of(fit), None, fb.grid_targets(), 0.001, 1)
    (tmp_path / "m.json").write_text(_core.ErrorMatrix.from_points(grid, "g").to_json())
    rng = np.random.default_rng(2)
    _xy(tmp_path / "xy.csv", np.c_[rng.uniform(163, 261, 50), rng.uniform(-74, 74, 50)])
    a, b = tmp_path / "a.csv", tmp_path / "b.csv"
    args = ["--fit", str(tmp_path / "fit.json"), "--matrix", str(tmp_path / "m.json"), "--targets", str(tmp_path / "xy.csv")]
    assert run("kincal", "hidden-robot", "command", *args, "--out", str(a)).returncode == 0
    r = run("kincal-compensate", "--fivebar", str(tmp_path / "fit.json"), "--matrix", str(tmp_path / "m.json"),
            "--program", str(tmp_path / "xy.csv"), "--out", str(b))
    assert r.returncode == 0, r.stderr
    qa = np.genfromtxt(a, delimiter=",", names=True)
    qb = np.genfromtxt(b, delimiter=",", names=True)
    assert np.max(np.abs(qa["theta1_deg"] - qb["theta1_deg"])) < 1e-9
    assert np.max(np.abs(qa["theta2_deg"] - qb["theta2_deg"])) < 1e-9
    s = run("kincal-compensate", "--fivebar", str(tmp_path / "fit.json"), "--matrix", str(tmp_path / "m.json"),
            "--stream", stdin=(tmp_path / "xy.csv").read_text())
    lines = s.stdout.strip().splitlines()
    assert lines[0] == "theta1_deg,theta2_deg" and len(lines) == 51
    assert abs(float(lines[1].split(",")[0]) - qa["theta1_deg"][0]) < 1e-9


@pytest.mark.parametrize("case", ["unreachable", "quoted", "offgrid", "badfit"])
def test_hidden_robot_bad_input(tmp_path, case):
    fit = tmp_path / "fit.json"
    fit.write_text(json.dumps({"a": 150, "b": 150, "c": 150, "d": 150}))
    out = tmp_path / "out.json"
    if case == "unreachable":
        _xy(tmp_path / "xy.csv", [(200, 0), (500, 0)])
        r = run("kincal", "hidden-robot", "command", "--fit", str(fit), "--targets", str(tmp_path / "xy.csv"),
                "--out", str(out))
        msg = "xy.csv:3: (500.000000, 0.000000) is out of the hidden robot's reach"  # its second row
    elif case == "quoted":  # a quoted field holding a line break: the core's CSV reader counts the lines
        (tmp_path / "xy.csv").write_text('x,y,note\n200,0,"first\nsecond line"\n\n500,0,far\n')
        r = run("kincal", "hidden-robot", "command", "--fit", str(fit), "--targets", str(tmp_path / "xy.csv"),
                "--out", str(out))
        msg = "xy.csv:5: (500.000000, 0.000000) is out of the hidden robot's reach"  # the row on line 5
    elif case == "offgrid":
        (tmp_path / "g.csv").write_text("point,theta1_deg,theta2_deg,x_desired_mm,y_desired_mm,x_measured_mm,y_measured_mm\n"
                                        "1,0,0,0,0,0,0\n2,0,0,5,0,5,0\n3,0,0,0,5,0,5\n4,0,0,5.5,5,5,5\n")
        r = run("kincal", "hidden-robot", "matrix", "--fit", str(fit), "--data", str(tmp_path / "g.csv"), "--out", str(out))
        msg = "g.csv:3: the desired point is not on a regular grid"
    else:
        fit.write_text(json.dumps({"a": 150, "b": -1, "c": 150, "d": 150}))
        _xy(tmp_path / "xy.csv", [(200, 0)])
        r = run("kincal", "hidden-robot", "command", "--fit", str(fit), "--targets", str(tmp_path / "xy.csv"),
                "--out", str(out))
        msg = "must be positive"
    assert r.returncode == 1
    assert msg in r.stderr, r.stderr
    assert not out.exists()


def test_matrix_refuses_a_grid_another_model_commanded(tmp_path):
    """Truth: the simulated 6-bar of `hidden-robot simulate`; a minimax fit on Table I's 9 positions
    (20 um noise) commands the 5 mm grid. A matrix for a different fit (every length 0.2 mm longer)
    would correct the wrong model: refused, naming the grid's line and the fit, nothing written;
    with the fit that commanded the grid it is written."""
    fit, other = tmp_path / "fit.json", tmp_path / "other.json"
    _xy(tmp_path / "table.csv", TABLE_XY)
    for s in (("simulate", "--noise", "0.02", "--targets", str(tmp_path / "table.csv"), "--out", str(tmp_path / "t.csv")),
              ("fit", "--data", str(tmp_path / "t.csv"), "--method", "minimax", "--out", str(fit)),
              ("simulate", "--fit", str(fit), "--out", str(tmp_path / "grid.csv"))):
        r = run("kincal", "hidden-robot", *s)
        assert r.returncode == 0, (s, r.stderr)
    doc = json.loads(fit.read_text())
    other.write_text(json.dumps({**doc, **{k: doc[k] + 0.2 for k in "abcd"}}))
    out = tmp_path / "m.json"
    r = run("kincal", "hidden-robot", "matrix", "--fit", str(other), "--data", str(tmp_path / "grid.csv"), "--out", str(out))
    assert r.returncode == 1 and "grid.csv:" in r.stderr and f"not commanded by {other}" in r.stderr, r.stderr
    assert not out.exists()
    r = run("kincal", "hidden-robot", "matrix", "--fit", str(fit), "--data", str(tmp_path / "grid.csv"), "--out", str(out))
    assert r.returncode == 0 and out.exists(), r.stderr
    # angles a turn apart are the same command (a controller may count 368.7 for 8.7)
    pts = fb.read_table(str(tmp_path / "grid.csv"))
    turned = dict(pts, theta1_deg=pts["theta1_deg"] + 360.0, theta2_deg=pts["theta2_deg"] - 360.0)
    assert fb.check_commanded_by(fb.load_fit(str(fit)), turned, "fit.json", "grid.csv") is turned


def test_matrix_names_the_line_of_a_point_out_of_reach(tmp_path):
    """A regular grid whose second column (x = 700 mm) the 150 mm links cannot reach: the error
    names the grid's line of the first such point and the fit, no matrix written."""
    (tmp_path / "fit.json").write_text(json.dumps({"a": 150, "b": 150, "c": 150, "d": 150}))
    (tmp_path / "g.csv").write_text("point,theta1_deg,theta2_deg,x_desired_mm,y_desired_mm,x_measured_mm,y_measured_mm\n"
                                    "1,0,0,200,0,200,0\n2,0,0,700,0,700,0\n3,0,0,200,5,200,5\n4,0,0,700,5,700,5\n")
    out = tmp_path / "m.json"
    r = run("kincal", "hidden-robot", "matrix", "--fit", str(tmp_path / "fit.json"), "--data", str(tmp_path / "g.csv"),
            "--out", str(out))
    assert r.returncode == 1 and f"{tmp_path / 'g.csv'}:3: (700.000000, 0.000000) is out of the hidden robot's reach" \
        in r.stderr, r.stderr
    assert not out.exists()
