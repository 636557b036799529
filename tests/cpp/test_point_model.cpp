// The identification's measurement model: the analytic Jacobian of PointModel (rigid, compliant,
// with effects) and of the 6-D row residuals against central differences.
#include "kincal/identify/design.hpp"
#include "kincal/identify/point_model.hpp"
#include "kincal/identify/simulate.hpp"
#include "identify_test_util.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <algorithm>
#include <random>

using namespace kincal;
using kincal::test::kTargets;
using kincal::test::truth_spec;

namespace {

// Central differences of the prediction against the analytic Jacobian, every parameter.
// Returns the largest error of every column relative to that column's largest entry.
std::vector<double> jacobian_errors(const PointModel& pm, const std::vector<double>& x, const MeasurementSet& d) {
  const int P = pm.layout().size;
  std::vector<double> worst(P, 0.0);
  for (const auto& row : d.rows) {
    const PointState at_x = pm.at(x);
    std::vector<double> J(3 * P);
    at_x.predict(row, J.data());
    for (int i = 0; i < P; ++i) {
      const double h = pm.layout().units[i] == "rad" ? 1e-5 : 1e-3;
      std::vector<double> xp = x, xm = x;
      xp[i] += h;
      xm[i] -= h;
      const PointState at_xp = pm.at(xp);
      const Vec3 yp = at_xp.predict(row, nullptr);
      const PointState at_xm = pm.at(xm);
      const Vec3 ym = at_xm.predict(row, nullptr);
      const Vec3 fd = (yp - ym) / (2 * h);
      const Vec3 an(J[i], J[P + i], J[2 * P + i]);
      const double scale = std::max(1.0, an.cwiseAbs().maxCoeff());
      worst[i] = std::max(worst[i], (fd - an).cwiseAbs().maxCoeff() / scale);
    }
  }
  return worst;
}

/// A noise-free campaign of 20 poses on a truth (for the derivative tests).
MeasurementSet small_campaign(const Model& truth, const std::vector<Vec3>& targets, double orientation_noise = -1) {
  SimulationOptions so;
  so.seed = test::test_seed(1);  // the simulator's default
  so.poses = 20;
  so.noise_mm = 0;
  so.targets = targets;
  so.orientation_noise_deg = orientation_noise;
  return simulate(truth, so, test::truth_campaign());
}

}  // namespace

TEST(PointModel, JacobianMatchesFiniteDifferencesRigid) {
  KINCAL_SEED_TRACE(3, 1, 5);
  // truth: kr500 with geometric errors, three targets; parameters at a random non-zero point,
  // compliance zero (the geometry does not act through gravity torque)
  const MeasurementSet d = small_campaign(Model(truth_spec(3, 0.0)), kTargets);
  const Model nominal(kr500_spec());
  PointModel pm(nominal, {3});
  std::vector<double> x = pm.start(d);
  std::mt19937_64 rng(test::test_seed(5));
  std::normal_distribution<double> nd(0, 1);
  for (int i = 0; i < pm.layout().size; ++i) {
    if (i >= pm.layout().compliance && i < pm.layout().tool) continue;
    x[i] += nd(rng) * (pm.layout().units[i] == "rad" ? 0.01 : 2.0);
  }
  const auto worst = jacobian_errors(pm, x, d);
  for (int i = 0; i < pm.layout().size; ++i) EXPECT_LT(worst[i], 1e-6) << pm.layout().names[i];
}

TEST(PointModel, JacobianMatchesFiniteDifferencesCompliant) {
  KINCAL_SEED_TRACE(4, 1, 6);
  // with compliance the geometry also acts through the gravity torque (links, axes, payload move)
  const MeasurementSet d = small_campaign(Model(truth_spec(4, 0.003)), kTargets);
  const Model nominal(kr500_spec());
  PointModel pm(nominal, {3});
  std::vector<double> x = pm.start(d);
  std::mt19937_64 rng(test::test_seed(6));
  std::normal_distribution<double> nd(0, 1);
  for (int i = 0; i < pm.layout().size; ++i)
    x[i] += (i >= pm.layout().compliance && i < pm.layout().tool) ? 0.003 : nd(rng) * (pm.layout().units[i] == "rad" ? 0.001 : 1.0);
  const auto worst = jacobian_errors(pm, x, d);
  for (int i = 0; i < pm.layout().size; ++i)
    EXPECT_LT(worst[i], 1e-6) << pm.layout().names[i];
}

