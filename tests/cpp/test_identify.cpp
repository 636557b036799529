// Identification: completeness of the model (noise-free data fitted exactly), the noise floor
// reached on a simulated kr500 campaign, robust loss, hidden effects and 6-D poses.
#include "kincal/identify/identify.hpp"
#include "kincal/identify/simulate.hpp"
#include "kincal/kinematics/kinematics.hpp"
#include "identify_test_util.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <algorithm>
#include <utility>

using namespace kincal;
using kincal::test::kTargets;
using kincal::test::truth_spec;

namespace {

double rms(const std::vector<double>& e) {
  double s = 0;
  for (double v : e) s += v * v;
  return std::sqrt(s / e.size());
}

/// A campaign to fit (seed a) and one to hold out (seed b) on the same truth.
std::pair<MeasurementSet, MeasurementSet> fit_and_held(const Model& truth, SimulationOptions so, unsigned a,
                                                       unsigned b) {
  so.seed = test::test_seed(a);
  MeasurementSet fit = simulate(truth, so, test::truth_campaign());
  so.seed = test::test_seed(b);
  return {std::move(fit), simulate(truth, so, test::truth_campaign())};
}

/// Standardized errors (estimate - truth) / standard deviation of identified parameters, gathered
/// over 8 independent draws of 4 parameters each: whether the estimates are as near the truth as their
/// standard deviations say. Under that claim each value is N(0, 1), and, whatever the correlations of
/// the 4 within a draw, the largest of the 32 exceeds 4.5 with probability below 2.2e-4 (the union
/// bound) and their RMS exceeds 1.81 with probability below 0.001 (the values of a draw identical at
/// worst: 32 RMS^2 = 4 chi-square(8), above 26.1 with probability 0.001). A standard deviation 1.5x
/// too small is found at about the rate of the former check, 3 sigma on one draw's two or four
/// values, which fails about once in 370 draws per parameter and did on the draws of some
/// KINCAL_TEST_SEED. Standard deviations larger than needed are not part of the claim (not checked).
struct StandardizedErrors {
  std::vector<double> z;
  void add(double estimate, double truth, double stddev) { z.push_back((estimate - truth) / stddev); }
  double rms() const {
    double s = 0;
    for (double v : z) s += v * v;
    return std::sqrt(s / static_cast<double>(z.size()));
  }
  double max_abs() const {
    double m = 0;
    for (double v : z) m = std::max(m, std::abs(v));
    return m;
  }
  void expect_standard(const char* what) const {
    std::printf("%s: %zu standardized errors, RMS %.3f, largest %.2f\n", what, z.size(), rms(), max_abs());
    ASSERT_EQ(z.size(), 32u);
    EXPECT_LT(rms(), 1.81) << what;
    EXPECT_LT(max_abs(), 4.5) << what;
  }
};

}  // namespace

TEST(Identify, NoiseFreeGeometricErrorsFittedExactly) {
  KINCAL_SEED_TRACE(11, 1, 2);
  // truth: kr500 with ~1 mm / 0.05 deg errors, no compliance, three targets, no noise. Held-out
  // poses (another seed) are predicted to below 1e-6 mm: the 30-parameter model is complete.
  const Model truth(truth_spec(11, 0.0));
  SimulationOptions so;
  so.poses = 60;
  so.noise_mm = 0;
  so.targets = kTargets;
  const auto [fit, held] = fit_and_held(truth, so, 1, 2);
  const Model nominal(kr500_spec());
  IdentifyOptions opt;
  opt.compliance = false;
  opt.loss = Loss::none;
  const IdentifyResult r = identify(nominal, fit, opt);
  const Model cal(r.calibrated);
  const double before = rms(point_errors(nominal, Campaign{}, {Vec3::Zero()}, held));
  const double after = rms(point_errors(cal, r.campaign, r.targets, held));
  EXPECT_LT(after, 1e-6) << r.termination;
  EXPECT_GT(before, 1.0);
  int fixed = 0;
  for (bool f : r.fixed) fixed += f;
  // base vs chain (6) and tool vs targets (6) are redundant, plus the 5 compliances not asked for
  EXPECT_EQ(fixed, 12 + 5);
}

