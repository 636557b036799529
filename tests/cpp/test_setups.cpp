// Several instrument setups and the instrument's drift: the measurement columns (time_s, config,
// setup) through the CSV reader and writer, the analytic Jacobian of the setups' frames and of the
// drift against central differences, the drift carried inert by a model (FK and compensation
// never apply it), model JSON with setups and drift, and identification recovering a hidden drift
// and the placements of two setups.
#include "kincal/compensation/pose.hpp"
#include "kincal/identify/identify.hpp"
#include "kincal/identify/point_model.hpp"
#include "kincal/identify/simulate.hpp"
#include "kincal/identify/so3.hpp"
#include "kincal/io/measurements.hpp"
#include "kincal/io/model_json.hpp"
#include "kincal/kinematics/kinematics.hpp"
#include "identify_test_util.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <random>

using namespace kincal;
using kincal::test::kTargets;
using kincal::test::truth_spec;

namespace {

double rms(const std::vector<double>& e) {
  double s = 0;
  for (double v : e) s += v * v;
  return std::sqrt(s / e.size());
}

/// A drift of the size a laser tracker shows over a 3 h campaign: 0.04 mm/h, 0.001 deg/h (at 3.8 m
/// from the instrument about 0.07 mm/h), in core units (mm/h, rad/h).
std::vector<double> tracker_drift() { return {0.03, -0.02, 0.015, 0.0006 * kDeg, -0.0008 * kDeg, 0.001 * kDeg}; }

/// The second placement of the two-setup tests: the tracker moved 2.4 m and turned 70 deg.
Pose6 second_placement() { return Pose6{Vec3(-900, -2600, -250), Vec3(105, -1.2, 0.6)}; }

/// Rows of b appended to a with setup code 1 (a's rows setup 0), the setups named A and B.
MeasurementSet two_setups(MeasurementSet a, const MeasurementSet& b) {
  a.setup_names = {"A", "B"};
  const int offset = a.rows.back().pose + 1;
  for (Measurement r : b.rows) {
    r.setup = 1;
    r.pose += offset;
    a.rows.push_back(r);
  }
  return a;
}

}  // namespace

TEST(Setups, MeasurementColumnsRoundTrip) {
  // time_s (a number), config and setup (any text, coded in order of first appearance)
  const std::string text =
      "pose,q1,q2,q3,q4,q5,q6,x,y,z,time_s,config,setup\n"
      "0,1,2,3,4,5,6,10,20,30,0.5,c7,B\n"
      "1,1,2,3,4,5,6,11,21,31,12.25,c7,A\n"
      "2,2,2,3,4,5,6,12,22,32,30,home,B\n";
  const MeasurementSet m = parse_measurements(text, "m.csv", 6);
  ASSERT_EQ(m.rows.size(), 3u);
  EXPECT_EQ(m.setup_names, (std::vector<std::string>{"B", "A"}));
  EXPECT_EQ(m.config_names, (std::vector<std::string>{"c7", "home"}));
  EXPECT_EQ(m.n_setups(), 2);
  EXPECT_EQ(m.rows[1].setup, 1);
  EXPECT_EQ(m.rows[2].config, 1);
  EXPECT_DOUBLE_EQ(m.rows[1].time_s, 12.25);
  const MeasurementSet back = parse_measurements(format_measurements(m, 6), "back.csv", 6);
  EXPECT_EQ(back.setup_names, m.setup_names);
  EXPECT_EQ(back.config_names, m.config_names);
  for (size_t i = 0; i < 3; ++i) {
    EXPECT_EQ(back.rows[i].setup, m.rows[i].setup);
    EXPECT_EQ(back.rows[i].config, m.rows[i].config);
    EXPECT_EQ(back.rows[i].time_s, m.rows[i].time_s);
  }
  // without the columns: setup 0, config -1, time NaN, and the writer adds none of them
  const MeasurementSet plain = parse_measurements("pose,q1,q2,q3,q4,q5,q6,x,y,z\n0,1,2,3,4,5,6,1,2,3\n", "p.csv", 6);
  EXPECT_EQ(plain.rows[0].setup, 0);
  EXPECT_EQ(plain.rows[0].config, -1);
  EXPECT_TRUE(std::isnan(plain.rows[0].time_s));
  EXPECT_EQ(plain.n_setups(), 1);
  EXPECT_EQ(format_measurements(plain, 6).find("setup"), std::string::npos);
  // a bad time and an empty setup name file:line
  try {
    parse_measurements("pose,q1,q2,q3,q4,q5,q6,x,y,z,time_s\n0,1,2,3,4,5,6,1,2,3,soon\n", "t.csv", 6);
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("t.csv:2: column 'time_s'"), std::string::npos) << e.what();
  }
  try {
    parse_measurements("pose,q1,q2,q3,q4,q5,q6,x,y,z,setup\n0,1,2,3,4,5,6,1,2,3,\n", "s.csv", 6);
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("s.csv:2: column 'setup': empty value"), std::string::npos) << e.what();
  }
}

