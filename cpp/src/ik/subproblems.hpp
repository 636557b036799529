// kincal: the closed-form IK's subproblems (Paden-Kahan 1-4 as the IK uses them), shared by its
// vector form (ik.cpp) and its ortho-parallel form (ik_ortho.cpp). Internal to the library.
#pragma once

#include "kincal/core/fastmath.hpp"
#include "kincal/ik/ik.hpp"

#include <algorithm>
#include <cmath>
#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace kincal::ik_detail {

// The per-call state of the subproblems: values a hair outside [-1, 1] are tangency (one
// solution), beyond is none, unless the nearest configuration is asked for (clamp); clamped records
// that a subproblem of the current branch was clamped to tangency.
struct Tangency {
  bool clamp = false;    // solve(..., OutOfReach::Nearest) is running
  bool clamped = false;  // a subproblem was clamped to tangency
};

inline double wrap(double a) {  // to (-pi, pi]; the angles here are at most a few turns off
  constexpr double two_pi = 2 * kPi;
  if (!(std::abs(a) < 4 * two_pi)) {  // far references (and inf, NaN): the general reduction
    a -= two_pi * std::floor((a + kPi) / two_pi);
    return a <= -kPi ? a + two_pi : (a > kPi ? a - two_pi : a);
  }
  a -= two_pi * fastmath::round_nearest(a * (1 / two_pi));  // no data-dependent branch
  return a <= -kPi ? a + two_pi : (a > kPi ? a - two_pi : a);
}

// An angle with its cosine and sine, taken from the atan2 arguments that define it: the rotations
// of the IK are built from these, with no trigonometric call.
struct Angle {
  double q = 0, c = 1, s = 0;
};

inline Angle from_xy(double x, double y) {
  const double h = std::sqrt(x * x + y * y);
  if (!(h > 0)) return Angle{};
  const double inv = 1 / h;
  return Angle{fastmath::atan2(y, x), x * inv, y * inv};
}

// from_xy of two pairs at once (fastmath::atan2x2): the same angles, bit for bit
inline void from_xy2(double x0, double y0, double x1, double y1, Angle& a0, Angle& a1) {
  typedef double v2d __attribute__((vector_size(16)));
  const v2d x = {x0, x1}, y = {y0, y1};
  const v2d h2 = x * x + y * y;
#if defined(__SSE2__)
  const v2d h = (v2d)_mm_sqrt_pd((__m128d)h2);  // one instruction; h2 >= 0
#else
  const v2d h = {std::sqrt(h2[0]), std::sqrt(h2[1])};
#endif
  const v2d inv = 1 / h;
  double q0, q1;
  fastmath::atan2x2(y0, x0, y1, x1, q0, q1);
  a0 = h[0] > 0 ? Angle{q0, x0 * inv[0], y0 * inv[0]} : Angle{};
  a1 = h[1] > 0 ? Angle{q1, x1 * inv[1], y1 * inv[1]} : Angle{};
}

inline Angle negated(const Angle& a) { return Angle{-a.q, a.c, -a.s}; }

// phi + a and phi - a, a = atan2(sa, ca) given with its cosine and sine
inline void plus_minus(const Angle& phi, double a, double ca, double sa, Angle& plus, Angle& minus) {
  plus = Angle{phi.q + a, phi.c * ca - phi.s * sa, phi.s * ca + phi.c * sa};
  minus = Angle{phi.q - a, phi.c * ca + phi.s * sa, phi.s * ca - phi.c * sa};
}

// the sine of an angle in [0, pi] from its cosine (clamped by the caller to [-1, 1])
inline double sine_of(double ca) { return std::sqrt((1 - ca) * (1 + ca)); }

// rot(k, a) v by Rodrigues, k unit
inline Vec3 rotv(const Vec3& k, double c, double s, const Vec3& v) {
  return c * v + s * k.cross(v) + ((1 - c) * k.dot(v)) * k;
}

