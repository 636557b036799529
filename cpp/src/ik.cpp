#include "kincal/ik.hpp"

#include <Eigen/Cholesky>

#include <algorithm>
#include <cmath>

namespace kincal {

namespace {

inline Mat3 rot(const Vec3& k, double t) {
  // Rodrigues, k unit
  const double c = std::cos(t), s = std::sin(t), v = 1 - c;
  Mat3 r;
  r << c + k[0] * k[0] * v, k[0] * k[1] * v - k[2] * s, k[0] * k[2] * v + k[1] * s,  //
      k[1] * k[0] * v + k[2] * s, c + k[1] * k[1] * v, k[1] * k[2] * v - k[0] * s,    //
      k[2] * k[0] * v - k[1] * s, k[2] * k[1] * v + k[0] * s, c + k[2] * k[2] * v;
  return r;
}

// acos with tolerance: values a hair outside [-1, 1] are tangency (one solution), beyond is none.
thread_local bool t_clamp = false;   // ik_all(..., nearest_if_unreachable) is running
thread_local bool t_clamped = false;  // a subproblem was clamped to tangency

inline bool safe_acos(double x, double& out, bool& tangent) {
  constexpr double tol = 1e-10;
  tangent = false;
  if (!std::isfinite(x)) return false;
  if (x > 1 + tol || x < -1 - tol) {
    if (!t_clamp) return false;
    t_clamped = true;
    x = x > 0 ? 1.0 : -1.0;
  }
  if (x >= 1 - 1e-14) {
    out = 0;
    tangent = true;
  } else if (x <= -1 + 1e-14) {
    out = kPi;
    tangent = true;
  } else {
    out = std::acos(x);
  }
  return true;
}

// Near the wrist singularity SP2 loses half the digits (q5 comes from a square root of a
// difference): two Gauss-Newton steps with a pseudo-inverse restore the orientation to round-off.
void polish_wrist(const Vec3& w4, const Vec3& w5, const Vec3& w6, const Mat3& target, double* q) {
  for (int it = 0; it < 2; ++it) {
    const Mat3 r4 = rot(w4, q[0]), r45 = r4 * rot(w5, q[1]);
    const Mat3 r = r45 * rot(w6, q[2]);
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

inline double wrap(double a) {  // to (-pi, pi]; a few turns at most here, so no std::remainder (slow)
  constexpr double two_pi = 2 * kPi;
  if (a > kPi || a <= -kPi) a -= two_pi * std::floor((a + kPi) / two_pi);
  return a <= -kPi ? a + two_pi : (a > kPi ? a - two_pi : a);
}

}  // namespace

double pk_sub1(const Vec3& k, const Vec3& u, const Vec3& v) {
  const Vec3 up = u - k * k.dot(u), vp = v - k * k.dot(v);
  return std::atan2(k.dot(up.cross(vp)), up.dot(vp));
}

int pk_sub2(const Vec3& k1, const Vec3& k2, const Vec3& u, const Vec3& v, double t1[2], double t2[2]) {
  // c = rot(k2, t2) u = rot(k1, -t1) v: k2.c = k2.u, k1.c = k1.v, |c| = |u|.
  const double k12 = k1.dot(k2);
  const double den = k12 * k12 - 1;
  const double alpha = (k12 * k2.dot(u) - k1.dot(v)) / den;
  const double beta = (k12 * k1.dot(v) - k2.dot(u)) / den;
  const Vec3 k1xk2 = k1.cross(k2);
  const double g2 = (u.squaredNorm() - alpha * alpha - beta * beta - 2 * alpha * beta * k12) / k1xk2.squaredNorm();
  const double scale = std::max(1.0, u.squaredNorm());
  if (!std::isfinite(g2)) return 0;
  if (g2 < -1e-10 * scale) {
    if (!t_clamp) return 0;
    t_clamped = true;
  }
  const double g = g2 > 0 ? std::sqrt(g2) : 0.0;
  const int count = g > 0 ? 2 : 1;
  for (int i = 0; i < count; ++i) {
    const Vec3 c = alpha * k1 + beta * k2 + (i == 0 ? g : -g) * k1xk2;
    t2[i] = pk_sub1(k2, u, c);
    t1[i] = pk_sub1(k1, c, v);
  }
  return count;
}

int pk_sub3(const Vec3& k, const Vec3& u, const Vec3& v, double d, double t[2]) {
  const Vec3 up = u - k * k.dot(u), vp = v - k * k.dot(v);
  const double dz = k.dot(u - v);
  const double dp2 = d * d - dz * dz;
  const double nu = up.norm(), nv = vp.norm();
  if (nu < 1e-12 || nv < 1e-12) return 0;
  const double theta0 = std::atan2(k.dot(up.cross(vp)), up.dot(vp));
  double a;
  bool tangent;
  if (!safe_acos((nu * nu + nv * nv - dp2) / (2 * nu * nv), a, tangent)) return 0;
  t[0] = theta0 - a;
  if (tangent) return 1;
  t[1] = theta0 + a;
  return 2;
}

int pk_sub4(const Vec3& h, const Vec3& k, const Vec3& u, double d, double t[2]) {
  // h . (k (k.u) + cos t (u - k (k.u)) + sin t (k x u)) = d
  const double A = h.dot(u - k * k.dot(u));
  const double B = h.dot(k.cross(u));
  const double C = d - h.dot(k) * k.dot(u);
  const double r = std::hypot(A, B);
  if (r < 1e-12) return 0;
  const double phi = std::atan2(B, A);
  double a;
  bool tangent;
  if (!safe_acos(C / r, a, tangent)) return 0;
  t[0] = phi + a;
  if (tangent) return 1;
  t[1] = phi - a;
  return 2;
}

IkSolutions ik_all(const Model& m, const Eigen::Isometry3d& target, const double* ref_deg,
                   bool nearest_if_unreachable, bool nearest_branch) {
  const bool greedy = nearest_branch && ref_deg != nullptr;
  // index of the candidate nearest the reference angle (deg), comparing modulo 360
  auto nearer = [&](const double* cand, int n, int joint) {
    if (!greedy || n < 2) return 0;
    const double r = ref_deg[joint] * kDeg;
    return std::abs(wrap(cand[1] - r)) < std::abs(wrap(cand[0] - r)) ? 1 : 0;
  };
  IkSolutions out;
  t_clamp = nearest_if_unreachable;
  t_clamped = false;
  struct Reset {
    ~Reset() { t_clamp = false; }
  } reset;
  const IkStructure& st = m.ik_structure();
  if (!st.spherical_wrist_parallel_23) {
    out.status = IkStatus::Unsupported;
    return out;
  }
  const Vec3& pw = st.wrist_center;
  // G = T M^-1 = e^{xi1 q1} ... e^{xi6 q6}; the wrist centre maps to p = G pw.
  const Mat3 gr = target.linear() * m.tool().linear().transpose();
  const Vec3 gt = target.translation() - gr * m.tool().translation();
  const Vec3 p = gr * pw + gt;
  const Vec3 &w1 = m.axis(0), &w2 = m.axis(1), &w3 = m.axis(2), &w4 = m.axis(3), &w5 = m.axis(4),
             &w6 = m.axis(5);
  const Vec3 &p1 = m.point(0), &p2 = m.point(1), &p3 = m.point(2);

  // q1: rotations about axes 2 and 3 keep the component along w2, so w2 . rot(w1, -q1)(p - p1)
  // must equal w2 . (pw - p1).
  double t1[2];
  const int n1 = pk_sub4(w2, w1, p - p1, w2.dot(pw - p1), t1);
  bool shoulder = false;
  double q1s[2];
  int nq1 = 0;
  if (n1 == 0) {
    // wrist centre on axis 1 (shoulder singularity): any q1 satisfies it when the residual is zero
    const Vec3 u = p - p1;
    const Vec3 along = w1 * w1.dot(u);
    if ((u - along).norm() < 1e-9 && std::abs(w2.dot(along) - w2.dot(pw - p1)) < 1e-9) {
      shoulder = true;
      q1s[0] = ref_deg ? ref_deg[0] * kDeg : 0.0;
      nq1 = 1;
    }
  } else {
    for (int i = 0; i < n1; ++i) q1s[i] = -t1[i];
    nq1 = n1;
  }
  const bool clamped1 = t_clamped;  // q1 itself came from a tangency
  const int b1 = nearer(q1s, nq1, 0);
  for (int i1 = greedy ? b1 : 0; i1 < (greedy ? std::min(b1 + 1, nq1) : nq1); ++i1) {
    const double q1 = q1s[i1];
    const Mat3 r1 = rot(w1, q1);
    const Vec3 pp = r1.transpose() * (p - p1) + p1;  // e^{-xi1 q1} p
    double t3[2];
    t_clamped = clamped1;
    const int n3 = pk_sub3(w3, pw - p3, p2 - p3, (pp - p2).norm(), t3);
    const bool clamped3 = t_clamped;  // flags of this shoulder and elbow branch only
    const int b3 = nearer(t3, n3, 2);
    for (int i3 = greedy ? b3 : 0; i3 < (greedy ? std::min(b3 + 1, n3) : n3); ++i3) {
      const double q3 = t3[i3];
      const Mat3 r3 = rot(w3, q3);
      const Vec3 x = r3 * (pw - p3) + p3;
      const double q2 = pk_sub1(w2, x - p2, pp - p2);
      const Mat3 r123 = r1 * rot(w2, q2) * r3;
      const Mat3 r456 = r123.transpose() * gr;
      double t4[2], t5[2];
      t_clamped = clamped3;
      const int n45 = pk_sub2(w4, w5, w6, r456 * w6, t4, t5);
      int b45 = 0;
      if (greedy && n45 == 2) {
        auto dist = [&](int i) {
          return std::abs(wrap(t4[i] - ref_deg[3] * kDeg)) + std::abs(wrap(t5[i] - ref_deg[4] * kDeg));
        };
        b45 = dist(1) < dist(0) ? 1 : 0;
      }
      for (int i45 = greedy ? b45 : 0; i45 < (greedy ? std::min(b45 + 1, n45) : n45); ++i45) {
        const Mat3 r5 = rot(w5, t5[i45]);
        const Mat3 r45 = rot(w4, t4[i45]) * r5;
        // any vector normal to w6
        const Vec3 v = w6.unitOrthogonal();
        const double q6 = pk_sub1(w6, v, r45.transpose() * r456 * v);
        IkSolution& s = out.sol[out.count];
        double q[6] = {q1, q2, q3, t4[i45], t5[i45], q6};
        const double wrist = w4.cross(r5 * w6).norm();  // sin of the angle between axes 4 and 6
        if (wrist < 1e-6) polish_wrist(w4, w5, w6, r456, q + 3);
        for (int j = 0; j < 6; ++j) s.q_deg[j] = wrap(q[j]) / kDeg;
        s.wrist_singular = wrist < 1e-7;
        s.shoulder_singular = shoulder;
        s.approximate = t_clamped;
        ++out.count;
      }
    }
  }
  // shift by 360 deg into the limits, nearest the reference
  for (int i = 0; i < out.count; ++i) {
    IkSolution& s = out.sol[i];
    bool ok = true;
    for (int j = 0; j < 6; ++j) {
      const auto& js = m.spec().joints[j];
      const double ref = ref_deg ? ref_deg[j] : 0.0;
      double best = s.q_deg[j];
      bool found = false;
      for (int k = -2; k <= 2; ++k) {
        const double c = s.q_deg[j] + 360.0 * k;
        if (c < js.lower_deg - 1e-9 || c > js.upper_deg + 1e-9) continue;
        if (!found || std::abs(c - ref) < std::abs(best - ref)) best = c;
        found = true;
      }
      s.q_deg[j] = best;
      ok = ok && found;
    }
    s.within_limits = ok;
  }
  out.status = out.count > 0 ? IkStatus::Ok : IkStatus::OutOfReach;
  return out;
}

int ik_nearest(const Model& m, const IkSolutions& s, const double* ref_deg) {
  (void)m;
  int best = -1;
  double bestd = 0;
  for (int i = 0; i < s.count; ++i) {
    if (!s.sol[i].within_limits) continue;
    double d = 0;
    for (int j = 0; j < 6; ++j) {
      const double e = s.sol[i].q_deg[j] - (ref_deg ? ref_deg[j] : 0.0);
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