TEST(Setups, JacobianOfSetupsAndDriftMatchesFiniteDifferences) {
  KINCAL_SEED_TRACE(7, 1, 17);
  // kr500 truth with compliance; 24 poses over 3 h (time_s), every other pose from a second setup;
  // the layout with two setups, the drift and thermal expansion, at a random parameter point (the
  // drift non-zero); position rows, then 6-D rows (the orientation residual's Jacobian too)
  for (const bool six_d : {false, true}) {
    SimulationOptions so;
    so.seed = test::test_seed(1);  // the simulator's default
    so.poses = 24;
    so.noise_mm = 0;
    so.targets = six_d ? std::vector<Vec3>{Vec3::Zero()} : kTargets;
    so.duration_s = 3 * 3600;
    so.orientation_noise_deg = six_d ? 0.01 : -1;
    MeasurementSet d = simulate(Model(truth_spec(7, 0.003)), so, test::truth_campaign());
    d.setup_names = {"A", "B"};
    for (auto& r : d.rows) r.setup = r.pose % 2;
    const Model nominal(kr500_spec());
    const std::vector<Effect> eff = {{"drift", -1, {}}, {"thermal_expansion", -1, {}}};
    PointModel pm(nominal, {d.n_targets, eff, 24.0, d.setup_names, 5400.0});
    const ParamLayout& L = pm.layout();
    ASSERT_EQ(L.n_setups, 2);
    ASSERT_EQ(L.targets - L.base, 12);
    EXPECT_EQ(L.names[L.base + 6], "base[B].x");
    EXPECT_EQ(L.names[L.drift + 5], "drift_rz");
    std::vector<double> x = pm.start(d);
    std::mt19937_64 rng(test::test_seed(17));
    std::normal_distribution<double> nd(0, 1);
    for (int i = 0; i < L.size; ++i) {
      if (i >= L.compliance && i < L.tool) x[i] += 0.003;
      else if (i >= L.drift && i < L.drift + 6) x[i] += (i < L.drift + 3 ? 0.05 : 2e-5) * nd(rng);
      else if (i >= L.effects) x[i] += 1e-5 * nd(rng);
      else x[i] += nd(rng) * (L.units[i] == "rad" ? 0.001 : 1.0);
    }
    const ResidualKind kind = residual_kind(d);
    const int R = residual_size(kind);
    double worst = 0;
    std::string worst_name;
    for (const auto& row : d.rows) {
      const PointState at_x = pm.at(x);
      std::vector<double> J(6 * L.size), r(6);
      row_residuals(at_x, row, kind, 100.0, r.data(), J.data());
      for (int i = 0; i < L.size; ++i) {
        // the steps of the other Jacobian tests: rad 1e-5 on positions (rounding of 5 m coordinates),
        // 1e-6 on orientations; mm 1e-3
        const double hr = six_d ? 1e-6 : 1e-5;
        const double h = L.units[i].rfind("rad", 0) == 0 ? hr : (L.units[i].rfind("mm", 0) == 0 ? 1e-3 : 1e-5);
        std::vector<double> xp = x, xm = x, rp(6), rm(6);
        xp[i] += h;
        xm[i] -= h;
        const PointState at_xp = pm.at(xp);
        row_residuals(at_xp, row, kind, 100.0, rp.data(), nullptr);
        const PointState at_xm = pm.at(xm);
        row_residuals(at_xm, row, kind, 100.0, rm.data(), nullptr);
        double scale = 1.0;
        for (int k = 0; k < R; ++k) scale = std::max(scale, std::abs(J[k * L.size + i]));
        for (int k = 0; k < R; ++k) {
          const double err = std::abs((rp[k] - rm[k]) / (2 * h) - J[k * L.size + i]) / scale;
          if (err > worst) worst = err, worst_name = L.names[i];
        }
      }
    }
    EXPECT_LT(worst, 1e-6) << worst_name << (six_d ? " (6-D rows)" : "");
  }
}

