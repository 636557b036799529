#include "kincal/kinematics/kinematics.hpp"

#include <cmath>

#include "chain_recursions.hpp"
#include "kincal/core/fastmath.hpp"
#include "weight_torque.hpp"

namespace kincal {

using namespace kinematics_detail;

Eigen::Isometry3d fk(const Model& m, const VecQ& q) {
  Mat3 r;
  Vec3 t;
  walk(m, q, r, t, [](int, const Mat3&, const Vec3&) {});
  Eigen::Isometry3d out;
  out.linear() = r;
  out.translation() = t;
  out.makeAffine();
  return out;
}

void fk_frames(const Model& m, const VecQ& q, ChainFrames& f) {
  Mat3 r = m.c0_r();  // (before the sines and cosines, as walk_n)
  Vec3 t = m.c0_t();
  auto visit = [&](int j, const Mat3& rj, const Vec3& tj) {
    f.z[j] = rj.col(2);
    f.o[j] = tj;
  };
  if (m.dof() == 6) {
    joint_sincos<6>(m, q.data(), f.s.data(), f.c.data());
    walk_sc<6>(m, f.s.data(), f.c.data(), r, t, visit);
  } else {
    joint_sincos<0>(m, q.data(), f.s.data(), f.c.data());
    walk_sc<0>(m, f.s.data(), f.c.data(), r, t, visit);
  }
  f.n = m.dof();
  f.tool.linear() = r;
  f.tool.translation() = t;
  f.tool.makeAffine();
}

void jacobian_from(const ChainFrames& f, Jac& jac) {
  const Vec3 t = f.tool.translation();
  jac.resize(6, f.n);
  for (int j = 0; j < f.n; ++j) {
    jac.block<3, 1>(0, j) = f.z[j].cross(t - f.o[j]);
    jac.block<3, 1>(3, j) = f.z[j];
  }
}

void fk_jacobian(const Model& m, const VecQ& q, Eigen::Isometry3d& tool, Jac& jac) {
  ChainFrames f;
  fk_frames(m, q, f);
  jacobian_from(f, jac);
  tool = f.tool;
}

namespace {

void gravity_torque_local(const Model& m, const double* q, VecQ& tau) {
  double s[kMaxJoints + 1], c[kMaxJoints + 1];
  joint_sincos<0>(m, q, s, c);
  tau.resize(m.dof());
  gravity_torque_sc(m, s, c, [&](int j, double t, double, double) { tau[j] = t; });
}

}  // namespace

void gravity_torque(const Model& m, const VecQ& q, VecQ& tau, MatQ* dtau) {
  if (!dtau) {
    gravity_torque_local(m, q.data(), tau);
    return;
  }
  const int n = m.dof();
  std::array<Vec3, kMaxJoints> z, o, mc;
  std::array<double, kMaxJoints> mass;
  Mat3 r;
  Vec3 t;
  walk(m, q, r, t, [&](int j, const Mat3& rj, const Vec3& tj) {
    z[j] = rj.col(2);
    o[j] = tj;
    const Model::Link& l = m.link(j);
    mass[j] = l.m;
    mc[j] = rj * l.mc + l.m * tj;  // first moment about the base origin
  });
  // what joint j carries, summed from the tip in the same pass as its torque (the payload is in the
  // last link's mass table)
  const Vec3& g = m.gravity();
  tau.resize(n);
  std::array<Vec3, kMaxJoints> arm;
  Vec3 s = Vec3::Zero();
  double msum = 0;
  for (int j = n - 1; j >= 0; --j) {
    s += mc[j];
    msum += mass[j];
    tau[j] = detail::weight_torque(z[j], o[j], s, msum, g, arm[j]);
  }
  if (dtau) {
    // i <= j: the whole sub-chain rotates about z_i, d tau_j / d q_i = g . (z_i x (z_j x arm_j));
    // i > j: only the part beyond joint i moves, g . (z_j x (z_i x arm_i)). Both are u_k . h_l with
    // u_k = z_k x arm_k, h_l = g x z_l, k = max(i, j), l = min(i, j).
    std::array<Vec3, kMaxJoints> u, h;
    for (int j = 0; j < n; ++j) {
      u[j] = z[j].cross(arm[j]);
      h[j] = g.cross(z[j]);
    }
    dtau->resize(n, n);
    for (int i = 0; i < n; ++i)  // column by column (column-major)
      for (int j = 0; j < n; ++j) (*dtau)(j, i) = i <= j ? u[j].dot(h[i]) : u[i].dot(h[j]);
  }
}

VecQ deflected(const Model& m, const VecQ& q, MatQ* dqd) {
  const int n = m.dof();
  if (!m.has_compliance()) {
    if (dqd) *dqd = MatQ::Identity(n, n);
    return q;
  }
  VecQ tau;
  gravity_torque(m, q, tau, dqd);  // dqd holds d tau/dq
  VecQ out = q;
  for (int j = 0; j < n; ++j) out[j] += m.compliance(j) * tau[j];
  if (dqd) {  // d(q + K tau)/dq = I + K dtau/dq, in place, column by column
    for (int i = 0; i < n; ++i) {
      for (int j = 0; j < n; ++j) (*dqd)(j, i) *= m.compliance(j);
      (*dqd)(i, i) += 1.0;
    }
  }
  return out;
}

void check_context(const Model& m, const EffectContext& ctx, const std::string& who) {
  if (m.needs_dir() && ctx.dir.size() != m.dof()) {
    std::string joints, name;
    for (const EffectValue& e : m.joint_effects())
      if (e.effect.kind().reads_dir())
        joints += (joints.empty() ? "" : ", ") + std::to_string(e.effect.joint + 1), name = e.effect.name;
    throw InputError(who + "the model has " + name + " on joint(s) " + joints +
                     ": the direction of motion into each pose is needed (dir1..dir" + std::to_string(m.dof()) +
                     ")");
  }
  if (m.needs_dir())
    for (int j = 0; j < m.dof(); ++j)
      if (ctx.dir[j] != 1.0 && ctx.dir[j] != -1.0)
        throw InputError(who + "dir" + std::to_string(j + 1) + " must be +1 or -1");
  if (m.needs_temperature() && !std::isfinite(ctx.temperature_c))
    throw InputError(who + "the model has thermal expansion: the temperature is needed (temperature_c)");
}

namespace {

// The joint effects' angles (transmission error, backlash, ...) added to out, their derivative to dqd.
void add_joint_effects(const Model& m, const VecQ& q, const EffectContext& ctx, VecQ& out, MatQ* dqd) {
  for (const EffectValue& ev : m.joint_effects()) add_joint_effect(ev, q, ctx, out, dqd);
}

}  // namespace

VecQ joint_angles(const Model& m, const VecQ& q, const EffectContext& ctx, MatQ* dqd) {
  VecQ out = deflected(m, q, dqd);
  if (m.has_joint_effects()) add_joint_effects(m, q, ctx, out, dqd);
  return out;
}

namespace {

template <int N>
void fk_frames_actual_n(const Model& m, const VecQ& q, const EffectContext& ctx, ChainFrames& f) {
  const int n = m.dof();
  double* s = f.s.data();
  double* c = f.c.data();
  joint_sincos<N>(m, q.data(), s, c);
  VecQ theta = q;
  if (m.has_compliance()) {
    gravity_torque_sc<N>(m, s, c, [&](int j, double t, double, double) { theta[j] += m.compliance(j) * t; });
  }
  if (m.has_joint_effects()) add_joint_effects(m, q, ctx, theta, nullptr);
  // theta's sines and cosines from q's by the small angle theta - q (larger: sincos of theta itself)
  for (int j = 0; j < n; ++j) {
    const double d = theta[j] - q[j];
    if (!(std::abs(d) <= kTurnMax)) {
      fk_frames(m, theta, f);
      return;
    }
    turn_sincos(d, s[j], c[j]);
  }
  Mat3 r = m.c0_r();
  Vec3 t = m.c0_t();
  walk_sc<N>(m, s, c, r, t, [&](int j, const Mat3& rj, const Vec3& tj) {
    f.z[j] = rj.col(2);
    f.o[j] = tj;
  });
  f.n = n;
  f.tool.linear() = r;
  f.tool.translation() = t;
  f.tool.makeAffine();
}

}  // namespace

void fk_frames_actual(const Model& m, const VecQ& q, const EffectContext& ctx, ChainFrames& f) {
  if (m.dof() == 6)
    fk_frames_actual_n<6>(m, q, ctx, f);
  else
    fk_frames_actual_n<0>(m, q, ctx, f);
}

Eigen::Isometry3d fk_model(const Model& m, const VecQ& q, const EffectContext& ctx) {
  Eigen::Isometry3d t = fk(m, joint_angles(m, q, ctx));
  t.translation() *= length_scale(m, ctx);
  return t;
}

void fk_jacobian_model(const Model& m, const VecQ& q, const EffectContext& ctx, Eigen::Isometry3d& tool, Jac& jac) {
  MatQ dqd;
  const VecQ qd = joint_angles(m, q, ctx, &dqd);
  Jac j0;
  fk_jacobian(m, qd, tool, j0);
  jac.noalias() = j0 * dqd;
  const double s = length_scale(m, ctx);
  tool.translation() *= s;
  jac.topRows<3>() *= s;
}

Eigen::Isometry3d fk_compliant(const Model& m, const VecQ& q) { return fk(m, deflected(m, q)); }

void fk_jacobian_compliant(const Model& m, const VecQ& q, Eigen::Isometry3d& tool, Jac& jac) {
  if (!m.has_compliance()) {
    fk_jacobian(m, q, tool, jac);
    return;
  }
  MatQ dqd;
  const VecQ qd = deflected(m, q, &dqd);
  Jac j0;
  fk_jacobian(m, qd, tool, j0);
  jac.noalias() = j0 * dqd;
}

}  // namespace kincal
