// joint_compliance (serial, per gravity-loaded joint): dq_j = c_j tau_j(q), c in deg per kN m. The
// deflection itself is the model's (Model::compliance, kinematics' deflected()), from the gravity
// torques of the link masses or of mass moments identified with it.
#include "kincal/effects/effects.hpp"

namespace kincal {

const EffectKind& joint_compliance_kind() {
  static const EffectKind k{EffectId::joint_compliance, "joint_compliance", "serial", "joint", "", "joint_angle",
                            "joint deflection proportional to the gravity torque (deg per kN m)", true, false, 1,
                            [](const Effect&) { return std::vector<std::string>{"compliance"}; },
                            [](const Effect&) { return std::vector<std::string>{"deg/kNm"}; }, nullptr, nullptr};
  return k;
}

}  // namespace kincal
