// kincal: the numerical IK of robots without a closed form (and of calibrated models): damped least
// squares from the reference, home and seeded starts, then Newton compensation on the model.
#include "kincal/compensation/pose.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Geometry>
#include <cmath>
#include <random>
#include <vector>

#include "kincal/kinematics/kinematics.hpp"

namespace kincal {

Vec6 wrap_near(const Model& m, const Vec6& q, const Vec6& ref) {
  Vec6 out = q;
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
bool dls(const Model& m, const Eigen::Isometry3d& target, Vec6& q, const EffectContext& ctx) {
  Eigen::Isometry3d t;
  Jac jg;
  double lambda = 1e-2;
  const double w = 1000.0;  // mm per rad of orientation error
  auto error = [&](const Vec6& qq, Vec6& e) {
    const Eigen::Isometry3d tt = fk_model(m, VecQ(qq * kDeg), ctx);
    const Eigen::AngleAxisd aa(tt.linear() * target.linear().transpose());
    e.head<3>() = tt.translation() - target.translation();
    e.tail<3>() = w * aa.angle() * aa.axis();
    return e.norm();
  };
  Vec6 e;
  double err = error(q, e);
  for (int it = 0; it < 300 && err > 1e-6; ++it) {
    fk_jacobian_model(m, VecQ(q * kDeg), ctx, t, jg);
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
      const Vec6 qn = q - step / kDeg;
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

std::optional<Vec6> numeric_ik(const Model& m, const Pose6& desired, const Vec6& ref, const CompensationOptions& opt,
                               int starts, const EffectContext& ctx) {
  const Eigen::Isometry3d target = pose_to_iso(desired);
  std::vector<Vec6> seeds = {ref};
  if (m.spec().home_deg.size() == 6) seeds.push_back(Eigen::Map<const Vec6>(m.spec().home_deg.data()));
  std::mt19937_64 rng(12345);
  for (int k = 0; k < starts; ++k) {
    Vec6 s;
    for (int j = 0; j < 6; ++j) {
      const auto& js = m.spec().joints[j];
      s[j] = std::uniform_real_distribution<double>(std::max(js.lower_deg, -180.0), std::min(js.upper_deg, 180.0))(rng);
    }
    seeds.push_back(s);
  }
  std::optional<Vec6> found;
  double best = 0;
  for (size_t k = 0; k < seeds.size(); ++k) {
    Vec6 q = seeds[k];
    if (!dls(m, target, q, ctx)) continue;
    const CompensationResult r = compensate(m, desired, q, opt, ctx);
    if (r.status != CompStatus::Converged) continue;
    const Vec6 qq = wrap_near(m, r.q_deg, ref);
    if (!m.within_limits_deg(qq)) continue;
    const double d = (qq - ref).cwiseAbs().maxCoeff();
    if (!found || d < best) {
      best = d;
      found = qq;
    }
    if (k == 0) break;  // converged from the reference itself: the continuous branch
  }
  return found;
}

}  // namespace kincal
