// kincal: sine, cosine and arctangent for the hot paths (FK, Jacobians, IK, Newton compensation).
//
// libm's sincos and atan2 were 35% of the time of kinematics and compensation. These are table +
// short-polynomial versions, inlined: the argument is reduced to a small remainder around a table
// point (table values from long-double libm, checked by the test), where a few terms of the
// Taylor series are exact to below 1e-20. Results are within 3 ulp of the true values (tests/cpp
// test_fastmath.cpp checks 4 ulp on millions of arguments, and the special values);
// arguments outside the fast range (|x| > 1e5 for sincos, zeros, infinities, NaN) go to libm.
#pragma once

#include <cmath>

namespace kincal::fastmath {

namespace detail {

constexpr double kPiHi = 3.141592653589793;        // M_PI, the double nearest pi
constexpr double kPiLo = 1.2246467991473532e-16;   // pi - kPiHi
constexpr int kSinSteps = 64;                      // table step pi / 32 over one turn

// sin(j pi / 32), j = 0..16, and atan(k / 16), k = 0..16: long-double libm rounded to double
// (tests/cpp/test_fastmath.cpp recomputes them). Written out so that no call checks an initialisation.
constexpr double kSinQuadrant[17] = {
    0x0p+0, 0x1.917a6bc29b42cp-4, 0x1.8f8b83c69a60bp-3, 0x1.294062ed59f06p-2, 0x1.87de2a6aea963p-2,
    0x1.e2b5d3806f63bp-2, 0x1.1c73b39ae68c8p-1, 0x1.44cf325091dd6p-1, 0x1.6a09e667f3bcdp-1,
    0x1.8bc806b151741p-1, 0x1.a9b66290ea1a3p-1, 0x1.c38b2f180bdb1p-1, 0x1.d906bcf328d46p-1,
    0x1.e9f4156c62ddap-1, 0x1.f6297cff75cbp-1, 0x1.fd88da3d12526p-1, 0x1p+0};
constexpr double kAtanSixteenths[17] = {
    0x0p+0, 0x1.ff55bb72cfdeap-5, 0x1.fd5ba9aac2f6ep-4, 0x1.7b97b4bce5b02p-3, 0x1.f5b75f92c80ddp-3,
    0x1.362773707ebccp-2, 0x1.6f61941e4def1p-2, 0x1.a64eec3cc23fdp-2, 0x1.dac670561bb4fp-2,
    0x1.0657e94db30dp-1, 0x1.1e00babdefeb4p-1, 0x1.345f01cce37bbp-1, 0x1.4978fa3269ee1p-1,
    0x1.5d58987169b18p-1, 0x1.700a7c5784634p-1, 0x1.819d0b7158a4dp-1, 0x1.921fb54442d18p-1};

struct Tables {
  double s[kSinSteps], c[kSinSteps];  // sin, cos of j pi / 32 over one turn
};

// the whole turn from the first quadrant by symmetry, so that the zeros and ones are exact
constexpr Tables make_tables() {
  Tables t{};
  for (int j = 0; j < kSinSteps; ++j) {
    const int m = j % 32;  // sin(j pi/32) = +-sin(m pi/32), the sign flips every half turn
    const double v = m <= 16 ? kSinQuadrant[m] : kSinQuadrant[32 - m];
    t.s[j] = j < 32 ? v : -v;
  }
  for (int j = 0; j < kSinSteps; ++j) t.c[j] = t.s[(j + 16) % kSinSteps];  // cos a = sin(a + pi/2)
  return t;
}

inline constexpr Tables kTables = make_tables();

}  // namespace detail

/// Round to the nearest integer (ties to even) for |v| < 2^51: libm's nearbyint is a call on
/// baseline x86-64, where this is two additions.
inline double round_nearest(double v) {
  constexpr double magic = 6755399441055744.0;  // 1.5 * 2^52
  return (v + magic) - magic;  // IEEE double arithmetic (no -ffast-math here): the sum is rounded
}


namespace detail {

// The argument reduction and the two short series of sincos, for a double or a pair of doubles
// (the same operations lane by lane: the pair's results are bit-identical to two single calls).
template <class T>
inline void sincos_core(T x, T& k, T& sr, T& cr1) {
  constexpr double magic = 6755399441055744.0;  // round_nearest
  k = (x * (32 / kPiHi) + magic) - magic;
  // x - k pi/32 in three parts (Cody-Waite): c1 has 24 significant bits, so k c1 is exact
  constexpr double step = kPiHi / 32;
  constexpr double c1 = static_cast<double>(static_cast<float>(step));
  constexpr double c2 = step - c1;
  constexpr double c3 = kPiLo / 32;
  const T r = ((x - k * c1) - k * c2) - k * c3;
  const T r2 = r * r;
  // |r| <= pi/64: the next Taylor terms are below 1e-20
  sr = r + r * r2 * (-1.0 / 6 + r2 * (1.0 / 120 + r2 * (-1.0 / 5040 + r2 * (1.0 / 362880))));
  cr1 = r2 * (-0.5 + r2 * (1.0 / 24 + r2 * (-1.0 / 720 + r2 * (1.0 / 40320 + r2 * (-1.0 / 3628800)))));
}

inline int table_index(double k) { return static_cast<int>(static_cast<long long>(k) & (kSinSteps - 1)); }

}  // namespace detail

/// sin(x) and cos(x); within 2 ulp of the true values for |x| <= 1e5 (libm's own beyond).
inline void sincos(double x, double& s, double& c) {
  using namespace detail;
  if (!(std::abs(x) <= 1e5)) {
    s = std::sin(x);
    c = std::cos(x);
    return;
  }
  double k, sr, cr1;
  sincos_core(x, k, sr, cr1);
  const int j = table_index(k);
  const double sk = kTables.s[j], ck = kTables.c[j];
  // sin(a + r) = sin a + (sin a (cos r - 1) + cos a sin r), and the same for cos: small corrections last
  s = sk + (sk * cr1 + ck * sr);
  c = ck + (ck * cr1 - sk * sr);
}

/// sincos of two arguments at once in the two lanes of an SSE2 register (GCC/Clang vector
/// extensions): the same results as two sincos calls at about half the instructions.
inline void sincos2(double x0, double x1, double& s0, double& c0, double& s1, double& c1) {
  using namespace detail;
  if (!(std::abs(x0) <= 1e5) || !(std::abs(x1) <= 1e5)) {
    sincos(x0, s0, c0);
    sincos(x1, s1, c1);
    return;
  }
  typedef double v2d __attribute__((vector_size(16)));
  const v2d x = {x0, x1};
  v2d k, sr, cr1;
  sincos_core(x, k, sr, cr1);
  const int j0 = table_index(k[0]), j1 = table_index(k[1]);
  const v2d sk = {kTables.s[j0], kTables.s[j1]}, ck = {kTables.c[j0], kTables.c[j1]};
  const v2d s = sk + (sk * cr1 + ck * sr);
  const v2d c = ck + (ck * cr1 - sk * sr);
  s0 = s[0];
  s1 = s[1];
  c0 = c[0];
  c1 = c[1];
}

/// atan2(y, x) within 3 ulp of the true value; zeros, infinities and NaN go to libm.
inline double atan2(double y, double x) {
  using namespace detail;
  const double ax = std::abs(x), ay = std::abs(y);
  const double big = ax > ay ? ax : ay, small = ax > ay ? ay : ax;
  if (!(big > 0) || !(big < HUGE_VAL) || !(small < big * 1e300)) return std::atan2(y, x);
  const double t = small / big;  // in [0, 1]
  const int k = static_cast<int>(t * 16 + 0.5);
  const double ck = k * (1.0 / 16);
  const double u = (t - ck) / (1 + t * ck);  // atan t = atan ck + atan u, |u| <= 1/32
  const double u2 = u * u;
  const double u4 = u2 * u2, u3 = u * u2;  // the series by Estrin's scheme: half Horner's latency
  const double au = u + u3 * ((-1.0 / 3 + u2 * (1.0 / 5)) + u4 * ((-1.0 / 7 + u2 * (1.0 / 9)) + u4 * (-1.0 / 11)));
  const double atk = kAtanSixteenths[k];
  double a = atk + au;
  constexpr double pio2_lo = kPiLo / 2;
  if (ay > ax) a = (kPiHi / 2 - atk) + (pio2_lo - au);  // atan(y/x) = pi/2 - atan(x/y)
  if (x < 0) a = (kPiHi - a) + kPiLo;
  return std::signbit(y) ? -a : a;
}

/// atan2 of two arguments at once in the two lanes of an SSE2 register (GCC/Clang vector
/// extensions): lane by lane the operations of atan2, so the results are bit-identical to two atan2
/// calls (test_fastmath.cpp), at about half the instructions: two vector divisions where two calls
/// take four scalar ones. A lane with a zero, infinity or NaN sends both to atan2. (The scalar and
/// the pair are written out separately: atan2's branches are the pair's lane selects.)
inline void atan2x2(double y0, double x0, double y1, double x1, double& a0, double& a1) {
  using namespace detail;
  typedef double v2d __attribute__((vector_size(16)));
  typedef long long v2l __attribute__((vector_size(16)));
  const v2d y = {y0, y1}, x = {x0, x1};
  const v2l abs_mask = {0x7fffffffffffffffLL, 0x7fffffffffffffffLL};
  const v2d ax = (v2d)((v2l)x & abs_mask), ay = (v2d)((v2l)y & abs_mask);
  const v2l x_bigger = ax > ay, y_bigger = ay > ax;
  const v2d big = x_bigger ? ax : ay, small = x_bigger ? ay : ax;
  const v2l ok = (big > 0) & (big < HUGE_VAL) & (small < big * 1e300);
  if (!(ok[0] && ok[1])) {
    a0 = fastmath::atan2(y0, x0);
    a1 = fastmath::atan2(y1, x1);
    return;
  }
  const v2d t = small / big;  // in [0, 1]
  const v2d t16 = t * 16 + 0.5;
  const int k0 = static_cast<int>(t16[0]), k1 = static_cast<int>(t16[1]);
  const v2d ck = v2d{static_cast<double>(k0), static_cast<double>(k1)} * (1.0 / 16);
  const v2d u = (t - ck) / (1 + t * ck);  // atan t = atan ck + atan u, |u| <= 1/32
  const v2d u2 = u * u;
  const v2d u4 = u2 * u2, u3 = u * u2;  // as atan2
  const v2d au = u + u3 * ((-1.0 / 3 + u2 * (1.0 / 5)) + u4 * ((-1.0 / 7 + u2 * (1.0 / 9)) + u4 * (-1.0 / 11)));
  const v2d atk = {kAtanSixteenths[k0], kAtanSixteenths[k1]};
  constexpr double pio2_lo = kPiLo / 2;
  v2d a = atk + au;
  a = y_bigger ? (kPiHi / 2 - atk) + (pio2_lo - au) : a;  // atan(y/x) = pi/2 - atan(x/y)
  a = x < 0 ? (kPiHi - a) + kPiLo : a;
  const v2l sign = {static_cast<long long>(0x8000000000000000ULL), static_cast<long long>(0x8000000000000000ULL)};
  a = (v2d)((v2l)a ^ ((v2l)y & sign));
  a0 = a[0];
  a1 = a[1];
}

/// acos(x) for x in [-1, 1], as atan2(sqrt((1 - x)(1 + x)), x).
inline double acos(double x) { return fastmath::atan2(std::sqrt((1 - x) * (1 + x)), x); }

}  // namespace kincal::fastmath
