// kincal: forward kinematics and Jacobians on the compiled evaluator of a Model.
// Joint angles are radians here (the hot path); the program layer converts degrees.
// Nothing here allocates: every buffer has a fixed maximum size.
#pragma once

#include "kincal/core/fastmath.hpp"
#include "kincal/model/model.hpp"

#include <limits>
#include <string>

namespace kincal {

/// Rotation by angle q (rad) about the unit axis k (Rodrigues), with the hot paths' sine and cosine.
inline Mat3 axis_rotation(const Vec3& k, double q) {
  double s, c;
  fastmath::sincos(q, s, c);
  const double v = 1 - c;
  Mat3 r;
  r << c + k[0] * k[0] * v, k[0] * k[1] * v - k[2] * s, k[0] * k[2] * v + k[1] * s,  //
      k[1] * k[0] * v + k[2] * s, c + k[1] * k[1] * v, k[1] * k[2] * v - k[0] * s,    //
      k[2] * k[0] * v - k[1] * s, k[2] * k[1] * v + k[0] * s, c + k[2] * k[2] * v;
  return r;
}

/// Tool pose in the base frame (rigid model: no compliance).
Eigen::Isometry3d fk(const Model& m, const VecQ& q);

/// The joint frames of one FK pass: axis z_j and origin o_j of every joint (base frame) and the tool.
struct ChainFrames {
  std::array<Vec3, kMaxJoints> z, o;
  Eigen::Isometry3d tool;
  int n = 0;
  std::array<double, kMaxJoints + 1> s, c;  ///< the sines and cosines of the angles walked (+ offsets)
};

/// FK keeping the joint frames, so that the Jacobian can follow only when it is needed.
void fk_frames(const Model& m, const VecQ& q, ChainFrames& f);

/// The geometric Jacobian (as fk_jacobian) from the frames of fk_frames.
void jacobian_from(const ChainFrames& f, Jac& jac);

/// Geometric Jacobian 6xN at the tool point: rows 0-2 linear velocity (mm/rad), rows 3-5 angular
/// velocity, both in the base frame (the same convention as KDL::ChainJntToJacSolver).
void fk_jacobian(const Model& m, const VecQ& q, Eigen::Isometry3d& tool, Jac& jac);

/// Gravity torque on every joint (N mm) and, when dtau is not null, its derivative dtau/dq.
void gravity_torque(const Model& m, const VecQ& q, VecQ& tau, MatQ* dtau = nullptr);

/// The joint angles after deflection under gravity: q + K tau(q); with dqd, also their derivative
/// d(q + K tau)/dq = I + K dtau/dq (the identity for a model without compliance).
VecQ deflected(const Model& m, const VecQ& q, MatQ* dqd = nullptr);

/// What the model's effects read besides the joint angles: each joint's direction of motion into
/// the pose (+-1, backlash; empty when unknown) and the temperature (thermal expansion; NaN when
/// unknown). Fixed size: no allocation.
struct EffectContext {
  VecQ dir;
  double temperature_c = std::numeric_limits<double>::quiet_NaN();
};

/// InputError naming what the model needs and the context lacks (`who` in front), e.g. the dir
/// columns for backlash; nothing when the context suffices.
void check_context(const Model& m, const EffectContext& ctx, const std::string& who);

/// The angles the joints stand at for commanded q (rad): q + K tau(q) + transmission error(q) +
/// backlash * dir; with dqd their derivative with respect to q. The context must suffice.
VecQ joint_angles(const Model& m, const VecQ& q, const EffectContext& ctx, MatQ* dqd = nullptr);

/// fk_frames at joint_angles(m, q, ctx), the sines and cosines of q shared by the gravity torque and
/// the walk (theta's from q's by the small angle theta - q): one evaluation of the model's F in
/// Newton compensation. The same frames as fk_frames(m, joint_angles(m, q, ctx)) to rounding.
void fk_frames_actual(const Model& m, const VecQ& q, const EffectContext& ctx, ChainFrames& f);

/// The sines and cosines of every joint's angle (q + its offset) as the chain's walk uses them, kept
/// with the angles they are of, to be turned by series (turn_to) to angles a small step away instead
/// of computed anew (JointAnglesNear). (Kept from one Newton step of the chain's FK to the next they
/// made the FK slower than its own sincos: BENCHMARKS.md.)
struct JointTrig {
  std::array<double, kMaxJoints + 1> s, c;  ///< (not zeroed: set() writes them)
  VecQ q;  ///< the angles (rad) they are of
  /// of q anew
  void set(const Model& m, const VecQ& q);
};

/// The band of the derivative of the joint angles' offset theta - q at a reference (joint j's with
/// respect to q_j-1, q_j and q_j+1), as JointAnglesNear::at_reference gives it: the preconditioner of
/// the commands' fixed point in compensation.
struct JointBand {
  std::array<double, kMaxJoints> lower, diag, upper;
  /// (I + band)^-1 v by the series I - band + band^2 (6 joints)
  Vec6 inverse_times(const Vec6& v) const;
};

/// joint_angles at commands near one reference: the commands' fixed point in compensation evaluates
/// it a few times within 1e-2 deg of one solution. The gravity torque from the reference's sines and
/// cosines turned to q (sin d and 1 - cos d by their series where every joint moves by at most 0.01
/// rad, the next terms below 1e-17; anew otherwise); the harmonic joint effects (transmission error,
/// joint map) on each joint by their Taylor series about the reference, of degree 5, where its
/// remainder is below 1e-18 rad (at q itself otherwise), and the angle-free ones (backlash) from the
/// reference. The same angles as joint_angles(m, q, ctx) to rounding.
class JointAnglesNear {
 public:
  JointAnglesNear(const Model& m, const VecQ& ref, const EffectContext& ctx);
  /// the reference's sines and cosines given (as ChainFrames keeps them)
  JointAnglesNear(const Model& m, const JointTrig& ref, const EffectContext& ctx);
  VecQ operator()(const VecQ& q) const;
  /// the same for a 6-joint robot in fixed sizes (compensation's fixed point); std::invalid_argument
  /// for other robots
  Vec6 at6(const Vec6& q) const;
  /// at the reference itself, with the band of the derivative there (the compliance's and the
  /// harmonic and angle-free effects'; other effects' left out)
  VecQ at_reference(JointBand& band) const;