TEST(Setups, OneSetupNamedIsTheLayoutWithoutSetups) {
  KINCAL_SEED_TRACE(3, 1);
  // a setup column with a single value changes nothing: same names, same predictions
  SimulationOptions so;
  so.seed = test::test_seed(1);  // the simulator's default
  so.poses = 10;
  so.targets = kTargets;
  const MeasurementSet d = simulate(Model(truth_spec(3, 0.003)), so, test::truth_campaign());
  const Model nominal(kr500_spec());
  PointModel a(nominal, {3}), b(nominal, {3, {}, 20.0, {"only"}});
  EXPECT_EQ(a.layout().names, b.layout().names);
  const std::vector<double> x = a.start(d);
  EXPECT_EQ(x, b.start(d));
  const PointState a_x = a.at(x);
  const PointState b_x = b.at(x);
  for (const auto& r : d.rows) EXPECT_EQ(a_x.predict(r, nullptr), b_x.predict(r, nullptr));
}

TEST(Setups, DriftAndPlacementsAreTheCampaignsAndRoundTrip) {
  KINCAL_SEED_TRACE(5);
  // a campaign carrying a drift and two setups: the model is the robot's alone (a drift among a
  // model's effects is refused: the campaign carries it); the measurement side (simulate_point)
  // applies them; the model JSON keeps them in its campaign section
  const Model a(truth_spec(5, 0.003));
  const Campaign plain = test::truth_campaign();
  Campaign carried = plain;
  carried.drift = EffectValue{Effect{"drift", -1, {}}, tracker_drift()};
  carried.t_mean_s = 5400;
  carried.setups = {{"A", plain.base_in_instrument}, {"B", second_placement()}};
  ModelSpec drifting = a.spec();
  drifting.effects.push_back(*carried.drift);
  EXPECT_NE(test::error_of([&] { Model m(drifting); }).find("the campaign carries it"), std::string::npos);
  // a row at the campaign's mean time sees the placement itself, one an hour later the placement
  // moved by one hour of drift
  Measurement row;
  row.q_deg = VecQ::Zero(6);
  row.q_deg[1] = -90;
  row.q_deg[2] = 90;
  row.time_s = 5400;
  const Vec3 p0 = simulate_point(a, plain, row, Vec3::Zero());
  EXPECT_LT((simulate_point(a, carried, row, Vec3::Zero()) - p0).norm(), 1e-9);
  row.time_s = 5400 + 3600;
  const auto& v = tracker_drift();
  const Vec3 tb = plain.base().translation();  // the rotation turns about the base's origin
  const Vec3 expect = so3::exp(Vec3(v[3], v[4], v[5])) * (p0 - tb) + tb + Vec3(v[0], v[1], v[2]);
  EXPECT_LT((simulate_point(a, carried, row, Vec3::Zero()) - expect).norm(), 1e-9);
  // JSON: the setups, the drift and its reference time come back
  auto nom = std::make_shared<Model>(kr500_spec());
  const Robot back =
      robot_from_json(robot_to_json(Robot{nom, std::make_shared<Model>(a.spec()), carried}), "m.json");
  ASSERT_EQ(back.campaign().setups.size(), 2u);
  EXPECT_EQ(back.campaign().setups[1].name, "B");
  EXPECT_LT((back.campaign().setups[1].base_in_instrument.xyz - second_placement().xyz).norm(), 1e-12);
  EXPECT_EQ(back.campaign().t_mean_s, 5400);
  ASSERT_TRUE(back.campaign().drift.has_value());
  for (int k = 0; k < 6; ++k) EXPECT_NEAR(back.campaign().drift->p[k], v[k], 1e-18);
  EXPECT_TRUE(back.calibrated()->spec().effects.empty());  // the model's own effects: none
}