TEST(Identify, Kr500WithComplianceReachesTheNoiseFloor) {
  KINCAL_SEED_TRACE(21, 3, 4);
  // truth: kr500, 1 mm / 0.05 deg geometric errors, compliance ~0.003 deg/kNm on the 5 loaded
  // joints with the 300 kg head, instrument noise 0.02 mm per coordinate (0.035 mm RMS per point),
  // 150 poses with 3 targets to fit, 150 other poses held out.
  const Model truth(truth_spec(21, 0.003));
  SimulationOptions so;
  so.poses = 150;
  so.noise_mm = 0.02;
  so.targets = kTargets;
  const auto [fit, held] = fit_and_held(truth, so, 3, 4);
  const Model nominal(kr500_spec());
  const double floor = 0.02 * std::sqrt(3.0);
  IdentifyOptions opt;
  const IdentifyResult r = identify(nominal, fit, opt);
  const double after = rms(point_errors(Model(r.calibrated), r.campaign, r.targets, held));
  EXPECT_LT(after, 1.2 * floor) << r.termination;
  // without the compliance parameters a gap remains
  opt.compliance = false;
  const IdentifyResult rg = identify(nominal, fit, opt);
  const double geometric_only = rms(point_errors(Model(rg.calibrated), rg.campaign, rg.targets, held));
  EXPECT_GT(geometric_only, 1.5 * floor);
  // the compliances of A2..A5 are recovered as their standard deviations say: over 8 draws (truths
  // and campaigns, this one first) the 32 standardized errors are standard (StandardizedErrors); A6
  // carries no gravity torque (the head's centre of mass is on its axis), so its compliance is held
  // and named. Until the twenty-fifth session each compliance of this draw alone was checked within
  // 3 sigma, which KINCAL_TEST_SEED=19 failed (3.1 sigma on one of them).
  StandardizedErrors z;
  for (unsigned draw = 0; draw < 8; ++draw) {
    const Model truth_d(truth_spec(21 + 1000 * draw, 0.003));
    const IdentifyResult rd =
        draw == 0 ? r
                  : identify(nominal, fit_and_held(truth_d, so, 3 + 1000 * draw, 4 + 1000 * draw).first,
                             IdentifyOptions());
    for (size_t i = 0; i < rd.layout.loaded.size(); ++i) {
      const int k = rd.layout.compliance + static_cast<int>(i);
      const double t = truth_d.spec().joints[rd.layout.loaded[i]].compliance_deg_per_knm;
      if (rd.layout.loaded[i] == 5) {
        EXPECT_TRUE(rd.fixed[k]);
        EXPECT_NE(rd.fixed_reason[k].find("gravity torque too small"), std::string::npos);
        continue;
      }
      EXPECT_FALSE(rd.fixed[k]) << rd.layout.names[k];
      z.add(rd.x[k], t, rd.stddev[k]);
    }
  }
  z.expect_standard("compliances of A2..A5");
}

TEST(Identify, RobustLossIgnoresGrossOutliers) {
  KINCAL_SEED_TRACE(31, 7, 8);
  // truth: kr500 with geometric errors and compliance, 0.02 mm noise, 150 poses x 3 targets; then
  // the same campaign with 5% of the points moved 5 mm in random directions. With the Huber loss
  // (default) the held-out RMS changes by less than 10%; plain least squares is visibly hurt.
  const Model truth(truth_spec(31, 0.003));
  SimulationOptions so;
  so.poses = 150;
  so.targets = kTargets;
  so.seed = test::test_seed(7);
  const MeasurementSet clean = simulate(truth, so, test::truth_campaign());
  so.outlier_fraction = 0.05;
  so.outlier_mm = 5.0;
  const MeasurementSet dirty = simulate(truth, so, test::truth_campaign());
  so.outlier_fraction = 0;
  so.seed = test::test_seed(8);
  const MeasurementSet held = simulate(truth, so, test::truth_campaign());
  const Model nominal(kr500_spec());
  IdentifyOptions opt;
  auto held_rms = [&](const MeasurementSet& d, const IdentifyOptions& o) {
    const IdentifyResult r = identify(nominal, d, o);
    return rms(point_errors(Model(r.calibrated), r.campaign, r.targets, held));
  };
  const double e_clean = held_rms(clean, opt);
  const double e_dirty = held_rms(dirty, opt);
  EXPECT_LT(std::abs(e_dirty - e_clean), 0.1 * e_clean) << e_clean << " " << e_dirty;
  IdentifyOptions plain = opt;
  plain.loss = Loss::none;
  EXPECT_GT(held_rms(dirty, plain), 1.1 * e_clean);
}

TEST(Identify, TooFewMeasurementsIsAnInputError) {
  KINCAL_SEED_TRACE(1);
  const Model nominal(kr500_spec());
  SimulationOptions so;
  so.seed = test::test_seed(1);  // the simulator's default
  so.poses = 5;
  const MeasurementSet d = simulate(Model(truth_spec(1, 0)), so, test::truth_campaign());
  EXPECT_THROW(identify(nominal, d, IdentifyOptions()), InputError);
}

