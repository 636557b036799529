// The hot paths' sine, cosine and arctangent (fastmath.hpp) against long-double libm on millions of
// arguments: within 4 ulp of the true value (libm's double versions are within 1), and the special
// values handed to libm.
#include "kincal/core/fastmath.hpp"

#include "test_util.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <random>

namespace fm = kincal::fastmath;

namespace {

double ulps(double got, long double truth) {
  const double t = static_cast<double>(truth);
  const double ulp = std::nextafter(std::abs(t), INFINITY) - std::abs(t);
  return static_cast<double>(std::abs(static_cast<long double>(got) - truth)) / ulp;
}

}  // namespace

TEST(FastMath, SinCosWithinFourUlp) {
  KINCAL_SEED_TRACE(11);
  std::mt19937_64 rng(kincal::test::test_seed(11));
  double worst_s = 0, worst_c = 0;
  const int n = std::max(400000, kincal::test::count(0));
  for (double range : {1.0, 7.0, 40.0, 1e3, 1e5}) {
    std::uniform_real_distribution<double> u(-range, range);
    for (int i = 0; i < n; ++i) {
      const double x = u(rng);
      double s, c;
      fm::sincos(x, s, c);
      worst_s = std::max(worst_s, ulps(s, std::sin(static_cast<long double>(x))));
      worst_c = std::max(worst_c, ulps(c, std::cos(static_cast<long double>(x))));
    }
  }
  // table points and their neighbours, where the reduced argument is zero or half a step
  for (int k = -200; k <= 200; ++k) {
    for (double d : {0.0, 1e-12, -1e-12, 0.0490873852123405}) {
      const double x = k * (3.14159265358979323846 / 32) + d;
      double s, c;
      fm::sincos(x, s, c);
      worst_s = std::max(worst_s, ulps(s, std::sin(static_cast<long double>(x))));
      worst_c = std::max(worst_c, ulps(c, std::cos(static_cast<long double>(x))));
    }
  }
  EXPECT_LT(worst_s, 4.0);
  EXPECT_LT(worst_c, 4.0);
  RecordProperty("worst_sin_ulp", std::to_string(worst_s));
  RecordProperty("worst_cos_ulp", std::to_string(worst_c));
}

TEST(FastMath, Atan2AndAcosWithinFourUlp) {
  KINCAL_SEED_TRACE(12);
  std::mt19937_64 rng(kincal::test::test_seed(12));
  std::uniform_real_distribution<double> sign(-1, 1), expo(-9, 9), rel(-1e-3, 1e-3);
  double worst = 0, worst_acos = 0;
  const int n = std::max(1000000, kincal::test::count(0));
  for (int i = 0; i < n; ++i) {
    const double y = (sign(rng) < 0 ? -1 : 1) * std::pow(10.0, expo(rng));
    double x = (sign(rng) < 0 ? -1 : 1) * std::pow(10.0, expo(rng));
    if (i % 4 == 0) x = y * (1 + rel(rng));  // near the octant boundaries
    worst = std::max(worst, ulps(fm::atan2(y, x), std::atan2(static_cast<long double>(y), static_cast<long double>(x))));
    const double z = sign(rng);
    worst_acos = std::max(worst_acos, ulps(fm::acos(z), std::acos(static_cast<long double>(z))));
  }
  EXPECT_LT(worst, 4.0);
  EXPECT_LT(worst_acos, 4.0);
  RecordProperty("worst_atan2_ulp", std::to_string(worst));
}

