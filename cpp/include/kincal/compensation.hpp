// kincal: Newton compensation of a desired tool pose on a calibrated model (Samak, section II).
//
// F = [dX, dY, dZ, dA, dB, dC] in mm and degrees (eq. 6) between the calibrated model's pose at the
// current machine coordinates and the desired pose; q <- q - J^-1 F (eq. 8) until |F|^2 < epsilon
// (eq. 9). J is either the paper's finite-difference Jacobian (eq. 7, step delta in degrees of the
// machine coordinates) or the analytic one (default): the geometric Jacobian of the compliant model
// mapped to ABC rates.
#pragma once

#include "kincal/model.hpp"

namespace kincal {

struct CompensationOptions {
  bool finite_difference = false;  ///< the paper's eq. 7 instead of the analytic Jacobian
  double delta = 1e-8;             ///< finite-difference step (degrees of the machine coordinates)
  double epsilon = 1e-15;          ///< stop when |F|^2 < epsilon (mm^2 + deg^2)
  int max_iterations = 20;
};

enum class CompStatus { Converged, NotConverged, SingularJacobian, OrientationSingular, NotSixJoints };
const char* to_string(CompStatus s);

struct CompensationResult {
  Eigen::Matrix<double, 6, 1> q_deg;
  int iterations = 0;        ///< Newton updates made
  double residual = 0;       ///< |F| at q_deg (mm and degrees mixed as in eq. 9)
  double position_error_mm = 0, orientation_error_deg = 0;  ///< |dXYZ| and |dABC| at q_deg
  CompStatus status = CompStatus::NotConverged;
};

/// The pose deviation F (eq. 6) of the calibrated model at q_deg from the desired pose (xyz, abc).
Vec6 pose_deviation(const Model& cal, const Eigen::Matrix<double, 6, 1>& q_deg, const Pose6& desired);

/// The analytic Jacobian of pose_deviation with respect to q_deg, as the default compensation uses
/// it: rows mm and degrees, columns per degree (the ABC rates singular at B = +-90 deg).
Mat6 pose_deviation_jacobian(const Model& cal, const Eigen::Matrix<double, 6, 1>& q_deg, const Pose6& desired);

/// Newton compensation from the start q0_deg (normally the nominal IK solution).
CompensationResult compensate(const Model& cal, const Pose6& desired, const Eigen::Matrix<double, 6, 1>& q0_deg,
                              const CompensationOptions& opt = {});

/// Each joint moved by whole turns to the position nearest the reference, inside its limits when one is.
Eigen::Matrix<double, 6, 1> wrap_near(const Model& m, const Eigen::Matrix<double, 6, 1>& q_deg,
                                      const Eigen::Matrix<double, 6, 1>& ref_deg);

/// Numerical inverse kinematics for robots without a closed form (e.g. the UR10): damped least
/// squares (Levenberg-Marquardt) on position and rotation-vector error from the reference, then from
/// home and from seeded starts inside the joint limits; the converged solution within the limits
/// nearest the reference (largest joint difference), polished by compensate(). false when none.
bool numeric_ik(const Model& m, const Pose6& desired, const Eigen::Matrix<double, 6, 1>& ref_deg,
                Eigen::Matrix<double, 6, 1>& q_deg, const CompensationOptions& opt, int starts = 48);

}  // namespace kincal
