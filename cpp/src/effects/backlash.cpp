// backlash (serial, per joint): dq_j = b_j dir_j, dir_j = +-1 the sign of the last motion into the
// pose; a gear's play makes the joint lag behind the command: b < 0, in deg (with b > 0, a lead, a
// reversal smaller than 2|b| has no commanded angle that reaches the pose: the compensated program
// then misses it by up to 2|b|).
#include "kincal/effects/effects.hpp"

namespace kincal {

const EffectKind& backlash_kind() {
  static const EffectKind k = [] {
    EffectKind e{
      EffectId::backlash, "backlash", "serial", "joint", "dir", "joint_angle",
      "an offset of the joint angle that depends on the approach direction: b dir (deg)", false, false, 1,
      [](const Effect&) { return std::vector<std::string>{"backlash"}; },
      [](const Effect&) { return std::vector<std::string>{"rad"}; }, nullptr,
      [](const Effect&, double, double dir, double* b, double* db) {
        b[0] = dir;
        if (db) db[0] = 0;
      }};
    e.angle_free = true;
    return e;
  }();
  return k;
}

}  // namespace kincal
