"""Derivative analysis (kincal feed): a synthetic path with known derivatives, toppra as the peer for
eq. 21, violations found where they are, and the paper's use case on kr500."""

from __future__ import annotations

import json
import os
import subprocess
from pathlib import Path

import numpy as np
import pytest

from kincal.programs import feed

from conftest import run

# Synthetic truth: a helix in joint space traversed at unit speed in s (so s is its arc length):
# q1 = R cos(k s), q2 = R sin(k s), q3 = c k s, q4 = 0.1 rad, k = 1 / sqrt(R^2 + c^2).
R, C = 0.8, 0.5
K = 1 / np.sqrt(R * R + C * C)
S = 2.0


def helix(s):
    q = np.c_[R * np.cos(K * s), R * np.sin(K * s), C * K * s, 0.1 + 0 * s]
    d1 = np.c_[-R * K * np.sin(K * s), R * K * np.cos(K * s), C * K + 0 * s, 0 * s]
    d2 = np.c_[-R * K ** 2 * np.cos(K * s), -R * K ** 2 * np.sin(K * s), 0 * s, 0 * s]
    d3 = np.c_[R * K ** 3 * np.sin(K * s), -R * K ** 3 * np.cos(K * s), 0 * s, 0 * s]
    return q, d1, d2, d3


LIM_V = np.array([60.0, 50.0, 40.0, 30.0])       # deg/s
LIM_A = np.array([120.0, 100.0, 80.0, 60.0])     # deg/s^2
LIM_J = np.array([1200.0, 1000.0, 800.0, 600.0])  # deg/s^3


def test_derivatives_and_feed_limits_match_the_analytic_ones():
    """297 program points of the helix: the spline derivatives in s are within 1e-5 of the analytic
    ones (the chord-length s of the paper differs from the arc length by 3e-6 rad here), and so are
    the feed limits of eqs. 21, 27 and 28 (relative). The paper's linear interpolation makes third
    derivatives 1000 times too large: it invents jerk."""
    prog = np.degrees(helix(np.linspace(0, S, 297))[0])
    res = feed.analyse(prog, LIM_V, LIM_A, LIM_J, optimal=False)
    arr = res["arrays"]
    _, e1, e2, e3 = helix(arr["s"])
    assert abs(res["s_total_rad"] - S) < 1e-5
    for got, exp in ((arr["d1"], e1), (arr["d2"], e2), (arr["d3"], e3)):
        assert np.max(np.abs(got - exp)) < 1e-5
    v, a, j = np.radians(LIM_V), np.radians(LIM_A), np.radians(LIM_J)
    sv = 1 / np.max(np.abs(e1) / v, axis=1)
    sa = np.sqrt(1 / np.max(np.abs(e2) / a, axis=1))
    sj = np.cbrt(1 / np.max(np.abs(e3) / j, axis=1))
    for got, exp in ((arr["sv"], sv), (arr["sa"], sa), (arr["sj"], sj)):
        assert np.max(np.abs(got / exp - 1)) < 1e-4
    lin = feed.analyse(prog, LIM_V, LIM_A, LIM_J, method="linear", optimal=False)["arrays"]
    assert np.max(np.abs(lin["d3"] - e3)) > 1000 * np.max(np.abs(e3))


@pytest.mark.peer
def test_eq21_equals_toppra_velocity_constraint():
    """toppra's JointVelocityConstraint on the same path (our resampled derivative q'(s) given to it
    as the path) bounds s-dot^2; its square root equals eq. 21 to the peer's own precision. toppra
    0.6.10 (PyPI wheel, Cython) keeps its s-dot bounds in C `float` variables ("cdef float sdmin,
    sdmax" in _CythonUtils.pyx), so it rounds to single precision: the agreement is bounded by
    float32's epsilon 2**-23 = 1.2e-7 relative (measured: 8e-8). The 1e-9 check is against toppra's
    C++ library below."""
    toppra = pytest.importorskip("toppra")
    from toppra.constraint import JointVelocityConstraint

    prog = np.degrees(helix(np.linspace(0, S, 297))[0])
    res = feed.analyse(prog, LIM_V, LIM_A, LIM_J, optimal=False)
    arr = res["arrays"]

    class GivenPath(toppra.interpolator.AbstractGeometricPath):
        def __call__(self, ss, order=0):
            assert order == 1 and np.array_equal(ss, arr["s"])
            return arr["d1"]

        @property
        def dof(self):
            return 4

        @property
        def path_interval(self):
            return np.array([arr["s"][0], arr["s"][-1]])

    vlim = np.radians(np.c_[-LIM_V, LIM_V])
    *_, xbound = JointVelocityConstraint(vlim).compute_constraint_params(GivenPath(), arr["s"])
    assert np.max(np.abs(np.sqrt(xbound[:, 1]) / arr["sv"] - 1)) < 2.0 ** -23