TEST(Identify, HiddenTransmissionErrorIsRecovered) {
  KINCAL_SEED_TRACE(41, 11, 12);
  // truth: kr500 geometric errors + compliance + a transmission error on A2 (0.01 deg first
  // harmonic's sine, 0.005 deg second's cosine, the other two amplitudes 0), 0.02 mm noise;
  // identified with that effect in the model the held-out error reaches the noise floor and the four
  // amplitudes are recovered as their standard deviations say: over 8 draws (truths and campaigns,
  // this one first) the 32 standardized errors are standard (StandardizedErrors). Until the
  // twenty-fifth session the two nonzero amplitudes of this draw alone were checked within 3 sigma,
  // which KINCAL_TEST_SEED=15 failed.
  const double d2r = kDeg;
  SimulationOptions so;
  so.poses = 150;
  so.targets = kTargets;
  EffectValue te;
  te.effect = Effect("transmission_error");
  te.effect.joint = 1;
  te.p = {0.01 * d2r, 0.0, 0.0, 0.005 * d2r};
  so.effects.push_back(te);
  so.seed = test::test_seed(11);
  const Model truth(truth_spec(41, 0.003));
  const MeasurementSet fit = simulate(truth, so, test::truth_campaign());
  so.seed = test::test_seed(12);
  const MeasurementSet held = simulate(truth, so, test::truth_campaign());
  const Model nominal(kr500_spec());
  IdentifyOptions opt;
  opt.effects = {{"transmission_error", 1}};
  const IdentifyResult r = identify(nominal, fit, opt);
  const double after = rms(point_errors(Model(r.calibrated), r.campaign, r.targets, held));
  EXPECT_LT(after, 1.2 * 0.02 * std::sqrt(3.0));
  StandardizedErrors z;
  for (unsigned draw = 0; draw < 8; ++draw) {
    const Model truth_d(truth_spec(41 + 1000 * draw, 0.003));
    so.seed = test::test_seed(11 + 1000 * draw);
    const IdentifyResult rd = draw == 0 ? r : identify(nominal, simulate(truth_d, so, test::truth_campaign()), opt);
    ASSERT_EQ(rd.effects.size(), 1u);
    const int c = rd.layout.effect_offset[0];
    for (int k = 0; k < 4; ++k) z.add(rd.x[c + k], te.p[k], rd.stddev[c + k]);
  }
  z.expect_standard("transmission error amplitudes");
}

TEST(Identify, SixDimensionalPosesDetermineTheToolOrientation) {
  KINCAL_SEED_TRACE(51, 21, 22);
  // truth: kr500 with geometric errors (the tool turned by about 0.05 deg too) and compliance; one
  // target (the TCP) measured as a full pose (0.02 mm, 0.005 deg noise). From the points alone the
  // tool's orientation stays nominal (it is redundant with the target offset): held-out orientation
  // errors keep the tool's error. With the measured orientations they fall to the noise, and the
  // positions stay at their noise floor.
  SimulationOptions so;
  so.poses = 120;
  so.noise_mm = 0.02;
  so.orientation_noise_deg = 0.005;
  so.targets = {Vec3(0, 0, 0)};
  so.seed = test::test_seed(21);
  const Model truth(truth_spec(51, 0.003));
  const MeasurementSet fit = simulate(truth, so, test::truth_campaign());
  so.seed = test::test_seed(22);
  const MeasurementSet held = simulate(truth, so, test::truth_campaign());
  const Model nominal(kr500_spec());
  auto orientation_rms_deg = [&](const Model& cal, const Campaign& c) {
    double ss = 0;
    for (const auto& row : held.rows) {
      const Mat3 rm = c.base().linear() * fk_compliant(cal, row.q_deg * kDeg).linear();
      const double e = Eigen::AngleAxisd(abc_to_rotation(row.abc).transpose() * rm).angle() / kDeg;
      ss += e * e;
    }
    return std::sqrt(ss / held.rows.size());
  };
  IdentifyOptions opt;
  opt.orientation_weight = 0.02 / (0.005 * kDeg);  // position noise over orientation noise
  const IdentifyResult r6 = identify(nominal, fit, opt);
  const Model cal6(r6.calibrated);
  const double noise_deg = 0.005 * std::sqrt(3.0);
  EXPECT_LT(orientation_rms_deg(cal6, r6.campaign), 1.3 * noise_deg);
  EXPECT_LT(rms(point_errors(cal6, r6.campaign, r6.targets, held)), 1.2 * 0.02 * std::sqrt(3.0));
  MeasurementSet points = fit;
  points.orientation = false;
  const IdentifyResult r3 = identify(nominal, points, IdentifyOptions());
  EXPECT_GT(orientation_rms_deg(Model(r3.calibrated), r3.campaign), 3 * noise_deg);
}

