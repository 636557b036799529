// The time-optimal feed along a joint path (feed/feed.cpp, time_optimal_feed) in C++: the rate s-dot(s) from
// rest to rest under joint velocity and acceleration limits and a cap, on paths with known derivatives. (The
// derivatives of a sampled program, the feed limits of eqs. 21, 27 and 28 and the violations are computed in
// Python, kincal.programs.feed: tests/python/test_feed.py; the C++ unit is this integration.)
//
// Truth: (1) a straight joint path q = p s (q' = p, q'' = 0): the time-optimal rest-to-rest motion is the
// trapezoid s-dot = min(sqrt(2 a s), v, sqrt(2 a (L - s))) with v = min v_i / |p_i| and a = min a_i / |p_i|,
// its time L / v + v / a (or 2 sqrt(L / a) when it never cruises); the forward-backward integration of
// x = s-dot^2 is exact for constant acceleration (and the trapezoid rule of the time for linear s-dot), so the
// grid values and the time agree to rounding, the time to the grid's resolution at the corners. (2) A cubic
// joint program q_i(s) with its analytic q', q'': with accelerations out of the way the rate is the velocity
// limit min_i v_i / |q_i'(s)| at every interior point, its minimum where |q_2'| peaks (s = 4/3, axis 2, 0.375);
// with acceleration limits every point keeps |q' s-dot| <= v and the acceleration between two grid points,
// |q' s-ddot + q'' s-dot^2|, within a (to the grid's resolution); and a cap holds wherever it is lowest.
#include "kincal/feed/feed.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>

using namespace kincal;

namespace {

Eigen::VectorXd grid(double length, int n) { return Eigen::VectorXd::LinSpaced(n, 0.0, length); }

// the cubic program: q1 = 0.5 s - 0.3 s^2 + 0.05 s^3, q2 = 0.2 + 0.4 s^2 - 0.1 s^3, q3 = -0.3 s (rad), s in [0, 2]
void cubic(const Eigen::VectorXd& s, RowMatrix& d1, RowMatrix& d2) {
  d1.resize(s.size(), 3);
  d2.resize(s.size(), 3);
  for (Eigen::Index k = 0; k < s.size(); ++k) {
    const double x = s[k];
    d1.row(k) << 0.5 - 0.6 * x + 0.15 * x * x, 0.8 * x - 0.3 * x * x, -0.3;
    d2.row(k) << -0.6 + 0.3 * x, 0.8 - 0.6 * x, 0.0;
  }
}

}  // namespace

TEST(Feed, StraightPathIsTheTrapezoid) {
  const Eigen::Vector3d p(0.6, -0.3, 0.2);  // rad per unit of s
  const Eigen::Vector3d v(1.2, 0.9, 0.5), a(3.0, 2.0, 0.8);
  const double vmax = std::min({v[0] / 0.6, v[1] / 0.3, v[2] / 0.2});  // 2.0 (axis 1)
  const double amax = std::min({a[0] / 0.6, a[1] / 0.3, a[2] / 0.2});  // 4.0 (axes 2 and 3)
  for (const double length : {3.0, 0.5}) {  // cruising (L >= v^2 / a = 1), and not (the triangle)
    const int n = 2001;
    const Eigen::VectorXd s = grid(length, n);
    RowMatrix d1(n, 3), d2 = RowMatrix::Zero(n, 3);
    for (int k = 0; k < n; ++k) d1.row(k) = p.transpose();
    double time = 0;
    const Eigen::VectorXd sd = time_optimal_feed(s, d1, d2, v, a, Eigen::VectorXd(), time);
    ASSERT_EQ(sd.size(), n);
    double worst = 0;
    for (int k = 0; k < n; ++k) {
      const double want = std::min({std::sqrt(2 * amax * s[k]), vmax, std::sqrt(2 * amax * (length - s[k]))});
      worst = std::max(worst, std::abs(sd[k] - want));
    }
    EXPECT_LT(worst, 1e-12) << length;
    const double t = length >= vmax * vmax / amax ? length / vmax + vmax / amax : 2 * std::sqrt(length / amax);
    EXPECT_NEAR(time, t, 1e-4 * t) << length;
    EXPECT_EQ(sd[0], 0.0);
    EXPECT_EQ(sd[n - 1], 0.0);
  }
}

