// Measurements without a tracker: the probe rows of the measurement CSV (sphere, plane, distance)
// and the artifact file, their residuals' analytic Jacobians against finite differences, the checks
// of a station's rows, and identification from a simulated probe campaign against its truth.
#include "identify_test_util.hpp"
#include "test_util.hpp"

#include "kincal/core/rigid.hpp"
#include "kincal/identify/identify.hpp"
#include "kincal/identify/point_model.hpp"
#include "kincal/identify/simulate.hpp"
#include "kincal/io/measurements.hpp"

#include <gtest/gtest.h>

#include <random>

using namespace kincal;
using test::error_of;
using test::truth_spec;

namespace {

const char* kMixed =
    "pose,q1,q2,q3,q4,q5,q6,x,y,z,kind,station,radius,length\n"
    "0,0,-90,90,0,30,0,1500,0,1800,,,,\n"
    "1,10,-80,85,5,35,10,,,,sphere,S1,,\n"
    "2,12,-82,86,6,33,40,,,,sphere,S1,,\n"
    "3,20,-70,80,0,40,0,,,,plane,top,3,\n"
    "4,25,-70,82,0,40,0,,,,distance,P,,150.25\n";

/// The ball centre (tool frame offset `probe`) of a model at q, base frame.
Vec3 ball(const Model& m, const VecQ& q_deg, const Vec3& probe) { return fk_compliant(m, q_deg * kDeg) * probe; }

/// The 200 random configurations (10 deg inside the kr500's limits) the accuracy is scored on.
std::vector<Vec6> scoring_configurations(unsigned seed) {
  const Model nominal(kr500_spec());
  std::mt19937_64 rng(seed);
  std::vector<Vec6> qs;
  for (int k = 0; k < 200; ++k) qs.push_back(test::random_q(nominal, rng, 10.0));
  return qs;
}

/// The ball centres of a model at every configuration.
Eigen::Matrix3Xd balls(const Model& m, const std::vector<Vec6>& qs, const Vec3& probe) {
  Eigen::Matrix3Xd out(3, static_cast<Eigen::Index>(qs.size()));
  for (size_t k = 0; k < qs.size(); ++k) out.col(static_cast<Eigen::Index>(k)) = ball(m, qs[k], probe);
  return out;
}

/// A probe campaign's options: the ball 150 mm out on the tool, the simulator's noise (0.005 mm).
ProbeSimulationOptions probe_options(MeasureKind kind, int stations, int touches, double cone_deg, unsigned seed) {
  ProbeSimulationOptions so;
  so.kind = kind;
  so.stations = stations;
  so.touches = touches;
  so.cone_deg = cone_deg;
  so.probe = Vec3(0, 0, 150);
  so.seed = seed;
  return so;
}

}  // namespace

TEST(Stations, CsvRowsAndRoundTrip) {
  const MeasurementSet m = parse_measurements(kMixed, "m.csv", 6);
  ASSERT_EQ(m.rows.size(), 5u);
  EXPECT_EQ(m.rows[0].kind, MeasureKind::point);
  EXPECT_EQ(m.rows[1].kind, MeasureKind::sphere);
  EXPECT_EQ(m.rows[3].kind, MeasureKind::plane);
  EXPECT_DOUBLE_EQ(m.rows[3].radius_mm, 3.0);
  EXPECT_DOUBLE_EQ(m.rows[4].length_mm, 150.25);
  EXPECT_EQ(m.station_names, (std::vector<std::string>{"S1", "top", "P"}));
  EXPECT_EQ(m.rows[2].station, 0);
  EXPECT_EQ(m.rows[0].station, -1);
  const MeasurementSet back = parse_measurements(format_measurements(m, 6), "back.csv", 6);
  ASSERT_EQ(back.rows.size(), m.rows.size());
  for (size_t i = 0; i < m.rows.size(); ++i) {
    EXPECT_EQ(back.rows[i].kind, m.rows[i].kind);
    EXPECT_EQ(back.rows[i].station, m.rows[i].station);
    EXPECT_EQ(back.rows[i].radius_mm, m.rows[i].radius_mm);
    EXPECT_TRUE(back.rows[i].length_mm == m.rows[i].length_mm ||
                (std::isnan(back.rows[i].length_mm) && std::isnan(m.rows[i].length_mm)));
  }
  // a probe-only file needs no x, y, z columns
  const MeasurementSet probe =
      parse_measurements("pose,q1,q2,q3,q4,q5,q6,kind,station\n0,0,-90,90,0,30,0,sphere,A\n", "p.csv", 6);
  EXPECT_EQ(probe.rows[0].kind, MeasureKind::sphere);
}