// the cosine of a subproblem's angle: a hair outside [-1, 1] is tangency (one solution), beyond is
// none (false) unless the nearest configuration is asked for
inline bool cos_of(double x, double& out, bool& tangent, Tangency& tg) {
  constexpr double tol = 1e-10;
  tangent = false;
  if (!std::isfinite(x)) return false;
  if (x > 1 + tol || x < -1 - tol) {
    if (!tg.clamp) return false;
    tg.clamped = true;
  }
  if (x >= 1 - 1e-14 || x <= -1 + 1e-14) {
    tangent = true;
    x = x > 0 ? 1.0 : -1.0;
  }
  out = x;
  return true;
}

// Paden-Kahan subproblems on unit axes k through the origin (callers subtract the axis point).
// SP1: theta with rot(k, theta) u = v (u, v projected on the plane normal to k):
// cos ~ up . vp = u . v - (k.u)(k.v), sin ~ k . (up x vp) = k . (u x v).
inline Angle sub1(const Vec3& k, const Vec3& u, const Vec3& v) {
  return from_xy(u.dot(v) - k.dot(u) * k.dot(v), k.dot(u.cross(v)));
}

// SP2 of the wrist: (theta1, theta2) with rot(k1, theta1) rot(k2, theta2) u = v for the model's
// k1 = w4, k2 = w5, u = w6 (IkSolver::Constants), v given. Returns the count (0, 1 or 2); with
// first_only, only the first of two solutions is written (the caller knows the second).
// c = rot(k2, t2) u = rot(k1, -t1) v: k2.c = k2.u, k1.c = k1.v, |c| = |u|; c = a k1 + b k2 +- g n.
// Both subproblem-1 solutions are linear in +-g: theta2 takes u to c about k2, theta1 takes c to v
// about k1; with up, vp the parts of u, v normal to k2, k1 and m = k1 x n, the projections reduce to
// dot products of v with k1, k2, n and m (the terms with a vector twice in a triple product vanish):
// sub2_dots takes these four products.
inline int sub2_dots(const IkSolver::Constants& k, double k1v, double k2v, double nv, double mv, Angle t1[2], Angle t2[2],
              bool first_only, Tangency& tg) {
  const double alpha = (k.k12 * k.k2u - k1v) * k.inv_den;
  const double beta = (k.k12 * k1v - k.k2u) * k.inv_den;
  const double g2 = (k.u2 - alpha * alpha - beta * beta - 2 * alpha * beta * k.k12) * k.inv_n2;
  const double scale = std::max(1.0, k.u2);
  if (!std::isfinite(g2)) return 0;
  if (g2 < -1e-10 * scale) {
    if (!tg.clamp) return 0;
    tg.clamped = true;
  }
  const double g = g2 > 0 ? std::sqrt(g2) : 0.0;
  const int count = g > 0 ? 2 : 1;
  const double x20 = alpha * k.a1 + (beta - k.k2u) * k.a2, y20 = alpha * k.b1;
  const double x10 = beta * (k2v - k.k12 * k1v), x11 = nv, y10 = beta * nv, y11 = mv;
  for (int i = 0; i < (first_only ? 1 : count); ++i) {
    const double sg = i == 0 ? g : -g;
    from_xy2(x20 + sg * k.x21, y20 + sg * k.y21, x10 + sg * x11, y10 + sg * y11, t2[i], t1[i]);
  }
  return count;
}

inline int sub2_wrist(const IkSolver::Constants& k, const Vec3& k1, const Vec3& k2, const Vec3& v, Angle t1[2],
               Angle t2[2], bool first_only, Tangency& tg) {
  return sub2_dots(k, k1.dot(v), k2.dot(v), k.n.dot(v), k.m.dot(v), t1, t2, first_only, tg);
}

