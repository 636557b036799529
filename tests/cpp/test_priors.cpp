// Identification's priors and the data's noise scale (identify/priors.cpp) in C++: the prior standard
// deviations by kind, the prior terms of a solve, the residuals' robust spread and the robust loss's scale.
//
// Truth: the definitions of priors.hpp and of the statistics behind them. A Gaussian prior N(mean, sd) on a
// parameter whose data residuals weigh 1 / noise is the penalty residual (noise / sd) (z - mean): the cost is
// the negative log posterior times noise^2, whose minimum is the posterior mean (checked on a scalar with m
// measurements against the conjugate formula). The robust spread is 1.4826 x the median absolute deviation
// (the standard deviation of Gaussian data) times sqrt(n / (n - p)); the loss bends at the 99.9% point of the
// norm of 3 or 6 Gaussian components (chi-square quantiles checked with the closed-form distribution
// functions of 3 and 6 degrees of freedom).
#include "kincal/identify/identifiability.hpp"
#include "kincal/identify/priors.hpp"
#include "kincal/model/robots.hpp"

#include "test_util.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <limits>
#include <random>
#include <string>

using namespace kincal;

namespace {

using test::error_of;

double sd_of(const std::vector<double>& v) {
  double m = 0, s = 0;
  for (double x : v) m += x;
  m /= v.size();
  for (double x : v) s += (x - m) * (x - m);
  return std::sqrt(s / (v.size() - 1));
}

}  // namespace

// prior_sds: each kind's parameters (by range and unit) get its standard deviation times the scale, the
// others none (infinity); no priors at scale 0; unknown kinds, non-positive deviations and scales refused.
TEST(Priors, StandardDeviationsFollowTheKinds) {
  const Model m(kr500_spec());
  const ParamLayout L(m, {2, {Effect{"backlash", 1, {}}}});
  IdentifyOptions opt;
  opt.prior_scale = 2;
  const double inf = std::numeric_limits<double>::infinity(), deg = kPi / 180;
  std::vector<double> sd = prior_sds(L, opt);
  ASSERT_EQ(sd.size(), static_cast<size_t>(L.size));
  for (int i = 0; i < L.size; ++i) {
    const std::string& n = L.names[i];
    double want = inf;  // the defaults: the joint lines (1 mm, 0.1 deg) and the tool (5 mm, 1 deg)
    if (i < L.compliance) want = L.units[i] == "mm" ? 2 * 1.0 : 2 * 0.1 * deg;
    if (i >= L.tool && i < L.base) want = L.units[i] == "mm" ? 2 * 5.0 : 2 * 1.0 * deg;
    EXPECT_DOUBLE_EQ(sd[i], want) << n;
  }
  opt.prior_sd = {{"compliance", 0.001}, {"base_mm", 3}, {"base_rad", 0.01}, {"target_mm", 0.5}, {"backlash", 1e-4}};
  opt.prior_scale = 1;
  sd = prior_sds(L, opt);
  for (int i = 0; i < L.size; ++i) {
    double want = inf;
    if (i >= L.compliance && i < L.tool) want = 0.001;
    if (i >= L.base && i < L.targets) want = L.units[i] == "mm" ? 3 : 0.01;
    if (i >= L.targets && i < L.effects) want = 0.5;
    if (i >= L.effects) want = 1e-4;
    EXPECT_DOUBLE_EQ(sd[i], want) << L.names[i];
  }
  opt.prior_scale = 0;
  for (double s : prior_sds(L, opt)) EXPECT_EQ(s, inf);
  opt.prior_scale = 1;
  opt.prior_sd = {{"joints_mm", 1}};
  EXPECT_NE(error_of([&] { prior_sds(L, opt); }).find("no prior kind 'joints_mm'"), std::string::npos);
  for (double bad : {0.0, -1.0, std::nan(""), inf}) {
    opt.prior_sd = {{"tool_mm", bad}};
    EXPECT_NE(error_of([&] { prior_sds(L, opt); }).find("'tool_mm' must be a positive number"), std::string::npos)
        << bad;
  }
  opt.prior_sd = default_prior_sd();
  for (double bad : {-1.0, std::nan(""), inf}) {
    opt.prior_scale = bad;
    EXPECT_NE(error_of([&] { prior_sds(L, opt); }).find("prior scale must be a positive number"), std::string::npos)
        << bad;
  }
}