/// A version 3 model file rewritten in version 2's layout (kincal up to the twentieth session): the
/// campaign's keys inside the calibrated model's section, its drift among that model's effects, the
/// nominal section with the identity placement.
std::string as_version2(const std::string& v3) {
  nlohmann::json o = nlohmann::json::parse(v3);
  nlohmann::json c = o["campaign"];
  o.erase("campaign");
  o["version"] = 2;
  nlohmann::json& cal = o["calibrated"];
  o["nominal"]["base_in_instrument"] = {{"xyz_mm", {0.0, 0.0, 0.0}}, {"abc_deg", {0.0, 0.0, 0.0}}};
  cal["base_in_instrument"] = c["base_in_instrument"];
  for (const char* key : {"setups", "t_mean_s", "fitted_joint_ranges_deg"})
    if (c.contains(key)) cal[key] = c[key];
  if (c.contains("drift")) cal["effects"].push_back(c["drift"]);
  return o.dump(2);
}

TEST(Setups, ModelFilesOfVersions3And2ReadTheSame) {
  KINCAL_SEED_TRACE(5);
  // a calibrated kr500 (seed 5) with a transmission error, its campaign with a drift, two setups and
  // fitted ranges: written (version 3: a campaign section), rewritten in version 2's layout, both
  // read back to the same models and campaign, value for value
  ModelSpec cs = truth_spec(5, 0.003);
  cs.effects.push_back({Effect{"transmission_error", 1, {1, 2}}, {3e-4, -2e-4, 1e-4, 0.0}});
  Campaign c = test::truth_campaign();
  c.drift = EffectValue{Effect{"drift", -1, {}}, tracker_drift()};
  c.t_mean_s = 5400;
  c.setups = {{"A", c.base_in_instrument}, {"B", second_placement()}};
  c.fitted_deg.assign(6, JointRange{-170.0, 170.0});
  const std::string v3 = robot_to_json(Robot{std::make_shared<Model>(kr500_spec()), std::make_shared<Model>(cs), c});
  EXPECT_NE(v3.find("\"version\": 3"), std::string::npos);
  EXPECT_NE(v3.find("\"campaign\""), std::string::npos);
  const std::string v2 = as_version2(v3);
  const Robot a = robot_from_json(v3, "v3.json"), b = robot_from_json(v2, "v2.json");
  for (const Robot* r : {&a, &b}) {
    const Campaign& rc = r->campaign();
    EXPECT_EQ(rc.base_in_instrument.xyz, c.base_in_instrument.xyz);
    EXPECT_EQ(rc.base_in_instrument.abc, c.base_in_instrument.abc);
    ASSERT_EQ(rc.setups.size(), 2u);
    EXPECT_EQ(rc.setups[1].name, "B");
    EXPECT_EQ(rc.setups[1].base_in_instrument.xyz, second_placement().xyz);
    EXPECT_EQ(rc.t_mean_s, 5400);
    ASSERT_TRUE(rc.drift.has_value());
    for (int k = 0; k < 6; ++k) EXPECT_NEAR(rc.drift->p[k], tracker_drift()[static_cast<size_t>(k)], 1e-18);
    EXPECT_EQ(rc.fitted_deg, c.fitted_deg);
    const ModelSpec& rs = r->calibrated()->spec();
    ASSERT_EQ(rs.effects.size(), 1u);  // the robot's own effect; the drift is the campaign's
    EXPECT_EQ(rs.effects[0].effect.name, "transmission_error");
    for (int j = 0; j < 6; ++j) {
      EXPECT_EQ(rs.joints[j].point, cs.joints[j].point);
      EXPECT_EQ(rs.joints[j].axis, cs.joints[j].axis);
      EXPECT_EQ(rs.joints[j].compliance_deg_per_knm, cs.joints[j].compliance_deg_per_knm);
      EXPECT_EQ(r->nominal()->spec().joints[j].point, kr500_spec().joints[j].point);
    }
  }
  // the same file written again from either: version 3, byte for byte
  EXPECT_EQ(robot_to_json(b), v3);
  // version 1 (the layout of version 2) still reads
  std::string v1 = v2;
  v1.replace(v1.find("\"version\": 2"), 12, "\"version\": 1");
  EXPECT_EQ(robot_to_json(robot_from_json(v1, "v1.json")), v3);
}