TEST(FastMath, SpecialValuesAsLibm) {
  const double inf = std::numeric_limits<double>::infinity(), nan = std::nan("");
  for (double y : {0.0, -0.0, 1.0, -1.0, inf, -inf})
    for (double x : {0.0, -0.0, 1.0, -1.0, inf, -inf}) {
      const double a = fm::atan2(y, x), b = std::atan2(y, x);
      EXPECT_EQ(a, b) << y << ", " << x;
      EXPECT_EQ(std::signbit(a), std::signbit(b)) << y << ", " << x;
    }
  EXPECT_TRUE(std::isnan(fm::atan2(nan, 1.0)));
  EXPECT_TRUE(std::isnan(fm::atan2(1.0, nan)));
  double s, c;
  fm::sincos(nan, s, c);
  EXPECT_TRUE(std::isnan(s) && std::isnan(c));
  fm::sincos(inf, s, c);
  EXPECT_TRUE(std::isnan(s) && std::isnan(c));
  fm::sincos(0.0, s, c);
  EXPECT_EQ(s, 0.0);
  EXPECT_EQ(c, 1.0);
  fm::sincos(3e7, s, c);  // beyond the fast range: libm's own
  EXPECT_EQ(s, std::sin(3e7));
  EXPECT_EQ(c, std::cos(3e7));
  EXPECT_EQ(fm::round_nearest(2.5), 2.0);
  EXPECT_EQ(fm::round_nearest(-3.5), -4.0);
  EXPECT_EQ(fm::round_nearest(-0.4), 0.0);
}

// The pair version gives what two single calls give, bit for bit (and libm's beyond the fast range).
TEST(FastMath, PairsEqualSingles) {
  KINCAL_SEED_TRACE(12);
  std::mt19937_64 rng(kincal::test::test_seed(12));
  std::uniform_real_distribution<double> u(-40, 40);
  int differ = 0;
  for (int i = 0; i < 200000; ++i) {
    const double a = i % 1000 == 0 ? 3e7 : u(rng), b = u(rng);
    double s0, c0, s1, c1, t0, d0, t1, d1;
    fm::sincos2(a, b, s0, c0, s1, c1);
    fm::sincos(a, t0, d0);
    fm::sincos(b, t1, d1);
    differ += s0 != t0 || c0 != d0 || s1 != t1 || c1 != d1;
  }
  EXPECT_EQ(differ, 0);
  // atan2x2: random arguments over 18 decades, near the octant boundaries, and special values
  // (zeros of both signs, infinities, NaN) in either lane; bit-identical, NaN to NaN
  std::uniform_real_distribution<double> sign(-1, 1), expo(-9, 9), rel(-1e-3, 1e-3);
  const double special[] = {0.0, -0.0, HUGE_VAL, -HUGE_VAL, std::nan(""), 1e-310, 1.0, -1.0};
  auto same = [](double p, double q) { return (std::isnan(p) && std::isnan(q)) || std::memcmp(&p, &q, sizeof p) == 0; };
  int differ2 = 0;
  for (int i = 0; i < 400000; ++i) {
    double v[4];
    for (double& w : v) w = (sign(rng) < 0 ? -1 : 1) * std::pow(10.0, expo(rng));
    if (i % 4 == 0) v[1] = v[0] * (1 + rel(rng));
    if (i % 97 == 0) v[i % 4] = special[(i / 97) % 8];
    double a0, a1;
    fm::atan2x2(v[0], v[1], v[2], v[3], a0, a1);
    differ2 += !same(a0, fm::atan2(v[0], v[1])) || !same(a1, fm::atan2(v[2], v[3]));
  }
  EXPECT_EQ(differ2, 0);
}

// The written-out tables are long-double libm rounded to double.
TEST(FastMath, TablesAreLibmRounded) {
  const long double pi = 3.14159265358979323846264338327950288L;
  namespace d = fm::detail;
  for (int j = 0; j <= 16; ++j)
    EXPECT_EQ(d::kSinQuadrant[j], static_cast<double>(std::sin(j * pi / 32))) << "sin(" << j << " pi/32)";
  for (int k = 0; k <= 16; ++k)
    EXPECT_EQ(d::kAtanSixteenths[k], static_cast<double>(std::atan(k / 16.0L))) << "atan(" << k << "/16)";
  // the whole turn by symmetry: equal to the rounded values, with exact zeros where long-double pi
  // leaves about 1e-19
  for (int j = 0; j < d::kSinSteps; ++j) {
    EXPECT_NEAR(d::kTables.s[j], static_cast<double>(std::sin(j * pi / 32)), 1e-18) << j;
    EXPECT_NEAR(d::kTables.c[j], static_cast<double>(std::cos(j * pi / 32)), 1e-18) << j;
  }
}
