#include "kincal/ik/ik.hpp"

#include "kincal/kinematics/kinematics.hpp"

#include <Eigen/Cholesky>

#include <algorithm>
#include <cmath>
#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "kincal/core/fastmath.hpp"

namespace kincal {

namespace {

// The per-call state of the subproblems: values a hair outside [-1, 1] are tangency (one
// solution), beyond is none, unless the nearest configuration is asked for (clamp); clamped records
// that a subproblem of the current branch was clamped to tangency.
struct Tangency {
  bool clamp = false;    // solve(..., OutOfReach::Nearest) is running
  bool clamped = false;  // a subproblem was clamped to tangency
};

// Near the wrist singularity SP2 loses half the digits (q5 comes from a square root of a
// difference): two Gauss-Newton steps with a pseudo-inverse restore the orientation to round-off.
void polish_wrist(const Vec3& w4, const Vec3& w5, const Vec3& w6, const Mat3& target, double* q) {
  for (int it = 0; it < 2; ++it) {
    const Mat3 r4 = axis_rotation(w4, q[0]), r45 = r4 * axis_rotation(w5, q[1]);
    const Mat3 r = r45 * axis_rotation(w6, q[2]);
    const Eigen::AngleAxisd e(target * r.transpose());
    const Vec3 err = e.axis() * e.angle();
    Mat3 j;
    j.col(0) = w4;
    j.col(1) = r4 * w5;
    j.col(2) = r45 * w6;
    // damped least squares: J^T (J J^T + lambda I)^-1 err, rank-deficient at the singularity
    const Mat3 jjt = j * j.transpose() + 1e-14 * Mat3::Identity();
    const Vec3 dq = j.transpose() * jjt.ldlt().solve(err);
    for (int k = 0; k < 3; ++k) q[k] += dq[k];
  }
}

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
int sub2_dots(const IkSolver::Constants& k, double k1v, double k2v, double nv, double mv, Angle t1[2], Angle t2[2],
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

int sub2_wrist(const IkSolver::Constants& k, const Vec3& k1, const Vec3& k2, const Vec3& v, Angle t1[2],
               Angle t2[2], bool first_only, Tangency& tg) {
  return sub2_dots(k, k1.dot(v), k2.dot(v), k.n.dot(v), k.m.dot(v), t1, t2, first_only, tg);
}

// SP3 of the elbow: q3 with |rot(w3, q3)(pw - p3) - (p2 - p3)| = d (IkSolver::Constants).
// Returns the count (0, 1 or 2).
int sub3_elbow(const IkSolver::Constants& k, double d, Angle t[2], Tangency& tg) {
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
int sub4_abc(double A, double B, double C, Angle t[2], Tangency& tg) {
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
int sub4(const Vec3& h, const Vec3& k, const Vec3& u, double d, Angle t[2], Tangency& tg) {
  return sub4_abc(h.dot(u - k * k.dot(u)), h.dot(k.cross(u)), d - h.dot(k) * k.dot(u), t, tg);
}

bool parallel(const Vec3& a, const Vec3& b, double tol) { return a.cross(b).norm() < tol; }

// The closed form's constants for a model of the class, from its unit axes w, axis points p and
// wrist centre c.
void fill_constants(IkSolver::Constants& k, const Vec3* w, const Vec3* p, const Vec3& c) {
  k.v6 = w[5].unitOrthogonal();
  k.sigma23 = w[2] == w[1] ? 1.0 : (w[2] == -w[1] ? -1.0 : 0.0);
  {  // elbow (sub3_elbow): |rot(w3, q3) u - v| = d, u = pw - p3, v = p2 - p3; up, vp their parts normal to w3
    const Vec3& ax = w[2];
    const Vec3 u = c - p[2], v = p[1] - p[2];
    const Vec3 up = u - ax * ax.dot(u), vp = v - ax * ax.dot(v);
    k.elbow_dz = ax.dot(u - v);
    k.elbow_nu = up.norm();
    k.elbow_nv = vp.norm();
    k.elbow_inv_2nunv = 1 / (2 * k.elbow_nu * k.elbow_nv);
    const double x = up.dot(vp), y = ax.dot(up.cross(vp)), h = std::sqrt(x * x + y * y);
    if (h > 0) {
      k.elbow_q = std::atan2(y, x);
      k.elbow_c = x / h;
      k.elbow_s = y / h;
    }
  }
  {  // wrist (sub2_wrist): rot(k1, t1) rot(k2, t2) u = v with k1 = w4, k2 = w5, u = w6
    const Vec3 &k1 = w[3], &k2 = w[4], &u = w[5];
    k.k12 = k1.dot(k2);
    k.inv_den = 1 / (k.k12 * k.k12 - 1);
    k.k2u = k2.dot(u);
    k.n = k1.cross(k2);
    k.m = k1.cross(k.n);
    k.inv_n2 = 1 / k.n.squaredNorm();
    k.u2 = u.squaredNorm();
    const Vec3 up = u - k2 * k.k2u;
    k.a1 = up.dot(k1);
    k.a2 = up.dot(k2);
    k.b1 = k2.dot(up.cross(k1));
    k.x21 = up.dot(k.n);
    k.y21 = k2.dot(up.cross(k.n));
  }
}

}  // namespace

IkSolver::IkSolver(const Model& m, IkForm form) {
  const int n = m.dof();
  w_.fill(Vec3::Zero());
  p_.fill(Vec3::Zero());
  for (int j = 0; j < std::min(n, 6); ++j) {
    w_[j] = m.axis(j);
    p_[j] = m.point(j);
    lo_[j] = m.spec().joints[j].lower_deg - 1e-9;
    hi_[j] = m.spec().joints[j].upper_deg + 1e-9;
  }
  tool_ = m.tool();
  // The structure: 6 joints, axes 2 and 3 parallel, axes 4, 5, 6 meeting in one point.
  if (n != 6) {
    st_.reason = "closed-form IK needs 6 joints";
  } else if (!parallel(w_[1], w_[2], 1e-9)) {
    st_.reason = "axes 2 and 3 are not parallel";
  } else if (parallel(w_[0], w_[1], 1e-6)) {
    st_.reason = "axes 1 and 2 are parallel";
  } else if (parallel(w_[2], w_[3], 1e-6) || parallel(w_[3], w_[4], 1e-6) || parallel(w_[4], w_[5], 1e-6)) {
    st_.reason = "consecutive wrist axes are parallel";
  } else {
    Mat3 a = Mat3::Zero();
    Vec3 b = Vec3::Zero();
    for (int j = 3; j < 6; ++j) {
      const Mat3 pr = Mat3::Identity() - w_[j] * w_[j].transpose();
      a += pr;
      b += pr * p_[j];
    }
    const Vec3 c = a.ldlt().solve(b);
    double dmax = 0;
    for (int j = 3; j < 6; ++j) dmax = std::max(dmax, ((Mat3::Identity() - w_[j] * w_[j].transpose()) * (c - p_[j])).norm());
    if (dmax > 1e-6) {
      st_.reason = "axes 4, 5 and 6 do not meet in one point (off by " + std::to_string(dmax) + " mm)";
    } else {
      st_.spherical_wrist_parallel_23 = true;
      st_.wrist_center = c;
      st_.wrist_flip = std::abs(w_[3].dot(w_[4])) < 1e-12 && std::abs(w_[4].dot(w_[5])) < 1e-12 &&
                       w_[3].cross(w_[5]).norm() < 1e-12;
      fill_constants(k_, w_.data(), p_.data(), c);
      fill_ortho(form, c);
    }
  }
}

void IkSolver::fill_ortho(IkForm form, const Vec3& c) {
  const Vec3 &w1 = w_[0], &w2 = w_[1], &w3 = w_[2];
  const double sigma = w3.dot(w2) > 0 ? 1.0 : -1.0;
  st_.ortho_parallel = form == IkForm::Fastest && st_.wrist_flip && std::abs(w1.dot(w2)) < 1e-12 &&
                       (w3 - sigma * w2).norm() < 1e-12;
  if (!st_.ortho_parallel) return;
  Ortho& o = o_;
  o.ct.row(0) = w1;
  o.ct.row(1) = w2;
  o.ct.row(2) = w1.cross(w2).normalized();
  o.d = w2.dot(c - p_[0]);
  o.p21 = o.ct * (p_[1] - p_[0]);
  const Vec3 pw3 = o.ct * (c - p_[2]), p32 = o.ct * (p_[2] - p_[1]);
  o.pw3_1 = pw3[0];
  o.pw3_3 = pw3[2];
  o.p32_1 = p32[0];
  o.p32_3 = p32[2];
  o.sigma = sigma;
  o.tau = w_[5].dot(w_[3]) > 0 ? 1.0 : -1.0;
  o.w4 = o.ct * w_[3];
  o.w5 = o.ct * w_[4];
  o.n = o.ct * k_.n;
  o.m = o.ct * k_.m;
}

namespace {

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

IkSolutions unsupported() {
  IkSolutions out;
  out.status = IkStatus::Unsupported;
  return out;
}

}  // namespace

IkSolutions IkSolver::solve(const Eigen::Isometry3d& target, const IkOptions& opt) const {
  if (!st_.spherical_wrist_parallel_23) return unsupported();
  // G = T M^-1 = e^{xi1 q1} ... e^{xi6 q6}; the wrist centre maps to p = G pw.
  const Mat3 gr = target.linear() * tool_.linear().transpose();
  const Vec3 gt = target.translation() - gr * tool_.translation();
  const Vec3 p = gr * st_.wrist_center + gt;
  IkSolutions out = st_.ortho_parallel ? solve_ortho(gr, p, opt) : solve_vector(gr, p, opt);
  to_degrees(out, opt.reference_deg);
  out.status = out.count > 0 ? IkStatus::Ok : IkStatus::OutOfReach;
  return out;
}

// One solution (radians) into out, its wrist polished near the singularity (wrist: the sine of the
// angle between axes 4 and 6), flagged; to_degrees converts all of them at the end.
void IkSolver::record(IkSolutions& out, double* q, double wrist, const Mat3& gr, bool shoulder, bool clamped) const {
  const Vec3 &w1 = w_[0], &w2 = w_[1], &w3 = w_[2];
  IkSolution& s = out.sol[out.count];
  if (wrist < 1e-3) {  // within 0.06 deg of the singularity q5 has lost digits
    const Mat3 r456 = (axis_rotation(w1, q[0]) * axis_rotation(w2, q[1]) * axis_rotation(w3, q[2])).transpose() * gr;
    polish_wrist(w_[3], w_[4], w_[5], r456, q + 3);
  }
  for (int j = 0; j < 6; ++j) s.q_deg[j] = q[j];
  s.wrist_singular = wrist < 1e-7;
  s.shoulder_singular = shoulder;
  s.approximate = clamped;
  ++out.count;
}

IkSolutions IkSolver::solve_vector(const Mat3& gr, const Vec3& p, const IkOptions& opt) const {
  const double* ref_deg = opt.reference_deg;
  const Branch br{ref_deg, opt.branches == Branches::NearestReference && ref_deg != nullptr};
  IkSolutions out;
  Tangency tg;
  tg.clamp = opt.out_of_reach == OutOfReach::Nearest;
  const Vec3& pw = st_.wrist_center;
  const Vec3 &w1 = w_[0], &w2 = w_[1], &w3 = w_[2], &w4 = w_[3], &w5 = w_[4], &w6 = w_[5];
  const Vec3 &p1 = p_[0], &p2 = p_[1], &p3 = p_[2];
  // The wrist rotation R456 = (R1 R2 R3)^T G is needed only applied to w6 (for q4, q5) and to a
  // vector v normal to w6 (for q6): both are carried through the rotations as vectors.
  const Constants& kc = k_;
  const Vec3& v6 = kc.v6;
  const Vec3 gw6 = gr * w6, gv6 = gr * v6;

  // q1: rotations about axes 2 and 3 keep the component along w2, so w2 . rot(w1, -q1)(p - p1)
  // must equal w2 . (pw - p1).
  Angle t1[2];
  const int n1 = sub4(w2, w1, p - p1, w2.dot(pw - p1), t1, tg);
  bool shoulder = false;
  Angle q1s[2];
  int nq1 = 0;
  if (n1 == 0) {
    // wrist centre on axis 1 (shoulder singularity): any q1 satisfies it when the residual is zero
    const Vec3 u = p - p1;
    const Vec3 along = w1 * w1.dot(u);
    if ((u - along).norm() < 1e-9 && std::abs(w2.dot(along) - w2.dot(pw - p1)) < 1e-9) {
      shoulder = true;
      const double q = ref_deg ? ref_deg[0] * kDeg : 0.0;
      q1s[0] = Angle{q, std::cos(q), std::sin(q)};
      nq1 = 1;
    }
  } else {
    for (int i = 0; i < n1; ++i) q1s[i] = negated(t1[i]);
    nq1 = n1;
  }
  const bool clamped1 = tg.clamped;  // q1 itself came from a tangency
  const int b1 = br.pick(q1s, nq1, 0);
  for (int i1 = br.begin(b1); i1 < br.end(b1, nq1); ++i1) {
    const Angle& a1 = q1s[i1];
    const Vec3 pp = rotv(w1, a1.c, -a1.s, p - p1) + p1;  // e^{-xi1 q1} p
    const Vec3 w6_1 = rotv(w1, a1.c, -a1.s, gw6), v6_1 = rotv(w1, a1.c, -a1.s, gv6);
    Angle t3[2];
    tg.clamped = clamped1;
    const int n3 = sub3_elbow(kc, (pp - p2).norm(), t3, tg);
    const bool clamped3 = tg.clamped;  // flags of this shoulder and elbow branch only
    const int b3 = br.pick(t3, n3, 2);
    for (int i3 = br.begin(b3); i3 < br.end(b3, n3); ++i3) {
      const Angle& a3 = t3[i3];
      const Vec3 x = rotv(w3, a3.c, a3.s, pw - p3) + p3;
      const Angle a2 = sub1(w2, x - p2, pp - p2);
      // R456 w6 and R456 v6: rotated back by -q2, then -q3
      Vec3 w6_456, v6_456;
      if (kc.sigma23 != 0) {  // w3 = sigma w2 exactly: one rotation about w2 by -(q2 + sigma q3)
        const double c = a2.c * a3.c - kc.sigma23 * a2.s * a3.s, s = a2.s * a3.c + kc.sigma23 * a2.c * a3.s;
        w6_456 = rotv(w2, c, -s, w6_1);
        v6_456 = rotv(w2, c, -s, v6_1);
      } else {
        w6_456 = rotv(w3, a3.c, -a3.s, rotv(w2, a2.c, -a2.s, w6_1));
        v6_456 = rotv(w3, a3.c, -a3.s, rotv(w2, a2.c, -a2.s, v6_1));
      }
      Angle t4[2], t5[2];
      tg.clamped = clamped3;
      const bool flip = st_.wrist_flip;
      const int n45 = sub2_wrist(kc, w4, w5, w6_456, t4, t5, flip, tg);
      if (flip && n45 == 2) {  // the other wrist: (q4 + pi, -q5, q6 + pi)
        t4[1] = Angle{t4[0].q + kPi, -t4[0].c, -t4[0].s};
        t5[1] = negated(t5[0]);
      }
      Angle a6_first;  // q6 of the first wrist solution, when the second is its flip
      if (flip && n45 == 2)
        a6_first = sub1(w6, v6, rotv(w5, t5[0].c, -t5[0].s, rotv(w4, t4[0].c, -t4[0].s, v6_456)));
      const int b45 = br.pick_wrist(t4, t5, n45);
      for (int i45 = br.begin(b45); i45 < br.end(b45, n45); ++i45) {
        const Angle &a4 = t4[i45], &a5 = t5[i45];
        // q6 takes v6 to rot(w5, -q5) rot(w4, -q4) R456 v6
        const Angle a6 = !(flip && n45 == 2) ? sub1(w6, v6, rotv(w5, a5.c, -a5.s, rotv(w4, a4.c, -a4.s, v6_456)))
                         : i45 == 0          ? a6_first
                                             : Angle{a6_first.q + kPi, -a6_first.c, -a6_first.s};
        double q[6] = {a1.q, a2.q, a3.q, a4.q, a5.q, a6.q};
        // sin of the angle between axes 4 and 6 (|sin q5| for a wrist with the flip)
        const double wrist = flip ? std::abs(a5.s) : w4.cross(rotv(w5, a5.c, a5.s, w6)).norm();
        record(out, q, wrist, gr, shoulder, tg.clamped);
      }
    }
  }
  return out;
}

// The ortho-parallel robots: the subproblems of solve_vector in the frame C of axes 1 and 2, where a
// rotation about axis 1 (axis 2, 3) turns components 2 and 3 (1 and 3) only, and the wrist's in the
// frame (w4, w5, w4 x w5), with v6 = w5: each rotation is a plane rotation of two numbers. The arm
// branches (q1, q3) go through each stage together, so that their independent arctangents overlap.
// Same branches in the same order; a wrist centre on axis 1 (or out of reach) goes to solve_vector.
IkSolutions IkSolver::solve_ortho(const Mat3& gr, const Vec3& p, const IkOptions& opt) const {
  const double* ref_deg = opt.reference_deg;
  const Branch br{ref_deg, opt.branches == Branches::NearestReference && ref_deg != nullptr};
  Tangency tg;
  tg.clamp = opt.out_of_reach == OutOfReach::Nearest;
  const Ortho& o = o_;
  const Constants& kc = k_;
  const Vec3 u = o.ct * (p - p_[0]);
  const Vec3 gw = o.ct * (gr * w_[5]), gv = o.ct * (gr * w_[4]);  // C G w6, C G w5
  // q1 (sub4 with h = w2, k = w1: A = w2 . u, B = w2 . (w1 x u), C = d)
  Angle t1[2];
  const int n1 = sub4_abc(u[1], -u[2], o.d, t1, tg);
  if (n1 == 0) return solve_vector(gr, p, opt);
  const bool clamped1 = tg.clamped;
  // the arm branches (q1, q3), in the order of solve_vector's loops
  struct Arm {
    Angle a1, a3, a2;
    Vec3 y, w6, v6;  // e^{-xi1 q1} p - p2, and C G w6, C G w5 turned back by -q1
    bool clamped;
  };
  Arm arm[4];
  int na = 0;
  Angle q1s[2];
  for (int i = 0; i < n1; ++i) q1s[i] = negated(t1[i]);
  const int b1 = br.pick(q1s, n1, 0);
  for (int i1 = br.begin(b1); i1 < br.end(b1, n1); ++i1) {
    const Angle& a1 = q1s[i1];
    // rotation about axis 1 by -q1 on components 2, 3
    auto r1 = [&](const Vec3& v) { return Vec3(v[0], v[1] * a1.c + v[2] * a1.s, -v[1] * a1.s + v[2] * a1.c); };
    const Vec3 y = r1(u) - o.p21;
    Angle t3[2];
    tg.clamped = clamped1;
    const int n3 = sub3_elbow(kc, y.norm(), t3, tg);
    const int b3 = br.pick(t3, n3, 2);
    for (int i3 = br.begin(b3); i3 < br.end(b3, n3); ++i3) arm[na++] = Arm{a1, t3[i3], Angle{}, y, r1(gw), r1(gv), tg.clamped};
  }
  // q2 (sub1 about w2 from x - p2 = rot(w2, sigma q3)(pw - p3) + p3 - p2 to y, components 1 and 3)
  for (int k = 0; k < na; ++k) {
    Arm& a = arm[k];
    const double c3 = a.a3.c, s3 = o.sigma * a.a3.s;
    const double x1 = o.pw3_1 * c3 + o.pw3_3 * s3 + o.p32_1, x3 = -o.pw3_1 * s3 + o.pw3_3 * c3 + o.p32_3;
    a.a2 = from_xy(x1 * a.y[0] + x3 * a.y[2], x3 * a.y[0] - x1 * a.y[2]);
  }
  // q4, q5 (sub2 of the wrist) and q6 of the first wrist solution of each arm branch
  Angle t4[4][2], t5[4][2], a6[4];
  int n45[4];
  for (int k = 0; k < na; ++k) {
    Arm& a = arm[k];
    // rotation about axis 2 by -(q2 + sigma q3) on components 1, 3
    const double c = a.a2.c * a.a3.c - o.sigma * a.a2.s * a.a3.s, s = a.a2.s * a.a3.c + o.sigma * a.a2.c * a.a3.s;
    const Vec3 w6(a.w6[0] * c - a.w6[2] * s, a.w6[1], a.w6[0] * s + a.w6[2] * c);
    a.v6 = Vec3(a.v6[0] * c - a.v6[2] * s, a.v6[1], a.v6[0] * s + a.v6[2] * c);
    tg.clamped = a.clamped;
    n45[k] = sub2_dots(kc, o.w4.dot(w6), o.w5.dot(w6), o.n.dot(w6), o.m.dot(w6), t4[k], t5[k], true, tg);
    a.clamped = tg.clamped;
  }
  for (int k = 0; k < na; ++k) {
    if (n45[k] == 0) continue;
    // q6 takes w5 to rot(w5, -q5) rot(w4, -q4) R456 w5; in the frame (w4, w5, n) a turn about w4
    // moves components 2, 3 and one about w5 components 1, 3; sub1 about tau w4 from (0, 1, 0)
    const Vec3& v = arm[k].v6;
    const double e1 = o.w4.dot(v), e2 = o.w5.dot(v), e3 = o.n.dot(v);
    const Angle &a4 = t4[k][0], &a5 = t5[k][0];
    const double f2 = e2 * a4.c + e3 * a4.s, f3 = -e2 * a4.s + e3 * a4.c;
    a6[k].q = fastmath::atan2(o.tau * (e1 * a5.s + f3 * a5.c), f2);
  }
  IkSolutions out;
  for (int k = 0; k < na; ++k) {
    if (n45[k] == 2) {  // the other wrist: (q4 + pi, -q5, q6 + pi)
      t4[k][1].q = t4[k][0].q + kPi;
      t5[k][1] = negated(t5[k][0]);
    }
    const int b45 = br.pick_wrist(t4[k], t5[k], n45[k]);
    for (int i45 = br.begin(b45); i45 < br.end(b45, n45[k]); ++i45) {
      double q[6] = {arm[k].a1.q, arm[k].a2.q, arm[k].a3.q, t4[k][i45].q, t5[k][i45].q, a6[k].q + i45 * kPi};
      record(out, q, std::abs(t5[k][i45].s), gr, false, arm[k].clamped);
    }
  }
  return out;
}

// The solutions' angles, radians within a few turns, to degrees, each shifted by whole turns into the
// limits, nearest the reference. For a reference within the limits and less than a turn from zero
// (the usual case): the turn nearest the reference when it lands inside; else the next turn towards
// the limits (the candidates beyond are farther from both); else none (the angle in [-180, 180], out
// of limits): the choice into_limits makes, up to rounding, joint by joint over the solutions, two at
// a time in SSE2 registers without branches on the data (other targets: into_limits one by one).
void IkSolver::to_degrees(IkSolutions& out, const double* ref_deg) const {
  const int n = out.count;
  bool simple = true;
  for (int j = 0; j < 6; ++j) {
    const double r = ref_deg ? ref_deg[j] : 0.0;
    simple = simple && r >= lo_[j] && r <= hi_[j] && std::abs(r) < 360;
  }
#if defined(__SSE2__)
  if (simple && n > 2) {  // (one or two solutions, the nearest branch: the scalar loop is as quick)
    const __m128d magic = _mm_set1_pd(6755399441055744.0);  // fastmath::round_nearest
    auto round = [&](__m128d v) { return _mm_sub_pd(_mm_add_pd(v, magic), magic); };
    auto select = [](__m128d m, __m128d a, __m128d b) { return _mm_or_pd(_mm_and_pd(m, a), _mm_andnot_pd(m, b)); };
    const __m128d turn = _mm_set1_pd(360), inv_turn = _mm_set1_pd(1.0 / 360), half = _mm_set1_pd(-180);
    const __m128d sign = _mm_set1_pd(-0.0), deg = _mm_set1_pd(180 / kPi);
    __m128d ok[4];
    for (auto& o : ok) o = _mm_castsi128_pd(_mm_set1_epi32(-1));
    for (int j = 0; j < 6; ++j) {
      const __m128d r = _mm_set1_pd(ref_deg ? ref_deg[j] : 0.0), lo = _mm_set1_pd(lo_[j]), hi = _mm_set1_pd(hi_[j]);
      for (int i = 0; i < n; i += 2) {
        const int i2 = i + 1 < n ? i + 1 : i;  // an odd count: the last lane repeats the last solution
        const __m128d d = _mm_mul_pd(_mm_set_pd(out.sol[i2].q_deg[j], out.sol[i].q_deg[j]), deg);
        // the turn nearest r, then the next turn towards the limits
        const __m128d y0 = _mm_add_pd(d, _mm_mul_pd(turn, round(_mm_mul_pd(_mm_sub_pd(r, d), inv_turn))));
        const __m128d above = _mm_cmpgt_pd(y0, hi);
        const __m128d in0 = _mm_andnot_pd(above, _mm_cmpge_pd(y0, lo));
        const __m128d y1 = _mm_add_pd(y0, _mm_xor_pd(turn, _mm_and_pd(above, sign)));
        const __m128d in1 = _mm_and_pd(_mm_cmpge_pd(y1, lo), _mm_cmple_pd(y1, hi));
        // none inside: the angle in (-180, 180]
        __m128d w = _mm_sub_pd(d, _mm_mul_pd(turn, round(_mm_mul_pd(d, inv_turn))));
        w = _mm_add_pd(w, _mm_and_pd(_mm_cmple_pd(w, half), turn));
        const __m128d y = select(in0, y0, select(in1, y1, w));
        ok[i / 2] = _mm_and_pd(ok[i / 2], _mm_or_pd(in0, in1));
        _mm_storel_pd(&out.sol[i].q_deg[j], y);
        _mm_storeh_pd(&out.sol[i2].q_deg[j], y);
      }
    }
    for (int i = 0; i < n; ++i) out.sol[i].within_limits = (_mm_movemask_pd(ok[i / 2]) >> (i % 2)) & 1;
    return;
  }
#endif
  for (int i = 0; i < n; ++i) {
    Vec6& q = out.sol[i].q_deg;
    for (int j = 0; j < 6; ++j) q[j] = wrap(q[j]) * (180 / kPi);
    out.sol[i].within_limits = into_limits(q, ref_deg);
  }
}

// The angles (deg, in [-180, 180]) shifted by whole turns into the limits, nearest the reference
// (or 0): the whole turn nearest the reference (|k| <= 2); when it falls outside the limits, the
// nearest of the five that lie inside; none: q kept, out of limits (false). to_degrees' general case.
bool IkSolver::into_limits(Vec6& qd, const double* ref_deg) const {
  bool ok = true;
  for (int j = 0; j < 6; ++j) {
    const double q = qd[j], ref = ref_deg ? ref_deg[j] : 0.0;
    const double kn = std::min(2.0, std::max(-2.0, fastmath::round_nearest((ref - q) * (1.0 / 360))));
    const double c = q + 360.0 * kn;
    if (c >= lo_[j] && c <= hi_[j]) {
      qd[j] = c;
      continue;
    }
    double best = q;
    bool found = false;
    for (int k = -2; k <= 2; ++k) {
      const double ck = q + 360.0 * k;
      if (ck < lo_[j] || ck > hi_[j]) continue;
      if (!found || std::abs(ck - ref) < std::abs(best - ref)) best = ck;
      found = true;
    }
    qd[j] = best;
    ok = ok && found;
  }
  return ok;
}

int IkSolutions::nearest(const double* ref_deg) const {
  int best = -1;
  double bestd = 0;
  for (int i = 0; i < count; ++i) {
    if (!sol[i].within_limits) continue;
    double d = 0;
    for (int j = 0; j < 6; ++j) {
      const double e = sol[i].q_deg[j] - (ref_deg ? ref_deg[j] : 0.0);
      d += e * e;
    }
    if (best < 0 || d < bestd) {
      best = i;
      bestd = d;
    }
  }
  return best;
}


}  // namespace kincal
