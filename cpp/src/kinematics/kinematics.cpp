#include "kincal/kinematics/kinematics.hpp"

#include <cmath>

#include "kincal/core/fastmath.hpp"
#include "weight_torque.hpp"

namespace kincal {

namespace {

// R <- R * Rz(q) for q of cosine c and sine s: mixes the first two columns of the rotation.
inline void rotate_z(Mat3& r, double c, double s) {
  const Vec3 x = r.col(0), y = r.col(1);
  r.col(0) = c * x + s * y;
  r.col(1) = c * y - s * x;
}

// R <- R * Rx(alpha): mixes the last two columns.
inline void rotate_x(Mat3& r, double ca, double sa) {
  const Vec3 y = r.col(1), z = r.col(2);
  r.col(1) = ca * y + sa * z;
  r.col(2) = ca * z - sa * y;
}

// The sines and cosines of every joint's angle (q + its offset), two at a time.
template <int N>
inline void joint_sincos(const Model& m, const double* q, double* s, double* c) {
  const int n = N > 0 ? N : m.dof();
#pragma GCC unroll 3
  for (int j = 0; j < n; j += 2) {
    const double a = q[j] + m.link(j).offset, b = j + 1 < n ? q[j + 1] + m.link(j + 1).offset : 0.0;
    fastmath::sincos2(a, b, s[j], c[j], s[j + 1], c[j + 1]);
  }
}

// Walks the chain (Model::Link) from r, t (the chain's base, C0); calls visit(j, R, t) with the frame
// right after joint j's rotation. N > 0: the joint count known at compile time (the loop unrolled),
// N = 0: m.dof(). walk_sc from the joints' sines and cosines, walk_n from their angles.
template <int N, class Visit>
inline void walk_sc(const Model& m, const double* s, const double* c, Mat3& r, Vec3& t, Visit&& visit) {
  const int n = N > 0 ? N : m.dof();
#pragma GCC unroll 6
  for (int j = 0; j < n; ++j) {
    const Model::Link& l = m.link(j);
    rotate_z(r, c[j], s[j]);
    visit(j, r, t);
    t += r * l.t;
    if (j + 1 < n)
      rotate_x(r, l.ca, l.sa);
    else
      r = r * m.last_r();
  }
}

template <int N, class Visit>
inline void walk_n(const Model& m, const double* q, Mat3& r, Vec3& t, Visit&& visit) {
  r = m.c0_r();  // (before the sines and cosines: with r and t set after them the FK took 12% longer)
  t = m.c0_t();
  double s[kMaxJoints + 1], c[kMaxJoints + 1];
  joint_sincos<N>(m, q, s, c);
  walk_sc<N>(m, s, c, r, t, visit);
}

template <class Visit>
inline void walk(const Model& m, const VecQ& q, Mat3& r, Vec3& t, Visit&& visit) {
  if (m.dof() == 6)
    walk_n<6>(m, q.data(), r, t, visit);
  else
    walk_n<0>(m, q.data(), r, t, visit);
}

}  // namespace

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

// The gravity torque alone, without rotation matrices: two recursions of 3-vectors in the joints' own
// frames (the frame right after each joint's rotation, as walk_n visits it). Forward, gravity in
// frame j: g_0 = Rz(th_0)^T C0^T g, g_j+1 = Rz(th_j+1)^T Rx(alpha_j)^T g_j. Backward, the first
// moment about joint j's origin of everything it carries, in frame j:
// A_j = mc_j + M_j+1 t_j + Rx(alpha_j) Rz(th_j+1) A_j+1 (M_j+1: the mass beyond joint j). Then
// tau_j = z . (A_j x g_j), z = (0, 0, 1) in its own frame. About a third of the walk's work.
// N > 0: the joint count known at compile time (as walk_sc). out(j, tau_j) takes each torque (its
// callers add the deflection there: an array of torques stored one by one and read two at a time
// stalled the fixed point of compensation on the failed store forwarding).
template <int N = 0, class Out>
void gravity_torque_sc(const Model& m, const double* s, const double* c, Out&& out) {
  const int n = N > 0 ? N : m.dof();
  std::array<double, kMaxJoints> gx, gy;
  Vec3 v = m.c0_r().transpose() * m.gravity();
#pragma GCC unroll 6
  for (int j = 0; j < n; ++j) {
    const double x = c[j] * v[0] + s[j] * v[1], y = c[j] * v[1] - s[j] * v[0];
    gx[j] = x;
    gy[j] = y;
    const Model::Link& l = m.link(j);
    v = Vec3(x, l.ca * y + l.sa * v[2], l.ca * v[2] - l.sa * y);
  }
  Vec3 a = m.link(n - 1).mc;
  double mass = m.link(n - 1).m;
  out(n - 1, a[0] * gy[n - 1] - a[1] * gx[n - 1]);
#pragma GCC unroll 6
  for (int j = n - 2; j >= 0; --j) {
    const Model::Link& l = m.link(j);
    const double x = c[j + 1] * a[0] - s[j + 1] * a[1], y = s[j + 1] * a[0] + c[j + 1] * a[1];
    a = l.mc + mass * l.t + Vec3(x, l.ca * y - l.sa * a[2], l.sa * y + l.ca * a[2]);
    mass += l.m;
    out(j, a[0] * gy[j] - a[1] * gx[j]);
  }
}

// gravity_torque_sc with the diagonal of its derivative and the one next to it (the derivative is
// symmetric: d tau_j / d q_j+1 = d tau_j+1 / d q_j), diag[j] = d tau_j / d q_j and
// next[j] = d tau_j / d q_j+1, in the same two recursions. In frame j (after joint j's rotation)
// tau_j = (A_j x g_j)_z: turning joint j turns g_j by -z x g_j; turning joint j+1 turns what A_j
// carries beyond it, Rx(alpha_j) (z x Rz(th_j+1) A_j+1).
template <int N = 0>
void gravity_torque_band_sc(const Model& m, const double* s, const double* c, double* tau, double* diag, double* next) {
  const int n = N > 0 ? N : m.dof();
  std::array<double, kMaxJoints> gx, gy;
  Vec3 v = m.c0_r().transpose() * m.gravity();
#pragma GCC unroll 6
  for (int j = 0; j < n; ++j) {
    const double x = c[j] * v[0] + s[j] * v[1], y = c[j] * v[1] - s[j] * v[0];
    gx[j] = x;
    gy[j] = y;
    const Model::Link& l = m.link(j);
    v = Vec3(x, l.ca * y + l.sa * v[2], l.ca * v[2] - l.sa * y);
  }
  Vec3 a = m.link(n - 1).mc;
  double mass = m.link(n - 1).m;
  tau[n - 1] = a[0] * gy[n - 1] - a[1] * gx[n - 1];
  diag[n - 1] = -(a[0] * gx[n - 1] + a[1] * gy[n - 1]);
  next[n - 1] = 0;
#pragma GCC unroll 6
  for (int j = n - 2; j >= 0; --j) {
    const Model::Link& l = m.link(j);
    const double x = c[j + 1] * a[0] - s[j + 1] * a[1], y = s[j + 1] * a[0] + c[j + 1] * a[1];
    a = l.mc + mass * l.t + Vec3(x, l.ca * y - l.sa * a[2], l.sa * y + l.ca * a[2]);
    mass += l.m;
    tau[j] = a[0] * gy[j] - a[1] * gx[j];
    diag[j] = -(a[0] * gx[j] + a[1] * gy[j]);
    next[j] = -y * gy[j] - l.ca * x * gx[j];
  }
}

void gravity_torque_local(const Model& m, const double* q, VecQ& tau) {
  double s[kMaxJoints + 1], c[kMaxJoints + 1];
  joint_sincos<0>(m, q, s, c);
  tau.resize(m.dof());
  gravity_torque_sc(m, s, c, [&](int j, double t) { tau[j] = t; });
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

// One joint effect's angle added to out, its derivative to dqd.
inline void add_joint_effect(const EffectValue& ev, const VecQ& q, const EffectContext& ctx, VecQ& out, MatQ* dqd) {
  double b[128], db[128];
  const int j = ev.effect.joint;
  joint_basis(ev.effect, q[j], ev.effect.kind().reads_dir() ? ctx.dir[j] : 0.0, b, dqd ? db : nullptr);
  double d = 0, dd = 0;
  for (size_t k = 0; k < ev.p.size(); ++k) {
    d += ev.p[k] * b[k];
    if (dqd) dd += ev.p[k] * db[k];
  }
  out[j] += d;
  if (dqd) (*dqd)(j, j) += dd;
}

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

// s, c of an angle x turned into those of x + d for a small d (|d| <= 0.01 rad): sin d and 1 - cos d
// by their series, whose next terms are below 1e-17 there.
inline void turn_sincos(double d, double& s, double& c) {
  const double d2 = d * d;
  const double sd = d - d * d2 * (1.0 / 6 - d2 * (1.0 / 120));
  const double cd1 = d2 * (0.5 - d2 * (1.0 / 24 - d2 * (1.0 / 720)));  // 1 - cos d
  const double s0 = s, c0 = c;
  s = s0 + (c0 * sd - s0 * cd1);
  c = c0 - (s0 * sd + c0 * cd1);
}
constexpr double kTurnMax = 0.01;  // rad: the largest d turn_sincos takes

template <int N>
void fk_frames_actual_n(const Model& m, const VecQ& q, const EffectContext& ctx, ChainFrames& f) {
  const int n = m.dof();
  double* s = f.s.data();
  double* c = f.c.data();
  joint_sincos<N>(m, q.data(), s, c);
  VecQ theta = q;
  if (m.has_compliance()) {
    gravity_torque_sc<N>(m, s, c, [&](int j, double t) { theta[j] += m.compliance(j) * t; });
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

void JointTrig::set(const Model& m, const VecQ& q_rad) {
  q = q_rad;
  joint_sincos<0>(m, q.data(), s.data(), c.data());
}

namespace {
// rad: the largest bound on the remainder of JointAnglesNear's series of the harmonic joint effects
// (their angles are 1e-4 rad in size, theta's rounding 2e-16 rad)
constexpr double kSeriesLeft = 1e-18;
}  // namespace

JointAnglesNear::JointAnglesNear(const Model& m, const VecQ& ref, const EffectContext& ctx) : m_(m), ctx_(ctx) {
  ref_.set(m, ref);
  prepare_effects();
}

JointAnglesNear::JointAnglesNear(const Model& m, const JointTrig& ref, const EffectContext& ctx)
    : m_(m), ctx_(ctx), ref_(ref) {
  prepare_effects();
}

void JointAnglesNear::prepare_effects() {
  const Model& m = m_;
  for (int j = 0; j < m.dof(); ++j) {
    taylor_[j].fill(0.0);
    remainder_[j] = m.harmonic_bound(j);
    series_[j] = false;
  }
  // the harmonic terms: sin q and cos q from the reference's sines and cosines of q + offset turned
  // back by the offset, sin kq and cos kq by angle addition; each term's derivatives are k^n times
  // itself (f'' = -k^2 f, f''' = -k^2 f', f'''' = k^4 f, ...)
  int last = -1;
  double sq = 0, cq = 1;
  for (const Model::HarmonicTerm& h : m.harmonic_terms()) {
    const int j = h.joint;
    if (j != last) {
      sq = ref_.s[j] * m.offset_cos(j) - ref_.c[j] * m.offset_sin(j);
      cq = ref_.c[j] * m.offset_cos(j) + ref_.s[j] * m.offset_sin(j);
      last = j;
      series_[j] = true;
    }
    double sk = sq, ck = cq;
    for (int i = 1; i < h.k; ++i) {
      const double t = sk * cq + ck * sq;
      ck = ck * cq - sk * sq;
      sk = t;
    }
    const double k = h.k, k2 = k * k;
    const double f = h.sin_amp * sk + h.cos_amp * ck, f1 = k * (h.sin_amp * ck - h.cos_amp * sk);
    std::array<double, 6>& c = taylor_[j];
    c[0] += f;
    c[1] += f1;
    c[2] -= k2 * f * (1.0 / 2);
    c[3] -= k2 * f1 * (1.0 / 6);
    c[4] += k2 * k2 * f * (1.0 / 24);
    c[5] += k2 * k2 * f1 * (1.0 / 120);
  }
  // the angle-free effects (backlash) at the reference; the others at each q
  double b[128];
  for (const EffectValue& ev : m.joint_effects()) {
    const EffectKind& kind = ev.effect.kind();
    if (kind.harmonic) continue;
    if (!kind.angle_free) {
      other_effects_ = true;
      continue;
    }
    const int j = ev.effect.joint;
    series_[j] = true;
    joint_basis(ev.effect, ref_.q[j], kind.reads_dir() ? ctx_.dir[j] : 0.0, b);
    for (size_t l = 0; l < ev.p.size(); ++l) taylor_[j][0] += ev.p[l] * b[l];
  }
}

VecQ JointAnglesNear::at_reference(double* lower, double* diag, double* upper) const {
  const int n = m_.dof();
  VecQ theta(n);
  if (m_.has_compliance()) {
    double tau[kMaxJoints], dg[kMaxJoints], nx[kMaxJoints];
    if (n == 6)
      gravity_torque_band_sc<6>(m_, ref_.s.data(), ref_.c.data(), tau, dg, nx);
    else
      gravity_torque_band_sc<0>(m_, ref_.s.data(), ref_.c.data(), tau, dg, nx);
    for (int j = 0; j < n; ++j) {
      const double k = m_.compliance(j);
      theta[j] = ref_.q[j] + k * tau[j];
      diag[j] = k * dg[j];
      upper[j] = k * nx[j];
      lower[j] = j > 0 ? k * nx[j - 1] : 0.0;
    }
  } else {
    theta = ref_.q;
    for (int j = 0; j < n; ++j) lower[j] = diag[j] = upper[j] = 0;
  }
  if (m_.has_joint_effects()) {
    for (int j = 0; j < n; ++j)
      if (series_[j]) {
        theta[j] += taylor_[j][0];
        diag[j] += taylor_[j][1];
      }
    if (other_effects_)  // (their derivative left out)
      for (const EffectValue& ev : m_.joint_effects())
        if (!(ev.effect.kind().harmonic || ev.effect.kind().angle_free)) add_joint_effect(ev, ref_.q, ctx_, theta, nullptr);
  }
  return theta;
}

VecQ JointAnglesNear::operator()(const VecQ& q) const {
  const int n = m_.dof();
  VecQ theta(n);  // (not a copy of q: that one called memcpy, 3% of compensation with effects)
  if (m_.has_compliance()) {
    // the reference's sines and cosines turned to q (all of q's anew where a joint is farther)
    std::array<double, kMaxJoints + 1> s = ref_.s, c = ref_.c;
    bool near = true;
    for (int j = 0; j < n; ++j) {
      const double d = q[j] - ref_.q[j];
      near = near && std::abs(d) <= kTurnMax;
      turn_sincos(d, s[j], c[j]);
    }
    if (!near) joint_sincos<0>(m_, q.data(), s.data(), c.data());
    auto deflect = [&](int j, double t) { theta[j] = q[j] + m_.compliance(j) * t; };
    if (n == 6)
      gravity_torque_sc<6>(m_, s.data(), c.data(), deflect);
    else
      gravity_torque_sc<0>(m_, s.data(), c.data(), deflect);
  } else {
    theta = q;
  }
  if (m_.has_joint_effects()) {
    // the harmonic effects by their series where its remainder is below kSeriesLeft, at q itself
    // (with the others) elsewhere
    std::array<bool, kMaxJoints> exact{};
    bool any_exact = other_effects_;
    for (int j = 0; j < n; ++j) {
      if (!series_[j]) continue;
      const double d = q[j] - ref_.q[j], d2 = d * d;
      if (remainder_[j] * (d2 * d2 * d2) <= kSeriesLeft) {
        const std::array<double, 6>& t = taylor_[j];
        theta[j] += t[0] + d * (t[1] + d * (t[2] + d * (t[3] + d * (t[4] + d * t[5]))));
      } else {
        exact[j] = true;
        any_exact = true;
      }
    }
    if (any_exact)
      for (const EffectValue& ev : m_.joint_effects())
        if (exact[ev.effect.joint] || !(ev.effect.kind().harmonic || ev.effect.kind().angle_free))
          add_joint_effect(ev, q, ctx_, theta, nullptr);
  }
  return theta;
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
