// kincal (private): the chain's recursions that the FK (kinematics.cpp) and the joint angles near a
// reference (joint_angles_near.cpp) share: the walk from the joints' sines and cosines, the gravity
// torque in the joints' own frames, the small turn of a sine and cosine, one joint effect's angle.
#pragma once

#include "kincal/effects/effects.hpp"
#include "kincal/kinematics/kinematics.hpp"

namespace kincal::kinematics_detail {

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

// The gravity torque alone, without rotation matrices: two recursions of 3-vectors in the joints' own
// frames (the frame right after each joint's rotation, as walk_n visits it). Forward, gravity in
// frame j: g_0 = Rz(th_0)^T C0^T g, g_j+1 = Rz(th_j+1)^T Rx(alpha_j)^T g_j. Backward, the first
// moment about joint j's origin of everything it carries, in frame j:
// A_j = mc_j + M_j+1 t_j + Rx(alpha_j) Rz(th_j+1) A_j+1 (M_j+1: the mass beyond joint j). Then
// tau_j = z . (A_j x g_j), z = (0, 0, 1) in its own frame. About a third of the walk's work.
// N > 0: the joint count known at compile time (as walk_sc). out(j, tau_j, diag_j, next_j) takes
// each torque (its callers add the deflection there: an array of torques stored one by one and read
// two at a time stalled the fixed point of compensation on the failed store forwarding) with the
// diagonal of its derivative and the entry next to it (the derivative is symmetric), diag_j =
// d tau_j / d q_j and next_j = d tau_j / d q_j+1 (0 for the last joint): turning joint j turns g_j by
// -z x g_j; turning joint j+1 turns what A_j carries beyond it, Rx(alpha_j) (z x Rz(th_j+1) A_j+1).
// (Inlined, the derivative's few products vanish where out ignores them.)
template <int N = 0, class Out>
inline void gravity_torque_sc(const Model& m, const double* s, const double* c, Out&& out) {
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
  out(n - 1, a[0] * gy[n - 1] - a[1] * gx[n - 1], -(a[0] * gx[n - 1] + a[1] * gy[n - 1]), 0.0);
#pragma GCC unroll 6
  for (int j = n - 2; j >= 0; --j) {
    const Model::Link& l = m.link(j);
    const double x = c[j + 1] * a[0] - s[j + 1] * a[1], y = s[j + 1] * a[0] + c[j + 1] * a[1];
    a = l.mc + mass * l.t + Vec3(x, l.ca * y - l.sa * a[2], l.sa * y + l.ca * a[2]);
    mass += l.m;
    out(j, a[0] * gy[j] - a[1] * gx[j], -(a[0] * gx[j] + a[1] * gy[j]), -y * gy[j] - l.ca * x * gx[j]);
  }
}

// s, c of an angle x turned into those of x + d for a small d (|d| <= kTurnMax): sin d and 1 - cos d
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

}  // namespace kincal::kinematics_detail