TEST(PointModel, JacobianMatchesFiniteDifferencesWithEffects) {
  KINCAL_SEED_TRACE(5, 1, 8);
  // truth: kr500 with compliance, transmission error on A3, backlash on A2, thermal expansion;
  // the model adds a joint_map of order 6 on A5; the parameters at a random point (every effect
  // non-zero) and 30 poses with dir and temperature
  SimulationOptions so;
  so.seed = test::test_seed(1);  // the simulator's default
  so.poses = 30;
  so.noise_mm = 0;
  so.targets = kTargets;
  const MeasurementSet d = simulate(Model(truth_spec(5, 0.003)), so, test::truth_campaign());
  const Model nominal(kr500_spec());
  const std::vector<Effect> eff = {{"transmission_error", 2}, {"backlash", 1}, {"thermal_expansion", -1}, joint_map(4, 6)};
  PointModel pm(nominal, {3, eff, 24.0});
  std::vector<double> x = pm.start(d);
  std::mt19937_64 rng(test::test_seed(8));
  std::normal_distribution<double> nd(0, 1);
  const ParamLayout& L = pm.layout();
  for (int i = 0; i < L.size; ++i) {
    if (i >= L.compliance && i < L.tool) x[i] += 0.003;
    else if (i >= L.effects) x[i] += (L.units[i] == "rad" ? 1e-4 : 1e-5) * nd(rng);
    else x[i] += nd(rng) * (L.units[i] == "rad" ? 0.001 : 1.0);
  }
  const auto worst = jacobian_errors(pm, x, d);
  for (int i = 0; i < L.size; ++i) EXPECT_LT(worst[i], 1e-6) << L.names[i];
}

TEST(PointModel, OrientationJacobianMatchesFiniteDifferences) {
  KINCAL_SEED_TRACE(6, 1, 9);
  // 6-D rows (the tool frame's orientation measured): the 6 x P residual Jacobian of row_residuals
  // against central differences, at a random parameter point with compliance and effects
  SimulationOptions so;
  so.seed = test::test_seed(1);  // the simulator's default
  so.poses = 15;
  so.noise_mm = 0.02;
  so.orientation_noise_deg = 0.01;
  so.targets = {Vec3(0, 0, 0)};
  const MeasurementSet d = simulate(Model(truth_spec(6, 0.003)), so, test::truth_campaign());
  ASSERT_TRUE(d.orientation);
  const Model nominal(kr500_spec());
  const std::vector<Effect> eff = {{"transmission_error", 3}, {"thermal_expansion", -1}};
  PointModel pm(nominal, {1, eff, 24.0});
  std::vector<double> x = pm.start(d);
  std::mt19937_64 rng(test::test_seed(9));
  std::normal_distribution<double> nd(0, 1);
  const ParamLayout& L = pm.layout();
  for (int i = 0; i < L.size; ++i) {
    if (i >= L.compliance && i < L.tool) x[i] += 0.003;
    else if (i >= L.effects) x[i] += (L.units[i] == "rad" ? 1e-4 : 1e-5) * nd(rng);
    else x[i] += nd(rng) * (L.units[i] == "rad" ? 0.001 : 1.0);
  }
  const double w = 100.0;
  for (const auto& row : d.rows) {
    const PointState at_x = pm.at(x);
    std::vector<double> J(6 * L.size), r(6);
    ASSERT_EQ(row_residuals(at_x, row, ResidualKind::pose, w, r.data(), J.data()), 6);
    for (int i = 0; i < L.size; ++i) {
      // (rad: 1e-5, where the rounding of 3000 mm points over 2h and the truncation, 3000 mm/rad^3 h^2 / 6, are both
      // 5e-8; at 1e-6 the rounding alone reached 1.3e-6 on some seeds)
      const double h = L.units[i] == "rad" ? 1e-5 : (L.units[i] == "mm" ? 1e-3 : 1e-5);
      std::vector<double> xp = x, xm = x, rp(6), rm(6);
      xp[i] += h;
      xm[i] -= h;
      const PointState at_xp = pm.at(xp);
      row_residuals(at_xp, row, ResidualKind::pose, w, rp.data(), nullptr);
      const PointState at_xm = pm.at(xm);
      row_residuals(at_xm, row, ResidualKind::pose, w, rm.data(), nullptr);
      double scale = 1.0;
      for (int k = 0; k < 6; ++k) scale = std::max(scale, std::abs(J[k * L.size + i]));
      for (int k = 0; k < 6; ++k)
        EXPECT_LT(std::abs((rp[k] - rm[k]) / (2 * h) - J[k * L.size + i]) / scale, 1e-6) << L.names[i] << " row " << k;
    }
  }
}

