#include "kincal/model/joint_convention.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace kincal {

void check_joint_convention(const std::string& name) {
  if (!name.empty() && name != "fanuc")
    throw InputError("joint convention '" + name + "': not known (fanuc, or none for the model's own angles)");
}

// How far from parallel axes 2 and 3 may be and still take the coupling. The coupling is how the
// controller numbers the joints, not a property of the exact geometry: FANUC's own model has the two
// axes parallel and the controller applies J3 = q3 + s q2 whatever the arm's real misalignment. An
// identified (or simulated, or diagnosed) model holds the real arm's axes, never exactly parallel: the
// identification finds them hundredths to tenths of a degree apart (0.18 deg on the kr500 truth of
// `kincal simulate --seed 3`), of the order of 1 deg at most on a sound arm. An arm whose axes 2 and 3
// are tens of degrees apart is another design: there J3 "to the horizontal" means nothing and s, the
// sign of z2 . z3, is undefined near 90 deg; it is refused. 5 deg is 5 times the largest misalignment
// an identification finds on a sound arm and far below any other design.
constexpr double kParallelTolDeg = 5.0;

int j3_coupling(const ModelSpec& spec) {
  check_joint_convention(spec.joint_convention);
  if (spec.joint_convention.empty()) return 0;
  if (spec.joints.size() < 3) throw InputError("joint convention fanuc: the robot has fewer than 3 joints");
  const double d = spec.joints[1].axis.normalized().dot(spec.joints[2].axis.normalized());
  static const double cos_tol = std::cos(kParallelTolDeg * kDeg);
  if (!(std::abs(d) >= cos_tol)) {  // a NaN (zero axis) refused too
    char angle[32];
    std::snprintf(angle, sizeof angle, "%.1f", std::acos(std::min(1.0, std::abs(d))) / kDeg);
    throw InputError(std::string("joint convention fanuc: the axes of joints 2 and 3 are ") + angle +
                     " deg from parallel at zero (a FANUC arm's are parallel; up to 5 deg is taken as a "
                     "calibrated misalignment)");
  }
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