// prior_terms: one term per free parameter that has a prior, indexed among the free ones, weight noise / sd,
// centred on the start. Solving the scalar problem its residuals make (m measurements y_j of z in mm, the
// term) gives the posterior mean of z under the prior N(start, sd) with Gaussian noise: the conjugate formula.
TEST(Priors, TermsWeighNoiseOverTheStandardDeviation) {
  const double inf = std::numeric_limits<double>::infinity();
  const std::vector<double> sd = {0.5, inf, 2.0, 0.1, inf};
  const std::vector<double> start = {1.0, 2.0, 3.0, 4.0, 5.0};
  const std::vector<int> free_idx = {0, 1, 3, 4};  // parameter 2 held: no term
  const std::vector<PenaltyTerm> t = prior_terms(sd, start, free_idx, 0.02);
  ASSERT_EQ(t.size(), 2u);
  EXPECT_EQ(t[0].index, 0);
  EXPECT_DOUBLE_EQ(t[0].weight, 0.02 / 0.5);
  EXPECT_DOUBLE_EQ(t[0].mean, 1.0);
  EXPECT_EQ(t[1].index, 2);  // parameter 3 is the third free one
  EXPECT_DOUBLE_EQ(t[1].weight, 0.02 / 0.1);
  EXPECT_DOUBLE_EQ(t[1].mean, 4.0);
  // the scalar problem: residuals y_j - z (mm) and w (z - mean); its least-squares minimum against the
  // posterior mean (sum y / noise^2 + mean / sd^2) / (m / noise^2 + 1 / sd^2)
  std::mt19937_64 rng(test::test_seed(101));
  KINCAL_SEED_TRACE(101);
  std::normal_distribution<double> nd(0.3, 0.02);
  const double noise = 0.02, prior_mean = 0.25, prior_sd = 0.01;
  std::vector<double> y(8);
  double sum = 0;
  for (double& v : y) v = nd(rng), sum += v;
  const PenaltyTerm p = prior_terms({prior_sd}, {prior_mean}, {0}, noise).at(0);
  const double z = (sum + p.weight * p.weight * p.mean) / (y.size() + p.weight * p.weight);
  const double posterior = (sum / (noise * noise) + prior_mean / (prior_sd * prior_sd)) /
                           (y.size() / (noise * noise) + 1 / (prior_sd * prior_sd));
  EXPECT_NEAR(z, posterior, 1e-15);
}

// robust_noise: 1.4826 x the median absolute deviation, corrected by sqrt(n / (n - p)); on Gaussian data the
// standard deviation (30000 draws: within 3%); with 10% gross errors (5 mm) still within 20% (the median's
// bias under 10% contamination is 13%) while the standard deviation grows 25 times; never below 0.1 um.
TEST(Priors, RobustNoiseOnKnownData) {
  KINCAL_SEED_TRACE(102);
  // {1, 2, 3, 4, 100}: median 3, absolute deviations {2, 1, 0, 1, 97}, their median 1
  EXPECT_DOUBLE_EQ(robust_noise({1, 2, 3, 4, 100}, 0), 1.4826);
  EXPECT_DOUBLE_EQ(robust_noise({1, 2, 3, 4, 100}, 1), 1.4826 * std::sqrt(5.0 / 4.0));
  std::mt19937_64 rng(test::test_seed(102));
  const double sigma = 0.02;
  std::normal_distribution<double> nd(0.1, sigma);  // an offset changes nothing: deviations from the median
  std::vector<double> v(30000);
  for (double& x : v) x = nd(rng);
  EXPECT_NEAR(robust_noise(v, 0), sigma, 0.03 * sigma);
  std::uniform_real_distribution<double> u(0, 1);
  for (size_t i = 0; i < v.size(); i += 10) v[i] += u(rng) < 0.5 ? 5.0 : -5.0;
  EXPECT_GT(sd_of(v), 25 * sigma);
  EXPECT_NEAR(robust_noise(v, 0), 1.134 * sigma, 0.07 * sigma);
  EXPECT_EQ(robust_noise(std::vector<double>(50, 0.3), 0), 1e-4);
  EXPECT_EQ(robust_noise({}, 0), 1e-4);
}