TEST(Stations, ASubsetKeepsTheStationsAndCountsItsOwnTargets) {
  // kMixed: a point row of target 0, then probe rows; rows 3 and 1 picked in that order
  MeasurementSet m = parse_measurements(kMixed, "m.csv", 6);
  m.rows[0].target = 2;  // the point row names a third target
  m.n_targets = 3;
  const MeasurementSet s = subset(m, {3, 1});
  ASSERT_EQ(s.rows.size(), 2u);
  EXPECT_EQ(s.rows[0].line, m.rows[3].line);
  EXPECT_EQ(s.rows[1].line, m.rows[1].line);
  EXPECT_EQ(s.source, "m.csv");
  EXPECT_EQ(s.station_names, m.station_names);
  EXPECT_EQ(s.station_kinds, m.station_kinds);
  EXPECT_EQ(s.n_targets, 1);  // the point row with target 2 left out
  EXPECT_EQ(subset(m, {0}).n_targets, 3);
  EXPECT_TRUE(without_rows(m).rows.empty());
  EXPECT_EQ(without_rows(m).station_names, m.station_names);
  EXPECT_THROW(subset(m, {5}), std::out_of_range);
}

TEST(Stations, CsvErrorsNameFileAndLine) {
  const std::string head = "pose,q1,q2,q3,q4,q5,q6,x,y,z,kind,station,radius,length\n";
  auto err = [&](const std::string& row) { return error_of([&] { parse_measurements(head + row, "m.csv", 6); }); };
  EXPECT_EQ(err("0,0,0,0,0,0,0,,,,distance,P,,\n"), "m.csv:2: a distance row needs its 'length' (mm)");
  EXPECT_EQ(err("0,0,0,0,0,0,0,1,2,3,sphere,S,,\n"), "m.csv:2: a sphere row has no x, y, z (leave them empty)");
  EXPECT_EQ(err("0,0,0,0,0,0,0,,,,sphere,,,\n"), "m.csv:2: column 'station': empty value");
  EXPECT_EQ(err("0,0,0,0,0,0,0,,,,cube,S,,\n"),
            "m.csv:2: column 'kind': 'cube' is none of point, pose, sphere, plane, distance");
  EXPECT_EQ(err("0,0,0,0,0,0,0,,,,sphere,S,2,\n"), "m.csv:2: a radius on a sphere row (planes only)");
  EXPECT_EQ(err("0,0,0,0,0,0,0,,,,sphere,S,,\n1,0,0,0,0,0,0,,,,plane,S,,\n"),
            "m.csv:3: station 'S' is a sphere station, this row a plane");
  EXPECT_EQ(err("0,0,0,0,0,0,0,,,,,,,\n").substr(0, 9), "m.csv:2: ");  // a point without its x
  MeasurementSet m = parse_measurements(kMixed, "m.csv", 6);
  EXPECT_EQ(error_of([&] { parse_artifact("a,b,distance_mm,angle_deg\nS1,Q,100,\n", "art.csv", m); }),
            "art.csv:2: station 'Q' is in no row of m.csv");
  EXPECT_EQ(error_of([&] { parse_artifact("a,b,distance_mm,angle_deg\nS1,P,,30\n", "art.csv", m); }),
            "art.csv:2: an angle between stations that are not both planes");
  EXPECT_EQ(error_of([&] { parse_artifact("a,b,distance_mm,angle_deg\nS1,top,50,\n", "art.csv", m); }),
            "art.csv:2: a distance between a sphere and a plane station");
  EXPECT_EQ(error_of([&] { parse_artifact("a,b,distance_mm,angle_deg\nS1,P,50,10\n", "art.csv", m); }),
            "art.csv:2: give one of distance_mm and angle_deg, the other empty");
  parse_artifact("a,b,distance_mm,angle_deg\nS1,P,250.5,\n", "art.csv", m);
  ASSERT_EQ(m.artifact.size(), 1u);
  EXPECT_EQ(m.artifact[0].b, 2);
  EXPECT_EQ(format_artifact(m), "a,b,distance_mm,angle_deg\nS1,P,250.5,\n");
}