// SP3 of the elbow: q3 with |rot(w3, q3)(pw - p3) - (p2 - p3)| = d (IkSolver::Constants), in two
// parts: the cosine of q3's offset from the constant angle (the count: 0, 1 or 2), then the angles
// from that offset a = atan2(sine_of(ca), ca) (the form for ortho-parallel robots pairs the
// arctangents of its two shoulder branches).
inline int sub3_elbow_cos(const IkSolver::Constants& k, double d, double& ca, Tangency& tg) {
  const double dp2 = d * d - k.elbow_dz * k.elbow_dz;
  const double nu = k.elbow_nu, nv = k.elbow_nv;
  if (nu < 1e-12 || nv < 1e-12) return 0;
  bool tangent;
  if (!cos_of((nu * nu + nv * nv - dp2) * k.elbow_inv_2nunv, ca, tangent, tg)) return 0;
  return tangent ? 1 : 2;
}

inline void sub3_elbow_angles(const IkSolver::Constants& k, double a, double ca, double sa, Angle t[2]) {
  plus_minus(Angle{k.elbow_q, k.elbow_c, k.elbow_s}, a, ca, sa, t[1], t[0]);
}

inline int sub3_elbow(const IkSolver::Constants& k, double d, Angle t[2], Tangency& tg) {
  double ca;
  const int n = sub3_elbow_cos(k, d, ca, tg);
  if (n == 0) return 0;
  const double sa = sine_of(ca);
  sub3_elbow_angles(k, fastmath::atan2(sa, ca), ca, sa, t);
  return n;
}

// SP4 reduced to A cos t + B sin t = C. Returns the count (0, 1 or 2).
inline int sub4_abc(double A, double B, double C, Angle t[2], Tangency& tg) {
  const double r = std::sqrt(A * A + B * B);  // mm-sized terms: no overflow
  if (r < 1e-12) return 0;
  const double inv_r = 1 / r;
  double ca;
  bool tangent;
  if (!cos_of(C * inv_r, ca, tangent, tg)) return 0;
  const double sa = sine_of(ca);
  double q_phi, a;
  fastmath::atan2x2(B, A, sa, ca, q_phi, a);
  plus_minus(Angle{q_phi, A * inv_r, B * inv_r}, a, ca, sa, t[0], t[1]);
  if (tangent) return 1;
  return 2;
}

// SP4: theta with h . rot(k, theta) u = d. Returns the count (0, 1 or 2).
// h . (k (k.u) + cos t (u - k (k.u)) + sin t (k x u)) = d
inline int sub4(const Vec3& h, const Vec3& k, const Vec3& u, double d, Angle t[2], Tangency& tg) {
  return sub4_abc(h.dot(u - k * k.dot(u)), h.dot(k.cross(u)), d - h.dot(k) * k.dot(u), t, tg);
}

// Which branches of a subproblem's solutions a solve visits: all, or (NearestReference) the one
// nearest the reference angle, comparing modulo 360.
struct Branch {
  const double* ref_deg;
  bool greedy;
  int pick(const Angle* cand, int n, int joint) const {
    if (!greedy || n < 2) return 0;
    const double r = ref_deg[joint] * kDeg;
    return std::abs(wrap(cand[1].q - r)) < std::abs(wrap(cand[0].q - r)) ? 1 : 0;
  }
  int pick_wrist(const Angle* t4, const Angle* t5, int n) const {
    if (!greedy || n < 2) return 0;
    auto dist = [&](int i) {
      return std::abs(wrap(t4[i].q - ref_deg[3] * kDeg)) + std::abs(wrap(t5[i].q - ref_deg[4] * kDeg));
    };
    return dist(1) < dist(0) ? 1 : 0;
  }
  int begin(int b) const { return greedy ? b : 0; }
  int end(int b, int n) const { return greedy ? std::min(b + 1, n) : n; }
};

}  // namespace kincal::ik_detail