PEER = Path(__file__).resolve().parents[2] / "build" / "cpp" / "toppra_velocity_bound"


def toppra_x_bounds(s: np.ndarray, d1: np.ndarray, v_rad: np.ndarray) -> np.ndarray:
    """toppra's C++ LinearJointVelocity (double precision; cmeel-toppra's libtoppra from PyPI, run
    by tests/peers/toppra_velocity_bound.cpp) on the path given by q'(s): bounds on s-dot^2."""
    if not PEER.exists():
        if os.environ.get("CI"):
            pytest.fail(f"{PEER} was not built: scripts/setup.sh installs cmeel-toppra for it")
        pytest.skip(f"{PEER} not built (needs cmeel-toppra, see scripts/setup.sh)")
    lines = [f"{d1.shape[1]} {len(s)}", " ".join(repr(float(x)) for x in v_rad)]
    lines += [" ".join(repr(float(x)) for x in (si, *row)) for si, row in zip(s, d1)]
    out = subprocess.run([str(PEER)], input="\n".join(lines) + "\n", capture_output=True, text=True, check=True)
    return np.loadtxt(out.stdout.splitlines(), ndmin=2)


@pytest.mark.peer
@pytest.mark.parametrize("path", ["helix", "random"])
def test_eq21_equals_toppra_cpp_velocity_constraint_to_1e9(path):
    """Eq. 21 against toppra's C++ joint-velocity constraint on the same path (our resampled q'(s)
    handed to it at the same 2900 grid points): the square root of its upper bound on s-dot^2 equals
    our velocity feed limit to 1e-9 relative at every point. Paths: the helix above (axis 4 still,
    which both skip), and six axes of random sums of sines (seed 4, amplitudes up to 0.5 rad)."""
    if path == "helix":
        prog, lim_v = np.degrees(helix(np.linspace(0, S, 297))[0]), LIM_V
    else:
        rng = np.random.default_rng(4)
        t = np.linspace(0, 1, 297)[:, None]
        amp, freq, phase = rng.uniform(0.05, 0.5, (3, 6)), rng.uniform(0.2, 2.0, (3, 6)), rng.uniform(0, 6, (3, 6))
        prog = np.degrees(sum(amp[i] * np.sin(2 * np.pi * freq[i] * t + phase[i]) for i in range(3)))
        lim_v = np.array([60.0, 50.0, 40.0, 30.0, 90.0, 120.0])
    res = feed.analyse(prog, lim_v, np.full(len(lim_v), 1e3), np.full(len(lim_v), 1e4), optimal=False)
    arr = res["arrays"]
    xb = toppra_x_bounds(arr["s"], arr["d1"], np.radians(lim_v))
    assert xb.shape == (len(arr["s"]), 2) and np.all(xb[:, 0] == 0)
    assert np.max(np.abs(np.sqrt(xb[:, 1]) / arr["sv"] - 1)) < 1e-9


def test_tightened_acceleration_limit_is_found_at_the_right_s_and_axis():
    """Axis 2's acceleration limit tightened so that at feed f it is exceeded where
    R k^2 |sin(k s)| f^2 > a2: the reported runs start and end there (within one resampling step),
    on axis 2, as acceleration violations; nothing else is reported."""
    f = 1.0
    lim_a = LIM_A.copy()
    a2 = 0.7 * R * K ** 2 * f ** 2
    lim_a[1] = np.degrees(a2)
    lim_a[0] = 1e6  # axis 1's acceleration (R k^2 |cos|) out of the way
    prog = np.degrees(helix(np.linspace(0, S, 297))[0])
    res = feed.analyse(prog, LIM_V * 100, lim_a, LIM_J * 100, feed=f, optimal=False)
    vio = res["violations"]
    assert vio and all(v["axis"] == 2 and v["limit"] == "acceleration" for v in vio)
    # analytic: |sin(k s)| > 0.7 with k s in [0, k S] = [0, 2.12]: s in (asin(0.7)/k, (pi - asin(0.7))/k)
    s0, s1 = np.arcsin(0.7) / K, (np.pi - np.arcsin(0.7)) / K
    step = S / 2899
    assert len(vio) == 1
    assert abs(vio[0]["s"] - s0) < 2 * step and abs(vio[0]["s_end"] - min(s1, S)) < 2 * step