// Every probe kind's residual Jacobian (and the artifact's gradients) against central differences, at
// a perturbed parameter vector: truth the kr500 with 1 mm / 0.05 deg errors and compliance, no noise.
TEST(Stations, JacobiansMatchFiniteDifferences) {
  KINCAL_SEED_TRACE(41, 42);
  const Model truth(truth_spec(41, 0.003)), nominal(kr500_spec());
  for (MeasureKind kind : {MeasureKind::sphere, MeasureKind::plane, MeasureKind::distance}) {
    SCOPED_TRACE(to_string(kind));
    // the simulator's default cone (35 deg); the ball off the tool's axis, so that every target column acts
    ProbeSimulationOptions so = probe_options(kind, kind == MeasureKind::plane ? 3 : 2, 5, 35, test::test_seed(42));
    so.probe = Vec3(10, -20, 150);
    const MeasurementSet d = simulate_probe(truth, so);
    LayoutOptions lo(1);
    lo.station_names = d.station_names;
    lo.station_kinds = d.station_kinds;
    const PointModel pm(nominal, lo, &d);
    const ParamLayout& L = pm.layout();
    std::vector<double> x = pm.start(d);
    std::mt19937_64 rng(test::test_seed(43));
    std::normal_distribution<double> nd(0, 1);
    for (int i = 0; i < L.size; ++i)
      if (i < L.base || i >= L.targets) x[i] += nd(rng) * (L.units[i] == "rad" ? 1e-3 : 0.5);
    const PointState at = pm.at(x);
    for (const Measurement& row : d.rows) {
      std::vector<double> J(3 * L.size), r(3), rp(3), rm(3);
      row_residuals(at, row, ResidualKind::position, 100.0, r.data(), J.data());
      for (int i = 0; i < L.size; ++i) {
        const double h = L.units[i] == "rad" ? 1e-6 : 1e-4;
        std::vector<double> xp = x, xm = x;
        xp[i] += h;
        xm[i] -= h;
        row_residuals(pm.at(xp), row, ResidualKind::position, 100.0, rp.data(), nullptr);
        row_residuals(pm.at(xm), row, ResidualKind::position, 100.0, rm.data(), nullptr);
        for (int k = 0; k < 3; ++k) {
          const double fd = (rp[k] - rm[k]) / (2 * h), an = J[k * L.size + i];
          EXPECT_NEAR(an, fd, 1e-5 * std::max(1.0, std::abs(fd))) << L.names[i] << " component " << k;
        }
      }
    }
    for (const ArtifactTerm& a : d.artifact) {
      std::vector<double> g(L.size);
      at.artifact_residual(a, g.data());
      for (int i = 0; i < L.size; ++i) {
        const double h = L.units[i] == "rad" ? 1e-6 : 1e-4;
        std::vector<double> xp = x, xm = x;
        xp[i] += h;
        xm[i] -= h;
        const double fd = (pm.at(xp).artifact_residual(a, nullptr) - pm.at(xm).artifact_residual(a, nullptr)) / (2 * h);
        EXPECT_NEAR(g[i], fd, 1e-5 * std::max(1.0, std::abs(fd))) << L.names[i];
      }
    }
  }
}