namespace kincal {

#if defined(__SSE2__)
namespace ik_detail {

// Two angles (radians within a few turns) to degrees, each shifted by whole turns into its limits
// [lo, hi] nearest its reference r (within the limits and less than a turn from zero, see
// IkSolver::delivers()): the turn nearest the reference when it lands inside; else the next turn
// towards the limits (the candidates beyond are farther from both); else none (the angle in
// (-180, 180], out of limits): the choice into_limits makes, up to rounding, without branches on the
// data. inside: a bit per lane within its limits (_mm_movemask_pd).
inline __m128d to_limits2(__m128d q, __m128d r, __m128d lo, __m128d hi, int& inside) {
  const __m128d magic = _mm_set1_pd(6755399441055744.0);  // fastmath::round_nearest
  auto round = [&](__m128d v) { return _mm_sub_pd(_mm_add_pd(v, magic), magic); };
  auto select = [](__m128d m, __m128d a, __m128d b) { return _mm_or_pd(_mm_and_pd(m, a), _mm_andnot_pd(m, b)); };
  const __m128d turn = _mm_set1_pd(360), inv_turn = _mm_set1_pd(1.0 / 360), half = _mm_set1_pd(-180);
  const __m128d d = _mm_mul_pd(q, _mm_set1_pd(180 / kPi));
  // the turn nearest r, then the next turn towards the limits
  const __m128d y0 = _mm_add_pd(d, _mm_mul_pd(turn, round(_mm_mul_pd(_mm_sub_pd(r, d), inv_turn))));
  const __m128d above = _mm_cmpgt_pd(y0, hi);
  const __m128d in0 = _mm_andnot_pd(above, _mm_cmpge_pd(y0, lo));
  const __m128d y1 = _mm_add_pd(y0, _mm_xor_pd(turn, _mm_and_pd(above, _mm_set1_pd(-0.0))));
  const __m128d in1 = _mm_and_pd(_mm_cmpge_pd(y1, lo), _mm_cmple_pd(y1, hi));
  // none inside: the angle in (-180, 180]
  __m128d w = _mm_sub_pd(d, _mm_mul_pd(turn, round(_mm_mul_pd(d, inv_turn))));
  w = _mm_add_pd(w, _mm_and_pd(_mm_cmple_pd(w, half), turn));
  inside = _mm_movemask_pd(_mm_or_pd(in0, in1));
  return select(in0, y0, select(in1, y1, w));
}

}  // namespace ik_detail

// One solution's angles to degrees within the limits nearest the reference (null: zero), two joints
// at a time (to_limits2). Returns whether every angle is within its limits.
inline bool IkSolver::deliver(const double* q, const double* ref_deg, double* q_deg) const {
  int ok = 3;
  for (int p = 0; p < 3; ++p) {
    const __m128d r = ref_deg ? _mm_loadu_pd(ref_deg + 2 * p) : _mm_setzero_pd();
    const __m128d lo = _mm_loadu_pd(lo_.data() + 2 * p), hi = _mm_loadu_pd(hi_.data() + 2 * p);
    int inside;
    _mm_storeu_pd(q_deg + 2 * p, ik_detail::to_limits2(_mm_set_pd(q[2 * p + 1], q[2 * p]), r, lo, hi, inside));
    ok &= inside;
  }
  return ok == 3;
}
#else
inline bool IkSolver::deliver(const double*, const double*, double*) const { return false; }  // delivers() is false
#endif

// One solution (radians) into out, its wrist polished near the singularity (wrist: the sine of the
// angle between axes 4 and 6), flagged; with deliver, in degrees within the limits as well (else
// to_degrees converts all of them at the end). Inline in both forms: eight calls per solve, whose
// conversions overlap the next solutions' arithmetic.
inline void IkSolver::record(IkSolutions& out, double* q, double wrist, const Mat3& gr, bool shoulder, bool clamped,
                             const IkOptions& opt, bool deliver_now) const {
  IkSolution& s = out.sol[out.count];
  if (wrist < 1e-3) polish(q, gr);  // within 0.06 deg of the singularity q5 has lost digits
  if (deliver_now) {
    s.within_limits = deliver(q, opt.reference_deg, s.q_deg.data());
  } else {
    for (int j = 0; j < 6; ++j) s.q_deg[j] = q[j];
  }
  s.wrist_singular = wrist < 1e-7;
  s.shoulder_singular = shoulder;
  s.approximate = clamped;
  ++out.count;
}

}  // namespace kincal