// loss_threshold: noise times the square root of the chi-square 99.9% quantile, 3 components (a point) or 6
// (a pose): the distribution functions there, F3(x) = erf(sqrt(x/2)) - sqrt(2x/pi) exp(-x/2) and
// F6(x) = 1 - exp(-x/2) (1 + x/2 + x^2/8), are 0.999.
TEST(Priors, LossThresholdIsTheNormsQuantile) {
  for (const double noise : {0.02, 0.5}) {
    const double x3 = std::pow(loss_threshold(noise, 3) / noise, 2), x6 = std::pow(loss_threshold(noise, 6) / noise, 2);
    EXPECT_NEAR(std::erf(std::sqrt(x3 / 2)) - std::sqrt(2 * x3 / kPi) * std::exp(-x3 / 2), 0.999, 2e-6);
    EXPECT_NEAR(1 - std::exp(-x6 / 2) * (1 + x6 / 2 + x6 * x6 / 8), 0.999, 2e-6);
  }
  EXPECT_NEAR(loss_threshold(1.0, 3), 4.03, 0.005);
  EXPECT_NEAR(loss_threshold(1.0, 6), 4.74, 0.005);
}

// least_squares_noise: after one Gauss-Newton step of the determined columns the residuals are the noise: a
// linear model r = J b + e (e Gaussian, 0.05 mm on the positions) gives back 0.05 mm within 5%. With 6-residual
// rows whose orientation components are noise-free (exactly J b: zero after the fit) it is still 0.05 mm: only
// the positions are measured (the zeros would halve the median). Without the columns that made part of r the
// fit leaves that part in, far above the noise.
TEST(Priors, LeastSquaresNoiseIsTheResidualsSpreadAfterTheFit) {
  KINCAL_SEED_TRACE(103);
  std::mt19937_64 rng(test::test_seed(103));
  std::normal_distribution<double> nd(0, 1);
  const double sigma = 0.05;
  for (const int row : {3, 6}) {
    SCOPED_TRACE(row);
    const int rows = 2000, n = rows * row, p = 8;
    Linearization lin;
    lin.jacobian.resize(n, p);
    for (int i = 0; i < n; ++i)
      for (int k = 0; k < p; ++k) lin.jacobian(i, k) = nd(rng);
    Eigen::VectorXd b(p);
    for (int k = 0; k < p; ++k) b[k] = 3 * nd(rng);
    const Eigen::VectorXd clean = lin.jacobian * b;
    lin.residuals.resize(static_cast<size_t>(n));
    for (int i = 0; i < n; ++i)
      lin.residuals[static_cast<size_t>(i)] = clean[i] + (i % row < 3 ? sigma * nd(rng) : 0.0);
    std::vector<int> all(p);
    for (int k = 0; k < p; ++k) all[static_cast<size_t>(k)] = k;
    MeasurementSet points;  // the rows' kind: points (3 position equations each)
    points.rows.resize(static_cast<size_t>(rows));
    EXPECT_NEAR(least_squares_noise(lin, all, points, row), sigma, 0.05 * sigma);
    EXPECT_GT(least_squares_noise(lin, {0, 1, 2, 3}, points, row), 20 * sigma);
    // plane rows of a probe: one equation each (the first component); the other two, noise-free
    // here, are not counted
    MeasurementSet planes = points;
    for (auto& r : planes.rows) r.kind = MeasureKind::plane;
    Linearization one = lin;
    for (int i = 0; i < n; ++i)
      if (i % row != 0) one.residuals[static_cast<size_t>(i)] = clean[i];
    EXPECT_NEAR(least_squares_noise(one, all, planes, row), sigma, 0.08 * sigma);
  }
}
