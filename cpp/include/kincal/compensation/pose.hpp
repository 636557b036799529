// kincal: Newton compensation of a desired tool pose on a calibrated model (Samak, section II).
//
// F = [dX, dY, dZ, dR1, dR2, dR3] between the calibrated model's pose at the current machine
// coordinates and the desired pose: the position difference in mm and, by default, the rotation
// vector of R_model R_desired^T (base frame) in degrees, which has no singularity (a tool pose with
// B = +-90 deg is an ordinary pose); or, as an option, the paper's ABC differences dA, dB, dC in
// degrees (eq. 6), singular at B = +-90. q <- q - J^-1 F (eq. 8) until |F|^2 < epsilon (eq. 9) in
// mm^2 + deg^2 (for the rotation vector: the squared rotation angle in deg^2). J is either the
// paper's finite-difference Jacobian (eq. 7, step delta in degrees of the machine coordinates) or
// the analytic one (default): the geometric Jacobian of the whole model (compliance, transmission
// error, backlash, thermal expansion) mapped to the residual's rates. The analytic iteration reuses
// its last Jacobian for a step while the steps shrink |F| tenfold (a chord step: F only, no Jacobian
// and no factorisation; `reuse_contraction`), corrects its first step by the step's second-order term
// (`second_order`), and takes the rotation vector's rates as the angular velocity (exact at the
// solution, and used once |phi| < 0.05 rad): the same stopping rule on the exact F, at 0.76x the time
// per pose (BENCHMARKS.md). With compliance or joint effects (`split_effects`) it solves for the
// joints' actual angles a* on the chain alone, then for the commands q with a(q) = a* by a fixed point
// that contracts by the effects' derivative (1e-4..1e-3 per step), F at q from the chain's F and
// Jacobian at a*; where that fixed point does not contract tenfold per step, Newton on the whole model.
#pragma once

#include "kincal/kinematics/kinematics.hpp"
#include "kincal/model/model.hpp"

#include <optional>

namespace kincal {

/// The orientation part of Newton's residual F.
enum class Residual {
  RotationVector,  ///< rotation vector of R_model R_desired^T, degrees (default; no singularity)
  Abc              ///< the paper's ABC differences (eq. 6), degrees; singular at B = +-90 deg
};

struct CompensationOptions {
  Residual residual = Residual::RotationVector;
  bool finite_difference = false;  ///< the paper's eq. 7 instead of the analytic Jacobian
  double delta = 1e-8;             ///< finite-difference step (degrees of the machine coordinates)
  double epsilon = 1e-15;          ///< stop when |F|^2 < epsilon (mm^2 + deg^2)
  int max_iterations = 20;
  /// The analytic Jacobian is reused (a chord step) while each step shrinks |F| by at least this
  /// factor and |F| < 1e-3 (mm, deg), and taken anew otherwise; 0 takes it at every step (Newton's
  /// iteration as eq. 8 reads).
  double reuse_contraction = 0.1;
  /// The analytic iteration's first step corrected by its second-order term (the tool's acceleration
  /// along the step, solved with the same Jacobian): F falls to 1e-5..1e-3 of its start instead of
  /// 1e-3..1e-2, and one fresh step more converges. Skipped where the correction is over half the step,
  /// and with the ABC residual.
  bool second_order = true;
  /// With compliance or joint effects: the actual joint angles solved on the chain first, then the
  /// commands from them by a fixed point (compensation/pose.cpp); false: Newton's iteration on the
  /// whole model. Both stop on the same |F|^2 < epsilon.
  bool split_effects = true;
};

enum class CompStatus { Converged, NotConverged, SingularJacobian, OrientationSingular, NotSixJoints };
const char* to_string(CompStatus s);

struct CompensationResult {
  Vec6 q_deg;
  int iterations = 0;        ///< Newton updates made
  int joint_iterations = 0;  ///< with split_effects: the fixed point's updates of the commands
  double residual = 0;       ///< |F| at q_deg (mm and degrees mixed as in eq. 9)
  double position_error_mm = 0, orientation_error_deg = 0;  ///< |dXYZ| and |dABC| at q_deg
  CompStatus status = CompStatus::NotConverged;
};

/// The pose deviation F of the calibrated model (every effect acting in the context ctx) at q_deg
/// from the desired pose (xyz, abc): mm, and degrees of the chosen residual.
Vec6 pose_deviation(const Model& cal, const Vec6& q_deg, const Pose6& desired,
                    Residual residual = Residual::RotationVector, const EffectContext& ctx = EffectContext());

/// The analytic Jacobian of pose_deviation with respect to q_deg, as the default compensation uses
/// it: rows mm and degrees, columns per degree (with the ABC residual singular at B = +-90 deg).
Mat6 pose_deviation_jacobian(const Model& cal, const Vec6& q_deg, const Pose6& desired,
                             Residual residual = Residual::RotationVector, const EffectContext& ctx = EffectContext());

/// Half the second derivative of pose_deviation along step_deg at q_deg, as the first step of the
/// compensation uses it: pose_deviation(q + s) = F + J s + pose_deviation_second_order(s) + O(s^3)
/// where the model's pose equals the desired one (the rotation vector's own curvature, O(phi), and
/// the joint effects' curvature are omitted). The rotation-vector residual only (invalid_argument
/// for Residual::Abc).
Vec6 pose_deviation_second_order(const Model& cal, const Vec6& q_deg, const Pose6& desired, const Vec6& step_deg,
                                 Residual residual = Residual::RotationVector,
                                 const EffectContext& ctx = EffectContext());

/// Newton compensation from the start q0_deg (normally the nominal IK solution), every effect of
/// the model acting in the context ctx (InputError when the context lacks what the model needs).
CompensationResult compensate(const Model& cal, const Pose6& desired, const Vec6& q0_deg,
                              const CompensationOptions& opt = {}, const EffectContext& ctx = EffectContext());

/// Each joint moved by whole turns to the position nearest the reference, inside its limits when one is.
Vec6 wrap_near(const Model& m, const Vec6& q_deg, const Vec6& ref_deg);

/// Numerical inverse kinematics for robots without a closed form (e.g. the UR10): damped least
/// squares (Levenberg-Marquardt) on position and rotation-vector error from the reference, then from
/// home and from seeded starts inside the joint limits; the converged solution within the limits
/// nearest the reference (largest joint difference), polished by compensate(). Empty when none.
std::optional<Vec6> numeric_ik(const Model& m, const Pose6& desired, const Vec6& ref_deg,
                               const CompensationOptions& opt, int starts = 48,
                               const EffectContext& ctx = EffectContext());

}  // namespace kincal
