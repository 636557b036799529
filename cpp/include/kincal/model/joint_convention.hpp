// kincal: the controller's joint numbers, as the controller shows them. A FANUC controller reports and
// takes J3 as the forearm's angle to the horizontal, not to the upper arm: with the axes of joints 2 and
// 3 parallel at the zero configuration (directions z2, z3, s = z2 . z3 = +-1), the forearm's angle about
// z3 is q3 + s q2, so
//     J3 (controller) = q3 (model) + s q2 (model),   q3 (model) = J3 - s J2,   every other joint equal.
// (A ROS-Industrial FANUC URDF has z2 = +y, z3 = -y: s = -1, the URDF's joint 3 is J3 + J2.) The
// model's zero must have the forearm horizontal when the upper arm is vertical, as FANUC's has.
// Every file of joint angles holds the controller's numbers; kincal converts where it reads and writes
// them (measurements, joint programs, native and controller programs, fk, ik, compensate).
#pragma once

#include "kincal/model/model.hpp"

#include <string>

namespace kincal {

/// "" (none) or "fanuc"; InputError "joint convention 'x': ..." otherwise.
void check_joint_convention(const std::string& name);

/// s of the FANUC coupling (+1 or -1, the sign of z2 . z3) of spec, 0 when the convention is the model's
/// own; InputError when it is "fanuc" and axes 2 and 3 are more than 5 deg from parallel (a calibrated
/// arm's misalignment, a fraction of a degree, is taken: the coupling is the controller's numbering, not
/// the exact geometry) or the robot has fewer than 3 joints.
int j3_coupling(const ModelSpec& spec);

/// In place, n angles (deg): the model's to the controller's, and back.
void joints_to_controller(const ModelSpec& spec, double* q_deg, int n);
void joints_from_controller(const ModelSpec& spec, double* q_deg, int n);

/// The spec with the joint convention set (checked).
ModelSpec with_joint_convention(ModelSpec spec, const std::string& name);

}  // namespace kincal