// A station with too few rows and a plane touched along a line: refused with the file and line.
TEST(Stations, TooFewRowsAndCollinearPlanesAreRefused) {
  const Model nominal(kr500_spec());
  const std::string head = "pose,q1,q2,q3,q4,q5,q6,kind,station,radius\n";
  const MeasurementSet few = parse_measurements(head + "0,0,-90,90,0,30,0,sphere,A,\n1,5,-90,90,0,30,0,sphere,A,\n", "few.csv", 6);
  EXPECT_EQ(error_of([&] { identify(nominal, few, IdentifyOptions()); }),
            "few.csv:2: station 'A' has 2 row(s); a sphere station needs 3 at least");
  // joint 6 alone turning: the nominal ball centres (the tool point, on the kr500's flange axis) do
  // not spread over any plane
  std::string rows;
  for (int i = 0; i < 6; ++i) rows += std::to_string(i) + ",0,-90,90,0,30," + std::to_string(10 * i) + ",plane,F,3\n";
  const MeasurementSet line = parse_measurements(head + rows, "line.csv", 6);
  const std::string e = error_of([&] { identify(nominal, line, IdentifyOptions()); });
  EXPECT_EQ(e.substr(0, 41), "line.csv:2: station 'F': its touches lie ") << e;
}

/// The identified robot's accuracy on a probe campaign: the RMS of the ball centre on 200 random
/// configurations against the noise-free truth after the best rigid transform (the base frame is free
/// in these data), with the nominal's the same way; prints both.
struct Accuracy {
  double nominal = 0, identified = 0, fit_rms = 0;
};
Accuracy probe_accuracy(const Model& truth, const MeasurementSet& d, const Vec3& probe, unsigned seed,
                        const char* what, double prior_scale = 0) {
  const Model nominal(kr500_spec());
  IdentifyOptions opt;
  opt.covariance = false;
  opt.prior_scale = prior_scale;
  const IdentifyResult res = identify(nominal, d, opt);
  const Model cal(res.calibrated);
  const std::vector<Vec6> qs = scoring_configurations(seed);
  const Eigen::Matrix3Xd t = balls(truth, qs, probe), c = balls(cal, qs, res.targets[0]), z = balls(nominal, qs, probe);
  auto rms_after_fit = [&](const Eigen::Matrix3Xd& a) {
    const Eigen::Isometry3d f = rigid_fit(a, t);
    return std::sqrt(((f * a) - t).colwise().squaredNorm().mean());
  };
  Accuracy a{rms_after_fit(z), rms_after_fit(c), res.rms_mm};
  std::printf("%s: nominal %.3f mm, identified %.4f mm (rms of the fit %.4f mm, %zu rows)\n", what, a.nominal,
              a.identified, a.fit_rms, d.rows.size());
  return a;
}

// Identification from spheres with a length bar. Truth: the kr500 with 1 mm / 0.05 deg geometric
// errors and joint compliance; 6 spheres x 25 touches in a 60 deg cone, the probe's ball 150 mm out
// on the tool, 0.005 mm noise, the distances of the stations from the first known (the artifact).
// Accuracy: RMS of the ball centre on 200 random configurations (10 deg inside the limits) against the
// noise-free truth after
// the best rigid transform (the base frame is free in these data).
TEST(Stations, SpheresWithALengthBarRecoverTheRobot) {
  KINCAL_SEED_TRACE(51, 52, 53);
  const Model truth(truth_spec(51, 0.003));
  const ProbeSimulationOptions so = probe_options(MeasureKind::sphere, 6, 25, 60, test::test_seed(52));
  const Accuracy a = probe_accuracy(truth, simulate_probe(truth, so), so.probe, test::test_seed(53), "spheres");
  EXPECT_GT(a.nominal, 1.0);
  EXPECT_LT(a.identified, 0.05);  // measured 0.0075 mm
  EXPECT_LT(a.fit_rms, 0.02);  // the fit reaches the noise (0.005 mm per axis)
}