def test_paper_use_case_reports_no_violations(tmp_path):
    """The paper's case: the 297-pose line on kr500, compensated on a simulated calibrated model
    (kincal demo: 1 mm / 0.05 deg errors and joint compliance, seed 7) against the uncompensated
    program, with the built-in limits at the default feed: no violation, as the paper found. The
    analysis writes feed.json of the contract and one figure per axis."""
    r = run("kincal", "demo", "--out", str(tmp_path / "demo"))
    assert r.returncode == 0, r.stderr
    d = tmp_path / "demo"
    r = run("kincal", "feed", "--robot", "kr500", "--program", str(d / "compensated.gcode"), "--compare",
            str(d / "uncompensated.gcode"), "--out", str(tmp_path / "feed"))
    assert r.returncode == 0, r.stderr
    doc = json.loads((tmp_path / "feed" / "feed.json").read_text())
    for key in ("program", "compare"):
        p = doc["programs"][key]
        assert p["violations"] == []
        assert len(p["s"]) == 2900 and len(p["sdot_v_max"]) == 2900
        assert len(p["sdot_a_max"]) == 2900 and len(p["sdot_j_max"]) == 2900
        assert 0.5 < p["s_total_rad"] < 2.0
    for k in range(1, 7):
        assert (tmp_path / "feed" / f"axis{k}.png").read_bytes()[:4] == b"\x89PNG"
    # the paper's linear resampling invents jerk violations on the same programs
    r = run("kincal", "feed", "--robot", "kr500", "--program", str(d / "compensated.gcode"), "--method", "linear",
            "--out", str(tmp_path / "feed_linear"))
    lin = json.loads((tmp_path / "feed_linear" / "feed.json").read_text())["programs"]["program"]
    assert any(v["limit"] == "jerk" for v in lin["violations"])


# The figures (kincal feed, kincal demo): the panels' y ranges and limit lines, without pixels.

def test_panel_range_comes_from_the_data_and_names_far_limit_lines():
    """The audit's theta_s panel: data in [-0.2, 0.2], lines at +-5.24 (velocity), +-10.5 (eq. 22)
    and +-105 (eq. 23): the range is the data's widened by 8% of their height on each side and every
    line is off scale. With lines at +-0.09 (within the data), +-0.4 and +-0.7: the range may grow to
    3 times the data's (1.392 here), so +-0.09 and +-0.4 are drawn ([-0.432, 0.432]), then +0.7
    ([-0.432, 0.732], 1.164) and not -0.7 (1.464). Flat data at 0 get a height of 1 and the margin:
    +-0.58."""
    data = [np.linspace(-0.2, 0.2, 50), np.linspace(-0.1, 0.1, 50)]
    far = [5.24, -5.24, 10.5, -10.5, 105.0, -105.0]
    (lo, hi), drawn, off = feed.panel_range(data, far)
    assert lo == pytest.approx(-0.232) and hi == pytest.approx(0.232)
    assert drawn == [] and sorted(off) == sorted(far)
    (lo, hi), drawn, off = feed.panel_range(data, [0.4, -0.4, 0.09, -0.09, 0.7, -0.7, 5.0, -5.0])
    assert sorted(drawn) == [-0.4, -0.09, 0.09, 0.4, 0.7] and sorted(off) == [-5.0, -0.7, 5.0]
    assert lo == pytest.approx(-0.432) and hi == pytest.approx(0.732)
    assert (hi - lo) <= 3 * 0.464 + 1e-12
    assert feed.panel_range([np.zeros(10)], [])[0] == pytest.approx((-0.58, 0.58))
    # a line the data pass is always drawn, however far the data go
    (lo, hi), drawn, off = feed.panel_range([np.array([0.0, 1000.0])], [1.0, -1.0])
    assert drawn == [1.0, -1.0] and off == [] and lo < -1.0 and hi > 1000.0