TEST(Setups, HiddenDriftIsRecoveredWithinItsUncertainty) {
  KINCAL_SEED_TRACE(31, 5);
  // truth: kr500 (seed 31) with compliance, 1 mm / 0.05 deg errors, a tracker drift of 0.04 mm/h
  // and 0.001 deg/h (tracker_drift) over a 3 h campaign of 150 poses, 3 targets, 0.02 mm noise.
  // Identified with the drift: each of its 6 rates within 4 standard deviations of the truth, the
  // held-out points (another campaign over 3 h on the same truth, another seed) predicted at the
  // noise floor; without the drift the fit is worse.
  SimulationOptions so;
  so.poses = 150;
  so.noise_mm = 0.02;
  so.targets = kTargets;
  so.duration_s = 3 * 3600;
  so.effects = {{Effect{"drift", -1, {}}, tracker_drift()}};
  so.seed = test::test_seed(5);
  const Model truth(truth_spec(31, 0.003));
  const MeasurementSet fit = simulate(truth, so, test::truth_campaign());
  const Model nominal(kr500_spec());
  IdentifyOptions opt;
  opt.effects = {Effect{"drift", -1, {}}};
  const IdentifyResult r = identify(nominal, fit, opt);
  ASSERT_GE(r.layout.drift, 0);
  const auto& v = tracker_drift();
  for (int k = 0; k < 6; ++k) {
    const int i = r.layout.drift + k;
    ASSERT_FALSE(r.fixed[i]) << r.layout.names[i] << ": " << r.fixed_reason[i];
    EXPECT_LT(std::abs(r.x[i] - v[k]), 4 * r.stddev[i]) << r.layout.names[i] << " " << r.x[i] << " +- " << r.stddev[i];
  }
  ASSERT_TRUE(r.campaign.drift.has_value());
  EXPECT_NEAR(r.campaign.t_mean_s, 5400, 1e-9);
  // the rows of the fit: at the noise floor with the drift, clearly above without it
  const double floor = 0.02 * std::sqrt(3.0);
  EXPECT_LT(r.rms_mm, 1.1 * floor);
  IdentifyOptions plain;
  const IdentifyResult rp = identify(nominal, fit, plain);
  EXPECT_GT(rp.rms_mm, 1.3 * floor) << "the drift should leave a visible residual";
}

