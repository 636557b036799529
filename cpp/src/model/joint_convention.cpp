#include "kincal/model/joint_convention.hpp"

#include <cmath>

namespace kincal {

void check_joint_convention(const std::string& name) {
  if (!name.empty() && name != "fanuc")
    throw InputError("joint convention '" + name + "': not known (fanuc, or none for the model's own angles)");
}

int j3_coupling(const ModelSpec& spec) {
  check_joint_convention(spec.joint_convention);
  if (spec.joint_convention.empty()) return 0;
  if (spec.joints.size() < 3) throw InputError("joint convention fanuc: the robot has fewer than 3 joints");
  const double d = spec.joints[1].axis.normalized().dot(spec.joints[2].axis.normalized());
  if (std::abs(std::abs(d) - 1) > 1e-6)
    throw InputError("joint convention fanuc: the axes of joints 2 and 3 are not parallel at zero (a FANUC arm's are)");
  return d > 0 ? 1 : -1;
}

void joints_to_controller(const ModelSpec& spec, double* q, int n) {
  if (const int s = j3_coupling(spec); s != 0 && n >= 3) q[2] += s * q[1];
}

void joints_from_controller(const ModelSpec& spec, double* q, int n) {
  if (const int s = j3_coupling(spec); s != 0 && n >= 3) q[2] -= s * q[1];
}

ModelSpec with_joint_convention(ModelSpec spec, const std::string& name) {
  spec.joint_convention = name;
  j3_coupling(spec);
  return spec;
}

}  // namespace kincal
