// link_deflection (the five-bar hidden robot, per link): the link's length varies with the pose as
// p1 cos t1 + p2 sin t1 + p3 cos t2 + p4 sin t2, p in mm (the basis below; fitted by the five-bar
// diagnosis).
#include "kincal/effects/effects.hpp"

#include <cmath>

namespace kincal {

const EffectKind& link_deflection_kind() {
  static const EffectKind k{
      EffectId::link_deflection, "link_deflection", "fivebar", "link", "", "link_length",
      "a link length that varies with the pose: p1 cos t1 + p2 sin t1 + p3 cos t2 + p4 sin t2 (mm)", false, false, 4,
      [](const Effect&) { return std::vector<std::string>{"p1_cos_t1", "p2_sin_t1", "p3_cos_t2", "p4_sin_t2"}; },
      [](const Effect&) { return std::vector<std::string>(4, "mm"); }, nullptr, nullptr, false,
      [](const Effect&, double t1, double t2, double* b) {
        b[0] = std::cos(t1), b[1] = std::sin(t1), b[2] = std::cos(t2), b[3] = std::sin(t2);
      }};
  return k;
}

}  // namespace kincal