TEST(Identify, NoiseFreeSixDimensionalPosesIdentifyTheToolFrame) {
  KINCAL_SEED_TRACE(61, 31, 32);
  // truth: kr500 with ~1 mm / 0.05 deg geometric errors (tool frame included), no compliance, seen
  // from the instrument; one target at the tool frame's origin measured as a full pose
  // (no noise, position or orientation), 300 poses to fit, 100 other poses held out. The frame a 6-D
  // row measures is the tool frame: its target is held at zero, the tool frame is identified (free),
  // and the model alone (fk, no target offset) reproduces the held-out poses.
  const Model truth(truth_spec(61, 0.0));
  SimulationOptions so;
  so.poses = 300;
  so.noise_mm = 0;
  so.orientation_noise_deg = 0;
  so.targets = {Vec3::Zero()};
  const auto [fit, held] = fit_and_held(truth, so, 31, 32);
  ASSERT_TRUE(fit.orientation);
  const Model nominal(kr500_spec());
  IdentifyOptions opt;
  opt.loss = Loss::none;
  const IdentifyResult r = identify(nominal, fit, opt);
  const ParamLayout& L = r.layout;
  for (int i = L.tool; i < L.tool + 6; ++i) EXPECT_FALSE(r.fixed[i]) << L.names[i] << ": " << r.fixed_reason[i];
  for (int k = 0; k < 3; ++k) {
    EXPECT_TRUE(r.fixed[L.targets + k]);
    EXPECT_EQ(r.x[L.targets + k], 0.0);
  }
  EXPECT_EQ(r.calibrated.tcp, "measured");
  const Model cal(r.calibrated);
  const std::vector<double> ep = point_errors(cal, r.campaign, {Vec3::Zero()}, held);  // the tool frame's origin
  EXPECT_LT(*std::max_element(ep.begin(), ep.end()), 1e-4) << r.termination;
  const std::vector<double> eo = orientation_errors(cal, r.campaign, held);
  ASSERT_EQ(eo.size(), held.rows.size());
  EXPECT_LT(*std::max_element(eo.begin(), eo.end()), 1e-6);
  // the nominal geometry (its base and tool frames fitted) is off by more than 1 mm RMS
  EXPECT_GT(rms(point_errors(Model(r.nominal_fitted), r.nominal_campaign, {Vec3::Zero()}, held)), 1.0);
}

TEST(Identify, SixDimensionalRowsWithReflectorsKeepTheReflectorsOffsetsInTheToolFrame) {
  KINCAL_SEED_TRACE(62, 33, 34);
  // truth as above (seed 62); the first target measured as a full pose (the tool frame), the two
  // others (120, 0, 30) and (0, 150, -20) mm as points in the same file; no noise, 200 poses. The
  // tool frame is identified, the reflectors' offsets come out in it (to 1e-6 mm), and held-out
  // poses and points are reproduced.
  const Model truth(truth_spec(62, 0.0));
  SimulationOptions so;
  so.poses = 200;
  so.noise_mm = 0;
  so.orientation_noise_deg = 0;
  so.targets = kTargets;
  const auto [fit, held] = fit_and_held(truth, so, 33, 34);
  int six_d = 0;
  for (const auto& row : fit.rows) {
    six_d += row.has_abc;
    EXPECT_EQ(row.has_abc, row.target == 0);
  }
  ASSERT_EQ(six_d, 200);
  IdentifyOptions opt;
  opt.loss = Loss::none;
  const IdentifyResult r = identify(Model(kr500_spec()), fit, opt);
  EXPECT_EQ(r.calibrated.tcp, "measured");
  ASSERT_EQ(r.targets.size(), 3u);
  for (int t = 0; t < 3; ++t) EXPECT_LT((r.targets[t] - kTargets[t]).norm(), 1e-6) << t;
  const Model cal(r.calibrated);
  const std::vector<double> e = point_errors(cal, r.campaign, r.targets, held);
  EXPECT_LT(*std::max_element(e.begin(), e.end()), 1e-4);
  const std::vector<double> eo = orientation_errors(cal, r.campaign, held);
  EXPECT_EQ(eo.size(), 200u);  // the 6-D rows only
  EXPECT_LT(*std::max_element(eo.begin(), eo.end()), 1e-6);
  // 6-D rows of two targets claim two tool frames: an error naming both
  MeasurementSet two = fit;
  two.rows[1].has_abc = true;
  try {
    identify(Model(kr500_spec()), two, opt);
    ADD_FAILURE() << "6-D rows of two targets accepted";
  } catch (const InputError& err) {
    EXPECT_NE(std::string(err.what()).find("6-D rows of target 0 and of target 1"), std::string::npos) << err.what();
  }
}

