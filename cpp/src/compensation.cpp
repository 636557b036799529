#include "kincal/compensation.hpp"

#include <random>
#include <vector>

#include "kincal/kinematics.hpp"

#include <Eigen/LU>
#include <cmath>

#include "kincal/fastmath.hpp"
#include "kincal/solve6.hpp"

namespace kincal {

const char* to_string(CompStatus s) {
  switch (s) {
    case CompStatus::Converged: return "converged";
    case CompStatus::NotConverged: return "did not converge within the iteration limit";
    case CompStatus::SingularJacobian: return "singular Jacobian (the robot is at a singularity)";
    case CompStatus::OrientationSingular: return "orientation at B = +-90 deg, where ABC angles are singular";
    case CompStatus::NotSixJoints: return "Newton compensation needs a 6-joint robot";
  }
  return "?";
}

namespace {

using Q6 = Eigen::Matrix<double, 6, 1>;

inline double wrap180(double a) {  // to [-180, 180] without std::remainder (slow)
  if (a > 180.0 || a < -180.0) a -= 360.0 * std::floor((a + 180.0) / 360.0);
  return a;
}

// F (eq. 6) from the pose's position and its ABC angles in degrees
inline Vec6 deviation_from(const Vec3& xyz, const Vec3& abc, const Pose6& d) {
  Vec6 f;
  f.head<3>() = xyz - d.xyz;
  for (int i = 0; i < 3; ++i) f[3 + i] = wrap180(abc[i] - d.abc[i]);
  return f;
}

inline Vec6 deviation(const Eigen::Isometry3d& t, const Pose6& d) {
  return deviation_from(t.translation(), rotation_to_abc(t.linear()), d);
}

// The sines and cosines of A and B of a rotation (the ABC rates need them), read off the matrix;
// at gimbal lock (cb = 0) A is taken as 0, and Newton stops there with OrientationSingular.
struct AbcTrig {
  double ca = 1, sa = 0, cb = 1, sb = 0;
};
inline AbcTrig abc_trig(const Mat3& r) {
  AbcTrig tr;
  tr.cb = std::sqrt(r(0, 0) * r(0, 0) + r(1, 0) * r(1, 0));
  tr.sb = -r(2, 0);
  if (tr.cb >= 1e-12) {
    const double inv = 1 / tr.cb;
    tr.ca = r(0, 0) * inv;
    tr.sa = r(1, 0) * inv;
  }
  return tr;
}

inline VecQ to_rad(const Q6& q) { return q * kDeg; }

}  // namespace

Vec6 pose_deviation(const Model& cal, const Q6& q_deg, const Pose6& desired) {
  return deviation(fk_compliant(cal, to_rad(q_deg)), desired);
}

namespace {

// F (eq. 6) and its analytic Jacobian at one q, in fixed sizes: the Jacobian follows from the frames
// of the FK only when it is asked for, the ABC rates from the rotation itself. With compliance the
// chain is evaluated at the deflected angles q + K tau(q) and the Jacobian chained with
// d(q + K tau)/dq = I + K dtau/dq.
struct DeviationEvaluator {
  const Model& cal;
  const Pose6& desired;
  const bool compliant;
  ChainFrames frames;
  MatQ dqd;  // d(q + K tau)/dq, with compliance
  AbcTrig tr;

  DeviationEvaluator(const Model& m, const Pose6& d) : cal(m), desired(d), compliant(m.has_compliance()) {}

  Vec6 deviation_at(const Q6& q_deg) {
    const VecQ qr = q_deg * kDeg;
    fk_frames(cal, compliant ? deflected(cal, qr, &dqd) : qr, frames);
    tr = abc_trig(frames.tool.linear());
    // rotation_to_abc's angles, its division by the degree as a multiplication on this path
    return deviation_from(frames.tool.translation(), rotation_to_abc_rad(frames.tool.linear()) * (1 / kDeg), desired);
  }

  bool orientation_singular() const { return std::abs(tr.cb) < 1e-9; }

  // Solves jf step = f for the step (f becomes it); returns |det jf|. The position rows are first
  // moved from the tool point to the wrist (joint 5's origin): v_wrist = v_tool + d x w with
  // d = tool - wrist and w = E (A', B', C'), a row operation of determinant 1 on jf and f alike,
  // after which the arm's position block alone is singular only where the arm is (solve_blocks).
  double solve(Mat6r& jf, Vec6& f) const {
    const Vec3 d = frames.tool.translation() - frames.o[4];
    Mat3 e;  // angular velocity per ABC rate
    e << 0, -tr.sa, tr.ca * tr.cb, 0, tr.ca, tr.sa * tr.cb, 1, 0, -tr.sb;
    Mat3 dx;
    dx << 0, -d[2], d[1], d[2], 0, -d[0], -d[1], d[0], 0;
    const Mat3 m = kDeg * dx * e;  // mm per degree of A, B, C
    jf.topRows<3>() += m * jf.bottomRows<3>();
    f.head<3>() += m * f.tail<3>();
    return solve_blocks(jf, f);
  }