namespace {

/// The kr500 without a mass table (a URDF without inertials): every link mass zero.
ModelSpec massless_kr500() {
  ModelSpec s = kr500_spec();
  for (JointSpec& j : s.joints) j.mass_kg = 0, j.com.setZero();
  return s;
}

/// A parameter point of the fitted gravity: the geometry moved, compliances and moments non-zero.
std::vector<double> fitted_gravity_point(const PointModel& pm, const MeasurementSet& d, unsigned seed) {
  const ParamLayout& L = pm.layout();
  std::vector<double> x = pm.start(d);
  std::mt19937_64 rng(test::test_seed(seed));
  std::normal_distribution<double> nd(0, 1);
  for (int i = 0; i < L.size; ++i) {
    if (i >= L.compliance && i < L.moments) x[i] = 0.003 * (1.0 + 0.3 * nd(rng));
    else if (i >= L.moments && i < L.tool) x[i] = 0.4 * nd(rng);  // t m: deflections of ~0.01 deg
    else x[i] += nd(rng) * (L.units[i] == "rad" ? 0.001 : 1.0);
  }
  return x;
}

}  // namespace

TEST(PointModel, GravityModeFromTheMassTable) {
  const Model with(kr500_spec()), without(massless_kr500());
  EXPECT_FALSE(gravity_fitted(with, GravityTorques::automatic));
  EXPECT_TRUE(gravity_fitted(without, GravityTorques::automatic));
  EXPECT_TRUE(gravity_fitted(with, GravityTorques::fit));
  EXPECT_FALSE(gravity_fitted(with, GravityTorques::masses));
  EXPECT_THROW(gravity_fitted(without, GravityTorques::masses), InputError);
  EXPECT_THROW(parse_gravity("guess"), InputError);
  EXPECT_EQ(gravity_word(parse_gravity("fit")), "fit");
  EXPECT_THROW(parse_loss("l1"), InputError);
  EXPECT_EQ(loss_word(parse_loss("cauchy")), "cauchy");
  // the fitted layout: 2 moments per link from the first loaded joint's (A2) on, after the compliances
  const ParamLayout L(without, {3, {}, 20.0, {}, 0, true});
  ASSERT_EQ(L.moment_links, (std::vector<int>{1, 2, 3, 4, 5}));
  EXPECT_EQ(L.moments, L.compliance + static_cast<int>(L.loaded.size()));
  EXPECT_EQ(L.tool, L.moments + 10);
  EXPECT_EQ(L.names[L.moments], "link2.moment_u");
  EXPECT_EQ(L.units[L.moments + 9], "t m");
  EXPECT_EQ(ParamLayout(without, {3}).moment_links.size(), 0u);
}

TEST(PointModel, JacobianMatchesFiniteDifferencesFittedGravity) {
  KINCAL_SEED_TRACE(4, 1, 11);
  // truth: kr500 with compliance; the model without masses, its gravity torques from fitted moments
  // (and the kr500's 300 kg payload, known), at a random point: every column against central
  // differences, the moments' included (they act through the torque only)
  const MeasurementSet d = small_campaign(Model(truth_spec(4, 0.003)), kTargets);
  const Model nominal(massless_kr500());
  PointModel pm(nominal, {3, {}, 20.0, {}, 0, true});
  const std::vector<double> x = fitted_gravity_point(pm, d, 11);
  const auto worst = jacobian_errors(pm, x, d);
  for (int i = 0; i < pm.layout().size; ++i) EXPECT_LT(worst[i], 1e-6) << pm.layout().names[i];
}

TEST(PointModel, FittedGravityOrientationJacobianAndWrittenModel) {
  KINCAL_SEED_TRACE(6, 1, 12);
  // 6-D rows: the Jacobian of the moments and compliances, position and orientation rows, against
  // central differences relative to each column's largest entry (the test above is absolute for
  // columns below 1); and the model written from the parameters (its mass table of unit masses) predicts
  // every point as the measurement model does, so fk and compensate apply the fitted deflection
  SimulationOptions so;
  so.seed = test::test_seed(1);  // the simulator's default
  so.poses = 12;
  so.noise_mm = 0.02;
  so.orientation_noise_deg = 0.01;
  so.targets = {Vec3(0, 0, 0)};
  const MeasurementSet d = simulate(Model(truth_spec(6, 0.003)), so, test::truth_campaign());
  const Model nominal(massless_kr500());
  PointModel pm(nominal, {1, {}, 20.0, {}, 0, true});
  const ParamLayout& L = pm.layout();
  const std::vector<double> x = fitted_gravity_point(pm, d, 12);
  const double w = 100.0;
  for (const auto& row : d.rows) {
    const PointState at_x = pm.at(x);
    std::vector<double> J(6 * L.size), r(6);
    ASSERT_EQ(row_residuals(at_x, row, ResidualKind::pose, w, r.data(), J.data()), 6);
    for (int i = L.compliance; i < L.tool; ++i) {
      // moments: 0.4 t m; compliances 0.003 deg/kNm: 1e-4 (the rounding of points 3000 mm from the base, 1e-12 mm,
      // over 2h: 5e-9 per unit)
      const double h = L.units[i] == "t m" ? 1e-3 : 1e-4;
      std::vector<double> xp = x, xm = x, rp(6), rm(6);
      xp[i] += h;
      xm[i] -= h;
      const PointState at_xp = pm.at(xp);
      row_residuals(at_xp, row, ResidualKind::pose, w, rp.data(), nullptr);
      const PointState at_xm = pm.at(xm);
      row_residuals(at_xm, row, ResidualKind::pose, w, rm.data(), nullptr);
      double scale = 0;
      for (int k = 0; k < 6; ++k) scale = std::max(scale, std::abs(J[k * L.size + i]));
      ASSERT_GT(scale, 0) << L.names[i];
      // relative to 0.01 at least (mm or weighted rad per unit): below it the rounding above is 1e-6 of the
      // column and more (on some seeds A6's compliance, which gravity barely loads, moves a row by 0.002)
      scale = std::max(scale, 0.01);
      for (int k = 0; k < 6; ++k)
        EXPECT_LT(std::abs((rp[k] - rm[k]) / (2 * h) - J[k * L.size + i]) / scale, 1e-6) << L.names[i] << " row " << k;
    }
  }
  const PointState at_x = pm.at(x);
  const Model written(at_x.spec());
  const std::vector<Vec3> targets = {Vec3(x[L.targets], x[L.targets + 1], x[L.targets + 2])};
  const std::vector<double> e = point_errors(written, at_x.campaign(), targets, d);
  ASSERT_EQ(e.size(), d.rows.size());
  for (size_t i = 0; i < d.rows.size(); ++i)
    EXPECT_NEAR(e[i], (at_x.predict(d.rows[i], nullptr) - d.rows[i].xyz).norm(), 1e-9);
}