def test_off_scale_note_gives_the_values_and_says_when_the_data_pass_a_line():
    bounds = [(5.236, "velocity", "velocity"), (104.7, "jerk", "jerk (eq. 23)"), (1676.0, "jerk", "jerk")]
    assert feed.off_scale_note(bounds, []) == ""
    note = feed.off_scale_note(bounds, [104.7, -104.7, 1676.0], [np.array([-0.2, 0.2])])
    assert note == "off scale: jerk (eq. 23) \u00b1105, jerk +1676"
    note = feed.off_scale_note([(0.175, "acceleration", "acceleration")], [0.175, -0.175],
                               [np.array([0.43, 0.47])])
    assert note == "off scale: acceleration \u00b10.175 (exceeded)"


def test_figure_panels_scale_to_their_own_window(tmp_path):
    """The helix above, two programs (the second 1e-3 rad off on every axis): each panel's y range
    holds its own window's data, which fill at least a third of it; the zoom's theta_s range of axis
    1 is the zoom's (under 1/50 of the full window's); no drawn line lies outside its panel and every
    off-scale line lies outside it and is named above it."""
    prog = np.degrees(helix(np.linspace(0, S, 297))[0])
    res = {"program": feed.analyse(prog, LIM_V, LIM_A, LIM_J, feed=1.0, optimal=False),
           "compare": feed.analyse(prog + np.degrees(1e-3), LIM_V, LIM_A, LIM_J, feed=1.0, optimal=False)}
    zoom = (0.99, 1.01)
    panels = feed.figure(res, LIM_V, LIM_A, LIM_J, 1.0, 1, str(tmp_path / "a1.png"), zoom=zoom)
    assert (tmp_path / "a1.png").read_bytes()[:4] == b"\x89PNG"
    for (row, col), p in panels.items():
        lo_s, hi_s = (0.0, S) if col == 0 else zoom
        vals = np.concatenate([r["arrays"][("q", "d1", "d2", "d3")[row]][:, 0][
            (r["arrays"]["s"] >= lo_s) & (r["arrays"]["s"] <= hi_s)] for r in res.values()])
        ylo, yhi = p["ylim"]
        assert ylo < vals.min() and vals.max() < yhi
        assert (vals.max() - vals.min()) * 1.16 >= (yhi - ylo) / 3 - 1e-12
        assert all(ylo <= v <= yhi for v in p["drawn"]) and all(not ylo <= v <= yhi for v in p["off"])
        assert bool(p["off"]) == p["note"].startswith("off scale")
    full, zoomed = panels[1, 0]["ylim"], panels[1, 1]["ylim"]
    assert zoomed[1] - zoomed[0] < (full[1] - full[0]) / 50
    # axis 1's theta_s (-R k sin(k s), in [-0.85, 0]) at feed 1: the velocity line (1.05) is drawn,
    # acceleration (eq. 22, 2.09) and jerk (eq. 23, 20.9) are off scale
    assert sorted(panels[1, 0]["drawn"]) == pytest.approx([-np.radians(60), np.radians(60)])
    assert "acceleration (eq. 22) \u00b12.09" in panels[1, 0]["note"] and "jerk (eq. 23) \u00b120.9" in panels[1, 0]["note"]


def test_point_scatter_recovers_a_stated_scatter():
    """A line along axis 4 (297 points, 1.1 rad; axes 1-3 still) with independent uniform scatter
    +-5e-8 rad (standard deviation 5e-8/sqrt(3)) on every axis, 10 seeds: on axes 1-3 the estimate is
    within 30% of it (measured 0.88-1.26: the median of 291 overlapping sixth differences), 10% on
    the mean of the 30; on axis 4 the scatter runs along the path, which s absorbs: below 1e-12 rad.
    Without scatter, on the helix, below 1e-13 rad."""
    assert np.all(feed.point_scatter(helix(np.linspace(0, S, 297))[0]) < 1e-13)
    line = np.zeros((297, 4))
    line[:, 3], line[:, :3] = np.linspace(0, 1.1, 297), [0.3, -0.8, 1.6]
    ratios = []
    for seed in range(10):
        est = feed.point_scatter(line + np.random.default_rng(seed).uniform(-5e-8, 5e-8, line.shape))
        ratios += list(est[:3] / (5e-8 / np.sqrt(3)))
        assert est[3] < 1e-12
    assert np.all(np.abs(np.array(ratios) - 1) < 0.3) and abs(np.mean(ratios) - 1) < 0.1