  // dF/dq at the last deviation_at: rows mm and degrees, columns per degree of q: the geometric
  // Jacobian of the frames (jacobian_from's columns, written here in fixed size: through
  // jacobian_from's 6 x N matrix the compensation took 40 ns longer), its angular rows mapped to
  // the ABC rates by E^-1 = [[ca sb/cb, sa sb/cb, 1], [-sa, ca, 0], [ca/cb, sa/cb, 0]] for
  // R = Rz(a) Ry(b) Rx(c)
  void jacobian(Mat6r& jf) const {
    const double icb = 1 / tr.cb;
    const double e0 = tr.ca * tr.sb * icb, e1 = tr.sa * tr.sb * icb, e2 = tr.ca * icb, e3 = tr.sa * icb;
    const Vec3 tip = frames.tool.translation();
#pragma GCC unroll 6
    for (int j = 0; j < 6; ++j) {
      const Vec3& z = frames.z[j];
      jf.col(j).head<3>() = z.cross(tip - frames.o[j]) * kDeg;
      jf(3, j) = e0 * z[0] + e1 * z[1] + z[2];
      jf(4, j) = -tr.sa * z[0] + tr.ca * z[1];
      jf(5, j) = e2 * z[0] + e3 * z[1];
    }
    if (compliant) jf = (jf * dqd.topLeftCorner<6, 6>()).eval();
  }
};

CompensationResult compensate_analytic(const Model& cal, const Pose6& desired, const Q6& q0_deg,
                                       const CompensationOptions& opt) {
  CompensationResult res;
  Q6 q = q0_deg;
  DeviationEvaluator ev(cal, desired);
  Mat6r jf;
  for (int it = 0;; ++it) {
    const Vec6 f = ev.deviation_at(q);
    const double f2 = f.squaredNorm();
    auto finish = [&](CompStatus status) {
      res.q_deg = q;
      res.iterations = it;
      res.residual = std::sqrt(f2);
      res.position_error_mm = f.head<3>().norm();
      res.orientation_error_deg = f.tail<3>().norm();
      res.status = status;
      return res;
    };
    if (f2 < opt.epsilon) return finish(CompStatus::Converged);
    if (it >= opt.max_iterations) return finish(CompStatus::NotConverged);
    if (ev.orientation_singular()) return finish(CompStatus::OrientationSingular);
    ev.jacobian(jf);
    Vec6 step = f;
    const double det = ev.solve(jf, step);
    if (!(det > 1e-18) || !std::isfinite(det) || !step.allFinite()) return finish(CompStatus::SingularJacobian);
    q -= step;
  }
}

}  // namespace

Mat6 pose_deviation_jacobian(const Model& cal, const Q6& q_deg, const Pose6& desired) {
  if (cal.dof() != 6) throw std::invalid_argument("pose_deviation_jacobian needs a 6-joint robot");
  DeviationEvaluator ev(cal, desired);
  ev.deviation_at(q_deg);
  Mat6r jf;
  ev.jacobian(jf);
  return jf;
}

CompensationResult compensate(const Model& cal, const Pose6& desired, const Q6& q0_deg, const CompensationOptions& opt) {
  CompensationResult res;
  res.q_deg = q0_deg;
  if (cal.dof() != 6) {
    res.status = CompStatus::NotSixJoints;
    return res;
  }
  if (!opt.finite_difference) return compensate_analytic(cal, desired, q0_deg, opt);
  // the paper's iteration with its finite-difference Jacobian (eq. 7)
  Q6 q = q0_deg;
  Mat6r jf;
  for (int it = 0;; ++it) {
    Vec6 f = deviation(fk_compliant(cal, to_rad(q)), desired);
    res.q_deg = q;
    res.iterations = it;
    res.residual = f.norm();
    res.position_error_mm = f.head<3>().norm();
    res.orientation_error_deg = f.tail<3>().norm();
    if (f.squaredNorm() < opt.epsilon) {
      res.status = CompStatus::Converged;
      return res;
    }
    if (it >= opt.max_iterations) {
      res.status = CompStatus::NotConverged;
      return res;
    }
    // eq. 7: column i = (F(q + delta e_i) - F(q)) / delta
    for (int i = 0; i < 6; ++i) {
      Q6 qi = q;
      qi[i] += opt.delta;
      Vec6 fi = deviation(fk_compliant(cal, to_rad(qi)), desired);
      jf.col(i) = (fi - f) / opt.delta;
    }
    const double det = solve6(jf, f);
    if (!(det > 1e-18) || !std::isfinite(det) || !f.allFinite()) {
      res.status = CompStatus::SingularJacobian;
      return res;
    }
    q -= f;
  }
}

Q6 wrap_near(const Model& m, const Q6& q, const Q6& ref) {
  Q6 out = q;
  for (int j = 0; j < 6; ++j) {
    const auto& js = m.spec().joints[j];
    // the same joint position (360 degree periodic) nearest the reference, inside the limits if any is
    double best = out[j];
    const double k0 = std::round((ref[j] - q[j]) / 360.0);
    bool inside = false;
    for (int dk = -2; dk <= 2; ++dk) {
      const double c = q[j] + 360.0 * (k0 + dk);
      const bool in = c >= js.lower_deg - 1e-9 && c <= js.upper_deg + 1e-9;
      if ((in && !inside) || (in == inside && std::abs(c - ref[j]) < std::abs(best - ref[j]))) {
        best = c;
        inside = inside || in;
      }
    }
    out[j] = best;
  }
  return out;
}

namespace {

/// Damped least squares from q (deg) toward the desired pose; true when it gets within 1e-6 mm/rad.
bool dls(const Model& m, const Eigen::Isometry3d& target, Q6& q) {
  Eigen::Isometry3d t;
  Jac jg;
  double lambda = 1e-2;
  const double w = 1000.0;  // mm per rad of orientation error
  auto error = [&](const Q6& qq, Vec6& e) {
    const Eigen::Isometry3d tt = fk_compliant(m, to_rad(qq));
    const Eigen::AngleAxisd aa(tt.linear() * target.linear().transpose());
    e.head<3>() = tt.translation() - target.translation();
    e.tail<3>() = w * aa.angle() * aa.axis();
    return e.norm();
  };
  Vec6 e;
  double err = error(q, e);
  for (int it = 0; it < 300 && err > 1e-6; ++it) {
    fk_jacobian_compliant(m, to_rad(q), t, jg);
    Mat6 j;
    j.topRows<3>() = jg.topRows<3>();
    j.bottomRows<3>() = w * jg.bottomRows<3>();
    const Mat6 jtj = j.transpose() * j;
    const Vec6 g = j.transpose() * e;
    bool improved = false;
    for (int tries = 0; tries < 10 && !improved; ++tries) {
      Mat6 a = jtj;
      a.diagonal() += lambda * (jtj.diagonal().array() + 1e-9).matrix();
      Vec6 step = a.ldlt().solve(g);           // radians
      const double mx = step.cwiseAbs().maxCoeff();
      if (mx > 0.3) step *= 0.3 / mx;           // at most about 17 degrees per step
      const Q6 qn = q - step / kDeg;
      Vec6 en;
      const double errn = error(qn, en);
      if (errn < err) {
        q = qn;
        e = en;
        err = errn;
        lambda = std::max(lambda / 3, 1e-9);
        improved = true;
      } else {
        lambda *= 10;
      }
    }
    if (!improved) return false;
  }
  return err <= 1e-6;
}

}  // namespace

bool numeric_ik(const Model& m, const Pose6& desired, const Q6& ref, Q6& q_out, const CompensationOptions& opt,
                int starts) {
  const Eigen::Isometry3d target = pose_to_iso(desired);
  std::vector<Q6> seeds = {ref};
  if (m.spec().home_deg.size() == 6) seeds.push_back(Eigen::Map<const Q6>(m.spec().home_deg.data()));
  std::mt19937_64 rng(12345);
  for (int k = 0; k < starts; ++k) {
    Q6 s;
    for (int j = 0; j < 6; ++j) {
      const auto& js = m.spec().joints[j];
      s[j] = std::uniform_real_distribution<double>(std::max(js.lower_deg, -180.0), std::min(js.upper_deg, 180.0))(rng);
    }
    seeds.push_back(s);
  }
  bool found = false;
  double best = 0;
  for (size_t k = 0; k < seeds.size(); ++k) {
    Q6 q = seeds[k];
    if (!dls(m, target, q)) continue;
    const CompensationResult r = compensate(m, desired, q, opt);
    if (r.status != CompStatus::Converged) continue;
    const Q6 qq = wrap_near(m, r.q_deg, ref);
    if (!m.within_limits_deg(qq)) continue;
    const double d = (qq - ref).cwiseAbs().maxCoeff();
    if (!found || d < best) {
      best = d;
      q_out = qq;
      found = true;
    }
    if (k == 0) break;  // converged from the reference itself: the continuous branch
  }
  return found;
}

}  // namespace kincal
