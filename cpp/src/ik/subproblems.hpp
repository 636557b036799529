// kincal: the closed-form IK's subproblems (Paden-Kahan 1-4 as the IK uses them), shared by its
// vector form (ik.cpp) and its ortho-parallel form (ik_ortho.cpp). Internal to the library.
#pragma once

#include "kincal/core/fastmath.hpp"
#include "kincal/ik/ik.hpp"

#include <algorithm>
#include <cmath>

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

inline Angle negated(const Angle& a) { return Angle{-a.q, a.c, -a.s}; }

// phi + a and phi - a, a from its cosine (clamped by the caller to [-1, 1])
inline void plus_minus(const Angle& phi, double ca, Angle& plus, Angle& minus) {
  const double sa = std::sqrt((1 - ca) * (1 + ca));
  const double a = fastmath::atan2(sa, ca);
  plus = Angle{phi.q + a, phi.c * ca - phi.s * sa, phi.s * ca + phi.c * sa};
  minus = Angle{phi.q - a, phi.c * ca + phi.s * sa, phi.s * ca - phi.c * sa};
}

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
    t2[i] = from_xy(x20 + sg * k.x21, y20 + sg * k.y21);
    t1[i] = from_xy(x10 + sg * x11, y10 + sg * y11);
  }
  return count;
}

inline int sub2_wrist(const IkSolver::Constants& k, const Vec3& k1, const Vec3& k2, const Vec3& v, Angle t1[2],
               Angle t2[2], bool first_only, Tangency& tg) {
  return sub2_dots(k, k1.dot(v), k2.dot(v), k.n.dot(v), k.m.dot(v), t1, t2, first_only, tg);
}

// SP3 of the elbow: q3 with |rot(w3, q3)(pw - p3) - (p2 - p3)| = d (IkSolver::Constants).
// Returns the count (0, 1 or 2).
inline int sub3_elbow(const IkSolver::Constants& k, double d, Angle t[2], Tangency& tg) {
  const double dp2 = d * d - k.elbow_dz * k.elbow_dz;
  const double nu = k.elbow_nu, nv = k.elbow_nv;
  if (nu < 1e-12 || nv < 1e-12) return 0;
  double ca;
  bool tangent;
  if (!cos_of((nu * nu + nv * nv - dp2) * k.elbow_inv_2nunv, ca, tangent, tg)) return 0;
  plus_minus(Angle{k.elbow_q, k.elbow_c, k.elbow_s}, ca, t[1], t[0]);
  if (tangent) return 1;
  return 2;
}

// SP4 reduced to A cos t + B sin t = C. Returns the count (0, 1 or 2).
inline int sub4_abc(double A, double B, double C, Angle t[2], Tangency& tg) {
  const double r = std::sqrt(A * A + B * B);  // mm-sized terms: no overflow
  if (r < 1e-12) return 0;
  const double inv_r = 1 / r;
  const Angle phi{fastmath::atan2(B, A), A * inv_r, B * inv_r};
  double ca;
  bool tangent;
  if (!cos_of(C * inv_r, ca, tangent, tg)) return 0;
  plus_minus(phi, ca, t[0], t[1]);
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