TEST(Feed, VelocityLimitIsFoundWhereItIs) {
  const int n = 1501;
  const Eigen::VectorXd s = grid(2.0, n);
  RowMatrix d1, d2;
  cubic(s, d1, d2);
  const Eigen::Vector3d v(1.0, 0.2, 0.5), a = Eigen::Vector3d::Constant(1e6);
  double time = 0;
  const Eigen::VectorXd sd = time_optimal_feed(s, d1, d2, v, a, Eigen::VectorXd(), time);
  double worst = 0;
  int at = 1;
  for (int k = 1; k + 1 < n; ++k) {
    double limit = std::numeric_limits<double>::infinity();
    for (int i = 0; i < 3; ++i) limit = std::min(limit, v[i] / std::abs(d1(k, i)));
    worst = std::max(worst, std::abs(sd[k] / limit - 1));
    if (sd[k] < sd[at]) at = k;
  }
  EXPECT_LT(worst, 1e-12);  // the velocity limit itself at every interior point
  const double step = 2.0 / (n - 1);
  EXPECT_NEAR(s[at], 4.0 / 3.0, step);                    // where |q2'| = 0.8 s - 0.3 s^2 peaks
  EXPECT_NEAR(sd[at], 0.375, 1e-6);                        // v2 / 0.5333
  EXPECT_NEAR(std::abs(d1(at, 1)) * sd[at], v[1], 1e-12);  // axis 2 binds there
  // the time is the integral of 1 / s-dot (trapezoid rule on the grid)
  double t = 0;
  for (int k = 0; k + 1 < n; ++k) t += step / (0.5 * (sd[k] + sd[k + 1]));
  EXPECT_NEAR(time, t, 1e-12 * t);
}

TEST(Feed, EveryLimitHoldsAlongTheCubic) {
  const int n = 4001;
  const Eigen::VectorXd s = grid(2.0, n);
  RowMatrix d1, d2;
  cubic(s, d1, d2);
  const Eigen::Vector3d v(1.0, 0.6, 0.5), a(0.8, 0.3, 0.4);
  Eigen::VectorXd cap = Eigen::VectorXd::Constant(n, 10.0);
  for (int k = 0; k < n; ++k)
    if (s[k] > 0.9 && s[k] < 1.1) cap[k] = 0.2;  // a slow stretch in the middle
  double time = 0;
  const Eigen::VectorXd sd = time_optimal_feed(s, d1, d2, v, a, cap, time);
  const double step = 2.0 / (n - 1);
  double worst_v = 0, worst_a = 0;
  for (int k = 0; k < n; ++k) {
    EXPECT_LE(sd[k], cap[k] * (1 + 1e-12)) << s[k];
    for (int i = 0; i < 3; ++i) worst_v = std::max(worst_v, std::abs(d1(k, i)) * sd[k] / v[i]);
    if (k + 1 == n) break;
    // s-ddot over the step, x = s-dot^2 linear in s; the acceleration at the step's midpoint
    const double sdd = (sd[k + 1] * sd[k + 1] - sd[k] * sd[k]) / (2 * step);
    const double x = 0.5 * (sd[k] * sd[k] + sd[k + 1] * sd[k + 1]);
    for (int i = 0; i < 3; ++i) {
      const double p = 0.5 * (d1(k, i) + d1(k + 1, i)), c = 0.5 * (d2(k, i) + d2(k + 1, i));
      worst_a = std::max(worst_a, std::abs(p * sdd + c * x) / a[i]);
    }
  }
  std::printf("cubic with limits: largest velocity %.9f, acceleration %.6f of the limit, time %.4f\n", worst_v, worst_a,
              time);
  EXPECT_LE(worst_v, 1 + 1e-12);
  // the bounds hold at the steps' ends: at their midpoints within the grid's resolution, first order in the step
  // (1.009 at 1000 steps, 1.0023 at 4000, 1.00015 at 64000)
  EXPECT_LE(worst_a, 1 + 10 * step);
  EXPECT_GT(worst_a, 0.99);      // and the acceleration is used: bang-bang, not a cautious profile
  // the cap binds over its stretch (the path's own limits allow more there)
  for (int k = 0; k < n; ++k)
    if (s[k] > 0.95 && s[k] < 1.05) {
      EXPECT_NEAR(sd[k], 0.2, 1e-12) << s[k];
    }
  EXPECT_TRUE(std::isfinite(time) && time > 0);
}

TEST(Feed, InconsistentSizesAreAnInputError) {
  const Eigen::VectorXd s = grid(1.0, 5);
  RowMatrix d1 = RowMatrix::Ones(5, 2), d2 = RowMatrix::Zero(5, 2);
  const Eigen::Vector2d v(1, 1), a(1, 1);
  double t = 0;
  EXPECT_NO_THROW(time_optimal_feed(s, d1, d2, v, a, Eigen::VectorXd(), t));
  const auto err = [&](const RowMatrix& x1, const RowMatrix& x2, const Eigen::VectorXd& vv,
                       const Eigen::VectorXd& cap) {
    try {
      time_optimal_feed(s, x1, x2, vv, a, cap, t);
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("(no error)");
  };
  const std::string want = "time_optimal_feed: inconsistent array sizes";
  EXPECT_EQ(err(RowMatrix::Ones(4, 2), d2, v, Eigen::VectorXd()), want);
  EXPECT_EQ(err(d1, RowMatrix::Zero(5, 3), v, Eigen::VectorXd()), want);
  EXPECT_EQ(err(d1, d2, Eigen::Vector3d(1, 1, 1), Eigen::VectorXd()), want);
  EXPECT_EQ(err(d1, d2, v, Eigen::VectorXd::Ones(4)), want);
}