TEST(Identify, ReflectorsAloneLeaveTheTcpNominal) {
  KINCAL_SEED_TRACE(63, 35);
  // truth as above (seed 63), three reflectors measured as points, 60 poses, no noise: the tool frame
  // stays at its start value (redundant with the offsets) and the model records it
  const Model truth(truth_spec(63, 0.0));
  SimulationOptions so;
  so.poses = 60;
  so.noise_mm = 0;
  so.targets = kTargets;
  so.seed = test::test_seed(35);
  IdentifyOptions opt;
  opt.compliance = false;
  opt.loss = Loss::none;
  const IdentifyResult r = identify(Model(kr500_spec()), simulate(truth, so, test::truth_campaign()), opt);
  EXPECT_EQ(r.calibrated.tcp, "nominal");
  for (int i = r.layout.tool; i < r.layout.tool + 6; ++i) EXPECT_TRUE(r.fixed[i]) << r.layout.names[i];
}

TEST(Identify, GravityWithoutAMassTablePredictsAsTheTrueMasses) {
  KINCAL_SEED_TRACE(23, 5, 6);
  // truth: kr500 (its masses and 300 kg head), 1 mm / 0.05 deg geometric errors, compliance
  // 0.003 deg/kNm x U(0.5, 1.5) on the loaded joints, noise 0.02 mm per coordinate; 100 poses with
  // 3 targets to fit, 150 other poses held out. The starting model without link masses (a URDF
  // without inertials; the head's mass known) fits the mass moments and predicts the held-out
  // poses within 10% of the run on the true masses, and far better than without compliance.
  const Model truth(truth_spec(23, 0.003));
  SimulationOptions so;
  so.poses = 100;
  so.noise_mm = 0.02;
  so.targets = kTargets;
  const auto [fit, held] = fit_and_held(truth, so, 5, 6);
  ModelSpec massless = kr500_spec();
  for (JointSpec& j : massless.joints) j.mass_kg = 0, j.com.setZero();
  IdentifyOptions opt;
  const IdentifyResult rm = identify(Model(kr500_spec()), fit, opt);
  const IdentifyResult rf = identify(Model(massless), fit, opt);
  EXPECT_FALSE(rm.layout.fit_gravity);
  ASSERT_TRUE(rf.layout.fit_gravity);
  const double e_masses = rms(point_errors(Model(rm.calibrated), rm.campaign, rm.targets, held));
  const double e_fitted = rms(point_errors(Model(rf.calibrated), rf.campaign, rf.targets, held));
  opt.compliance = false;
  const IdentifyResult rr = identify(Model(massless), fit, opt);
  const double e_rigid = rms(point_errors(Model(rr.calibrated), rr.campaign, rr.targets, held));
  std::printf("held-out RMS: true masses %.4f mm, fitted moments %.4f mm, no compliance %.4f mm (%s)\n", e_masses,
              e_fitted, e_rigid, rf.termination.c_str());
  EXPECT_LT(e_fitted, 1.10 * e_masses);
  EXPECT_GT(e_rigid, 2 * e_fitted);
  // the scale: the first loaded joint's compliance held; the written model carries unit masses
  const int held_k = rf.layout.compliance;
  EXPECT_TRUE(rf.fixed[held_k]);
  EXPECT_NE(rf.fixed_reason[held_k].find("scale of the fitted mass moments"), std::string::npos);
  EXPECT_EQ(rf.calibrated.joints[1].mass_kg, kUnitMass);
  // what is identified is each compliance relative to the held one: the truth's ratios within 3
  // standard deviations (A3..A5; A6 carries no torque: the head's centre of mass is on its axis)
  const double k2 = truth.spec().joints[1].compliance_deg_per_knm, held_value = rf.x[held_k];
  for (int j : {2, 3, 4}) {
    const int k = rf.layout.compliance + j - 1;
    EXPECT_NEAR(rf.x[k] / held_value, truth.spec().joints[j].compliance_deg_per_knm / k2, 3 * rf.stddev[k] / held_value)
        << rf.layout.names[k];
  }
  EXPECT_TRUE(rf.fixed[rf.layout.compliance + 4]);
  // --gravity masses on the massless model is an input error
  opt.compliance = true;
  opt.gravity = GravityTorques::masses;
  EXPECT_THROW(identify(Model(massless), fit, opt), InputError);
}