// The simulator places every sphere and ballbar pivot in reach (issue 32): a station whose seed pose
// leaves too few of its touches reachable is placed again. Over 40 draws (truths and campaigns: the
// kr500 with 1 mm / 0.05 deg errors and compliance; 6 spheres x 25 touches and 4 pivots x 40 in a 60 deg
// cone, the ball 150 mm out) every station has all its touches; before, the ballbar of
// KINCAL_TEST_SEED=10 in BlockFacesAndABallbarRecoverTheRobot was refused ("station S1 is out of the
// robot's reach (18 of 40 touches)").
TEST(Stations, EveryStationPlacedInReach) {
  KINCAL_SEED_TRACE(91, 92);
  for (unsigned k = 0; k < 20; ++k) {
    const Model truth(truth_spec(91 + 100 * k, 0.003));
    for (const MeasureKind kind : {MeasureKind::sphere, MeasureKind::distance}) {
      const bool bar = kind == MeasureKind::distance;
      const ProbeSimulationOptions so = probe_options(kind, bar ? 4 : 6, bar ? 40 : 25, 60, test::test_seed(92 + 100 * k));
      MeasurementSet m;
      ASSERT_NO_THROW(m = simulate_probe(truth, so)) << "draw " << k << (bar ? ", ballbar" : ", spheres");
      std::vector<int> touches(static_cast<size_t>(so.stations), 0);
      for (const Measurement& r : m.rows) ++touches[static_cast<size_t>(r.station)];
      for (int t : touches) EXPECT_EQ(t, so.touches) << "draw " << k;
    }
  }
}

// Four faces of a 400 mm block (top, the one towards the robot and the two sideways; 40 touches each
// in a 60 deg cone, 3 mm ball, touches over 70% of each face) with their 90 deg angles and the block's
// edge between the sideways faces; and a ballbar of 150 mm at 4 pivots (40
// rows each, 0.002 mm noise on its length). Truth and accuracy as above.
// Random touches on four faces leave one direction mostly to the priors (BENCHMARKS.md, "Planning a
// probe campaign"), so one draw says little: over 16 values of KINCAL_TEST_SEED a draw gave 0.028-0.41
// mm (median 0.16; the default draw 0.083), and one of the 150 draws of KINCAL_TEST_SEED 1-30 0.61 mm
// (9.8 times better than its nominal model). The claim is therefore on five draws (truth and touches
// each their own): every one at least five times better than the nominal model, and their median no
// worse than the upper end of issue 32's figure for a plain MAP fit of such touches on a similar
// robot (0.22-0.28 mm). Over KINCAL_TEST_SEED 1-30 the median of the five was 0.041-0.274 mm: a
// draw of random faces can come close to it; planned touches do better (BENCHMARKS.md).
// (A 120 mm block in a 35 deg cone: 3 mm, nothing determined.)
TEST(Stations, BlockFacesAndABallbarRecoverTheRobot) {
  KINCAL_SEED_TRACE(61, 62, 63, 64);
  std::vector<double> identified;
  for (unsigned k = 0; k < 5; ++k) {
    const Model truth(truth_spec(61 + 100 * k, 0.003));
    ProbeSimulationOptions planes = probe_options(MeasureKind::plane, 4, 40, 60, test::test_seed(62 + 100 * k));
    planes.block_mm = 400;
    const MeasurementSet faces = simulate_probe(truth, planes);
    ASSERT_EQ(faces.artifact.size(), 4u);  // 3 angles, 1 edge
    const Accuracy a = probe_accuracy(truth, faces, planes.probe, test::test_seed(63), "block faces");
    EXPECT_LT(a.identified, a.nominal / 5) << "draw " << k;
    identified.push_back(a.identified);
  }
  std::nth_element(identified.begin(), identified.begin() + 2, identified.end());
  EXPECT_LT(identified[2], 0.28);  // the default draws: 0.083, 0.28, 0.34, 0.17, 0.20 mm (median 0.20)
  const Model truth(truth_spec(61, 0.003));
  ProbeSimulationOptions bar = probe_options(MeasureKind::distance, 4, 40, 60, test::test_seed(64));
  bar.noise_mm = 0.002;
  const Accuracy b = probe_accuracy(truth, simulate_probe(truth, bar), bar.probe, test::test_seed(63), "ballbar");
  EXPECT_GT(b.nominal, 1.0);
  EXPECT_LT(b.identified, 0.05);  // measured 0.011 mm
}