TEST(Setups, TwoSetupsIdentifiedJointly) {
  KINCAL_SEED_TRACE(41, 1, 2, 3, 4);
  // truth: kr500 (seed 41) with compliance seen from two tracker placements, A (the usual one)
  // and B (second_placement), 80 poses from each, 3 targets, 0.02 mm noise. Identified jointly:
  // the relative placement of the two instruments (B's frame seen from A's, which the robot's
  // gauge cannot change) maps the workspace within 0.02 mm of the truth's, and held-out campaigns
  // from each placement are predicted at the noise floor.
  const Model truth(truth_spec(41, 0.003));
  Campaign campaign_b;
  campaign_b.base_in_instrument = second_placement();
  SimulationOptions so;
  so.poses = 80;
  so.noise_mm = 0.02;
  so.targets = kTargets;
  so.seed = test::test_seed(1);
  const MeasurementSet a = simulate(truth, so, test::truth_campaign());
  so.seed = test::test_seed(2);
  const MeasurementSet data = two_setups(a, simulate(truth, so, campaign_b));
  const Model nominal(kr500_spec());
  const IdentifyResult r = identify(nominal, data, IdentifyOptions{});
  ASSERT_EQ(r.campaign.setups.size(), 2u);
  const Model cal(r.calibrated);
  const Eigen::Isometry3d ia = pose_to_iso(r.campaign.setups[0].base_in_instrument);
  const Eigen::Isometry3d ib = pose_to_iso(r.campaign.setups[1].base_in_instrument);
  const Eigen::Isometry3d ta = test::truth_campaign().base(), tb = campaign_b.base();
  double worst = 0;  // B's instrument coordinates of the measured points, mapped into A's
  for (const auto& row : data.rows)
    if (row.setup == 1) worst = std::max(worst, ((ia * ib.inverse()) * row.xyz - (ta * tb.inverse()) * row.xyz).norm());
  EXPECT_LT(worst, 0.02);
  so.seed = test::test_seed(3);
  const MeasurementSet held_a = simulate(truth, so, test::truth_campaign());
  so.seed = test::test_seed(4);
  const MeasurementSet held = two_setups(held_a, simulate(truth, so, campaign_b));
  const double floor = 0.02 * std::sqrt(3.0);
  EXPECT_LT(rms(point_errors(cal, r.campaign, r.targets, held)), 1.2 * floor);
}

TEST(Setups, ACampaignIsCheckedWhereItEntersARobotOrASimulation) {
  // every value a campaign carries is checked when a Robot is built with it (and a hidden drift when
  // a simulation adds it): one InputError naming the cause
  auto m = std::make_shared<Model>(kr500_spec());
  auto refused = [&](const Campaign& c) { return test::error_of([&] { Robot r(m, m, c); }); };
  Campaign twice;
  twice.setups = {{"A", Pose6{}}, {"A", second_placement()}};
  EXPECT_NE(refused(twice).find("setup 'A' is given twice"), std::string::npos);
  Campaign nan_base;
  nan_base.base_in_instrument.xyz[1] = std::nan("");
  EXPECT_NE(refused(nan_base).find("NaN or infinite"), std::string::npos);
  Campaign short_drift;
  short_drift.drift = EffectValue{Effect{"drift", -1, {}}, {0.1, 0.2}};
  EXPECT_NE(refused(short_drift).find("2 values for 6 parameters"), std::string::npos);
  Campaign not_a_drift;
  not_a_drift.drift = EffectValue{Effect{"backlash", 1, {}}, {0.001}};
  EXPECT_NE(refused(not_a_drift).find("not the instrument's drift"), std::string::npos);
  Campaign ranges;
  ranges.fitted_deg.assign(5, JointRange{-10.0, 10.0});
  EXPECT_NE(refused(ranges).find("5 ranges for 6 joints"), std::string::npos);
  Campaign drifting;
  drifting.drift = EffectValue{Effect{"drift", -1, {}}, tracker_drift()};
  SimulationOptions so;
  so.poses = 3;
  so.duration_s = 600;
  so.effects = {{Effect{"drift", -1, {}}, tracker_drift()}};
  EXPECT_NE(test::error_of([&] { simulate(*m, so, drifting); }).find("drift is given twice"), std::string::npos);
  so.effects = {{Effect{"drift", -1, {}}, {0.1}}};
  EXPECT_NE(test::error_of([&] { simulate(*m, so); }).find("1 values for 6 parameters"), std::string::npos);
}