 private:
  const Model& m_;
  const EffectContext& ctx_;
  JointTrig ref_;
  /// per joint: the harmonic and angle-free effects' angle as a polynomial in q - ref (Taylor
  /// coefficients; its remainder's bound is the model's, Model::harmonic_bound)
  std::array<std::array<double, 6>, kMaxJoints> taylor_;  // (the first dof() set)
  std::array<bool, kMaxJoints> series_;  ///< the joint has such effects
  bool other_effects_ = false;  ///< joint effects of other kinds: at q itself
  void prepare_effects();
  template <int N>
  void evaluate(const double* q, double* theta) const;
};

/// The factor every length of the robot scales by (thermal expansion; 1 without it).
inline double length_scale(const Model& m, const EffectContext& ctx) {
  return m.thermal_alpha() == 0 ? 1.0 : 1.0 + m.thermal_alpha() * (ctx.temperature_c - m.spec().t_ref_c);
}

/// Tool pose (base frame) with every effect of the model acting.
Eigen::Isometry3d fk_model(const Model& m, const VecQ& q, const EffectContext& ctx);

/// Tool pose and the 6xN Jacobian (as fk_jacobian) of the whole model with respect to commanded q.
void fk_jacobian_model(const Model& m, const VecQ& q, const EffectContext& ctx, Eigen::Isometry3d& tool, Jac& jac);

/// Tool pose with joint compliance (equals fk() for a model without compliance).
Eigen::Isometry3d fk_compliant(const Model& m, const VecQ& q);

/// Tool pose and the 6xN Jacobian of the compliant model with respect to the commanded q.
void fk_jacobian_compliant(const Model& m, const VecQ& q, Eigen::Isometry3d& tool, Jac& jac);

}  // namespace kincal