// Without a known length the overall scale is not seen: the result says so, and the ball centres the
// fit predicts on 200 random configurations equal those of the fit with the length after the best
// similarity transform (rotation, translation and scale: Umeyama) to 0.01 mm. Truth, campaign: the
// spheres above (6 x 25 touches, 60 deg cone, 0.005 mm noise), the length the distance of the second
// station from the first; both fits without priors. Thirty draws of the campaign (and of the scoring
// configurations), each within 0.01 mm, their median within 0.002 mm.
// The same touches with and without the length must hold the same parameters but the one the scale
// leaves to them: where the lengths' rows took part in judging what the data determine, a parameter
// near the weak threshold was held in one fit and not in the other (joint6.tilt_u, 2.0e-3 of its
// effect its own with the length; KINCAL_TEST_SEED=33 of this test until the thirty-second session,
// which gave five lengths: 0.0147 mm, and 0.0154 with one). Over KINCAL_TEST_SEED 1-60 (one draw each,
// one length) the largest three were 0.0154, 0.0090 and 0.0060 mm; now 0.0059, 0.0039 and 0.0031
// (median 0.0007; BENCHMARKS.md). With the distances of all five other
// stations from the first (a ball plate: four lengths more than the scale needs) the two fits differ
// by what those lengths add about the stations' layout: 0.0122 mm on one of those 60 draws (seed 60),
// with the same parameters held. A tracker campaign sees the scale (60 poses: 40, without priors, left
// base.rz barely determined on one of 30 draws, KINCAL_TEST_SEED=5, and identify refused them before
// any scale was looked at).
TEST(Stations, WithoutALengthTheScaleIsNamedAndOnlyItIsFree) {
  KINCAL_SEED_TRACE(51, 52, 53);
  const Model truth(truth_spec(51, 0.003)), nominal(kr500_spec());
  IdentifyOptions opt;
  opt.covariance = false;
  std::vector<double> gaps;
  for (unsigned k = 0; k < 30; ++k) {
    MeasurementSet with = simulate_probe(truth, probe_options(MeasureKind::sphere, 6, 25, 60, test::test_seed(52 + 100 * k)));
    ASSERT_FALSE(with.artifact.empty());
    with.artifact.resize(1);  // one known length: stations 1 and 2
    MeasurementSet without = with;
    without.artifact.clear();
    const IdentifyResult a = identify(nominal, with, opt), b = identify(nominal, without, opt);
    EXPECT_TRUE(a.scale_determined) << "draw " << k;
    EXPECT_FALSE(b.scale_determined) << "draw " << k;
    const std::vector<Vec6> qs = scoring_configurations(test::test_seed(53 + 100 * k));
    const Eigen::Matrix3Xd pa = balls(Model(a.calibrated), qs, a.targets[0]), pb = balls(Model(b.calibrated), qs, b.targets[0]);
    const Eigen::Matrix4d sim = Eigen::umeyama(pb, pa, true);
    const Eigen::Matrix3Xd moved = (sim.topLeftCorner<3, 3>() * pb).colwise() + sim.topRightCorner<3, 1>();
    gaps.push_back(std::sqrt((moved - pa).colwise().squaredNorm().mean()));
    std::printf("without the length, draw %u: scale %.6f, ball centres after the similarity %.5f mm\n", k,
                std::cbrt(sim.topLeftCorner<3, 3>().determinant()), gaps.back());
    EXPECT_LT(gaps.back(), 0.01) << "draw " << k;
  }
  std::nth_element(gaps.begin(), gaps.begin() + 15, gaps.end());
  EXPECT_LT(gaps[15], 0.002);
  SimulationOptions tracker;
  tracker.poses = 60;
  tracker.seed = test::test_seed(54);
  EXPECT_TRUE(identify(nominal, simulate(truth, tracker), opt).scale_determined);
}

