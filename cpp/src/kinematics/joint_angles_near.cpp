// kincal: the joint angles at commands near one reference (JointAnglesNear: compensation's fixed
// point on the commands), its series of the joint effects and the band of its derivative.
#include "chain_recursions.hpp"
#include "kincal/kinematics/kinematics.hpp"

#include <cmath>
#include <stdexcept>

namespace kincal {

using namespace kinematics_detail;

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

Vec6 JointBand::inverse_times(const Vec6& v) const {
  auto times = [&](const Vec6& x) {
    Vec6 w;
    for (int j = 0; j < 6; ++j) w[j] = diag[j] * x[j] + (j > 0 ? lower[j] * x[j - 1] : 0.0) + (j < 5 ? upper[j] * x[j + 1] : 0.0);
    return w;
  };
  const Vec6 bv = times(v);
  return v - bv + times(bv);
}

VecQ JointAnglesNear::at_reference(JointBand& band) const {
  double* lower = band.lower.data();
  double* diag = band.diag.data();
  double* upper = band.upper.data();
  const int n = m_.dof();
  VecQ theta(n);
  if (m_.has_compliance()) {
    double nx[kMaxJoints];
    auto deflect = [&](int j, double t, double dt, double next) {
      const double k = m_.compliance(j);
      theta[j] = ref_.q[j] + k * t;
      diag[j] = k * dt;
      upper[j] = k * next;
      nx[j] = next;
    };
    if (n == 6)
      gravity_torque_sc<6>(m_, ref_.s.data(), ref_.c.data(), deflect);
    else
      gravity_torque_sc<0>(m_, ref_.s.data(), ref_.c.data(), deflect);
    for (int j = 0; j < n; ++j) lower[j] = j > 0 ? m_.compliance(j) * nx[j - 1] : 0.0;
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

// joint_angles at q from the reference (operator(), at6)
template <int N>
void JointAnglesNear::evaluate(const double* q, double* theta) const {
  const int n = N > 0 ? N : m_.dof();
  if (m_.has_compliance()) {
    // the reference's sines and cosines turned to q (all of q's anew where a joint is farther)
    double s[kMaxJoints + 1], c[kMaxJoints + 1];
    bool near = true;
    for (int j = 0; j < n; ++j) {
      const double d = q[j] - ref_.q[j];
      near = near && std::abs(d) <= kTurnMax;
      s[j] = ref_.s[j];
      c[j] = ref_.c[j];
      turn_sincos(d, s[j], c[j]);
    }
    if (!near) joint_sincos<N>(m_, q, s, c);
    gravity_torque_sc<N>(m_, s, c, [&](int j, double t, double, double) { theta[j] = q[j] + m_.compliance(j) * t; });
  } else {
    for (int j = 0; j < n; ++j) theta[j] = q[j];
  }
  if (m_.has_joint_effects()) {
    // the harmonic effects by their series where its remainder is below kSeriesLeft, at q itself
    // (with the others) elsewhere
    std::array<bool, kMaxJoints> exact{};
    bool any_exact = other_effects_;
    for (int j = 0; j < n; ++j) {
      if (!series_[j]) continue;
      const double d = q[j] - ref_.q[j], d2 = d * d;
      if (m_.harmonic_bound(j) * (d2 * d2 * d2) <= kSeriesLeft) {
        const std::array<double, 6>& t = taylor_[j];
        theta[j] += t[0] + d * (t[1] + d * (t[2] + d * (t[3] + d * (t[4] + d * t[5]))));
      } else {
        exact[j] = true;
        any_exact = true;
      }
    }
    if (any_exact) {
      const VecQ qv = Eigen::Map<const VecQ>(q, n);
      VecQ out = Eigen::Map<const VecQ>(theta, n);
      for (const EffectValue& ev : m_.joint_effects())
        if (exact[ev.effect.joint] || !(ev.effect.kind().harmonic || ev.effect.kind().angle_free))
          add_joint_effect(ev, qv, ctx_, out, nullptr);
      for (int j = 0; j < n; ++j) theta[j] = out[j];
    }
  }
}

VecQ JointAnglesNear::operator()(const VecQ& q) const {
  VecQ theta(m_.dof());  // (not a copy of q: that one called memcpy, 3% of compensation with effects)
  if (m_.dof() == 6)
    evaluate<6>(q.data(), theta.data());
  else
    evaluate<0>(q.data(), theta.data());
  return theta;
}

Vec6 JointAnglesNear::at6(const Vec6& q) const {
  if (m_.dof() != 6) throw std::invalid_argument("JointAnglesNear::at6: 6 joints only");
  Vec6 theta;
  evaluate<6>(q.data(), theta.data());
  return theta;
}

}  // namespace kincal
