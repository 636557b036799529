// kincal: the branch data of filtered Cartesian targets: which of the nominal inverse kinematics'
// solutions the controller is to take, in each controller's documented terms, and the selection the
// controller makes from them (to check that a written target brings back the compensated joints).
//
// Arm classes, from the nominal geometry (robots whose axes 2 and 3 are parallel and whose wrist
// axes meet), independent of the joints' senses:
//  - behind: the wrist centre's x in the A1 coordinate system (the base frame turned with axis 1;
//    x: the direction of the wrist centre at the zero configuration) is negative (KUKA: overhead area);
//  - elbow up: the forearm (axis 3 to the wrist centre) turns from the upper arm (axis 2 to axis 3)
//    about y' = z x x' (x' the A1 x axis, z the base's up) by an angle in (0, 180) deg: the elbow above
//    the line from shoulder to wrist, as at the upright home with the forearm forward (KUKA: A3 >= phi);
//  - the wrist by the sign of axis 5 (controller numbers).
// KUKA (KSS 8 system integrators' manual, "Status" and "Turn"): S bit 0 overhead, bit 1 A3 >= phi
// (elbow up), bit 2 A5 in [-180, 0) or >= 180; T bit i set when A(i+1) < 0.
// ABB (RAPID reference, confdata): cf1, cf4, cf6 the quadrants floor(q / 90 deg) of axes 1, 4, 6;
// cfx = 4 (wrist centre behind axis 1) + 2 (behind the lower arm: elbow down) + 1 (axis 5 negative).
// FANUC (configuration string): F (J5 > 0) or N, U (elbow up) or D, T (front) or B (back), then the
// turn numbers of J1, J4, J6: floor((q + 180) / 360).
#pragma once

#include "kincal/io/controllers.hpp"
#include "kincal/model/model.hpp"

#include <optional>
#include <string>
#include <vector>

namespace kincal {

struct ArmClass {
  bool behind = false;
  bool elbow_up = false;
  bool wrist_negative = false;  ///< axis 5 < 0 (wrapped to [-180, 180))
  double x_a1 = 0;              ///< the wrist centre's x in the A1 system (mm)
  double elbow_sin = 0;         ///< sine of the forearm's angle from the upper arm about y'
};

/// The arm class of the nominal robot at q_deg (needs the closed-form IK's structure).
ArmClass arm_class(const Robot& robot, const Vec6& q_deg);

/// Fills the target's branch data (kuka_s, kuka_t, abb_conf, fanuc_config) from its joints.
void set_branch_data(const Robot& robot, ControllerTarget& t);

/// What the controller's nominal model does with a filtered target: the solution of the nominal IK of
/// t.pose whose branch data (in format f: Krl, Rapid or FanucLs) is the target's. Empty, with why,
/// when none or several different ones match. border_tolerance (deg): a joint that close to a border (a
/// multiple of 90 deg) counts on either side of it: a taught program's target read back from its printed
/// pose (A1 taught at 0 comes back at -2e-6); 0: the controller's exact selection.
std::optional<Vec6> select_branch(const Robot& robot, ControllerFormat f, const ControllerTarget& t,
                                  std::string* why = nullptr, double border_tolerance = 0);

/// How joints q_deg sit against a taught target's branch data in format f (Krl, Rapid, FanucLs): `arm`
/// when the arm, elbow and wrist choice differs (KUKA S, ABB cfx, FANUC F/N U/D T/B); `turns` the joints
/// (0-based) whose turn differs (KUKA T bit, ABB cf1/cf4/cf6, FANUC turn numbers).
struct BranchDifference {
  bool arm = false;
  std::vector<int> turns;
};
/// A target's branch data as the controller writes them: "S 6, T 50", "cfx 1, cf1 0, cf4 -1, cf6 0", "N U T, 0, 0, 0".
std::string branch_text(ControllerFormat f, const ControllerTarget& t);

BranchDifference branch_difference(const Robot& robot, ControllerFormat f, const ControllerTarget& taught,
                                   const Vec6& q_deg);

}  // namespace kincal
