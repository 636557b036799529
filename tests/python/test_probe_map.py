"""Randomly placed touches (no plan): kincal's fit is at least as accurate as a plain maximum a posteriori
(MAP) fit of the same data with the same prior widths, written here with scipy, on each probe kind (the
median over nine truths).

Truth: ident.default_truth(kr500, seed=1..9; the other tests here seed 3): the kr500 with 1 mm / 0.05 deg
geometric errors (its tool frame too) and joint compliance of about 0.003 deg/kNm on joints 2-6, seen
from the simulator's instrument placement. Campaigns: kincal.calibration.simulation.simulate_probe,
seed 5, the probe's axis within a 60 deg cone, the ball centre 150 mm along the tool's z, every row's
configuration random (no plan):
  1. spheres with a length bar: 6 spheres x 25 touches, noise 0.005 mm on each coordinate of the ball
     centre, the artifact's 5 distances from the first sphere;
  2. block faces: 4 faces (top, x-, y+, y-) of the default 400 mm block x 40 touches with a 3 mm ball,
     noise 0.005 mm along the face's normal, the artifact's 3 right angles and the y+/y- edge; and the
     same with the surface plate the block stands on as a fifth plane (the top's height over it known);
  3. ballbar: 4 pivots x 40 touches of a 150 mm bar, noise 0.002 mm on its measured length. The simulator
     has one noise figure; for a ballbar row it is the noise of the length (the ball centre is on the
     bar's sphere exactly), so this campaign is simulated with 0.002 mm.
The artifact's values are exact. Score: the ball centre's RMS error on 200 random configurations within
90% of each joint limit, against the noise-free truth, after the best rigid transform (_core.rigid_fit).

kincal's fit: identify() (what `kincal identify` runs) on the data written to CSV and read back with
their artifact file, default priors and loss, --effects joint_compliance: the truth's model (geometry
and joint compliance), so that both fits estimate the same parameters. The default `--effects auto`
must find that model itself (test_the_default_effect_choice_finds_the_compliance below): it scores its
candidates on the fit's maximum a posteriori problem on probe data (effect_choice._prior_rows); before,
without the priors, it kept the geometry alone on the spheres and the faces (1.59 and 1.06 mm off on the
score's configurations), and a ballbar's padding coordinates put its robust scale at zero.

The MAP fit minimises sum (r_i / sigma_i)^2 + sum ((x_j - x0_j) / sd_j)^2 with scipy.optimize.least_squares
(no robust loss): r the core's residuals and analytic Jacobian (_core.PointModel built as identify
builds it for probe data: the same layout, stations and their reference normals) and the artifact's
terms (stations.cpp's artifact_residual, mirrored below: mm, an angle on a 1 m lever), sigma_i the
simulated noise (an artifact term weighs as one probe reading, as in kincal's cost), x0 the start
(PointModel.start: the nominal model, the stations' start) and sd_j kincal's default prior widths
(priors.DEFAULT_PRIOR_SD in the core's units, on the kinds priors.cpp gives them to; none for the
compliances, targets, base and stations). kincal weighs the same priors by noise_mm / sd against
residuals in mm, noise_mm its robust estimate of the noise: the same cost with that estimate as sigma.
The MAP holds only what is strictly gauge: the base frame (the stations absorb it; neither has a prior)
and a parameter without prior that moves no point (joint 6's compliance: gravity never loads joint 6).
kincal holds the same since its priors keep free what a generic campaign of the rows finds redundant
(identifiability.cpp, at_prior(); before, it held those at their start: spheres 0.00426 mm against the
MAP's 0.00333, faces 0.174 against 0.052 on the simulator's previous draw of them). What is left between
the two is the noise: the MAP is told the simulated one, kincal estimates it (the priors weigh noise / sd);
see test_kincal_is_at_least_as_accurate_as_a_plain_map_fit.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.optimize import least_squares

import kincal
from kincal import _core
from kincal.calibration import identify as ident, priors
from kincal.calibration.probe_plan import ball_centres as _balls, rigid_rms as _rigid_rms
from kincal.calibration import simulation as sim

from conftest import run

LEVER_MM = 1000.0  # kArtifactLever (point_eval.hpp): an artifact's angle weighs as mm on a 1 m lever
PROBE = np.array([0.0, 0.0, 150.0])  # simulate_probe's ball centre in the tool frame
# the kind of each Parameter (its `kind`) as priors.cpp's prior kinds, "{}": its unit appended
PRIOR_KIND = {"joint_geometry": "joint_{}", "tool": "tool_{}", "base": "base_{}", "target": "target_mm"}

CASES = {
    "spheres": {"kind": "sphere", "stations": 6, "touches": 25, "noise_mm": 0.005},
    "block_faces": {"kind": "plane", "stations": 4, "touches": 40, "noise_mm": 0.005},
    "block_and_plate": {"kind": "plane", "stations": 5, "touches": 40, "noise_mm": 0.005},
    "ballbar": {"kind": "distance", "stations": 4, "touches": 40, "noise_mm": 0.002},
}


def _unit_orthogonal(n: np.ndarray) -> np.ndarray:
    """Eigen's unitOrthogonal() of a 3-vector (a plane station's first tilt direction)."""
    x, y, z = n
    if abs(x) > abs(z) * 1e-12 or abs(y) > abs(z) * 1e-12:
        return np.array([-y, x, 0.0]) / math.hypot(x, y)
    return np.array([0.0, -z, y]) / math.hypot(y, z)


class PlainMap:
    """The MAP fit of probe data on the layout L of kincal's fit of them (its stations and their
    reference normals: structure, not fitted values), every parameter free but the gauge."""

    def __init__(self, robot: kincal.Robot, data: dict, L: _core.ParamLayout, sigma: float) -> None:
        self.data, self.L, self.sigma = data, L, sigma
        self.pm = _core.PointModel(robot, L.n_targets, list(L.effect_list), fit_gravity=L.gravity == "fit",
                                   stations_of=L)
        assert self.pm.layout.names == L.names
        self.x0 = np.asarray(self.pm.start(data))
        core_sd = dict(priors.core_prior_sd(priors.DEFAULT_PRIOR_SD))  # file units -> mm, rad (prior scale 1)
        self.sd = np.array([core_sd.get(PRIOR_KIND.get(p.kind, p.kind).format(p.unit), math.inf)
                            for p in L.parameters])
        names = list(data["station_names"])
        self.artifact_terms = [(names.index(a), names.index(b), dist, ang) for a, b, dist, ang, _ in data["artifact"]]
        self.n0 = [np.asarray(n, dtype=float) for n in L.station_normals]
        self.uv = [(_unit_orthogonal(n), np.cross(n, _unit_orthogonal(n))) for n in self.n0]
        # a plane's or a ballbar's row has one residual (the core's other two are zero)
        one = np.array([L.station_kinds[s] != "sphere" for s in np.asarray(data["station"])])
        keep = np.ones((len(one), 3), dtype=bool)
        keep[one, 1:] = False
        self.keep = keep.ravel()
        free = np.ones(L.size, dtype=bool)
        free[L.base:L.targets] = False  # gauge: the stations absorb the base frame
        col = np.linalg.norm(self.pm.residuals(self.x0, data, True)[1], axis=0)
        free &= ~((col < 1e-9 * col.max()) & ~np.isfinite(self.sd))  # moves no point, no prior
        self.free, self.idx = free, np.flatnonzero(free)
        self.prior = free & np.isfinite(self.sd)
        self.result = None

    def station(self, x: np.ndarray, k: int):
        """Station k at x: its point (a sphere, a pivot) or normal, offset and the normal's derivatives
        along its two tilts (a plane), as stations.cpp's init_stations."""
        p = x[self.L.stations + 3 * k:self.L.stations + 3 * k + 3]
        if self.L.station_kinds[k] != "plane":
            return p, None, None, None
        u, v = self.uv[k]
        w = self.n0[k] + p[0] * u + p[1] * v
        nw = np.linalg.norm(w)
        n = w / nw
        return p, n, p[2], [(u - n * n.dot(u)) / nw, (v - n * n.dot(v)) / nw]

    def artifact(self, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The artifact's residuals and their Jacobian (stations.cpp's artifact_residual)."""
        r, J = np.zeros(len(self.artifact_terms)), np.zeros((len(self.artifact_terms), self.L.size))
        for i, (a, b, dist, ang) in enumerate(self.artifact_terms):
            oa, ob = self.L.stations + 3 * a, self.L.stations + 3 * b
            pa, na, da, dna = self.station(x, a)
            pb, nb, db, dnb = self.station(x, b)
            if not math.isnan(ang):  # the unsigned angle between two planes
                c = na.dot(nb)
                ac = min(1.0, abs(c))
                d = -LEVER_MM / max(math.sqrt(1 - ac * ac), 1e-9) * (-1.0 if c < 0 else 1.0)
                for k in range(2):
                    J[i, oa + k], J[i, ob + k] = d * nb.dot(dna[k]), d * na.dot(dnb[k])
                r[i] = LEVER_MM * (math.acos(ac) - math.radians(ang))
            elif self.L.station_kinds[a] == "plane":  # the gap between two parallel faces
                s = -1.0 if na.dot(nb) < 0 else 1.0
                gap = da - s * db
                sg = -1.0 if gap < 0 else 1.0
                J[i, oa + 2], J[i, ob + 2] = sg, -s * sg
                r[i] = abs(gap) - dist
            else:  # the distance between two points
                e = (pa - pb) / np.linalg.norm(pa - pb)
                J[i, oa:oa + 3], J[i, ob:ob + 3] = e, -e
                r[i] = np.linalg.norm(pa - pb) - dist
        return r, J

    def full(self, z: np.ndarray) -> np.ndarray:
        x = self.x0.copy()
        x[self.idx] = z
        return x

    def fun(self, z: np.ndarray) -> np.ndarray:
        x = self.full(z)
        r = np.asarray(self.pm.residuals(x, self.data, False)[0])[self.keep]
        return np.concatenate([r / self.sigma, self.artifact(x)[0] / self.sigma,
                               (x[self.prior] - self.x0[self.prior]) / self.sd[self.prior]])

    def jac(self, z: np.ndarray) -> np.ndarray:
        x = self.full(z)
        J = np.asarray(self.pm.residuals(x, self.data, True)[1])[self.keep]
        P = np.zeros((int(self.prior.sum()), self.L.size))
        P[np.arange(len(P)), np.flatnonzero(self.prior)] = 1.0 / self.sd[self.prior]
        return np.vstack([J / self.sigma, self.artifact(x)[1] / self.sigma, P])[:, self.idx]

    def cost(self, x: np.ndarray) -> float:
        return 0.5 * float(np.sum(self.fun(x[self.idx]) ** 2))

    def solve(self) -> np.ndarray:
        self.result = least_squares(self.fun, self.x0[self.idx], jac=self.jac, method="lm", x_scale="jac",
                                    ftol=1e-15, xtol=1e-15, gtol=1e-15, max_nfev=2000)
        assert self.result.success, self.result.message
        return self.full(self.result.x)


def _point_balls(robot: kincal.Robot, L: _core.ParamLayout, x: np.ndarray, q: np.ndarray) -> np.ndarray:
    """The ball centres at q of the parameters x (the robot's part of layout L), by the core's
    measurement model: point rows measured at zero, their residuals the predicted points."""
    pm = _core.PointModel(robot, L.n_targets, list(L.effect_list), fit_gravity=L.gravity == "fit")
    assert pm.layout.names == L.names[:L.stations]
    n = len(q)
    rows = {"pose": np.arange(n), "q_deg": q, "xyz": np.zeros((n, 3)), "target": np.zeros(n, dtype=int),
            "payload_kg": np.full(n, np.nan), "line": np.zeros(n, dtype=int), "source": "score"}
    return np.asarray(pm.residuals(x[:L.stations], rows, False)[0]).reshape(-1, 3)


#: the truths the comparison is made on (default_truth seeds): one draw is a coin flip where the priors
#: decide a direction (below), so the claim is of the median over these nine
TRUTHS = range(1, 10)


def _one_draw(tmp_path, kr500: kincal.Robot, case: dict, seed: int) -> tuple[float, float]:
    """kincal's and the plain MAP's ball-centre RMS on one truth, and the checks that make the two
    fits comparable (the same layout, start, prior widths and stations; the MAP at its own optimum)."""
    truth = ident.default_truth(kr500, seed=seed)
    sim_data = simulation_of(truth, case)
    (tmp_path / "m.csv").write_text(ident.measurements_csv(sim_data, 6))
    (tmp_path / "a.csv").write_text(_core.format_artifact(sim_data, 6))
    data = ident.read_measurements(str(tmp_path / "m.csv"), kr500, str(tmp_path / "a.csv"))

    # (a) kincal's fit: `kincal identify --effects joint_compliance` (the folds only validate: the model
    # is fitted on every row either way)
    fit = ident.identify(kr500, data, effects="joint_compliance", k_folds=0)
    f, L = fit.fit, fit.fit.layout
    x_kincal = np.asarray(f.x)

    # (b) the plain MAP fit of the same rows, layout and start, with the same prior widths
    m = PlainMap(kr500, data, L, case["noise_mm"])
    assert np.array_equal(m.x0, np.asarray(f.start))
    assert np.array_equal(m.sd, np.asarray(f.prior_sd))  # the core's own prior widths (inf: none)
    for k, st in enumerate(f.stations):  # the stations as the artifact's terms see them, at kincal's x
        p, n, offset, _ = m.station(x_kincal, k)
        assert (np.allclose(p, st.point, rtol=0, atol=1e-9) if n is None else
                np.allclose(n, st.normal, rtol=0, atol=1e-12) and abs(offset - st.offset) < 1e-9)
    x_map = m.solve()
    assert m.cost(x_map) <= m.cost(x_kincal)  # the optimum of its own cost (kincal's x is a point of it)

    # the score: the same 200 configurations for both, two paths to the ball centre
    rng = np.random.default_rng(7)
    lim = np.asarray(truth.limits_deg)
    q = rng.uniform(0.9 * lim[:, 0], 0.9 * lim[:, 1], size=(200, 6))
    t = _balls(truth, q, PROBE)
    kincal_balls = _balls(fit.robot, q, np.asarray(fit.targets)[0])
    assert np.max(np.abs(_point_balls(kr500, L, x_kincal, q) - kincal_balls)) < 1e-6  # mm: the paths agree
    kincal_rms = _rigid_rms(kincal_balls, t)
    map_rms = _rigid_rms(_point_balls(kr500, L, x_map, q), t)
    print(f"  truth {seed}: nominal {_rigid_rms(_balls(kr500, q, PROBE), t):.3f} mm, kincal {kincal_rms:.5f} mm, "
          f"plain MAP {map_rms:.5f} mm, ratio {kincal_rms / map_rms:.4f}; kincal's noise estimate "
          f"{f.noise_mm:.5f} mm (simulated {case['noise_mm']})")
    return kincal_rms, map_rms


@pytest.mark.parametrize("name", list(CASES))
def test_kincal_is_at_least_as_accurate_as_a_plain_map_fit(tmp_path, name):
    """kincal / MAP ball-centre RMS over the nine truths TRUTHS (campaign seed 5): the median at most 1 on
    each kind. Measured (2026-11-29), per truth 1-9:
      spheres          0.9935 0.9950 0.9981 0.9962 0.9958 1.0011 0.9975 1.0027 1.0006 (median 0.9975)
      block faces      0.9666 0.9884 1.0262 0.9882 1.0206 0.9989 1.0000 0.9866 0.9950 (median 0.9950)
      block and plate  0.9912 0.9712 0.9582 0.9929 1.0095 1.0098 0.9979 0.9906 1.0087 (median 0.9929)
      ballbar          0.9865 0.9518 0.9985 1.0159 0.9972 1.0015 1.0018 0.9866 0.9668 (median 0.9972)
    A single draw goes either way by up to 5%: where the rows leave a direction to the priors (four faces
    seen along their normals: the ball's offset along the probe against the top's and front's offsets),
    the figure follows the priors' weight, which kincal sets by its estimate of the noise (0.95-1.39 x
    the simulated one here) and the MAP by the simulated noise itself; told it (`--noise`), kincal is the
    MAP (test_told_the_noise_kincal_is_the_plain_map_fit). No truth may be worse by 5% (the worst measured,
    2.6%, with room: a guard against one draw going badly wrong, not a claim). Until the thirty-first
    session this test took truth 3 alone, and the faces were an expected failure there (1.0262)."""
    case = CASES[name]
    kr500 = kincal.load_robot("kr500")
    print(f"\n{name}:")
    ratios = [k / m for k, m in (_one_draw(tmp_path, kr500, case, seed) for seed in TRUTHS)]
    assert np.median(ratios) <= 1.0 and max(ratios) < 1.05, np.round(ratios, 4)


def simulation_of(truth: kincal.Robot, case: dict) -> dict:
    """The case's probe campaign on the truth (seed 5, a 60 deg cone, the artifact's terms)."""
    return sim.simulate_probe(truth, case["kind"], stations=case["stations"], touches=case["touches"],
                              cone_deg=60, noise_mm=case["noise_mm"], seed=5)


@pytest.mark.parametrize("name", list(CASES))
def test_the_default_effect_choice_finds_the_compliance(name):
    # the same campaigns: `--effects auto` (the default) keeps the joint compliance the truth has, and
    # its model is the fixed choice's (measured: spheres 0.0033, faces 0.1192, with the plate 0.0567,
    # ballbar 0.0053 mm)
    case = CASES[name]
    kr500 = kincal.load_robot("kr500")
    truth = ident.default_truth(kr500, seed=3)
    data = simulation_of(truth, case)
    auto = ident.identify(kr500, data, effects="auto", k_folds=0)
    fixed = ident.identify(kr500, data, effects="joint_compliance", k_folds=0)
    assert auto.effect_labels() and all(label.startswith("joint_compliance") for label in auto.effect_labels()), auto.effect_labels()
    rng = np.random.default_rng(7)
    lim = np.asarray(truth.limits_deg)
    q = rng.uniform(0.9 * lim[:, 0], 0.9 * lim[:, 1], size=(200, 6))
    t = _balls(truth, q, PROBE)
    a = _rigid_rms(_balls(auto.robot, q, np.asarray(auto.targets)[0]), t)
    f = _rigid_rms(_balls(fixed.robot, q, np.asarray(fixed.targets)[0]), t)
    print(f"{name}: auto ({', '.join(auto.effect_labels())}) {a:.4f} mm, --effects joint_compliance {f:.4f} mm")
    assert a <= f * (1 + 1e-3), (a, f)


def test_told_the_noise_kincal_is_the_plain_map_fit(tmp_path):
    # the four faces, where the default loses to the MAP by its noise estimate: told the simulated
    # noise (`--noise 0.005`), kincal weighs its priors as the MAP does and lands on its figure
    from kincal.calibration.fitting import FitOptions
    case = CASES["block_faces"]
    kr500 = kincal.load_robot("kr500")
    truth = ident.default_truth(kr500, seed=3)
    data = simulation_of(truth, case)
    fit = ident.identify(kr500, data, effects="joint_compliance", k_folds=0, fit=FitOptions(noise_mm=0.005))
    assert fit.fit.noise_mm == 0.005
    m = PlainMap(kr500, data, fit.fit.layout, case["noise_mm"])
    rng = np.random.default_rng(7)
    lim = np.asarray(truth.limits_deg)
    q = rng.uniform(0.9 * lim[:, 0], 0.9 * lim[:, 1], size=(200, 6))
    t = _balls(truth, q, PROBE)
    kincal_rms = _rigid_rms(_balls(fit.robot, q, np.asarray(fit.targets)[0]), t)
    map_rms = _rigid_rms(_point_balls(kr500, fit.fit.layout, m.solve(), q), t)
    print(f"faces, noise given: kincal {kincal_rms:.5f} mm, plain MAP {map_rms:.5f} mm")
    assert abs(kincal_rms / map_rms - 1) <= 1e-3, (kincal_rms, map_rms)  # the same fit: float noise apart


def test_a_noise_that_is_no_noise_is_refused(tmp_path):
    kr500 = kincal.load_robot("kr500")
    data = sim.simulate_probe(ident.default_truth(kr500, seed=3), "sphere", stations=2, touches=5, seed=5)
    (tmp_path / "m.csv").write_text(ident.measurements_csv(data, 6))
    for bad in ("0", "-0.01", "nan"):
        r = run("kincal", "identify", "--robot", "kr500", "--data", str(tmp_path / "m.csv"), "--noise", bad,
                "--out", str(tmp_path / "o.json"))
        assert r.returncode == 1 and "(--noise, --fit-noise) must be a positive number of mm" in r.stderr, r.stderr
        assert not (tmp_path / "o.json").exists()


def test_the_artifacts_uncertainty_weighs_its_lengths():
    # six spheres (truth seed 3, campaign seed 5, 0.005 mm) whose length bar reads 0.05 mm long: weighed
    # as one probe reading the fit meets the data halfway; given its uncertainty (`--artifact-sd
    # 0.0001`) the fitted centres keep the bar's lengths, to a small share of the 0.05 mm
    from kincal.calibration.fitting import FitOptions
    kr500 = kincal.load_robot("kr500")
    data = simulation_of(ident.default_truth(kr500, seed=3), CASES["spheres"])
    data = data.with_columns(artifact=[(a, b, d + 0.05, ang, note) for a, b, d, ang, note in data["artifact"]])
    names = list(data["station_names"])

    def worst(fit: ident.Identification) -> float:
        pts = {s.name: np.asarray(s.point) for s in fit.fit.stations}
        return max(abs(np.linalg.norm(pts[a] - pts[b]) - d) for a, b, d, _, _ in data["artifact"]
                   if a in names and b in names)
    plain = worst(ident.identify(kr500, data, effects="joint_compliance", k_folds=0))
    weighed = worst(ident.identify(kr500, data, effects="joint_compliance", k_folds=0,
                                   fit=FitOptions(artifact_sd_mm=1e-4)))
    print(f"largest length error of the fitted centres: as a row {plain:.4f} mm, weighed {weighed:.5f} mm")
    assert weighed < 0.1 * plain and weighed < 0.005, (plain, weighed)