def test_scatter_derivative_predicts_the_spline_response_to_independent_scatter():
    """A straight line in 6 axes (direction (1,..,1)/sqrt(6), 297 points 3.7e-3 rad apart) with
    independent normal scatter 2e-8 rad, 3 seeds: the rms of the spline's second and third
    derivatives over the middle half is scatter_derivative's, for the scatter across the path (the
    component along it moves the points along the line and the chord-length s follows them):
    2e-8 * sqrt(1 - 1/6). Within 20% per axis and seed (about 280 points' worth of samples: 6%
    sampling error), within 5% on the mean of the 18."""
    n, h, sig = 297, 3.7e-3, 2e-8
    line = np.outer(np.arange(n) * h, np.ones(6) / np.sqrt(6))
    ratios = {2: [], 3: []}
    for seed in range(3):
        prog = line + np.random.default_rng(seed).normal(0.0, sig, line.shape)
        arr = feed.analyse(np.degrees(prog), [100.0] * 6, [100.0] * 6, [100.0] * 6, optimal=False)["arrays"]
        mid = (arr["s"] > 0.25 * arr["s"][-1]) & (arr["s"] < 0.75 * arr["s"][-1])
        assert arr["spacing"] == pytest.approx(h, rel=1e-4)
        for k in (2, 3):
            pred = feed.scatter_derivative(sig * np.sqrt(1 - 1 / 6), arr["spacing"], k)[0]
            ratios[k] += list(np.sqrt(np.mean(arr[f"d{k}"][mid] ** 2, axis=0)) / pred)
    for k in (2, 3):
        assert np.all(np.abs(np.array(ratios[k]) - 1) < 0.2)
        assert abs(np.mean(ratios[k]) - 1) < 0.05


def test_rounded_coordinates_dominate_the_third_derivative_of_a_line(kr500):
    """Why theta_sss of kincal demo's line ripples: the kr500 straight line of 297 poses 5 mm apart
    (start (2000.123456789, -740.987654321, 500.314159265) mm, direction (0.1, 1, -0.05), tool
    down), inverse kinematics of its exact coordinates and of the same coordinates rounded to 4
    decimals as the demo's line.gcode writes them (+-5e-5 mm). Exact: |theta_sss| <= 2 1/rad^2 on
    every axis and no scatter (< 1e-13 rad). Rounded: axes 2, 3 and 5 reach |theta_sss| above 5 times
    the exact one's peak (measured 13-43 against 0.5-1.5). The figure's estimate of what the points'
    scatter alone gives (point_scatter through scatter_derivative, for independent scatter) is within
    a factor 2.5 of the rms of the difference over the middle half (measured 0.46-1.48: rounding of
    evenly spaced coordinates is not independent scatter)."""
    import kincal

    poses = kincal.line_program(start=(2000.123456789, -740.987654321, 500.314159265), direction=(0.1, 1.0, -0.05))
    rounded = poses.copy()
    rounded[:, :3] = np.round(rounded[:, :3], 4)
    lim = feed.robot_limits(kr500)
    exact, rnd = (feed.analyse(np.asarray(kincal.compensate(kr500, p, compensate=False)["q_deg"]), *lim,
                               optimal=False)["arrays"] for p in (poses, rounded))
    assert np.all(np.abs(exact["d3"]).max(axis=0) <= 2.0) and np.all(exact["scatter"] < 1e-13)
    peak_e, peak_r = np.abs(exact["d3"]).max(axis=0), np.abs(rnd["d3"]).max(axis=0)
    assert np.all(peak_r[[1, 2, 4]] > 5 * peak_e[[1, 2, 4]])
    mid = (exact["s"] > 0.25 * exact["s"][-1]) & (exact["s"] < 0.75 * exact["s"][-1])
    ripple = np.sqrt(np.mean((rnd["d3"] - exact["d3"])[mid] ** 2, axis=0))
    moving = [0, 1, 2, 4, 5]  # axis 4 stays at 0 on this line
    ratio = feed.scatter_derivative(rnd["scatter"], rnd["spacing"], 3)[0][moving] / ripple[moving]
    assert np.all(ratio > 1 / 2.5) and np.all(ratio < 2.5)