// A tracker campaign plus one sphere station, fitted together: the probe's rows share the fit's
// robot, the tracker's rows place the instrument; the joint fit is not worse than the tracker alone
// by more than 5% (it should be better). Truth as above; tracker: 60 poses, one reflector at the
// ball's offset, 0.02 mm noise per coordinate; the sphere: 25 touches in a 60 deg cone, 0.005 mm.
// Accuracy: the ball centre on 200 random configurations after the best rigid transform. Both fits
// with the defaults of kincal identify (priors on the robot): over KINCAL_TEST_SEED 1-30 the joint fit
// was the better on 29 draws and 0.6% worse on one. Without priors (this test's fits until the
// twenty-fourth session) the joint fit was 5.1% worse on one draw (seed 16), and on another (seed 7)
// identify refused the joint campaign: see the next test.
struct MixedCampaign {
  MeasurementSet tracker, both;
};

MixedCampaign tracker_and_sphere(const Model& truth, const Vec3& probe, unsigned tracker_seed, unsigned sphere_seed) {
  SimulationOptions tr;
  tr.poses = 60;
  tr.targets = {probe};
  tr.seed = tracker_seed;
  MixedCampaign m;
  m.tracker = simulate(truth, tr);
  const MeasurementSet sphere = simulate_probe(truth, probe_options(MeasureKind::sphere, 1, 25, 60, sphere_seed));
  m.both = m.tracker;
  m.both.station_names = sphere.station_names;
  m.both.station_kinds = sphere.station_kinds;
  for (Measurement r : sphere.rows) {
    r.pose += static_cast<int>(m.tracker.rows.size());
    m.both.rows.push_back(r);
  }
  return m;
}

TEST(Stations, ATrackerCampaignWithASphereStation) {
  KINCAL_SEED_TRACE(71, 72, 73, 74);
  const Model truth(truth_spec(71, 0.003));
  const Vec3 probe(0, 0, 150);
  const MixedCampaign m = tracker_and_sphere(truth, probe, test::test_seed(72), test::test_seed(73));
  const Accuracy alone = probe_accuracy(truth, m.tracker, probe, test::test_seed(74), "tracker alone", 1.0);
  const Accuracy joint = probe_accuracy(truth, m.both, probe, test::test_seed(74), "tracker + a sphere", 1.0);
  EXPECT_LT(joint.identified, 1.05 * alone.identified);
}

// The same campaigns without priors: what the data determine is judged against a generic campaign
// of the same rows' kinds, and the data's choice among equivalent parameters is no loss. On the draw
// of KINCAL_TEST_SEED=7 in the test above (truth 2447241861, tracker 704224887, sphere 1397620085)
// identify refused the joint campaign until the twenty-fifth session ("cannot determine base.z: too
// few or too similar poses") where the tracker alone passes: in those data base.z is the sum of joints
// 2-6's move_v less the target's x, and the greedy choice took joint 6's move_v before base.z, where
// the generic campaign holds joint 6's move_v; both leave 13 parameters held. Now the data choose in
// the generic campaign's basis first. Both draws (that one and the test's default): the joint
// campaign is accepted and its ball centre within 0.03 mm of the truth (after the best rigid
// transform; the nominal is 5-10 mm off), as is the tracker alone's.
TEST(Stations, AMixedCampaignWithoutPriorsIsAccepted) {
  struct Draw {
    unsigned truth, tracker, sphere;
  };
  for (const Draw& d : {Draw{2447241861u, 704224887u, 1397620085u}, Draw{71, 72, 73}}) {
    const Model truth(truth_spec(d.truth, 0.003));
    const Vec3 probe(0, 0, 150);
    const MixedCampaign m = tracker_and_sphere(truth, probe, d.tracker, d.sphere);
    const Accuracy alone = probe_accuracy(truth, m.tracker, probe, 74, "tracker alone, no priors", 0.0);
    const Accuracy joint = probe_accuracy(truth, m.both, probe, 74, "tracker + a sphere, no priors", 0.0);
    EXPECT_GT(joint.nominal, 1.0);
    EXPECT_LT(alone.identified, 0.03);
    EXPECT_LT(joint.identified, 0.03);
  }
}
