#include "kincal/compensation.hpp"

#include "kincal/kinematics.hpp"

#include <Eigen/LU>
#include <cmath>

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

inline double wrap180(double a) { return std::remainder(a, 360.0); }

inline Vec6 deviation(const Eigen::Isometry3d& t, const Pose6& d, Vec3& abc) {
  abc = rotation_to_abc(t.linear());
  Vec6 f;
  f.head<3>() = t.translation() - d.xyz;
  for (int i = 0; i < 3; ++i) f[3 + i] = wrap180(abc[i] - d.abc[i]);
  return f;
}

inline VecQ to_rad(const Q6& q) { return q * kDeg; }

}  // namespace

Vec6 pose_deviation(const Model& cal, const Q6& q_deg, const Pose6& desired) {
  Vec3 abc;
  return deviation(fk_compliant(cal, to_rad(q_deg)), desired, abc);
}

CompensationResult compensate(const Model& cal, const Pose6& desired, const Q6& q0_deg, const CompensationOptions& opt) {
  CompensationResult res;
  res.q_deg = q0_deg;
  if (cal.dof() != 6) {
    res.status = CompStatus::NotSixJoints;
    return res;
  }
  Q6 q = q0_deg;
  Eigen::Isometry3d t;
  Jac jg;
  Vec3 abc;
  Mat6 jf;
  for (int it = 0;; ++it) {
    Vec6 f;
    if (opt.finite_difference) {
      f = deviation(fk_compliant(cal, to_rad(q)), desired, abc);
    } else {
      fk_jacobian_compliant(cal, to_rad(q), t, jg);
      f = deviation(t, desired, abc);
    }
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
    if (opt.finite_difference) {
      // eq. 7: column i = (F(q + delta e_i) - F(q)) / delta
      for (int i = 0; i < 6; ++i) {
        Q6 qi = q;
        qi[i] += opt.delta;
        Vec3 abci;
        Vec6 fi = deviation(fk_compliant(cal, to_rad(qi)), desired, abci);
        jf.col(i) = (fi - f) / opt.delta;
      }
    } else {
      const double cb = std::cos(abc[1] * kDeg);
      if (std::abs(cb) < 1e-9) {
        res.status = CompStatus::OrientationSingular;
        return res;
      }
      // angular velocity w = E(a, b, c) [a', b', c'] for R = Rz(a) Ry(b) Rx(c)
      const double sa = std::sin(abc[0] * kDeg), ca = std::cos(abc[0] * kDeg), sb = std::sin(abc[1] * kDeg);
      Mat3 einv;  // inverse of [[0, -sa, ca cb], [0, ca, sa cb], [1, 0, -sb]]
      einv << ca * sb / cb, sa * sb / cb, 1, -sa, ca, 0, ca / cb, sa / cb, 0;
      // columns per degree of q; rows mm and degrees
      jf.topRows<3>() = jg.topRows<3>() * kDeg;
      jf.bottomRows<3>() = einv * jg.bottomRows<3>();
    }
    Eigen::PartialPivLU<Mat6> lu(jf);
    const double det = std::abs(lu.determinant());
    if (!(det > 1e-18) || !std::isfinite(det)) {
      res.status = CompStatus::SingularJacobian;
      return res;
    }
    q -= lu.solve(f);
  }
}

}  // namespace kincal