// The D-optimal gain of kincal plan: log det(I + J_i M^-1 J_i^T) for each candidate, against the
// determinant of that matrix in double precision. Truth: 40 candidates of 9 rows x 12 standard normal
// columns, M = 0.5 I + B^T B of 30 more such rows (seeded); the gains are single precision products,
// so they agree to 1e-4 relative.
TEST(Design, GainsAreTheLogDeterminantsOfTheCandidatesBlocks) {
  std::mt19937_64 rng(test::test_seed(21));
  std::normal_distribution<double> nd;
  const int n = 40, rows = 9, cols = 12;
  Eigen::MatrixXd Jd(n * rows, cols), B(30, cols);
  for (Eigen::Index i = 0; i < Jd.size(); ++i) Jd.data()[i] = nd(rng);
  for (Eigen::Index i = 0; i < B.size(); ++i) B.data()[i] = nd(rng);
  const Eigen::MatrixXd M = 0.5 * Eigen::MatrixXd::Identity(cols, cols) + B.transpose() * B;
  const Eigen::MatrixXd Minv = M.inverse();
  const Eigen::MatrixXd Ld = Eigen::LLT<Eigen::MatrixXd>(0.5 * (Minv + Minv.transpose())).matrixL();
  // row-major float copies, as numpy hands them over
  std::vector<float> J(static_cast<size_t>(n * rows * cols)), L(static_cast<size_t>(cols * cols));
  for (int r = 0; r < n * rows; ++r)
    for (int c = 0; c < cols; ++c) J[static_cast<size_t>(r * cols + c)] = static_cast<float>(Jd(r, c));
  for (int r = 0; r < cols; ++r)
    for (int c = 0; c < cols; ++c) L[static_cast<size_t>(r * cols + c)] = static_cast<float>(c <= r ? Ld(r, c) : 99.0);
  const std::vector<std::int64_t> idx = {39, 0, 17, 17, 5};  // any order, repeats allowed
  std::vector<float> gain(idx.size());
  d_optimal_gains(J.data(), n, rows, cols, idx.data(), idx.size(), L.data(), gain.data());
  for (size_t k = 0; k < idx.size(); ++k) {
    const Eigen::MatrixXd Ji = Jd.middleRows(idx[k] * rows, rows);
    const double want =
        std::log((Eigen::MatrixXd::Identity(rows, rows) + Ji * Minv * Ji.transpose()).determinant());
    EXPECT_NEAR(gain[k], want, 1e-4 * std::abs(want)) << "candidate " << idx[k];
  }
  const std::vector<std::int64_t> out_of_range = {40};
  EXPECT_EQ(test::error_of([&] {
              d_optimal_gains(J.data(), n, rows, cols, out_of_range.data(), 1, L.data(), gain.data());
            }),
            "d_optimal_gains: candidate 40 of 40");
  J[0] = std::nanf("");
  const std::string nan_error =
      test::error_of([&] { d_optimal_gains(J.data(), n, rows, cols, idx.data(), idx.size(), L.data(), gain.data()); });
  EXPECT_NE(nan_error.find("candidate 0: its block is not positive definite"), std::string::npos) << nan_error;
}
