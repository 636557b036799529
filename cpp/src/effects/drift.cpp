// drift (serial, the whole robot; a property of the measurement): the instrument's placement moves
// linearly with time, a point x of the robot base frame is seen at Exp(tau w) R x + t + tau v instead
// of R x + t (R, t the placement; the rotation turns about the robot base's origin, v and w in the
// instrument's axes), tau = (t_s - t_mean) / 3600 s in hours. Removed from the fit and reported; a
// Model carries it inert: FK and compensation never apply it. v in mm/h, w in rad/h (deg/h in files).
#include "kincal/effects/effects.hpp"

namespace kincal {

const EffectKind& drift_kind() {
  static const EffectKind k{
      EffectId::drift, "drift", "serial", "robot", "time_s", "instrument",
      "the instrument's placement moving linearly with time (a property of the measurement: removed from "
      "the fit, never compensated): translation mm/h and rotation deg/h about the campaign's mean time",
      false, false, 6,
      [](const Effect&) {
        return std::vector<std::string>{"drift_x", "drift_y", "drift_z", "drift_rx", "drift_ry", "drift_rz"};
      },
      [](const Effect&) { return std::vector<std::string>{"mm/h", "mm/h", "mm/h", "rad/h", "rad/h", "rad/h"}; },
      nullptr, nullptr};
  return k;
}

}  // namespace kincal
