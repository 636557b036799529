"""Derivative analysis (kincal feed): a synthetic path with known derivatives, toppra as the peer for
eq. 21, violations found where they are, and the paper's use case on kr500."""

from __future__ import annotations

import json
import os
import subprocess
from pathlib import Path

import numpy as np
import pytest

from kincal import feed

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
