#include "kincal/ik/ik.hpp"

#include "kincal/kinematics/kinematics.hpp"

#include <Eigen/Cholesky>

#include <algorithm>
#include <cmath>

#include "kincal/core/fastmath.hpp"
#include "subproblems.hpp"

namespace kincal {

using namespace ik_detail;

namespace {

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

namespace {

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
  const bool deliver_now = delivers(opt);
  IkSolutions out = st_.ortho_parallel ? solve_ortho(gr, p, opt, deliver_now) : solve_vector(gr, p, opt, deliver_now);
  if (!deliver_now) to_degrees(out, opt.reference_deg);
  out.status = out.count > 0 ? IkStatus::Ok : IkStatus::OutOfReach;
  return out;
}

// The wrist angles of one solution (radians) polished near the singularity (IkSolver::record).
void IkSolver::polish(double* q, const Mat3& gr) const {
  const Vec3 &w1 = w_[0], &w2 = w_[1], &w3 = w_[2];
  const Mat3 r456 = (axis_rotation(w1, q[0]) * axis_rotation(w2, q[1]) * axis_rotation(w3, q[2])).transpose() * gr;
  polish_wrist(w_[3], w_[4], w_[5], r456, q + 3);
}

IkSolutions IkSolver::solve_vector(const Mat3& gr, const Vec3& p, const IkOptions& opt, bool deliver_now) const {
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
        record(out, q, wrist, gr, shoulder, tg.clamped, opt, deliver_now);
      }
    }
  }
  return out;
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
